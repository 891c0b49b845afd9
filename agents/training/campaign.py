"""Training campaigns: configurations x seeds trained on this machine or on a Ray cluster, then every run
evaluated on the test seeds, then the comparison over the runs (issue 35).

    lvgym campaign agents/training/campaigns/v2_example.yaml --dry-run     # check the whole file, list the runs
    lvgym campaign my_campaign.yaml                                # run it here (workers train.py processes at once)
    lvgym campaign my_campaign.yaml --executor ray                 # on a local Ray, or the cluster at $RAY_ADDRESS
    RAY_ADDRESS=head-node:6379 lvgym campaign my_campaign.yaml --executor ray

The campaign file (docs/training.md, "Campaigns"; :mod:`lvgym.agents.training.campaign_schema`) names the
configurations (``train.py`` options), the training seeds, the options common to every run and the
evaluation. The whole file is checked before anything runs, each configuration by ``train.py``'s own
checks: a bad value is one line naming the file, the key path, the value and what is allowed, and no
folder is made.

Everything lives in ``<runs_dir>/<name>/``: the run folders ``<configuration>-s<seed>/`` (``train.py``'s),
``logs/<run>.log`` (each run's output, every attempt), ``evaluation/<run or baseline>.json`` (the episodes
of the test seeds), ``comparison.md`` and ``comparison.json`` (:mod:`lvgym.agents.training.campaign_compare`) and
``campaign.json`` (the file's text and every run's ``train.py`` options).

Each run is one task: a ``train.py`` process started by a worker of the executor (``local``: ``workers``
threads of this process, each waiting for its ``train.py``; ``ray``: a Ray task of one CPU). What the task
does is decided when it starts: a run with ``final_model.json`` at its target step is finished and skipped, a
run folder without it (or stopped short by its wall-time budget) continues with ``--resume`` (from its newest
checkpoint), else the run starts. So the command can simply be run again after a kill, and a Ray task whose worker or node died is retried by Ray (its
default ``max_retries``, 3) on another node, where it resumes; the run's lock file (``logs/<run>.lock``)
keeps a retry from starting while a ``train.py`` of the earlier attempt still writes. On a cluster the runs
folder must be on a file system every node sees (and lvgym installed on every node). A run that fails, or
stops at its wall-time budget, stops the campaign before the evaluation, naming it and its log; run the
campaign again to continue. Stopped by SIGTERM or Ctrl-C, the campaign sends each running ``train.py``
(local) one SIGTERM: it writes a checkpoint and exits; a ``train.py`` whose worker dies gets the same
(``PR_SET_PDEATHSIG``).

The evaluation flies, together (the benchmark's batched evaluation, on the same executor), every run's
policy (its best model by validation, else its final one) and every classical baseline that has no
evaluation file of the campaign's settings yet; a file already written is not flown again. The
comparison is then made from the files.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import hashlib
import json
import os
import socket
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from lvgym.commandline import arg, command_name, fail, parse
from lvgym.errors import ConfigError
from lvgym.parallel import TaskFailed, default_workers, exit_on_sigterm, run_map

from .campaign_schema import CAMPAIGN_EXECUTORS, Campaign, load_campaign

__all__ = ["Args", "RunTask", "campaign_state", "main", "run_state", "train_run"]

PROG = "lvgym campaign"


@dataclass
class Args:
    """Command-line arguments (``lvgym campaign --help``)."""

    file: str = arg(positional=True, metavar="FILE")
    """the campaign's YAML file"""
    executor: str | None = arg(None, choices=CAMPAIGN_EXECUTORS)
    """local (train.py processes on this machine, workers at once) or ray (a local Ray, or the cluster at $RAY_ADDRESS); default:
    the file's executor"""
    workers: int | None = arg(None, lo=1, hi=100_000, allowed="an integer >= 1")
    """runs at once on this machine (local; the CPUs of a local Ray); default: the file's, else the CPUs"""
    dry_run: bool = False
    """check the file and list the runs and what each would do, run nothing"""
    progress: bool = True
    """show the evaluation's progress bar"""


@dataclass(frozen=True)
class RunTask:
    """What a worker needs to train (or resume, or skip) one run; ``own_session``: start its train.py in a
    session of its own (on this machine: the campaign signals it, not the terminal)."""

    name: str
    folder: str
    argv: tuple[str, ...]
    log: str
    cwd: str
    own_session: bool = False


