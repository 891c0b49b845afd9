"""The Gymnasium envs: checkers, seeding, reward terms, vector env against single envs, robustness."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env

import lvgym  # noqa: F401  (registers the envs)
from lvgym.envs import OBS_STATE, REWARD_TERMS, TaskSpec
from lvgym.errors import ConfigError

ENV_IDS = ("lvgym/SmileAscent-v0", "lvgym/SmileAscent-v1", "lvgym/StratosIII-v0", "lvgym/StratosIII-v1",
           "lvgym/SlenderAscent-v0", "lvgym/SlenderAscent-v1")
MODELS = ("rigid", "slosh", "flex", "nonrigid")


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("model", MODELS)
def test_gymnasium_and_sb3_checkers(env_id, model):
    from stable_baselines3.common.env_checker import check_env as sb3_check_env
    env = gym.make(env_id, model=model).unwrapped
    gym_check_env(env, skip_render_check=True)
    sb3_check_env(env, warn=False)
    env.close()


def _rollout(env_id, seed, n, **options):
    env = gym.make(env_id, **options)
    obs, _ = env.reset(seed=seed)
    env.action_space.seed(seed)
    out = [obs]
    for _ in range(n):
        obs, reward, term, trunc, info = env.step(env.action_space.sample())
        out.append(np.append(obs, reward))
        if term or trunc:
            break
    return np.concatenate(out)


def test_same_seed_same_rollout_with_every_randomisation():
    kw = dict(wind="random", randomize=True, observation="sensors")
    a = _rollout("lvgym/SmileAscent-v0", 7, 100, **kw)
    b = _rollout("lvgym/SmileAscent-v0", 7, 100, **kw)
    c = _rollout("lvgym/SmileAscent-v0", 8, 100, **kw)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_reward_terms_add_up_and_sum_to_the_cumulative_error():
    env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", wind="gust", effort_weight=0.0,
                   effort_rate_weight=0.0)
    env.reset(seed=0)
    total = 0.0
    while True:
        _, reward, term, trunc, info = env.step(np.array([0.3, -0.2], dtype=np.float32))
        assert set(info["reward_terms"]) == set(REWARD_TERMS)
        assert reward == pytest.approx(sum(info["reward_terms"].values()), abs=1e-15)
        total += reward
        if term or trunc:
            break
    if not term:
        assert total == pytest.approx(-(info["cumulative_rate_error"][1] + info["cumulative_rate_error"][2]), rel=1e-12)


def test_truncation_only_at_the_mission_end():
    env = gym.make("lvgym/SlenderAscent-v0", model="rigid", mission_time_s=1.0)
    env.reset(seed=0)
    steps = 0
    while True:
        _, _, term, trunc, info = env.step(np.zeros(2, dtype=np.float32))
        steps += 1
        if term or trunc:
            break
    assert trunc and not term and steps == 50 and info["time"] == pytest.approx(1.0)


def test_controller_is_off_during_the_staging_coast():
    env = gym.make("lvgym/SmileAscent-v0", model="rigid").unwrapped
    env.reset(seed=0)
    ons = {}
    while env.flight.t[0] < 45.5:
        _, _, term, trunc, info = env.step(np.zeros(2, dtype=np.float32))
        ons[round(info["time"], 2)] = info["controller_on"]
        assert not term
    assert not ons[1.0] and ons[3.0] and not ons[44.0] and ons[45.5]


def test_vector_env_matches_single_envs_step_for_step():
    n, seed = 3, 11
    options = dict(model="nonrigid", wind="turbulence", randomize=True, observation="sensors")
    venv = gym.make_vec("lvgym/SmileAscent-v0", num_envs=n, vectorization_mode="vector_entry_point", **options)
    singles = [gym.make("lvgym/SmileAscent-v0", **options) for _ in range(n)]
    vobs, _ = venv.reset(seed=seed)
    sobs = [e.reset(seed=seed + i)[0] for i, e in enumerate(singles)]
    np.testing.assert_array_equal(vobs, np.stack(sobs))
    rng = np.random.default_rng(0)
    for _ in range(40):
        actions = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        vobs, vrew, vterm, vtrunc, _ = venv.step(actions)
        for i, e in enumerate(singles):
            o, r, term, trunc, _ = e.step(actions[i])
            np.testing.assert_array_equal(vobs[i], o)
            assert vrew[i] == r and vterm[i] == term and vtrunc[i] == trunc


def test_sb3_vec_env_runs_the_same_batch():
    from stable_baselines3.common.vec_env import VecEnv
    from lvgym.envs import make_sb3_vec_env
    venv = make_sb3_vec_env("lvgym/SmileAscent-v0", num_envs=2, seed=5, model="rigid", mission_time_s=0.1)
    assert isinstance(venv, VecEnv)
    obs = venv.reset()
    single = gym.make("lvgym/SmileAscent-v0", model="rigid", mission_time_s=0.1)
    np.testing.assert_array_equal(obs[1], single.reset(seed=6)[0])
    for k in range(5):
        obs, reward, done, infos = venv.step(np.zeros((2, 2), dtype=np.float32))
    assert done.all() and "terminal_observation" in infos[0] and infos[0]["TimeLimit.truncated"]


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("model", MODELS)
def test_ten_thousand_random_steps_stay_finite(env_id, model):
    venv = gym.make_vec(env_id, num_envs=50, vectorization_mode="vector_entry_point", model=model,
                        wind="random", randomize=True, observation="sensors")
    venv.reset(seed=0)
    venv.action_space.seed(0)
    for _ in range(200):
        obs, reward, term, trunc, info = venv.step(venv.action_space.sample())
        assert np.all(np.isfinite(obs)) and np.all(np.isfinite(reward))
        for reason in info["termination"][term]:
            assert reason in ("non-finite state", "q-alpha beyond the structural limit",
                              "attitude error beyond the limit")


def test_bad_options_name_the_key():
    with pytest.raises(ConfigError, match="wind"):
        gym.make("lvgym/SmileAscent-v0", wind="hurricane")
    with pytest.raises(ConfigError, match="randomize"):
        gym.make("lvgym/SmileAscent-v0", randomize=["mass", "gravity"])
    with pytest.raises(ConfigError, match="control_dt_s"):
        gym.make("lvgym/SmileAscent-v0", control_dt_s=0.015)
    with pytest.raises(ConfigError, match="unknown option"):
        TaskSpec.build({"vehicle": "smile"}, {"modle": "rigid"})


def test_observation_names_match_the_space():
    env = gym.make("lvgym/StratosIII-v0")
    assert env.observation_space.shape == (OBS_STATE.size,)
    assert env.action_space == gym.spaces.MultiDiscrete([3])
    assert gym.make("lvgym/StratosIII-v0", control="tvc").action_space.shape == (2,)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_rgb_array_render_through_the_env(env_id):
    env = gym.make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(120):
        env.step(env.action_space.sample())
    img = env.render()
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3 and len(np.unique(img)) > 10
    env.close()


def _fly_zero(env) -> dict:
    env.reset(seed=10000)
    while True:
        _, _, term, trunc, info = env.step(np.zeros(2, dtype=np.float32))
        if term or trunc:
            return info


def test_slender_aerodynamics_frozen_at_mach_2_by_default():
    """SlenderAscent-v0 holds the thesis's constant coefficients (its tables frozen at Mach 2): with the
    gimbal at zero in turbulence the vehicle flies the 10 s; with the full Mach tables (``aero_mach=None``)
    its fins lose lift above Mach 3 and q-alpha passes the limit before 7.5 s (docs/vehicles.md)."""
    env = gym.make("lvgym/SlenderAscent-v0", model="rigid", wind="turbulence", randomize=["wind"])
    assert env.unwrapped.sim.vehicle.aerodynamics["mach"] == [2.0]
    info = _fly_zero(env)
    assert info["termination"] == "" and info["time"] == pytest.approx(10.0)
    assert info["mach"] > 5.0                                  # 5.96: the task's fast, high-q part is flown
    full = gym.make("lvgym/SlenderAscent-v0", model="rigid", wind="turbulence", randomize=["wind"], aero_mach=None)
    assert "mach" not in full.unwrapped.sim.vehicle.aerodynamics
    info = _fly_zero(full)
    assert info["termination"] == "q-alpha beyond the structural limit" and info["time"] < 7.5
    with pytest.raises(ConfigError, match="aero_mach"):
        gym.make("lvgym/SlenderAscent-v0", aero_mach=40.0)


def test_an_unknown_keyword_is_one_short_line_with_the_closest_option():
    with pytest.raises(ConfigError) as err:
        gym.make("lvgym/SmileAscent-v1", wnd="turbulence")
    assert str(err.value) == ("wnd = 'turbulence': unknown option (did you mean 'wind'?); the env options: "
                              "help(lvgym.envs.TaskSpec)")
    with pytest.raises(ConfigError, match=r"^lenght = 9: unknown option \(did you mean 'length'\?\)"):  # the class's own
        gym.make("lvgym/SlenderAscent-v1", lenght=9)
    with pytest.raises(ConfigError, match=r"^lenght = 9: unknown option \(did you mean 'length'\?\)"):
        gym.make_vec("lvgym/SlenderAscent-v0", num_envs=2, vectorization_mode="vector_entry_point", lenght=9)
    with pytest.raises(ConfigError, match=r"^zzz = 1: unknown option; the env options"):          # nothing close
        gym.make("lvgym/StratosIII-v1", zzz=1)


def test_an_unknown_reset_option_names_the_key_and_the_keys_allowed():
    from lvgym.envs import make_sb3_vec_env

    allowed = r"unknown reset option \(allowed keys: none\)"
    env = gym.make("lvgym/SmileAscent-v1", mission_time_s=0.1)
    env.reset(seed=0, options={})                                       # empty or None: fine
    with pytest.raises(ConfigError, match=rf"^reset\(options\)\['wind'\] = 'gust': {allowed}; 'wind' is an env "
                                          r"keyword \(gymnasium\.make\(env_id, wind=\.\.\.\)\)"):
        env.reset(seed=0, options={"wind": "gust"})
    venv = gym.make_vec("lvgym/SmileAscent-v1", num_envs=2, vectorization_mode="vector_entry_point", mission_time_s=0.1)
    with pytest.raises(ConfigError, match=rf"^reset\(options\)\['sede'\] = 3: {allowed}; the env options"):
        venv.reset(seed=0, options={"sede": 3})
    sb3 = make_sb3_vec_env("lvgym/SmileAscent-v1", num_envs=2, seed=0, mission_time_s=0.1)
    sb3.set_options({"reward": 1})
    with pytest.raises(ConfigError, match=rf"^reset\(options\)\['reward'\] = 1: {allowed}"):
        sb3.reset()
    sb3.set_options(None)
    assert sb3.reset().shape == (2, 14)


def test_one_table_of_ids_and_one_vector_entry_point():
    import functools

    from lvgym.envs import ENVS, SlenderAscentEnv, SlenderAscentV1Env
    from lvgym.envs.vector import batch_task

    assert list(ENVS) == list(lvgym.ENV_IDS) and set(ENVS) == set(ENV_IDS)
    for env_id, cls in ENVS.items():
        spec = gym.spec(env_id)
        assert spec.entry_point == lvgym.ENV_IDS[env_id] and lvgym.env_class(env_id) is cls
        assert isinstance(spec.vector_entry_point, functools.partial)
        assert spec.vector_entry_point.func is lvgym.make_vector and spec.vector_entry_point.args == (env_id,)
    # the slender geometry's defaults are the presets' values, read by the single and the batched env alike
    from lvgym.vehicle.slender import SlenderGeometry
    for cls, key in ((SlenderAscentEnv, SlenderGeometry(8.5, 0.3, 2.0, 0.002)),
                     (SlenderAscentV1Env, SlenderGeometry(8.5, 0.2833, 2.0, 0.0045))):
        assert batch_task(cls, {}).vehicle == key == cls().task.vehicle == cls.PRESET.vehicle
    assert batch_task(SlenderAscentV1Env, {"wall_thickness_m": 0.002, "aero_mach": None}).vehicle == \
        SlenderGeometry(8.5, 0.2833, None, 0.002)
    with pytest.raises(ConfigError, match=r"^env_id = 'lvgym/SmileAscent-v2': one of .* \(did you mean "
                                          r"'lvgym/SmileAscent-v1'\?\)$"):
        lvgym.env_class("lvgym/SmileAscent-v2")
