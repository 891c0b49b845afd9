"""A lower bound on the q-alpha any TVC controller can keep in a given wind (docs/flex-design.md, "The
slender vehicle"): the best the gimbal could do with perfect knowledge of the wind ahead, on the rigid
pitch-plane model.

Model: :func:`.linearize.analytic_rigid` (states ``(w, theta, q)``: the lateral velocity [m/s], the pitch
angle [rad] and rate [rad/s]; ``alpha = theta + w / V``), frozen at the times ``times`` of the vehicle's
v1 flight with the gimbal centred, its matrices interpolated linearly in time. A horizontal wind ``u_w``
[m/s] across the plane adds ``-u_w / V`` to the angle of attack, so it enters the model as
``x_dot = A x + B delta + E (u_w / V)`` with ``E = -V A[:, 0]`` (the column of ``w`` carries the
aerodynamic terms, ``d x_dot / d alpha = V A[:, 0]``).

:func:`min_peak_qalpha` solves, by linear programming (scipy's HiGHS), ``min_delta max_k q_k |alpha_k|``
over the control steps ``k`` (zero-order hold of ``delta_k``, exact discretisation per step), subject to
``|delta_k| <= delta_max`` (the gimbal limit), ``|delta_k - delta_{k-1}| <= rate_max dt`` (the servo's
rate limit) and ``delta_k = 0`` before the controller starts. The servo's lag, the computational delay,
the sensors, the bending and the slosh are left out and the wind is known in advance, so the result is
optimistic: no causal controller of the rigid vehicle does better. Per plane (north, east): the vehicle
flies vertically, so each horizontal axis is a pitch plane of the axisymmetric vehicle; the total angle
of attack is at least each plane's, so the larger of the two planes' bounds is a lower bound on the total
q-alpha (each plane's gimbal limited to ``delta_max``, as it is at zero roll with the body axes on north
and east; at another roll a plane could have up to sqrt(2) times more, see ``delta_max``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import linalg, optimize

from lvgym.commandline import arg, parse

from lvgym.baselines.design.linearize import aero_slopes, analytic_rigid, operating_point

__all__ = ["rigid_models", "min_peak_qalpha"]


def rigid_models(times: Any, vehicle: str = "slender", protocol: str = "v1", **options: Any) -> dict[str, np.ndarray]:
    """The rigid pitch model at ``times`` [s] (flown with the gimbal centred, no wind): ``t`` (n,),
    ``A`` (n, 3, 3) [SI], ``B`` (n, 3) per rad of gimbal and ``E`` (n, 3) per rad of wind angle ``u_w / V``."""
    A, B, E = [], [], []
    for t in times:
        op = operating_point(vehicle, float(t), "rigid", protocol=protocol, **options)
        g = analytic_rigid(op)
        a = np.asarray(g.A, float)
        V = aero_slopes(op)[2]
        A.append(a)
        B.append(np.asarray(g.B, float)[:, 0])
        E.append(-V * a[:, 0])
    return {"t": np.asarray(times, float), "A": np.array(A), "B": np.array(B), "E": np.array(E)}


def _interp(models: dict[str, np.ndarray], key: str, t: float) -> np.ndarray:
    ts, arr = models["t"], models[key]
    flat = arr.reshape(len(ts), -1)
    return np.array([np.interp(t, ts, flat[:, j]) for j in range(flat.shape[1])]).reshape(arr.shape[1:])


def min_peak_qalpha(models: dict[str, np.ndarray], time_s: np.ndarray, qbar_pa: np.ndarray, airspeed_mps: np.ndarray,
                    wind_mps: np.ndarray, delta_max_rad: float, rate_max_radps: float, on_after_s: float = 2.0,
                    count_after_s: float | None = None) -> dict[str, Any]:
    """The smallest peak ``q |alpha|`` [Pa deg] over ``time_s`` [s] (equally spaced control steps) that a
    gimbal history within the limits achieves in the wind ``wind_mps`` [m/s] across the plane, with the
    vehicle starting on the reference (zero deviation) at ``time_s[0]``; ``qbar_pa`` [Pa] and
    ``airspeed_mps`` [m/s] per step (from a flight). The peak is counted from ``count_after_s`` [s] (default:
    ``on_after_s``, when the controller starts). Returns ``peak_pa_deg``, the gimbal history ``delta_rad``,
    ``alpha_rad`` and the peak of the gimbal at zero (``zero_peak_pa_deg``) on the same model."""
    t = np.asarray(time_s, float)
    n = len(t)
    dt = float(t[1] - t[0])
    theta_w = np.asarray(wind_mps, float) / np.asarray(airspeed_mps, float)
    q_deg = np.asarray(qbar_pa, float) * 180.0 / np.pi
    Gx = np.zeros((3, n))                           # sensitivity of the state to the gimbal history
    hx = np.zeros(3)                                # the state with the gimbal at zero
    G, h = np.zeros((n, n)), np.zeros(n)            # alpha_k = G[k] @ delta + h[k]
    for k in range(n):
        V = float(airspeed_mps[k])
        c = np.array([1.0 / V, 1.0, 0.0])
        G[k], h[k] = c @ Gx, c @ hx - theta_w[k]
        a, b, e = (_interp(models, key, t[k]) for key in ("A", "B", "E"))
        M = np.zeros((5, 5))
        M[:3, :3], M[:3, 3], M[:3, 4] = a * dt, b * dt, e * dt
        F = linalg.expm(M)
        Phi, Gam, Psi = F[:3, :3], F[:3, 3], F[:3, 4]
        Gx = Phi @ Gx
        Gx[:, k] += Gam
        hx = Phi @ hx + Psi * theta_w[k]
    count = t >= (on_after_s if count_after_s is None else count_after_s)
    rows = np.flatnonzero(count)
    # variables (delta_0 .. delta_{n-1}, s); minimise s with -s <= q_k alpha_k <= s
    qa = q_deg[rows, None] * G[rows]
    qh = q_deg[rows] * h[rows]
    ones = np.ones((len(rows), 1))
    A_ub = [np.hstack([qa, -ones]), np.hstack([-qa, -ones])]
    b_ub = [-qh, qh]
    D = np.zeros((n - 1, n + 1))
    D[np.arange(n - 1), np.arange(1, n)] = 1.0
    D[np.arange(n - 1), np.arange(n - 1)] = -1.0
    A_ub += [D, -D]
    b_ub += [np.full(n - 1, rate_max_radps * dt)] * 2
    bounds = [(0.0, 0.0) if tk < on_after_s else (-delta_max_rad, delta_max_rad) for tk in t] + [(0.0, None)]
    c_obj = np.zeros(n + 1)
    c_obj[-1] = 1.0
    res = optimize.linprog(c_obj, A_ub=np.vstack(A_ub), b_ub=np.concatenate(b_ub), bounds=bounds, method="highs")
    if res.status != 0:
        raise RuntimeError(f"linear programme: {res.message}")
    delta = res.x[:n]
    alpha = G @ delta + h
    return {"peak_pa_deg": float(res.x[-1]), "delta_rad": delta, "alpha_rad": alpha,
            "zero_peak_pa_deg": float(np.max(np.abs(q_deg[rows] * h[rows]))),
            "t_peak_s": float(t[rows][int(np.argmax(np.abs(q_deg[rows] * alpha[rows])))])}


#: the frozen times [s] of :func:`main`'s rigid models (the slender vehicle burns out just after 8.9 s)
SLENDER_TIMES = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 8.9)


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.load_relief.loadbound --help``)."""

    seeds: int = arg(10, lo=1, hi=10_000)
    """validation seeds 0 .. n-1"""
    gimbal_deg: float = arg(5.0, lo=0.0, lo_open=True, hi=90.0)
    """gimbal limit per plane [deg]"""


