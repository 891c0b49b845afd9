"""``train.py --suite``: a run trains on a benchmark suite's condition (its env id, wind, dispersions and
options, e.g. smile-v2-faults' in-flight faults) and is validated on the suite, on a v2 suite by v2's
selection (failed or unflyable, then ``score_v2``). Runs are tiny (as in test_agents.py)."""

from __future__ import annotations

import json
import re

import pytest

from lvgym.agents.training.callbacks import SELECTION_V2
from lvgym.benchmark.suites import condition
from lvgym.vehicle.yamlfile import read_yaml

from test_agents import ENV_KW, TINY, TRAIN


def _suite_argv(tmp, name: str, suite: str, extra: tuple = ()) -> list[str]:
    return ["--suite", suite, "--name", name, "--runs-dir", str(tmp), "--total-timesteps", "128", "--n-envs", "4",
            "--hp", *TINY["ppo"], "--env-kwargs", *ENV_KW, "--checkpoint-freq", "128", "--eval-freq", "128",
            "--eval-episodes", "1", "--eval-mission-time-s", "0.5", "--no-progress", *extra]


def test_a_run_on_a_v2_suite_trains_on_its_condition_and_selects_by_v2(tmp_path):
    run = TRAIN.train(_suite_argv(tmp_path, "faults", "smile-v2-faults", extra=("--model", "rigid")))
    config = read_yaml(run / "config.yaml")[0]
    cond = condition("smile-v2-faults", "rigid")
    kw = config["env_kwargs"]
    assert config["env_id"] == cond.env_id and config["eval_suite"] == "smile-v2-faults"
    assert kw["wind"] == cond.wind == "turbulence_gust" and kw["randomize"] == list(cond.randomize)
    assert "fault" in kw["randomize"]
    for key, value in cond.options:                        # the suite's options, then --env-kwargs over them
        if key != "mission_time_s":
            assert kw[key] == (list(value) if isinstance(value, tuple) else value), key
    assert kw["mission_time_s"] == 2 and kw["model"] == "rigid"
    assert config["residual"]["baseline"] == "lqg" and kw["history"] == 4    # the id's recipe but its wind
    state = json.loads((run / "final_model.json").read_text())
    ev = state["evaluations"][-1]
    assert ev["selection"] == SELECTION_V2 and ev["version"] == "v2+override"
    assert ev["score"] == [ev["failure_rate_v2"], ev["score_v2"]]
    assert all("score_v2_mean" in c for c in ev["conditions"].values())


@pytest.mark.parametrize("extra, message", [
    (("--suite", "family-v2", "--family-vehicles", "5"), r"--family-vehicles = 5: 1 \.\. the run's rows \(--n-envs 4\)"),
    (("--suite", "smile-v3"), r"--suite = 'smile-v3': one of \["),
    (("--suite", "smile-v2", "--env-id", "lvgym/StratosIII-v1"),
     r"--env-id = 'lvgym/StratosIII-v1': 'lvgym/SmileAscent-v1' \(suite 'smile-v2' flies it\) or no --env-id"),
])
def test_a_bad_suite_is_one_line_and_leaves_no_run_folder(tmp_path, capsys, extra, message):
    argv = _suite_argv(tmp_path, "bad", "smile-v2")
    i = argv.index("--suite")
    del argv[i:i + 2]
    with pytest.raises(SystemExit) as exit_:
        TRAIN.train([*argv, *extra])
    text = exit_.value.code if isinstance(exit_.value.code, str) else capsys.readouterr().err
    assert text.startswith("train.py: ") and len(text.strip().splitlines()) == 1, text
    assert re.search(message, text), text
    assert not list(tmp_path.iterdir()), "a refused command left files behind"


def test_concat_vecenv_rows_are_its_parts_rows():
    """Two vehicles' batched VecEnvs joined: each row steps as in its own part, seeded from its first row."""
    import numpy as np

    from lvgym.agents.training.familytrain import ConcatVecEnv, concat_venv, row_split
    from lvgym.envs import make_sb3_vec_env

    kw = {"mission_time_s": 1.0, "wind": "turbulence", "randomize": ["wind", "mass"]}
    vehicles = ["smile", "family/validation_10000"]

    def part(vehicle, rows, first):
        return make_sb3_vec_env("lvgym/SmileAscent-v1", num_envs=rows, seed=first, vehicle=vehicle, **kw)

    assert row_split(5, 2) == [3, 2] and row_split(4, 4) == [1, 1, 1, 1]
    joined = concat_venv(part, vehicles, 5, seed=7)
    alone = [part("smile", 3, 7), part("family/validation_10000", 2, 10)]
    assert isinstance(joined, ConcatVecEnv) and joined.num_envs == 5
    obs = joined.reset()
    np.testing.assert_array_equal(obs, np.concatenate([a.reset() for a in alone]))
    assert len(joined.reset_infos) == 5
    rng = np.random.default_rng(0)
    for _ in range(30):                                  # past the end of an episode: autoreset on both sides
        act = rng.uniform(-0.3, 0.3, size=(5, 2)).astype(np.float32)
        o, r, d, infos = joined.step(act)
        parts = [alone[0].step(act[:3]), alone[1].step(act[3:])]
        np.testing.assert_array_equal(o, np.concatenate([p[0] for p in parts]))
        np.testing.assert_array_equal(r, np.concatenate([p[1] for p in parts]))
        np.testing.assert_array_equal(d, np.concatenate([p[2] for p in parts]))
        assert [i.get("time") for i in infos] == [i.get("time") for p in parts for i in p[3]]
    assert joined.seed(3) == [3, 4, 5, 6, 7]
    assert joined.get_attr("num_envs", [0, 4]) == [3, 2]


def test_a_family_run_flies_train_vehicles_and_selects_on_validation_vehicles(tmp_path, monkeypatch):
    from lvgym.agents.training.callbacks import ValidationEvaluator
    from lvgym.benchmark.suites import FAMILY_VALIDATION_VEHICLES, FAMILY_VEHICLES

    monkeypatch.setenv("LVGYM_CACHE_DIR", str(tmp_path / "cache"))
    argv = _suite_argv(tmp_path / "runs", "fam", "family-v2-informed",
                       extra=("--family-vehicles", "2", "--residual", "none", "--history", "0", "--eval-freq", "0"))
    run = TRAIN.train(argv)
    config = read_yaml(run / "config.yaml")[0]
    assert config["family_vehicles"] == 2 and len(config["vehicles"]) == 2
    assert all(v.startswith("train_") for v in config["vehicles"]), config["vehicles"]
    assert "vehicle" not in config["env_kwargs"] and config["env_kwargs"]["vehicle_info"] is True
    assert (tmp_path / "cache" / "family" / config["vehicles"][0]).is_file()
    ev = ValidationEvaluator("family-v2-informed", 1)
    flown = {dict(c.options)["vehicle"] for c in ev.suite.conditions}
    assert flown == set(FAMILY_VALIDATION_VEHICLES) and not flown & set(FAMILY_VEHICLES)
    assert ev.suite.name == "family-v2-informed@validation-vehicles"
