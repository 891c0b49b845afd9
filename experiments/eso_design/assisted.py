"""Model-assisted ESO for SMILE v1: per-row search, in the frequency domain (probe.py's cached plants).

Per row the observer's model is theta_dd = -m theta - c omega + b0 delta + f with (m, c) kappa times the rigid
short-period pair of the design linearisation (kappa 0: Gao's plain ESO, 1: model-assisted); the law
u = -(k1 theta_hat + k2 omega_hat + f_hat) / b0 with k1 = wn^2 - kappa m, k2 = 2 zeta wn - kappa c (the
observer's model closed at (s^2 + 2 zeta wn s + wn^2)). The compensator's response is computed in closed form
(strapdown integral x core x its own input model, servo and one period of delay), the plant's once per row;
the closed loop's stability from its eigenvalues for the candidates whose margins pass.

    python assisted.py [rows] [--lp W]   rows: comma list of times (default all nine)
"""
import sys, warnings
import numpy as np
warnings.filterwarnings("ignore")
from probe import plants, ed
from lvgym.baselines.design.lqg_row import response, margins_from_response, closed_loop_growth
from lvgym.baselines.eso import servo_model

DT = 0.02
P = plants(None)
W = np.logspace(-4, np.log10(np.pi / DT * 0.999), 1500)
Z = np.exp(1j * W * DT)
As, Bs = servo_model(15.0, 0.7, DT)
MS = np.array([(np.linalg.solve(z * np.eye(2) - As, Bs))[0] for z in Z]) / Z      # delay then servo
INTEG = 0.5 * DT * (Z + 1) / (Z - 1)


def stiffness(p):
    """(m, c): the rigid short-period pair s^2 + c s + m of the row's rigid plant (eigenvalues of the sampled
    plant, continuous equivalents, |s| < 12 rad/s, the drift pole left out)."""
    ev = np.linalg.eigvals(p["rigid"].A)
    s = np.log(ev[np.abs(ev) > 1e-9].astype(complex)) / DT
    s = s[np.abs(s) < 12]
    cx = s[np.abs(s.imag) > 1e-6]
    if cx.size:
        q = cx[cx.imag > 0][0]
        return abs(q) ** 2, -2 * q.real
    r = np.sort(s.real)
    a, b = r[0], r[-1]                              # the pair: the most negative and the most positive
    return a * b, -(a + b)


def comp_response(b0, m, c, k1, k2, wo, filt=None):
    phi, gam = ed.eso_model(DT, m, c)
    L = ed.observer_gain(wo, DT, m, c)
    ilc = np.eye(3) - np.outer(L, [1, 0, 0])
    F, G = ilc @ phi, ilc @ gam
    K = np.array([k1, k2, 1.0]) / b0
    zi = Z[:, None, None] * np.eye(3) - F
    xt = np.linalg.solve(zi, (Z[:, None] * L)[..., None])[..., 0]
    xd = np.linalg.solve(zi, (G * b0)[None, :, None] * ((Z + 1) / 2)[:, None, None])[..., 0]
    cth, cd = -xt @ K, -xd @ K
    out = INTEG * cth / (1 - cd * MS)
    return out if filt is None else out * filt


def plant_resp(g):
    g1 = __import__("control").ss(g.A, g.B, g.C[:1], g.D[:1], g.dt)
    return response(g1, W)


def score(a):
    """The worst ratio to the rules over rigid and non-rigid: GM/6, -GRM/6, |PM|/30 (1: met)."""
    s = []
    for k in ("rigid", "nonrigid"):
        m = a[k]
        s += [m["gain_margin_db"] / 6.0, -m["gain_reduction_margin_db"] / 6.0, abs(m["phase_margin_deg"]) / 30.0]
    return min(s)


def evaluate(t, wn, zeta, ratio, kappa, filt=None, stab=True):
    p = P[t]
    m, c = stiffness(p)
    m, c = kappa * m, kappa * c
    k1, k2 = wn * wn - m, 2 * zeta * wn - c
    cr = comp_response(p["b0"], m, c, k1, k2, ratio * wn, filt)
    out = {"k1": k1, "k2": k2}
    for k in ("rigid", "nonrigid"):
        out[k] = margins_from_response(-cr * PG[t][k], W)
    return out


def stable(t, wn, zeta, ratio, kappa):
    p = P[t]
    m, c = stiffness(p)
    comp = ed.compensator(p["b0"], wn, ratio * wn, DT, None, ed.input_model(DT, 1, (15.0, 0.7)),
                          stiffness=kappa * m, damping=kappa * c, zeta=zeta)
    return {k: closed_loop_growth(ed.open_loop(comp, p[k])) for k in ("rigid", "nonrigid")}


PG = {t: {k: plant_resp(p[k]) for k in ("rigid", "nonrigid")} for t, p in P.items()}

if __name__ == "__main__":
    times = [float(x) for x in sys.argv[1].split(",")] if len(sys.argv) > 1 and sys.argv[1] != "all" else list(P)
    for t in times:
        m, c = stiffness(P[t])
        res = []
        for kappa in (0.0, 1.0):
            for zeta in (0.5, 0.7, 1.0, 1.4):
                for wn in np.geomspace(0.5, 8.0, 13):
                    for wo in (2.0, 3.0, 4.0, 6.0, 8.0, 11.0, 16.0):
                        a = evaluate(t, wn, zeta, wo / wn, kappa)
                        res.append((score(a), kappa, zeta, wn, wo / wn, a))
        res.sort(key=lambda x: -x[0])
        shown = 0
        print(f"--- t {t:g}: b0 {P[t]['b0']:.2f} m {m:.2f} c {c:.2f}")
        for s, kappa, zeta, wn, ratio, a in res[:40]:
            g = stable(t, wn, zeta, ratio, kappa)
            if max(g.values()) > 1e-4:
                continue
            f = lambda x: f"{x['gain_margin_db']:.1f}/{x['gain_reduction_margin_db']:.1f} {x['phase_margin_deg']:.1f}@{x['gain_crossover_radps']:.2f}"
            print(f"score {s:.2f} kappa {kappa:g} zeta {zeta} wn {wn:.2f} wo {ratio*wn:.1f} k1 {a['k1']:.2f} k2 {a['k2']:.2f} | rig {f(a['rigid'])} | non {f(a['nonrigid'])}", flush=True)
            shown += 1
            if shown >= 4:
                break
