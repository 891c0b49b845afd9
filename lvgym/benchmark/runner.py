"""Running the protocol: episodes of policies on the conditions of suites, serially, on a local process
pool or on Ray, with a progress bar and results in a fixed order.

A policy travels to a worker as a :class:`PolicySpec` (a name and an importable factory, never an
object), a condition as its frozen :class:`~.suites.Condition`; :func:`run_episode` builds both there
(cached per process: envs and policies are reused across episodes, ``reset`` with the seed makes each
episode independent of what ran before) and returns a plain dict. The result of an evaluation does not
depend on the executor, the number of workers or the order in which episodes finish.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from lvgym.errors import ConfigError
from lvgym.parallel import EXECUTORS, default_workers, run_map

from .factory import load_factory
from .metrics import TrajectoryBuilder, combined_record, episode_metrics
from .policy import Policy, ZeroPolicy
from .scoring import FlightLog, flight_metrics
from .suites import PROTOCOL_VERSION, Condition, Suite


@dataclass(frozen=True)
class PolicySpec:
    """A policy by reference: ``factory`` is ``"package.module:attribute"`` or
    ``"/abs/path/file.py:attribute"`` (:mod:`.factory`), imported in the worker and called with ``kwargs``
    (sorted ``(key, value)`` pairs), plus ``env=<the condition's env>`` when it takes an ``env`` argument.
    ``name`` labels the policy in the results; ``path`` (optional) is a folder the worker appends to
    ``sys.path`` before importing the factory's module (a user's module outside the installed packages)."""

    name: str
    factory: str
    kwargs: tuple[tuple[str, Any], ...] = ()
    path: str = ""

    def resolve(self) -> Callable[..., Any]:
        """The factory object (raises ``ImportError`` naming the policy and the missing module, file or
        attribute, or what the module's code raised)."""
        try:
            return load_factory(self.factory, self.path)
        except ImportError as exc:
            raise type(exc)(f"policy {self.name!r}: {exc}") from exc


class PolicyError(ConfigError):
    """A policy that could not be built: its factory did not import, raised, or gave no Policy. One line
    (``policy = 'name': ...``) naming the policy and the cause, which survives a worker process (the
    cause is also ``__cause__`` where the policy is built)."""


def zero_policy(env: Any) -> ZeroPolicy:
    """:class:`ZeroPolicy` shaped for ``env``'s action space (``MultiDiscrete``: the no-pulse action)."""
    space = env.action_space
    discrete = not hasattr(space, "low")
    return ZeroPolicy(int(space.shape[0]) if space.shape else 1, discrete)


ZERO = PolicySpec("zero", "lvgym.benchmark.runner:zero_policy")


def build_policy(spec: PolicySpec, env: Any) -> Policy:
    """Call ``spec``'s factory (with ``env=env`` if it takes one); checks the result is a Policy. A
    factory that does not import or raises, or a result that is no Policy, raises a :class:`PolicyError`
    naming the policy and the cause in one line (from the cause)."""
    try:
        factory = spec.resolve()
    except ImportError as exc:
        raise PolicyError("policy", spec.name, str(exc).removeprefix(f"policy {spec.name!r}: ")) from exc
    kwargs = dict(spec.kwargs)
    try:
        params = inspect.signature(factory).parameters
    except (TypeError, ValueError):
        params = {}
    if "env" in params:
        kwargs["env"] = env
    try:
        policy = factory(**kwargs)
    except Exception as exc:
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        raise PolicyError("policy", spec.name, f"its factory {spec.factory} raised {type(exc).__name__}"
                                               f"{': ' + text if text else ''}") from exc
    if not isinstance(policy, Policy):
        raise PolicyError("policy", spec.name, f"its factory {spec.factory} gave {type(policy).__name__}, which "
                                               "lacks name, reset() or act(observation, info)")
    return policy


_ENVS: dict[Condition, Any] = {}
_POLICIES: dict[tuple[PolicySpec, Condition], Policy] = {}


def _env(condition: Condition) -> Any:
    if condition not in _ENVS:
        _ENVS[condition] = condition.make_env()
    return _ENVS[condition]


def play_episode(policy: Policy, env: Any, seed: int) -> dict[str, Any]:
    """Fly one episode of a policy object on an lvgym env reset with ``seed``; returns protocol v0's
    :func:`~.metrics.episode_metrics` (frozen) and, beside them, the v1 metrics of
    :func:`~.scoring.flight_metrics` (``score``, the per-phase rate errors, the flexibility metrics,
    ``qalpha_cost_s``; its ``rate_error_rad`` and failure fields are v0's, bit for bit). In-process (e.g.
    a validation callback during training: ``play_episode(policy, condition.make_env(), seed)`` over
    ``suite.seeds("validation", n)``)."""
    obs, info = env.reset(seed=int(seed))
    policy.reset()
    traj = TrajectoryBuilder(float(env.unwrapped.task.control_dt_s))
    log = FlightLog.for_env(env)
    while True:
        action = policy.act(obs, info)
        obs, reward, terminated, truncated, info = env.step(action)
        traj.add(reward, info)
        log.step(env, obs, reward, info)
        if terminated or truncated:
            break
    return combined_record(episode_metrics(traj.build()), flight_metrics(log))


def episode_objects(policy_spec: PolicySpec, condition: Condition) -> tuple[Any, Policy]:
    """The env of ``condition`` and the policy of ``policy_spec`` built for it, cached per process (both
    are reset at the start of every episode, so an episode does not depend on what ran before)."""
    env = _env(condition)
    key = (policy_spec, condition)
    if key not in _POLICIES:
        _POLICIES[key] = build_policy(policy_spec, env)
    return env, _POLICIES[key]


def run_episode(policy_spec: PolicySpec, condition: Condition, seed: int) -> dict[str, Any]:
    """One episode of ``policy_spec`` on ``condition``, reset with ``seed``; returns the record: the
    policy and condition labels, the seed and :func:`~.metrics.episode_metrics`. A function of its
    arguments only (envs and policies are cached per process, and reset every episode)."""
    env, policy = episode_objects(policy_spec, condition)
    return {"policy": policy_spec.name, "condition": condition.name, "group": condition.group,
            "env_id": condition.env_id, "model": condition.model, "wind": condition.wind, "seed": int(seed),
            **play_episode(policy, env, seed)}


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


def _describe(task: Task) -> str:
    return f"policy {task.policy.name!r} on {task.condition.name!r} seed {task.seed}"


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
    return run_map(run_task, tasks, executor, workers, progress, desc="episodes", unit="ep", describe=_describe)


__all__ = ["EXECUTORS", "PROTOCOL_VERSION", "PolicyError", "PolicySpec", "Task", "ZERO", "build_policy", "default_workers",
           "episode_objects", "evaluate", "make_tasks", "play_episode", "run_episode", "run_task", "zero_policy"]
