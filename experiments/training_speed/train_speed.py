"""Training throughput of ``train.py`` settings, measured side by side (docs/training.md, "Training speed").

    python -m experiments.training_speed.train_speed --steps 300000 --repeats 2 \\
        --common "--env-id lvgym/SmileAscent-v1 --residual lqg --residual-scale 0.05 --history 4" \\
        --variant default "" --variant threads2 "--torch-threads 2" --variant epochs5 "--hp algo.n_epochs=5"

Each variant is a short ``train.py`` run (its own process, ``--eval-freq 0``, no wall-time checkpoints, in a temporary
runs folder) of ``--steps`` env steps; the variants take turns, ``--repeats`` times, so that a change of the machine's
load falls on all of them alike. From each run's progress table (SB3's ``time/`` entries, written after every rollout
and update): env steps per second of wall time after the first rollout-and-update (``steps/s``: start-up, imports and
the first compilation left out), and the env's share of the wall time (``time/env_share``,
:class:`lvgym.agents.training.timing.EnvClock`: the env and a residual's baselines; the rest is the learner: the
policy's forward passes, the PPO epochs). Printed as a Markdown table: the median over the repeats and each repeat.
Throughput only: whether a faster setting learns as well per env step is a training experiment (several seeds, learning
curves against wall time; ``lvgym curves``, :mod:`lvgym.agents.training.curves`).
"""

from __future__ import annotations

import csv
import shlex
import statistics
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lvgym.commandline import arg, command_name, fail, parse
from lvgym.errors import ConfigError

__all__ = ["throughput", "run_variant", "speed_table"]

PROG = "python -m experiments.training_speed.train_speed"
TRAIN = Path(__file__).resolve().parents[2] / "train.py"


def throughput(progress_csv: Path) -> dict[str, float]:
    """``steps_per_s`` after the first row of a run's progress table, ``env_share`` at its last row, and
    ``rows`` (how many rollouts it logged)."""
    with open(progress_csv, newline="") as f:
        rows = [r for r in csv.DictReader(f) if r.get("time/total_timesteps")]
    if len(rows) < 2:
        raise ValueError(f"{progress_csv}: {len(rows)} rollout(s) logged; at least 2 are needed (raise --steps)")
    first, last = rows[0], rows[-1]
    steps = float(last["time/total_timesteps"]) - float(first["time/total_timesteps"])
    wall = float(last["time/train_wall_s"]) - float(first["time/train_wall_s"])
    share = float(last["time/env_share"]) if last.get("time/env_share") else float("nan")
    return {"steps_per_s": steps / wall, "env_share": share, "rows": float(len(rows))}


def run_variant(common: list[str], extra: list[str], steps: int, runs_dir: Path, name: str) -> dict[str, float]:
    """One short ``train.py`` run of ``common + extra`` and its :func:`throughput`."""
    cmd = [sys.executable, str(TRAIN), *common, *extra, "--total-timesteps", str(steps), "--eval-freq", "0",
           "--checkpoint-interval-s", "0", "--checkpoint-freq", str(10 * steps), "--no-progress",
           "--runs-dir", str(runs_dir), "--name", name]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        tail = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["no output"]
        raise RuntimeError(f"{name}: train.py exited {done.returncode}: {tail[0]}")
    csvs = sorted((runs_dir / name).glob("progress_*.csv"))
    return throughput(csvs[-1])


def speed_table(results: dict[str, list[dict[str, float]]]) -> str:
    """Markdown: per variant the median steps/s over the repeats (each repeat), the ratio to the first
    variant's median and the env's share of the wall time."""
    names = list(results)
    base = statistics.median(r["steps_per_s"] for r in results[names[0]])
    lines = ["| variant | env steps/s (median) | each repeat | vs first | env share |", "|---|---:|---|---:|---:|"]
    for n in names:
        sps = [r["steps_per_s"] for r in results[n]]
        med = statistics.median(sps)
        share = statistics.median(r["env_share"] for r in results[n])
        lines.append(f"| {n} | {med:,.0f} | {', '.join(f'{x:,.0f}' for x in sps)} | {med / base:.2f} | {share:.2f} |")
    return "\n".join(lines) + "\n"


def _split(option: str, text: str) -> list[str]:
    """``text`` split as a shell would (a ConfigError naming ``option`` if it cannot be)."""
    try:
        return shlex.split(text)
    except ValueError as exc:
        raise ConfigError(option, text, f"train.py arguments as one string ({exc})") from None


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.training_speed.train_speed --help``)."""

    variant: list[tuple[str, str]] = arg(metavar=("NAME", "ARGS"))
    """a variant's name and its extra train.py arguments (one string, may be empty); repeat the flag"""
    common: str = "--env-id lvgym/SmileAscent-v1"
    """train.py arguments every variant shares (one string)"""
    steps: int = arg(300_000, lo=1, hi=10**9)
    """env steps per run"""
    repeats: int = arg(2, lo=1, hi=100)
    """runs of each variant, in turn"""
    keep: str | None = None
    """keep the runs in this folder (default: a temporary one)"""

    def __post_init__(self) -> None:
        names = [v[0] for v in self.variant]
        if len(set(names)) != len(names):
            raise ConfigError("--variant", names, "distinct names")
        _split("--common", self.common)
        for _, args in self.variant:
            _split("--variant", args)


def main(argv: list[str] | None = None) -> int:
    """Run the variants in turn, print the table."""
    a = parse(Args, argv, PROG, __doc__)
    names = [v[0] for v in a.variant]
    common = shlex.split(a.common)
    extras = {n: shlex.split(args) for n, args in a.variant}
    results: dict[str, list[dict[str, Any]]] = {n: [] for n in names}
    with tempfile.TemporaryDirectory(prefix="lvgym-speed-") as tmp:
        runs = Path(a.keep) if a.keep else Path(tmp)
        for k in range(a.repeats):
            for n in names:
                try:
                    r = run_variant(common, extras[n], a.steps, runs, f"{n}-r{k}")
                except (RuntimeError, ValueError) as exc:
                    fail(command_name(PROG), exc)
                results[n].append(r)
                print(f"{n} repeat {k}: {r['steps_per_s']:,.0f} env steps/s, env share {r['env_share']:.2f}",
                      file=sys.stderr, flush=True)
    sys.stdout.write(speed_table(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
