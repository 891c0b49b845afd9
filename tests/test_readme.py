"""The README's quick starts run: every python and sh block, in a temporary folder, shortened where a full
run would take minutes (:data:`SHORTEN`: options each command documents, such as ``--episodes 2
--mission-time-s 5``).
"""

from __future__ import annotations

import importlib.util
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest


ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"```(python|sh)\n(.*?)```", README, re.S)

#: the ``lvgym`` command and its subcommands

#: the set-up commands of the README (they install into .venv or run the whole benchmark: not run here)
SETUP = ("make ", "pip ")
#: README command -> the options appended to run it in seconds (each a documented option of the command)
SHORT_EVAL = "--episodes 2 --mission-time-s 5 --executor serial --no-plots --no-progress --out results"
SHORTEN = {
    "lvgym train --name my-ppo --total-timesteps 2e6":
        "--total-timesteps 128 --n-envs 2 --hp algo.n_steps=64 algo.batch_size=64 algo.n_epochs=1 "
        "policy.net_arch=[8,8] --env-kwargs mission_time_s=2 controller_on_after_s=0.2 --checkpoint-freq 128 "
        "--eval-episodes 1 --eval-mission-time-s 0.5 --no-progress",
    "lvgym evaluate --policies runs/my-ppo": SHORT_EVAL,
    "lvgym train --suite smile-v2-faults --name my-faults":
        "--total-timesteps 128 --n-envs 2 --hp algo.n_steps=64 algo.batch_size=64 algo.n_epochs=1 "
        "policy.net_arch=[8,8] --env-kwargs mission_time_s=2 controller_on_after_s=0.2 --checkpoint-freq 128 "
        "--eval-episodes 1 --eval-mission-time-s 0.5 --no-progress",
    "lvgym campaign agents/training/campaigns/v2_faults_gust.yaml --dry-run": "",
    "lvgym evaluate --policies my_policy.py:make lqg-front": SHORT_EVAL,
    "cp lvgym/vehicles/smile_v1.yaml my_rocket.yaml": "",
    "lvgym design pid-flex --vehicle smile": "--times 28.8 --starts 0",
    "lvgym design lqg --vehicle smile": "--rows 28.8",
    "lvgym margins --policies gs-pid-flex lqg": "--seeds 1 --mission-time-s 5",
    "lvgym design auto --vehicle my_rocket.yaml": "--rows 2 --flex-maxiter 20 --workers 1",
}


def _commands(block: str) -> list[str]:
    """The command lines of an sh block, without their comments."""
    lines = [line.split("#", 1)[0].strip() for line in block.splitlines()]
    return [line for line in lines if line]


def _python(n: int) -> str:
    return [code for lang, code in BLOCKS if lang == "python"][n]


def _sh(n: int) -> list[str]:
    return _commands([code for lang, code in BLOCKS if lang == "sh"][n])


def _run(command: str, cwd: Path, cache: Path | None = None) -> subprocess.CompletedProcess:
    """One README command, shortened, run in ``cwd`` (the repository's scripts and files by their path);
    ``cache``: its ``$LVGYM_CACHE_DIR``."""
    argv = shlex.split(command) + shlex.split(SHORTEN[command])
    if argv[0] == "python":
        argv = [sys.executable, *[str(ROOT / a) if a.endswith(".py") and (ROOT / a).exists() else a for a in argv[1:]]]
    elif argv[0] == "cp":
        argv = ["cp", str(ROOT / argv[1]), *argv[2:]]
    elif argv[0] == "lvgym":
        argv = [sys.executable, "-m", "lvgym.cli.main", *argv[1:]]
    env = None if cache is None else {**os.environ, "LVGYM_CACHE_DIR": str(cache)}
    proc = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=600, env=env)
    assert proc.returncode == 0, f"{command}: exit {proc.returncode}\n{proc.stdout[-2000:]}\n{proc.stderr[-3000:]}"
    return proc


def test_every_readme_command_is_known():
    """Every command of the README is run below (shortened by SHORTEN) or is a set-up command."""
    commands = [c for lang, code in BLOCKS if lang == "sh" for c in _commands(code)]
    assert commands[:2] == ["make run", "make test"], "the README starts with make run and make test"
    unknown = [c for c in commands if not c.startswith(SETUP) and c not in SHORTEN]
    assert not unknown, f"README commands without a shortened form in SHORTEN: {unknown}"
    assert set(SHORTEN) <= set(commands), f"SHORTEN names commands the README no longer has: {set(SHORTEN) - set(commands)}"
    assert len([lang for lang, _ in BLOCKS if lang == "python"]) == 4


