"""Verification cases of the dynamics core (thesis chapter 4; docs/verification.md).

Each ``case_*`` function runs one case and returns its ``Check`` rows; the tests assert them and
``python -m lvgym.verify`` prints them. Step sizes are arguments so that tests and the report use the
same code.
"""

from __future__ import annotations

import numpy as np
from scipy.special import ellipk

from ..dynamics import NonRigidModel, integrate
from .report import Check

G0 = 9.80665
#: rigid body of thesis 4.2: 21,100 kg, inertia of the 10 t tanks + structure + engine [kg m^2]
THESIS_MASS = 21_100.0
THESIS_INERTIA = (2101.0, 446_509.3249, 446_509.3249)
HUGE = 1e20  # "inertia made huge": a vehicle that the pendulum cannot move

#: Case E, the masses and inertias we chose (the thesis does not give them). Mode shapes of 0.32 and
#: 0.16 at the hinges, mass-normalised, belong to a vehicle of about 40 kg (a uniform free-free beam of
#: mass M has 2/sqrt(M) at its ends); the slosh masses take 10 % and 5 % of the unit modal mass.
CASE_E = {"m_b": 40.0, "J_b": (1.0, 200.0, 200.0), "m_slosh": (1.0, 2.0), "inertia_slosh": (0.0, 0.0)}


def _pitch(q: np.ndarray) -> np.ndarray:
    """Rotation angle about y_b of a pure-pitch quaternion (scalar first) [rad]."""
    return 2.0 * np.arctan2(q[..., 2], q[..., 0])


# --------------------------------------------------------------------------- R1, R2: rigid body
def case_r1(dt: float = 1e-2) -> list[Check]:
    """Rigid translation in vacuum under m * a along +x_b (thesis 4.2.1)."""
    model = NonRigidModel()
    p = model.params(m_b=THESIS_MASS, J_b=THESIS_INERTIA)
    x0 = model.layout.zeros_state()
    push = model.loads(f_b_i=(THESIS_MASS, 0.0, 0.0))
    out = []
    tr = integrate(model, x0, p, push, (0.0, 10.0), dt=dt)
    out += [Check("R1 constant", "x at 10 s", 50.0, tr.x[-1, 0], "m", 1e-3),
            Check("R1 constant", "v at 10 s", 10.0, tr.x[-1, 3], "m/s", 1e-3)]

    def profile(t: float) -> np.ndarray:
        a = 1.0 if t < 5.0 else (0.0 if t < 10.0 else -1.0)
        return model.loads(f_b_i=(a * THESIS_MASS, 0.0, 0.0))

    tr = integrate(model, x0, p, profile, (0.0, 15.0), dt=dt, t_events=(5.0, 10.0))
    for t, xe, ve in ((5.0, 12.5, 5.0), (10.0, 37.5, 5.0), (15.0, 50.0, 0.0)):
        k = int(np.argmin(np.abs(tr.t - t)))
        out += [Check("R1 profile", f"x at {t:g} s", xe, tr.x[k, 0], "m", 1e-3),
                Check("R1 profile", f"v at {t:g} s", ve, tr.x[k, 3], "m/s", 1e-3)]
    # the thesis's 25 mm: the same profile with steps that straddle the switches and no alignment
    tr = integrate(model, x0, p, profile, (0.0, 15.0), dt=0.037)
    out.append(Check("R1 profile", "x at 15 s, steps straddling the switches", 50.0, tr.x[-1, 0], "m",
                     note="no event alignment, steps of 36.9 ms straddle 5 s and 10 s: the kind of "
                          "error the thesis saw (25 mm)"))
    return out


def case_r2(dt: float = 1e-2) -> list[Check]:
    """Rigid rotation in vacuum under a +/-10 kN m pitch moment (thesis 4.2.2)."""
    model = NonRigidModel()
    p = model.params(m_b=THESIS_MASS, J_b=THESIS_INERTIA)

    def moment(t: float) -> np.ndarray:
        my = 1e4 if 5.0 <= t < 6.0 else (-1e4 if 6.0 <= t < 7.0 else 0.0)
        return model.loads(m_b_b=(0.0, my, 0.0))

    tr = integrate(model, model.layout.zeros_state(), p, moment, (0.0, 21.0), dt=dt,
                   t_events=(5.0, 6.0, 7.0))
    alpha = 1e4 / THESIS_INERTIA[1]
    out = []
    for t, w_e, th_e in ((6.0, alpha, 0.5 * alpha), (7.0, 0.0, alpha), (21.0, 0.0, alpha)):
        k = int(np.argmin(np.abs(tr.t - t)))
        out += [Check("R2", f"pitch rate at {t:g} s", w_e, tr.x[k, 11], "rad/s", 1e-6),
                Check("R2", f"pitch angle at {t:g} s", th_e, _pitch(tr.x[k, 6:10]), "rad", 1e-6)]
    return out


