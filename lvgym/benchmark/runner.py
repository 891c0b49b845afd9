"""Running the protocol: episodes of policies on the conditions of suites, serially, on a local process
pool or on Ray, with a progress bar and results in a fixed order.

A policy travels to a worker as a :class:`PolicySpec` (a name and an importable factory, never an
object), a condition as its frozen :class:`~.suites.Condition`; the worker builds both (cached per
process: envs and policies are reused, ``reset`` with the seed makes each episode independent of what ran
before) and returns plain dicts. :func:`run_episode` flies one episode on the single env
(:func:`play_episode`); :func:`evaluate` flies the episodes of a condition together, as the rows of its
batched env (:func:`run_block`, :mod:`.rows`), with the single env's records to the bit. The result of an
evaluation does not depend on the executor, the number of workers, the block size or the order in which
blocks finish.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.errors import ConfigError
from lvgym.parallel import EXECUTORS, check_workers, default_workers, run_map

from .batch import BatchPolicy, as_batch, own_rows
from .factory import load_factory
from .flyability import applies
from .policy import Policy, ZeroPolicy
from .rows import OneRowEnv, fly_rows
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


#: its kind in protocol v2's headline (:func:`~.headline.policy_kind`): no control
zero_policy.kind = "none"  # type: ignore[attr-defined]
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
_VEC_ENVS: dict[tuple[Condition, int], Any] = {}
_BATCHES: dict[tuple[PolicySpec, Condition], tuple[int, BatchPolicy]] = {}
#: batched envs kept per process (one per condition and row count; the oldest goes first)
KEEP_VEC_ENVS = 8


def _env(condition: Condition) -> Any:
    if condition not in _ENVS:
        _ENVS[condition] = condition.make_env()
    return _ENVS[condition]


def play_episode(policy: Policy, env: Any, seed: int, *, flyability: bool = False, gain: float = 1.0,
                 delay_steps: int = 0) -> dict[str, Any]:
    """Fly one episode of a policy object on an lvgym env (single, wrapped or not) reset with ``seed``: the
    env as a batched env of one row and the policy's own state (:func:`~.batch.own_rows`) through
    :func:`~.rows.fly_rows`, the one path every flight of the benchmark takes. Returns protocol v0's
    :func:`~.metrics.episode_metrics` (frozen) and, beside them, the v1 metrics of
    :func:`~.scoring.flight_metrics` (``score``, the per-phase rate errors, the flexibility metrics,
    ``qalpha_cost_s``; its ``rate_error_rad`` and failure fields are v0's, bit for bit); with
    ``flyability`` (protocol v2), also :func:`~.flyability.flyability_metrics` (``flyable``, ``score_v2``,
    the commanded gimbal rate); with an env that draws in-flight faults, ``fault`` (its name, ``""`` for
    none; :mod:`lvgym.envs.faults`). ``gain`` [-] and ``delay_steps`` [physics steps] perturb the loop as the
    margins do (1 and 0: none). In-process (e.g. a validation callback during training:
    ``play_episode(policy, condition.make_env(), seed)`` over ``suite.seeds("validation", n)``)."""
    gains = None if gain == 1.0 else [float(gain)]
    delays = [int(delay_steps)] if delay_steps else None
    return fly_rows(OneRowEnv(env), [int(seed)], [(own_rows(policy), [0])], gains=gains, delay_steps=delays,
                    flyability=flyability)[0]


def episode_objects(policy_spec: PolicySpec, condition: Condition) -> tuple[Any, Policy]:
    """The env of ``condition`` and the policy of ``policy_spec`` built for it, cached per process (both
    are reset at the start of every episode, so an episode does not depend on what ran before)."""
    env = _env(condition)
    key = (policy_spec, condition)
    if key not in _POLICIES:
        _POLICIES[key] = build_policy(policy_spec, env)
    return env, _POLICIES[key]


def vec_env(condition: Condition, n: int) -> Any:
    """The batched env of ``n`` rows of ``condition``, cached per process (reset at every flight)."""
    key = (condition, int(n))
    if key not in _VEC_ENVS:
        while len(_VEC_ENVS) >= KEEP_VEC_ENVS:
            _VEC_ENVS.pop(next(iter(_VEC_ENVS))).close()
        _VEC_ENVS[key] = condition.make_vec_env(int(n))
    return _VEC_ENVS[key]


def batch_objects(policy_spec: PolicySpec, condition: Condition, n: int) -> BatchPolicy:
    """The batched policy of ``policy_spec`` for at least ``n`` rows of ``condition``'s batched env, cached
    per process: the policy's own ``batch(n)``, else one policy per row built by its factory
    (:func:`~.batch.as_batch`); its rows are reset at the start of every flight."""
    key = (policy_spec, condition)
    have = _BATCHES.get(key)
    if have is None or have[0] < n:
        env = _env(condition)
        _BATCHES[key] = (int(n), as_batch(build_policy(policy_spec, env), int(n),
                                          lambda: build_policy(policy_spec, env)))
    return _BATCHES[key][1]


def fly_block(condition: Condition, rows: Sequence[tuple[PolicySpec, int]], *, gains: Sequence[float] | None = None,
              delay_steps: Sequence[int] | None = None, first_observations: list[np.ndarray] | None = None,
              flyability: bool = False) -> list[dict[str, Any]]:
    """One episode per ``(policy spec, seed)`` of ``rows``, flown together as the rows of ``condition``'s
    batched env (:func:`~.rows.fly_rows`; ``gains``, ``delay_steps``, ``first_observations``, ``flyability``
    as there);
    the records in the order of ``rows``, each the :func:`play_episode` of its policy and seed on the
    single env, to the bit. Envs and batched policies are cached per process."""
    env = vec_env(condition, len(rows))
    owners: dict[PolicySpec, list[int]] = {}
    for i, (spec, _) in enumerate(rows):
        owners.setdefault(spec, []).append(i)
    groups = [(batch_objects(spec, condition, len(rows)), idx) for spec, idx in owners.items()]
    return fly_rows(env, [int(seed) for _, seed in rows], groups, gains=gains, delay_steps=delay_steps,
                    first_observations=first_observations, flyability=flyability)


def _labels(policy_spec: PolicySpec, condition: Condition, seed: int) -> dict[str, Any]:
    return {"policy": policy_spec.name, "condition": condition.name, "group": condition.group,
            "env_id": condition.env_id, "model": condition.model, "wind": condition.wind, "seed": int(seed)}


def run_episode(policy_spec: PolicySpec, condition: Condition, seed: int, flyability: bool = False) -> dict[str, Any]:
    """One episode of ``policy_spec`` on ``condition``, reset with ``seed``; returns the record: the
    policy and condition labels, the seed and :func:`play_episode`'s metrics (``flyability``: protocol v2's
    too). A function of its arguments only (envs and policies are cached per process, and reset every
    episode)."""
    env, policy = episode_objects(policy_spec, condition)
    return {**_labels(policy_spec, condition, seed), **play_episode(policy, env, seed, flyability=flyability)}


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
    """:func:`run_episode` of a task, labelled with the suite, the protocol version and the episode (with
    the flyability fields from protocol v2 on, :func:`~.flyability.applies`)."""
    record = run_episode(task.policy, task.condition, task.seed, applies(task.version))
    return {"protocol": task.version, "suite": task.suite, "episode": task.episode, **record}


def _per_suite(policies: Sequence[PolicySpec] | Mapping[str, Sequence[PolicySpec]],
               suites: Sequence[Suite]) -> dict[str, list[PolicySpec]]:
    """``{suite name: its policies}``: the same list for every suite, or a mapping's own (every suite named)."""
    if not isinstance(policies, Mapping):
        return {s.name: list(policies) for s in suites}
    missing = [s.name for s in suites if s.name not in policies]
    if missing:
        raise ValueError(f"policies per suite: none given for {missing}")
    return {s.name: list(policies[s.name]) for s in suites}


