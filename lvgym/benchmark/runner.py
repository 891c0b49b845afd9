"""Running the protocol: episodes of policies on the conditions of suites, serially, on a local process
pool or on Ray, with a progress bar and results in a fixed order.

A policy travels to a worker as a :class:`PolicySpec` (a name and an importable factory, never an
object), a condition as its frozen :class:`~.suites.Condition`; :func:`run_episode` builds both there
(cached per process: envs and policies are reused across episodes, ``reset`` with the seed makes each
episode independent of what ran before) and returns a plain dict. The result of an evaluation does not
depend on the executor, the number of workers or the order in which episodes finish.
"""

from __future__ import annotations

import importlib
import inspect
import os
import sys
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from typing import Any

from .metrics import TrajectoryBuilder, episode_metrics
from .policy import Policy, ZeroPolicy
from .suites import PROTOCOL_VERSION, Condition, Suite

EXECUTORS = ("local", "serial", "ray")


@dataclass(frozen=True)
class PolicySpec:
    """A policy by reference: ``factory`` is ``"package.module:attribute"``, imported in the worker and
    called with ``kwargs`` (sorted ``(key, value)`` pairs), plus ``env=<the condition's env>`` when it
    takes an ``env`` argument. ``name`` labels the policy in the results."""

    name: str
    factory: str
    kwargs: tuple[tuple[str, Any], ...] = ()

    def resolve(self) -> Callable[..., Any]:
        """The factory object (raises ``ImportError`` naming the missing module or attribute)."""
        module, _, attr = self.factory.partition(":")
        try:
            mod = importlib.import_module(module)
        except ImportError as exc:
            raise ImportError(f"policy {self.name!r}: cannot import {module!r} ({exc})") from exc
        obj: Any = mod
        for part in attr.split(".") if attr else []:
            if not hasattr(obj, part):
                raise ImportError(f"policy {self.name!r}: {module!r} has no {attr!r} (factory {self.factory!r})")
            obj = getattr(obj, part)
        return obj


def zero_policy(env: Any) -> ZeroPolicy:
    """:class:`ZeroPolicy` shaped for ``env``'s action space (``MultiDiscrete``: the no-pulse action)."""
    space = env.action_space
    discrete = not hasattr(space, "low")
    return ZeroPolicy(int(space.shape[0]) if space.shape else 1, discrete)


ZERO = PolicySpec("zero", "lvgym.benchmark.runner:zero_policy")


def build_policy(spec: PolicySpec, env: Any) -> Policy:
    """Call ``spec``'s factory (with ``env=env`` if it takes one); checks the result is a Policy."""
    factory = spec.resolve()
    kwargs = dict(spec.kwargs)
    try:
        params = inspect.signature(factory).parameters
    except (TypeError, ValueError):
        params = {}
    if "env" in params:
        kwargs["env"] = env
    policy = factory(**kwargs)
    if not isinstance(policy, Policy):
        raise TypeError(f"policy {spec.name!r}: {spec.factory} gave {type(policy).__name__}, which lacks "
                        "name, reset() or act(observation, info)")
    return policy


_ENVS: dict[Condition, Any] = {}
_POLICIES: dict[tuple[PolicySpec, Condition], Policy] = {}


def _env(condition: Condition) -> Any:
    if condition not in _ENVS:
        _ENVS[condition] = condition.make_env()
    return _ENVS[condition]


def play_episode(policy: Policy, env: Any, seed: int) -> dict[str, Any]:
    """Fly one episode of a policy object on an lvgym env reset with ``seed``; returns
    :func:`~.metrics.episode_metrics`. In-process (e.g. a validation callback during training:
    ``play_episode(policy, condition.make_env(), seed)`` over ``suite.seeds("validation", n)``)."""
    obs, info = env.reset(seed=int(seed))
    policy.reset()
    traj = TrajectoryBuilder(float(env.unwrapped.task.control_dt_s))
    while True:
        action = policy.act(obs, info)
        obs, reward, terminated, truncated, info = env.step(action)
        traj.add(reward, info)
        if terminated or truncated:
            break
    return episode_metrics(traj.build())


def run_episode(policy_spec: PolicySpec, condition: Condition, seed: int) -> dict[str, Any]:
    """One episode of ``policy_spec`` on ``condition``, reset with ``seed``; returns the record: the
    policy and condition labels, the seed and :func:`~.metrics.episode_metrics`. A function of its
    arguments only (envs and policies are cached per process, and reset every episode)."""
    env = _env(condition)
    key = (policy_spec, condition)
    if key not in _POLICIES:
        _POLICIES[key] = build_policy(policy_spec, env)
    return {"policy": policy_spec.name, "condition": condition.name, "group": condition.group,
            "env_id": condition.env_id, "model": condition.model, "wind": condition.wind, "seed": int(seed),
            **play_episode(_POLICIES[key], env, seed)}


@dataclass(frozen=True)
class Task:
    """One episode to run: its position in the results, what to run and its labels."""

    index: int
    suite: str
    version: str
    episode: int
    policy: PolicySpec
    condition: Condition
    seed: int


def run_task(task: Task) -> dict[str, Any]:
    """:func:`run_episode` of a task, labelled with the suite, the protocol version and the episode."""
    record = run_episode(task.policy, task.condition, task.seed)
    return {"protocol": task.version, "suite": task.suite, "episode": task.episode, **record}


