"""Finer search of the model-assisted full ESO at one row (assisted.py), stable candidates only."""
import sys, itertools, numpy as np, assisted as A
t = float(sys.argv[1])
res = []
for kappa, zeta, wn, wo in itertools.product((0.5, 0.75, 1.0), (0.3, 0.4, 0.5, 0.7, 1.0), np.geomspace(1.5, 6.0, 9),
                                             (3.0, 4.0, 5.0, 6.0, 7.0, 8.5, 10.0)):
    a = A.evaluate(t, wn, zeta, wo / wn, kappa)
    res.append((A.score(a), kappa, zeta, wn, wo, a))
res.sort(key=lambda x: -x[0])
shown = 0
f = lambda x: f"{x['gain_margin_db']:.1f}/{x['gain_reduction_margin_db']:.1f} {x['phase_margin_deg']:.1f}@{x['gain_crossover_radps']:.2f}"
for s, kappa, zeta, wn, wo, a in res[:80]:
    g = A.stable(t, wn, zeta, wo / wn, kappa)
    if max(g.values()) > 1e-4:
        continue
    print(f"score {s:.2f} kappa {kappa:g} zeta {zeta} wn {wn:.2f} wo {wo:.1f} k1 {a['k1']:.2f} k2 {a['k2']:.2f} | rig {f(a['rigid'])} | non {f(a['nonrigid'])}", flush=True)
    shown += 1
    if shown >= 5:
        break