def policy_options(policy: PolicySpec) -> dict[str, Any]:
    """The env options ``policy`` flies a condition with: ``privileged_info=True`` for a privileged reference
    (its factory's ``privileged``), and what its factory's ``condition_options(**kwargs)`` names (a saved
    teacher's privileged observation, e.g. ``fault_info``); none for a causal policy."""
    factory = policy.resolve()
    out: dict[str, Any] = {"privileged_info": True} if getattr(factory, "privileged", False) else {}
    extra = getattr(factory, "condition_options", None)
    if callable(extra):
        out.update(extra(**dict(policy.kwargs)))
    return out


def make_tasks(policies: Sequence[PolicySpec] | Mapping[str, Sequence[PolicySpec]], suites: Sequence[Suite],
               episodes: int, seed_set: str = "test", first: int = 0) -> list[Task]:
    """Every episode of every policy on every condition of every suite, in the order of the results:
    suite, condition, policy, episode. ``policies``: one list for every suite, or a mapping of suite name to
    that suite's own list. A policy whose factory has ``privileged = True`` flies each condition with
    ``privileged_info=True`` (the same flight, with the true state in the info), one that sees privileged
    observations (a teacher trained with ``fault_info``) with its options (:func:`policy_options`). ``first``:
    the index of the first seed of ``seed_set`` (:meth:`~.suites.Suite.seeds`)."""
    per_suite = _per_suite(policies, suites)
    options: dict[str, dict[str, Any]] = {}
    for suite in suites:
        names = [p.name for p in per_suite[suite.name]]
        if len(set(names)) != len(names):
            raise ValueError(f"policy names {names}: each must be distinct (they label the results)")
        options.update({p.name: policy_options(p) for p in per_suite[suite.name] if p.name not in options})
    tasks: list[Task] = []
    for suite in suites:
        seeds = suite.seeds(seed_set, episodes, first)
        for cond in suite.conditions:
            for pol in per_suite[suite.name]:
                c = cond.with_options(**options[pol.name]) if options[pol.name] else cond
                for i, seed in enumerate(seeds):
                    tasks.append(Task(len(tasks), suite.name, suite.version, i, pol, c, seed))
    return tasks


