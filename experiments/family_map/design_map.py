"""The thesis's question for control, as maps over the launcher family (issue 34): from which slenderness and
thrust-to-weight does the flexible, sloshing vehicle break a controller designed for it, or for its rigid body?

    python -m experiments.family_map.design_map --seeds 5

For each cell of a grid of slenderness L/D (``--ld``) and lift-off thrust-to-weight (``--tw``) the family's
generator (:mod:`lvgym.vehicle.generator`, every other parameter drawn from the cell's seed, as in
``flexibility_map``) builds ``--vehicles`` vehicles that pass the family's checks (``generate_flyable``: the
vehicle checks, and a nominal flight below half its q-alpha limit and half its divergence pressure; a cell
with no such draw stays empty). Each is designed by
``lvgym design auto`` (:mod:`lvgym.baselines.design.auto`: a rigid-body gs-pid, the flexible gs-pid-flex and
an LQG, from the vehicle file alone, through the design cache), and each baseline flies it in the main
suite's conditions (``smile-v2``: turbulence, a gust, every dispersion, the flight sensors) on validation
seeds ``0 .. seeds - 1``, rigid and non-rigid, under v2's flyability rule:

* ``privileged``: the reference that needs no design (the true rigid-body state, the wind ahead);
* ``auto-gs-pid``: the per-vehicle rigid-body design (the thesis's practice);
* ``auto-gs-pid-flex``, ``auto-lqg``: the per-vehicle designs on the flexible vehicle (the field's practice);
* ``fixed-gs-pid-flex``, ``fixed-lqg``: the family's nominal member's designs, flown on every vehicle.

It writes ``cells.csv`` (one line per cell, vehicle, policy and model: failed or unflyable flights and the
mean ``score_v2``), ``designs.csv`` (per vehicle: design time and the rows that meet their requirements),
and three figures into ``--out``: ``failures.png`` (non-rigid failed-or-unflyable share per baseline),
``ratio.png`` (non-rigid over rigid mean score_v2 per baseline) and ``rigid_design.png`` (where the rigid
design holds the rigid vehicle, no flight failed, and stops holding the flexible one). Finished cells are kept in
``--out``/cells and skipped by a second run (``--fresh`` flies them again). A study: it flies no test seed.
"""

from __future__ import annotations

import csv
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lvgym.commandline import arg, parse

PROG = "python -m experiments.family_map.design_map"
POLICIES = ("privileged", "auto-gs-pid", "auto-gs-pid-flex", "auto-lqg", "fixed-gs-pid-flex", "fixed-lqg")
MODELS = ("rigid", "nonrigid")
#: the categories of ``rigid_design.png`` (the rigid design's holding: no failed or unflyable flight)
HOLDS = ("holds both", "holds the rigid vehicle only", "holds neither", "holds the flexible vehicle only")


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.family_map.design_map --help``)."""

    ld: list[float] = arg(default_factory=lambda: [10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0], lo=5.0, hi=60.0,
                          metavar="L/D")
    """the slenderness of the grid's columns"""
    tw: list[float] = arg(default_factory=lambda: [1.3, 1.7, 2.1, 2.5], lo=1.05, hi=5.0, metavar="T/W")
    """the lift-off thrust-to-weight of the grid's rows"""
    vehicles: int = arg(1, lo=1, hi=20)
    """vehicles per cell (the cell's seeds, drawn in turn)"""
    seeds: int = arg(5, lo=1, hi=1000)
    """validation seeds per vehicle, policy and model"""
    mission_time_s: float = arg(60.0, lo=1.0, hi=70.0)
    """flight time of each episode [s]"""
    workers: int = arg(2, lo=1, hi=64)
    """worker processes of the evaluation"""
    out: str = arg("results/family_design_map", metavar="FOLDER")
    """where to write the tables, the figures and the vehicles"""
    fresh: bool = False
    """fly the finished cells again"""