def run_state(folder: str | Path) -> str:
    """``finished`` (``final_model.json`` at the run's target step), ``resume`` (a run folder without it, or whose
    final model is short of the target: a run stopped by its wall-time budget ends with one too) or ``new``."""
    folder = Path(folder)
    final = folder / "final_model.json"
    if final.is_file() and _reached_target(folder, final):
        return "finished"
    return "resume" if (folder / "config.yaml").is_file() else "new"


def _reached_target(folder: Path, final: Path) -> bool:
    """Whether the final model's step is the run's target (``total_timesteps`` of its config.yaml) or beyond;
    True where either is not recorded."""
    import yaml

    try:
        step = json.loads(final.read_text(encoding="utf-8")).get("num_timesteps")
        target = (yaml.safe_load((folder / "config.yaml").read_text(encoding="utf-8")) or {}).get("total_timesteps")
    except (OSError, ValueError, AttributeError, yaml.YAMLError):
        return True
    return step is None or target is None or int(step) >= int(target)


#: the train.py child: SIGTERM (it checkpoints and exits) once the worker thread that started it is gone
#: (PR_SET_PDEATHSIG, Linux; set in the child itself, not in a preexec_fn, which threads make unsafe)
_CHILD = """import ctypes, os, runpy, signal, sys
try:
    ctypes.CDLL(None).prctl(1, signal.SIGTERM)
except Exception:
    pass
if os.getppid() != int(os.environ.pop("LVGYM_CAMPAIGN_PARENT", os.getppid())):
    sys.exit(128 + signal.SIGTERM)
sys.argv[0] = "train.py"
runpy.run_module("lvgym.agents.training.train", run_name="__main__", alter_sys=True)
"""


def _command(task: RunTask) -> list[str]:
    """The run's train.py options now: ``--resume`` for a run folder without final_model.json."""
    state = run_state(task.folder)
    argv = ["--resume", task.folder] if state == "resume" else list(task.argv)
    return [*argv, "--no-progress"]


#: the train.py processes this process started and waits for, and whether the campaign is stopping
_CHILDREN: set[Any] = set()
_GUARD = threading.Lock()
_STOPPING = threading.Event()


def train_run(task: RunTask) -> dict[str, Any]:
    """Train, resume or skip one run (decided now, from its folder: a retried task resumes); returns its
    status: ``skipped``, ``finished``, ``unfinished`` (stopped at its wall-time budget or by a signal) or
    ``failed``. The run's lock file (``logs/<run>.lock``, held by the train.py process too) makes a retried
    task wait for a train.py of an earlier attempt that is still writing its last checkpoint."""
    import fcntl
    import subprocess

    out = {"run": task.name, "host": socket.gethostname(), "pid": os.getpid()}
    if run_state(task.folder) == "finished":
        return {**out, "status": "skipped", "seconds": 0.0}
    Path(task.log).parent.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    with open(str(Path(task.log).with_suffix(".lock")), "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if run_state(task.folder) == "finished":
            return {**out, "status": "skipped", "seconds": 0.0}
        cmd = _command(task)
        with open(task.log, "ab") as log:
            log.write(f"== {dt.datetime.now(dt.timezone.utc).isoformat(timespec='seconds')} on {out['host']} "
                      f"(worker {os.getpid()}): {sys.executable} -m lvgym.agents.training.train "
                      f"{' '.join(cmd)}\n".encode())
            log.flush()
            cwd = task.cwd if os.path.isdir(task.cwd) else str(Path(task.folder).parent)
            with _GUARD:
                if _STOPPING.is_set():
                    return {**out, "status": "unfinished", "seconds": 0.0, "returncode": None}
                proc = subprocess.Popen([sys.executable, "-c", _CHILD, *cmd], stdout=log, stderr=subprocess.STDOUT,
                                        cwd=cwd, pass_fds=(lock.fileno(),), start_new_session=task.own_session,
                                        env={**os.environ, "LVGYM_CAMPAIGN_PARENT": str(os.getpid())})
                _CHILDREN.add(proc)
            try:
                proc.wait()
            finally:
                with _GUARD:
                    _CHILDREN.discard(proc)
    seconds = round(time.monotonic() - t0, 1)
    resumed = cmd[0] == "--resume"
    if proc.returncode == 0:
        status = "finished" if run_state(task.folder) == "finished" else "unfinished"
        return {**out, "status": status, "seconds": seconds, "resumed": resumed}
    tail = Path(task.log).read_text(encoding="utf-8", errors="replace").strip().splitlines()[-1:]
    status = "unfinished" if proc.returncode in (128 + 2, 128 + 15) else "failed"    # stopped by a signal
    return {**out, "status": status, "seconds": seconds, "returncode": proc.returncode, "resumed": resumed,
            "last_line": " ".join(tail)}


def _train_here(tasks: list[RunTask], workers: int, done: Any) -> list[dict[str, Any]]:
    """The runs on this machine, ``workers`` at once (a thread each waits for its train.py). Stopped (a
    signal, Ctrl-C): each running train.py gets one SIGTERM, writes a checkpoint and exits."""
    import signal
    from concurrent.futures import ThreadPoolExecutor, as_completed

    results = []
    pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="campaign-run")
    futures = [pool.submit(train_run, t) for t in tasks]
    try:
        for f in as_completed(futures):
            results.append(f.result())
            done(len(results) - 1, results[-1])
    except BaseException:
        with _GUARD:
            _STOPPING.set()
            for f in futures:
                f.cancel()
            for proc in _CHILDREN:
                with contextlib.suppress(ProcessLookupError):
                    proc.send_signal(signal.SIGTERM)
        _say("stopping: each running train.py writes a checkpoint and exits; run the campaign again to continue")
        raise
    finally:
        pool.shutdown(wait=True)
    return results


