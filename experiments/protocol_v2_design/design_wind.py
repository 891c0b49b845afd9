"""What a severe wind at max q asks of SMILE: the q-alpha budget, and how smile-v1-maxq-gust's winds spend it.

    python -m experiments.protocol_v2_design.design_wind                        # trajectory, budget, 20 maxq-gust seeds
    python -m experiments.protocol_v2_design.design_wind --seeds 10 --policies lqg

1. **The calm trajectory.** ``lqg`` flies smile-v1's rigid vehicle without wind or dispersion; per time the
   altitude, airspeed, Mach number and dynamic pressure (``sim.conditions``).
2. **The q-alpha budget.** A vehicle that holds its attitude (the benchmark's zero-rate goal) in a horizontal
   wind ``w`` flies at an angle of attack ``atan(w / V)`` (SMILE climbs vertically, so all of the wind is normal
   to its axis). The wind that alone reaches the structural limit ``QA`` is ``w_lim = V tan(QA / q)``; at max q
   it is the smallest.
3. **The maxq-gust draws.** For the validation seeds of ``smile-v1-maxq-gust`` (non-rigid), the wind each seed draws
   (the suite's own model, captured at the env's reset, so the episode is the protocol's) evaluated along the
   calm trajectory: the q-alpha it alone would cause, ``max_t q(t) atan(|w(h(t))| / V(t))``, against the limit;
   then each policy flies the seed, and its failure and largest q-alpha are recorded.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies the command line names)
from lvgym.benchmark.runner import build_policy
from lvgym.benchmark.suites import condition as suite_condition
from lvgym.commandline import arg, parse
from lvgym.environment import make
from lvgym.envs import functional

__all__ = ["budget", "calm_trajectory", "maxq_draws", "wind_qalpha"]

PROG = "python -m experiments.protocol_v2_design.design_wind"


def _fly(env: Any, policy: Any, seed: int, wind_probe: list | None = None) -> dict[str, np.ndarray]:
    obs, info = env.reset(seed=int(seed))
    policy.reset()
    rows: dict[str, list] = {k: [] for k in ("t", "alt", "airspeed", "mach", "qbar", "qalpha")}
    while True:
        obs, _, terminated, truncated, info = env.step(policy.act(obs, info))
        rows["t"].append(float(info["time"]))
        flight = env.unwrapped.flight                  # the view of the current state
        rows["alt"].append(float(flight.conditions("altitude")[0]))
        rows["airspeed"].append(float(flight.conditions("airspeed")[0]))
        rows["mach"].append(float(info["mach"]))
        rows["qbar"].append(float(info["qbar"]))
        rows["qalpha"].append(float(info["qalpha_pa_deg"]))
        if terminated or truncated:
            break
    out = {k: np.array(v) for k, v in rows.items()}
    out["failed"] = bool(terminated)
    out["termination"] = str(info.get("termination", ""))
    return out


def calm_trajectory(policy: str = "lqg") -> dict[str, np.ndarray]:
    """``policy`` on smile-v1's rigid vehicle, no wind, no dispersion, seed 0 (the trajectory the budget uses)."""
    from lvgym.benchmark.registry import resolve_policy

    cond = dataclasses.replace(suite_condition("smile-v1", "rigid"), wind="none", randomize=())
    env = cond.make_env()
    return _fly(env, build_policy(resolve_policy(policy, PROG), env), 0)


def budget(traj: dict[str, np.ndarray], qalpha_limit: float = 250e3) -> np.ndarray:
    """The horizontal wind [m/s] that alone reaches ``qalpha_limit`` [Pa deg] at each step of ``traj`` with
    the attitude held (inf where q is below 1 kPa)."""
    q, v = traj["qbar"], traj["airspeed"]
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.radians(qalpha_limit / np.maximum(q, 1.0))
        return np.where((q > 1e3) & (a < math.pi / 2), v * np.tan(np.minimum(a, 1.5)), np.inf)


def wind_qalpha(traj: dict[str, np.ndarray], wind: Any) -> tuple[float, float, float]:
    """The largest ``q atan(|w_h| / V)`` [Pa deg] of ``wind`` (a reset wind model) along ``traj``, the time [s]
    of it and the horizontal wind [m/s] there."""
    w = wind.velocity_ned(traj["alt"], traj["t"])
    wh = np.hypot(w[:, 0], w[:, 1])
    qa = traj["qbar"] * np.degrees(np.arctan2(wh, np.maximum(traj["airspeed"], 1.0)))
    i = int(np.argmax(qa))
    return float(qa[i]), float(traj["t"][i]), float(wh[i])


