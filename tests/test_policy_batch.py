"""The batched act of the classical controllers (``policy.batch(n)``, lvgym.baselines.batch) against the
per-row policies: rows of the v1 suites' VectorEnv flown with the batch's actions, each row's own policy
object fed that row's observation and the single env's info of that row, the actions and the gimbal
commands before them (float64) equal (==) at every step; rows reset at different steps, stepped in changing subsets, through the controller's switch-on and
an episode's end."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import lvgym
import lvgym.baselines  # noqa: F401  (registers the baselines)
from lvgym.baselines.aac import AdaptiveAugmentingPolicy, flex_aac
from lvgym.baselines.aacbatch import AACBatch
from lvgym.baselines.batch import RowCopies
from lvgym.baselines.lqg import LQGBatch
from lvgym.baselines.pid import GainSchedule, GainScheduledPIDPolicy, PIDPolicy, flex_pid
from lvgym.baselines.pidbatch import PIDBatch
from lvgym.baselines.pidkernel import interp_k, nearest_k
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.runner import build_policy
from lvgym.envs.core import row_info as _row

N = 4
MISSION_S = 3.0           # the controller switches on at 1-2 s; the episodes end at 3 s and start again
STEPS = 230


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


class Halved(PIDPolicy):
    """A subclass that changes the law: the batch must not compile it."""

    def act(self, observation, info):
        return super().act(observation, info) * np.float32(0.5)


def fly(suite, make, kind, seed=0, model="nonrigid"):
    env = lvgym.make_vec_env(suite, model=model, num_envs=N, mission_time_s=MISSION_S)
    singles = [make(env) for _ in range(N)]
    batch = make(env).batch(N)
    assert isinstance(batch, kind) and batch.name == singles[0].name
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    batch.reset(np.arange(N))
    for p in singles:
        p.reset()
    actions = np.zeros((N, 2), np.float32)
    engaged = np.zeros(N, bool)
    for step in range(STEPS):
        rows = np.flatnonzero(rng.random(N) < 0.9) if step % 7 else np.arange(N)
        restart = rows[rng.random(rows.size) < 0.02]              # rows that start again mid-flight
        batch.reset(restart)
        for b in restart:
            singles[b].reset()
        got = batch.act(rows, obs[rows], info)
        want = np.array([singles[b].act(obs[b], _row(info, b)) for b in rows], np.float32).reshape(-1, 2)
        assert got.dtype == np.float32 and got.shape == (rows.size, 2)
        assert np.array_equal(got, want), (step, rows, got, want)
        if kind is not RowCopies:                                  # the commands [rad] before the float32 action
            assert np.array_equal(batch.gimbal[rows], [singles[b].last_gimbal for b in rows]), step
        actions[rows] = got
        engaged[rows] |= np.any(got != 0.0, axis=1)
        obs, _, terminated, truncated, info = env.step(actions)
    assert engaged.all()                                           # every row's controller flew


@pytest.mark.parametrize("name", ["pid", "pid-thesis", "gs-pid", "gs-pid-thesis", "gs-pid-flex", "aac", "lqg",
                                  "lqg-front", "gs-pd-relief"])
def test_every_baseline_batch_is_its_policy_per_row_on_smile(name):
    kind = {"aac": AACBatch, "lqg": LQGBatch, "lqg-front": LQGBatch}.get(name, PIDBatch)
    fly("smile-v1", registered(name), kind)


@pytest.mark.parametrize("suite", ["stratos-tvc-v1", "slender-v1"])
def test_flex_and_aac_batches_on_the_other_vehicles(suite):
    """gs-pid-flex and aac of each vehicle's flex schedule (slender's with load relief)."""
    fly(suite, registered("gs-pid-flex"), PIDBatch, seed=3)
    fly(suite, registered("aac"), AACBatch, seed=4)


def test_schedules_read_other_ways_and_aac_options():
    """A linear schedule with filters (discretised in Python per row), schedules on time and on Mach, a
    rigid flight, and the adaptive law with one shared gain and no restart at engagement."""
    fly("smile-v1", scheduled(interpolation="linear"), PIDBatch, seed=1)
    fly("smile-v1", scheduled(variable="time"), PIDBatch, seed=2)
    fly("smile-v1", scheduled(variable="mach", interpolation="linear", schedule="smile"), PIDBatch, seed=3,
        model="rigid")
    fly("smile-v1", lambda env: flex_aac(env, per_axis=False, reset_on_engage=False, damper_deadzone_rad2=0.0),
        AACBatch, seed=5)


def test_a_law_the_kernels_do_not_know_flies_as_copies():
    """A subclass of PIDPolicy, and aac on a base that is no PID of the kernels (the AAC tuning study's
    scaled base, which delegates its attributes and must survive the copy)."""
    from experiments.aac_tuning.aac_sweep import ScaledBase

    fly("smile-v1", lambda env: Halved(env=env, name="halved"), RowCopies, seed=6)
    fly("smile-v1", lambda env: AdaptiveAugmentingPolicy(ScaledBase(flex_pid(env), 2.0), env=env), RowCopies, seed=7)


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


def test_the_speed_study_replays_the_same_actions():
    """experiments/policy_batch_speed: the recorded flight replayed through per-row policies and the batch
    (it raises where their actions differ) gives a time per call of each."""
    from experiments.policy_batch_speed.act_speed import time_policy

    r = time_policy("aac", "smile-v1", rows=2, steps=120, repeats=1)
    assert r["policy"] == "aac" and r["batch"] == "AACBatch"
    assert r["row_us"] > 0.0 and r["batch_row_us"] > 0.0 and r["batch_call_us"] == pytest.approx(2 * r["batch_row_us"])