def test_readme_is_short():
    assert len(README.splitlines()) <= 200


def test_fly_an_env():
    namespace: dict = {}
    exec(compile(_python(0), "README.md (fly an env)", "exec"), namespace)
    assert namespace["obs"].shape == namespace["env"].observation_space.shape
    assert set(namespace["info"]["reward_terms"]) == {"rate_roll", "rate_pitch", "rate_yaw", "effort", "effort_rate",
                                                      "failure"}
    rows, _ = namespace["venv"].reset(seed=0)                                  # both faces: the same 8 rows
    sb3_venv = namespace["sb3_venv"]
    assert rows.shape == (8, *namespace["env"].observation_space.shape)
    np.testing.assert_array_equal(sb3_venv.reset(), rows)
    np.testing.assert_array_equal(rows[0], namespace["env"].reset(seed=0)[0])


def test_train_then_evaluate(tmp_path):
    """The train-then-evaluate quick start: a tiny run, then lvgym evaluate on its folder, beside the suite's
    classical designs and its privileged reference."""
    train, evaluate = _sh(2)[:2]
    _run(train, tmp_path)
    assert (tmp_path / "runs" / "my-ppo" / "config.yaml").exists()
    proc = _run(evaluate, tmp_path)
    for label in ("my-ppo", "lqg-front", "privileged"):
        assert label in proc.stdout, proc.stdout[-2000:]


def test_train_on_a_suite_and_a_campaigns_plan(tmp_path):
    """The same quick start's v2 lines: a tiny run on smile-v2-faults' condition, and the shipped campaign's
    dry run (the whole file checked, the runs listed, nothing run)."""
    suite, campaign = _sh(2)[2:]
    _run(suite, tmp_path)
    assert "suite: smile-v2-faults" in (tmp_path / "runs" / "my-faults" / "config.yaml").read_text()
    (tmp_path / "agents").symlink_to(ROOT / "agents")
    proc = _run(campaign, tmp_path)
    assert "6 runs (2 configurations x 3 seeds)" in proc.stdout and not (tmp_path / "runs" / "v2-faults-gust").exists()


def test_own_controller_file_acts(tmp_path):
    """The README's policy file is a benchmark policy: name, reset(), act() -> an action of the TVC space."""
    path = tmp_path / "my_policy.py"
    path.write_text(_python(1), encoding="utf-8")
    spec = importlib.util.spec_from_file_location("my_policy", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    policy = module.make()
    from lvgym.benchmark.policy import Policy
    assert isinstance(policy, Policy) and policy.name == "my-pd"
    policy.reset()
    obs = np.zeros(14, dtype=np.float32)
    obs[1], obs[4] = 0.01, -0.02                        # pitch rate error [rad/s], yaw attitude error [rad]
    action = policy.act(obs, {})
    np.testing.assert_allclose(action, [-0.057, 0.046], rtol=1e-6)
    assert action.dtype == np.float32


def test_own_controller_evaluated(tmp_path):
    (tmp_path / "my_policy.py").write_text(_python(1), encoding="utf-8")
    (command,) = _sh(3)
    proc = _run(command, tmp_path)
    assert "my-pd" in proc.stdout and "lqg-front" in proc.stdout
    assert "### Other policies beside the headline" in proc.stdout and "| `my-pd` | other |" in proc.stdout


def test_own_vehicle(tmp_path, monkeypatch):
    (command,) = _sh(4)
    _run(command, tmp_path)
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(_python(2), "README.md (own vehicle)", "exec"), namespace)
    assert 10_000.0 < namespace["mm"].properties(namespace["mm"].initial_state()).mass < 11_000.0
    obs, _ = namespace["env"].reset(seed=0)
    assert obs.shape == namespace["env"].observation_space.shape


def test_linearise():
    pytest.importorskip("control")
    namespace: dict = {}
    exec(compile(_python(3), "README.md (linearise)", "exec"), namespace)
    plant = namespace["plant"]
    assert plant.ninputs == plant.noutputs == 1 and plant.nstates > 6      # rigid body, slosh and bending states


def test_design_and_margins(tmp_path):
    shutil.copy(ROOT / "lvgym" / "vehicles" / "smile_v1.yaml", tmp_path / "my_rocket.yaml")   # the cp above
    for command in _sh(5):
        auto = command.startswith("lvgym design auto")
        proc = _run(command, tmp_path, cache=tmp_path / "cache" if auto else None)   # the test's design cache
        assert not auto or "designed in" in proc.stdout
