"""Uncontrolled flights, rigid against non-rigid (thesis 5.2 for Stratos III, 6.3.1 for SMILE).

Every flight here has the gimbal at zero. The vehicles are symmetric, so with no disturbance they
fly straight; the thesis's runs had wind, so these do too:

- ``stratos3``: El Arenosillo, 85 deg elevation, 10 m rail, 30 s; the env's ``profile`` wind (5 m/s
  at the ground, 20 m/s above 10 km, from the west: the "wind just after leaving the tower" of thesis
  5.2.2), alone and with a late 15 m/s 1-cosine gust at 12.3 km (about 21.6 s, just before the thrust
  drop at 22-23 s; the "sudden gust late in the flight" of 5.2.2). Two what-ifs, to find out what
  the thesis's departure needs: the thesis's slosh size (``thesis_slosh``: 15 kg on a 0.152 m pendulum,
  its Figure 5.6 and its 0.28 m inner radius, instead of our 2.8 kg on 0.073 m), and a thrust drop to
  below the drag (``drop_thrust_n``: the thrust table after 23 s replaced by a 2 kN ramp to zero).
- ``smile``: Andoya, vertical, 60 s; a fixed jet-stream profile peaking at 50 m/s at 10.5 km (where
  the vehicle passes at maximum dynamic pressure; thesis 6.3 used the Horizontal Wind Model), and a
  15 m/s 1-cosine gust at 9 km. Optionally a gimbal sine (``gimbal_sine``) to probe the staging coast.

Units: SI inside (s, m, kg, N, rad, rad/s); the summaries report angles in deg and rates in deg/s,
with ``_deg`` / ``_degps`` in the key. ``python -m experiments.uncontrolled_departures.uncontrolled`` prints the tables and
writes ``docs/figures/uncontrolled_stratos3.png`` and ``docs/figures/uncontrolled_smile.png``.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from lvgym.commandline import parse
from lvgym.envs.spec import wind_spec
from lvgym.simulator import LaunchSpec, Simulator, TimelineSpec
from lvgym.vehicle.config import VEHICLE_DIR

DEG = math.degrees(1.0)
FIGURES = Path(__file__).resolve().parents[2] / "docs" / "figures"

STRATOS3 = LaunchSpec("el_arenosillo", elevation_deg=85.0, rail_length=10.0)
STRATOS3_T_END = 30.0            # [s] the StratosIII-v0 mission
THRUST_DROP = (22.0, 23.0)       # [s] 12.5 kN -> 6 kN in stratos3.yaml's thrust table
SMILE = LaunchSpec("andoya", elevation_deg=90.0, rail_length=0.0)
SMILE_T_END = 60.0
SMILE_EVENTS = {"burnout": 43.0, "separation": 44.0, "ignition": 45.0}   # [s] smile.yaml
LATE_GUST = {"model": "gust", "amplitude": 15.0, "length": 200.0, "direction_deg": 270.0, "onset": 12300.0}
MAXQ_GUST = {"model": "gust", "amplitude": 15.0, "length": 200.0, "direction_deg": 270.0, "onset": 9000.0}
JET = {"model": "jet_stream", "surface_speed": [5.0, 5.0], "shear_exponent": [0.15, 0.15],
       "boundary_layer_m": [500.0, 500.0], "peak_altitude_m": [10500.0, 10500.0], "peak_speed": [50.0, 50.0],
       "width_m": [2000.0, 2000.0], "direction_deg": [270.0, 270.0], "veer_deg": [0.0, 0.0]}
THESIS_SLOSH_KG, THESIS_PENDULUM_M = 15.0, 0.152   # thesis Figure 5.6; L = 0.28 m / 1.84119
THESIS_DROP_S = 20.0             # [s] the thesis's model: its fuel empties "at around 20 seconds" (5.2)


def stratos3_winds() -> dict[str, Any]:
    """Stratos III wind cases: name -> wind mapping for ``lvgym.environment.make``."""
    profile = wind_spec("profile", STRATOS3_T_END)
    return {"profile": profile, "profile+late gust": {"model": "sum", "models": [profile, LATE_GUST]}}


def smile_winds() -> dict[str, Any]:
    """SMILE wind cases: name -> wind mapping."""
    return {"none": "none", "jet stream": JET, "gust at 9 km": MAXQ_GUST}


def thesis_thrust_table(table: list[list[float]]) -> list[list[float]]:
    """The thesis's Stratos III thrust law (5.2) on ``table`` ([time s, thrust N] rows): unchanged up to
    :data:`THESIS_DROP_S`, where "the thrust is quickly decreased to approximately half of its original
    value and decreasing to zero in approximately 10 seconds" (0.5 s to half, then linear to 0)."""
    t0, t_half, t_zero = THESIS_DROP_S, THESIS_DROP_S + 0.5, THESIS_DROP_S + 10.0
    f0 = float(np.interp(t0, [r[0] for r in table], [r[1] for r in table]))
    return [list(r) for r in table if r[0] < t0] + [[t0, f0], [t_half, 0.5 * f0], [t_zero, 0.0]]


