"""``lvgym curves``: the learning curves of training runs, from their run folders, against env steps and against
wall time: each validation's score per condition, the training rollouts' episodes, and over the seeds of a
configuration the interquartile mean (IQM) with its 95 % interval.

    lvgym curves runs/ppo-fast-smile-v2-nonrigid-s0-* --out results/curves
    lvgym curves runs/fast-s{0,1,2} --reference lqg-front/nonrigid=0.59 --out results/curves

The validations. Each run folder's ``evaluations.json`` (written at every validation by
:class:`lvgym.agents.training.callbacks.CheckpointCallback`: the validation seeds, never the test seeds): per
condition the mean ``score_v2`` where the suite charges flyability (protocol v2), else the failure-charged
``score`` of v1; the steps and the wall time ``train_wall_s`` [s] of the validation (every segment of a resumed
run included; runs made before that field existed take it from SB3's ``progress_*.csv``, ``time/time_elapsed`` at
the validation's step, segments added up).

The training rollouts. The run's ``progress_*.csv``: after each rollout the mean cost of the episodes that ended
in it, ``rollout/cost_mean`` = minus their mean return (written by ``--algo ppo-fast``; for an SB3 run minus
``rollout/ep_rew_mean``, its monitor's mean return of the last 100 episodes), which is the episodes' mean
``score_v2`` when the run's reward is the score, and otherwise the env's own charges; with its
``rollout/failure_rate`` (ppo-fast).

Seeds. Runs whose names differ only in the seed (``...-s<N>`` with an optional ``-<date>-<time>`` after it, as
``lvgym train`` names them) are one configuration. At every step each of its runs reached, the IQM over those
runs with its stratified-bootstrap interval (:func:`lvgym.benchmark.stats.iqm`); against wall time at the runs'
mean wall time of that step.

Writes with ``--out``: ``curves.csv`` (one row per run, validation and condition), ``rollouts.csv`` (one row
per run and rollout), ``iqm.csv`` (per configuration, source, condition and step: the IQM, its interval, the
runs) and ``curves.png`` (one column per condition and one for the rollouts; the top row against env steps, the
bottom row against wall time; each run thin, each configuration's IQM bold with its interval shaded, the
references dashed). Prints a table: per run and condition the first and the best validation score, the steps
and wall minutes of the best, and the wall minutes at which the score first reached each reference with no
failure (``-`` if never; a reference ``NAME/CONDITION`` is for that condition only), then the last IQM of each
configuration.
"""

from __future__ import annotations

import csv
import json
import math
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lvgym.commandline import arg, command_name, parse
from lvgym.errors import ConfigError

__all__ = ["config_name", "iqm_rows", "load_curves", "load_rollouts", "main", "reached", "summary_rows"]

FIELDS = ("run", "num_timesteps", "train_wall_s", "condition", "score", "failure_rate", "rate_error_rad")
ROLLOUT_FIELDS = ("run", "num_timesteps", "train_wall_s", "cost", "failure_rate")
IQM_FIELDS = ("config", "source", "condition", "num_timesteps", "train_wall_s", "iqm", "low", "high", "runs")
#: the seed (and the time stamp ``lvgym train`` adds) at the end of a run's name
_SEED = re.compile(r"-s\d+(-\d{8}-\d{6})?$")
#: the most steps of a curve whose IQM is bootstrapped (the rollouts' curve is thinned to them)
MAX_POINTS = 200


def _progress_rows(run: Path) -> list[tuple[dict[str, str], float]]:
    """Every row of the run's SB3 progress files in order, each with the wall seconds of the segments before it."""
    out: list[tuple[dict[str, str], float]] = []
    offset = 0.0
    for path in sorted(run.glob("progress_*.csv")):
        last = 0.0
        with open(path, encoding="utf-8") as f:
            for row in csv.DictReader(f):
                out.append((row, offset))
                if row.get("time/time_elapsed"):
                    last = float(row["time/time_elapsed"])
        offset += last
    return out


