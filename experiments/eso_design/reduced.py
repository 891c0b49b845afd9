"""Reduced-order ESO on the rate for SMILE v1: per-row search in the frequency domain (assisted.py's plants).

Per plane the observer estimates the rate and the disturbance from the gyro sample, with the strapdown attitude
as a known input: omega_dot = -m theta - c omega + f + b0 delta (m, c: kappa times the rigid pair); the law
u = -(k1 theta + k2 omega_hat + f_hat) / b0, k1 = wn^2 - kappa m, k2 = 2 zeta wn - kappa c. Optional low-pass on
the gyro (second order, `lp` rad/s, damping 0.7, Tustin as baselines/filters.py).

    python reduced.py rows [lp]
"""
import math, sys
import numpy as np
import scipy.linalg as sla
import assisted as A
from lvgym.baselines.filters import StructuralFilter
from lvgym.baselines.design.lqg_row import response, margins_from_response

DT, Z, W = A.DT, A.Z, A.W


def model2(m, c):
    a = np.array([[-c, 1.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    e = sla.expm(a * DT)
    return e[:2, :2], e[:2, 2]


def gain2(wo, phi):
    beta = math.exp(-wo * DT)
    c = np.array([[1.0, 0.0]])
    o = np.vstack([c @ phi, c @ phi @ phi])
    co = np.poly([beta, beta])
    pp = phi @ phi + co[1] * phi + co[2] * np.eye(2)
    return pp @ np.linalg.solve(o, np.array([0.0, 1.0]))


def comp_response(b0, m, c, k1, k2, wo, filt=None):
    phi, gam = model2(m, c)
    L = gain2(wo, phi)
    ilc = np.eye(2) - np.outer(L, [1, 0])
    F, G = ilc @ phi, ilc @ gam
    fr = np.ones_like(Z) if filt is None else filt
    half = (Z + 1) / 2
    zi = Z[:, None, None] * np.eye(2) - F
    rg = (Z[:, None] * L)[:, :] * fr[:, None] - G[None, :] * (m * half * A.INTEG * fr)[:, None]
    xg = np.linalg.solve(zi, rg[..., None])[..., 0]
    xd = np.linalg.solve(zi, (G[None, :] * (b0 * half)[:, None])[..., None])[..., 0]
    K2 = np.array([k2, 1.0])
    cg = -(k1 * A.INTEG * fr + xg @ K2) / b0
    cd = -(xd @ K2) / b0
    return cg / (1 - cd * A.MS)


def evaluate(t, wn, zeta, wo, kappa, filt=None):
    p = A.P[t]
    m, c = A.stiffness(p)
    m, c = kappa * m, kappa * c
    k1, k2 = wn * wn - m, 2 * zeta * wn - c
    cr = comp_response(p["b0"], m, c, k1, k2, wo, filt)
    out = {"k1": k1, "k2": k2, "cr": cr}
    for k in ("rigid", "nonrigid"):
        out[k] = margins_from_response(-cr * A.PG[t][k], W)
    return out


def core_ss(b0, m, c, k1, k2, wo):
    """The reduced observer and law from (gyro g_k, gimbal delta_k) to u_k; states x_hat (2), theta_{k-1},
    delta_{k-1}, g_{k-1} (the strapdown attitude as the trapezoidal integral of the gyro inside)."""
    import control
    phi, gam = model2(m, c)
    L = gain2(wo, phi)
    ilc = np.eye(2) - np.outer(L, [1, 0])
    F, G = ilc @ phi, ilc @ gam
    h = 0.5 * DT
    # theta_k = th + h gp + h g ;  x_k = F x + G b0/2 (dp + d) - G m/2 (th + theta_k) + L g
    A_ = np.zeros((5, 5)); B_ = np.zeros((5, 2))
    A_[:2, :2] = F; A_[:2, 3] = G * b0 / 2; A_[:2, 2] = -G * m / 2 - G * m / 2; A_[:2, 4] = -G * m / 2 * h
    B_[:2, 0] = L - G * m / 2 * h; B_[:2, 1] = G * b0 / 2
    A_[2, 2] = 1.0; A_[2, 4] = h; B_[2, 0] = h           # theta_k
    B_[3, 1] = 1.0; B_[4, 0] = 1.0
    K = np.array([k2, 1.0])
    C_ = -(K @ A_[:2] + k1 * A_[2]) / b0
    D_ = -(K @ B_[:2] + k1 * B_[2]) / b0
    return control.ss(A_, B_, C_.reshape(1, -1), D_.reshape(1, -1), DT)


def comp_ss(b0, m, c, k1, k2, wo, lp=0):
    import control
    comp = A.ed.close_input(core_ss(b0, m, c, k1, k2, wo), A.ed.input_model(DT, 1, (15.0, 0.7)))
    if lp:
        comp = control.ss(control.series(StructuralFilter(lowpass_radps=lp, lowpass_damping=0.7).tf(DT), comp))
    return comp


def growth(t, wn, zeta, wo, kappa, lp=0):
    from lvgym.baselines.design.lqg_row import closed_loop_growth
    p = A.P[t]
    m, c = A.stiffness(p)
    m, c = kappa * m, kappa * c
    comp = comp_ss(p["b0"], m, c, wn * wn - m, 2 * zeta * wn - c, wo, lp)
    return {k: closed_loop_growth(A.ed.open_loop(comp, p[k])) for k in ("rigid", "nonrigid")}, comp


if __name__ == "__main__":
    times = [float(x) for x in sys.argv[1].split(",")]
    lp = float(sys.argv[2]) if len(sys.argv) > 2 else 0
    filt = None if not lp else response(StructuralFilter(lowpass_radps=lp, lowpass_damping=0.7).tf(DT), W)
    for t in times:
        m, c = A.stiffness(A.P[t])
        res = []
        for kappa in (0.0, 1.0):
            for zeta in (0.5, 0.7, 1.0, 1.4):
                for wn in np.geomspace(0.5, 8.0, 13):
                    for wo in (2.0, 3.0, 4.0, 6.0, 8.0, 11.0, 16.0, 22.0):
                        a = evaluate(t, wn, zeta, wo, kappa, filt)
                        res.append((A.score(a), kappa, zeta, wn, wo, a))
        res.sort(key=lambda x: -x[0])
        print(f"--- t {t:g}: b0 {A.P[t]['b0']:.2f} m {m:.2f} c {c:.2f} lp {lp}")
        f = lambda x: f"{x['gain_margin_db']:.1f}/{x['gain_reduction_margin_db']:.1f} {x['phase_margin_deg']:.1f}@{x['gain_crossover_radps']:.2f}"
        shown = 0
        for s, kappa, zeta, wn, wo, a in res[:60]:
            g, _ = growth(t, wn, zeta, wo, kappa, lp)
            if max(g.values()) > 1e-4:
                continue
            shown += 1
            if shown > 4:
                break
            print(f"score {s:.2f} kappa {kappa:g} zeta {zeta} wn {wn:.2f} wo {wo:.1f} k1 {a['k1']:.2f} k2 {a['k2']:.2f} | rig {f(a['rigid'])} | non {f(a['nonrigid'])}", flush=True)