def _stratos3_vehicle(drop_thrust_n: float | None, thesis_thrust: bool = False) -> str:
    """``stratos3``, or a temporary copy with another thrust law after the drop: a ramp from
    ``drop_thrust_n`` [N] at 23 s to 0 at the table's end (same mass flow, so the propellant lasts to
    the end), or the thesis's law (:func:`thesis_thrust_table`, mass flow raised so the N2O empties
    just before the shorter table ends, as in the shipped file)."""
    if drop_thrust_n is None and not thesis_thrust:
        return "stratos3"
    data = yaml.safe_load((VEHICLE_DIR / "stratos3.yaml").read_text(encoding="utf-8"))
    engine = data["stages"][0]["engines"][0]
    table = engine["thrust_table"]
    t_last = table[-1][0]
    if thesis_thrust:
        engine["thrust_table"] = thesis_thrust_table(table)
        engine["mass_flow"] = engine["mass_flow"] * t_last / engine["thrust_table"][-1][0]
    else:
        for row in table:
            if row[0] >= THRUST_DROP[1]:
                row[1] = drop_thrust_n * (t_last - row[0]) / (t_last - THRUST_DROP[1])
    fh = tempfile.NamedTemporaryFile("w", suffix=".yaml", prefix="stratos3_drop_", delete=False)
    with fh:
        yaml.safe_dump(data, fh)
    return fh.name


def _thesis_slosh(sim: Simulator) -> tuple[np.ndarray, np.ndarray]:
    """``param_scale`` and ``param_offset`` (1, n_p) that give the N2O pendulum the thesis's 15 kg and
    0.152 m, taking the added slosh mass out of the rigid body B (total mass kept)."""
    lay = sim.layout
    scale, offset = np.ones((1, lay.n_p)), np.zeros((1, lay.n_p))
    p = sim.timeline.params_at([THRUST_DROP[0]])[0]
    m_s, length = p[lay.slosh_param(0, "m")][0], p[lay.slosh_param(0, "length")][0]
    k = THESIS_SLOSH_KG / m_s
    scale[0, lay.slosh_param(0, "m")] = k
    scale[0, lay.slosh_param(0, "length")] = THESIS_PENDULUM_M / length
    offset[0, lay.params["m_b"]] = -(k - 1.0) * m_s
    return scale, offset


