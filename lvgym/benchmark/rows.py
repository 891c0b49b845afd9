"""The one way the benchmark flies episodes: as rows of a batched env, one policy call per step for all rows.

:func:`fly_rows` resets a batched lvgym env (``Condition.make_vec_env(n)``, a Gymnasium ``VectorEnv``) with
one seed per row (row ``i`` flies exactly the single env's episode of ``seeds[i]``) and steps every row
together: each step, each :class:`~.batch.BatchPolicy` acts for its rows still flying; a row that ends
(terminated or truncated) is masked out (no more policy calls, nothing more recorded; the env's autoreset
flies it on with the neutral action, unseen) and the flight stops when every row has ended. Per row it can
scale the actions by a gain (:func:`scaled`) and delay them by whole physics steps (:class:`RowDelay`): the
margins' perturbations (:mod:`.margins`). A single env flies the same way as a batch of one
(:class:`OneRowEnv`: :func:`~.runner.play_episode`).

:class:`RowsLog` keeps whole steps as arrays (one entry per row) and cuts each row's episode out at the end
into its record: protocol v0's :func:`~.metrics.episode_metrics`, v1's :func:`~.scoring.flight_metrics` and
v2's :func:`~.flyability.flyability_metrics` of the same arrays.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from lvgym.simulator.layouts import ACTUATOR

from .batch import BatchPolicy, OneRowInfo
from .flyability import flyability_metrics
from .metrics import Trajectory, combined_record, episode_metrics
from .scoring import FlightColumns, FlightFacts, flight_metrics, gimbal_command

__all__ = ["OneRowEnv", "RowDelay", "RowsLog", "fly_rows", "neutral_action", "scaled"]

#: the info entries kept per step (what the records read)
STEP_KEYS = ("rate_error", "gimbal", "alpha_total", "qalpha_pa_deg", "time", "qbar", "gimbal_rate", "eta",
             "slosh_angles", "controller_on", "qalpha_limit_pa_deg")


def neutral_action(space: Any) -> np.ndarray:
    """The action of one row that commands nothing: zeros of a ``Box``, the middle of a ``MultiDiscrete``."""
    if hasattr(space, "low"):
        return np.zeros(space.shape, dtype=space.dtype)
    return np.asarray(space.nvec, dtype=np.int64) // 2


class RowsLog:
    """The steps of every row of a batched env, kept whole (``add`` after each ``step``, ``end`` for the rows
    that ended), and each row's record (:meth:`records`); with ``terms`` also the reward's terms of every step
    (:meth:`rewards`)."""

    def __init__(self, env: Any, terms: bool = False) -> None:
        u = env.unwrapped
        self.env, self.n = env, int(env.num_envs)
        self.facts = FlightFacts.for_env(env)              # the task's facts (control period, limits, gyro)
        self.dt_s = float(u.task.control_dt_s)
        self.steps: dict[str, list[np.ndarray]] = {key: [] for key in ("reward", "gyro", "action", *STEP_KEYS)}
        self.length = np.zeros(self.n, dtype=np.int64)
        self.events: list[list[tuple[float, str]]] = [[] for _ in range(self.n)]
        self.termination = [""] * self.n
        self.fault: list[str] | None = None               # the rows' faults, when the env draws them
        self.terms: list[str] | None = None                # the reward terms' names, when they are kept
        if terms:
            self.steps["terms"] = []
            self.terms = []

    def add(self, live: np.ndarray, observations: np.ndarray, reward: np.ndarray, info: dict[str, Any],
            actions: np.ndarray | None = None) -> None:
        """One step of every row; ``live``: the rows still flying before it (they count it); ``actions``:
        the policies' actions of the step (before any delay; kept with a gimbal: protocol v2's commands)."""
        steps = self.steps
        steps["reward"].append(np.asarray(reward, dtype=float))
        if actions is not None and self.facts.gimbal_limit_rad > 0.0:
            steps["action"].append(np.array(actions, dtype=float))
        for key in STEP_KEYS:
            steps[key].append(np.asarray(info[key]))
        if self.terms is not None:
            self.terms = list(info["reward_terms"])
            steps["terms"].append(np.stack([np.asarray(info["reward_terms"][k], dtype=float) for k in self.terms],
                                           axis=1))
        if self.facts.gyro_index is not None:        # the gyro's view against the body rate
            u = self.env.unwrapped
            w = u.sim.state(u.state.sim, "omega_bi_b")
            ip, iy, iref = self.facts.gyro_index
            o = np.asarray(observations, dtype=np.float64)
            steps["gyro"].append(np.stack([o[:, ip] + o[:, iref] - w[:, 1], o[:, iy] - w[:, 2]], axis=1))
        self.length[live] += 1
        events = info.get("events")
        if events is not None:
            for b in live.tolist():
                if events[b]:
                    self.events[b] += [(float(t), str(text)) for t, text in events[b]]

    def end(self, rows: np.ndarray, info: dict[str, Any]) -> None:
        """The rows ``rows`` ended with this step (their failure, if any, from ``info["termination"]``; the
        fault they flew, when the env draws faults, from ``info["fault"]``)."""
        if "fault" in info and self.fault is None:
            self.fault = [""] * self.n
        for b in rows.tolist():
            reason = info["termination"][b]
            if reason:
                self.termination[b] = str(reason)
            if self.fault is not None:
                self.fault[b] = str(info["fault"][b])

    def rewards(self) -> list[dict[str, np.ndarray]]:
        """Every row's per-step rewards (``reward``, (L,)) and, when kept, each reward term's (by its name)."""
        reward = np.stack(self.steps["reward"]) if self.steps["reward"] else np.zeros((0, self.n))
        terms = np.stack(self.steps["terms"]) if self.terms else None
        out = []
        for b in range(self.n):
            L = int(self.length[b])
            series = {"reward": reward[:L, b].copy()}
            for i, name in enumerate(self.terms or ()):
                series[name] = terms[:L, b, i].copy()
            out.append(series)
        return out

    def records(self, flyability: bool = False) -> list[dict[str, Any]]:
        """Every row's record: :func:`~.metrics.episode_metrics` and :func:`~.scoring.flight_metrics` of its
        steps (C-contiguous copies, as the single env's builders make them); with ``flyability`` (protocol
        v2) also :func:`~.flyability.flyability_metrics`."""
        stacked = {key: np.stack(v) if v else None for key, v in self.steps.items()}
        out = []
        for b in range(self.n):
            L = int(self.length[b])

            def col(key: str) -> np.ndarray:
                return np.ascontiguousarray(stacked[key][:L, b], dtype=float)

            traj = Trajectory(self.dt_s, col("rate_error"), col("gimbal"), col("alpha_total"), col("qalpha_pa_deg"),
                              col("reward"), col("time"), col("qbar"), self.termination[b])
            gyro = col("gyro") if stacked["gyro"] is not None else None
            command = None
            if stacked["action"] is not None and L:
                command = gimbal_command(col("action"), self.facts.gimbal_limit_rad)
            on = np.ascontiguousarray(stacked["controller_on"][:L, b], dtype=bool)
            columns = FlightColumns(traj.time_s, traj.rate_error_radps, traj.qbar_pa, traj.qalpha_pa_deg,
                                    col("gimbal_rate"), gyro, col("eta"), col("slosh_angles"), self.events[b],
                                    self.termination[b], command, on, col("qalpha_limit_pa_deg"))
            record = combined_record(episode_metrics(traj), flight_metrics(self.facts, columns))
            if flyability:
                record.update(flyability_metrics(self.facts, columns, record))
            if self.fault is not None:
                record["fault"] = self.fault[b]
            out.append(record)
        return out


def scaled(actions: np.ndarray, gains: np.ndarray, name: str) -> np.ndarray:
    """``actions`` (m, n_a) times the rows' ``gains`` (m,) [-], in the actions' own precision (a ``Box``
    action; the env then clips it to the action space, as it clips every action): the margins' gain,
    ``20 log10 k`` dB."""
    if actions.dtype.kind not in "fc":
        raise ValueError(f"policy {name!r} gave actions of dtype {actions.dtype}: a gain needs a Box (TVC) action")
    return (actions * gains.astype(actions.dtype)[:, None]).astype(actions.dtype, copy=False)


class RowDelay:
    """A pure extra delay of ``steps[b]`` physics steps (``physics_dt_s``, 10 ms by default; 0: none) between the
    policy of row ``b`` of a batched lvgym TVC env and its actuator. ``steps = n P + m`` (``P`` physics steps
    per control period): the whole periods ``n`` are a first-in first-out buffer of actions that starts with
    the neutral action (zeros; the env's own computational delay, ``action_delay_steps``, is such a buffer too);
    the ``m`` steps are added to the row's servo delay, on top of its dispersed one (layout
    :data:`lvgym.simulator.layouts.ACTUATOR`, field ``delay``: the first so many physics steps of a control
    period follow the previous period's command; when the sum reaches ``P`` a period moves into the buffer),
    written here, right after the env's reset. The gimbal command is held over a control period, so both are
    the same pure shift of the command signal, and no equation is written twice. :meth:`apply` takes the
    actions the policies gave every row and returns those the env gets (float64, which holds every action's
    value exactly). The buffer sits, as the env's own delay does, before the env masks the command while the
    controller is off; the servo's part acts after it."""

    def __init__(self, env: Any, steps: Any) -> None:
        u = env.unwrapped
        task = u.task
        if task.control != "tvc":
            raise ValueError(f"control = {task.control!r}: an actuator delay needs a TVC env")
        n = int(env.num_envs)
        raw = np.asarray(steps).reshape(-1)
        if raw.size != n or np.any(raw < 0) or np.any(raw != np.round(raw)):
            raise ValueError(f"steps = {raw.tolist()!r}: {n} whole numbers of physics steps >= 0, one per row")
        steps = raw.astype(np.int64)
        per = int(task.substeps)
        self.physics_dt_s = float(task.control_dt_s) / per
        delay = ACTUATOR.view(u.state.sim.actuator, "delay")
        self.length = np.zeros(n, dtype=np.int64)
        for b in np.flatnonzero(steps).tolist():
            periods, servo_steps = divmod(int(steps[b]), per)
            more, delay[b, 0] = divmod(int(round(delay[b, 0])) + servo_steps, per)
            self.length[b] = periods + more
        self.rows = np.flatnonzero(self.length)
        n_a = int(np.prod(env.single_action_space.shape))
        self._buffer = np.zeros((n, max(1, int(self.length.max(initial=0))), n_a))
        self._next = np.zeros(n, dtype=np.int64)

    def apply(self, actions: np.ndarray) -> np.ndarray:
        """The actions (n, n_a) the env gets this step: a buffered row's oldest action (its buffer takes
        this one), the others' own."""
        q = self.rows
        if not q.size:
            return actions
        a = np.asarray(actions)
        out = a.astype(np.float64)
        k = self._next[q]
        out[q] = self._buffer[q, k]
        self._buffer[q, k] = a[q]
        self._next[q] = (k + 1) % self.length[q]
        return out


class OneRowEnv:
    """A single lvgym env (``gymnasium.Env``, wrapped or not) as a batched env of one row, the face
    :func:`fly_rows` flies: ``reset(seed=[s])`` and ``step(actions (1, n_a))`` return the single env's results
    with a leading axis of one (its info read as one row, :class:`~.batch.OneRowInfo`)."""

    num_envs = 1

    def __init__(self, env: Any) -> None:
        self.env = env
        self.unwrapped = env.unwrapped
        self.single_action_space = env.action_space

    def reset(self, seed: Sequence[int]) -> tuple[np.ndarray, OneRowInfo]:
        (s,) = seed
        obs, info = self.env.reset(seed=int(s))
        return np.asarray(obs)[None], OneRowInfo(info)

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, OneRowInfo]:
        obs, reward, terminated, truncated, info = self.env.step(actions[0])
        return (np.asarray(obs)[None], np.array([reward], dtype=float), np.array([terminated]),
                np.array([truncated]), OneRowInfo(info))


