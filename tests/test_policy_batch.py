"""Every registered controller is one batch law: a batch of one (its one-row face on the single env's info of
that row) equals the same row of a batch of four, to the bit, on the rows of the VectorEnv of the suite it is made
for, the actions and the commands before them, with rows reset at different steps, stepped in changing subsets,
through the controller's switch-on and an episode's end. Also: a user's per-row policy through the one adapter
(PerRow), a subclass that changes a face's law, and the laws' compiled schedule look-ups."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import lvgym
import lvgym.agents  # noqa: F401  (registers the learned policies)
import lvgym.baselines  # noqa: F401  (registers the baselines)
from lvgym.baselines.aac import flex_aac
from lvgym.baselines.pid import GainSchedule, GainScheduledPIDPolicy, PIDPolicy
from lvgym.baselines.pidkernel import interp_k, nearest_k
from lvgym.benchmark.batch import BatchLaw, PerRow, RowFace, as_batch, own_rows
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.runner import build_policy, policy_options
from lvgym.envs.core import row_info

N = 4
MISSION_S = 3.0           # the controller switches on at 1-2 s; the episodes end at 3 s and start again
STEPS = 230
#: the suite each registered controller is made for (smile-v1 unless named); the automatic designs are made for
#: a vehicle file on first use (tests/test_auto_design.py flies them)
SUITE = {"ppo": "smile-windy", "inversion-id": "smile-v2-faults", "inversion-id-smile": "smile-v2",
         "inversion-id-stratos": "stratos-tvc-v2", "privileged": "smile-v2"}
REGISTERED = sorted(n for n in POLICIES if not n.startswith(("auto-", "fixed-")))


def registered(name):
    return lambda env: build_policy(POLICIES[name], env)


def scheduled(variable=None, interpolation=None, schedule="smile_flex"):
    """gs-pid-flex's schedule read another way (a linear schedule's filters change at every step)."""
    def make(env):
        s = GainSchedule.load(schedule)
        change = {"interpolation": interpolation} if interpolation else {}
        if variable == "time":
            change |= {"variable": "time", "points": tuple(float(r["time_s"]) for r in s.meta["rows"])}
        elif variable == "mach":
            change |= {"variable": "mach", "points": tuple(np.linspace(0.01, 0.3, len(s.points)))}
        return GainScheduledPIDPolicy(dataclasses.replace(s, **change), env=env, name="variant")
    return make


def fly(suite, make, seed=0, model="nonrigid", law=True, **options):
    """Rows of ``suite``'s VectorEnv flown by ``make(env)``'s batch of N rows, each row's actions checked against
    a one-row policy of its own fed that row's observation and single-env info (``law``: the batch is the
    policy's batch law, and the commands it keeps agree too). Returns the batch."""
    env = lvgym.make_vec_env(suite, model=model, num_envs=N, mission_time_s=MISSION_S, **options)
    singles = [make(env) for _ in range(N)]
    batch = as_batch(make(env), N, lambda: make(env))
    assert batch.name == singles[0].name
    assert isinstance(batch, BatchLaw) == law, type(batch)
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    batch.reset(np.arange(N))
    for p in singles:
        p.reset()
    actions = np.zeros((N, *env.single_action_space.shape), env.single_action_space.dtype)
    engaged = np.zeros(N, bool)
    for step in range(STEPS):
        rows = np.flatnonzero(rng.random(N) < 0.9) if step % 7 else np.arange(N)
        restart = rows[rng.random(rows.size) < 0.02]              # rows that start again mid-flight
        batch.reset(restart)
        for b in restart:
            singles[b].reset()
        got = batch.act(rows, obs[rows], info)
        want = np.array([singles[b].act(obs[b], row_info(info, int(b))) for b in rows]).reshape(got.shape)
        assert got.dtype == want.dtype and got.shape == (rows.size, *actions.shape[1:])
        assert np.array_equal(got, want), (step, rows, got, want)
        if hasattr(batch, "gimbal"):                              # the commands [rad] before the float32 action
            assert np.array_equal(batch.gimbal[rows], [singles[b].law.gimbal[0] for b in rows]), step
        actions[rows] = got
        engaged[rows] |= np.any(got != 0.0, axis=1)
        obs, _, terminated, truncated, info = env.step(actions)
    assert engaged.all()                                           # every row's controller flew
    return batch


