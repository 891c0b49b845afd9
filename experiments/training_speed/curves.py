"""Learning curves of training runs against wall time: the validation score of each condition after each
validation, per run, and when each run first reached a reference score.

    python -m experiments.training_speed.curves runs/v1/robust-*  --reference lqg/nonrigid=0.6715 lqg/rigid=0.6271 --out results/curves

Reads each run folder's ``evaluations.json`` (written by :class:`lvgym.agents.training.callbacks.CheckpointCallback` at
every validation: the validation seeds, never the test seeds). The wall time of a validation is its
``train_wall_s`` [s] (every segment of a resumed run included); runs made before that field existed take
it from SB3's ``progress_*.csv`` (``time/time_elapsed`` at the validation's step, segments added up).
Writes ``curves.csv`` (one row per run, validation and condition), ``curves.png`` (score against wall
minutes, one panel per condition, one line per run, the references dashed) and prints a table: per run
and condition the first and the best validation score, the steps and wall minutes of the best, and the
wall minutes at which the score first reached each reference with no failure (``-`` if never; a
reference ``NAME/CONDITION`` is for that condition only).
"""

from __future__ import annotations

import csv
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lvgym.commandline import arg, command_name, parse
from lvgym.errors import ConfigError

__all__ = ["load_curves", "main", "reached", "summary_rows"]

FIELDS = ("run", "num_timesteps", "train_wall_s", "condition", "score", "failure_rate", "rate_error_rad")


def _elapsed_from_progress(run: Path) -> dict[int, float]:
    """``{total_timesteps: wall seconds}`` from SB3's progress files, segments added up in order."""
    out: dict[int, float] = {}
    offset = 0.0
    for path in sorted(run.glob("progress_*.csv")):
        last = 0.0
        with open(path, encoding="utf-8") as f:
            for row in csv.DictReader(f):
                if row.get("time/total_timesteps") and row.get("time/time_elapsed"):
                    last = float(row["time/time_elapsed"])
                    out[int(float(row["time/total_timesteps"]))] = offset + last
        offset += last
    return out


def load_curves(run: str | Path) -> list[dict[str, Any]]:
    """The rows (:data:`FIELDS`) of one run folder's validations."""
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
            rows.append({"run": run.name, "num_timesteps": step, "train_wall_s": float(wall),
                         "condition": name.split("/")[-1], "score": float(c["score_mean"]),
                         "failure_rate": float(c["failure_rate"]), "rate_error_rad": float(c["rate_error_rad_mean"])})
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


def _applies(reference: str, condition: str) -> bool:
    """A reference ``NAME/CONDITION`` is for that condition only; a plain ``NAME`` for every condition."""
    _, sep, cond = reference.partition("/")
    return not sep or cond == condition


def _plot(rows: list[dict[str, Any]], references: dict[str, float], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    conditions = sorted({r["condition"] for r in rows})
    fig, axes = plt.subplots(1, len(conditions), figsize=(6 * len(conditions), 4), squeeze=False)
    for ax, cond in zip(axes[0], conditions):
        for run in sorted({r["run"] for r in rows}):
            mine = [r for r in rows if r["run"] == run and r["condition"] == cond]
            ax.plot([r["train_wall_s"] / 60.0 for r in mine], [r["score"] for r in mine], marker="o", ms=3, label=run)
            failed = [r for r in mine if r["failure_rate"] > 0]
            if failed:
                ax.scatter([r["train_wall_s"] / 60.0 for r in failed], [r["score"] for r in failed], marker="x",
                           color="k", zorder=3, label="validation with failures" if run == mine[0]["run"] else None)
        for name, value in references.items():
            if not _applies(name, cond):
                continue
            ax.axhline(value, ls="--", color="0.4", lw=1, label=name)
        ax.set_title(f"validation score, {cond}")
        ax.set_xlabel("training wall time [min]")
        ax.set_ylabel("score [rad] (lower is better)")
        ax.grid(alpha=0.3)
    for ax in axes[0]:
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
    """Command-line arguments (``python -m experiments.training_speed.curves --help``)."""

    runs: list[str] = arg(positional=True, metavar="RUN")
    """run folders (with evaluations.json)"""
    reference: list[str] = arg(default_factory=list, nargs="*", metavar="NAME[/CONDITION]=SCORE",
                               check=lambda option, items: _checked(items, option))
    """scores to reach, e.g. a baseline's validation score"""
    out: str | None = None
    """folder for curves.csv and curves.png (default: print only)"""


def main(argv: list[str] | None = None) -> None:
    """Print the table; write curves.csv and curves.png with --out."""
    prog = "python -m experiments.training_speed.curves"
    args = parse(Args, argv, prog, __doc__)
    references = dict(_reference(x) for x in args.reference)
    try:
        rows = [r for run in args.runs for r in load_curves(run)]
    except FileNotFoundError as exc:                 # one line on stderr, as a refused option
        sys.stderr.write(f"{command_name(prog)}: {exc}\n")
        raise SystemExit(2) from None
    table = summary_rows(rows, references)
    minutes = lambda s: "-" if s is None else f"{s / 60.0:.1f}"             # noqa: E731
    head = ["run", "condition", "first", "best", "best failures", "best at [M steps]", "best at [min]",
            *[f"reached {n} [min]" for n in references]]
    print("| " + " | ".join(head) + " |\n|" + "---|" * len(head))
    for t in table:
        cells = [t["run"], t["condition"], f"{t['first']:.4f}", f"{t['best']:.4f}", f"{t['best_failure_rate']:.0%}",
                 f"{t['best_steps'] / 1e6:.2f}", minutes(t["best_wall_s"]),
                 *[minutes(t[f"reached {n}"]) for n in references]]
        print("| " + " | ".join(cells) + " |")
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        with open(out / "curves.csv", "w", newline="", encoding="utf-8") as f:
            w = csv.DictWriter(f, fieldnames=FIELDS)
            w.writeheader()
            w.writerows(rows)
        _plot(rows, references, out / "curves.png")
        print(f"curves in {out}/: curves.csv, curves.png", file=sys.stderr)


if __name__ == "__main__":
    main()
