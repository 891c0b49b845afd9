"""The three faces of the batch core against each other, step for step, through autoresets.

Row ``i`` of the Gymnasium ``VectorEnv`` (``NEXT_STEP`` autoreset) and of the SB3 ``VecEnv`` (same-step
reset) seeded ``s + i``, and the single env seeded ``s + i`` (reset by hand when an episode ends), given
the same action at the same step of the same episode, fly the same episodes: every observation, reward,
termination, truncation and info entry is identical; the vector env's reset rows return the single env's
reset observation and info, and SB3's ``terminal_observation`` is the vector env's last observation of
the episode. Short missions (and a tight attitude limit) end the rows' episodes at different steps.
"""

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401  (registers the envs)
from lvgym.envs import make_sb3_vec_env
from lvgym.envs.core import RESET_INFO_KEYS, row_info

B, SEED, STEPS = 3, 40, 45
CASES = {
    "smile-v1": ("lvgym/SmileAscent-v1", {"model": "slosh", "wind": "turbulence", "mission_time_s": 0.4,
                                          "controller_on_after_s": 0.06, "attitude_limit_deg": 0.3,
                                          "randomize": ["wind", "sensor_noise", "thrust_misalignment", "mass"]}),
    "stratos-v0-rcs": ("lvgym/StratosIII-v0", {"model": "rigid", "mission_time_s": 0.25, "controller_on_after_s": 0.04,
                                               "observation": "sensors", "randomize": True}),
}


def _action(space, row: int, episode: int, k: int) -> np.ndarray:
    """The action of step ``k`` of episode ``episode`` of row ``row`` (the same in every face)."""
    rng = np.random.default_rng([row, episode, k])
    if isinstance(space, gym.spaces.Box):
        return rng.uniform(-1.0, 1.0, space.shape).astype(np.float32)
    return rng.integers(0, 3, space.shape)


def _fly_single(env_id, options) -> list[list[dict]]:
    """Per row, its episodes: the reset (obs, info) and the transitions (action, obs, reward, flags, info)."""
    rows = []
    for i in range(B):
        env = gym.make(env_id, **options)
        obs, info = env.reset(seed=SEED + i)
        episodes = [{"reset": (obs, info), "steps": []}]
        for _ in range(STEPS):
            ep = episodes[-1]
            a = _action(env.action_space, i, len(episodes) - 1, len(ep["steps"]))
            obs, r, term, trunc, info = env.step(a)
            ep["steps"].append((obs, r, term, trunc, info))
            if term or trunc:
                episodes.append({"reset": env.reset(), "steps": []})
        rows.append(episodes)
    return rows


def _fly_vector(env_id, options) -> list[list[dict]]:
    env = gym.make_vec(env_id, num_envs=B, vectorization_mode="vector_entry_point", **options)
    obs, info = env.reset(seed=SEED)
    rows = [[{"reset": (obs[i], row_info(info, i)), "steps": []}] for i in range(B)]
    ended = np.zeros(B, dtype=bool)
    space = env.single_action_space
    for _ in range(STEPS):
        acts = np.stack([_action(space, i, len(rows[i]) - 1, len(rows[i][-1]["steps"])) if not ended[i]
                         else _action(space, 99, 99, 99) for i in range(B)])        # an ended row's is ignored
        obs, r, term, trunc, info = env.step(acts)
        for i in range(B):
            if ended[i]:
                assert r[i] == 0.0 and not term[i] and not trunc[i]
                one = row_info(info, i)
                rows[i].append({"reset": (obs[i], {k: one[k] for k in RESET_INFO_KEYS}), "steps": [],
                                "reset_row_info": one})
            else:
                rows[i][-1]["steps"].append((obs[i], r[i], term[i], trunc[i], row_info(info, i)))
        ended = term | trunc
    return rows


def _fly_sb3(env_id, options) -> list[list[dict]]:
    env = make_sb3_vec_env(env_id, num_envs=B, seed=SEED, **options)
    obs = env.reset()
    rows = [[{"reset": (obs[i], env.reset_infos[i]), "steps": []}] for i in range(B)]
    space = env.action_space
    for _ in range(STEPS):
        acts = np.stack([_action(space, i, len(rows[i]) - 1, len(rows[i][-1]["steps"])) for i in range(B)])
        if acts.ndim == 2 and acts.shape[1] == 1 and not isinstance(space, gym.spaces.Box):
            acts = acts[:, 0]                             # SB3 hands MultiDiscrete([3]) actions as (B,)
        obs, r, done, infos = env.step(acts)
        for i in range(B):
            info = dict(infos[i])
            if done[i]:
                final = info.pop("terminal_observation")
                trunc = info.pop("TimeLimit.truncated")
                rows[i][-1]["steps"].append((final, r[i], not trunc, trunc, info))
                rows[i].append({"reset": (obs[i], env.reset_infos[i]), "steps": []})
            else:
                rows[i][-1]["steps"].append((obs[i], r[i], False, False, info))
    return rows


def _same(a, b, where: str) -> None:
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            _same(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for j, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{j}]")
    else:
        x, y = np.asarray(a), np.asarray(b)
        assert x.shape == y.shape, where
        assert np.array_equal(x, y, equal_nan=x.dtype.kind in "fc"), where


def _compare(ref, got, what: str, reward_dtype=np.float64) -> int:
    """Every episode both faces finished (and the one each is in, up to the shorter): returns the
    number of steps compared."""
    n = 0
    for i in range(B):
        for e, (ep, other) in enumerate(zip(ref[i], got[i])):
            where = f"{what} row {i} episode {e}"
            _same(ep["reset"][0], other["reset"][0], where + " reset obs")
            _same(ep["reset"][1], other["reset"][1], where + " reset info")
            for k, (s, t) in enumerate(zip(ep["steps"], other["steps"])):
                _same(s[0], t[0], f"{where} step {k} obs")
                assert reward_dtype(s[1]) == t[1], f"{where} step {k} reward"
                assert (bool(s[2]), bool(s[3])) == (bool(t[2]), bool(t[3])), f"{where} step {k} flags"
                _same(s[4], t[4], f"{where} step {k} info")
                n += 1
    return n


@pytest.mark.parametrize("case", CASES)
def test_single_vector_and_sb3_faces_fly_the_same_episodes(case):
    env_id, options = CASES[case]
    single, vector, sb3 = _fly_single(env_id, options), _fly_vector(env_id, options), _fly_sb3(env_id, options)
    # the rows' episodes end at different steps, each row resets at least once, some episodes terminate
    lengths = [[len(ep["steps"]) for ep in row[:-1]] for row in single]
    assert all(lengths), lengths
    ends = [ep["steps"][-1] for row in single for ep in row[:-1]]
    if case == "smile-v1":
        assert len({tuple(x) for x in lengths}) > 1 and any(s[2] for s in ends) and any(s[3] for s in ends), lengths
    n_vector = _compare(single, vector, "vector")
    n_sb3 = _compare(single, sb3, "sb3", np.float32)
    assert n_vector > 2 * STEPS and n_sb3 == B * STEPS
    # a reset row's info at the NEXT_STEP autoreset is its new episode's first state (a superset of the reset info)
    for row in vector:
        for ep in row[1:]:
            assert ep["reset_row_info"]["time"] == 0.0 and ep["reset_row_info"]["events"] == []
    # SB3's terminal observation is the vector env's last observation of the episode
    for i in range(B):
        for ep_v, ep_s in zip(vector[i][:-1], sb3[i][:-1]):
            _same(ep_v["steps"][-1][0], ep_s["steps"][-1][0], f"row {i} final observation")
