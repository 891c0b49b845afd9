"""Speed of the ascent envs: env steps per second (``lvgym bench-envs``, ``python -m lvgym.bench_envs``).

SMILE's env of protocol v1 (``lvgym/SmileAscent-v1``; ``--protocol v0``: ``lvgym/SmileAscent-v0``), rigid
and non-rigid, at the protocol's defaults (50 Hz control over 100 Hz RK4: two RK4 steps, eight evaluations
of the flight loads, the servo and the task signals per env step; v1 also the IMU's filters, the flight
computer, one period of action delay, the coast control and the settling thrust), with zero actions from
mid-flight states (the first 5 s, on the pad and before the controller acts, are skipped by a warm-up).
Three ways: one env through ``gymnasium.make`` (with its wrappers), the native ``VectorEnv`` of N rows
(``gymnasium.make_vec``; rows split over the threads of the simulator), and the SB3 ``VecEnv`` adapter
(which builds one info dict per row, as SB3 requires).

Numbers from different machines differ (the same 2-core kind has given 60 % of another's). So every row of
the table also gives a ratio that does not depend on the machine: the cost of one env step (per simulator
thread) in steps of the bare dynamics core (one RK4 step of the same vehicle size with held loads,
:mod:`lvgym.bench`), measured in the same run. A SMILE env step does 2 RK4 steps, each with 4 evaluations
of the flight loads, plus the servo, the events and the task signals, so the ratio is at least 2.
A row "the floor" measures that physics alone on the batched env's own rows (:func:`floor`): the 2 RK4 steps
of a control period with their 8 load evaluations, nothing else.
The ratio is given twice: from wall times (the core's RK4 steps per second times the simulator threads,
over the env steps per second: a thread waiting for the Python part of a step counts) and from CPU times
(``time.process_time``, every thread's: the CPU seconds of an env step over those of a core RK4 step). On a
shared machine the wall-time ratio of the batched envs moves with the other jobs (the second thread's
share of a core varies; runs of the same code gave 7.7-10.1 under a load of 4 on 2 cores), the CPU-time
ratio much less. ``--threads 1`` (``$LVGYM_THREADS``) runs the batched envs on one thread.

Construction (``--only construction``): wall time of starting a simulator, median of ``--repeats`` runs in one
process after a warm-up (imports done, Numba's kernels loaded from its disk cache): **cold**, an empty timeline
cache, so the mass and mode tables are built (a new or dispersed vehicle); **warm**, the same cache folder
again, the tables read back (:mod:`lvgym.simulator.cache`). Both read the vehicle file and build the
aerodynamic tables. Cases: the rigid Stratos III simulator of the RocketPy validation (240 s, 4,803 table rows;
:func:`lvgym.verify.rocketpy_flights.lvgym_simulator`) and ``gymnasium.make`` plus ``reset`` of SmileAscent-v0
(non-rigid, 1,224 rows, modes at lift-off and at the separation), SmileAscent-v1 (modes every 2 s: 33 beam
eigen-solves), SlenderAscent-v0 (10 s) and SlenderAscent-v1 (6 eigen-solves). A third column, **new
process**, times a fresh interpreter's ``import lvgym`` and the same start with the tables cached
(:func:`first_start`): what a script or a worker process pays before its first step. Each cold and warm
time is given as wall time and as CPU time of the process (``time.process_time``; much less sensitive to
other jobs on the machine than the wall time, though not immune to them).

``--against DIR`` (construction only) compares with another checkout of lvgym (``DIR`` holds its ``lvgym``
package, e.g. a ``git worktree`` of an older commit) in the same sitting: ``--rounds`` rounds, each a new
process of that checkout and one of this, in turn (the order alternating), each timing ``--repeats`` cold and
warm starts after a warm-up (:data:`CHILD`, code that runs on either); it prints the medians over the
processes of their medians and the ratios (``DIR`` / this: how many times faster this one starts).
"""

from __future__ import annotations

import os
import platform
import time
from dataclasses import dataclass
from typing import Literal

import gymnasium as gym
import numpy as np

import lvgym  # noqa: F401  (registers the envs)
from lvgym.commandline import arg, parse
from lvgym.envs import make_sb3_vec_env

