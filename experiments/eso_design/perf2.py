"""Per row, among the attitude-fed model-assisted ESOs that meet the rules with a margin (score >= 1.05, closed
loop stable), the one of the largest rigid loop gain at 1 rad/s (tracking of the pitch programme, rejection of
the wind), with a damping floor (argument 2, default 0.3; 0: the margin rules alone): the rigid closed loop's
poles between 0.3 and 30 rad/s damped at least ZMIN (the margin rules alone leave the weathercock mode near
5 rad/s at zeta ~0.1 when the crossover sits below it, and the wind rings it: twice lqg's rate error on
validation seeds)."""
import sys, itertools, numpy as np, control, assisted as A
ZMIN = float(sys.argv[2]) if len(sys.argv) > 2 else 0.3
i1 = np.argmin(np.abs(A.W - 1.0))


def min_damping(t, wn, zeta, wo, kappa):
    p = A.P[t]
    m, c = A.stiffness(p)
    comp = A.ed.compensator(p["b0"], wn, wo, A.DT, None, A.ed.input_model(A.DT, 1, (15.0, 0.7)), stiffness=kappa * m,
                            damping=kappa * c, zeta=zeta)
    L = A.ed.open_loop(comp, p["rigid"])
    z = np.linalg.eigvals(np.asarray(control.feedback(L, 1).A, float)).astype(complex)
    s = np.log(z[np.abs(z) > 1e-12]) / A.DT
    s = s[(np.abs(s) > 0.3) & (np.abs(s) < 30)]
    return float(np.min(-s.real / np.abs(s))) if s.size else 1.0


for t in [float(x) for x in sys.argv[1].split(",")]:
    res = []
    for kappa, zeta, wn, wo in itertools.product((0.5, 1.0), (0.3, 0.5, 0.7, 1.0), np.geomspace(1.5, 8.0, 8), (4.0, 6.0, 8.0, 11.0, 16.0)):
        a = A.evaluate(t, wn, zeta, wo / wn, kappa)
        s = A.score(a)
        if s >= 1.05:
            m, c = A.stiffness(A.P[t])
            cr = A.comp_response(A.P[t]["b0"], kappa * m, kappa * c, wn * wn - kappa * m, 2 * zeta * wn - kappa * c, wo)
            res.append((abs(cr[i1] * A.PG[t]["rigid"][i1]), s, kappa, zeta, wn, wo, a))
    res.sort(key=lambda x: -x[0])
    f = lambda x: f"{x['gain_margin_db']:.1f}/{x['gain_reduction_margin_db']:.1f} {x['phase_margin_deg']:.1f}@{x['gain_crossover_radps']:.2f}"
    shown = 0
    for g1, s, kappa, zeta, wn, wo, a in res[:60]:
        g = A.stable(t, wn, zeta, wo / wn, kappa)
        if max(g.values()) > 1e-4:
            continue
        zd = min_damping(t, wn, zeta, wo, kappa)
        if zd < ZMIN:
            continue
        print(f"t {t:g} |L(1)| {g1:.2f} zmin {zd:.2f} score {s:.2f} kappa {kappa:g} zeta {zeta} wn {wn:.2f} wo {wo:.1f} | rig {f(a['rigid'])} | non {f(a['nonrigid'])}", flush=True)
        shown += 1
        if shown >= 2:
            break
    if not shown:
        print(f"t {t:g}: none at zmin {ZMIN}", flush=True)