def fly_rows(env: Any, seeds: Sequence[int], groups: Sequence[tuple[BatchPolicy, Sequence[int]]], *,
             gains: Sequence[float] | None = None, delay_steps: Sequence[int] | None = None,
             first_observations: list[np.ndarray] | None = None, flyability: bool = False,
             rewards: list[dict[str, np.ndarray]] | None = None) -> list[dict[str, Any]]:
    """One episode per row of the batched lvgym env ``env`` (``env.num_envs == len(seeds)``), row ``i``
    reset with ``seeds[i]``; ``groups``: (batch policy, its rows) pairs that cover every row once (a
    policy's batch holds at least ``num_envs`` rows and is addressed by the env's row numbers). ``gains``
    (per row, 1: none) scales each row's actions (:func:`scaled`), ``delay_steps`` (per row, 0: none) delays
    them by whole physics steps (:class:`RowDelay`). Returns the rows' records in row order, each that of the
    single env's episode with that seed (and perturbation); ``first_observations``, if given, receives the
    reset's observation of every row; ``flyability``: add protocol v2's flyability fields
    (:mod:`.flyability`) to every record; ``rewards``, if given, receives every row's per-step rewards and reward
    terms (:meth:`RowsLog.rewards`)."""
    n = int(env.num_envs)
    if len(seeds) != n:
        raise ValueError(f"{len(seeds)} seeds for a batched env of {n} rows")
    owned = np.zeros(n, dtype=np.int64)
    groups = [(policy, np.asarray(rows, dtype=np.int64).reshape(-1)) for policy, rows in groups]
    for _, rows in groups:
        np.add.at(owned, rows, 1)
    if np.any(owned != 1):
        raise ValueError(f"the groups' rows must cover each of the {n} rows once (counts {owned.tolist()})")
    gain = None if gains is None else np.asarray(gains, dtype=float).reshape(n)
    obs, info = env.reset(seed=[int(s) for s in seeds])
    if first_observations is not None:
        first_observations.extend(np.array(o) for o in obs)
    delay = None
    if delay_steps is not None and np.any(np.asarray(delay_steps) != 0):
        delay = RowDelay(env, delay_steps)
    neutral = neutral_action(env.single_action_space)
    log = RowsLog(env, terms=rewards is not None)
    for policy, rows in groups:
        policy.reset(rows)
    done = np.zeros(n, dtype=bool)
    while not done.all():
        acted = []
        for policy, rows in groups:
            live = rows[~done[rows]]
            if live.size:
                a = np.asarray(policy.act(live, obs[live], info))
                acted.append((live, a if gain is None else scaled(a, gain[live], policy.name)))
        dtype = np.result_type(neutral.dtype, *(a.dtype for _, a in acted))
        actions = np.broadcast_to(neutral.astype(dtype), (n, *neutral.shape)).copy()
        for live, a in acted:
            actions[live] = a
        asked = actions
        if delay is not None:
            actions = delay.apply(actions)
        live = np.flatnonzero(~done)
        obs, reward, terminated, truncated, info = env.step(actions)
        log.add(live, obs, reward, info, asked)
        ended = live[(np.asarray(terminated) | np.asarray(truncated))[live]]
        log.end(ended, info)
        done[ended] = True
    if rewards is not None:
        rewards.extend(log.rewards())
    return log.records(flyability)
