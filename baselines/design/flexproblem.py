"""The design problem of one ``gs-pid-flex`` schedule row (:mod:`.flexdesign` designs the schedule row by
row; docs/flex-design.md, "The design method").

:class:`Requirements` are the margins a row must meet. :class:`RowProblem` holds the discrete plants of the
row's own time and of the ends of its stretch on a frequency grid, reads the loop's margins there and
turns the requirements into quadratic penalties on top of the objective, the energy of the rate's response
to a disturbance at the plant input. :func:`design_row` minimises it by Nelder-Mead over the nine
parameters of :data:`PARAMETERS` (or those not held fixed).

Two things a load-relief row needs (``python -m lvgym.baselines.design.flexdesign --load-relief``):

- ``fixed``: parameters held at a value and not optimised (the relieved row's integral gain);
- ``drift="vehicle"``: the loop's slowest divergence may be as fast as the vehicle's own open-loop one at
  each plant, but no faster, in place of the ``drift_per_s`` requirement. A load-relief loop gives the
  attitude hold up, so it leaves the vehicle's drift (docs/flex-design.md, "The slender vehicle"); a design
  held to ``drift_per_s`` spends its gain margin on an integral the relief then removes.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass
from typing import Any

import control
import numpy as np
from scipy import optimize, signal

from ..filters import Filter, StructuralFilter
from .flightloop import frequency_response
from .linearize import pid_tf
from .noise import noise_rate_on_grid

__all__ = ["Requirements", "PARAMETERS", "DRIFT_MODES", "START", "RowProblem", "controller", "controller_tf",
           "design_row", "folded", "notch_frequency", "open_loop_growth"]


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
    ``noise_rate_fraction``: None (the default: not required, only reported), or the largest RMS of the
    gimbal rate the flight gyro's white noise may command, as a fraction of the servo's rate limit
    (:mod:`.noise`; rigid and non-rigid loops; docs/flex-design.md, "Sensor noise in the command")."""

    rigid_gm_db: float = 6.0
    rigid_pm_deg: float = 30.0
    flex_gm_db: float = 6.0
    flex_pm_deg: float = 30.0
    attenuation_db: float = 6.0
    drift_per_s: float = 0.02
    bending1: str = "gain"
    noise_rate_fraction: float | None = None

    def __post_init__(self) -> None:
        for k, v in asdict(self).items():
            if k == "bending1":
                if v not in ("gain", "phase"):
                    raise ValueError(f"bending1 = {v!r}: 'gain' or 'phase'")
            elif k == "noise_rate_fraction" and v is None:
                continue
            elif not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0.0):
                raise ValueError(f"{k} = {v!r}: a finite number >= 0")


#: the parameter vector of the optimiser: (name, lower, upper, log-scaled)
PARAMETERS = (("kp", 1e-4, 10.0, True), ("ki", 1e-4, 10.0, True), ("kd", 1e-5, 1.0, True),
              ("lead_zero_radps", 0.5, 100.0, True), ("lead_ratio", 1.0, 1000.0, True),
              ("lowpass_radps", 20.0, 155.0, True), ("lowpass_damping", 0.2, 1.0, False),
              ("notch_damping", 0.02, 1.0, True), ("notch_depth", 0.02, 1.0, True))


def _from_unit(u: np.ndarray, params: tuple = PARAMETERS) -> dict[str, float]:
    """Parameters ``params`` (rows of :data:`PARAMETERS`) from the optimiser's unbounded vector (a logistic
    map into each range)."""
    out = {}
    for (name, lo, hi, log), x in zip(params, u):
        s = 1.0 / (1.0 + math.exp(-float(np.clip(x, -40, 40))))
        out[name] = math.exp(math.log(lo) + s * (math.log(hi) - math.log(lo))) if log else lo + s * (hi - lo)
    return out


def _to_unit(values: dict[str, float], params: tuple = PARAMETERS) -> np.ndarray:
    u = []
    for name, lo, hi, log in params:
        v = min(max(values[name], lo * (1 + 1e-9)), hi * (1 - 1e-9))
        s = (math.log(v) - math.log(lo)) / (math.log(hi) - math.log(lo)) if log else (v - lo) / (hi - lo)
        u.append(math.log(s / (1.0 - s)))
    return np.array(u)


