"""Whose failures are the students': every failed or unflyable flight of an ``evaluate.py`` run on the fault
suite's **validation** seeds, flown again by the privileged reference, by its law on the flight computer's
errors without the wind ahead (the disturbance-observer student's teacher) and by ``lqg``.

    python evaluate.py --suites smile-v2-faults --seed-set validation --episodes 300 --no-plots \
        --out results/fault_id/val300-gain6 --policies inversion-id-gain6-s0=experiments.fault_id.inversion:gain6_s0 ...
    python -m experiments.fault_id.feasible --folder results/fault_id/val300-gain6

A flight the reference fails too is beyond what the law can fly on this actuator; one its teacher flies is
the student's own (its estimate's) failure. ``--late 5 10``: the teacher again, knowing what the fault changed
(the plant's entries of the info, :data:`.privileges.PLANT`) that many control steps late: how soon a causal
law must know it. Refuses a run on the test seeds: what fails there is reported,
never studied flight by flight.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from lvgym.commandline import arg, parse

from .privileges import reference
from .train import SUITE, condition, lost

#: the laws each failed flight is flown again with
LAWS = ("privileged", "teacher", "lqg")


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.feasible --help``)."""

    folder: str = arg("results/fault_id/val300-gain6")
    """evaluate.py's --out folder of a validation run on smile-v2-faults (its results.json)"""
    late: list[int] = arg(default_factory=list, metavar="STEPS", lo=1, hi=500)
    """the teacher flown again with the plant known that many control steps late (one column each)"""
    seeds: list[int] = arg(default_factory=list, metavar="SEED", lo=0, hi=9_999)
    """only these validation seeds of the run's lost flights (default: all)"""


def failed(records: list[dict]) -> dict[tuple[str, int], list[str]]:
    """The failed or unflyable flights of ``records`` on the fault suite: (flight model, seed) -> the policies
    that lost it, in order of model and seed."""
    out: dict[tuple[str, int], list[str]] = {}
    for r in records:
        if r["suite"] == SUITE and lost(r):
            out.setdefault((r["condition"].rsplit("/", 1)[-1], int(r["seed"])), []).append(r["policy"])
    return dict(sorted(out.items()))


def main(argv: Sequence[str] | None = None) -> None:
    import lvgym.cli.policies  # noqa: F401  (registers lqg)
    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import build_policy, play_episode

    a = parse(Args, argv, "python -m experiments.fault_id.feasible", __doc__)
    run = json.loads((Path(a.folder) / "results.json").read_text())
    records = run["episodes"]
    if run["meta"]["seed_set"] != "validation":
        raise SystemExit(f"{a.folder}: a run on the test seeds; this study takes validation runs only")
    envs = {m: condition(m, privileged_info=True).make_env() for m in ("rigid", "nonrigid")}
    names = list(LAWS) + [f"teacher, plant {k} steps late" for k in a.late]
    print("| model | seed | fault | lost by | " + " | ".join(names) + " |\n|---|---|---|---|" + "---|" * len(names))
    for (model, seed), policies in failed(records).items():
        if a.seeds and seed not in a.seeds:
            continue
        env = envs[model]
        laws = (reference(env), reference(env, preview=False, observed=True), build_policy(resolve_policy("lqg"), env),
                *(reference(env, preview=False, observed=True, plant_late_steps=k) for k in a.late))
        flown = [play_episode(law, env, seed, flyability=True) for law in laws]
        cells = ["fails" if lost(r) else "flies" for r in flown]
        print(f"| {model} | {seed} | {flown[0]['fault']} | {', '.join(policies)} | " + " | ".join(cells) + " |",
              flush=True)


if __name__ == "__main__":
    main()