def _describe(task: Task) -> str:
    return f"policy {task.policy.name!r} on {task.condition.name!r} seed {task.seed}"


@dataclass(frozen=True)
class Block:
    """Episodes flown together: tasks of one suite and condition (any policies and seeds), as the rows of
    the condition's batched env."""

    tasks: tuple[Task, ...]


#: the most rows a block of :func:`evaluate` flies together by default (the memory of its steps grows with it)
MAX_BLOCK_ROWS = 128


def make_blocks(tasks: Sequence[Task], rows: int) -> list[Block]:
    """``tasks`` in blocks of at most ``rows`` consecutive tasks of one suite and condition, in order."""
    if int(rows) < 1:
        raise ValueError(f"rows = {rows!r}: at least one row per block")
    blocks: list[Block] = []
    part: list[Task] = []
    for t in tasks:
        if part and (len(part) >= rows or (t.suite, t.condition) != (part[0].suite, part[0].condition)):
            blocks.append(Block(tuple(part)))
            part = []
        part.append(t)
    if part:
        blocks.append(Block(tuple(part)))
    return blocks


def block_rows(n_tasks: int, workers: int) -> int:
    """The default block size: at least two blocks per worker where there are enough episodes, at most
    :data:`MAX_BLOCK_ROWS` rows (the results do not depend on it)."""
    return max(1, min(MAX_BLOCK_ROWS, math.ceil(n_tasks / (2 * max(1, workers)))))


