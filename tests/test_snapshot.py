"""Episode snapshots: get_state / set_state through pickle replay the rest of an episode bit for bit.

For every env id and every flight model, single env and vector env: fly a while, take the state,
pickle it, fly on, restore the unpickled state, fly the same actions again: every observation, reward,
flag and info entry must be identical. Sensor noise, dispersions and winds are on, so the generators'
states are part of what is restored; short missions make the episodes end (and the vector env autoreset)
inside the replayed part.
"""

import pickle

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401  (registers the envs)
from lvgym.envs import EpisodeState

ENV_IDS = ["lvgym/SmileAscent-v0", "lvgym/StratosIII-v0", "lvgym/SlenderAscent-v0"]
MODELS = ["rigid", "slosh", "flex", "nonrigid"]
#: keys compared besides observation, reward and the flags (every numeric info entry)
INFO_KEYS = ("cumulative_rate_error", "rate_error", "qbar", "mach", "alpha_total", "qalpha_pa_deg", "time",
             "stage", "controller_on", "slosh_angles", "eta", "gimbal", "effort_rad_s", "attitude_error", "mass",
             "termination", "events")


def _options(env_id: str, model: str) -> dict:
    opts = {"model": model, "wind": "turbulence", "randomize": True, "observation": "sensors",
            "mission_time_s": 1.2}
    if env_id == "lvgym/StratosIII-v0":
        opts["controller_on_after_s"] = 0.1
    else:
        opts["controller_on_after_s"] = 0.2
    return opts


def _actions(env, n: int, seed: int) -> list:
    rng = np.random.default_rng(seed)
    space = env.action_space
    if isinstance(space, gym.spaces.Box):
        return [rng.uniform(-1.0, 1.0, space.shape).astype(np.float32) for _ in range(n)]
    return [rng.integers(0, 3, space.shape) for _ in range(n)]


def _same(a, b, where: str) -> None:
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            _same(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, (list, tuple)) and a and isinstance(a[0], (list, tuple, dict, np.ndarray)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{i}]")
    else:
        x, y = np.asarray(a), np.asarray(b)
        assert x.shape == y.shape and x.dtype == y.dtype, where
        if x.dtype.kind in "fc":
            assert np.array_equal(x, y, equal_nan=True), where
        else:
            assert np.array_equal(x, y), where


def _fly_single(env, actions) -> list:
    out = []
    for a in actions:
        obs, r, term, trunc, info = env.step(a)
        out.append((obs, r, term, trunc, {k: info[k] for k in INFO_KEYS}))
        if term or trunc:
            obs, info = env.reset()
            out.append((obs, dict(info)))
    return out


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_single_env_snapshot_replays_bit_for_bit(env_id, model):
    env = gym.make(env_id, **_options(env_id, model))
    env.reset(seed=21)
    acts = _actions(env, 100, 3)
    _fly_single(env, acts[:25])
    snap = env.unwrapped.get_state()
    assert isinstance(snap, EpisodeState) and snap.n == 1
    restored = pickle.loads(pickle.dumps(snap))
    first = _fly_single(env, acts[25:])               # 75 steps of 20 ms: through a truncation and a reset
    assert any(len(r) == 2 for r in first), "the replayed part should cross the end of an episode"
    env.unwrapped.set_state(restored)
    second = _fly_single(env, acts[25:])
    _same(first, second, f"{env_id} {model}")
    env.unwrapped.set_state(restored)                 # a snapshot restores more than once
    _same(first, _fly_single(env, acts[25:]), f"{env_id} {model} (again)")


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_env_snapshot_replays_bit_for_bit(env_id, model):
    env = gym.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point", **_options(env_id, model))
    env.reset(seed=40)
    rng = np.random.default_rng(8)
    space = env.action_space
    acts = [rng.uniform(-1.0, 1.0, space.shape).astype(np.float32) if env.single_action_space.dtype.kind == "f"
            else rng.integers(0, 3, space.shape) for _ in range(90)]

    def fly(actions):
        out = []
        for a in actions:
            obs, r, term, trunc, info = env.step(a)
            out.append((obs, r, term, trunc, {k: info[k] for k in INFO_KEYS}))
        return out

    fly(acts[:30])
    snap = pickle.loads(pickle.dumps(env.unwrapped.get_state()))
    first = fly(acts[30:])
    assert any(r[2].any() or r[3].any() for r in first), "the replayed part should cross an autoreset"
    env.unwrapped.set_state(snap)
    _same(first, fly(acts[30:]), f"{env_id} {model} vector")


def test_a_vector_row_restores_into_a_single_env():
    opts = _options("lvgym/SmileAscent-v0", "nonrigid")
    venv = gym.make_vec("lvgym/SmileAscent-v0", num_envs=2, vectorization_mode="vector_entry_point", **opts)
    venv.reset(seed=3)
    rng = np.random.default_rng(1)
    for _ in range(20):
        venv.step(rng.uniform(-1, 1, (2, 2)).astype(np.float32))
    snap = venv.unwrapped.get_state()
    single = gym.make("lvgym/SmileAscent-v0", **opts)
    single.reset(seed=0)
    single.unwrapped.set_state(snap.row(1))
    for _ in range(30):
        a = rng.uniform(-1, 1, (2, 2)).astype(np.float32)
        vobs, vrew, vterm, vtrunc, _ = venv.step(a)
        obs, r, term, trunc, _ = single.step(a[1])
        np.testing.assert_array_equal(vobs[1], obs)
        assert (vrew[1], vterm[1], vtrunc[1]) == (r, term, trunc)
        if term or trunc:
            break


def test_slender_variant_is_part_of_the_state():
    env = gym.make("lvgym/SlenderAscent-v0", model="flex", diameter=(0.25, 0.35), mission_time_s=0.5)
    seen = set()
    for seed in range(12):
        env.reset(seed=seed)
        seen.add(env.unwrapped.variant)
        if len(seen) > 1:
            break
    assert len(seen) > 1
    snap = env.unwrapped.get_state()
    variant = env.unwrapped.variant
    a = np.zeros(2, np.float32)
    first = [env.step(a)[0] for _ in range(5)]
    env.reset(seed=100 + seed)
    env.unwrapped.set_state(snap)
    assert env.unwrapped.variant == variant
    np.testing.assert_array_equal(first, [env.step(a)[0] for _ in range(5)])


def test_a_state_of_another_task_is_refused():
    a = gym.make("lvgym/SmileAscent-v0", model="rigid")
    b = gym.make("lvgym/SmileAscent-v0", model="nonrigid")
    a.reset(seed=0)
    b.reset(seed=0)
    with pytest.raises(ValueError, match=r"another task: options \['model'\]"):
        b.unwrapped.set_state(a.unwrapped.get_state())
    fresh = gym.make("lvgym/SmileAscent-v0", model="rigid")
    with pytest.raises(RuntimeError, match="reset"):
        fresh.unwrapped.get_state()
