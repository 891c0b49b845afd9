"""What the q-alpha limit asks of a controller on a suite: the flights of policies on a suite's seeds, and
the load a perfect attitude hold would carry in the same wind (docs/flex-design.md, "The slender vehicle").

For every episode :func:`fly` records, at every control step, the time [s], the dynamic pressure ``q``
[Pa], the total angle of attack [rad], the env's q-alpha [Pa deg], the horizontal wind (its size and its
north and east components) [m/s] and the airspeed [m/s]. Its summary (:func:`summary`) gives the
failure (time, q, alpha, q-alpha), the peak q-alpha and the **attitude-hold estimate**: the vehicle
flies vertically with the body held on the reference axis (the vertical), so its angle of attack is the
wind's, ``alpha_hold = atan(|w_h| / V)`` (``w_h`` the horizontal wind, ``V`` the airspeed), and the hold
carries ``q alpha_hold`` [Pa deg]; its peak over the flight says whether any controller that holds the
attitude could meet the limit. What a controller that turns into the wind could do is
:mod:`.loadbound`'s.

``python -m experiments.load_relief.qalpha_floor --policies zero gs-pid-flex --seeds 10`` (validation seeds 0-9 of
``slender-v1``) prints one line per episode and the summary; ``--plain baselines/schedules/slender_flex.yaml``
also flies the plain designs (integral kept) the load-relief schedule's rows record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.benchmark.runner import PolicySpec, build_policy
from lvgym.benchmark.suites import SUITES, get_suite
from lvgym.commandline import arg, command_name, parse

__all__ = ["fly", "summary", "hold_qalpha"]


def hold_qalpha(qbar_pa: np.ndarray, wind_h_mps: np.ndarray, airspeed_mps: np.ndarray) -> np.ndarray:
    """q-alpha [Pa deg] of a vehicle held on the vertical: ``q`` [Pa] times the wind's angle
    ``atan(|w_h| / V)`` [deg] (horizontal wind ``w_h``, airspeed ``V`` [m/s])."""
    return np.asarray(qbar_pa, float) * np.degrees(np.arctan2(np.abs(wind_h_mps), np.asarray(airspeed_mps, float)))


def fly(policy_spec: PolicySpec, condition: Any, seed: int) -> dict[str, np.ndarray | str | bool]:
    """One episode of ``policy_spec`` on ``condition`` with ``seed``: the per-step record (module docstring)."""
    env = condition.make_env()
    policy = build_policy(policy_spec, env)
    obs, info = env.reset(seed=int(seed))
    policy.reset()
    rows = []
    while True:
        obs, _, terminated, truncated, info = env.step(policy.act(obs, info))
        sim = env.unwrapped.flight
        wind = np.asarray(sim.conditions("wind_n")[0], float)
        v_air = float(np.linalg.norm(sim.conditions("v_air_b")[0]))
        rows.append([info["time"], info["qbar"], info["alpha_total"], info["qalpha_pa_deg"],
                     math.hypot(wind[0], wind[1]), v_air, wind[0], wind[1]])
        if terminated or truncated:
            break
    env.close()
    a = np.array(rows, float)
    return {"time": a[:, 0], "qbar": a[:, 1], "alpha": a[:, 2], "qalpha": a[:, 3], "wind_h": a[:, 4],
            "airspeed": a[:, 5], "wind_ne": a[:, 6:8], "failed": bool(terminated), "reason": info.get("termination", "")}


def summary(rec: dict[str, Any]) -> dict[str, float | str | bool]:
    """The failure (or the end), the peak q-alpha of the flight and of an attitude hold in its wind."""
    hold = hold_qalpha(rec["qbar"], rec["wind_h"], rec["airspeed"])
    k = int(np.argmax(rec["qalpha"]))
    j = int(np.argmax(hold))
    return {"failed": rec["failed"], "reason": rec["reason"], "t_end_s": float(rec["time"][-1]),
            "t_peak_s": float(rec["time"][k]), "q_peak_kpa": float(rec["qbar"][k] / 1e3),
            "alpha_peak_deg": float(np.degrees(rec["alpha"][k])), "qalpha_peak_kpa_deg": float(rec["qalpha"][k] / 1e3),
            "wind_h_at_peak_mps": float(rec["wind_h"][k]),
            "hold_peak_kpa_deg": float(hold[j] / 1e3), "hold_peak_t_s": float(rec["time"][j]),
            "hold_alpha_at_peak_deg": float(hold[j] / max(rec["qbar"][j], 1.0)),
            "wind_h_max_mps": float(rec["wind_h"].max())}


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.load_relief.qalpha_floor --help``)."""

    policies: list[str] = arg(default_factory=lambda: ["zero"], metavar="POLICY")
    """registered names, SB3 .zip files or train.py run folders"""
    suite: str = arg("slender-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the suite flown"""
    seeds: int = arg(10, lo=1, hi=10_000)
    """validation seeds 0 .. n-1"""
    schedule: list[str] = arg(default_factory=list, extend=True, metavar="YAML")
    """also fly the gain-scheduled PID of these schedule files (a repeated flag adds)"""
    plain: list[str] = arg(default_factory=list, extend=True, metavar="YAML")
    """also fly the plain designs (integral kept) that these load-relief schedules' rows record"""
    unlimited: bool = False
    """lift the q-alpha limit (1e9 Pa deg): every flight goes to the mission's end, so the peaks are those of
    the whole flight"""


def main(argv: list[str] | None = None) -> int:
    """Fly, print a line per episode and a summary per policy and condition."""
    from lvgym.benchmark.registry import resolve_policy

    from lvgym.baselines.design.flexdesign import plain_schedule
    from lvgym.baselines.pid import GainSchedule

    prog = "python -m experiments.load_relief.qalpha_floor"
    a = parse(Args, argv, prog, __doc__)
    suite = get_suite(a.suite)
    specs = [(n, resolve_policy(n, command_name(prog))) for n in a.policies]
    specs += [(f"file:{i}", PolicySpec(f"file:{i}", "lvgym.baselines.pid:GainScheduledPIDPolicy", (("schedule", p),)))
              for i, p in enumerate(a.schedule)]
    specs += [(f"plain:{i}", PolicySpec(f"plain:{i}", "lvgym.baselines.pid:GainScheduledPIDPolicy",
                                        (("schedule", plain_schedule(GainSchedule.load(p))),)))
              for i, p in enumerate(a.plain)]
    for name, spec in specs:
        for cond in suite.conditions:
            cond = cond.with_options(qalpha_limit_pa_deg=1e9) if a.unlimited else cond
            holds = []
            fails = 0
            for seed in suite.seeds("validation", a.seeds):
                s = summary(fly(spec, cond, seed))
                holds.append(s["hold_peak_kpa_deg"])
                fails += s["failed"]
                print(f"{name:12s} {cond.model:8s} seed {seed:2d}  {'FAIL' if s['failed'] else 'ok  '} end {s['t_end_s']:5.2f} s"
                      f"  peak q-alpha {s['qalpha_peak_kpa_deg']:6.1f} kPa deg at {s['t_peak_s']:5.2f} s"
                      f" (q {s['q_peak_kpa']:5.0f} kPa, alpha {s['alpha_peak_deg']:.3f} deg, wind {s['wind_h_at_peak_mps']:.1f} m/s)"
                      f"  hold {s['hold_peak_kpa_deg']:6.1f} kPa deg at {s['hold_peak_t_s']:5.2f} s"
                      f" (alpha {s['hold_alpha_at_peak_deg']:.3f} deg), wind max {s['wind_h_max_mps']:.1f} m/s", flush=True)
            print(f"{name} {cond.model}: {fails}/{len(holds)} failed; attitude-hold peak q-alpha "
                  f"{min(holds):.0f}-{max(holds):.0f} kPa deg (median {np.median(holds):.0f})", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
