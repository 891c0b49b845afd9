"""Automatic classical design for any vehicle: from its file alone, the three schedules the benchmark's
classical baselines fly, made with the same tools as the shipped ones, cached by the vehicle's content.

``lvgym design auto --vehicle PATH`` (``python -m lvgym.baselines.design.auto``); in Python,
:func:`design_vehicle`. The vehicle flies in SMILE's v1 env (:data:`.target.FILE_ENV`, env keywords change
it); the rows are :func:`.target.file_times` (8 equal parts of its burning flight up to the mission's end),
and the three designs are:

=================  ==========================================================================================
``gs-pid``         the rigid-body design, the thesis's practice (section 6.3): :func:`.tune.schedule`, a PID
                   per row placed on the rigid linearisation (75 rad/s, 35 deg, lowered until it holds),
                   with its rigid and non-rigid margins
``gs-pid-flex``    the field's practice: :func:`.flexdesign.design_schedule`, the PID with its structural
                   filter per row designed on the non-rigid flight loop against the margin, attenuation and
                   drift requirements (:class:`.flexproblem.Requirements`), with the gyro noise held to
                   :data:`NOISE_RATE` of the servo's rate limit (protocol v2's flyability)
``lqg``            :func:`.lqg_design.design_schedule`: LQG per row and plane on the non-rigid plant, the
                   weights searched against the margin targets
=================  ==========================================================================================

What differs from the shipped designs, so that one vehicle designs in about a minute on 2 cores
(:class:`Budget`; docs/own-launcher.md measures it):

- every operating point is flown with the privileged reference (``fly="privileged"``, :func:`.target.
  privileged_flyer`): it needs no design for the vehicle, so the designs do not wait on each other, and one
  flight per flight model serves all the rows of a design (:func:`.linearize.reused_flights`);
- the flexible design's optimiser runs :attr:`Budget.flex_maxiter` iterations from the previous row's design
  and no random start (the shipped designs: 3,000 and two random starts);
- the LQG search tries the :data:`AUTO_GRID` weights (64 of the shipped search's 240);
- the rigid design, then the LQG design, run in one worker process and the flexible design in another.

The result is a folder (the cache's entry, or ``--out``) with ``gs-pid.yaml``, ``gs-pid-flex.yaml`` (and
its ``_margins.md``), ``lqg.npz`` (and ``lqg_margins.md``) and ``design.json``: the vehicle, the budget,
how long each design took, and per design and row whether it meets its requirements, with the worst
margins. The cache's key is a SHA-256 of the vehicle's content (its parsed, frozen dataclasses without the
file's name, as the timeline cache keys it: :mod:`lvgym.simulator.cache`), the env keywords, the budget and
the source of the design tools, so an edited vehicle or an edited tool designs again; the folder is
``$LVGYM_CACHE_DIR/designs`` (default ``~/.cache/lvgym/designs``). :func:`latest_design` finds the last
design of a vehicle whatever its budget (what the ``auto-*`` policies fly).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import pickle
import shutil
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import yaml

from lvgym.commandline import arg
from lvgym.errors import ConfigError, check_number

from .target import vehicle_option

__all__ = ["AUTO_GRID", "Budget", "NOISE_RATE", "VehicleDesign", "design_vehicle", "designs_folder", "latest_design"]

#: the LQG weights the automatic design searches (a subset of :data:`.lqg_design.SEARCH_GRID`: the two
#: integral weights, four of the five gimbal weights, both gimbal noises, and the low and high mode weights)
AUTO_GRID = {"q_int": (10.0, 100.0), "r_gimbal": (1.0, 3.0, 10.0, 30.0), "w_gimbal": (1e-8, 1e-7),
             "q_modes": (1e-5, 1e-3), "w_modes": (1e-5, 1e-3)}
#: the gyro noise's commanded gimbal rate the flexible design holds, as a share of the servo's rate limit
#: (the shipped ``gs-pid-flex-quiet`` SMILE design's: protocol v2's flyability rule)
NOISE_RATE = 0.2
#: the version of the automatic design's method (a change here designs every vehicle again)
VERSION = 1
#: the files of a design's folder
FILES = {"gs-pid": "gs-pid.yaml", "gs-pid-flex": "gs-pid-flex.yaml", "lqg": "lqg.npz", "summary": "design.json"}


@dataclass(frozen=True)
class Budget:
    """How much the automatic design searches (module docstring). ``flex_maxiter``: the flexible design's
    optimiser iterations per row and start; ``flex_starts``: its random starts per row; ``workers``: worker
    processes (1: all in this process), each with one BLAS thread; ``rows``: the schedules' rows
    (:func:`.target.file_times`)."""

    flex_maxiter: int = 600
    flex_starts: int = 0
    workers: int = 2
    rows: int = 8

    def __post_init__(self) -> None:
        for key, lo, hi in (("flex_maxiter", 10, 100_000), ("flex_starts", 0, 100), ("workers", 1, 2), ("rows", 1, 40)):
            object.__setattr__(self, key, int(check_number(f"budget.{key}", getattr(self, key), lo, hi, integer=True)))


@dataclass(frozen=True)
class VehicleDesign:
    """The automatic design of one vehicle: its ``folder``, the paths of the three schedules, and the
    ``summary`` written to ``design.json`` (module docstring); ``cached``: read from the cache."""

    folder: Path
    summary: dict
    cached: bool

    def path(self, kind: str) -> Path:
        """The file of ``kind`` (``gs-pid``, ``gs-pid-flex``, ``lqg``)."""
        if kind not in ("gs-pid", "gs-pid-flex", "lqg"):
            raise ConfigError("kind", kind, "one of 'gs-pid', 'gs-pid-flex', 'lqg'")
        return self.folder / FILES[kind]


def designs_folder() -> Path | None:
    """The cache's folder of automatic designs, or None when ``$LVGYM_CACHE_DIR`` is ``off``."""
    from lvgym.simulator.cache import cache_dir

    root = cache_dir()
    return None if root is None else root.parent / "designs"