def _elapsed_from_progress(run: Path) -> dict[int, float]:
    """``{total_timesteps: wall seconds}`` from SB3's progress files, segments added up in order."""
    return {int(float(row["time/total_timesteps"])): offset + float(row["time/time_elapsed"])
            for row, offset in _progress_rows(run) if row.get("time/total_timesteps") and row.get("time/time_elapsed")}


def load_curves(run: str | Path) -> list[dict[str, Any]]:
    """The rows (:data:`FIELDS`) of one run folder's validations; ``score`` is the condition's mean ``score_v2``
    where the validation has it, else its mean v1 ``score`` (and ``failure_rate`` then v2's failed or unflyable
    share)."""
    run = Path(run)
    path = run / "evaluations.json"
    if not path.is_file():
        raise FileNotFoundError(f"{run}: no evaluations.json (a run without validations, or not a run folder)")
    evaluations = json.loads(path.read_text(encoding="utf-8"))
    progress: dict[int, float] | None = None
    rows = []
    for e in evaluations:
        step = int(e["num_timesteps"])
        wall = e.get("train_wall_s")
        if wall is None:
            progress = _elapsed_from_progress(run) if progress is None else progress
            at = [s for s in progress if s <= step]
            wall = progress[max(at)] if at else float("nan")
        for name, c in e["conditions"].items():
            v2 = "score_v2_mean" in c
            rows.append({"run": run.name, "num_timesteps": step, "train_wall_s": float(wall),
                         "condition": name.split("/")[-1], "score": float(c["score_v2_mean" if v2 else "score_mean"]),
                         "failure_rate": float(c["failure_rate_v2" if v2 and "failure_rate_v2" in c else "failure_rate"]),
                         "rate_error_rad": float(c["rate_error_rad_mean"])})
    return rows


def load_rollouts(run: str | Path) -> list[dict[str, Any]]:
    """The rows (:data:`ROLLOUT_FIELDS`) of one run's training rollouts (the module docstring); empty for a run
    whose progress files log no episodes."""
    run = Path(run)
    rows = []
    for row, offset in _progress_rows(run):
        cost = row.get("rollout/cost_mean") or ""
        if not cost and row.get("rollout/ep_rew_mean"):
            cost = str(-float(row["rollout/ep_rew_mean"]))
        if not cost or not row.get("time/total_timesteps"):
            continue
        wall = row.get("time/train_wall_s") or ""
        wall_s = float(wall) if wall else offset + float(row.get("time/time_elapsed") or "nan")
        fail = row.get("rollout/failure_rate") or ""
        rows.append({"run": run.name, "num_timesteps": int(float(row["time/total_timesteps"])), "train_wall_s": wall_s,
                     "cost": float(cost), "failure_rate": float(fail) if fail else float("nan")})
    return rows


def reached(rows: list[dict[str, Any]], reference: float) -> float | None:
    """Wall time [s] of the first validation (rows of one run and condition, in order) scoring at or below
    ``reference`` with no failure, or None."""
    for r in rows:
        if r["failure_rate"] == 0.0 and r["score"] <= reference:
            return r["train_wall_s"]
    return None


def summary_rows(rows: list[dict[str, Any]], references: dict[str, float]) -> list[dict[str, Any]]:
    """Per run and condition: first and best score (best: fewest failures, then lowest score), the steps
    and wall time of the best, and the wall time at which each reference was reached."""
    out = []
    keys = sorted({(r["run"], r["condition"]) for r in rows})
    for run, cond in keys:
        mine = [r for r in rows if r["run"] == run and r["condition"] == cond]
        best = min(mine, key=lambda r: (r["failure_rate"], r["score"]))
        out.append({"run": run, "condition": cond, "first": mine[0]["score"], "best": best["score"],
                    "best_failure_rate": best["failure_rate"], "best_steps": best["num_timesteps"],
                    "best_wall_s": best["train_wall_s"],
                    **{f"reached {name}": reached(mine, value) if _applies(name, cond) else None
                       for name, value in references.items()}})
    return out


def config_name(run: str) -> str:
    """The configuration of a run's name: the name without its seed (and time stamp) at the end."""
    return _SEED.sub("", run) or run