# --------------------------------------------------------------------------- pendulums
def _fixed_vehicle_pendulum(length: float, offset_rad: float, accel: tuple, g: tuple,
                            rate: tuple = (0.0, 0.0)):
    """A vehicle that nothing can move (huge mass and inertia) with one point-mass pendulum hinged
    at its CG, swung ``offset_rad`` about z_s; the support force makes ``accel`` its acceleration."""
    model = NonRigidModel(n_slosh=1)
    p = model.params(m_b=HUGE, J_b=(HUGE, HUGE, HUGE),
                     slosh=[{"m": 1.0, "length": length, "r_hinge": (0.0, 0.0, 0.0)}])
    x0 = model.layout.zeros_state()
    lay = model.layout
    x0[lay.state["q_si"]] = (np.cos(offset_rad / 2), 0.0, 0.0, np.sin(offset_rad / 2))
    x0[lay.state["omega_si_s"]] = rate
    support = HUGE * (np.asarray(accel) - np.asarray(g))
    u = model.loads(f_b_i=support, g_i=g)
    return model, x0, p, u


def _period(t: np.ndarray, y: np.ndarray) -> float:
    """Oscillation period from the linearly interpolated zero crossings of y."""
    i = np.nonzero(np.signbit(y[:-1]) != np.signbit(y[1:]))[0]
    tc = t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])
    return 2.0 * (tc[-1] - tc[0]) / (len(tc) - 1)


def exact_period(length: float, accel: float, amplitude_rad: float) -> float:
    """Period of a plane pendulum of any amplitude: 4 sqrt(L/a) K(sin(theta0 / 2))."""
    return 4.0 * np.sqrt(length / accel) * ellipk(np.sin(amplitude_rad / 2) ** 2)


def _swing(length, amplitude_rad, accel, g, dt, periods=4.0):
    model, x0, p, u = _fixed_vehicle_pendulum(length, amplitude_rad, accel, g)
    a = np.linalg.norm(np.asarray(accel) - np.asarray(g))
    tr = integrate(model, x0, p, u, (0.0, periods * 2 * np.pi * np.sqrt(length / a)), dt=dt)
    r, _ = model.slosh_kinematics(tr.x, p)
    rel = r[:, 0, :] - tr.x[:, 0:3]
    return model, x0, p, tr, rel


def case_s1(dt: float = 1e-3) -> list[Check]:
    """Slosh pendulum on a fixed vehicle under gravity along the rod (thesis 4.3)."""
    L, g = 2.0, (-G0, 0.0, 0.0)
    model, x0, p, _ = _fixed_vehicle_pendulum(L, np.radians(5), (0, 0, 0), g)
    r, _ = model.slosh_kinematics(x0, p)
    out = [Check("S1", "initial lateral offset", 2 * np.sin(np.radians(5)), abs(r[0, 1]), "m", 1e-6),
           Check("S1", "initial axial offset", 2 * np.cos(np.radians(5)), abs(r[0, 0]), "m", 1e-6)]
    small = 2 * np.pi * np.sqrt(L / G0)
    for amp_deg, expected, what in ((0.5, small, "period, 0.5 deg (2 pi sqrt(L/g))"),
                                    (5.0, exact_period(L, G0, np.radians(5)), "period, 5 deg (exact)"),
                                    (30.0, exact_period(L, G0, np.radians(30)),
                                     "period, 30 deg (exact)")):
        *_, tr, rel = _swing(L, np.radians(amp_deg), (0, 0, 0), g, dt)
        out.append(Check("S1", what, expected, _period(tr.t, rel[:, 1]), "s", 1e-3, relative=True))
    return out


def case_axial_pendulum(dt: float = 1e-3, accel: float = 20.0, length: float = 1.5) -> list[Check]:
    """No gravity; the vehicle accelerates along +x_b: the pendulum swings at sqrt(a / L)."""
    amp = np.radians(2.0)
    *_, tr, rel = _swing(length, amp, (accel, 0.0, 0.0), (0.0, 0.0, 0.0), dt)
    got = 2 * np.pi / _period(tr.t, rel[:, 1])
    return [Check("pendulum, thrust", f"frequency at a = {accel:g} m/s2, 2 deg",
                  2 * np.pi / exact_period(length, accel, amp), got, "rad/s", 1e-4, relative=True,
                  note=f"sqrt(a/L) = {np.sqrt(accel / length):.6f} rad/s at vanishing amplitude")]