def make_tasks(policies: Sequence[PolicySpec], suites: Sequence[Suite], episodes: int,
               seed_set: str = "test") -> list[Task]:
    """Every episode of every policy on every condition of every suite, in the order of the results:
    suite, condition, policy, episode."""
    names = [p.name for p in policies]
    if len(set(names)) != len(names):
        raise ValueError(f"policy names {names}: each must be distinct (they label the results)")
    tasks: list[Task] = []
    for suite in suites:
        seeds = suite.seeds(seed_set, episodes)
        for cond in suite.conditions:
            for pol in policies:
                for i, seed in enumerate(seeds):
                    tasks.append(Task(len(tasks), suite.name, suite.version, i, pol, cond, seed))
    return tasks


def default_workers() -> int:
    """CPUs this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def _progress(total: int, enabled: bool) -> Any:
    from tqdm.auto import tqdm

    return tqdm(total=total, desc="episodes", unit="ep", disable=not enabled, file=sys.stderr, dynamic_ncols=True)


def _describe(task: Task) -> str:
    return f"policy {task.policy.name!r} on {task.condition.name!r} seed {task.seed}"


def _run_serial(tasks: Sequence[Task], bar: Any) -> list[dict[str, Any]]:
    out = []
    for t in tasks:
        try:
            out.append(run_task(t))
        except Exception as exc:
            raise RuntimeError(f"episode failed: {_describe(t)}: {exc}") from exc
        bar.update(1)
    return out


def _exit_with_parent(parent: int) -> None:
    """Worker initializer: a daemon thread ends the worker once its parent is gone (a killed evaluation
    leaves no workers behind; a pool's workers otherwise wait for work forever)."""
    import threading
    import time

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


def _run_local(tasks: Sequence[Task], bar: Any, workers: int) -> list[dict[str, Any]]:
    import multiprocessing as mp

    results: list[dict[str, Any] | None] = [None] * len(tasks)
    # spawn: workers do not inherit the parent's threads (numba, BLAS) or open files
    with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"),
                             initializer=_exit_with_parent, initargs=(os.getpid(),)) as pool:
        futures = {pool.submit(run_task, t): i for i, t in enumerate(tasks)}
        try:
            for f in as_completed(futures):
                i = futures[f]
                exc = f.exception()
                if exc is not None:
                    raise RuntimeError(f"episode failed: {_describe(tasks[i])}: {exc}") from exc
                results[i] = f.result()
                bar.update(1)
        except BaseException:
            pool.shutdown(wait=True, cancel_futures=True)
            raise
    return [r for r in results if r is not None]


def _run_ray(tasks: Sequence[Task], bar: Any, workers: int) -> list[dict[str, Any]]:
    try:
        import ray
    except ImportError as exc:
        raise ImportError("executor 'ray' needs Ray: pip install 'lvgym[ray]' (or pip install ray)") from exc
    started = not ray.is_initialized()
    if started and os.environ.get("RAY_ADDRESS"):     # join the cluster named by RAY_ADDRESS
        ray.init(log_to_driver=False, configure_logging=False)
    elif started:                                     # a local Ray of `workers` CPUs, for this run
        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        remote = ray.remote(num_cpus=1)(run_task)
        refs = [remote.remote(t) for t in tasks]
        index = {r: i for i, r in enumerate(refs)}
        pending = list(refs)
        while pending:
            done, pending = ray.wait(pending, num_returns=len(pending), timeout=0.2)
            for ref in done:
                try:
                    ray.get(ref)
                except Exception as exc:
                    for p in pending:
                        ray.cancel(p, force=True)
                    raise RuntimeError(f"episode failed: {_describe(tasks[index[ref]])}: {exc}") from exc
            bar.update(len(done))
        return list(ray.get(refs))
    finally:
        if started:
            ray.shutdown()


def evaluate(policies: Sequence[PolicySpec], suites: Sequence[Suite], episodes: int, seed_set: str = "test",
             executor: str = "local", workers: int | None = None, progress: bool = True) -> list[dict[str, Any]]:
    """Run ``episodes`` seeds of ``seed_set`` for every policy on every condition of every suite and return
    the episode records in the order of :func:`make_tasks` (whatever the executor and worker count).

    executor: ``local`` (a process pool of ``workers`` processes, default: the CPUs available),
    ``serial`` (this process) or ``ray`` (one Ray task per episode: on the Ray already initialised in this
    process, else on the cluster at ``$RAY_ADDRESS``, else on a local Ray of ``workers`` CPUs started and
    stopped here). Ray workers import ``lvgym`` and the policy factories, so install the project on
    every node."""
    if executor not in EXECUTORS:
        raise ValueError(f"executor = {executor!r}: one of {EXECUTORS}")
    tasks = make_tasks(policies, suites, episodes, seed_set)
    n = max(1, min(int(workers) if workers else default_workers(), len(tasks)))
    with _progress(len(tasks), progress) as bar:
        if executor == "serial" or (executor == "local" and n == 1):
            return _run_serial(tasks, bar)
        if executor == "local":
            return _run_local(tasks, bar, n)
        return _run_ray(tasks, bar, n)


__all__ = ["EXECUTORS", "PROTOCOL_VERSION", "PolicySpec", "Task", "ZERO", "build_policy", "default_workers",
           "evaluate", "make_tasks", "play_episode", "run_episode", "run_task", "zero_policy"]