def iqm_rows(rows: list[dict[str, Any]], source: str, key: str, max_points: int = MAX_POINTS) -> list[dict[str, Any]]:
    """Per configuration (:func:`config_name`) and condition (``rows`` without one: ``rollouts``), at every step
    that each of its runs reached, the IQM of ``key`` over the runs with its interval (:data:`IQM_FIELDS`);
    ``source``: ``validation`` or ``rollouts``. At most ``max_points`` steps per curve (evenly thinned)."""
    import numpy as np

    from lvgym.benchmark.stats import iqm

    out = []
    groups: dict[tuple[str, str], dict[str, dict[int, dict[str, Any]]]] = {}
    for r in rows:
        cond = r.get("condition", "rollouts")
        groups.setdefault((config_name(r["run"]), cond), {}).setdefault(r["run"], {})[r["num_timesteps"]] = r
    for (config, cond), runs in sorted(groups.items()):
        steps = sorted(set.intersection(*(set(v) for v in runs.values())))
        if len(steps) > max_points:
            steps = [steps[i] for i in np.linspace(0, len(steps) - 1, max_points).round().astype(int)]
        for step in steps:
            values = np.array([[runs[name][step][key]] for name in sorted(runs)], dtype=float)
            if not np.all(np.isfinite(values)):
                continue
            mid, low, high = iqm({"x": values})["x"]
            out.append({"config": config, "source": source, "condition": cond, "num_timesteps": step,
                        "train_wall_s": float(np.mean([runs[name][step]["train_wall_s"] for name in runs])),
                        "iqm": mid, "low": low, "high": high, "runs": len(runs)})
    return out


def _applies(reference: str, condition: str) -> bool:
    """A reference ``NAME/CONDITION`` is for that condition only; a plain ``NAME`` for every condition."""
    _, sep, cond = reference.partition("/")
    return not sep or cond == condition


def _plot(rows: list[dict[str, Any]], rollouts: list[dict[str, Any]], iqms: list[dict[str, Any]],
          references: dict[str, float], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [("validation", c) for c in sorted({r["condition"] for r in rows})]
    panels += [("rollouts", "rollouts")] if rollouts else []
    axes_x = (("num_timesteps", 1e-6, "env steps [M]"), ("train_wall_s", 1 / 60.0, "training wall time [min]"))
    fig, axes = plt.subplots(2, len(panels), figsize=(5.5 * len(panels), 7.5), squeeze=False)
    colours = {name: f"C{i}" for i, name in enumerate(sorted({config_name(r["run"]) for r in rows + rollouts}))}
    for col, (source, cond) in enumerate(panels):
        mine = rollouts if source == "rollouts" else [r for r in rows if r["condition"] == cond]
        key = "cost" if source == "rollouts" else "score"
        for row_i, (x, scale, label) in enumerate(axes_x):
            ax = axes[row_i][col]
            for run in sorted({r["run"] for r in mine}):
                pts = [r for r in mine if r["run"] == run]
                ax.plot([r[x] * scale for r in pts], [r[key] for r in pts], lw=0.8, alpha=0.5,
                        color=colours[config_name(run)])
                failed = [r for r in pts if source == "validation" and r["failure_rate"] > 0]
                if failed:
                    ax.scatter([r[x] * scale for r in failed], [r[key] for r in failed], marker="x", s=12,
                               color="k", zorder=3)
            for config in sorted({r["config"] for r in iqms}):
                band = [r for r in iqms if r["config"] == config and r["source"] == source and r["condition"] == cond
                        and r["runs"] > 1]
                if band:
                    xs = [r[x] * scale for r in band]
                    ax.plot(xs, [r["iqm"] for r in band], lw=2, color=colours.get(config, "k"),
                            label=f"{config}: IQM of {band[0]['runs']} seeds")
                    ax.fill_between(xs, [r["low"] for r in band], [r["high"] for r in band], alpha=0.2,
                                    color=colours.get(config, "k"))
            for name, value in references.items():
                if source == "validation" and _applies(name, cond):
                    ax.axhline(value, ls="--", color="0.4", lw=1, label=name)
            ax.set_title(f"validation, {cond}" if source == "validation" else "training rollouts: minus the return")
            ax.set_xlabel(label)
            ax.set_ylabel("score_v2 [rad] (lower is better)" if source == "validation" else "episode cost")
            ax.grid(alpha=0.3)
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _reference(text: str, option: str = "--reference") -> tuple[str, float]:
    """``NAME[/CONDITION]=SCORE`` as (name, score)."""
    name, sep, value = text.partition("=")
    try:
        if not sep or not name:
            raise ValueError
        return name, float(value)
    except ValueError:
        raise ConfigError(option, text, "NAME[/CONDITION]=SCORE, e.g. lqg/nonrigid=0.67") from None


def _checked(items: list[str], option: str) -> list[str]:
    """``items``, each a reference (:func:`_reference`)."""
    for x in items:
        _reference(x, option)
    return items


@dataclass
class Args:
    """Command-line arguments (``lvgym curves --help``)."""

    runs: list[str] = arg(positional=True, metavar="RUN")
    """run folders (with evaluations.json; their progress_*.csv give the rollouts' curve)"""
    reference: list[str] = arg(default_factory=list, nargs="*", metavar="NAME[/CONDITION]=SCORE",
                               check=lambda option, items: _checked(items, option))
    """scores to reach, e.g. a baseline's validation score"""
    out: str | None = None
    """folder for curves.csv, rollouts.csv, iqm.csv and curves.png (default: print only)"""


def _write(path: Path, fields: tuple[str, ...], rows: list[dict[str, Any]]) -> None:
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)