def fly(sim: Simulator, data: Any, t_end: float, dt: float = 0.05, gimbal_sine: tuple[float, float] | None = None
        ) -> dict[str, np.ndarray]:
    """Fly every row of the reset rows ``data`` of ``sim`` to ``t_end`` [s], sampling every ``dt`` [s].

    ``gimbal_sine``: (amplitude [rad], frequency [Hz]) of a pitch gimbal sine, else the gimbal is 0.
    Returns ``t`` (n,) [s], ``omega`` (n, B, 3) [rad/s], ``slosh`` (n, B, N, 2) [rad] (NaN for an
    empty or separated tank), ``qbar`` (n, B) [Pa], ``ax`` (n, B) [m/s^2] specific force along
    ``x_b`` (thrust plus axial aerodynamic force over the stack's mass)."""
    v = sim.view(data)
    B, N = v.batch, sim.dynamics.n_slosh
    lay = sim.layout
    m_cols = [lay.slosh_param(j, "m").start for j in range(N)]
    out: dict[str, list] = {k: [] for k in ("t", "omega", "slosh", "qbar", "ax")}
    g = np.zeros((B, 2))
    n = int(round(t_end / dt))
    for _ in range(n):
        if gimbal_sine is not None:
            g[:, 0] = gimbal_sine[0] * np.sin(2.0 * math.pi * gimbal_sine[1] * v.t)
        sim.step(data, g, dt)
        out["t"].append(v.t[0])
        out["omega"].append(v.state("omega_bi_b").copy())
        ang = v.slosh_angles()
        if N:
            ang[v.p[:, m_cols] <= 0.0] = np.nan
        out["slosh"].append(ang)
        out["qbar"].append(v.conditions("qbar").copy())
        mass = sim.timeline.interp("mass", v.t)
        out["ax"].append((v.conditions("thrust") + v.conditions("f_aero_b")[:, 0]) / mass)
    return {k: np.asarray(v) for k, v in out.items()}


def transverse_rate(h: dict[str, np.ndarray]) -> np.ndarray:
    """Pitch-yaw rate magnitude ``hypot(q, r)`` (n, B) [rad/s]."""
    return np.hypot(h["omega"][..., 1], h["omega"][..., 2])


def window_max(h: dict[str, np.ndarray], x: np.ndarray, t0: float, t1: float) -> np.ndarray:
    """Largest |x| (per batch row) over samples with ``t0 <= t < t1``; NaN-safe, 0 if none."""
    sel = (h["t"] >= t0) & (h["t"] < t1)
    a = np.abs(x[sel]).reshape(sel.sum(), x.shape[1], -1)
    return np.nan_to_num(np.nanmax(a, axis=(0, 2)) if a.size and np.isfinite(a).any() else np.zeros(x.shape[1]))


def peak_time(h: dict[str, np.ndarray], t0: float, t1: float) -> np.ndarray:
    """Time [s] of the largest transverse rate in ``[t0, t1)``, per row."""
    sel = (h["t"] >= t0) & (h["t"] < t1)
    return h["t"][sel][np.argmax(transverse_rate(h)[sel], axis=0)]


def run_stratos3(model: str, drop_thrust_n: float | None = None, thesis_slosh: bool = False,
                 dt: float = 0.05, thesis_thrust: bool = False) -> dict[str, np.ndarray]:
    """Stratos III uncontrolled for 30 s, one batch row per wind of :func:`stratos3_winds`; the
    what-ifs of :func:`_stratos3_vehicle` and :func:`_thesis_slosh` on request."""
    winds = list(stratos3_winds().values())
    vehicle = _stratos3_vehicle(drop_thrust_n, thesis_thrust)
    try:
        sim = Simulator(vehicle, model, launch=STRATOS3, timeline=TimelineSpec(t_end=STRATOS3_T_END))
    finally:
        if vehicle != "stratos3":
            Path(vehicle).unlink(missing_ok=True)
    scale, offset = _thesis_slosh(sim) if thesis_slosh and sim.dynamics.n_slosh else (None, None)
    data = sim.reset(batch=len(winds), rng=np.random.default_rng(0), winds=winds, param_scale=scale,
                     param_offset=offset)
    return fly(sim, data, STRATOS3_T_END, dt)


def run_smile(model: str, winds: dict[str, Any] | None = None, gimbal_sine: tuple[float, float] | None = None,
              t_end: float = SMILE_T_END, dt: float = 0.05) -> dict[str, np.ndarray]:
    """SMILE uncontrolled (or with a gimbal sine), one batch row per wind (default :func:`smile_winds`)."""
    w = list((winds or smile_winds()).values())
    sim = Simulator("smile", model, launch=SMILE, timeline=TimelineSpec(t_end=SMILE_T_END))
    data = sim.reset(batch=len(w), rng=np.random.default_rng(0), winds=w)
    return fly(sim, data, t_end, dt, gimbal_sine)