def _source_digest() -> str:
    here = Path(__file__).parent
    h = hashlib.sha256()
    for f in sorted([*here.glob("*.py"), *here.parent.glob("*.py")]):
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def vehicle_key(vehicle: str) -> str:
    """A key of the vehicle file's content and of the design tools' source (module docstring)."""
    from lvgym.vehicle.config import load_vehicle

    content = dataclasses.replace(load_vehicle(vehicle), source=None)
    h = hashlib.sha256(pickle.dumps((content, VERSION), protocol=4))
    h.update(_source_digest().encode())
    return h.hexdigest()[:32]


def design_key(vehicle: str, budget: Budget, options: dict[str, Any]) -> str:
    """The cache key of the design of the vehicle file ``vehicle`` with ``budget`` and the env keywords
    ``options`` (module docstring)."""
    h = hashlib.sha256(vehicle_key(vehicle).encode())
    h.update(pickle.dumps((sorted(options.items()), asdict(budget)), protocol=4))
    return h.hexdigest()[:32]


def latest_design(vehicle: str | os.PathLike[str]) -> VehicleDesign | None:
    """The cache's last design of the vehicle file ``vehicle`` (whatever its budget and options: the one
    ``lvgym design auto`` made last), or None."""
    root = designs_folder()
    if root is None:
        return None
    index = root / f"{vehicle_key(os.fspath(vehicle))}.latest"
    folder = root / index.read_text().strip() if index.is_file() else None
    if folder is None or not (folder / FILES["summary"]).is_file():
        return None
    return VehicleDesign(folder, json.loads((folder / FILES["summary"]).read_text()), cached=True)


def _rigid_then_lqg(vehicle: str, folder: str, options: dict[str, Any], budget: Budget,
                    grid: dict[str, tuple[float, ...]]) -> dict[str, Any]:
    """The rigid and the LQG design of ``vehicle`` into ``folder`` (one worker's job): their summaries."""
    from threadpoolctl import threadpool_limits

    from . import lqg_design, tune
    from .target import burn_phases, file_times

    out = Path(folder)
    quiet = _quiet_log()
    start = time.perf_counter()
    times = file_times(vehicle, budget.rows)
    limits = threadpool_limits(1) if budget.workers > 1 else None
    rigid = tune.schedule(vehicle, times, protocol="v1", fly="privileged", log=quiet, **options)
    _write_yaml(out / FILES["gs-pid"], rigid, f"rigid gs-pid schedule of {vehicle} (lvgym design auto)")
    t_rigid = time.perf_counter() - start
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = lqg_design.design_schedule(vehicle, times, burn_phases(vehicle), grid=grid, fly="privileged",
                                         log=quiet, **options)
    if limits is not None:
        limits.restore_original_limits()
    lqg_design.save_schedule(doc, out / FILES["lqg"])
    (out / "lqg_margins.md").write_text(lqg_design.margin_table(doc))
    targets = lqg_design.MarginTargets()
    return {"gs-pid": {"seconds": round(t_rigid, 2), "rows": [_rigid_row(r) for r in rigid["rows"]]},
            "lqg": {"seconds": round(time.perf_counter() - start - t_rigid, 2),
                    "rows": [{"time_s": r["time_s"], **{p: round(lqg_design.shortfall(r[p]["assessment"], targets), 4)
                                                         for p in ("pitch", "yaw") if p in r}} for r in doc["rows"]]}}


