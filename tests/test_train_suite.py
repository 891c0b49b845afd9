"""``train.py --suite``: a run trains on a benchmark suite's condition (its env id, wind, dispersions and
options, e.g. smile-v2-faults' in-flight faults) and is validated on the suite, on a v2 suite by v2's
selection (failed or unflyable, then ``score_v2``). Runs are tiny (as in test_agents.py)."""

from __future__ import annotations

import json
import re

import pytest

from lvgym.agents.callbacks import SELECTION_V2
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
    (("--suite", "family-v2"), r"--suite = 'family-v2': a suite of one vehicle"),
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
