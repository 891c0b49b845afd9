"""Design of ``gs-pid-flex``: a gain-scheduled PID with structural filters, designed on the non-rigid
linear model of protocol v1's flight loop, at frozen flight times (docs/flex-design.md).

``python -m baselines.flexdesign --vehicle smile`` writes ``results/schedules/smile_flex.yaml`` (the
schedule, its margins and its frozen-time checks) and ``smile_flex_margins.md`` (the margin table); the
shipped schedule (``baselines/schedules/smile_flex.yaml``, the one ``gs-pid-flex`` flies) is replaced
only with ``--overwrite``.

At every schedule row the plant is :func:`.flightloop.flight_plant`: the commanded gimbal to the sampled
gyro at the control period, with the servo, the bending slope at the IMU, the gyro's filters, the hold
and the one-period computational delay, rigid and non-rigid. The controller is
``C(z) = PID(z) F(z)``: the backward-Euler PID of :mod:`.pid` (unfiltered derivative) times the
:class:`.filters.StructuralFilter` chain (lead-lag, low-pass, a notch on the first bending mode when it
lies below the Nyquist frequency). Each row flies its own stretch of the flight, from the midpoint to the
row before to the midpoint to the row after (the policy takes the nearest row on mass). Its nine
parameters minimise the energy of the rate's response to a disturbance at the plant input,
``sum |G / (1 + C G)|^2 dw`` over the frequency grid (the mean of the rigid and the non-rigid plant at
the row's time), under the constraints of :class:`Requirements` on the plants at the row's time and at
both ends of its stretch (penalties), by Nelder-Mead from the previous row's design and from seeded
random starts. Every row is then checked exactly with :func:`.linearize.margins` on the
python-control loops, in pitch and yaw, on all those plants.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass
from typing import Any, Callable

import control
import numpy as np
from scipy import optimize, signal

from .filters import StructuralFilter
from .flextable import margin_table, row_line
from .flightloop import flight_plant, frequency_response, mode_frequencies
from .linearize import margins, operating_point, pid_tf
from .noise import command_noise, gyro_noise, noise_fraction_on_grid

#: the flight times of the schedule per vehicle [s]: SMILE v1 boost (burnout 43 s) and upper stage
#: (ignition 54 s, mission 70 s); Stratos III (30 s); the slender vehicle (10 s)
FLEX_TIMES = {"smile": (3.0, 10.0, 15.0, 20.0, 24.4, 28.8, 32.4, 36.0, 42.5, 54.1, 62.0, 69.5),
              "stratos3": (2.0, 6.0, 10.0, 14.0, 18.0, 24.0, 29.0),
              "slender": (1.0, 3.0, 5.0, 7.0, 9.0)}


@dataclass(frozen=True)
class Requirements:
    """The margins each row must meet (docs/flex-design.md gives where each convention comes from).

    ``rigid_gm_db``, ``rigid_pm_deg``: rigid-body gain margin (up, and down where the loop is
    conditionally stable) and phase margin; ``flex_gm_db``, ``flex_pm_deg``: the same on the non-rigid
    loop, the stated margin of the phase-stabilised slosh and first bending modes; ``attenuation_db``:
    the modes' part of the loop, ``C (G_nonrigid - G_rigid)``, at the higher bending modes (and at the
    first where it is gain-stabilised) peaks at least this far below 0 dB over +-15 % of the frequency
    at which the sampler sees the mode (3 sigma of the suites' 5 % frequency dispersion);
    ``drift_per_s``: the slowest closed-loop divergence allowed [1/s] (a rate loop leaves the attitude
    drift of the translational mode, a doubling time of 35 s at 0.02);
    ``bending1``: how the first bending mode must be stabilised, ``"gain"`` (the default: v1's suites
    disperse the servo delay by 0 or 10 ms, 41 deg of phase at 71 rad/s, and the bending frequency by
    5 %, so the mode's phase is not known well enough to phase-stabilise it) or ``"phase"`` (inside
    the loop, held by the non-rigid margins, as Ares I's first stage did);
    ``noise_fraction``: the largest RMS of the gimbal command's response to the flight gyro's white
    noise, as a fraction of the gimbal limit (:mod:`.noise`; rigid and non-rigid loops), so that the
    actuator's travel and rate are not spent on sensor noise."""

    rigid_gm_db: float = 6.0
    rigid_pm_deg: float = 30.0
    flex_gm_db: float = 6.0
    flex_pm_deg: float = 30.0
    attenuation_db: float = 6.0
    drift_per_s: float = 0.02
    bending1: str = "gain"
    noise_fraction: float = 0.02

    def __post_init__(self) -> None:
        for k, v in asdict(self).items():
            if k == "bending1":
                if v not in ("gain", "phase"):
                    raise ValueError(f"bending1 = {v!r}: 'gain' or 'phase'")
            elif not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0.0):
                raise ValueError(f"{k} = {v!r}: a finite number >= 0")


#: the parameter vector of the optimiser: (name, lower, upper, log-scaled)
PARAMETERS = (("kp", 1e-4, 10.0, True), ("ki", 1e-4, 10.0, True), ("kd", 1e-5, 1.0, True),
              ("lead_zero_radps", 0.5, 100.0, True), ("lead_ratio", 1.0, 1000.0, True),
              ("lowpass_radps", 20.0, 155.0, True), ("lowpass_damping", 0.2, 1.0, False),
              ("notch_damping", 0.02, 1.0, True), ("notch_depth", 0.02, 1.0, True))


def _from_unit(u: np.ndarray) -> dict[str, float]:
    """Parameters from the optimiser's unbounded vector (a logistic map into each range)."""
    out = {}
    for (name, lo, hi, log), x in zip(PARAMETERS, u):
        s = 1.0 / (1.0 + math.exp(-float(np.clip(x, -40, 40))))
        out[name] = math.exp(math.log(lo) + s * (math.log(hi) - math.log(lo))) if log else lo + s * (hi - lo)
    return out


def _to_unit(values: dict[str, float]) -> np.ndarray:
    u = []
    for name, lo, hi, log in PARAMETERS:
        v = min(max(values[name], lo * (1 + 1e-9)), hi * (1 - 1e-9))
        s = (math.log(v) - math.log(lo)) / (math.log(hi) - math.log(lo)) if log else (v - lo) / (hi - lo)
        u.append(math.log(s / (1.0 - s)))
    return np.array(u)


def controller(values: dict[str, float], notch_radps: float | None) -> tuple[tuple[float, float, float], StructuralFilter]:
    """PID gains (kp, ki, kd) and the filter of a parameter set; ``notch_radps`` None: notch off."""
    filt = StructuralFilter(lead_zero_radps=values["lead_zero_radps"],
                            lead_pole_radps=values["lead_zero_radps"] * values["lead_ratio"],
                            lowpass_radps=values["lowpass_radps"], lowpass_damping=values["lowpass_damping"],
                            notch_radps=notch_radps or 100.0, notch_damping=values["notch_damping"],
                            notch_depth=values["notch_depth"] if notch_radps else 1.0)
    return (values["kp"], values["ki"], values["kd"]), filt


def controller_tf(gains: tuple[float, float, float], filt: StructuralFilter, dt: float) -> control.TransferFunction:
    """``C(z)``: the discrete PID (unfiltered derivative) times the structural filter, at ``dt`` [s]."""
    return pid_tf(gains[0], gains[1], gains[2], None, dt) * filt.tf(dt)


def _controller_poly(gains, filt: StructuralFilter, dt: float) -> tuple[np.ndarray, np.ndarray]:
    kp, ki, kd = gains                             # the PID of pid_tf over z (z - 1)
    b = kp * np.array([1.0, -1.0, 0.0]) + ki * dt * np.array([1.0, 0.0, 0.0]) + kd / dt * np.array([1.0, -2.0, 1.0])
    a = np.array([1.0, -1.0, 0.0])
    for bb, aa in filt.discrete(dt):
        b, a = np.polymul(b, bb), np.polymul(a, aa)
    return b, a


def folded(w: float, dt: float) -> float:
    """The frequency [rad/s] at which a sampler at ``dt`` [s] sees a signal of ``w`` (aliasing)."""
    ws = 2.0 * math.pi / dt
    return abs(((w + 0.5 * ws) % ws) - 0.5 * ws)


def notch_frequency(modes: dict[str, list[float]], dt: float) -> float | None:
    """The notch's frequency [rad/s]: the first bending mode's, if below 0.9 times the Nyquist
    frequency of ``dt`` [s]; else None (notch off)."""
    bending = modes.get("bending", [])
    return bending[0] if bending and bending[0] < 0.9 * math.pi / dt else None


class RowProblem:
    """The design problem of one row: the discrete plants of the row's own flight time and of the ends
    of the stretch it flies (``cases``: the first is the row's own, whose disturbance response is the
    objective; the requirements hold on all), their responses on a frequency grid, and the bands the
    mode constraints look at; ``noise``: the gyro's noise per sample [rad/s] and the gimbal limit [rad]
    (:func:`.noise.gyro_noise`; a zero noise leaves the noise requirement out)."""

    def __init__(self, cases: list[tuple[dict[str, control.StateSpace], dict[str, list[float]]]], req: Requirements,
                 n_grid: int = 3000, slack: tuple[float, float] = (0.5, 2.0),
                 noise: tuple[float, float] = (0.0, 1.0)) -> None:
        self.req = req
        self.noise = (float(noise[0]), float(noise[1]))
        self.slack_db, self.slack_deg = slack           # designed beyond the requirements by this much (the
        #                                               # grid's margins are a little optimistic)
        self.dt = float(cases[0][0]["rigid"].dt)
        nyq = math.pi / self.dt
        dense = [np.linspace(0.9 * f, min(1.1 * f, 0.999 * nyq), 300) for _, modes in cases
                 for f in (folded(m, self.dt) for kind in ("slosh", "bending") for m in modes.get(kind, []))]
        self.w = np.unique(np.concatenate([np.geomspace(1e-3, 0.999 * nyq, n_grid)] + dense))
        self.dw = np.gradient(self.w)                   # a log grid, and dense around every mode
        self.z = np.exp(1j * self.w * self.dt)
        self.notch_radps = notch_frequency(cases[0][1], self.dt)
        self.cases = []
        for plants, modes in cases:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                G = {k: frequency_response(g, self.w) for k, g in plants.items()}
            band = np.zeros_like(self.w, bool)
            b = modes.get("bending", [])
            for wb in (b if req.bending1 == "gain" else b[1:]):
                f = folded(wb, self.dt)
                band |= (self.w > 0.85 * f) & (self.w < 1.15 * f)
            mats = {k: (np.asarray(g.A), np.asarray(g.B), np.asarray(g.C)) for k, g in plants.items()}
            self.cases.append((G, band, mats))

    def growth(self, b: np.ndarray, a: np.ndarray, model: str, case: int = 0) -> float:
        """The fastest closed-loop growth rate [1/s] (the integrator's pole at z = 1 cancelling the plant's
        zero at z = 1 left out, as :func:`.linearize.margins` does)."""
        A, B, C = self.cases[case][2][model]
        Ac, Bc, Cc, Dc = signal.tf2ss(b, a)
        M = np.block([[A - B @ Dc @ C, B @ Cc], [-Bc @ C, Ac]])
        ev = np.linalg.eigvals(M)
        ev = ev[np.abs(ev - 1.0) > 1e-6]
        return float(np.max(np.log(np.maximum(np.abs(ev), 1e-300)) / self.dt))

    @staticmethod
    def grid_margins(L: np.ndarray) -> tuple[float, float, float]:
        """(gain margin up [dB], gain margin down [dB] (-inf: none), smallest |phase margin| [deg]) of an
        open-loop response on the grid."""
        mag, ph = np.abs(L), np.unwrap(np.angle(L))
        r = (ph + math.pi) / (2 * math.pi)               # phase crossings of -180 deg (mod 360)
        k = np.floor(r)
        i = np.where(np.diff(k) != 0)[0]
        edge = np.maximum(k[i], k[i + 1])
        f = np.clip((edge - r[i]) / (r[i + 1] - r[i]), 0.0, 1.0)
        m = np.exp(np.log(mag[i]) + f * (np.log(mag[i + 1]) - np.log(mag[i])))   # |L| there, interpolated
        up = -20 * np.log10(m[m < 1]) if np.any(m < 1) else np.array([99.0])
        down = -20 * np.log10(m[m > 1]) if np.any(m > 1) else np.array([-99.0])
        lm = np.log(mag)                                 # gain crossings, the phase interpolated
        j = np.where(np.diff(np.sign(lm)) != 0)[0]
        f = lm[j] / (lm[j] - lm[j + 1])
        pm = (np.degrees(ph[j] + f * (ph[j + 1] - ph[j])) + 180.0) % 360.0
        pm = np.where(pm > 180.0, pm - 360.0, pm)
        return float(up.min()), float(down.max()), float(np.abs(pm).min()) if pm.size else 99.0

    def evaluate(self, values: dict[str, float]) -> dict[str, Any]:
        """Worst margins over the cases per model (gain up, gain down, phase, growth), the modes' part of
        the loop at its peak over the gain-stabilised bands [dB], the command's noise as a fraction of the
        gimbal limit (``noise``, the largest over the cases and models), and the objective ``J``."""
        gains, filt = controller(values, self.notch_radps)
        b, a = _controller_poly(gains, filt, self.dt)
        C = np.polyval(b, self.z) / np.polyval(a, self.z)
        out: dict[str, Any] = {"values": values, "higher_db": -99.0, "noise": 0.0}
        for i, (G, band, _) in enumerate(self.cases):
            for model, g in G.items():
                L = C * g
                if self.noise[0] > 0.0:
                    out["noise"] = max(out["noise"], noise_fraction_on_grid(C, g, self.w, self.dt, *self.noise))
                m = self.grid_margins(L) + (self.growth(b, a, model, i),)
                w = out.get(model)
                out[model] = m if w is None else (min(w[0], m[0]), max(w[1], m[1]), min(w[2], m[2]), max(w[3], m[3]))
                if i == 0:
                    out["J"] = out.get("J", 0.0) + float(np.sum(np.abs(g / (1.0 + L)) ** 2 * self.dw)) / len(G)
            if band.any():                         # the modes' own part of the loop, C (G_nonrigid - G_rigid)
                modal = C[band] * (G["nonrigid"][band] - G["rigid"][band])
                out["higher_db"] = max(out["higher_db"], float(20 * np.log10(np.abs(modal).max())))
        return out

    def violations(self, e: dict[str, Any]) -> list[float]:
        r, sdb, sdeg = self.req, self.slack_db, self.slack_deg
        v = []
        for model, gm, pm in (("rigid", r.rigid_gm_db + sdb, r.rigid_pm_deg + sdeg),
                              ("nonrigid", r.flex_gm_db + sdb, r.flex_pm_deg + sdeg)):
            up, down, phase, growth = e[model]
            v += [max(0.0, gm - up), max(0.0, gm + down) if down > -99 else 0.0, max(0.0, pm - phase) / 5.0,
                  100.0 * max(0.0, growth - 0.8 * r.drift_per_s)]
        v.append(max(0.0, e["higher_db"] + r.attenuation_db + sdb))
        if self.noise[0] > 0.0:                        # relative, designed 10 % below the requirement
            v.append(5.0 * max(0.0, e["noise"] / max(r.noise_fraction, 1e-12) - 0.9))
        return v

    def cost(self, u: np.ndarray) -> float:
        try:
            e = self.evaluate(_from_unit(u))
        except (ValueError, np.linalg.LinAlgError):
            return 1e9
        return 10.0 * sum(x * x for x in self.violations(e)) + math.log(e["J"])


#: a start of the optimiser when there is no previous row: a slow PI with every filter near off
START = {"kp": 0.05, "ki": 0.2, "kd": 0.005, "lead_zero_radps": 5.0, "lead_ratio": 3.0, "lowpass_radps": 100.0,
         "lowpass_damping": 0.7, "notch_damping": 0.3, "notch_depth": 0.3}


def design_row(problem: RowProblem, warm: dict[str, float] | None, rng: np.random.Generator, starts: int = 3,
               maxiter: int = 3000) -> dict[str, Any]:
    """The best parameter set of ``problem`` from ``warm`` (or :data:`START`) and ``starts`` random starts."""
    seeds = [_to_unit(warm or START)] + [rng.normal(0.0, 1.5, len(PARAMETERS)) for _ in range(starts)]
    best = None
    for u0 in seeds:
        res = optimize.minimize(problem.cost, u0, method="Nelder-Mead",
                                options={"maxiter": maxiter, "xatol": 1e-4, "fatol": 1e-7, "adaptive": True})
        if best is None or res.fun < best.fun:
            best = res
    e = problem.evaluate(_from_unit(best.x))
    e["feasible"] = max(problem.violations(e)) < 1e-6
    return e


def row_plants(vehicle: str, t: float, policy: Callable | None) -> tuple[dict, dict, dict]:
    """Pitch and yaw ``flight_plant`` of the rigid and non-rigid v1 vehicle at ``t`` [s], flown there
    with ``policy`` (None: the zero action), the non-rigid modes, and the thrust [N], the mass [kg] and
    the gyro's noise with the gimbal limit (:func:`.noise.gyro_noise`) there."""
    plants: dict[str, dict[str, control.StateSpace]] = {"pitch": {}, "yaw": {}}
    thrust = None
    for model in ("rigid", "nonrigid"):
        op = operating_point(vehicle, t, model, protocol="v1", policy=policy)
        thrust = float(op.sim.conditions("thrust")[0])
        for plane in plants:
            plants[plane][model] = flight_plant(op, plane)
        if model == "nonrigid":
            modes = mode_frequencies(op)
            mass = float(op.sim.timeline.interp("mass", [op.t])[0])
            noise = gyro_noise(op)
    return plants, modes, {"thrust_n": thrust, "mass_kg": mass, "noise": noise}


def check_loops(plants: dict[str, dict[str, control.StateSpace]], gains, filt: StructuralFilter,
                modes: dict[str, list[float]], req: Requirements,
                noise: tuple[float, float] | None = None) -> dict[str, Any]:
    """Exact margins (:func:`.linearize.margins`) of ``C(z) G(z)`` for every plane and model; for each
    slosh and bending mode the peak of the modes' part of the pitch loop, ``C (G_nonrigid - G_rigid)``,
    near the frequency at which the sampler sees it (+-3 % for slosh, +-15 % for bending), and so how
    it is stabilised ('gain': at least ``req.attenuation_db`` below 0 dB; 'phase': held by the
    non-rigid margins); with ``noise`` (the gyro's noise per sample [rad/s], the gimbal limit [rad]) the
    command's noise as a fraction of the limit per loop (``noise_fraction``, :func:`.noise.command_noise`);
    and whether the row meets ``req``."""
    dt = float(plants["pitch"]["rigid"].dt)
    C = control.ss(controller_tf(gains, filt, dt))
    out: dict[str, Any] = {}
    ok = True
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for plane, pl in plants.items():
            for model, g in pl.items():
                m = margins(control.series(g, C))
                gm, pm = (req.rigid_gm_db, req.rigid_pm_deg) if model == "rigid" else (req.flex_gm_db, req.flex_pm_deg)
                m["meets"] = bool(m["max_pole_real_per_s"] < req.drift_per_s and m["gain_margin_db"] >= gm - 0.05
                                  and m["gain_reduction_margin_db"] <= -gm + 0.05 and abs(m["phase_margin_deg"]) >= pm - 0.5)
                if noise is not None and noise[0] > 0.0:
                    m["noise_fraction"] = command_noise(C, g, *noise)
                    m["meets"] = bool(m["meets"] and m["noise_fraction"] <= req.noise_fraction * 1.005)
                ok &= m["meets"]
                out[f"{model}_{plane}"] = m
        modal = control.series(plants["pitch"]["nonrigid"] - plants["pitch"]["rigid"], C)   # the modes' part
        mode_gain = []
        for kind in ("slosh", "bending"):
            for i, wm in enumerate(modes.get(kind, [])):
                f = folded(wm, dt)
                band = np.linspace(0.85 * f, 1.15 * f, 301) if kind == "bending" else np.linspace(0.97 * f, 1.03 * f, 61)
                db = float(20 * np.log10(np.abs(frequency_response(modal, band)).max()))
                gain_stab = db <= -req.attenuation_db
                if kind == "bending" and (i > 0 or req.bending1 == "gain") and not gain_stab:
                    ok = False                               # must be gain-stabilised
                mode_gain.append({"mode": kind, "radps": round(wm, 2), "seen_at_radps": round(f, 2),
                                  "loop_gain_db": round(db, 2),
                                  "stabilised": "gain" if gain_stab else "phase"})
    out["modes"] = mode_gain
    out["meets"] = bool(ok)
    return out


def _rounded(m: dict) -> dict:
    return {k: (round(v, 5 if k.startswith(("max_pole", "noise")) else 2) if isinstance(v, float) else v)
            for k, v in m.items()}


def schedule_policy(rows: list[dict[str, Any]]) -> Callable:
    """A factory ``env -> policy`` of the schedule made of ``rows`` so far (to fly to the next row)."""
    from .pid import GainSchedule, GainScheduledPIDPolicy

    sched = GainSchedule.from_dict({"variable": "mass", "interpolation": "nearest", "rows": [dict(r) for r in rows]})
    return lambda env: GainScheduledPIDPolicy(sched, env=env, name="gs-pid-flex")


def _checked(case: tuple, t: float, gains, filt: StructuralFilter, req: Requirements) -> dict[str, Any]:
    plants, modes, info = case
    chk = check_loops(plants, gains, filt, modes, req, info.get("noise"))
    return {"time_s": float(t), "mass_kg": round(info["mass_kg"], 2), "meets": chk["meets"],
            "margins": {k: _rounded(v) for k, v in chk.items() if k not in ("modes", "meets")}, "modes": chk["modes"]}


def relieved(gains: tuple[float, float, float], relief: tuple[float, float] | None) -> tuple[float, float, float]:
    """The gains of a load-relief row: ``relief = (ki_scale, accel_gain)`` scales the integral (the
    attitude hold that fights the weathercocking; :mod:`.pid`, "Load relief"); None: unchanged."""
    return gains if relief is None else (gains[0], gains[1] * relief[0], gains[2])


def design_schedule(vehicle: str = "smile", times=None, req: Requirements | None = None, starts: int = 2,
                    seed: int = 0, log=print, relief: tuple[float, float] | None = None,
                    planes: tuple[str, ...] = ("pitch",)) -> dict[str, Any]:
    """Design every row of ``vehicle``'s schedule in time order. Each row flies the stretch between the
    midpoints to its neighbours in the same burn (the policy switches rows at the mass midpoints,
    ``interpolation: nearest``), and is designed to meet the requirements at its own time and at both
    ends of its stretch; the end's plants are flown to with the rows before it (the right end: with
    a first design of the row from its time and left end, which the final design then starts from).
    ``relief = (ki_scale, accel_gain)``: every row, once designed, flies with its integral gain scaled
    and the load-relief gain ``accel_gain`` [rad/s per m/s^2] (the later rows are flown to so), and is
    checked so (the rate loop's margins; the accelerometer path is not in the linear plant). ``planes``:
    the planes whose loops the optimiser holds to the requirements (the pitch loop's disturbance response
    is the objective; every row is checked in both planes whatever it is). Returns the schedule document."""
    if not planes or any(p not in ("pitch", "yaw") for p in planes) or planes[0] != "pitch":
        raise ValueError(f"planes = {planes!r}: ('pitch',) or ('pitch', 'yaw')")
    req = req or Requirements()
    times = tuple(sorted(FLEX_TIMES[vehicle] if times is None else times))
    rng = np.random.default_rng(seed)
    rows: list[dict[str, Any]] = []
    skipped: list[dict[str, Any]] = []
    warm, left = None, None
    for k, t in enumerate(times):
        own = row_plants(vehicle, t, schedule_policy(rows) if rows else None)
        if own[2]["thrust_n"] <= 0.0:
            log(f"t = {t:g} s: no thrust (coast), skipped")
            skipped.append({"time_s": float(t), "reason": "coast"})
            warm, left = None, None
            continue
        notch = notch_frequency(own[1], float(own[0]["pitch"]["rigid"].dt))
        cases = [(t, own)] + ([left] if left is not None else [])
        noise = own[2]["noise"]
        e = design_row(RowProblem([(c[0][p], c[1]) for _, c in cases for p in planes], req, noise=noise), warm, rng,
                       starts)
        right = None
        if k + 1 < len(times):
            t_r = 0.5 * (t + times[k + 1])
            gains, filt = controller(e["values"], notch)
            gains = relieved(gains, relief)
            first = rows + [{"time_s": t, "mass_kg": own[2]["mass_kg"], "kp": gains[0], "ki": gains[1], "kd": gains[2],
                             "filter": filt.as_dict(), **({} if relief is None else {"accel_gain": relief[1]})}]
            try:
                case = row_plants(vehicle, t_r, schedule_policy(first))
                right = (t_r, case) if case[2]["thrust_n"] > 0.0 else None
            except RuntimeError as exc:                  # the flight ended before the stretch's end
                log(f"t = {t_r:g} s: not reached ({exc}); the row is designed without its right end")
        if right is not None:
            cases.append(right)
            e = design_row(RowProblem([(c[0][p], c[1]) for _, c in cases for p in planes], req, noise=noise),
                           e["values"], rng, starts=0)
        warm = e["values"]
        gains, filt = controller(e["values"], notch)
        gains = relieved(gains, relief)
        checks = [_checked(c, tc, gains, filt, req) for tc, c in cases]
        row = {"time_s": float(t), "mass_kg": round(own[2]["mass_kg"], 2), "kp": float(gains[0]),
               "ki": float(gains[1]), "kd": float(gains[2]), "filter": filt.as_dict(),
               **({} if relief is None else {"accel_gain": float(relief[1])}),
               "meets": all(c["meets"] for c in checks), "objective": round(float(e["J"]), 4),
               "stretch_s": [round(min(tc for tc, _ in cases), 3), round(max(tc for tc, _ in cases), 3)],
               "margins": checks[0]["margins"], "modes": checks[0]["modes"], "ends": checks[1:]}
        rows.append(row)
        log(row_line(row) + "".join(f"\n    end {row_line(c)}" for c in checks[1:]))
        left = right
    return {"vehicle": vehicle, "protocol": "v1",
            "source": "python -m baselines.flexdesign (non-rigid v1 flight loop, discrete)",
            "variable": "mass", "interpolation": "nearest", "requirements": asdict(req),
            "design": {"starts": starts, "seed": seed, "planes": list(planes), **({} if relief is None else
                                                          {"ki_scale": relief[0], "accel_gain": relief[1]})},
            "rows": rows, "skipped": skipped}


def main(argv: list[str] | None = None) -> int:
    import argparse
    import sys

    import yaml

    from lvgym.benchmark.results import atomic_write_text
    from lvgym.cli import fail, one_line_errors, option_number
    from lvgym.errors import ConfigError

    from .tune import SCHEDULES, output_path

    ap = one_line_errors(argparse.ArgumentParser(prog="python -m baselines.flexdesign",
                                                 description=__doc__.split("\n\n")[0]))
    ap.add_argument("--vehicle", default="smile", choices=sorted(FLEX_TIMES))
    ap.add_argument("--out", default=None, help="YAML file (default results/schedules/<vehicle>_flex.yaml; with "
                    "--overwrite: the shipped baselines/schedules/<vehicle>_flex.yaml)")
    ap.add_argument("--overwrite", action="store_true", help="allow replacing a shipped schedule (gs-pid-flex reads it)")
    ap.add_argument("--times", type=float, nargs="*", default=None, help="flight times of the rows [s]")
    ap.add_argument("--starts", type=int, default=2, help="random starts of the optimiser per row (besides the warm one)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the random starts")
    ap.add_argument("--load-relief", type=float, nargs=2, default=None, metavar=("KI_SCALE", "ACCEL_GAIN"),
                    help="load relief: scale every row's integral gain by KI_SCALE and add ACCEL_GAIN [rad/s per m/s^2]")
    ap.add_argument("--planes", nargs="+", choices=("pitch", "yaw"), default=["pitch"],
                    help="planes the optimiser holds to the requirements: pitch (default) or pitch yaw")
    a = ap.parse_args(argv)
    try:
        out = output_path(a.vehicle, a.out, a.overwrite, stem=f"{a.vehicle}_flex")
        option_number("--starts", a.starts, 0, 100)
        for t in a.times or ():
            option_number("--times", t, 0.0, 3600.0, lo_open=True)
        if a.load_relief is not None:
            option_number("--load-relief KI_SCALE", a.load_relief[0], 0.0, 1.0)
            option_number("--load-relief ACCEL_GAIN", a.load_relief[1], 0.0, 1.0)
    except ConfigError as exc:
        fail(ap.prog, exc)
    doc = design_schedule(a.vehicle, a.times, starts=a.starts, seed=a.seed,
                          relief=None if a.load_relief is None else tuple(a.load_relief), planes=tuple(dict.fromkeys(
                              ["pitch", *a.planes])))
    if not doc["rows"]:
        print(f"no flight time of {a.vehicle} could be designed; nothing written", file=sys.stderr)
        return 1
    shipped = out.parent.resolve() == SCHEDULES.resolve()
    again = (f"python -m baselines.flexdesign --vehicle {a.vehicle} --starts {a.starts}"
             + ("" if a.load_relief is None else " --load-relief {:g} {:g}".format(*a.load_relief))
             + ("" if not a.times else " --times " + " ".join(f"{t:g}" for t in a.times))
             + ("" if a.planes == ["pitch"] else " --planes " + " ".join(dict.fromkeys(["pitch", *a.planes])))
             + (" --overwrite" if shipped else f" --out {out}"))
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, f"# gs-pid-flex schedule of {a.vehicle}, regenerated by: {again}\n"
                      "# Gains: rad of gimbal per rad/s of filtered rate error (kp), per rad (ki), per rad/s^2 (kd); "
                      "filter frequencies [rad/s].\n"
                      + yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120))
    table = out.with_name(out.stem + "_margins.md")
    atomic_write_text(table, margin_table(doc))
    bad = [r["time_s"] for r in doc["rows"] if not r["meets"]]
    print(f"wrote {out} and {table}" + (f"; requirements NOT met at t = {bad} s" if bad else "; every row meets the requirements"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
