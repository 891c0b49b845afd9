"""Finer search of the reduced-order (rate-fed) ESO at one row (reduced.py), stable candidates only."""
import sys, itertools, numpy as np, assisted as A, reduced as R
t = float(sys.argv[1])
res = []
for kappa, zeta, wn, wo in itertools.product((0.0, 0.5, 1.0), (0.4, 0.7, 1.0, 1.4), np.geomspace(0.4, 3.2, 8),
                                             (4.0, 6.0, 8.0, 11.0, 16.0, 22.0, 30.0)):
    a = R.evaluate(t, wn, zeta, wo, kappa)
    res.append((A.score(a), kappa, zeta, wn, wo, a))
res.sort(key=lambda x: -x[0])
shown = 0
f = lambda x: f"{x['gain_margin_db']:.1f}/{x['gain_reduction_margin_db']:.1f} {x['phase_margin_deg']:.1f}@{x['gain_crossover_radps']:.2f}"
for s, kappa, zeta, wn, wo, a in res[:80]:
    g, _ = R.growth(t, wn, zeta, wo, kappa)
    if max(g.values()) > 1e-4:
        continue
    print(f"score {s:.2f} kappa {kappa:g} zeta {zeta} wn {wn:.2f} wo {wo:.1f} k1 {a['k1']:.2f} k2 {a['k2']:.2f} | rig {f(a['rigid'])} | non {f(a['nonrigid'])}", flush=True)
    shown += 1
    if shown >= 5:
        break
