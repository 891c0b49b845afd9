"""Per row, among the attitude-fed model-assisted ESOs that meet the rules with a margin (score >= 1.05, closed
loop stable), the one of the largest rigid loop gain at 1 rad/s (tracking of the pitch programme, rejection of
the wind): the margin-only search (fine20.py) picks low crossovers (0.6-0.8 rad/s) that fly the boost with twice
lqg's rate error and exceed q-alpha on 2 of 4 validation seeds."""
import sys, itertools, numpy as np, assisted as A
i1 = np.argmin(np.abs(A.W - 1.0))
for t in [float(x) for x in sys.argv[1].split(",")]:
    res = []
    for kappa, zeta, wn, wo in itertools.product((0.5, 1.0), (0.3, 0.5, 0.7), np.geomspace(1.5, 8.0, 8), (4.0, 6.0, 8.0, 11.0, 16.0)):
        a = A.evaluate(t, wn, zeta, wo / wn, kappa)
        s = A.score(a)
        if s >= 1.05:
            m, c = A.stiffness(A.P[t])
            cr = A.comp_response(A.P[t]["b0"], kappa * m, kappa * c, wn * wn - kappa * m, 2 * zeta * wn - kappa * c, wo)
            res.append((abs(cr[i1] * A.PG[t]["rigid"][i1]), s, kappa, zeta, wn, wo, a))
    res.sort(key=lambda x: -x[0])
    f = lambda x: f"{x['gain_margin_db']:.1f}/{x['gain_reduction_margin_db']:.1f} {x['phase_margin_deg']:.1f}@{x['gain_crossover_radps']:.2f}"
    shown = 0
    for g1, s, kappa, zeta, wn, wo, a in res[:40]:
        g = A.stable(t, wn, zeta, wo / wn, kappa)
        if max(g.values()) > 1e-4:
            continue
        print(f"t {t:g} |L(1)| {g1:.2f} score {s:.2f} kappa {kappa:g} zeta {zeta} wn {wn:.2f} wo {wo:.1f} | rig {f(a['rigid'])} | non {f(a['nonrigid'])}", flush=True)
        shown += 1
        if shown >= 2:
            break
