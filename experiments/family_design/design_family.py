"""The automatic design (``lvgym design auto``) of the launcher family's first test vehicles: how long each
takes on this machine, how many rows of each schedule meet their requirements, and how the three designs
fly the vehicle against the privileged reference and the family's fixed baseline (the nominal member's
design) on validation seeds of smile-v2's conditions.

``python -m experiments.family_design.design_family --vehicles 5 --episodes 10`` writes
``results/family_design/`` (the vehicle files, ``designs.json`` and ``flights.md``). The designs go to the
design cache (``$LVGYM_CACHE_DIR/designs``); a second run reads them from it (say so with ``--fresh`` to
design again into a fresh cache folder).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import yaml

from lvgym.commandline import arg, parse

POLICIES = ("zero", "privileged", "auto-gs-pid", "auto-gs-pid-flex", "auto-lqg", "fixed-gs-pid-flex", "fixed-lqg")


@dataclass
class Args:
    """Command-line arguments."""

    vehicles: int = arg(5, lo=1, hi=50)
    """how many test vehicles (the test split's first seeds that fly)"""
    episodes: int = arg(10, lo=0, hi=200)
    """validation episodes per vehicle, model and policy (0: design only)"""
    out: str = "results/family_design"
    """output folder"""
    fresh: bool = False
    """design into a fresh cache folder (the timing of a first design)"""


def main(argv: list[str] | None = None) -> int:
    from lvgym.baselines.design.auto import design_vehicle, summary_text
    from lvgym.baselines.family import generate_flyable
    from lvgym.simulator.cache import using
    from lvgym.vehicle.generator import SPLITS

    a = parse(Args, argv, "python -m experiments.family_design.design_family", __doc__)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    fresh = tempfile.mkdtemp(prefix="lvgym-designs-") if a.fresh else None
    records, lines = [], []
    if a.episodes:                                  # the fixed baseline's design, once, before the evaluations
        from lvgym.baselines.designed import nominal_file

        if fresh:
            with using(fresh):
                print(summary_text(design_vehicle(nominal_file())), flush=True)
        else:
            print(summary_text(design_vehicle(nominal_file())), flush=True)
    seed = SPLITS["test"][0]
    while len(records) < a.vehicles:
        g = generate_flyable(seed)
        path = out / f"family_{seed}.yaml"
        path.write_text(yaml.safe_dump(g.data, sort_keys=False))
        start = time.perf_counter()
        if fresh:
            with using(fresh):
                d = design_vehicle(path)
        else:
            d = design_vehicle(path)
        wall = time.perf_counter() - start
        print(f"vehicle {seed} (L/D {g.design['slenderness']:.1f}, T/W {g.design['thrust_to_weight']:.2f}, "
              f"{'finned' if g.design['finned'] else 'finless'}): {wall:.1f} s\n{summary_text(d)}", flush=True)
        records.append({"seed": seed, "design": g.design, "wall_s": round(wall, 2), "summary": d.summary})
        if a.episodes:
            env = {} if not fresh else {"LVGYM_CACHE_DIR": fresh}
            proc = subprocess.run([sys.executable, "-m", "lvgym.cli.main", "evaluate", "--vehicle", str(path),
                                   "--policies", *POLICIES, "--episodes", str(a.episodes), "--seed-set", "validation",
                                   "--no-plots", "--no-progress", "--out", str(out / f"eval_{seed}")],
                                  capture_output=True, text=True, env={**os.environ, **env})
            lines.append(f"## vehicle {seed}\n\n{proc.stdout[-4000:]}\n")
            print(proc.stdout[-3000:], proc.stderr[-2000:], flush=True)
        seed += 1
    (out / "designs.json").write_text(json.dumps(records, indent=1))
    (out / "flights.md").write_text("\n".join(lines))
    if a.episodes:
        table = summary_table(sorted(out.glob("eval_*/episodes.csv")))
        (out / "summary.md").write_text(table + "\n")
        print(table)
    return 0


def summary_table(files: list[Path]) -> str:
    """Over the vehicles' evaluations (their ``episodes.csv``): per policy and model, the vehicles with no
    failed or unflyable flight, the failed-or-unflyable flights of all, and the median over the vehicles of
    each vehicle's mean ``score_v2`` with its range, as a markdown table."""
    import pandas as pd

    frames = [pd.read_csv(f).assign(vehicle=f.parent.name.removeprefix("eval_")) for f in files]
    df = pd.concat(frames)
    df["bad"] = df["failed"].astype(bool) | ~df["flyable"].astype(bool)
    lines = [f"{len(files)} vehicles, {df['seed'].nunique()} validation seeds each: vehicles held (no failed or "
             "unflyable flight), bad flights of all, and the median [min, max] over the vehicles of the mean "
             "score_v2 [rad]", "", "| model | policy | vehicles held | bad flights | score_v2 |", "|---|---|---:|---:|---:|"]
    for model in ("rigid", "nonrigid"):
        for policy in POLICIES:
            d = df[(df["model"] == model) & (df["policy"] == policy)]
            if d.empty:
                continue
            per = d.groupby("vehicle").agg(bad=("bad", "sum"), score=("score_v2", "mean"))
            lines.append(f"| {model} | {policy} | {int((per['bad'] == 0).sum())} of {len(per)} | "
                         f"{int(d['bad'].sum())} of {len(d)} | {per['score'].median():.3f} "
                         f"[{per['score'].min():.3f}, {per['score'].max():.3f}] |")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main())