@pytest.mark.parametrize("name", REGISTERED)
def test_every_registered_controller_is_one_law(name):
    if name == "zero":
        return fly_zero()
    spec = POLICIES[name]
    options = policy_options(spec)
    fly(SUITE.get(name, "smile-v1"), registered(name), **options)


def fly_zero():
    policy = build_policy(POLICIES["zero"], lvgym.make_env("smile-v1"))
    law = policy.batch(3)
    assert isinstance(law, BatchLaw)
    np.testing.assert_array_equal(law.act([0, 2], np.zeros((2, 14), np.float32), {}), np.zeros((2, 2)))
    assert np.array_equal(policy.act(np.zeros(14, np.float32), {}), np.zeros(2, np.float32))


@pytest.mark.parametrize("suite", ["stratos-tvc-v1", "slender-v1"])
def test_flex_and_aac_on_the_other_vehicles(suite):
    """gs-pid-flex and aac of each vehicle's flex schedule (slender's with load relief)."""
    fly(suite, registered("gs-pid-flex"), seed=3)
    fly(suite, registered("aac"), seed=4)


def test_schedules_read_other_ways_and_aac_options():
    """A linear schedule with filters (discretised per row when they change), schedules on time and on Mach, a
    rigid flight, and the adaptive law with one shared gain and no restart at engagement."""
    fly("smile-v1", scheduled(interpolation="linear"), seed=1)
    fly("smile-v1", scheduled(variable="time"), seed=2)
    fly("smile-v1", scheduled(variable="mach", interpolation="linear", schedule="smile"), seed=3, model="rigid")
    fly("smile-v1", lambda env: flex_aac(env, per_axis=False, reset_on_engage=False, damper_deadzone_rad2=0.0),
        seed=5)


def test_mpc_solves_its_qps_row_by_row_as_one_row_does():
    """With a 10 deg/s servo the MPC's plans break the rate limit and OSQP solves them, a solver per row: each
    row's commands are still those of the one-row policy."""
    batch = fly("smile-v1", registered("mpc"), seed=8, gimbal_rate_limit_degps=10.0)
    assert batch.qp_counts["solves"] > 0


class Halved(PIDPolicy):
    """A subclass that changes the law: it flies as one object per row."""

    def act(self, observation, info):
        return super().act(observation, info) * np.float32(0.5)


class UserPD:
    """A user's controller: the benchmark's Policy interface only, its own state (a step counter)."""

    name = "user-pd"

    def __init__(self):
        self.steps = 0

    def reset(self):
        self.steps = 0

    def act(self, observation, info):
        self.steps += 1
        return np.clip(-5.7 * observation[1:3] - 2.3 * observation[3:5], -1.0, 1.0).astype(np.float32)


def test_a_users_policy_and_a_changed_law_fly_through_the_one_adapter():
    fly("smile-v1", lambda env: Halved(env=env, name="halved"), seed=6, law=False)
    user = UserPD()
    rows = as_batch(user, N, UserPD)
    assert isinstance(rows, PerRow) and own_rows(user).policies[0] is user
    fly("smile-v1", lambda env: UserPD(), seed=7, law=False)
    face = build_policy(POLICIES["lqg"], lvgym.make_env("smile-v1"))
    assert isinstance(face, RowFace) and own_rows(face) is face.law
    with pytest.raises(ValueError, match="need a factory"):
        as_batch(UserPD(), 2).act([1], np.zeros((1, 14), np.float32), {"time": np.zeros(2)})


def test_the_schedule_lookups_are_numpys():
    """interp_k is np.interp of one value (breakpoints, ends, beyond them, an infinite column) and
    nearest_k is argmin of the distance (the first of equals)."""
    rng = np.random.default_rng(0)
    for m in (1, 2, 4, 5, 13):
        xp = np.sort(rng.uniform(100.0, 200.0, m))
        for fp in (rng.normal(size=m), np.full(m, np.inf), np.r_[rng.normal(size=m - 1), np.inf]):
            for x in np.r_[xp, rng.uniform(90.0, 210.0, 200), xp[0] - 1.0, xp[-1] + 1.0]:
                want = np.interp(x, xp, fp)
                got = interp_k(float(x), xp, fp)
                assert got == want or (np.isnan(got) and np.isnan(want)), (m, x)
            for x in np.r_[xp, rng.uniform(90.0, 210.0, 50), 0.5 * (xp[:-1] + xp[1:])]:
                assert nearest_k(xp[::-1].copy(), float(x)) == int(np.argmin(np.abs(xp[::-1] - x)))