# ------------------------------------------------------------------------------------------ the plan
def campaign_state(campaign: Campaign) -> dict[str, str]:
    """Each run's state (:func:`run_state`)."""
    return {r.name: run_state(r.folder) for r in campaign.runs()}


def _check_unchanged(campaign: Campaign) -> None:
    """A run already started with other options than the file now gives is refused (naming its
    configuration): the run would continue with its own, and the comparison would mix the two."""
    path = campaign.folder / "campaign.json"
    if not path.is_file():
        return
    before = json.loads(path.read_text(encoding="utf-8")).get("runs", {})
    for r in campaign.runs():
        old = before.get(r.name, {}).get("argv")
        if old is None or run_state(r.folder) == "new":
            continue
        was, now = _options(old), _options(r.argv)
        changed = [f for f in dict.fromkeys([*was, *now]) if was.get(f) != now.get(f)]
        if changed:
            raise ConfigError(f"configurations.{r.configuration}", _shown(now, changed), f"run {r.name} was started "
                              f"with {_shown(was, changed)}, and continues with its own options: give the changed configuration a "
                              "new name (or remove its run folders)", campaign.source)


def _options(argv: Any) -> dict[str, tuple[str, ...]]:
    """train.py options by flag (their order in the file does not matter)."""
    out: dict[str, tuple[str, ...]] = {}
    flag = ""
    for word in argv:
        if word.startswith("--"):
            flag = word
            out[flag] = ()
        else:
            out[flag] = (*out.get(flag, ()), word)
    return out


def _shown(options: dict[str, tuple[str, ...]], flags: list[str]) -> str:
    return " ".join(" ".join([f, *options[f]]) for f in flags if f in options) or "(not given)"


def _write_plan(campaign: Campaign) -> None:
    from lvgym.benchmark.results import atomic_write_text, json_text

    path = campaign.folder / "campaign.json"
    runs = json.loads(path.read_text(encoding="utf-8")).get("runs", {}) if path.is_file() else {}
    runs.update({r.name: {"configuration": r.configuration, "seed": r.seed, "argv": list(r.argv)}
                 for r in campaign.runs()})
    campaign.folder.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, json_text({"name": campaign.name, "source": campaign.source,
                                       "file": Path(campaign.source).read_text(encoding="utf-8"), "runs": runs,
                                       "updated_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")}))


def _say(text: str) -> None:
    print(f"{command_name(PROG)}: {text}", file=sys.stderr, flush=True)