def main(argv: list[str] | None = None) -> int:
    """``python -m experiments.load_relief.loadbound --seeds 10``: the bound per plane on ``slender-v1``'s rigid
    validation seeds, in the wind of each seed's flight with the gimbal at zero (q-alpha limit lifted)."""
    import math

    from lvgym.benchmark.runner import ZERO
    from lvgym.benchmark.suites import get_suite

    from experiments.load_relief.qalpha_floor import fly

    a = parse(Args, argv, "python -m experiments.load_relief.loadbound", __doc__)
    models = rigid_models(SLENDER_TIMES)
    cond = get_suite("slender-v1").conditions[0].with_options(qalpha_limit_pa_deg=1e9)
    for seed in range(a.seeds):
        r = fly(ZERO, cond, seed)
        t = r["time"]
        sel = (t >= SLENDER_TIMES[0] - 1e-9) & (t <= SLENDER_TIMES[-1] + 1e-9)
        res = [min_peak_qalpha(models, t[sel], r["qbar"][sel], r["airspeed"][sel], r["wind_ne"][sel, j],
                               math.radians(a.gimbal_deg), math.radians(30.0)) for j in range(2)]
        print(f"seed {seed}: bound north {res[0]['peak_pa_deg'] / 1e3:5.1f}, east {res[1]['peak_pa_deg'] / 1e3:5.1f} "
              f"kPa deg; the model's gimbal at zero {res[0]['zero_peak_pa_deg'] / 1e3:5.1f}, "
              f"{res[1]['zero_peak_pa_deg'] / 1e3:5.1f}; flown at zero (total) {r['qalpha'][sel & (t >= 2.0)].max() / 1e3:5.1f}; "
              f"largest gimbal {max(np.abs(x['delta_rad']).max() for x in res) * 180 / math.pi:.2f} deg", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
