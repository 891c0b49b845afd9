"""In-flight faults (lvgym/envs/faults.py, the servo's fault fields): the servo against hand numbers, the
draw against its window and ranges, each kind in flight, the naming after the episode, the env's generator,
and batched rows against single envs."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.envs.faults import FAULT, FAULT_DRAW, FAULT_KINDS, FAULT_NAMES, decode, fault_names
from lvgym.errors import ConfigError
from lvgym.simulator.layouts import ACTUATOR, SERVO
from lvgym.simulator.servo import Servo, servo_step_k

F = FAULT.at


def _servo_run(fields: dict, command: float = 0.02, steps: int = 400, h: float = 0.01) -> np.ndarray:
    """The pitch gimbal [rad] over ``steps`` physics steps of a servo at rest, commanded ``command`` on both
    axes, with the actuator fault ``fields`` set."""
    s = Servo().params()
    act = ACTUATOR.zeros()
    ACTUATOR.view(act, "command")[:] = command
    for key, value in fields.items():
        ACTUATOR.view(act, key)[:] = value
    out = np.empty((steps, 2))
    for k in range(steps):
        servo_step_k(s, act, h, k)
        out[k] = ACTUATOR.view(act, "gimbal")
    return out


def test_the_servo_reaches_what_its_effectiveness_leaves():
    g = _servo_run({"effectiveness_loss": [0.4, 0.0]})
    assert g[-1, 0] == pytest.approx(0.6 * 0.02, rel=1e-6)
    assert g[-1, 1] == pytest.approx(0.02, rel=1e-6)


def test_a_lost_bandwidth_slows_the_servo_by_its_frequency():
    nominal = _servo_run({}, steps=4000, h=1e-3)[:, 0]
    slow = _servo_run({"bandwidth_loss": [0.5, 0.0]}, steps=4000, h=1e-3)[:, 0]
    t63 = [int(np.argmax(g >= 0.632 * 0.02)) for g in (nominal, slow)]
    assert t63[1] / t63[0] == pytest.approx(2.0, rel=0.03)         # half the frequency, twice the time
    assert slow[-1] == pytest.approx(0.02, rel=1e-4)


def test_a_stuck_axis_holds_its_angle_and_the_other_moves():
    s = Servo().params()
    act = ACTUATOR.zeros()
    ACTUATOR.view(act, "command")[:] = 0.02
    for k in range(20):
        servo_step_k(s, act, 0.01, k)
    held = ACTUATOR.view(act, "gimbal")[0]
    ACTUATOR.view(act, "stuck")[0] = 1.0
    ACTUATOR.view(act, "command")[:] = -0.03
    for k in range(200):
        servo_step_k(s, act, 0.01, k)
    assert ACTUATOR.view(act, "gimbal")[0] == held and ACTUATOR.view(act, "gimbal_rate")[0] == 0.0
    assert ACTUATOR.view(act, "gimbal")[1] == pytest.approx(-0.03, rel=1e-4)


def test_without_a_servo_the_faults_act_on_the_gimbal_directly():
    direct = SERVO.zeros()
    act = ACTUATOR.zeros()
    ACTUATOR.view(act, "command")[:] = [0.02, 0.01]
    ACTUATOR.view(act, "gimbal")[:] = [0.005, 0.0]
    ACTUATOR.view(act, "effectiveness_loss")[:] = [0.0, 0.5]
    ACTUATOR.view(act, "stuck")[:] = [1.0, 0.0]
    servo_step_k(direct, act, 0.01, 0)
    np.testing.assert_array_equal(ACTUATOR.view(act, "gimbal"), [0.005, 0.005])


def test_the_decoded_fault_lies_in_its_window_and_range():
    rng = np.random.default_rng(0)
    kinds = FAULT_NAMES
    seen = {k: 0 for k in kinds}
    for _ in range(5000):
        draw = np.array([rng.uniform(), rng.uniform(), rng.uniform(), rng.integers(0, 2), rng.integers(0, 2)], float)
        f = decode(draw, kinds, (12.0, 30.0))
        kind = FAULT_KINDS[int(f[F.kind]) - 1]
        seen[kind.name] += 1
        assert 12.0 <= f[F.onset_s] <= 30.0 and f[F.axis] in (0.0, 1.0) and f[F.active] == 0.0
        lo, hi = ((math.radians(kind.low), math.radians(kind.high)) if kind.unit in ("deg", "deg/s")
                  else (kind.low, kind.high))
        assert lo - 1e-15 <= abs(f[F.size]) <= hi + 1e-15
        if kind.name not in ("gyro_bias", "misalignment"):
            assert f[F.size] >= 0.0
    assert all(abs(n / 5000 - 1 / len(kinds)) < 0.03 for n in seen.values())          # an equal share each
    assert not decode(FAULT_DRAW.zeros(), (), (0.0, 1.0)).any()                          # no kinds: none
    one = decode(np.array([0.99, 0.5, 1.0, 1, 0]), ("stuck", "gyro_bias"), (10.0, 20.0))
    assert FAULT_KINDS[int(one[F.kind]) - 1].name == "gyro_bias" and one[F.onset_s] == 15.0
    assert one[F.size] == pytest.approx(-math.radians(0.25))
    assert fault_names(np.array([one, FAULT.zeros()])).tolist() == ["gyro_bias yaw", ""]


def test_bad_fault_options_name_the_key():
    with pytest.raises(ConfigError, match="fault_kinds"):
        gym.make("lvgym/SmileAscent-v1", fault_kinds=("jammed",))
    with pytest.raises(ConfigError, match="fault_onset_s"):
        gym.make("lvgym/SmileAscent-v1", fault_onset_s=(30.0, 10.0))


def _fly(kind: str, seed: int = 1, onset: float = 4.0, action=(0.05, -0.04)):
    """A short SMILE v1 flight with one fault of ``kind`` striking at ``onset`` and a fixed action; per step
    the time, the gimbal, the info's ``fault`` and the env's fault row, and the final info."""
    env = gym.make("lvgym/SmileAscent-v1", randomize={"fault"}, fault_kinds=(kind,), fault_onset_s=(onset, onset),
                   mission_time_s=6.0, controller_on_after_s=2.0)
    env.reset(seed=seed)
    rows = []
    while True:
        _, _, term, trunc, info = env.step(np.array(action, dtype=np.float32))
        rows.append((info["time"], np.array(info["gimbal"]), info["fault"],
                     env.unwrapped.core.state.task.fault[0].copy()))
        if term or trunc:
            return rows, info, env


@pytest.mark.parametrize("kind", FAULT_NAMES)
def test_each_fault_strikes_at_its_onset_and_is_named_only_at_the_end(kind):
    rows, info, env = _fly(kind)
    fault = rows[-1][3]
    assert FAULT_KINDS[int(fault[F.kind]) - 1].name == kind and fault[F.active] == 1.0
    struck = [t for t, _, _, f in rows if f[F.active]]
    assert struck[0] == pytest.approx(4.02)                 # the step that starts at the onset
    assert [n for _, _, n, _ in rows[:-1]] == [""] * (len(rows) - 1)
    assert info["fault"] == fault_names(fault[None])[0] and info["fault"].startswith(kind)
    gimbal = np.array([g for _, g, _, _ in rows])
    t = np.array([r[0] for r in rows])
    axis = int(fault[F.axis])
    after = t > 5.0
    limit = env.unwrapped.func.gimbal_limit
    if kind == "stuck":
        k0 = int(np.argmax(t >= 4.02))
        assert np.all(gimbal[k0:, axis] == gimbal[k0, axis])
    elif kind == "effectiveness":
        assert after.sum() > 40
        want = (0.05, -0.04)[axis] * limit * (1.0 - fault[F.size])
        assert gimbal[after, axis].mean() == pytest.approx(want, rel=0.02)
        assert gimbal[after, 1 - axis].mean() == pytest.approx((0.05, -0.04)[1 - axis] * limit, rel=0.02)


def test_a_thrust_loss_scales_the_thrust_from_the_onset():
    env = gym.make("lvgym/SmileAscent-v1", randomize={"fault"}, fault_kinds=("thrust",), fault_onset_s=(3.0, 3.0),
                   mission_time_s=5.0)
    env.reset(seed=2)
    u = env.unwrapped
    before = []
    for _ in range(150):                                   # to 3.0 s: not struck yet
        env.step(np.zeros(2, np.float32))
        before.append(u.flight.load_dispersion("thrust_scale")[0])
    env.step(np.zeros(2, np.float32))
    size = u.core.state.task.fault[0, F.size]
    assert set(before) == {1.0} and 0.1 <= size <= 0.3
    assert u.flight.load_dispersion("thrust_scale")[0] == 1.0 - size


def test_a_gyro_bias_step_moves_the_bias_of_its_axis():
    env = gym.make("lvgym/SmileAscent-v1", randomize={"fault"}, fault_kinds=("gyro_bias",), fault_onset_s=(3.0, 3.0),
                   mission_time_s=4.0)
    env.reset(seed=3)
    task = env.unwrapped.core.state.task
    b0 = task.gyro_bias[0].copy()
    for _ in range(200):
        env.step(np.zeros(2, np.float32))
    f = task.fault[0]
    want = b0.copy()
    want[1 + int(f[F.axis])] += f[F.size]
    np.testing.assert_array_equal(task.gyro_bias[0], want)


def test_a_misalignment_step_turns_the_thrust_of_its_axis_from_the_onset():
    env = gym.make("lvgym/SmileAscent-v1", randomize={"fault"}, fault_kinds=("misalignment",),
                   fault_onset_s=(3.0, 3.0), mission_time_s=4.0)
    env.reset(seed=4)
    u = env.unwrapped
    sim, data = u.func.sim, u.core.state.sim
    m0 = sim.misalignment(data)[0].copy()
    for _ in range(150):                                   # to 3.0 s: not struck yet
        env.step(np.zeros(2, np.float32))
    np.testing.assert_array_equal(sim.misalignment(u.core.state.sim)[0], m0)
    env.step(np.zeros(2, np.float32))
    f = u.core.state.task.fault[0]
    axis = int(f[F.axis])
    assert math.radians(0.5) <= abs(f[F.size]) <= math.radians(1.5)
    want = m0.copy()
    want[axis] += f[F.size]
    np.testing.assert_array_equal(sim.misalignment(u.core.state.sim)[0], want)
    # the thrust turns by it: with the gimbal centred, its lateral share on that axis is sin(misalignment)
    thrust_b = sim.conditions(u.core.state.sim, "thrust_b")[0]
    lateral = thrust_b[2] if axis == 0 else -thrust_b[1]
    turned = want[axis] + u.func.gimbal(u.core.state)[0, axis]
    assert lateral / np.linalg.norm(thrust_b) == pytest.approx(math.sin(turned), abs=1e-3)


def test_the_fault_comes_from_the_env_generator_and_rows_fly_as_single_envs():
    opts = dict(randomize={"fault", "wind", "sensor_noise", "mass"}, mission_time_s=8.0, fault_onset_s=(2.0, 6.0))
    seeds = [4, 5, 6]
    vec = gym.make_vec("lvgym/SmileAscent-v1", num_envs=3, vectorization_mode="vector_entry_point", **opts)
    vec.reset(seed=seeds)
    faults = vec.unwrapped.core.state.task.fault.copy()
    assert len({f[F.kind] * 100 + f[F.onset_s] for f in faults}) == 3            # the seeds draw differently
    a = np.full((3, 2), 0.1, np.float32)
    vec_rows, done = [], np.zeros(3, bool)
    for _ in range(400):
        _, _, term, trunc, info = vec.step(a)
        vec_rows.append((info["time"].copy(), info["gimbal"].copy(), info["fault"].copy()))
        done |= term | trunc
        if done.all():
            break
    for b, seed in enumerate(seeds):
        env = gym.make("lvgym/SmileAscent-v1", **opts)
        env.reset(seed=seed)
        np.testing.assert_array_equal(env.unwrapped.core.state.task.fault[0], faults[b])
        for t, g, names in vec_rows:
            _, _, term, trunc, info = env.step(a[b])
            assert info["time"] == t[b] and np.array_equal(info["gimbal"], g[b]) and info["fault"] == names[b]
            if term or trunc:
                break


def test_the_record_names_the_fault_batched_as_single():
    """A condition whose env draws faults: the batched rows and play_episode give the same records, each
    naming the fault it flew; a condition without faults has no ``fault`` field."""
    from dataclasses import replace

    from lvgym.benchmark.batch import as_batch
    from lvgym.benchmark.rows import fly_rows
    from lvgym.benchmark.runner import play_episode, zero_policy
    from lvgym.benchmark.suites import condition

    base = condition("smile-v1", "rigid").with_options(mission_time_s=6.0)
    cond = replace(base, randomize=tuple(base.randomize) + ("fault",)).with_options(fault_onset_s=(2.0, 5.0))
    seeds = [0, 1, 2]
    env = cond.make_vec_env(len(seeds))
    rows = fly_rows(env, seeds, [(as_batch(zero_policy(cond.make_env()), len(seeds)), list(range(len(seeds))))])
    for seed, rec in zip(seeds, rows):
        single = cond.make_env()
        assert play_episode(zero_policy(single), single, seed) == rec and rec["fault"]
    plain_env = base.make_vec_env(1)
    plain = fly_rows(plain_env, [0], [(as_batch(zero_policy(base.make_env()), 1), [0])])[0]
    assert "fault" not in plain


def test_a_snapshot_before_the_onset_replays_the_fault_bit_for_bit():
    env = gym.make("lvgym/SmileAscent-v1", randomize={"fault", "wind"}, fault_kinds=("effectiveness", "gyro_bias"),
                   fault_onset_s=(3.0, 3.5), mission_time_s=5.0)
    env.reset(seed=7)
    a = np.array([0.05, -0.05], np.float32)
    for _ in range(100):                                   # 2 s: before the onset
        env.step(a)
    snap = env.unwrapped.get_state()

    def rest():
        out = []
        while True:
            _, _, term, trunc, info = env.step(a)
            out.append((info["time"], info["gimbal"].tobytes(), info["fault"]))
            if term or trunc:
                return out

    first = rest()
    env.unwrapped.set_state(snap)
    assert rest() == first and first[-1][2]


def test_smile_cannot_fly_a_stuck_actuator_so_the_v2_fault_suite_leaves_it_out():
    """The contradiction behind smile-v2-faults' kinds: SMILE has one nozzle and no other effector on a jammed
    axis, so even lqg fails once an axis sticks (experiments/protocol_v2_design, part 5: every design, every
    seed of 20)."""
    from lvgym.benchmark import condition, run_episode
    from lvgym.benchmark.suites import V2_FAULT_KINDS
    from lvgym.cli.policies import resolve_policy

    assert "stuck" not in V2_FAULT_KINDS and "stuck" in [k.name for k in FAULT_KINDS]
    cond = condition("smile-v2-faults", "rigid", fault_kinds=("stuck",), fault_onset_s=(10.0, 20.0))
    for seed in (0, 1):
        rec = run_episode(resolve_policy("lqg"), cond, seed)
        assert rec["failed"] and rec["fault"].startswith("stuck"), rec["fault"]