def _flex(vehicle: str, folder: str, options: dict[str, Any], budget: Budget) -> dict[str, Any]:
    """The flexible design of ``vehicle`` into ``folder`` (the other worker's job): its summary."""
    from threadpoolctl import threadpool_limits

    from .flexdesign import design_schedule
    from .flexproblem import Requirements
    from .flextable import margin_table
    from .target import file_times

    start = time.perf_counter()
    with warnings.catch_warnings(), threadpool_limits(1 if budget.workers > 1 else None):
        warnings.simplefilter("ignore")
        doc = design_schedule(vehicle, file_times(vehicle, budget.rows), Requirements(noise_rate_fraction=NOISE_RATE),
                              starts=budget.flex_starts, fly="privileged", maxiter=budget.flex_maxiter,
                              log=_quiet_log(), **options)
    out = Path(folder)
    _write_yaml(out / FILES["gs-pid-flex"], doc, f"gs-pid-flex schedule of {vehicle} (lvgym design auto)")
    (out / "gs-pid-flex_margins.md").write_text(margin_table(doc))
    return {"gs-pid-flex": {"seconds": round(time.perf_counter() - start, 2),
                            "rows": [{"time_s": r["time_s"], "meets": bool(r["meets"]), "misses": list(r["misses"])}
                                     for r in doc["rows"]]}}


def _quiet_log() -> Any:
    return lambda *args, **kwargs: None


def _write_yaml(path: Path, doc: dict[str, Any], title: str) -> None:
    path.write_text(f"# {title}\n" + yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120))


def _rigid_row(r: dict[str, Any]) -> dict[str, Any]:
    """A rigid row's record: whether the tuning met its target, and its margins, rigid and non-rigid."""
    rigid, flex = r["rigid"], r["nonrigid"]
    return {"time_s": r["time_s"], "target_met": r["target_met"],
            "rigid_gm_db": rigid.get("gain_margin_db"), "rigid_pm_deg": rigid.get("phase_margin_deg"),
            "nonrigid_gm_db": flex.get("gain_margin_db"), "nonrigid_pm_deg": flex.get("phase_margin_deg"),
            "nonrigid_stable": flex.get("closed_loop_stable")}


def design_vehicle(vehicle: str | os.PathLike[str], budget: Budget = Budget(), out: str | os.PathLike[str] | None = None,
                   cache: bool = True, grid: dict[str, tuple[float, ...]] | None = None, **options: Any) -> VehicleDesign:
    """The three schedules of the vehicle file ``vehicle`` (module docstring), from the cache when it holds
    them; else designed into the cache's entry (and copied to ``out`` when given; ``cache=False``: designed
    into ``out`` alone). ``grid``: the LQG weights searched (default :data:`AUTO_GRID`); ``options``: env
    keywords of the vehicle's v1 env."""
    from .target import check_vehicle, is_shipped

    path = os.fspath(vehicle)
    if is_shipped(path) or is_shipped(path, "v0"):
        raise ConfigError("vehicle", path, "the path of a vehicle YAML file (a shipped vehicle has its shipped "
                          "schedules: gs-pid, gs-pid-flex, lqg)")
    path = str(Path(check_vehicle(path)).resolve())
    root = designs_folder() if cache else None
    if root is None and out is None:
        raise ConfigError("out", None, "a folder: the design cache is off ($LVGYM_CACHE_DIR=off or cache=False)")
    grid = AUTO_GRID if grid is None else grid
    folder = (root / design_key(path, budget, {**options, "lqg_grid": grid})) if root is not None else Path(out)
    summary_file = folder / FILES["summary"]
    if root is not None and summary_file.exists():
        design = VehicleDesign(folder, json.loads(summary_file.read_text()), cached=True)
    else:
        design = _design(path, folder, budget, grid, options, shared=root is not None)
    if root is not None:
        (root / f"{vehicle_key(path)}.latest").write_text(folder.name)
    if out is not None and Path(out).resolve() != folder.resolve():
        shutil.copytree(folder, out, dirs_exist_ok=True)
        design = VehicleDesign(Path(out), design.summary, design.cached)
    return design


