"""Agents compared over their training runs, across results folders (IQM and probability of improvement).

``evaluate.py`` compares policies within one evaluation. A training configuration (an agent) is judged
on several training runs, often evaluated apart (one ``evaluate.py`` per configuration, each with the
classical baseline beside it). This reads their ``episodes.csv`` and, per (suite, condition):

- every agent's ``(runs, episodes)`` matrix of ``metric`` on the seeds all of them flew: an agent is the
  label ``<agent>-s<seed>`` with its runs (:data:`.compare.RUN_LABEL`); any other policy (``lqg``) is an
  agent of one run;
- the IQM of each matrix with its stratified-bootstrap interval (:func:`.stats.iqm`), which resamples the
  runs within each episode (the episodes stay fixed), so it holds the spread of the training seeds on these
  test seeds (an agent of one run has an interval of zero width);
- the probability of improvement of every agent over every other (:func:`.stats.probability_of_improvement`:
  the chance that a run of the first scores lower on an episode than a run of the second, averaged over
  the episodes; 0.5: neither is better), with its interval.

A policy label found in two folders must have the same values on its common seeds (``lqg`` flown beside
each configuration is the same policy on the same seeds); otherwise it is refused.

    python -m experiments.training_configurations.runcompare results/sp-default-v1 results/rppo-v1 --condition nonrigid
"""

from __future__ import annotations

import csv
import itertools
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.commandline import arg, command_name, fail, parse
from lvgym.errors import ConfigError
from lvgym.benchmark.compare import RUN_LABEL
from lvgym.benchmark.metrics import per_seed
from lvgym.benchmark.stats import REPS, iqm, probability_of_improvement

__all__ = ["read_episodes", "merge", "agent_matrices", "compare_agents", "table"]

PROG = "python -m experiments.training_configurations.runcompare"


def read_episodes(folder: str | Path, metric: str = "score") -> dict[tuple[str, str, str], dict[int, float]]:
    """``{(suite, condition, policy): {seed: value of metric}}`` from ``folder/episodes.csv`` (written by
    ``evaluate.py``)."""
    path = Path(folder) / "episodes.csv"
    if not path.is_file():
        raise ConfigError("results folder", str(folder), "a folder written by evaluate.py (holding episodes.csv)")
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        if metric not in (reader.fieldnames or []):
            raise ConfigError("--metric", metric, f"a column of {path}: {', '.join(reader.fieldnames or [])}")
        rows = list(reader)
    try:
        return per_seed(rows, metric)
    except ValueError:
        bad = next(r[metric] for r in rows if not _is_number(r[metric]))
        raise ConfigError("--metric", metric, f"a numeric column of {path} (it holds {bad!r})") from None


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def merge(folders: Sequence[str | Path], metric: str = "score") -> dict[tuple[str, str, str], dict[int, float]]:
    """The episodes of every folder; a policy in two folders must agree on its common seeds."""
    merged: dict[tuple[str, str, str], dict[int, float]] = {}
    origin: dict[tuple[str, str, str], str] = {}
    for folder in folders:
        for key, values in read_episodes(folder, metric).items():
            if key in merged:
                common = set(merged[key]) & set(values)
                bad = [s for s in sorted(common) if not math.isclose(merged[key][s], values[s], rel_tol=1e-12)]
                if bad:
                    raise ConfigError(f"{folder}: {'/'.join(key)} seed {bad[0]}", values[bad[0]],
                                      f"the value in {origin[key]} ({merged[key][bad[0]]}): one label, one policy")
                merged[key].update(values)
            else:
                merged[key], origin[key] = dict(values), str(folder)
    return merged


def agent_matrices(values: dict[tuple[str, str, str], dict[int, float]], suite: str,
                   condition: str) -> tuple[dict[str, np.ndarray], list[int]]:
    """Per agent of ``(suite, condition)`` its ``(runs, episodes)`` matrix on the seeds every policy there
    flew (rows in the order of the run labels), and those seeds."""
    policies = sorted(p for s, c, p in values if (s, c) == (suite, condition))
    if not policies:
        raise ConfigError("condition", f"{suite}/{condition}", "a suite and condition of the results")
    seeds = sorted(set.intersection(*(set(values[(suite, condition, p)]) for p in policies)))
    if not seeds:
        raise ConfigError("seeds", f"{suite}/{condition}", "at least one seed that every policy flew")
    runs: dict[str, list[str]] = {}
    for p in policies:
        m = RUN_LABEL.match(p)
        runs.setdefault(m.group("agent") if m else p, []).append(p)
    return ({agent: np.array([[values[(suite, condition, p)][s] for s in seeds] for p in pols])
             for agent, pols in runs.items()}, seeds)