# ------------------------------------------------------------------------------------------ executors
@contextlib.contextmanager
def _ray_session(executor: str, workers: int | None) -> Iterator[None]:
    """Ray for both stages (started once): the cluster at $RAY_ADDRESS, else a local Ray of ``workers`` CPUs."""
    if executor != "ray":
        yield
        return
    import ray

    started = not ray.is_initialized()
    if started and os.environ.get("RAY_ADDRESS"):
        ray.init(log_to_driver=False, configure_logging=False)
    elif started:
        ray.init(address="local", num_cpus=workers or default_workers(), include_dashboard=False,
                 log_to_driver=False, configure_logging=False)
    try:
        yield
    finally:
        if started:
            ray.shutdown()


def _train_all(campaign: Campaign, executor: str, workers: int | None) -> list[dict[str, Any]]:
    runs = [r for r in campaign.runs() if run_state(r.folder) != "finished"]
    tasks = [RunTask(r.name, r.folder, r.argv, str(campaign.folder / "logs" / f"{r.name}.log"), os.getcwd())
             for r in runs]
    if not tasks:
        return []

    def done(i: int, result: dict[str, Any]) -> None:
        more = f": {result.get('last_line', '')}" if result.get("last_line") else ""
        again = " (resumed)" if result.get("resumed") else ""
        _say(f"run {result['run']} {result['status']}{again} in {result['seconds']:.0f} s on {result['host']}{more}")

    n = workers or default_workers()
    if executor == "local":
        return _train_here([replace(t, own_session=True) for t in tasks], min(n, len(tasks)), done)
    return run_map(train_run, tasks, executor, n, progress=False, on_result=done, desc="runs", unit="run",
                   describe=lambda t: f"run {t.name}")


def _stamp(folder: str) -> str:
    """What a run's evaluation depends on besides the settings: its final model's record."""
    return hashlib.sha1((Path(folder) / "final_model.json").read_bytes()).hexdigest()[:16]


def _evaluate_all(campaign: Campaign, executor: str, workers: int | None, progress: bool) -> list[dict[str, Any]]:
    """Every run's and baseline's evaluation records; those not written yet (with these settings) flown now,
    in one evaluation: a run on the suites its configuration flies (:meth:`Campaign.suites_of`: the family's
    informed runs on the informed suite, the others on the rest), a baseline on every suite."""
    import lvgym.baselines  # noqa: F401  (registers the controllers by name)
    from lvgym.benchmark import evaluate, get_suite
    from lvgym.benchmark.registry import resolve_policy

    from .campaign_compare import evaluation_settings, read_evaluation, write_evaluation

    ev = campaign.evaluation
    settings = evaluation_settings(ev)
    folder = campaign.folder / "evaluation"
    wanted = [(r.name, f"{r.name}={r.folder}", _stamp(r.folder), campaign.suites_of(r.configuration))
              for r in campaign.runs()]
    wanted += [(b, b, None, ev.suites) for b in ev.baselines]
    records: dict[str, list[dict[str, Any]]] = {}
    todo = []
    for label, ref, stamp, flies in wanted:
        have = read_evaluation(folder / f"{label}.json", settings, stamp)
        if have is None:
            todo.append((label, ref, stamp, flies))
        else:
            records[label] = have
    _say(f"evaluation: {len(records)} of {len(wanted)} already written; flying {len(todo)} "
         f"({', '.join(x[0] for x in todo) or 'none'})")
    if todo:
        suites = [get_suite(s) for s in ev.suites if any(s in flies for *_, flies in todo)]
        if ev.mission_time_s is not None:
            suites = [s.with_options(mission_time_s=ev.mission_time_s) for s in suites]
        specs = {label: resolve_policy(ref, command_name(PROG)) for label, ref, _, _ in todo}
        per_suite = {s.name: [specs[label] for label, *_, flies in todo if s.name in flies] for s in suites}
        t0 = time.perf_counter()
        flown = evaluate(per_suite, suites, ev.episodes, ev.seed_set, "ray" if executor == "ray" else "local",
                         workers, progress)
        for label, _, stamp, _ in todo:
            mine = [r for r in flown if r["policy"] == label]
            write_evaluation(folder / f"{label}.json", label, settings, mine, stamp)
            records[label] = mine
        _say(f"evaluation: {len(flown)} episodes in {time.perf_counter() - t0:.1f} s")
    return [r for label, *_ in wanted for r in records[label]]


