"""The functional env (AscentFuncEnv): explicit state and parameters, batched over rows.

Side by side: the functional env against the Gymnasium env built over it, a transition out of place
against one in place, a batch of rows against single rows; the parameters are explicit (a changed
reward weight changes only the reward).
"""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.experimental.functional import FuncEnv

import lvgym  # noqa: F401
from lvgym.envs import AscentFuncEnv, SmileAscentEnv, StratosIIIEnv, TaskSpec
from lvgym.envs.layouts import REWARD, TASK

OPTS = {"model": "nonrigid", "wind": "turbulence", "randomize": True, "observation": "sensors", "mission_time_s": 3.0}


def _func(cls=SmileAscentEnv, **kw) -> AscentFuncEnv:
    return AscentFuncEnv(TaskSpec.build(cls.PRESET, {**OPTS, **kw}))


def _same_state(a, b) -> None:
    for x, y in zip(a.sim, b.sim):
        np.testing.assert_array_equal(x, y)
    for x, y in zip(a.task, b.task):
        np.testing.assert_array_equal(x, y)
    assert a.events == b.events


def test_is_a_gymnasium_func_env_and_the_env_is_an_adapter_over_it():
    func = _func()
    assert isinstance(func, FuncEnv)
    env = gym.make("lvgym/SmileAscent-v0", **OPTS)
    obs, _ = env.reset(seed=5)
    rng = np.random.default_rng(5)                     # the env's np_random for seed 5
    from gymnasium.utils import seeding
    g, _ = seeding.np_random(5)
    state = func.initial([g])
    np.testing.assert_array_equal(func.observation(state)[0], obs)
    acts = rng.uniform(-1, 1, (120, 2)).astype(np.float32)
    for a in acts:
        obs, r, term, trunc, info = env.step(a)
        state = func.transition(state, a[None], [g])
        np.testing.assert_array_equal(func.observation(state)[0], obs)
        assert func.reward(None, a, state)[0] == r
        assert func.terminal(state)[0] == term and func.truncation(state)[0] == trunc
        fi = func.transition_info(None, a, state)
        np.testing.assert_array_equal(fi["cumulative_rate_error"][0], info["cumulative_rate_error"])
        if term or trunc:
            break


def test_a_transition_out_of_place_leaves_its_input_and_equals_one_in_place():
    func = _func()
    rngs = [np.random.default_rng(s) for s in range(4)]
    state = func.initial(rngs)
    for _ in range(20):
        state = func.transition(state, np.full((4, 2), 0.3), rngs, inplace=True)
    before = func.take(state)
    twin = [np.random.default_rng(0) for _ in range(4)]
    for g, h in zip(twin, rngs):
        g.bit_generator.state = h.bit_generator.state
    out = func.transition(state, np.full((4, 2), -0.2), rngs)
    _same_state(state, before)                         # the input is untouched
    same = func.transition(before, np.full((4, 2), -0.2), twin, inplace=True)
    _same_state(out, same)
    assert not np.array_equal(out.sim.x, state.sim.x)


def test_rows_of_a_batch_fly_as_single_rows():
    func = _func()
    seeds = [3, 4, 5]
    batch = func.initial([np.random.default_rng(s) for s in seeds])
    singles = [func.initial([np.random.default_rng(s)]) for s in seeds]
    rb = [np.random.default_rng(100 + s) for s in seeds]
    rs = [[np.random.default_rng(100 + s)] for s in seeds]
    acts = np.random.default_rng(0).uniform(-1, 1, (60, 3, 2))
    for a in acts:
        batch = func.transition(batch, a, rb, inplace=True)
        for i in range(3):
            singles[i] = func.transition(singles[i], a[i:i + 1], rs[i], inplace=True)
    for i in range(3):
        np.testing.assert_array_equal(func.observation(batch)[i], func.observation(singles[i])[0])
        np.testing.assert_array_equal(batch.sim.x[i], singles[i].sim.x[0])


def test_parameters_are_explicit():
    func = _func(randomize=False, wind="none", observation="state")
    rng = [np.random.default_rng(0)]
    p = func.default_params
    assert p.task.shape == (TASK.size,) and p.task[TASK.index("gimbal_limit")] == func.gimbal_limit
    heavy = p._replace(task=p.task.copy())
    heavy.task[TASK.slice("rate_weights")] *= 10.0
    a, b = func.initial(rng, p), func.initial(rng, heavy)
    for _ in range(150):
        a = func.transition(a, np.full((1, 2), 0.5), rng, p)
        b = func.transition(b, np.full((1, 2), 0.5), rng, heavy)
    np.testing.assert_array_equal(a.sim.x, b.sim.x)                       # the same flight
    rate = [REWARD.index(n) for n in ("rate_roll", "rate_pitch", "rate_yaw")]
    np.testing.assert_allclose(b.task.terms[0, rate], 10.0 * a.task.terms[0, rate], rtol=1e-12)
    assert b.task.reward[0] < a.task.reward[0]


def test_rows_reset_in_place_and_draw_only_from_their_generators():
    func = _func()
    state = func.initial([np.random.default_rng(s) for s in range(3)])
    fresh = func.initial([np.random.default_rng(9)])
    state = func.reset(state, [1], [np.random.default_rng(9)])
    np.testing.assert_array_equal(state.sim.x[1], fresh.sim.x[0])
    np.testing.assert_array_equal(func.observation(state)[1], func.observation(fresh)[0])