#: the env measured for each protocol (``--protocol``)
ENV_IDS = {"v0": "lvgym/SmileAscent-v0", "v1": "lvgym/SmileAscent-v1"}


def _timed(step, n_min: int, min_time: float) -> tuple[float, float]:
    """Calls per second of ``step()`` over at least ``n_min`` calls and ``min_time`` seconds (wall time),
    and the CPU time of the process per call [s] (``time.process_time``: every thread's)."""
    n, start, cpu = 0, time.perf_counter(), time.process_time()
    while n < n_min or time.perf_counter() - start < min_time:
        step()
        n += 1
    return n / (time.perf_counter() - start), (time.process_time() - cpu) / n


def single(env_id: str, model: str, min_time: float) -> tuple[float, float]:
    """Env steps per second and CPU seconds per env step of one env (:func:`_timed`)."""
    env = gym.make(env_id, model=model)
    env.reset(seed=0)
    a = np.zeros(2, dtype=np.float32)
    for _ in range(250):                                   # 5 s: off the pad, controller on
        env.step(a)

    def step():
        _, _, term, trunc, _ = env.step(a)
        if term or trunc:
            env.reset()
    return _timed(step, 200, min_time)


def vector(env_id: str, model: str, n: int, min_time: float) -> tuple[float, float]:
    """Env steps per second and CPU seconds per env step of the native VectorEnv of ``n`` rows."""
    env = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", model=model)
    env.reset(seed=0)
    a = np.zeros((n, 2), dtype=np.float32)
    for _ in range(250):
        env.step(a)
    rate, cpu = _timed(lambda: env.step(a), 20, min_time)
    return n * rate, cpu / n


def sb3(env_id: str, model: str, n: int, min_time: float) -> tuple[float, float]:
    """Env steps per second and CPU seconds per env step of the SB3 VecEnv of ``n`` rows."""
    env = make_sb3_vec_env(env_id, num_envs=n, seed=0, model=model)
    env.reset()
    a = np.zeros((n, 2), dtype=np.float32)
    for _ in range(250):
        env.step(a)
    rate, cpu = _timed(lambda: env.step(a), 20, min_time)
    return n * rate, cpu / n


#: the dynamics core's size of each model of SmileAscent-v0 and -v1 (slosh pendulums, modes per plane)
CORE_SIZE = {"rigid": (0, 0), "nonrigid": (6, 2)}


def core(model: str, min_time: float) -> tuple[float, float]:
    """RK4 vehicle-steps per second of the bare dynamics core for the model's size (one thread, a batch
    of 256 with held loads: :func:`lvgym.bench.vehicle`), and CPU seconds per vehicle-step."""
    from lvgym.bench import vehicle
    from lvgym.dynamics import step_batch, zoh_loads

    n_slosh, n_modes = CORE_SIZE[model]
    m, x, p, u = vehicle(n_slosh, n_modes, 256)
    n_u = m.layout.n_u
    step_batch(zoh_loads, x, p, u, 0.0, 1e-3, 20, n_slosh, n_modes, True, n_u)
    rate, cpu = _timed(lambda: step_batch(zoh_loads, x, p, u, 0.0, 1e-3, 20, n_slosh, n_modes, True, n_u), 20,
                       min_time)
    return 256 * 20 * rate, cpu / (256 * 20)


def floor(env_id: str, model: str, n: int, min_time: float) -> tuple[float, float]:
    """The physics of an env step alone, per row: the 2 RK4 steps of one control period, with their 8
    evaluations of the flight loads (:data:`lvgym.simulator.flight.flight_loads`: gravity, atmosphere,
    wind, aerodynamics, thrust), on the rows of the native VectorEnv of ``n`` rows at mid-flight (after
    the warm-up of :func:`vector`), on one thread; no servo, sensors, events, timeline look-up or task
    signals. Rows per second and CPU seconds per row. Each call starts from the same states."""
    from lvgym.dynamics import step_batch
    from lvgym.simulator.flight import flight_loads

    env = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", model=model)
    env.reset(seed=0)
    a = np.zeros((n, 2), dtype=np.float32)
    for _ in range(250):
        env.step(a)
    sim, data = env.unwrapped.func.sim, env.unwrapped.core.state.sim
    s, spec = sim.setup, env.unwrapped.func.spec
    n_rk4, h = spec.substeps, spec.timing.physics_dt_s
    x0, p, ctx = data.x.copy(), data.p.copy(), data.ctx.copy()
    x = x0.copy()

    def physics() -> None:
        x[:] = x0
        step_batch(flight_loads, x, p, ctx, 0.0, h, n_rk4, s.n_slosh, s.n_modes, True, s.n_u)

    physics()
    rate, cpu = _timed(physics, 20, min_time)
    return n * rate, cpu / n


