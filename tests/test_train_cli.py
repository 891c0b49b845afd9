"""train.py as a new user meets it (issue 19): a mistyped option is one line and leaves no run folder,
checkpoints by wall time, a checkpoint on SIGTERM and SIGINT, and ``--resume`` says what it resumed from.
Runs are tiny (as in test_agents.py): a few hundred env steps of 2 s episodes with 8-unit networks."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from lvgym.agents.policies.checkpoints import latest_checkpoint, list_checkpoints

from test_agents import ROOT, TRAIN, _argv


def _train_process(argv: list[str], log: Path) -> subprocess.Popen:
    with open(log, "wb") as out:
        return subprocess.Popen([sys.executable, str(ROOT / "train.py"), *argv], cwd=ROOT, stdout=out,
                                stderr=subprocess.STDOUT, start_new_session=True)


def _wait(cond, proc: subprocess.Popen, log: Path, what: str, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            proc.wait()
            raise AssertionError(f"{what} did not happen (exit {proc.returncode}):\n{log.read_text()[-3000:]}")
        time.sleep(0.05)


@pytest.mark.parametrize("extra, message", [
    (["--model", "flexible"], r"argument --model: invalid choice: 'flexible' \(choose from 'rigid', 'slosh'"),
    (["--hp", "algo.gama=0.99"], r"algo\.gama = 0\.99: unknown key; allowed: \[.*\]; did you mean 'gamma'\?"),
    (["--total-timesteps", "-5"], r"--total-timesteps = -5: an integer in \[1, "),
    (["--checkpoint-freq", "0"], r"--checkpoint-freq = 0: an integer in \[1, "),
    (["--checkpoint-interval-s", "-1"], r"--checkpoint-interval-s = -1\.0: a number in \[0\.0, "),
    (["--env-kwargs", "mission_time_s=-3"], r"lvgym/SmileAscent-v0 option mission_time_s = -3: a number in \(0\.0, "),
    (["--env-kwargs", "mision_time_s=3"], r"mision_time_s = 3: unknown option"),
    (["--hp", "policy.net_arch=[8,"], r"--hp = 'policy\.net_arch=\[8,': KEY=VALUE with a YAML value"),
    (["--randomize", "winds"], r"--randomize = 'winds': names of \["),
    (["--eval-suite", "nope"], r"--eval-suite = 'nope': one of \["),
    (["--seed", "100000"], r"--seed = 100000: an integer in \[0, 99999\]"),
    (["--recipe", "plain", "--residual", "lqg"], r"--residual = 'lqg': none with --recipe plain"),
])
def test_a_bad_option_is_one_line_and_leaves_no_run_folder(tmp_path, capsys, extra, message):
    with pytest.raises(SystemExit) as exit_:
        TRAIN.train([*_argv(tmp_path, "typo", steps=128), *extra])
    text = exit_.value.code if isinstance(exit_.value.code, str) else capsys.readouterr().err
    assert text.startswith("train.py: ") and len(text.strip().splitlines()) == 1, text
    import re

    assert re.search(message, text), text
    assert not list(tmp_path.iterdir()), "a refused command left files behind"


def test_the_corrected_command_runs_after_a_typo(tmp_path):
    with pytest.raises(SystemExit):
        TRAIN.train([*_argv(tmp_path, "fixed", steps=128, extra=("--eval-freq", "0")), "--model", "flexible"])
    run = TRAIN.train(_argv(tmp_path, "fixed", steps=128, extra=("--eval-freq", "0", "--model", "rigid")))
    assert (run / "final_model.json").is_file()


def test_resume_says_there_was_nothing_to_resume_from(tmp_path, capsys):
    args, given = TRAIN.parse_args(_argv(tmp_path, "early", steps=128, extra=("--eval-freq", "0")))
    _, config, run_dir, _ = TRAIN.prepare(args, given)
    TRAIN.create_run(config, run_dir)                  # a run killed before its first checkpoint
    TRAIN.train(["--resume", str(run_dir), "--no-progress"])
    err = capsys.readouterr().err
    assert f"{run_dir} has no complete checkpoint to resume from" in err and "starts again at step 0" in err
    assert latest_checkpoint(run_dir / "checkpoints")[1]["num_timesteps"] >= 128


def test_a_kill_loses_at_most_the_wall_time_interval(tmp_path, capsys):
    argv = _argv(tmp_path, "timed", steps=10**7, extra=("--eval-freq", "0", "--checkpoint-freq", "1000000000",
                                                        "--checkpoint-interval-s", "0.5"))
    log = tmp_path / "train.log"
    proc = _train_process(argv, log)
    folder = tmp_path / "timed" / "checkpoints"
    try:
        _wait(lambda: len(list_checkpoints(folder)) >= 2, proc, log, "two wall-time checkpoints")
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    (first, _), (last, _) = list_checkpoints(folder)[0], list_checkpoints(folder)[-1]
    assert 0 < first < last < 10**9                        # not the step schedule: wall time
    state = json.loads((folder / f"step_{last:012d}.json").read_text())
    assert state["train_wall_s"] > 0
    TRAIN.train(["--resume", str(tmp_path / "timed"), "--total-timesteps", str(last + 128), "--no-progress"])
    err = capsys.readouterr().err
    assert f"resuming {tmp_path / 'timed'} from checkpoint step_{last:012d}: step {last:,} of {last + 128:,}" in err
    segments = [json.loads(x) for x in (tmp_path / "timed" / "segments.jsonl").read_text().splitlines()]
    assert segments[-1]["start_step"] == last


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_writes_a_checkpoint_before_the_run_exits(tmp_path, signum):
    argv = _argv(tmp_path, "sig", steps=10**7, extra=("--eval-freq", "0", "--checkpoint-freq", "1000000000",
                                                      "--checkpoint-interval-s", "0"))
    log = tmp_path / "train.log"
    proc = _train_process(argv, log)
    progress = tmp_path / "sig" / "progress_000000000000.csv"
    try:                                                   # an update logged: training is under way
        _wait(lambda: progress.is_file() and len(progress.read_text().splitlines()) >= 3, proc, log, "training")
        assert not list_checkpoints(tmp_path / "sig" / "checkpoints")
        os.kill(proc.pid, signum)
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 128 + signum, log.read_text()[-2000:]
    text = log.read_text()
    assert f"stopped by {signal.Signals(signum).name} at step" in text and "--resume" in text
    (step, _), = list_checkpoints(tmp_path / "sig" / "checkpoints")
    assert step >= 2 * 4 * 32                              # at least the two logged rollouts of 4 x 32 steps
    assert not (tmp_path / "sig" / "final_model.json").exists()    # the run is not finished


def test_the_default_observation_and_randomisation_are_the_env_protocols():
    from lvgym.benchmark.suites import V1_DISPERSIONS

    v0 = TRAIN.env_kwargs_of(TRAIN.Args(env_id="lvgym/SmileAscent-v0"))
    assert v0["randomize"] == ["wind", "thrust_misalignment"] and "observation" not in v0   # v0's own: state
    assert v0["wind"] == "turbulence"
    v1 = TRAIN.env_kwargs_of(TRAIN.Args(env_id="lvgym/SmileAscent-v1"))
    assert sorted(v1["randomize"]) == sorted(V1_DISPERSIONS) and "observation" not in v1     # v1's own: flight
    assert v1["wind"] == "turbulence_gust"                                                  # smile-v1's wind
    assert TRAIN.env_kwargs_of(TRAIN.Args(env_id="lvgym/SlenderAscent-v1"))["wind"] == "turbulence"
    import lvgym.envs as envs

    assert envs.ENVS["lvgym/SmileAscent-v0"].PRESET.observation == "state"
    assert envs.ENVS["lvgym/SmileAscent-v1"].PRESET.observation == "flight"
    assert TRAIN.env_kwargs_of(TRAIN.Args(observation="state", randomize=["mass"], wind="turbulence")) == {
        "model": "nonrigid", "wind": "turbulence", "randomize": ["mass"], "observation": "state"}


def test_protocol_randomisation_is_alone(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        TRAIN.train([*_argv(tmp_path, "mixed", steps=128), "--randomize", "protocol", "mass"])
    text = exit_.value.code if isinstance(exit_.value.code, str) else capsys.readouterr().err
    assert "--randomize = 'protocol mass': 'protocol' alone" in text and not list(tmp_path.iterdir())


def test_repeated_list_options_add_up_and_randomize_replaces_its_default():
    """``--hp a=1 --hp b=2`` keeps both overrides (argparse's default would keep the last only), as does a
    repeated ``--env-kwargs``; ``--randomize`` replaces its default ``protocol``."""
    args, _ = TRAIN.parse_args(["--hp", "algo.n_steps=128", "--hp", "algo.n_epochs=2", "policy.net_arch=[8]",
                                "--env-kwargs", "mission_time_s=20", "--env-kwargs", "n_modes=1",
                                "--randomize", "wind"])
    assert args.hp == ["algo.n_steps=128", "algo.n_epochs=2", "policy.net_arch=[8]"]
    assert args.env_kwargs == ["mission_time_s=20", "n_modes=1"]
    assert args.randomize == ["wind"]
    assert TRAIN.parse_args([])[0].hp == [] and TRAIN.parse_args([])[0].randomize == ["protocol"]


def test_the_default_run_is_the_v1_recipe_and_given_options_win(tmp_path):
    """``python train.py`` trains SmileAscent-v1 with its recipe (train.RECIPES: residual on lqg at 5 %,
    a 4-sample history, turbulence without the gust), recorded in the run's config; an option on the
    command line wins over the recipe; a v0 id has none. Nothing is written by prepare()."""
    base = ["--runs-dir", str(tmp_path), "--name", "r"]
    args, config, _, _ = TRAIN.prepare(*TRAIN.parse_args(base))
    assert args.env_id == "lvgym/SmileAscent-v1"
    assert config["residual"] == {"baseline": "lqg", "scale": 0.05}
    assert config["env_kwargs"]["history"] == 4 and config["env_kwargs"]["wind"] == "turbulence"
    assert config["args"]["residual"] == "lqg" and config["args"]["history"] == 4
    args, config, _, _ = TRAIN.prepare(*TRAIN.parse_args(base + ["--residual", "none", "--history", "0",
                                                                 "--wind", "protocol"]))
    assert "residual" not in config and "history" not in config["env_kwargs"]
    assert config["env_kwargs"]["wind"] == "turbulence_gust"
    args, config, _, _ = TRAIN.prepare(*TRAIN.parse_args(base + ["--env-id", "lvgym/SmileAscent-v0"]))
    assert args.residual is None and "history" not in config["env_kwargs"]
    assert not (tmp_path / "r").exists()


def test_the_presets_plain_and_residual(tmp_path):
    """``--recipe plain``: from scratch on the protocol's wind, no residual, no history (an option given still
    wins); ``--recipe residual`` is the default, the env id's RECIPES; on an id without a recipe it trains plain.
    A run folder of the days before the presets (recipe ``sb3``) resumes as ``residual``."""
    base = ["--runs-dir", str(tmp_path), "--name", "r"]
    args, config, _, _ = TRAIN.prepare(*TRAIN.parse_args(base + ["--recipe", "plain"]))
    assert args.recipe == "plain" and args.residual is None and "residual" not in config
    assert "history" not in config["env_kwargs"] and config["env_kwargs"]["wind"] == "turbulence_gust"
    assert config["args"]["recipe"] == "plain"
    args, config, _, _ = TRAIN.prepare(*TRAIN.parse_args(base + ["--recipe", "plain", "--history", "2"]))
    assert config["env_kwargs"]["history"] == 2 and "residual" not in config
    args, config, _, _ = TRAIN.prepare(*TRAIN.parse_args(base + ["--recipe", "plain", "--residual", "none"]))
    assert args.residual in (None, "none") and "residual" not in config
    given = TRAIN.prepare(*TRAIN.parse_args(base + ["--recipe", "residual"]))[1]
    default = TRAIN.prepare(*TRAIN.parse_args(base))[1]
    assert given["residual"] == default["residual"] == {"baseline": "lqg", "scale": 0.05}
    assert given["env_kwargs"] == default["env_kwargs"] and default["args"]["recipe"] == "residual"
    v0 = TRAIN.prepare(*TRAIN.parse_args(base + ["--recipe", "residual", "--env-id", "lvgym/SmileAscent-v0"]))[1]
    plain = TRAIN.prepare(*TRAIN.parse_args(base + ["--recipe", "plain", "--env-id", "lvgym/SmileAscent-v0"]))[1]
    assert v0["env_kwargs"] == plain["env_kwargs"] and "residual" not in v0
    assert not (tmp_path / "r").exists()


def test_the_help_shows_the_true_defaults(capsys):
    """``--help`` gives each option's default as the default run flies it: the recipe's (RECIPES) for the default
    env id, no longer "(default: not residual)" and "(default: 0)" where the recipe sets lqg and 4."""
    with pytest.raises(SystemExit):
        TRAIN.parse_args(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    recipe = TRAIN.RECIPES[TRAIN.Args().env_id]
    assert TRAIN.Args().env_id == "lvgym/SmileAscent-v1" and TRAIN.Args().recipe == "residual"
    assert "--recipe {plain,residual,teacher-student}" in text and "preset's (default: residual)" in text
    assert "not residual" not in text
    for option, value, otherwise in (("--residual", recipe["residual"], "none"),
                                     ("--residual-scale", recipe["residual_scale"], "0.2"),
                                     ("--history", recipe["history"], "0"),
                                     ("--wind", recipe["wind"], "protocol")):
        tail = "" if option != "--wind" else " without --suite"
        shown = (f"(default: the --recipe's: {value:g}" if isinstance(value, float) else
                 f"default: the --recipe's: {value}")
        assert f"{shown} for residual on lvgym/SmileAscent-v1{tail}, else {otherwise})" in text, option
    args, config, _, _ = TRAIN.prepare(*TRAIN.parse_args(["--name", "r"]))
    assert (config["residual"]["baseline"], config["residual"]["scale"], config["env_kwargs"]["history"],
            config["env_kwargs"]["wind"]) == (recipe["residual"], recipe["residual_scale"], recipe["history"],
                                              recipe["wind"])


def test_a_spent_wall_time_budget_ends_the_run_validated_with_its_models(tmp_path, capsys):
    """``--max-wall-time``: the run stops at the next env step once the budget (counted from the start of the
    command) is spent and ends as a finished run does: a checkpoint of that step, validated, ``final_model``,
    ``best_model`` and ``evaluations.json``, which the curves tool reads; it says so and returns (no exit status);
    --resume continues it to its target."""
    from lvgym.agents.training import curves

    argv = _argv(tmp_path, "budget", steps=10**7, extra=("--checkpoint-freq", "1000000000", "--eval-freq", "1000000000",
                                                         "--checkpoint-interval-s", "0", "--max-wall-time", "2"))
    run = TRAIN.train(argv)
    err = capsys.readouterr().err
    (step, stem), = list_checkpoints(run / "checkpoints")
    assert 0 < step < 10**7
    assert "train.py: the wall-time budget of 2 s is spent: stopped at step" in err, err
    assert f"checkpoint step_{step:012d}, validated, final_model, best_model written" in err, err
    assert f"continue with python train.py --resume {run}" in err
    evaluations = json.loads((run / "evaluations.json").read_text())
    assert [e["num_timesteps"] for e in evaluations] == [step] and evaluations[0]["seed_set"] == "validation"
    for name in ("final_model", "best_model"):
        assert json.loads((run / f"{name}.json").read_text())["num_timesteps"] == step
        assert (run / f"{name}.zip").read_bytes() == stem.with_suffix(".zip").read_bytes()
    rows = curves.load_curves(run)
    assert {r["num_timesteps"] for r in rows} == {step} and {r["condition"] for r in rows} == {"rigid", "nonrigid"}
    from lvgym.agents.policies.saved import describe_saved

    assert describe_saved(run) == f"{run / 'best_model.zip'}: its best model by validation (step {step:,})"
    TRAIN.train(["--resume", str(run), "--total-timesteps", str(step + 128), "--max-wall-time", "600", "--no-progress"])
    assert json.loads((run / "final_model.json").read_text())["num_timesteps"] >= step + 128


def test_the_progress_line_gives_steps_speed_time_and_the_validation_score(tmp_path, capsys):
    """``--progress-interval-s``: a line on stdout at the end of a rollout once the interval has passed (here
    at every rollout: 3 rollouts of 4 x 32 steps) and one at the end, with the latest validation score."""
    run = TRAIN.train(_argv(tmp_path, "lines", steps=384, extra=("--progress-interval-s", "1e-9")))
    lines = [x for x in capsys.readouterr().out.splitlines() if x.startswith("train.py: step ")]
    assert 2 <= len(lines) <= 4, lines
    import re

    for line in lines:
        assert re.fullmatch(r"train\.py: step [\d,]+ / 384 \([\d.]+ %\), [\d,]+ steps/s, elapsed \d+:\d\d:\d\d.*", line)
    assert lines[-1].startswith("train.py: step 384 / 384 (100.0 %)") and "left" not in lines[-1]
    assert re.search(r"; validation at step 384: score [-\d.e+]+, failure rate \d+ %$", lines[-1]), lines[-1]
    assert "validation" not in lines[0]                       # none before the first validation (step 256)
    assert (run / "final_model.json").is_file()
    quiet = TRAIN.train(_argv(tmp_path, "quiet", steps=128, extra=("--eval-freq", "0", "--progress-interval-s", "0")))
    assert "train.py: step" not in capsys.readouterr().out and (quiet / "final_model.json").is_file()


def test_the_progress_line_on_a_v2_suite_gives_what_selection_ranks_on():
    """On protocol v2 the line gives score_v2 and the failed-or-unflyable share (an unflyable flight is charged
    like a failed one), not v1's failure rate, which would hide a policy that chatters."""
    from types import SimpleNamespace

    from lvgym.agents.training.progress import ProgressLineCallback

    last = {"num_timesteps": 2_048_000, "score": [0.81, 1.739], "episode_score": 0.236, "failure_rate": 0.0,
            "score_v2": 1.739, "failure_rate_v2": 0.81}
    cb = ProgressLineCallback(60.0, 3_000_000, SimpleNamespace(evaluations=[last]))
    cb.model = SimpleNamespace(num_timesteps=2_500_000)
    assert cb.line().endswith("; validation at step 2,048,000: score_v2 1.739, failed or unflyable 81 %")
    del last["score_v2"], last["failure_rate_v2"]
    assert cb.line().endswith("; validation at step 2,048,000: score 0.236, failure rate 0 %")
