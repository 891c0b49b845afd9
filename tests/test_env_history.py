"""The ``history=k`` option (a frame stack): the stack's layout and shift, zero-padding at a reset, the
single env against the batched ones, both env checkers, seeded determinism, and history off unchanged."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env

import lvgym  # noqa: F401  (registers the envs)
from lvgym.envs.history import lag_name
from lvgym.errors import ConfigError

ENV = "lvgym/SmileAscent-v1"
OPTS = dict(model="rigid", wind="turbulence", randomize=True, mission_time_s=1.0)


def _actions(n, seed=0, rows=None):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.3, 1.3, (n, 2) if rows is None else (n, rows, 2)).astype(np.float32)


def test_layout_names_every_lag_and_keeps_the_newest_sample_under_its_own_name():
    env = gym.make(ENV, history=3, **OPTS)
    base = env.unwrapped.func.sample_layout
    lay = env.unwrapped.observation_layout
    assert env.observation_space.shape == (3 * base.size + 3 * 2,) == (lay.size,)
    names = [f.name for _, f in lay.leaves()]
    want = [lag_name(n, j) for j in (2, 1, 0) for n in base.names] + \
        [f"{a}_lag{j}" for j in (3, 2, 1) for a in ("action_pitch", "action_yaw")]
    assert names == want
    for n in base.names:        # the newest sample: where a baseline reading by name expects it
        assert lay.index(n) == 2 * base.size + base.index(n)
    with pytest.raises(ConfigError, match="history"):
        gym.make(ENV, history=-1)
    with pytest.raises(ConfigError, match="history"):
        gym.make(ENV, history=1.5)


def test_the_stack_shifts_by_one_sample_and_one_action_per_step_and_zero_pads_at_reset():
    k = 3
    plain, stacked = gym.make(ENV, **OPTS), gym.make(ENV, history=k, **OPTS)
    lay = stacked.unwrapped.observation_layout
    n = plain.observation_space.shape[0]
    o, _ = plain.reset(seed=4)
    h, _ = stacked.reset(seed=4)
    assert np.array_equal(h[lay.slice("observation_lag0")], o)
    assert not h[:lay.slice("observation_lag0").start].any() and not h[lay.slice("action_lag3").start:].any()
    samples, actions = [o], []
    for a in _actions(8, 1):
        o = plain.step(a)[0]
        h = stacked.step(a)[0]
        samples.append(o)
        actions.append(np.clip(a, -1.0, 1.0))          # the action recorded: clipped to the Box
        for j in range(k):                             # by hand: lag j is the sample j steps back, or zeros
            want = samples[-1 - j] if j < len(samples) else np.zeros(n, np.float32)
            assert np.array_equal(h[lay.slice(f"observation_lag{j}")], want)
        for j in range(1, k + 1):
            want = actions[-j] if j <= len(actions) else np.zeros(2, np.float32)
            assert np.array_equal(h[lay.slice(f"action_lag{j}")], want)
    h, _ = stacked.reset(seed=5)                       # a new episode: zero-padded again
    assert not np.delete(h, np.r_[lay.slice("observation_lag0")]).any()


def test_history_off_is_bit_identical_to_no_option():
    a, b = gym.make(ENV, **OPTS), gym.make(ENV, history=0, **OPTS)
    oa, ob = a.reset(seed=2)[0], b.reset(seed=2)[0]
    assert oa.dtype == ob.dtype and np.array_equal(oa, ob) and a.observation_space == b.observation_space
    for u in _actions(20, 3):
        ra, rb = a.step(u), b.step(u)
        assert np.array_equal(ra[0], rb[0]) and ra[1] == rb[1]


def test_single_vector_and_sb3_envs_stack_alike():
    from lvgym.envs import make_sb3_vec_env
    rows, seed, k = 3, 7, 4
    opts = dict(OPTS, mission_time_s=0.3, history=k)          # 15 steps: the batches autoreset on the way
    venv = gym.make_vec(ENV, num_envs=rows, vectorization_mode="vector_entry_point", **opts)
    svec = make_sb3_vec_env(ENV, num_envs=rows, seed=seed, **opts)
    singles = [gym.make(ENV, **opts) for _ in range(rows)]
    vo, _ = venv.reset(seed=seed)
    so = svec.reset()
    sing = np.stack([e.reset(seed=seed + i)[0] for i, e in enumerate(singles)])
    assert np.array_equal(vo, sing) and np.array_equal(so, sing)
    for u in _actions(15, 5, rows):
        vo, vr, vterm, vtrunc, _ = venv.step(u)
        so, sr, sdone, sinfos = svec.step(u)
        for i, e in enumerate(singles):
            o, r, term, trunc, _ = e.step(u[i])
            assert np.array_equal(vo[i], o) and vr[i] == r
            if term or trunc:                          # SB3 resets at once: the stack of the last step is kept
                assert sdone[i] and np.array_equal(sinfos[i]["terminal_observation"], o)
                o, _ = e.reset(seed=None)
            else:
                assert np.array_equal(so[i], o)


@pytest.mark.parametrize("k", [1, 3])
def test_gymnasium_and_sb3_checkers_pass_with_history(k):
    from stable_baselines3.common.env_checker import check_env as sb3_check_env
    env = gym.make(ENV, history=k, **OPTS).unwrapped
    gym_check_env(env, skip_render_check=True)
    sb3_check_env(env, warn=False)
    rcs = gym.make("lvgym/StratosIII-v0", history=k, model="rigid", mission_time_s=0.5).unwrapped
    gym_check_env(rcs, skip_render_check=True)
    sb3_check_env(rcs, warn=False)


def test_seeded_episodes_with_history_repeat_bit_for_bit_and_snapshots_restore():
    def run():
        env = gym.make(ENV, history=2, **OPTS)
        out = [env.reset(seed=9)[0]]
        out += [env.step(u)[0] for u in _actions(12, 8)]
        return np.stack(out), env
    a, env = run()
    b, _ = run()
    assert np.array_equal(a, b)
    snap = env.unwrapped.get_state()
    x = [env.step(u)[0] for u in _actions(5, 9)]
    env.unwrapped.set_state(snap)
    y = [env.step(u)[0] for u in _actions(5, 9)]
    assert np.array_equal(np.stack(x), np.stack(y))