def run(min_time: float = 2.0, batch: int = 1024, protocol: str = "v1") -> list[tuple[str, str, float, float, float]]:
    """``(model, how, env-steps/s, cost, CPU cost)`` rows of the env of ``protocol`` (:data:`ENV_IDS`): the
    cost of an env step in core RK4 steps, per simulator thread from the wall times, and from the CPU
    times (see the module docstring)."""
    from lvgym.simulator.threads import default_threads

    env_id = ENV_IDS[protocol]
    threads = default_threads()
    rows = []
    for model in ("rigid", "nonrigid"):
        base, base_cpu = core(model, min_time)
        for how, (rate, cpu), used in (("single env (gymnasium.make)", single(env_id, model, min_time), 1),
                                       (f"VectorEnv, {batch} rows", vector(env_id, model, batch, min_time), threads),
                                       (f"SB3 VecEnv, {batch} rows", sb3(env_id, model, batch, min_time), threads)):
            rows.append((model, how, rate, base * used / rate, cpu / base_cpu))
        rate, cpu = floor(env_id, model, batch, min_time)
        rows.append((model, f"the floor: 2 RK4 steps with 8 flight-load evaluations, {batch} rows, 1 thread",
                     rate, base / rate, cpu / base_cpu))
        rows.append((model, "dynamics core alone, 256 vehicles, 1 thread [RK4 steps/s]", base, 1.0, 1.0))
    return rows


#: construction cases: label -> what to build (:func:`construction`)
CONSTRUCTION = {"Simulator('stratos3', 'rigid'), 240 s": "stratos3", "lvgym/SmileAscent-v0": "lvgym/SmileAscent-v0",
                "lvgym/SmileAscent-v1": "lvgym/SmileAscent-v1", "lvgym/SlenderAscent-v0": "lvgym/SlenderAscent-v0",
                "lvgym/SlenderAscent-v1": "lvgym/SlenderAscent-v1"}


def _start(what: str) -> None:
    """Start the simulator of a :data:`CONSTRUCTION` case, with the processes' vehicle and timeline caches
    emptied (each run reads its vehicle file and looks its tables up again)."""
    from lvgym.envs import functional
    from lvgym.vehicle import clear_vehicle_cache

    clear_vehicle_cache()
    functional.cached_vehicle.cache_clear()
    functional.cached_timeline.cache_clear()
    if what == "stratos3":
        from lvgym.verify.rocketpy_flights import lvgym_simulator
        lvgym_simulator().reset()
    else:
        gym.make(what).reset(seed=0)


def first_start(what: str, repeats: int = 3) -> float:
    """Median wall time [s] of a new Python process's ``import lvgym`` plus the start of a
    :data:`CONSTRUCTION` case, the tables taken from the user's cache (what a script or a worker pays
    before its first step; the interpreter's own start is not counted)."""
    import subprocess
    import sys

    code = ("import time, warnings; t = time.perf_counter(); warnings.simplefilter('ignore')\n"
            "import gymnasium as gym, lvgym\nfrom lvgym.bench_envs import _start\n"
            f"_start({what!r}); print(time.perf_counter() - t)")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)      # fills the cache
    times = [float(subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                                  text=True).stdout.split()[-1]) for _ in range(repeats)]
    return float(np.median(times))


