"""Where does a non-rigid model matter for control? A first map over the launcher family (issue 34's question).

    python -m experiments.family_map.flexibility_map --seeds 5

For each cell of a grid of slenderness L/D (``--ld``) and lift-off thrust-to-weight (``--tw``) the family's
generator (:mod:`lvgym.vehicle.generator`, every other parameter drawn from the cell's seed) builds one
vehicle that passes its checks, and the privileged reference (``baselines/privileged.py``: a controller that
needs no design for the vehicle) flies it in the main suite's conditions (``smile-v2``: turbulence, a gust,
every dispersion, the flight sensors) on validation seeds ``0 .. seeds - 1``, rigid and non-rigid. Per cell:
the failures of each model and the ratio of the mean ``score_v2``, non-rigid over rigid. It writes
``cells.csv`` and ``map.png`` (the ratio and the non-rigid failures over the grid) into ``--out``.

This is the map of one controller that knows the rigid body's true state and nothing of the slosh and the
bending: where its non-rigid flights fail or degrade, the flexible vehicle asks more than a rigid-body law
gives. The issue's own map (per-vehicle rigid and flex designs) needs the automatic design, not built yet.
A study: it flies no test seed.
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import lvgym
from lvgym.baselines.privileged import PrivilegedPolicy
from lvgym.benchmark.runner import play_episode
from lvgym.commandline import arg, parse
from lvgym.vehicle.generator import FamilyRanges, generate

PROG = "python -m experiments.family_map.flexibility_map"


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.family_map.flexibility_map --help``)."""

    ld: list[float] = arg(default_factory=lambda: [10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0], lo=5.0, hi=60.0,
                          metavar="L/D")
    """the slenderness of the grid's columns"""
    tw: list[float] = arg(default_factory=lambda: [1.3, 1.7, 2.1, 2.5], lo=1.05, hi=5.0, metavar="T/W")
    """the lift-off thrust-to-weight of the grid's rows"""
    seeds: int = arg(5, lo=1, hi=1000)
    """validation seeds per cell and model"""
    mission_time_s: float = arg(60.0, lo=1.0, hi=70.0)
    """flight time of each episode [s]"""
    out: str = arg("results/family_map", metavar="FOLDER")
    """where to write cells.csv, map.png and the vehicles"""


def fly_cell(ld: float, tw: float, index: int, seeds: int, mission_time_s: float, folder: Path) -> dict:
    """One cell: its vehicle (seed ``index``) and the reference's flights on it, rigid and non-rigid."""
    ranges = FamilyRanges(slenderness=(ld, ld), thrust_to_weight=(tw, tw))
    vehicle = generate(index, ranges)
    path = vehicle.write(folder)
    row = {"ld": ld, "tw": tw, "seed": index, "attempt": vehicle.attempt, "finned": vehicle.design["finned"],
           "length_m": round(vehicle.design["length_m"], 2), "burn_time_s": round(vehicle.design["burn_time_s"], 1)}
    scores = {}
    for model in ("rigid", "nonrigid"):
        env = lvgym.make_env("smile-v2", model, vehicle=str(path), privileged_info=True,
                             mission_time_s=mission_time_s)
        policy = PrivilegedPolicy(env)
        records = [play_episode(policy, env, s, flyability=True) for s in range(seeds)]
        scores[model] = np.mean([r["score_v2"] for r in records])
        row[f"failed_{model}"] = sum(bool(r["failed"]) for r in records)
        row[f"score_{model}"] = round(float(scores[model]), 4)
    row["ratio"] = round(float(scores["nonrigid"] / scores["rigid"]), 3)
    return row


def draw(rows: list[dict], ld: list[float], tw: list[float], seeds: int, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    grid = {(r["ld"], r["tw"]): r for r in rows}
    ratio = np.array([[grid[(a, b)]["ratio"] for a in ld] for b in tw])
    fails = np.array([[grid[(a, b)]["failed_nonrigid"] / seeds for a in ld] for b in tw])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
    for ax, data, title, cmap in ((axes[0], ratio, "score_v2 non-rigid / rigid", "viridis"),
                                  (axes[1], fails, "non-rigid failures (share of seeds)", "magma")):
        im = ax.imshow(data, origin="lower", aspect="auto", cmap=cmap)
        ax.set_xticks(range(len(ld)), [f"{a:g}" for a in ld])
        ax.set_yticks(range(len(tw)), [f"{b:g}" for b in tw])
        ax.set_xlabel("L/D")
        ax.set_ylabel("thrust-to-weight")
        ax.set_title(title)
        bright = data.min() + 0.6 * (data.max() - data.min())
        for (i, j), v in np.ndenumerate(data):                   # F: a finned vehicle
            fin = " F" if grid[(ld[j], tw[i])]["finned"] in (True, "True") else ""
            ax.text(j, i, f"{v:.2f}{fin}", ha="center", va="center", color="k" if v > bright else "w", fontsize=8)
        fig.colorbar(im, ax=ax)
    fig.suptitle("The privileged reference over the launcher family (smile-v2 conditions, validation seeds; "
                 "F: finned)")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> None:
    a = parse(Args, argv, PROG, __doc__)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for i, (tw, ld) in enumerate((tw, ld) for tw in a.tw for ld in a.ld):
        rows.append(fly_cell(ld, tw, i, a.seeds, a.mission_time_s, out / "vehicles"))
        r = rows[-1]
        print(f"L/D {ld:4.1f}  T/W {tw:4.2f}  {'finned' if r['finned'] else 'finless':7s}  failed rigid "
              f"{r['failed_rigid']}/{a.seeds}  non-rigid {r['failed_nonrigid']}/{a.seeds}  score_v2 "
              f"{r['score_rigid']:.3f} / {r['score_nonrigid']:.3f}  ratio {r['ratio']:.2f}", flush=True)
    with open(out / "cells.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    draw(rows, a.ld, a.tw, a.seeds, out / "map.png")
    print(f"{len(rows)} cells: {out / 'cells.csv'}, {out / 'map.png'}")


if __name__ == "__main__":
    main()
