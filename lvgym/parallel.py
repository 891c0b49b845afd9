"""Map a picklable function over tasks: serially, on a local process pool or on Ray, with a progress bar.

The one executor of the benchmark's episodes (:func:`lvgym.benchmark.evaluate`) and of the studies' runs
(:mod:`lvgym.studies`): any module-level function, any picklable tasks, and a callback per finished task
(the studies write their cache there, so an interrupted study keeps every run that finished). Results
come back in the order of the tasks whatever the executor. Pool workers are spawned (they inherit no
numba or BLAS threads) and exit when their parent dies, so a killed run leaves no workers behind.

An exception raised in a task reaches the caller as itself, with its own message, whatever the executor:
the worker checks that it survives pickling and, if it does not, sends a :class:`WorkerError` carrying
its type, message and traceback instead (a pool would otherwise break with ``BrokenProcessPool`` and
lose the message); Ray's ``RayTaskError`` wrapper is removed. With ``describe``, the error is a
:class:`TaskFailed` naming the task, raised from the original. A pool whose worker died (killed, out of
memory, or a calling script without an ``if __name__ == "__main__":`` guard, which every spawned worker
re-imports) raises a ``BrokenProcessPool`` that says so.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

__all__ = ["EXECUTORS", "TaskFailed", "WorkerError", "check_workers", "default_workers", "exit_on_sigterm",
           "run_map"]

EXECUTORS = ("local", "serial", "ray")
T = TypeVar("T")
R = TypeVar("R")

BROKEN_POOL_HELP = (
    "lvgym: a worker of the local process pool died. Workers are spawned and import the calling script again: a "
    "script that runs lvgym at import time needs its top level under `if __name__ == \"__main__\":` "
    "(Python printed its own explanation above if so). Other causes: the worker was killed or ran out of "
    "memory (fewer `workers`), or a native crash. executor='serial' runs in this process.")


def exit_on_sigterm() -> None:
    """Make SIGTERM end this process like ``sys.exit(128 + SIGTERM)``: ``finally`` blocks and context
    managers run (temporary files are removed, workers stopped), as on Ctrl-C. For the command lines."""
    import signal

    def _exit(signum: int, frame: Any) -> None:
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, _exit)


def default_workers() -> int:
    """CPUs this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:                        # not on Linux
        return max(1, os.cpu_count() or 1)


def _exit_with_parent(parent: int) -> None:
    """Worker initializer: a daemon thread ends the worker once its parent is gone (a pool's workers
    otherwise wait for work forever)."""
    import threading
    import time

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


class WorkerError(RuntimeError):
    """An exception of a task that could not be sent back from its worker as itself (it does not pickle):
    its type, message and the worker's traceback, as text."""


class TaskFailed(RuntimeError):
    """Task ``describe(task)`` failed; raised from the task's own exception (``__cause__``)."""


def check_workers(workers: Any, option: str = "workers") -> int | None:
    """``workers`` (None: the default) when it is an integer >= 1; else a ConfigError naming ``option``."""
    if workers is None:
        return None
    import numbers

    from lvgym.errors import check_number

    if isinstance(workers, numbers.Integral) and not isinstance(workers, bool):
        workers = int(workers)                        # numpy integers too
    return check_number(option, workers, 1, 100_000, integer=True)


def _call(fn: Callable[[T], R], task: T) -> R:
    """``fn(task)`` in a worker, its exception made safe to send back (see the module docstring)."""
    try:
        return fn(task)
    except Exception as exc:
        import pickle

        try:
            pickle.loads(pickle.dumps(exc))
        except Exception:  # noqa: BLE001
            import traceback

            text = "".join(traceback.format_exception(exc))
            raise WorkerError(f"{type(exc).__module__}.{type(exc).__qualname__}: {exc}\n\nworker traceback:\n"
                              f"{text}") from None
        raise


class _TaskError(Exception):
    """The exception of task ``index``, raised from it (``__cause__``)."""

    def __init__(self, index: int) -> None:
        super().__init__(index)
        self.index = index


def _serial(fn: Callable[[T], R], tasks: Sequence[T], done: Callable[[int, R], None]) -> None:
    for i, t in enumerate(tasks):
        try:
            r = fn(t)
        except Exception as exc:
            raise _TaskError(i) from exc
        done(i, r)


def _local(fn: Callable[[T], R], tasks: Sequence[T], done: Callable[[int, R], None], workers: int) -> None:
    import multiprocessing as mp

    # spawn: workers inherit neither the parent's threads (numba, BLAS) nor its open files
    with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"),
                             initializer=_exit_with_parent, initargs=(os.getpid(),)) as pool:
        futures = {pool.submit(_call, fn, t): i for i, t in enumerate(tasks)}
        pending = set(futures)
        try:
            while pending:
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for f in finished:
                    try:
                        r = f.result()
                    except BrokenProcessPool as exc:
                        raise _TaskError(futures[f]) from BrokenProcessPool(f"{exc} ({BROKEN_POOL_HELP})")
                    except Exception as exc:
                        raise _TaskError(futures[f]) from exc
                    done(futures[f], r)
        except BaseException:
            pool.shutdown(wait=True, cancel_futures=True)
            raise