def stratos3_summary(dt: float = 0.05) -> list[dict[str, Any]]:
    """One line per (set-up, wind): peak transverse rates [deg/s] before (15 s to the drop) and after
    (the drop to 30 s) the thrust drop, rigid and non-rigid, peak slosh angle [deg], the smallest
    specific force after the drop [m/s^2] and when it first turns negative [s] (NaN: never)."""
    rows = []
    setups = (("nominal", None, False, False), ("thesis slosh size", None, True, False),
              ("thesis thrust law", None, False, True), ("thesis thrust law and slosh size", None, True, True),
              ("thrust < drag after 23 s", 2000.0, False, False), ("thrust < drag and thesis slosh size", 2000.0, True, False))
    for name, drop, slosh, law in setups:
        hr, hn = run_stratos3("rigid", drop, slosh, dt, law), run_stratos3("nonrigid", drop, slosh, dt, law)
        wr, wn = transverse_rate(hr), transverse_rate(hn)
        t_drop = THESIS_DROP_S if law else THRUST_DROP[0]
        for b, wind in enumerate(stratos3_winds()):
            after = hn["t"] >= t_drop
            negative = hn["t"][after][hn["ax"][after, b] < 0.0]
            rows.append({"setup": name, "wind": wind, "t_drop_s": t_drop,
                         "rigid_before_degps": DEG * window_max(hr, wr, 15, t_drop)[b],
                         "rigid_after_degps": DEG * window_max(hr, wr, t_drop, 30.01)[b],
                         "nonrigid_before_degps": DEG * window_max(hn, wn, 15, t_drop)[b],
                         "nonrigid_after_degps": DEG * window_max(hn, wn, t_drop, 30.01)[b],
                         "slosh_before_deg": DEG * window_max(hn, hn["slosh"], 15, t_drop)[b],
                         "slosh_after_deg": DEG * window_max(hn, hn["slosh"], t_drop, 30.01)[b],
                         "ax_min_after_mps2": float(hn["ax"][after, b].min()),
                         "t_ax_negative_s": float(negative[0]) if negative.size else math.nan})
    return rows


def smile_summary(dt: float = 0.05) -> list[dict[str, Any]]:
    """One line per wind: time of maximum dynamic pressure [s], peak transverse rates [deg/s] near
    max q (20-35 s) and after ignition (45-60 s), rigid and non-rigid, the pendulums' (attached tanks)
    peak angle [deg] near max q and in the coast, and the time [s] of the largest rate between 5 s and
    burnout (43 s)."""
    hr, hn = run_smile("rigid", dt=dt), run_smile("nonrigid", dt=dt)
    wr, wn = transverse_rate(hr), transverse_rate(hn)
    tp_r, tp_n = peak_time(hr, 5.0, 43.0), peak_time(hn, 5.0, 43.0)
    rows = []
    for b, wind in enumerate(smile_winds()):
        rows.append({"wind": wind, "t_max_q_s": float(hn["t"][np.argmax(hn["qbar"][:, b])]),
                     "max_q_kpa": float(hn["qbar"][:, b].max() / 1e3),
                     "rigid_20_35_degps": DEG * window_max(hr, wr, 20, 35)[b],
                     "nonrigid_20_35_degps": DEG * window_max(hn, wn, 20, 35)[b],
                     "slosh_20_35_deg": DEG * window_max(hn, hn["slosh"], 20, 35)[b],
                     "slosh_coast_deg": DEG * window_max(hn, hn["slosh"], 44.0, 45.0)[b],
                     "rigid_45_60_degps": DEG * window_max(hr, wr, 45, 60.01)[b],
                     "nonrigid_45_60_degps": DEG * window_max(hn, wn, 45, 60.01)[b],
                     "t_peak_rigid_s": float(tp_r[b]), "t_peak_nonrigid_s": float(tp_n[b])})
    return rows