def case_tumble(dt: float = 1e-2, rate: float = 0.7, duration: float = 20.0) -> list[Check]:
    """No gravity, no acceleration: the pendulum keeps its rate and tumbles through 90 degrees."""
    model, x0, p, u = _fixed_vehicle_pendulum(1.0, 0.0, (0, 0, 0), (0, 0, 0), rate=(rate, 0.0))
    tr = integrate(model, x0, p, u, (0.0, duration), dt=dt)
    lay = model.layout
    w_end = tr.x[-1, lay.state["omega_si_s"]]
    r, _ = model.slosh_kinematics(tr.x[-1], p)
    theta = rate * duration
    n_expected = np.array([np.cos(theta), 0.0, -np.sin(theta)])
    n_got = -(r[0] - tr.x[-1, 0:3]) / 1.0
    return [Check("pendulum, free fall", f"rate after {duration:g} s", rate, w_end[0], "rad/s", 1e-9),
            Check("pendulum, free fall", f"rod direction error after {theta:.1f} rad", 0.0,
                  float(np.linalg.norm(n_got - n_expected)), "", 1e-6)]


# --------------------------------------------------------------------------- E: energy
def case_e_model(m_slosh=None, zeta: float = 0.0):
    """Model, initial state, parameters and gravity of case E (thesis Table 4.5, our masses)."""
    ms = CASE_E["m_slosh"] if m_slosh is None else m_slosh
    model = NonRigidModel(n_slosh=2, n_modes=1)
    p = model.params(m_b=CASE_E["m_b"], J_b=CASE_E["J_b"], omega_modes=[15 * 2 * np.pi],
                     zeta_modes=[0.0],
                     slosh=[{"m": ms[0], "length": 1.09, "r_hinge": (3.0, 0.0, 0.0), "phi": [-0.32],
                             "inertia": CASE_E["inertia_slosh"][0], "zeta": zeta, "omega": 3.0},
                            {"m": ms[1], "length": 1.09, "r_hinge": (-3.0, 0.0, 0.0), "phi": [0.16],
                             "inertia": CASE_E["inertia_slosh"][1], "zeta": zeta, "omega": 3.0}])
    lay = model.layout
    x = lay.zeros_state()
    x[lay.state["r_zw_i"]] = (6_379_137.0, 0.0, 0.0)
    x[lay.state["v_zw_i"]] = (500.0, 0.0, 0.0)
    x[lay.state["eta"]] = (0.2, 0.5)
    x[lay.state["eta_dot"]] = (0.1, -0.25)
    c, s = np.cos(np.radians(2.5)), np.sin(np.radians(2.5))
    lay.view(x, "state", "q_si")[:] = ((c, 0.0, 0.0, s), (c, 0.0, 0.0, -s))
    return model, x, p, np.array([-9.81, 0.0, 0.0])


def energy_drift(dt: float, duration: float = 15.0, sample: float = 0.05, method: str = "rk4",
                 m_slosh=None) -> float:
    """Largest ``|E(t) - E(0)| / E_internal(0)`` of case E over ``duration`` seconds."""
    model, x, p, g = case_e_model(m_slosh)
    u = model.loads(g_i=g)
    e0 = model.energy(x, p, g)
    n = max(1, int(round(sample / dt)))
    worst = 0.0
    for _ in range(int(round(duration / (n * dt)))):
        x = model.step(x, p, u, dt, n, method=method)
        worst = max(worst, abs(model.energy(x, p, g)["total"] - e0["total"]))
    return worst / e0["internal"]


def case_e(dts=(4e-3, 2e-3, 1e-3, 5e-4)) -> list[Check]:
    """Energy conservation of the coupled system (thesis 4.4) and its order of convergence."""
    drifts = [energy_drift(dt) for dt in dts]
    out = []
    for dt, d in zip(dts, drifts):
        note = ""
        if dt == 1e-3:
            note = ("the reference target 1e-6 at 1 ms is not met: the 0.16 m hinge motion at 15 Hz "
                    "(145 g) makes the pendulums tumble chaotically; see docs/verification.md")
        out.append(Check("E", f"max energy drift / E_int, dt = {dt:g} s", 0.0, d, "", None, note=note))
    for a, b, dta in zip(drifts[:-1], drifts[1:], dts[:-1]):
        out.append(Check("E", f"order of convergence, {dta:g} -> {dta / 2:g} s", 4.0,
                         float(np.log2(a / b)), "", 0.5))
    out.append(Check("E", "max energy drift / E_int, dt = 1 ms, rk4-classic", 0.0,
                     energy_drift(1e-3, method="rk4-classic"), "", None))
    return out