@pytest.mark.parametrize("action", [[1.5, -3.0], [0.2, 0.0]])
def test_box_actions_are_clipped(action):
    func = _func(randomize=False, wind="none", observation="state", controller_on_after_s=0.0)
    rng = [np.random.default_rng(0)]
    a = func.transition(func.initial(rng), np.array([action]), rng)
    b = func.transition(func.initial(rng), np.clip([action], -1, 1), rng)
    np.testing.assert_array_equal(a.sim.actuator, b.sim.actuator)


def test_rcs_task_and_state_info():
    func = _func(StratosIIIEnv, observation="state", randomize=False)
    rng = [np.random.default_rng(0)]
    state = func.initial(rng)
    info = func.state_info(state)
    assert info["time"][0] == 0.0 and info["mass"][0] > 0.0
    state = func.transition(state, np.array([[2]]), rng)
    assert func.transition_info(None, None, state)["time"][0] == pytest.approx(func.spec.control_dt_s)


@pytest.mark.parametrize("env_id, bad, match", [
    ("lvgym/StratosIII-v0", [7], r"action \[7\]: the action space is MultiDiscrete\(\[3\]\)"),
    ("lvgym/StratosIII-v0", [-1], r"action \[-1\]: the action space"),
    ("lvgym/StratosIII-v0", [1, 1], r"action \[1, 1\] has shape \(2,\): expected \(1,\)"),
    ("lvgym/StratosIII-v0", [0.5], r"whole numbers 0"),
    ("lvgym/SmileAscent-v0", [0.1, 0.2, 0.3], r"has shape \(3,\): expected \(2,\), an element of the action space Box"),
    ("lvgym/SmileAscent-v0", [np.nan, 0.0], r"is not finite: the action space is Box"),
    ("lvgym/SmileAscent-v0", [np.inf, 0.0], r"is not finite"),
])
def test_actions_outside_the_space_are_refused_with_the_action_and_the_space(env_id, bad, match):
    env = gym.make(env_id, model="rigid")
    env.reset(seed=0)
    with pytest.raises(ValueError, match=match):
        env.step(np.array(bad) if not isinstance(bad, list) or np.isnan(bad).any() or np.isinf(bad).any() else bad)
    obs, *_ = env.step(env.action_space.sample())         # the env is still usable
    assert np.isfinite(obs).all()


def test_vector_env_refuses_a_wrong_batch_of_actions():
    venv = gym.make_vec("lvgym/SmileAscent-v0", num_envs=3, vectorization_mode="vector_entry_point", model="rigid")
    venv.reset(seed=0)
    with pytest.raises(ValueError, match=r"has shape \(6,\): expected \(3, 2\), 3 row\(s\)"):
        venv.step(np.zeros(6, np.float32))
    with pytest.raises(ValueError, match="not finite"):
        venv.step(np.full((3, 2), np.nan, np.float32))


def test_an_action_acts_after_the_delay():
    """action_delay_steps = 2: what the policy samples at step k commands the gimbal at step k + 2."""
    from lvgym.simulator.layouts import ACTUATOR
    opts = dict(randomize=False, wind="none", observation="state", controller_on_after_s=0.0)
    late, now = _func(action_delay_steps=2, **opts), _func(**opts)
    rng = [np.random.default_rng(0)]
    a, b = late.initial(rng), now.initial(rng)
    acts = np.linspace(-0.9, 0.9, 8).reshape(4, 1, 2)
    cmds = []
    for k in range(6):
        a = late.transition(a, acts[k] if k < 4 else np.zeros((1, 2)), rng, inplace=True)
        cmds.append(ACTUATOR.view(a.sim.actuator, "command")[0].copy())
    np.testing.assert_array_equal(cmds[0], [0.0, 0.0])
    np.testing.assert_array_equal(cmds[1], [0.0, 0.0])
    for k in range(2, 6):
        np.testing.assert_allclose(cmds[k], acts[k - 2, 0] * late.gimbal_limit, rtol=1e-15)
    b = now.transition(b, acts[0], rng)
    np.testing.assert_allclose(ACTUATOR.view(b.sim.actuator, "command")[0], acts[0, 0] * now.gimbal_limit)


@pytest.mark.parametrize("velocity", ["inertial", "earth"])
def test_gravity_turn_follows_the_chosen_velocity(velocity):
    from lvgym.simulator.core import WGS84_OMEGA
    func = _func(randomize=False, wind="none", observation="state", reference="gravity_turn",
                 reference_velocity=velocity, kick_start_s=2.0, kick_end_s=4.0, mission_time_s=8.0)
    rng = [np.random.default_rng(0)]
    state = func.initial(rng)
    for _ in range(300):
        state = func.transition(state, np.zeros((1, 2)), rng, inplace=True)
    lay = func.sim.layout
    r, v = state.sim.x[0, lay.state["r_zw_i"]], state.sim.x[0, lay.state["v_zw_i"]]
    if velocity == "earth":
        v = v - np.cross([0.0, 0.0, WGS84_OMEGA], r)
    g = func.sim.conditions(state.sim, "g_i")[0]
    sin_th = np.linalg.norm(np.cross(v / np.linalg.norm(v), -g / np.linalg.norm(g)))
    expected = -np.linalg.norm(g) * sin_th / np.linalg.norm(v)
    ref = func.observation(state)[0, func.observation_layout.index("pitch_rate_reference")]
    assert ref == pytest.approx(expected, rel=1e-5)