def open_loop_growth(A: np.ndarray, dt: float) -> float:
    """The fastest growth rate [1/s] of the discrete system matrix ``A`` at the period ``dt`` [s]:
    ``max ln|z| / dt`` over its eigenvalues ``z``, a pole within 1e-6 of z = 1 left out (as
    :meth:`RowProblem.growth` does for the closed loop)."""
    ev = np.linalg.eigvals(np.asarray(A, float))
    ev = ev[np.abs(ev - 1.0) > 1e-6]
    return float(np.max(np.log(np.maximum(np.abs(ev), 1e-300)) / dt)) if ev.size else -math.inf


def controller(values: dict[str, float], notch_radps: float | None) -> tuple[tuple[float, float, float], StructuralFilter]:
    """PID gains (kp, ki, kd) and the filter of a parameter set; ``notch_radps`` None: notch off."""
    filt = StructuralFilter(lead_zero_radps=values["lead_zero_radps"],
                            lead_pole_radps=values["lead_zero_radps"] * values["lead_ratio"],
                            lowpass_radps=values["lowpass_radps"], lowpass_damping=values["lowpass_damping"],
                            notch_radps=notch_radps or 100.0, notch_damping=values["notch_damping"],
                            notch_depth=values["notch_depth"] if notch_radps else 1.0)
    return (values["kp"], values["ki"], values["kd"]), filt


def controller_tf(gains: tuple[float, float, float], filt: Filter, dt: float) -> control.TransferFunction:
    """``C(z)``: the discrete PID (unfiltered derivative) times the structural filter (one, or several in series:
    :class:`..filters.FilterSeries`), at ``dt`` [s]."""
    return pid_tf(gains[0], gains[1], gains[2], None, dt) * filt.tf(dt)


def _controller_poly(gains, filt: Filter, dt: float) -> tuple[np.ndarray, np.ndarray]:
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


#: how a row's slowest closed-loop divergence is held: ``"requirement"``, below ``0.8 * drift_per_s``
#: (the requirement with its slack); ``"vehicle"``, no faster than the vehicle's own open-loop divergence
#: at each plant (a load-relief row: module docstring)
DRIFT_MODES = ("requirement", "vehicle")


