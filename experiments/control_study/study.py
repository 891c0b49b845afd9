"""The thesis's SMILE control study (thesis 6.3, reference Case C) in kind.

``python -m experiments.control_study.study [--wind profile] [--out docs/figures]``

Flies ``lvgym/SmileAscent-v0`` for 60 s, rigid and non-rigid, uncontrolled, with the thesis's single PID
gains, the thesis's gain schedule (Table 6.10), and our own tuning (``schedules/smile.yaml``: its
28.8 s row as single gains, and the whole schedule). Writes rate-error and cumulative-error plots like
the thesis's figures 6.20-6.23 (``control_rates_<controller>.png``, ``control_cumulative_<controller>.png``)
and ``control_study.json`` with the cumulative pitch and yaw rate errors [rad] and the end state.
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import lvgym  # noqa: F401
from lvgym.benchmark.policy import ZeroPolicy
from lvgym.commandline import arg, parse

from lvgym.baselines.pid import GainSchedule, PIDPolicy, smile_scheduled_pid, smile_single_pid

THESIS = {  # cumulative rate error over 60 s [rad] (thesis 6.3.1, figures 6.21 and 6.23)
    "pid-thesis": {"rigid": (0.125, 0.038), "nonrigid": (0.115, 0.039)},
    "gs-pid-thesis": {"rigid": (0.042, 0.06), "nonrigid": (0.165, 0.15)},
}


def controllers() -> dict[str, Any]:
    """The study's controllers: name -> a function of the env that builds the policy for it."""
    ours = GainSchedule.load("smile")
    i = int(np.argmin(np.abs(np.array([r["time_s"] for r in ours.meta["rows"]]) - 28.8)))
    single = ours.gains(ours.points[i])
    return {"uncontrolled": lambda env: ZeroPolicy(),
            "pid-thesis": lambda env: smile_single_pid(env, name="pid-thesis"),
            "gs-pid-thesis": lambda env: smile_scheduled_pid(env, "smile_thesis", name="gs-pid-thesis"),
            "pid-tuned": lambda env: PIDPolicy(*single, env=env, name="pid-tuned"),
            "gs-pid-tuned": lambda env: smile_scheduled_pid(env, "smile", name="gs-pid-tuned")}


def fly(make: Any, model: str, wind: str = "profile", seed: int = 0, **options: Any) -> dict[str, np.ndarray]:
    """One 60 s episode of the policy ``make(env)``; returns time, pitch/yaw rate errors, gimbal and
    cumulative errors per step."""
    env = gym.make("lvgym/SmileAscent-v0", model=model, wind=wind, **options)
    policy = make(env)
    lay = env.unwrapped.observation_layout
    cols = [lay.index(n) for n in ("pitch_rate_error", "yaw_rate_error", "gimbal_pitch", "gimbal_yaw")]
    obs, info = env.reset(seed=seed)
    policy.reset()
    rows, done = [], False
    while not done:
        action = policy.act(obs, info)
        obs, _, term, trunc, info = env.step(action)
        done = term or trunc
        cum = info["cumulative_rate_error"]
        rows.append((info["time"], *obs[cols], cum[1], cum[2]))
    a = np.array(rows, dtype=float)
    return {"t": a[:, 0], "pitch": a[:, 1], "yaw": a[:, 2], "gimbal": a[:, 3:5], "cum_pitch": a[:, 5],
            "cum_yaw": a[:, 6], "termination": info.get("termination", ""), "t_end": float(a[-1, 0])}


def _plots(name: str, runs: dict[str, dict], out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for ax, axis in zip(axes, ("pitch", "yaw")):
        for model, style in (("rigid", "-"), ("nonrigid", "--")):
            r = runs[model]
            ax.plot(r["t"], r[axis], style, lw=0.8, label=model)
        ax.set_ylabel(f"{axis} rate error [rad/s]")
        ax.grid(alpha=0.3)
        ax.axvspan(43, 45, color="0.9")
    axes[0].legend()
    axes[0].set_title(f"SMILE, {name}: rate error (cf. thesis fig. 6.20 / 6.22); grey: staging coast")
    axes[-1].set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(out / f"control_rates_{name}.png", dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(8, 4))
    for model, style in (("rigid", "-"), ("nonrigid", "--")):
        r = runs[model]
        ax.plot(r["t"], r["cum_pitch"], style, color="C0", label=f"pitch, {model}")
        ax.plot(r["t"], r["cum_yaw"], style, color="C1", label=f"yaw, {model}")
    ax.axvspan(43, 45, color="0.9")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("cumulative |rate error| [rad]")
    ax.set_title(f"SMILE, {name}: cumulative error (cf. thesis fig. 6.21 / 6.23)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / f"control_cumulative_{name}.png", dpi=110)
    plt.close(fig)


def study(wind: str = "profile", out: Path | None = None, names=None, log=print) -> dict[str, Any]:
    results: dict[str, Any] = {}
    for name, make in controllers().items():
        if names and name not in names:
            continue
        runs = {model: fly(make, model, wind) for model in ("rigid", "nonrigid")}
        results[name] = {m: {"cum_pitch_rad": float(r["cum_pitch"][-1]), "cum_yaw_rad": float(r["cum_yaw"][-1]),
                             "cum_pitch_before_staging_rad": float(np.interp(43.0, r["t"], r["cum_pitch"])),
                             "cum_yaw_before_staging_rad": float(np.interp(43.0, r["t"], r["cum_yaw"])),
                             "max_abs_rate_error_radps": float(np.max(np.abs(np.r_[r["pitch"], r["yaw"]]))),
                             "t_end_s": r["t_end"], "termination": r["termination"]} for m, r in runs.items()}
        for m, v in results[name].items():
            log(f"{name:14s} {m:9s} pitch {v['cum_pitch_rad']:.4f}  yaw {v['cum_yaw_rad']:.4f} rad  "
                f"(before staging {v['cum_pitch_before_staging_rad']:.4f} / {v['cum_yaw_before_staging_rad']:.4f})"
                f"  max {v['max_abs_rate_error_radps']:.4f} rad/s  end {v['t_end_s']:.1f} s {v['termination']}")
        if out is not None:
            _plots(f"{name}_{wind}", runs, out)
    return results


def _wind_tiers() -> tuple[str, ...]:
    from lvgym.envs.spec import WIND_TIERS

    return tuple(WIND_TIERS)


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.control_study.study --help``)."""

    wind: list[str] = arg(default_factory=lambda: ["none", "profile"], nargs="*", choices=_wind_tiers)
    """the wind tiers flown, one study each"""
    out: str = "docs/figures"
    """folder of the figures and control_study.json"""


def main(argv: list[str] | None = None) -> int:
    """Run the study for every wind, write its figures and JSON."""
    a = parse(Args, argv, "python -m experiments.control_study.study", __doc__)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    doc = {"thesis": THESIS}
    for wind in a.wind:
        print(f"--- wind {wind}")
        doc[wind] = study(wind, out)
    with open(out / "control_study.json", "w") as f:
        json.dump(doc, f, indent=1)
    print(f"wrote {out / 'control_study.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