def construction(repeats: int = 5) -> list[tuple[str, float, float, float, float]]:
    """``(case, cold [s], warm [s], cold CPU [s], warm CPU [s])`` medians of ``repeats`` runs (see the
    module docstring)."""
    import tempfile
    import warnings

    from lvgym.simulator.cache import using

    rows = []
    with tempfile.TemporaryDirectory(prefix="lvgym-bench-") as root, warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)     # v0's "out of date" notice
        for label, what in CONSTRUCTION.items():
            with using(os.path.join(root, f"{what.replace('/', '_')}-warm-up")):
                _start(what)
            times: dict[str, list[float]] = {"cold": [], "warm": [], "cold_cpu": [], "warm_cpu": []}
            for k in range(repeats):
                with using(os.path.join(root, f"{what.replace('/', '_')}-{k}")):
                    for kind in ("cold", "warm"):
                        wall, cpu = time.perf_counter(), time.process_time()
                        _start(what)
                        times[kind + "_cpu"].append(time.process_time() - cpu)
                        times[kind].append(time.perf_counter() - wall)
            rows.append((label, *(float(np.median(times[k])) for k in ("cold", "warm", "cold_cpu", "warm_cpu"))))
    return rows


#: the construction timing of one case in a new process, for either checkout of :func:`compare` (it uses
#: only what the per-row code of 2026-11 had too): argv ``what repeats``; prints one JSON line of the medians
CHILD = """
import json, os, sys, tempfile, time, warnings
warnings.simplefilter("ignore")
import numpy as np, gymnasium as gym, lvgym, lvgym.vehicle
from lvgym.envs import functional
what, repeats = sys.argv[1], int(sys.argv[2])
def start():
    getattr(lvgym.vehicle, "clear_vehicle_cache", lambda: None)()      # (a checkout may not keep vehicles)
    functional.cached_vehicle.cache_clear()
    functional.cached_timeline.cache_clear()
    if what == "stratos3":
        from lvgym.verify.rocketpy_flights import lvgym_simulator
        lvgym_simulator().reset()
    else:
        gym.make(what).reset(seed=0)
root = tempfile.mkdtemp(prefix="lvgym-bench-")
os.environ["LVGYM_CACHE_DIR"] = os.path.join(root, "warm-up")
start()
start()
times = {"cold": [], "warm": [], "cold_cpu": [], "warm_cpu": []}
for k in range(repeats):
    os.environ["LVGYM_CACHE_DIR"] = os.path.join(root, str(k))
    for kind in ("cold", "warm"):
        wall, cpu = time.perf_counter(), time.process_time()
        start()
        times[kind + "_cpu"].append(time.process_time() - cpu)
        times[kind].append(time.perf_counter() - wall)
print(json.dumps({k: float(np.median(v)) for k, v in times.items()} | {"lvgym": lvgym.__file__}))
"""


def compare(other: str, rounds: int = 3, repeats: int = 7, cases: dict[str, str] | None = None
            ) -> list[tuple[str, str, float, float]]:
    """``(case, measure, other [s], this [s])``: medians over ``rounds`` processes of each checkout of the
    :data:`CHILD` medians (``measure``: cold, cold_cpu, warm, warm_cpu), the checkouts in turn (see the
    module docstring). ``other``: a folder holding another checkout's ``lvgym`` package."""
    import json
    import subprocess
    import sys
    import tempfile

    import lvgym as this_lvgym

    trees = {"other": os.path.abspath(other), "this": os.path.dirname(os.path.dirname(this_lvgym.__file__))}
    results: dict[tuple[str, str, str], list[float]] = {}
    with tempfile.TemporaryDirectory(prefix="lvgym-bench-cwd-") as cwd:     # no checkout on sys.path's ''
        for r in range(rounds):
            for label, what in (cases or CONSTRUCTION).items():
                for tree in (("other", "this") if r % 2 == 0 else ("this", "other")):
                    env = dict(os.environ, PYTHONPATH=trees[tree])
                    out = subprocess.run([sys.executable, "-c", CHILD, what, str(repeats)], cwd=cwd, env=env,
                                         check=True, capture_output=True, text=True).stdout
                    got = json.loads(out.strip().splitlines()[-1])
                    if not got["lvgym"].startswith(trees[tree]):
                        raise RuntimeError(f"{tree}: imported {got['lvgym']}, not from {trees[tree]}")
                    for measure in ("cold", "cold_cpu", "warm", "warm_cpu"):
                        results.setdefault((label, measure, tree), []).append(got[measure])
    return [(label, measure, float(np.median(results[label, measure, "other"])),
             float(np.median(results[label, measure, "this"])))
            for label in (cases or CONSTRUCTION) for measure in ("cold", "cold_cpu", "warm", "warm_cpu")]


