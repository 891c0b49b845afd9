"""The students on the test seeds against the classical designs: IQM over training seeds x test seeds, mean,
failed or unflyable, probability of improvement over the best classical design (by mean) per flight model.

    python evaluate.py --suites smile-v2-faults --out results/fault_id/test --no-plots --policies lqg lqg-front \
        aac-quiet lqg-thrust-id-s0=experiments/fault_id/estimator.py:s0 \
        lqg-thrust-id-s1=experiments/fault_id/estimator.py:s1 lqg-thrust-id-s2=experiments/fault_id/estimator.py:s2
    python -m experiments.fault_id.compare results/fault_id/test

(The same comparison a training campaign prints: :func:`agents.campaign_compare.comparison_rows`.)
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from pathlib import Path

BASELINES = ("lqg", "lqg-front", "aac-quiet")
CONFIGURATION = "lqg-thrust-id"


def main(argv: Sequence[str] | None = None) -> None:
    from agents.campaign_compare import comparison_rows, comparison_table

    args = list(sys.argv[1:] if argv is None else argv)
    if len(args) != 1:
        raise SystemExit("usage: python -m experiments.fault_id.compare RESULTS_FOLDER (evaluate.py's --out)")
    records = json.loads((Path(args[0]) / "results.json").read_text())["episodes"]
    labels = sorted({r["policy"] for r in records if r["policy"].startswith(CONFIGURATION + "-s")})
    if not labels:
        raise SystemExit(f"{args[0]}: no policy labelled {CONFIGURATION}-s<seed>")
    rows = comparison_rows(records, {CONFIGURATION: labels}, [b for b in BASELINES
                                                              if any(r["policy"] == b for r in records)])
    print(comparison_table(rows, f"{CONFIGURATION} on the test seeds"))


if __name__ == "__main__":
    main()