def run_block(block: Block) -> list[dict[str, Any]]:
    """The records of a block's tasks, in order, as :func:`run_task` gives each (flown together,
    :func:`fly_block`)."""
    first = block.tasks[0]
    records = fly_block(first.condition, [(t.policy, t.seed) for t in block.tasks], flyability=applies(first.version))
    return [{"protocol": t.version, "suite": t.suite, "episode": t.episode, **_labels(t.policy, t.condition, t.seed),
             **r} for t, r in zip(block.tasks, records)]


def _describe_block(block: Block) -> str:
    t = block.tasks
    names = list(dict.fromkeys(x.policy.name for x in t))
    who = f"policy {names[0]!r}" if len(names) == 1 else "policies " + ", ".join(map(repr, names))
    if len(t) == 1:
        return f"{who} on {t[0].condition.name!r} seed {t[0].seed}"
    seeds = f"seeds {min(x.seed for x in t)}..{max(x.seed for x in t)}"
    return f"{who} on {t[0].condition.name!r} {seeds} ({len(t)} episodes flown together)"


def evaluate(policies: Sequence[PolicySpec] | Mapping[str, Sequence[PolicySpec]], suites: Sequence[Suite], episodes: int, seed_set: str = "test",
             executor: str = "local", workers: int | None = None, progress: bool = True,
             rows: int | None = None, purpose: str | None = None, first: int = 0) -> list[dict[str, Any]]:
    """Run ``episodes`` seeds of ``seed_set`` for every policy on every condition of every suite (``policies``:
    one list, or a list per suite name, :func:`make_tasks`) and return the episode records in the order of :func:`make_tasks` (whatever the executor, worker count and block
    size).

    The episodes of a condition fly together as the rows of its batched env, in blocks of at most ``rows``
    (default :func:`block_rows`) consecutive episodes (:func:`run_block`); each record is the single env's
    episode of its seed (:func:`run_task`), to the bit. executor: ``local`` (a process pool of ``workers``
    processes, default: the CPUs available), ``serial`` (this process) or ``ray`` (one Ray task per block:
    on the Ray already initialised in this process, else on the cluster at ``$RAY_ADDRESS``, else on a local
    Ray of ``workers`` CPUs started and stopped here). Ray workers import ``lvgym`` and the policy
    factories, so install the project on every node.

    ``first``: the index of the first seed of ``seed_set`` flown (default 0: its first ``episodes`` seeds; a
    named block of seeds, e.g. :data:`~.suites.HEADLINE_BLOCK`, starts further on). A flight on test seeds
    is logged in the ledger of test flights before it starts (:func:`~.ledger.log_flight`, with ``purpose``)."""
    if executor not in EXECUTORS:
        raise ValueError(f"executor = {executor!r}: one of {EXECUTORS}")
    tasks = make_tasks(policies, suites, episodes, seed_set, first)
    if seed_set == "test" and tasks:
        from .ledger import log_flight

        log_flight({t.seed for t in tasks}, [s.name for s in suites], [c.model for s in suites for c in s.conditions],
                   [t.policy.name for t in tasks], purpose)
    n_workers = 1 if executor == "serial" else (check_workers(workers) or default_workers())
    blocks = make_blocks(tasks, block_rows(len(tasks), n_workers) if rows is None else rows)
    done = run_map(run_block, blocks, executor, workers, progress, desc="blocks", unit="block",
                   describe=_describe_block)
    return [r for block in done for r in block]


__all__ = ["Block", "EXECUTORS", "MAX_BLOCK_ROWS", "PROTOCOL_VERSION", "PolicyError", "PolicySpec", "Task", "ZERO",
           "batch_objects", "block_rows", "build_policy", "default_workers", "episode_objects", "evaluate",
           "fly_block", "make_blocks", "make_tasks", "play_episode", "policy_options", "run_block", "run_episode",
           "run_task", "vec_env", "zero_policy"]