def smile_suite_departures(suite: str = "smile-windy", n: int = 50, histories: dict | None = None
                           ) -> list[dict[str, Any]]:
    """SMILE uncontrolled (gimbal at zero) on ``n`` test seeds of a benchmark suite, per condition:
    failures, their reasons and end times [s], and over all episodes up to burnout (43 s) the median
    time [s] of the largest q-alpha and of the largest pitch-yaw rate, against the median time of
    maximum dynamic pressure [s]. ``histories``, if given, receives per condition name a list of
    ``(t [s], attitude error [deg], failed)`` per episode, every 0.1 s."""
    from lvgym.benchmark.suites import get_suite

    s = get_suite(suite)
    rows = []
    for cond in s.conditions:
        env = cond.make_env()
        ends, reasons, t_qa, t_rate, t_q = [], [], [], [], []
        for seed in s.seeds("test", n):
            env.reset(seed=seed)
            best = {"qa": (-1.0, 0.0), "rate": (-1.0, 0.0), "q": (-1.0, 0.0)}
            trace: list[tuple[float, float]] = []
            while True:
                _, _, term, trunc, info = env.step(np.zeros(2, np.float32))
                t = float(info["time"])
                if len(trace) < round(10.0 * t):
                    trace.append((t, DEG * math.hypot(*info["attitude_error"])))
                omega = env.unwrapped.flight.state("omega_bi_b")[0]
                for key, v in (("qa", info["qalpha_pa_deg"]), ("rate", math.hypot(omega[1], omega[2])),
                               ("q", info["qbar"])):
                    if v > best[key][0] and (key == "q" or t <= SMILE_EVENTS["burnout"]):
                        best[key] = (float(v), t)
                if term or trunc:
                    break
            if info["termination"]:
                ends.append(t)
                reasons.append(info["termination"])
            t_qa.append(best["qa"][1])
            t_rate.append(best["rate"][1])
            t_q.append(best["q"][1])
            if histories is not None:
                tr = np.asarray(trace)
                histories.setdefault(cond.name, []).append((tr[:, 0], tr[:, 1], bool(info["termination"])))
        env.close()
        rows.append({"condition": cond.name, "episodes": n, "failed": len(ends),
                     "reasons": "; ".join(sorted(set(reasons))), "end_s": ", ".join(f"{t:.1f}" for t in sorted(ends)),
                     "t_max_q_s": float(np.median(t_q)), "t_peak_qalpha_s": float(np.median(t_qa)),
                     "t_peak_rate_s": float(np.median(t_rate))})
    return rows


def coast_growth(h: dict[str, np.ndarray] | None = None, t0: float = 44.2, t1: float = 44.9
                 ) -> list[dict[str, float]]:
    """The staging coast's slosh divergence against an inverted pendulum (no wind, batch row 0).

    Between separation and ignition the drag decelerates the upper stack (``ax < 0``): the aft-hanging
    rest position of each pendulum is then an unstable equilibrium, and a small offset grows as
    ``exp(lambda t)`` with ``lambda = sqrt(|ax| / L)``. Returns per attached tank the fitted growth
    rate [1/s] of the pendulum angle over ``[t0, t1]`` [s], the predicted one and the mean ``ax``."""
    h = h if h is not None else run_smile("nonrigid", {"none": "none"}, t_end=45.0, dt=0.02)
    sim = Simulator("smile", "nonrigid", launch=SMILE, timeline=TimelineSpec(t_end=SMILE_T_END))
    p = sim.timeline.params_at([0.5 * (t0 + t1)])[0]
    sel = (h["t"] >= t0) & (h["t"] <= t1)
    ax = float(h["ax"][sel, 0].mean())
    out = []
    for j, name in enumerate(sim.timeline.slosh_names):
        m_s, length = p[sim.layout.slosh_param(j, "m")][0], p[sim.layout.slosh_param(j, "length")][0]
        if m_s <= 0.0:
            continue
        theta = np.hypot(h["slosh"][sel, 0, j, 0], h["slosh"][sel, 0, j, 1])
        fit = float(np.polyfit(h["t"][sel], np.log(theta), 1)[0])
        out.append({"tank": name, "slosh_mass_kg": float(m_s), "length_m": float(length), "ax_mps2": ax,
                    "fitted_per_s": fit, "predicted_per_s": math.sqrt(abs(ax) / length)})
    return out


