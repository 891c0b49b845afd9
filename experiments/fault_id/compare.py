"""The students on the test seeds against the classical designs: IQM over training seeds x test seeds, mean,
failed or unflyable, probability of improvement over the best classical design (by mean) per flight model.

    python evaluate.py --suites smile-v2-faults --out results/fault_id/test --no-plots --policies lqg lqg-front \
        aac-quiet lqg-thrust-id-s0=experiments/fault_id/estimator.py:s0 \
        lqg-thrust-id-s1=experiments/fault_id/estimator.py:s1 lqg-thrust-id-s2=experiments/fault_id/estimator.py:s2
    python -m experiments.fault_id.compare --folder results/fault_id/test

(and the same with ``inversion-id-s0=experiments.fault_id.inversion:s0`` ...: every student flown is compared)

(The same comparison a training campaign prints: :func:`lvgym.agents.training.campaign_compare.comparison_rows`.)
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from lvgym.commandline import arg, parse

BASELINES = ("lqg", "lqg-front", "aac-quiet", "gs-pd-relief", "gs-pid-flex-quiet")


def configurations() -> tuple[str, ...]:
    """The students' labels, ``<configuration>-s<training seed>``: the thrust-direction estimator on ``lqg``
    (:mod:`.estimator`) and every configuration of the reference's law on the learned disturbance observer
    (:data:`.inversion.STUDENTS`; flown as ``inversion-smile-lead5-gain6-s0=experiments.fault_id.inversion:
    smile_lead5_gain6_s0`` ...)."""
    from .inversion import STUDENTS

    return ("lqg-thrust-id", *dict.fromkeys(s.label for s in STUDENTS.values()))


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.compare --help``)."""

    folder: str = arg("results/fault_id/test")
    """evaluate.py's --out folder (its results.json)"""


def main(argv: Sequence[str] | None = None) -> None:
    from lvgym.agents.training.campaign_compare import comparison_rows, comparison_table

    a = parse(Args, argv, "python -m experiments.fault_id.compare", __doc__)
    path = Path(a.folder) / "results.json"
    if not path.is_file():
        raise SystemExit(f"python -m experiments.fault_id.compare: {path}: no such file (evaluate.py's --out)")
    records = json.loads(path.read_text())["episodes"]
    known = configurations()
    runs = {c: sorted({r["policy"] for r in records if re.fullmatch(re.escape(c) + r"-s\d+", r["policy"])})
            for c in known}
    runs = {c: labels for c, labels in runs.items() if labels}
    if not runs:
        raise SystemExit(f"{a.folder}: no policy labelled <configuration>-s<seed> of {list(known)}")
    rows = comparison_rows(records, runs, [b for b in BASELINES if any(r["policy"] == b for r in records)])
    print(comparison_table(rows, f"{', '.join(runs)} on the test seeds"))


if __name__ == "__main__":
    main()