def momentum_drift(dt: float, duration: float = 15.0) -> float:
    """Largest ``|P(t) - P(0)| / |P(0)|`` of case E in free space (no gravity), slosh damped."""
    model, x, p, _ = case_e_model(zeta=0.1)
    u = model.loads()
    p0 = model.momentum(x, p)
    worst = 0.0
    for _ in range(int(round(duration / 0.05))):
        x = model.step(x, p, u, dt, int(round(0.05 / dt)))
        worst = max(worst, float(np.linalg.norm(model.momentum(x, p) - p0)))
    return worst / float(np.linalg.norm(p0))


def case_momentum() -> list[Check]:
    """Free space: linear momentum with slosh (damped) and bending excited, case E's vehicle."""
    return [Check("momentum", "max |P - P0| / |P0| over 15 s, dt = 1 ms", 0.0, momentum_drift(1e-3),
                  "", None, note="case E's violent motion; 1e-9 is reached at 0.5 ms"),
            Check("momentum", "max |P - P0| / |P0| over 15 s, dt = 0.5 ms", 0.0,
                  momentum_drift(5e-4), "", 1e-9)]


def ascent_model():
    """Case E's vehicle at lift-off (thesis 4.5.1's second set): at rest, no bending, pendulums at
    5 degrees, thrust of 3 g along +x_b. The pendulums swing under thrust; nothing is chaotic.
    Positions are measured from the launch point (uniform gravity makes the origin free): at
    6,378 km from the Earth's centre the rounding of r alone (1e-9 m a step) would hide 1e-8 m."""
    model, x, p, g = case_e_model()
    lay = model.layout
    x[lay.state["r_zw_i"]] = 0.0
    x[lay.state["v_zw_i"]] = 0.0
    x[lay.state["eta"]] = 0.0
    x[lay.state["eta_dot"]] = 0.0
    total = CASE_E["m_b"] + sum(CASE_E["m_slosh"])
    return model, x, p, model.loads(thrust_b=(3 * G0 * total, 0.0, 0.0), g_i=g)


def case_rk4_vs_dop853(dt: float = 1e-3) -> list[Check]:
    """RK4 at a fixed step against DOP853 at tight tolerance."""
    out = []
    model, x, p, u = ascent_model()
    b = integrate(model, x, p, u, (0.0, 10.0), method="DOP853", rtol=1e-13, atol=1e-13, record_dt=0.5)
    diffs = []
    for h in (2 * dt, dt, dt / 2):
        a = integrate(model, x, p, u, (0.0, 10.0), dt=h, record_dt=0.5)
        diffs.append(float(np.max(np.linalg.norm(a.x[:, :3] - b.x[:, :3], axis=1))))
    out += [Check("RK4 vs DOP853", f"max CG position difference, ascent, 10 s, dt = {dt:g} s", 0.0,
                  diffs[1], "m", note="RK4 truncation error (it falls at fourth order)"),
            Check("RK4 vs DOP853", f"max CG position difference, ascent, 10 s, dt = {dt / 2:g} s",
                  0.0, diffs[2], "m", 1e-8),
            Check("RK4 vs DOP853", "order of convergence to DOP853, ascent", 4.0,
                  float(np.log2(diffs[1] / diffs[2])), "", 0.5)]
    model, x, p, g = case_e_model()
    u = model.loads(g_i=g)
    a = integrate(model, x, p, u, (0.0, 15.0), dt=dt, record_dt=0.5)
    b = integrate(model, x, p, u, (0.0, 15.0), method="DOP853", rtol=1e-12, atol=1e-12, record_dt=0.5)
    d = np.linalg.norm(a.x[:, :3] - b.x[:, :3], axis=1)
    k1 = int(np.argmin(np.abs(a.t - 1.0)))
    out += [Check("RK4 vs DOP853", "CG position difference, case E, 1 s", 0.0, float(d[k1]), "m",
                  note="case E is chaotic (tumbling pendulums): the two solutions part exponentially"),
            Check("RK4 vs DOP853", "max CG position difference, case E, 15 s", 0.0, float(d.max()), "m")]
    return out


def _case_m():
    from .mass_cases import case_m

    return case_m()


_case_m.__name__ = "case_m"


def _case_environment():
    from .environment_cases import case_environment

    return case_environment()


_case_environment.__name__ = "case_environment"

ALL_CASES = (case_r1, case_r2, case_s1, case_axial_pendulum, case_tumble, case_e, case_momentum,
             case_rk4_vs_dop853, _case_m, _case_environment)