class RowProblem:
    """The design problem of one row: the discrete plants of the row's own flight time and of the ends
    of the stretch it flies (``cases``: the first is the row's own, whose disturbance response is the
    objective; the requirements hold on all), their responses on a frequency grid, and the bands the
    mode constraints look at.

    ``fixed``: parameters of :data:`PARAMETERS` held at these values (in their units) and not optimised;
    ``drift``: one of :data:`DRIFT_MODES`; ``noise``: the gyro's white noise per sample [rad/s] and the
    servo's rate limit [rad/s] (:func:`.noise.gyro_noise`; held to ``Requirements.noise_rate_fraction``
    when that is set and the noise is not zero). The optimiser's vector holds the other parameters
    (:meth:`values`, :meth:`to_unit`)."""

    def __init__(self, cases: list[tuple[dict[str, control.StateSpace], dict[str, list[float]]]], req: Requirements,
                 n_grid: int = 3000, slack: tuple[float, float] = (0.5, 2.0), fixed: dict[str, float] | None = None,
                 drift: str = "requirement", noise: tuple[float, float] = (0.0, 1.0)) -> None:
        bounds = {name: (lo, hi) for name, lo, hi, _ in PARAMETERS}
        for k, v in (fixed or {}).items():
            if k not in bounds:
                raise ValueError(f"fixed parameter {k!r}: one of {sorted(bounds)}")
            if not (isinstance(v, (int, float)) and 0.0 <= v <= bounds[k][1]):
                raise ValueError(f"fixed {k} = {v!r}: a number in [0, {bounds[k][1]:g}]")
        if drift not in DRIFT_MODES:
            raise ValueError(f"drift = {drift!r}: one of {DRIFT_MODES}")
        self.fixed = {k: float(v) for k, v in (fixed or {}).items()}
        self.params = tuple(p for p in PARAMETERS if p[0] not in self.fixed)
        self.drift = drift
        self.req = req
        self.noise = (float(noise[0]), float(noise[1]))
        self._noise_held = self.noise[0] > 0.0 and req.noise_rate_fraction is not None
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
        #: per case and model, the closed-loop growth rate [1/s] the drift penalty allows
        self.allowed_growth = [{k: (0.8 * req.drift_per_s if drift == "requirement" else open_loop_growth(m[0], self.dt))
                                for k, m in mats.items()} for _, _, mats in self.cases]

    def values(self, u: np.ndarray) -> dict[str, float]:
        """Every parameter [its unit] from the optimiser's vector ``u`` over the free ones."""
        return {**_from_unit(u, self.params), **self.fixed}

    def to_unit(self, values: dict[str, float]) -> np.ndarray:
        """The optimiser's vector of the free parameters of ``values``."""
        return _to_unit(values, self.params)

    def growth(self, b: np.ndarray, a: np.ndarray, model: str, case: int = 0,
               realised: tuple[np.ndarray, ...] | None = None) -> float:
        """The fastest closed-loop growth rate [1/s] (the integrator's pole at z = 1 cancelling the plant's
        zero at z = 1 left out, as :func:`.linearize.margins` does); ``realised``: the controller's
        ``signal.tf2ss(b, a)`` when the caller has it."""
        A, B, C = self.cases[case][2][model]
        Ac, Bc, Cc, Dc = signal.tf2ss(b, a) if realised is None else realised
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
        the loop at its peak over the gain-stabilised bands [dB], the objective ``J`` and, per model, the
        largest excess of the growth over the allowed one (``drift_excess`` [1/s]); ``noise``: the gimbal rate
        the gyro's noise commands as a fraction of the rate limit, the largest over cases and models
        (computed only when the requirement is set)."""
        gains, filt = controller(values, self.notch_radps)
        b, a = _controller_poly(gains, filt, self.dt)
        C = np.polyval(b, self.z) / np.polyval(a, self.z)
        realised = signal.tf2ss(b, a)
        out: dict[str, Any] = {"values": values, "higher_db": -99.0, "drift_excess": {}, "noise": 0.0}
        for i, (G, band, _) in enumerate(self.cases):
            for model, g in G.items():
                L = C * g
                if self._noise_held:
                    out["noise"] = max(out["noise"], noise_rate_on_grid(C, g, self.w, self.dt, *self.noise))
                m = self.grid_margins(L) + (self.growth(b, a, model, i, realised),)
                w = out.get(model)
                out[model] = m if w is None else (min(w[0], m[0]), max(w[1], m[1]), min(w[2], m[2]), max(w[3], m[3]))
                x = m[3] - self.allowed_growth[i][model]
                out["drift_excess"][model] = max(out["drift_excess"].get(model, x), x)
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
            up, down, phase, _ = e[model]
            v += [max(0.0, gm - up), max(0.0, gm + down) if down > -99 else 0.0, max(0.0, pm - phase) / 5.0,
                  100.0 * max(0.0, e["drift_excess"][model])]
        v.append(max(0.0, e["higher_db"] + r.attenuation_db + sdb))
        if self._noise_held:                           # relative, designed 10 % below the requirement
            v.append(5.0 * max(0.0, e["noise"] / max(r.noise_rate_fraction, 1e-12) - 0.9))
        return v

    def cost(self, u: np.ndarray) -> float:
        try:
            e = self.evaluate(self.values(u))
        except (ValueError, np.linalg.LinAlgError):
            return 1e9
        return self.cost_of(e)

    def cost_of(self, e: dict[str, Any]) -> float:
        """The optimiser's cost of an evaluation ``e``: the squared violations (weighted 10) plus log J."""
        return 10.0 * sum(x * x for x in self.violations(e)) + math.log(e["J"])


#: a start of the optimiser when there is no previous row: a slow PI with every filter near off
START = {"kp": 0.05, "ki": 0.2, "kd": 0.005, "lead_zero_radps": 5.0, "lead_ratio": 3.0, "lowpass_radps": 100.0,
         "lowpass_damping": 0.7, "notch_damping": 0.3, "notch_depth": 0.3}


def design_row(problem: RowProblem, warm: dict[str, float] | list[dict[str, float]] | None, rng: np.random.Generator,
               starts: int = 3, maxiter: int = 3000) -> dict[str, Any]:
    """The best parameter set of ``problem`` from ``warm`` (one parameter set or a list of them; None:
    :data:`START`) and ``starts`` random starts; ``feasible``: every penalty zero."""
    warms = [warm or START] if not isinstance(warm, list) else warm
    seeds = [problem.to_unit(w) for w in warms] + [rng.normal(0.0, 1.5, len(problem.params)) for _ in range(starts)]
    best = None
    for u0 in seeds:
        res = optimize.minimize(problem.cost, u0, method="Nelder-Mead",
                                options={"maxiter": maxiter, "xatol": 1e-4, "fatol": 1e-7, "adaptive": True})
        if best is None or res.fun < best.fun:
            best = res
    e = problem.evaluate(problem.values(best.x))
    e["feasible"] = max(problem.violations(e)) < 1e-6
    return e