def _figure(title: str, hr: dict, hn: dict, row: int, marks: dict[str, float], names: tuple[str, ...],
            path: Path, extra: dict | None = None) -> Path:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11.0, 9.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots(3, 1, sharex=True)
    fig.suptitle(title)
    ax[0].plot(hr["t"], DEG * transverse_rate(hr)[:, row], label="rigid", color="k")
    ax[0].plot(hn["t"], DEG * transverse_rate(hn)[:, row], label="nonrigid", color="C3", alpha=0.8)
    if extra:
        for lab, (h, r, style) in extra.items():
            ax[0].plot(h["t"], DEG * transverse_rate(h)[:, r], style, label=lab)
    ax[0].set_ylabel("pitch-yaw rate |(q, r)| [deg/s]")
    ax[0].set_yscale("symlog", linthresh=0.1)
    for j, name in enumerate(names):
        ax[1].plot(hn["t"], DEG * np.hypot(hn["slosh"][:, row, j, 0], hn["slosh"][:, row, j, 1]), label=name)
    if extra:
        for lab, (h, r, style) in extra.items():
            if h["slosh"].shape[2]:
                ax[1].plot(h["t"], DEG * np.hypot(h["slosh"][:, r, 0, 0], h["slosh"][:, r, 0, 1]), style, label=lab)
    ax[1].set_ylabel("pendulum angle from the axis [deg]")
    ax[1].set_yscale("symlog", linthresh=1.0)
    ax[2].plot(hn["t"], hn["ax"][:, row], color="C0", label="specific force a_x [m/s^2]")
    for lab, (h, r, style) in (extra or {}).items():
        if h["slosh"].shape[2]:
            ax[2].plot(h["t"], h["ax"][:, r], "C0--", label="a_x, " + lab.split(": ", 1)[-1])
    ax[2].axhline(0.0, color="0.5", linewidth=0.8)
    ax[2].set_ylabel("a_x [m/s^2]", color="C0")
    tw = ax[2].twinx()
    tw.plot(hn["t"], hn["qbar"][:, row] / 1e3, color="C1")
    tw.set_ylabel("dynamic pressure [kPa]", color="C1")
    ax[2].set_xlabel("t [s]")
    for a in ax:
        a.grid(True, alpha=0.3)
        for lab, te in marks.items():
            a.axvline(te, color="0.3", linestyle=":", linewidth=1.0)
            if a is ax[0]:
                a.annotate(lab, (te, 0.97), xycoords=("data", "axes fraction"), rotation=90, va="top",
                           ha="right", fontsize="small", color="0.3")
        a.legend(fontsize="small", loc="upper left")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, format="png", dpi=90)
    return path