def main(argv: list[str] | None = None) -> None:
    """Print the tables; write the curves' CSV files and curves.png with --out."""
    prog = "lvgym curves"
    args = parse(Args, argv, prog, __doc__)
    references = dict(_reference(x) for x in args.reference)
    try:
        rows = [r for run in args.runs for r in load_curves(run)]
    except FileNotFoundError as exc:                 # one line on stderr, as a refused option
        sys.stderr.write(f"{command_name(prog)}: {exc}\n")
        raise SystemExit(2) from None
    rollouts = [r for run in args.runs for r in load_rollouts(run)]
    iqms = iqm_rows(rows, "validation", "score") + iqm_rows(rollouts, "rollouts", "cost")
    table = summary_rows(rows, references)
    minutes = lambda s: "-" if s is None or math.isnan(s) else f"{s / 60.0:.1f}"             # noqa: E731
    head = ["run", "condition", "first", "best", "best failures", "best at [M steps]", "best at [min]",
            *[f"reached {n} [min]" for n in references]]
    print("| " + " | ".join(head) + " |\n|" + "---|" * len(head))
    for t in table:
        cells = [t["run"], t["condition"], f"{t['first']:.4f}", f"{t['best']:.4f}", f"{t['best_failure_rate']:.0%}",
                 f"{t['best_steps'] / 1e6:.2f}", minutes(t["best_wall_s"]),
                 *[minutes(t[f"reached {n}"]) for n in references]]
        print("| " + " | ".join(cells) + " |")
    last = {}
    for r in iqms:
        last[(r["config"], r["source"], r["condition"])] = r
    if any(r["runs"] > 1 for r in last.values()):
        print("\n| configuration | curve | condition | seeds | at [M steps] | at [min] | IQM [95 % interval] |\n"
              "|---|---|---|---:|---:|---:|---|")
        for (config, source, cond), r in sorted(last.items()):
            if r["runs"] > 1:
                print(f"| {config} | {source} | {cond} | {r['runs']} | {r['num_timesteps'] / 1e6:.2f} | "
                      f"{minutes(r['train_wall_s'])} | {r['iqm']:.4f} [{r['low']:.4f}, {r['high']:.4f}] |")
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        _write(out / "curves.csv", FIELDS, rows)
        _write(out / "rollouts.csv", ROLLOUT_FIELDS, rollouts)
        _write(out / "iqm.csv", IQM_FIELDS, iqms)
        _plot(rows, rollouts, iqms, references, out / "curves.png")
        print(f"curves in {out}/: curves.csv, rollouts.csv, iqm.csv, curves.png", file=sys.stderr)


if __name__ == "__main__":
    main()