def fly_vehicle(ld: float, tw: float, seed: int, seeds: int, mission_time_s: float, workers: int,
                folder: Path) -> dict:
    """One vehicle of a cell (the generator's seed ``seed``): its automatic design and the baselines' flights."""
    from lvgym.baselines.design.auto import design_vehicle
    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import evaluate
    from lvgym.baselines.family import generate_flyable
    from lvgym.benchmark.suites import get_suite
    from lvgym.errors import ConfigError
    from lvgym.vehicle.generator import FamilyRanges

    try:
        vehicle = generate_flyable(seed, FamilyRanges(slenderness=(ld, ld), thrust_to_weight=(tw, tw)),
                                   mission_time_s)
    except ConfigError:                            # no draw of the cell passes the family's checks
        return {"ld": ld, "tw": tw, "seed": seed, "flights": []}
    path = vehicle.write(folder / "vehicles")
    design = design_vehicle(path)
    s = design.summary
    record = {"ld": ld, "tw": tw, "seed": seed, "attempt": vehicle.attempt, "finned": bool(vehicle.design["finned"]),
              "stages": int(vehicle.design["stages"]), "design_s": s["seconds"], "cached": design.cached,
              "flex_rows_met": sum(bool(r["meets"]) for r in s["gs-pid-flex"]["rows"]),
              "lqg_rows_met": sum(all(v == 0.0 for k, v in r.items() if k != "time_s") for r in s["lqg"]["rows"]),
              "rigid_rows_stable_nonrigid": sum(bool(r["nonrigid_stable"]) for r in s["gs-pid"]["rows"]),
              "rows": len(s["gs-pid"]["rows"])}
    suite = get_suite("smile-v2").with_options(vehicle=str(path), mission_time_s=mission_time_s)
    records = evaluate([resolve_policy(p) for p in POLICIES], [suite], seeds, "validation", "local", workers,
                       progress=False)
    flights = []
    for policy in POLICIES:
        for model in MODELS:
            rs = [r for r in records if r["policy"] == policy and r["model"] == model]
            flights.append({"policy": policy, "model": model, "episodes": len(rs),
                            "bad": sum(bool(r["failed"]) or not bool(r["flyable"]) for r in rs),
                            "failed": sum(bool(r["failed"]) for r in rs),
                            "score_v2": round(float(np.mean([r["score_v2"] for r in rs])), 5)})
    return {**record, "flights": flights}


def cell_rows(cells: list[dict]) -> list[dict]:
    """``cells.csv``'s lines: one per cell, vehicle, policy and model."""
    keys = ("ld", "tw", "seed", "finned", "stages")
    return [{**{k: c[k] for k in keys}, **f} for c in cells for f in c["flights"]]


def flown(cells: list[dict]) -> list[dict]:
    """The cells' vehicles that flew (a cell without a vehicle that passes the checks has none)."""
    return [c for c in cells if c["flights"]]


def _grid(cells: list[dict], ld: list[float], tw: list[float], value) -> np.ndarray:
    """A value per grid cell (``value`` of the cell's vehicles' records) as rows of T/W by columns of L/D."""
    out = np.full((len(tw), len(ld)), np.nan)
    for i, b in enumerate(tw):
        for j, a in enumerate(ld):
            here = [c for c in flown(cells) if c["ld"] == a and c["tw"] == b]
            if here:
                out[i, j] = value(here)
    return out


def _flight(cells: list[dict], policy: str, model: str, key: str) -> float:
    """Over the cell's vehicles: the share of bad flights (``key='bad'``: failed or unflyable), of failed
    flights (``'failed'``) or the mean score_v2 (``'score'``)."""
    fs = [f for c in cells for f in c["flights"] if f["policy"] == policy and f["model"] == model]
    if key in ("bad", "failed"):
        return sum(f[key] for f in fs) / sum(f["episodes"] for f in fs)
    return float(np.mean([f["score_v2"] for f in fs]))


def holding(cells: list[dict], policy: str = "auto-gs-pid") -> int:
    """The index in :data:`HOLDS` of where ``policy`` holds the cell's vehicles: no failed flight on a model
    (the thesis's criterion; the rigid design's commanded gimbal rate, which v2's flyability rule charges,
    is in ``failures.png``)."""
    rigid = _flight(cells, policy, "rigid", "failed") == 0.0
    flexible = _flight(cells, policy, "nonrigid", "failed") == 0.0
    return {(True, True): 0, (True, False): 1, (False, False): 2, (False, True): 3}[(rigid, flexible)]


def _panel(ax, data: np.ndarray, ld: list[float], tw: list[float], title: str, cmap: str, fmt: str,
           vmin: float | None = None, vmax: float | None = None):
    im = ax.imshow(data, origin="lower", aspect="auto", cmap=cmap, vmin=vmin, vmax=vmax)
    ax.set_xticks(range(len(ld)), [f"{a:g}" for a in ld])
    ax.set_yticks(range(len(tw)), [f"{b:g}" for b in tw])
    ax.set_xlabel("L/D")
    ax.set_ylabel("thrust-to-weight")
    ax.set_title(title, fontsize=9)
    lo, hi = (np.nanmin(data), np.nanmax(data)) if vmin is None else (vmin, vmax)
    for (i, j), v in np.ndenumerate(data):
        if np.isfinite(v):
            ax.text(j, i, format(v, fmt), ha="center", va="center", fontsize=7,
                    color="k" if v > lo + 0.6 * (hi - lo) else "w")
    return im