def compare_agents(values: dict[tuple[str, str, str], dict[int, float]], conditions: Sequence[str] | None = None,
                   reps: int = REPS) -> list[dict[str, Any]]:
    """Per (suite, condition) (``conditions``: their names, default all): one ``iqm`` row per agent
    (``runs``, ``episodes``, ``mean``, ``iqm``, ``iqm_ci_low``, ``iqm_ci_high``) in the order of the IQM,
    then one ``p_improvement`` row per pair, the agent of the lower IQM over the other (``agent`` over
    ``other``: ``p``, ``ci_low``, ``ci_high``; the other way round is ``1 - p``)."""
    keys = sorted({(s, c) for s, c, _ in values if conditions is None or c.split("/")[-1] in conditions or c in conditions})
    if not keys:
        raise ConfigError("--condition", list(conditions or []), "conditions of the results: " + ", ".join(
            sorted({c for _, c, _ in values})))
    rows: list[dict[str, Any]] = []
    for suite, cond in keys:
        mats, seeds = agent_matrices(values, suite, cond)
        est = iqm(mats, reps=reps)
        order = sorted(mats, key=lambda a: est[a][0])
        for a in order:
            rows.append({"kind": "iqm", "suite": suite, "condition": cond, "agent": a, "runs": mats[a].shape[0],
                         "episodes": len(seeds), "mean": float(mats[a].mean()), "iqm": est[a][0],
                         "iqm_ci_low": est[a][1], "iqm_ci_high": est[a][2]})
        for a, b in itertools.combinations(order, 2):
            p, lo, hi = probability_of_improvement(mats[a], mats[b], reps=reps)
            rows.append({"kind": "p_improvement", "suite": suite, "condition": cond, "agent": a, "other": b,
                         "p": p, "ci_low": lo, "ci_high": hi})
    return rows


def table(rows: Sequence[dict[str, Any]], metric: str = "score") -> str:
    """The rows of :func:`compare_agents` as Markdown: the IQM table, then the probabilities of
    improvement of each agent over the ones after it in the IQM order."""
    out = [f"| suite | condition | agent | runs | episodes | mean {metric} | IQM {metric} [95 % CI] |",
           "|---|---|---|---:|---:|---:|---:|"]
    for r in rows:
        if r["kind"] == "iqm":
            out.append(f"| {r['suite']} | {r['condition']} | {r['agent']} | {r['runs']} | {r['episodes']} | "
                       f"{r['mean']:.4f} | {r['iqm']:.4f} [{r['iqm_ci_low']:.4f}, {r['iqm_ci_high']:.4f}] |")
    out += ["", "P(a better than b): the probability that a run of a scores lower than a run of b on an episode",
            "", "| suite | condition | a | b | P(a better than b) [95 % CI] |", "|---|---|---|---|---:|"]
    for r in rows:
        if r["kind"] == "p_improvement":
            out.append(f"| {r['suite']} | {r['condition']} | {r['agent']} | {r['other']} | "
                       f"{r['p']:.3f} [{r['ci_low']:.3f}, {r['ci_high']:.3f}] |")
    return "\n".join(out)


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.training_configurations.runcompare --help``)."""

    folders: list[str] = arg(positional=True, metavar="FOLDER")
    """results folders of evaluate.py (each with episodes.csv)"""
    metric: str = "score"
    """a column of episodes.csv (lower is better)"""
    condition: list[str] | None = None
    """conditions to compare (e.g. nonrigid or smile-v1/nonrigid; default: all)"""
    reps: int = arg(REPS, lo=100, hi=10**8, allowed="an integer of at least 100")
    """bootstrap resamples"""


def main(argv: Sequence[str] | None = None) -> None:
    """Compare, print the table."""
    args = parse(Args, argv, PROG, __doc__)
    try:
        rows = compare_agents(merge(args.folders, args.metric), args.condition, args.reps)
    except ConfigError as exc:
        fail(command_name(PROG), exc)
    sys.stdout.write(table(rows, args.metric) + "\n")


if __name__ == "__main__":
    main()