def _compare(campaign: Campaign, records: list[dict[str, Any]]) -> tuple[str, list[dict[str, Any]]]:
    from lvgym.benchmark.results import atomic_write_text, json_text

    from .campaign_compare import comparison_rows, comparison_table, evaluation_settings

    runs: dict[str, list[str]] = {}
    for r in campaign.runs():
        runs.setdefault(r.configuration, []).append(r.name)
    rows = comparison_rows(records, runs, campaign.evaluation.baselines, campaign.evaluation.metric)
    n, k = len(runs), len(campaign.seeds)
    table = comparison_table(rows, f"Campaign {campaign.name}: {n} configuration{'s' * (n != 1)} x {k} "
                                   f"training seed{'s' * (k != 1)}, on the {campaign.evaluation.seed_set} seeds")
    atomic_write_text(campaign.folder / "comparison.md", table + "\n")
    atomic_write_text(campaign.folder / "comparison.json", json_text({
        "campaign": campaign.name, "settings": evaluation_settings(campaign.evaluation),
        "metric": campaign.evaluation.metric, "baselines": list(campaign.evaluation.baselines), "runs": runs,
        "rows": rows, "created_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")}))
    return table, rows


# ------------------------------------------------------------------------------------------ the command
def _listing(campaign: Campaign, executor: str, workers: int | None) -> list[str]:
    lines = []
    for r in campaign.runs():
        state = run_state(r.folder)
        what = {"finished": "finished: skipped", "resume": f"resume: train.py --resume {r.folder}",
                "new": "start: train.py " + " ".join(r.argv)}[state]
        lines.append(f"  {r.name}: {what}")
    ev = campaign.evaluation
    where = (f"ray ({'$RAY_ADDRESS=' + os.environ['RAY_ADDRESS'] if os.environ.get('RAY_ADDRESS') else 'a local Ray'})"
             if executor == "ray" else "local")
    head = (f"campaign {campaign.name} in {campaign.folder}: {len(campaign.runs())} runs "
            f"({len(campaign.configurations)} configurations x {len(campaign.seeds)} seeds) on {where}, "
            f"{workers or default_workers()} at once")
    tail = (f"then evaluation: {ev.episodes} {ev.seed_set} seeds of {', '.join(ev.suites)} beside "
            f"{', '.join(ev.baselines)}; then {campaign.folder / 'comparison.md'}")
    some = [f"  {c} flies {', '.join(campaign.suites_of(c))}" for c, _ in campaign.configurations
            if campaign.suites_of(c) != ev.suites]
    return [head, *lines, tail, *some]


def main(argv: list[str] | None = None) -> dict[str, Any]:
    """Run (or continue) the campaign of the file; returns the runs' results, the records and the comparison."""
    args = parse(Args, argv, PROG, __doc__, epilog=True)
    prog = command_name(PROG)
    exit_on_sigterm()
    try:
        campaign = load_campaign(args.file)
        _check_unchanged(campaign)
    except ConfigError as exc:
        fail(prog, exc)
    executor = args.executor or campaign.executor
    workers = args.workers or campaign.workers
    campaign = replace(campaign, executor=executor, workers=workers)
    for line in _listing(campaign, executor, workers):
        print(line, flush=True)
    if args.dry_run:
        return {"campaign": campaign, "states": campaign_state(campaign)}
    _write_plan(campaign)
    t0 = time.perf_counter()
    with _ray_session(executor, workers):
        try:
            results = _train_all(campaign, executor, workers)
        except TaskFailed as exc:
            fail(prog, exc)
        bad = [r for r in results if r["status"] in ("failed", "unfinished")]
        if bad:
            logs = campaign.folder / "logs"
            fail(prog, "; ".join(f"run {r['run']} {r['status']}" + (f" (exit {r['returncode']})" if r.get("returncode")
                                                                      else " (its wall-time budget is spent)")
                                 for r in bad) + f"; see {logs}/<run>.log, and run the campaign again to continue")
        _say(f"training: {len(campaign.runs())} runs finished ({sum(r['status'] == 'finished' for r in results)} "
             f"now) in {time.perf_counter() - t0:.0f} s")
        try:
            records = _evaluate_all(campaign, executor, workers, args.progress)
        except TaskFailed as exc:
            fail(prog, exc)
    table, rows = _compare(campaign, records)
    print(table)
    _say(f"comparison in {campaign.folder / 'comparison.md'} and comparison.json ({time.perf_counter() - t0:.0f} s)")
    return {"campaign": campaign, "results": results, "records": records, "rows": rows, "table": table}


if __name__ == "__main__":
    main()