def draw(cells: list[dict], ld: list[float], tw: list[float], out: Path) -> list[Path]:
    """The three figures (module docstring); their paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    for name, key, title, cmap, fmt, lim in (
            ("failures.png", "bad", "non-rigid: failed or unflyable share", "magma", ".1f", (0.0, 1.0)),
            ("ratio.png", "ratio", "score_v2 non-rigid / rigid", "viridis", ".2f", (None, None))):
        fig, axes = plt.subplots(2, 3, figsize=(15, 7), constrained_layout=True)
        for ax, policy in zip(axes.flat, POLICIES):
            if key == "bad":
                data = _grid(cells, ld, tw, lambda c, p=policy: _flight(c, p, "nonrigid", "bad"))
            else:
                data = _grid(cells, ld, tw, lambda c, p=policy: _flight(c, p, "nonrigid", "score")
                             / _flight(c, p, "rigid", "score"))
            fig.colorbar(_panel(ax, data, ld, tw, f"{policy}: {title}", cmap, fmt, *lim), ax=ax)
        fig.suptitle("The launcher family, smile-v2's conditions, validation seeds: per-vehicle automatic designs "
                     "(auto-*), the nominal member's (fixed-*) and the privileged reference")
        fig.savefig(out / name, dpi=100)
        plt.close(fig)
        paths.append(out / name)
    fig, ax = plt.subplots(figsize=(8, 4), constrained_layout=True)
    data = _grid(cells, ld, tw, holding).astype(float)
    cmap = matplotlib.colors.ListedColormap(["#4caf50", "#ff9800", "#b71c1c", "#2196f3"])
    ax.imshow(data, origin="lower", aspect="auto", cmap=cmap, vmin=-0.5, vmax=3.5)
    ax.set_xticks(range(len(ld)), [f"{a:g}" for a in ld])
    ax.set_yticks(range(len(tw)), [f"{b:g}" for b in tw])
    ax.set_xlabel("L/D")
    ax.set_ylabel("thrust-to-weight")
    for (i, j), v in np.ndenumerate(data):
        if np.isfinite(v):
            here = [c for c in flown(cells) if c["ld"] == ld[j] and c["tw"] == tw[i]]
            ax.text(j, i, f"{sum(c['rigid_rows_stable_nonrigid'] for c in here)}/{sum(c['rows'] for c in here)}",
                    ha="center", va="center", fontsize=8, color="w")
    ax.legend(handles=[matplotlib.patches.Patch(color=cmap(k), label=h) for k, h in enumerate(HOLDS)],
              loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    ax.set_title("auto-gs-pid, the per-vehicle rigid-body design, in flight (held: no failed flight);\n"
                 "the number: its rows whose linear loop is stable on the non-rigid plant", fontsize=8)
    fig.savefig(out / "rigid_design.png", dpi=100)
    plt.close(fig)
    return paths + [out / "rigid_design.png"]


def main(argv: Sequence[str] | None = None) -> None:
    from lvgym.baselines.design.auto import design_vehicle
    from lvgym.baselines.designed import nominal_file

    a = parse(Args, argv, PROG, __doc__)
    out = Path(a.out)
    (out / "cells").mkdir(parents=True, exist_ok=True)
    design_vehicle(nominal_file())                 # the fixed baseline's design, once, before the flights
    cells = []
    for i, (tw, ld) in enumerate((tw, ld) for tw in a.tw for ld in a.ld):
        for k in range(a.vehicles):
            seed = i + 1000 * k                    # k = 0: the vehicle of flexibility_map's cell
            done = out / "cells" / f"ld{ld:g}_tw{tw:g}_{seed}.json"
            if done.exists() and not a.fresh:
                cells.append(json.loads(done.read_text()))
                continue
            c = fly_vehicle(ld, tw, seed, a.seeds, a.mission_time_s, a.workers, out)
            done.write_text(json.dumps(c, indent=1))
            cells.append(c)
            if not c["flights"]:
                print(f"L/D {ld:4.1f} T/W {tw:4.2f} seed {seed}: no draw passes the family's checks", flush=True)
                continue
            bad = {f"{f['policy']}/{f['model'][0]}": f["bad"] for f in c["flights"]}
            print(f"L/D {ld:4.1f} T/W {tw:4.2f} seed {seed}: designed in {c['design_s']:.0f} s "
                  f"(flex {c['flex_rows_met']}/{c['rows']}, lqg {c['lqg_rows_met']}/{c['rows']}); bad of "
                  f"{a.seeds}: {bad}", flush=True)
    with open(out / "cells.csv", "w", newline="") as f:
        lines = cell_rows(cells)
        w = csv.DictWriter(f, fieldnames=list(lines[0]))
        w.writeheader()
        w.writerows(lines)
    with open(out / "designs.csv", "w", newline="") as f:
        keys = [k for k in flown(cells)[0] if k != "flights"]
        w = csv.DictWriter(f, fieldnames=keys, restval="")
        w.writeheader()
        w.writerows({k: c.get(k, "") for k in keys} for c in cells)
    paths = draw(cells, a.ld, a.tw, out)
    print(f"{len(cells)} vehicles: {out / 'cells.csv'}, {out / 'designs.csv'}, " + ", ".join(map(str, paths)))


if __name__ == "__main__":
    main()