def suite_figure(histories: dict, t_max_q: float, limit_deg: float, path: Path) -> Path:
    """Attitude error against time of every episode of :func:`smile_suite_departures`, one panel per
    condition; failed episodes in red, the attitude limit and maximum dynamic pressure marked."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11.0, 4.5), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(histories), sharey=True)
    for ax, (name, runs) in zip(np.atleast_1d(axes), histories.items()):
        for t, att, failed in runs:
            ax.plot(t, att, color="C3" if failed else "0.7", linewidth=1.2 if failed else 0.6, zorder=3 if failed else 2)
        n_fail = sum(r[2] for r in runs)
        ax.set_title(f"{name}, gimbal at zero: {n_fail} of {len(runs)} beyond {limit_deg:g} deg", fontsize="medium")
        ax.axhline(limit_deg, color="k", linestyle="--", linewidth=0.8)
        ax.axvline(t_max_q, color="C1", linestyle=":", linewidth=1.0)
        ax.annotate("max q", (t_max_q, 0.97), xycoords=("data", "axes fraction"), rotation=90, va="top", ha="right",
                    fontsize="small", color="C1")
        ax.set_xlabel("t [s]")
        ax.grid(True, alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("attitude error [deg]")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, format="png", dpi=90)
    return path


def figures(out_dir: Path = FIGURES) -> list[Path]:
    """Write ``uncontrolled_stratos3.png`` (profile wind; nominal, and the thrust-below-drag what-if
    with the thesis's slosh size dashed), ``uncontrolled_smile.png`` (jet-stream row) and
    ``uncontrolled_smile_dispersed.png`` (smile-dispersed's 50 test seeds)."""
    hr, hn = run_stratos3("rigid"), run_stratos3("nonrigid")
    hr2, hn2 = run_stratos3("rigid", 2000.0, True), run_stratos3("nonrigid", 2000.0, True)
    p1 = _figure("Stratos III uncontrolled, profile wind (thesis 5.2)", hr, hn, 0,
                 {"thrust drop": THRUST_DROP[0]}, ("n2o (nominal)",), out_dir / "uncontrolled_stratos3.png",
                 {"what-if rigid: thrust < drag": (hr2, 0, "k--"),
                  "what-if nonrigid: thrust < drag, 15 kg slosh": (hn2, 0, "C3--")})
    sr, sn = run_smile("rigid"), run_smile("nonrigid")
    tq = float(sn["t"][np.argmax(sn["qbar"][:, 1])])
    names = Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=1.0)).timeline.slosh_names
    p2 = _figure("SMILE uncontrolled, jet stream 50 m/s at 10.5 km (thesis 6.3.1)", sr, sn, 1,
                 {"max q": tq, **SMILE_EVENTS}, names, out_dir / "uncontrolled_smile.png")
    hist: dict = {}
    rows = smile_suite_departures("smile-dispersed", 50, hist)
    p3 = suite_figure(hist, rows[0]["t_max_q_s"], 30.0, out_dir / "uncontrolled_smile_dispersed.png")
    return [p1, p2, p3]


def _table(rows: list[dict[str, Any]]) -> str:
    keys = list(rows[0])
    fmt = [(lambda v: f"{v:.3g}" if isinstance(v, float) else str(v)) for _ in keys]
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(f(r[k]) for f, k in zip(fmt, keys)) + " |" for r in rows]
    return "\n".join(lines)


@dataclass
class Args:
    """No options."""


def main(argv: list[str] | None = None) -> None:
    """Print the tables and write the figures."""
    parse(Args, argv, "python -m experiments.uncontrolled_departures.uncontrolled", __doc__)
    print("Stratos III, uncontrolled (thesis 5.2): peak pitch-yaw rate and pendulum angle")
    print(_table(stratos3_summary()))
    print("\nSMILE, uncontrolled (thesis 6.3.1)")
    print(_table(smile_summary()))
    for suite in ("smile-windy", "smile-dispersed"):
        print(f"\nSMILE uncontrolled on {suite}'s 50 test seeds")
        print(_table(smile_suite_departures(suite)))
    print("\nSMILE staging coast: pendulum divergence against an inverted pendulum")
    print(_table(coast_growth()))
    print("\nSMILE with a 0.1 deg, 1 Hz pitch gimbal sine, no wind: peak rate [deg/s]")
    for model in ("rigid", "nonrigid"):
        h = run_smile(model, {"none": "none"}, gimbal_sine=(math.radians(0.1), 1.0))
        w = transverse_rate(h)
        print(f"  {model:8s} before burnout {DEG * window_max(h, w, 2, 43)[0]:.3f}, coast 43-45 s "
              f"{DEG * window_max(h, w, 43, 45)[0]:.2f}, after ignition {DEG * window_max(h, w, 45, 60.01)[0]:.2f}")
    for p in figures():
        print("wrote", p)


if __name__ == "__main__":
    main()