def maxq_draws(traj: dict[str, np.ndarray], seeds: Sequence[int], policies: Sequence[str],
               suite: str = "smile-v1-maxq-gust", model: str = "nonrigid") -> list[dict[str, Any]]:
    """Per seed: the drawn wind's q-alpha along ``traj`` and the largest horizontal wind below 15 km, the drawn
    gust's amplitude and onset, and for each policy its failure and largest q-alpha [kPa deg]."""
    from lvgym.benchmark.registry import resolve_policy

    captured: list[Any] = []
    original = functional.wind_spec

    def capturing(tier: str, mission_time: float) -> Any:
        model_ = make("wind", original(tier, mission_time))
        captured.append(model_)
        return model_

    cond = suite_condition(suite, model)
    env = cond.make_env()
    built = {p: build_policy(resolve_policy(p, PROG), env) for p in policies}
    out = []
    functional.wind_spec = capturing
    try:
        for seed in seeds:
            rec: dict[str, Any] = {"seed": int(seed)}
            for p, pol in built.items():
                captured.clear()
                r = _fly(env, pol, seed)
                rec[f"{p}_failed"] = r["termination"] if r["failed"] else ""
                rec[f"{p}_max_qalpha"] = float(np.max(r["qalpha"])) / 1e3
            wind = captured[-1]
            qa, t, wh = wind_qalpha(traj, wind)
            h = np.arange(0.0, 15000.0, 50.0)
            w = wind.velocity_ned(h, 0.0)
            gust = [c for c in wind.children if hasattr(c, "drawn") and "amplitude" in c.drawn]
            jet = [c for c in wind.children if hasattr(c, "drawn") and "peak_speed" in c.drawn]
            rec.update({"wind_qalpha": qa / 1e3, "wind_qalpha_t": t, "wind_h_at_peak": wh,
                        "wind_max_0_15km": float(np.max(np.hypot(w[:, 0], w[:, 1]))),
                        "jet_peak_speed": jet[0].drawn["peak_speed"] if jet else float("nan"),
                        "jet_peak_km": jet[0].drawn["peak_altitude_m"] / 1e3 if jet else float("nan"),
                        "gust_amplitude": gust[0].drawn["amplitude"] if gust else float("nan"),
                        "gust_onset_km": gust[0].drawn["onset"] / 1e3 if gust else float("nan")})
            out.append(rec)
    finally:
        functional.wind_spec = original
    return out


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.protocol_v2_design.design_wind --help``)."""

    seeds: int = arg(20, lo=1, hi=1000)
    """validation seeds of smile-v1-maxq-gust (from 0; a design study never flies the test seeds)"""
    policies: list[str] = arg(default_factory=lambda: ["lqg", "gs-pid-flex"], metavar="POLICY")
    """policies flown on each seed"""
    qalpha_limit_kpa_deg: float = arg(250.0, lo=1.0)
    """the structural limit [kPa deg] (SmileAscent-v1's)"""


def main(argv: Sequence[str] | None = None) -> int:
    a = parse(Args, argv, PROG, __doc__)
    traj = calm_trajectory()
    lim = budget(traj, a.qalpha_limit_kpa_deg * 1e3)
    i_q = int(np.argmax(traj["qbar"]))
    w = sys.stdout.write
    w("## Calm trajectory (lqg, rigid, no wind, no dispersion) and the wind that alone reaches the q-alpha limit\n\n")
    w("| t [s] | altitude [km] | airspeed [m/s] | Mach | q [kPa] | wind at the limit [m/s] |\n|---:|---:|---:|---:|---:|---:|\n")
    marks = sorted({int(round(x / 0.02)) - 1 for x in (5, 10, 15, 20, 25, 30, 35, 40)} | {i_q})
    for i in marks:
        if 0 <= i < traj["t"].size:
            star = " (max q)" if i == i_q else ""
            w(f"| {traj['t'][i]:.1f}{star} | {traj['alt'][i] / 1e3:.2f} | {traj['airspeed'][i]:.0f} | {traj['mach'][i]:.2f} "
              f"| {traj['qbar'][i] / 1e3:.1f} | {lim[i]:.1f} |\n")
    band = traj["qbar"] >= 0.8 * traj["qbar"][i_q]
    w(f"\nmax q {traj['qbar'][i_q] / 1e3:.1f} kPa at {traj['t'][i_q]:.1f} s, {traj['alt'][i_q] / 1e3:.2f} km; q >= 80 % of it from "
      f"{traj['t'][band][0]:.1f} to {traj['t'][band][-1]:.1f} s ({traj['alt'][band][0] / 1e3:.1f}-{traj['alt'][band][-1] / 1e3:.1f} km); "
      f"smallest wind at the limit {np.min(lim):.1f} m/s\n\n")
    names = list(a.policies)
    recs = maxq_draws(traj, range(a.seeds), names)
    w("## smile-v1-maxq-gust, non-rigid: each validation seed's wind along the calm trajectory, and the flights\n\n")
    head = "| seed | jet peak [m/s] at [km] | gust [m/s] at [km] | wind's own q-alpha [kPa deg] at [s] | " + \
        " | ".join(f"{p}: failed / max q-alpha" for p in names) + " |\n"
    w(head + "|---:|---:|---:|---:|" + "---|" * len(names) + "\n")
    for r in recs:
        cells = " | ".join(f"{'q-alpha' if 'q-alpha' in r[p + '_failed'] else (r[p + '_failed'] or 'no')} / {r[p + '_max_qalpha']:.0f}"
                           for p in names)
        w(f"| {r['seed']} | {r['jet_peak_speed']:.0f} at {r['jet_peak_km']:.1f} | {r['gust_amplitude']:.1f} at {r['gust_onset_km']:.1f} "
          f"| {r['wind_qalpha']:.0f} at {r['wind_qalpha_t']:.1f} | {cells} |\n")
    over = [r["wind_qalpha"] > a.qalpha_limit_kpa_deg for r in recs]
    w(f"\nseeds whose wind alone exceeds the limit: {sum(over)} of {len(recs)}\n")
    for p in names:
        fails = [bool(r[p + "_failed"]) for r in recs]
        both = sum(f and o for f, o in zip(fails, over))
        w(f"{p}: {sum(fails)} failures; {both} of them on seeds whose wind alone exceeds the limit; "
          f"{sum(o and not f for f, o in zip(fails, over))} such seeds flown without failure\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