def cpu_name() -> str:
    """The CPU's model name (``/proc/cpuinfo``), else what ``platform`` knows."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def load_average() -> str:
    """The 1, 5 and 15 minute load averages (``/proc/loadavg``), or ``?``."""
    try:
        with open("/proc/loadavg", encoding="utf-8") as f:
            return " ".join(f.read().split()[:3])
    except OSError:
        return "?"


@dataclass
class Args:
    """Command-line arguments (``lvgym bench-envs --help``)."""

    min_time: float = arg(2.0, lo=0.0, lo_open=True, hi=3600.0)
    """seconds per measurement"""
    batch: int = arg(1024, lo=1, hi=1 << 20)
    """rows of the batched envs"""
    repeats: int = arg(5, lo=1, hi=10_000)
    """runs per construction case"""
    protocol: Literal["v0", "v1"] = "v1"
    """steps: the protocol whose SMILE env is measured (lvgym/SmileAscent-v1 or -v0)"""
    threads: int | None = arg(None, lo=1, hi=1024)
    """simulator threads of the batched envs (default $LVGYM_THREADS, else the CPUs)"""
    only: Literal["steps", "construction"] | None = None
    """one of the two tables (default: both)"""
    against: str | None = arg(None, metavar="DIR")
    """construction: compare with the checkout whose lvgym package is in DIR, process by process in turn
    (see the module docstring)"""
    rounds: int = arg(3, lo=1, hi=10_000)
    """--against: processes of each checkout per case"""
    case: list[str] | None = arg(None, choices=tuple(sorted(CONSTRUCTION.values())), extend=True, metavar="CASE")
    """--against: only these construction cases (a repeated flag adds)"""


def main(argv: list[str] | None = None) -> None:
    """``lvgym bench-envs`` (``python -m lvgym.bench_envs``): print the tables."""
    args = parse(Args, argv, "python -m lvgym.bench_envs", __doc__)
    if args.against:
        cases = {k: v for k, v in CONSTRUCTION.items() if not args.case or v in args.case}
        rows = compare(args.against, args.rounds, args.repeats, cases)
        print(f"# construction [s], {args.against} against this checkout: medians over {args.rounds} processes "
              f"each of the medians of {args.repeats} runs, in turn ({cpu_name()}, load {load_average()})\n")
        print("| case | measure | other | this | other / this |")
        print("|---|---|---:|---:|---:|")
        for label, measure, other, this in rows:
            print(f"| {label} | {measure.replace('_cpu', ', CPU')} | {other:.4f} | {this:.4f} | {other / this:.1f} |")
        return
    from lvgym.simulator.threads import default_threads
    if args.threads is not None:
        os.environ["LVGYM_THREADS"] = str(args.threads)
    if args.only != "construction":
        rows = run(args.min_time, args.batch, args.protocol)
        print(f"# {ENV_IDS[args.protocol]} env steps per second ({cpu_name()}, {os.cpu_count()} cores, {default_threads()} "
              "simulator threads)\n")
        print("| model | how | env-steps/s | cost of an env step in core RK4 steps (per thread) | the same from "
              "CPU times |")
        print("|---|---|---|---|---|")
        for model, how, rate, ratio, ratio_cpu in rows:
            print(f"| {model} | {how} | {rate:,.0f} | {ratio:.2f} | {ratio_cpu:.2f} |")
    if args.only != "steps":
        print(f"\n# construction: starting a simulator [s], median of {args.repeats} ({cpu_name()})\n")
        print("| case | cold (tables built) | warm (tables from the cache) | cold, CPU | warm, CPU "
              "| new process (imports, cached tables) |")
        print("|---|---|---|---|---|---|")
        for label, cold, warm, cold_cpu, warm_cpu in construction(args.repeats):
            first = first_start(CONSTRUCTION[label], max(1, args.repeats // 2))
            print(f"| construction, {label} | {cold:.4f} | {warm:.4f} | {cold_cpu:.4f} | {warm_cpu:.4f} | {first:.3f} |")


if __name__ == "__main__":
    main()