def _design(path: str, folder: Path, budget: Budget, grid: dict, options: dict[str, Any], shared: bool) -> VehicleDesign:
    """Design into ``folder`` (through a partial folder renamed at the end); ``shared``: a cache entry,
    which another process may be making at the same time (the first one made is kept)."""
    work = folder.with_name(folder.name + f".partial-{os.getpid()}")
    work.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    if budget.workers == 1:
        results = [_rigid_then_lqg(path, str(work), options, budget, grid), _flex(path, str(work), options, budget)]
    else:
        with ProcessPoolExecutor(2) as pool:
            jobs = [pool.submit(_rigid_then_lqg, path, str(work), options, budget, grid),
                    pool.submit(_flex, path, str(work), options, budget)]
            results = [j.result() for j in jobs]
    summary = {"vehicle": path, "budget": asdict(budget), "lqg_grid": {k: list(v) for k, v in grid.items()},
               "env_options": options, "version": VERSION,
               "seconds": round(time.perf_counter() - start, 2), "operating_points": "the privileged reference",
               **{k: v for r in results for k, v in r.items()}}
    (work / FILES["summary"]).write_text(json.dumps(summary, indent=1))
    if shared and (folder / FILES["summary"]).exists():   # another process (an evaluation's worker) was first
        shutil.rmtree(work)
        return VehicleDesign(folder, json.loads((folder / FILES["summary"]).read_text()), cached=True)
    shutil.rmtree(folder, ignore_errors=True)        # an unfinished entry
    try:
        work.rename(folder)
    except OSError:                                  # ... or it finished just now
        shutil.rmtree(work)
        return VehicleDesign(folder, json.loads((folder / FILES["summary"]).read_text()), cached=True)
    return VehicleDesign(folder, summary, cached=False)


@dataclass
class Args:
    """Command-line arguments (``lvgym design auto --help``)."""

    vehicle: str = arg(check=vehicle_option, metavar="PATH")
    """the vehicle YAML file (docs/vehicles.md)"""
    out: str | None = None
    """a folder to copy the design into (default: the cache's entry only, printed)"""
    flex_maxiter: int = arg(Budget.flex_maxiter, lo=10, hi=100_000)
    """the flexible design's optimiser iterations per row"""
    workers: int = arg(Budget.workers, lo=1, hi=2)
    """worker processes"""
    rows: int = arg(Budget.rows, lo=1, hi=40)
    """the schedules' rows (equal parts of the burning flight)"""
    no_cache: bool = False
    """design again even if the cache holds the vehicle's design (needs --out)"""


def main(argv: list[str] | None = None) -> int:
    """``lvgym design auto``: design (or read from the cache) and print the summary."""
    from lvgym.commandline import command_name, fail, parse

    prog = "python -m lvgym.baselines.design.auto"
    a = parse(Args, argv, prog, __doc__)
    try:
        d = design_vehicle(a.vehicle, Budget(a.flex_maxiter, 0, a.workers, a.rows), out=a.out, cache=not a.no_cache)
    except ConfigError as exc:
        fail(command_name(prog), exc)
    print(summary_text(d))
    return 0


def summary_text(d: VehicleDesign) -> str:
    """The design's summary as a few lines of text: where, how long, and per design how many rows meet."""
    s = d.summary
    lines = [f"{'read from the cache' if d.cached else 'designed in %.1f s' % s['seconds']}: {d.folder}"]
    flex = s["gs-pid-flex"]["rows"]
    lines.append(f"  gs-pid-flex: {sum(r['meets'] for r in flex)} of {len(flex)} rows meet every requirement "
                 f"({s['gs-pid-flex']['seconds']:.1f} s)")
    lqg = s["lqg"]["rows"]
    n_lqg = sum(all(v == 0.0 for k, v in r.items() if k != "time_s") for r in lqg)
    lines.append(f"  lqg: {n_lqg} of {len(lqg)} rows meet the margin targets in both planes ({s['lqg']['seconds']:.1f} s)")
    rigid = s["gs-pid"]["rows"]
    held = sum(bool(r["nonrigid_stable"]) for r in rigid)
    lines.append(f"  gs-pid (rigid design): its loop is stable on the non-rigid plant at {held} of {len(rigid)} rows "
                 f"({s['gs-pid']['seconds']:.1f} s)")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main())