def _ray(fn: Callable[[T], R], tasks: Sequence[T], done: Callable[[int, R], None], workers: int) -> None:
    try:
        import ray
    except ImportError as exc:
        raise ImportError("executor 'ray' needs Ray: pip install 'lvgym[ray]' (or pip install ray)") from exc
    started = not ray.is_initialized()
    if started and os.environ.get("RAY_ADDRESS"):     # join the cluster named by RAY_ADDRESS
        ray.init(log_to_driver=False, configure_logging=False)
    elif started:                                     # a local Ray of `workers` CPUs, for this map
        # address="local": a new instance even if `ray start` ran on this machine (ray.init would join it)
        ray.init(address="local", num_cpus=workers, include_dashboard=False, log_to_driver=False,
                 configure_logging=False)
    from ray.exceptions import RayTaskError

    try:
        remote = ray.remote(num_cpus=1)(_call)
        refs = [remote.remote(fn, t) for t in tasks]
        index = {r: i for i, r in enumerate(refs)}
        pending = list(refs)
        try:
            while pending:
                finished, pending = ray.wait(pending, num_returns=1)
                for ref in finished:
                    try:
                        r = ray.get(ref)
                    except RayTaskError as exc:                     # the task's own exception
                        cause = exc.cause if isinstance(exc.cause, BaseException) else exc
                        raise _TaskError(index[ref]) from cause
                    except Exception as exc:                        # worker died, cancelled, ...
                        raise _TaskError(index[ref]) from exc
                    done(index[ref], r)
        except BaseException:
            for p in pending:
                ray.cancel(p, force=True)
            raise
    finally:
        if started:
            ray.shutdown()


class _NoBar:
    """Stands in for tqdm's bar when there is none to draw."""

    def __enter__(self) -> _NoBar:
        return self

    def __exit__(self, *exc: Any) -> None:
        return None

    def update(self, n: int = 1) -> None:
        return None


def _progress_bar(total: int, desc: str, unit: str, progress: bool) -> Any:
    """tqdm's bar on stderr when ``progress`` and tqdm is installed (the ``benchmark`` extra; the core install
    has no bar and runs the same)."""
    if not progress or importlib.util.find_spec("tqdm") is None:
        return _NoBar()
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, dynamic_ncols=True)


def run_map(fn: Callable[[T], R], tasks: Sequence[T], executor: str = "local", workers: int | None = None,
            progress: bool = True, on_result: Callable[[int, R], None] | None = None,
            desc: str = "runs", unit: str = "run", describe: Callable[[T], str] | None = None) -> list[R]:
    """``[fn(t) for t in tasks]`` computed by ``executor``, in the order of ``tasks``.

    executor: ``local`` (a spawn process pool of ``workers`` processes, default the CPUs available; one
    worker runs serially), ``serial`` (this process) or ``ray`` (Ray tasks; starts a local Ray with
    ``workers`` CPUs unless ``ray.init`` was called already or ``$RAY_ADDRESS`` names a cluster to join).
    ``fn`` must be a module-level function and the tasks picklable. ``progress``: a tqdm bar on stderr (none
    without tqdm, which the ``benchmark`` extra installs). ``on_result(i, result)`` is called in
    this process as each task finishes. An exception in a task stops the map and is raised here as
    itself, or as a :class:`TaskFailed` (a ``RuntimeError``) naming the task by ``describe(task)`` when
    ``describe`` is given. ``workers`` must be an integer >= 1 (a ConfigError otherwise)."""
    if executor not in EXECUTORS:
        raise ValueError(f"executor = {executor!r}: one of {EXECUTORS}")
    workers = check_workers(workers)
    results: list[Any] = [None] * len(tasks)
    if not tasks:
        return []
    n = max(1, min(workers or default_workers(), len(tasks)))
    with _progress_bar(len(tasks), desc, unit, progress) as bar:
        def done(i: int, r: R) -> None:
            results[i] = r
            if on_result is not None:
                on_result(i, r)
            bar.update(1)

        try:
            if executor == "serial" or (executor == "local" and n == 1):
                _serial(fn, tasks, done)
            elif executor == "local":
                _local(fn, tasks, done, n)
            else:
                _ray(fn, tasks, done, n)
        except _TaskError as exc:
            if describe is None:
                raise exc.__cause__ from None
            raise TaskFailed(f"task failed: {describe(tasks[exc.index])}: {exc.__cause__}") from exc.__cause__
    return results
