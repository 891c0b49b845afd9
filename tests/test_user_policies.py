"""A user's own policy in the benchmark: ``evaluate.py --policies module:factory`` and
``--policies path/to/file.py:factory`` reach the spawned workers (no ``__main__`` guard in the user's
file: it is loaded by path under a private name, never as ``__main__``), a factory that fails is one line
naming the policy and the cause, and the registry refuses a second factory under a taken name."""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

import pytest

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies)
from lvgym.benchmark import registry
from lvgym.benchmark.runner import PolicySpec
from lvgym.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]

#: a user's policy file: no __main__ guard; it logs who loaded it under which module name; the factory
#: flies a constant pitch command (so its episodes differ from zero's once the controller is on at 2 s)
POLICY_FILE = '''
import os
from pathlib import Path

import numpy as np

with open(Path(__file__).with_name("loads.log"), "a") as log:
    log.write(f"{os.getpid()} {__name__}\\n")


class Constant:
    name = "constant"

    def __init__(self, env, pitch):
        self.action = np.array([pitch, 0.0], dtype=np.float32)

    def reset(self):
        pass

    def act(self, observation, info):
        return self.action


def make(env):
    return Constant(env, 0.3)


def broken(env):
    raise ValueError("no gain table for " + type(env.unwrapped).__name__)


def plain():                     # a factory without the env: its policy's own name labels the results
    return Constant(None, 0.3)


def plain_broken():
    raise KeyError("pitch")
'''


def _evaluate_module():
    spec = importlib.util.spec_from_file_location("lvgym_evaluate_script_user", ROOT / "evaluate.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


EVALUATE = _evaluate_module()
ARGS = ["--suites", "smile-v1", "--episodes", "2", "--mission-time-s", "3", "--no-plots", "--no-progress"]


@pytest.fixture
def user_folder(tmp_path, monkeypatch):
    """A working folder with the user's policy file and a module that imports it (as a user's package
    would), not on sys.path; the test runs from there."""
    (tmp_path / "my_policy.py").write_text(POLICY_FILE, encoding="utf-8")
    (tmp_path / "user_controllers.py").write_text("from my_policy import make  # noqa: F401\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    for name in [n for n in sys.modules if n in ("my_policy", "user_controllers") or n.startswith("_lvgym_policy_")]:
        del sys.modules[name]
    for p in (str(tmp_path),):
        while p in sys.path:
            sys.path.remove(p)


def _scores(result, policy):
    return [(r["condition"], r["seed"], r["score"], r["rate_error_rad"]) for r in result["records"] if r["policy"] == policy]


def test_a_users_file_and_module_fly_on_two_spawned_workers(user_folder):
    out = EVALUATE.main(["--policies", "zero", "my_policy.py:make", "user_controllers:make", *ARGS, "--workers", "2",
                         "--out", str(user_folder / "out")])
    assert [p["name"] for p in out["meta"]["policies"]] == ["zero", "my_policy", "user_controllers"]
    assert out["meta"]["protocol"] == "v1+override"           # smile-v1, its mission shortened
    assert out["meta"]["policies"][1]["factory"] == f"{user_folder / 'my_policy.py'}:make"
    mine, via_module, zero = _scores(out, "my_policy"), _scores(out, "user_controllers"), _scores(out, "zero")
    assert len(mine) == 4 and mine == via_module                    # the same factory, by file and by module
    assert all(a[2] != b[2] for a, b in zip(mine, zero))            # flown: the constant command changed every score
    loads = [line.split() for line in (user_folder / "loads.log").read_text().splitlines()]
    workers = {pid for pid, name in loads if int(pid) != os.getpid()}
    assert workers, "the workers loaded the user's file"
    assert all(name not in ("__main__", "__mp_main__") for _, name in loads)
    assert {name for _, name in loads} <= {"my_policy"} | {n for _, n in loads if n.startswith("_lvgym_policy_my_policy_")}
    serial = EVALUATE.main(["--policies", "my_policy.py:make", *ARGS, "--executor", "serial",
                            "--out", str(user_folder / "serial")])
    assert _scores(serial, "my_policy") == mine                     # the workers flew what this process flies


def test_a_failing_factory_is_one_line_naming_the_policy_and_the_cause(user_folder):
    with pytest.raises(SystemExit) as err:
        EVALUATE.main(["--policies", "lqg", "mine=my_policy.py:broken", *ARGS, "--workers", "2",
                       "--out", str(user_folder / "out")])
    text = str(err.value.code)
    assert len(text.splitlines()) == 1, text
    assert text.startswith("evaluate.py: task failed: policy 'mine' on 'smile-v1/")
    assert text.endswith(f"policy = 'mine': its factory {user_folder / 'my_policy.py'}:broken raised ValueError: "
                         "no gain table for SmileAscentV1Env")
    assert "lqg" not in text


@pytest.mark.parametrize("arg, message", [
    ("my_policy.py:nope", r"^evaluate\.py: policy 'my_policy\.py:nope': '.*my_policy\.py' has no 'nope'$"),
    ("missing.py:make", r"^evaluate\.py: policy 'missing\.py:make': no such file '.*missing\.py'$"),
    ("no_such_module:make", r"^evaluate\.py: policy 'no_such_module:make': cannot import 'no_such_module' "),
    ("lqg-frnt", r"^evaluate\.py: policy 'lqg-frnt' \(did you mean 'lqg-front'\?\): not a registered name, module:factory, "
            r"path/to/file\.py:factory, a stable-baselines3 \.zip model or a train\.py run folder, a disturbance "
            r"observer's record \.json \(lvgym train --recipe teacher-student\), a cloned policy \.pt \(lvgym bc\); "
            r"the registered "
            r"names: \[.*'zero'\]$"),
])
def test_a_bad_policy_is_refused_in_one_line_before_any_episode(user_folder, arg, message):
    import re

    with pytest.raises(SystemExit) as err:
        EVALUATE.main(["--policies", arg, *ARGS, "--out", str(user_folder / "out")])
    assert re.search(message, str(err.value.code)), err.value.code
    assert not (user_folder / "out").exists()


def test_a_policys_own_name_labels_it_when_known_without_an_env(user_folder):
    assert registry.resolve_policy("my_policy.py:make").name == "my_policy"          # a factory of the env
    assert registry.resolve_policy("my_policy.py:plain").name == "constant"          # what it returns is named
    assert registry.resolve_policy("my_policy.py:Constant").name == "constant"       # a class's name
    assert registry.resolve_policy("fixed=my_policy.py:plain").name == "fixed"       # label= wins
    with pytest.raises(SystemExit, match=r"^evaluate\.py: policy 'my_policy\.py:plain_broken': its factory raised "
                                         r"KeyError: 'pitch'$"):
        registry.resolve_policy("my_policy.py:plain_broken")


def _factory(env, gain=1.0):
    """A module-level factory for the registry's tests (never flown)."""
    raise AssertionError("not flown")


def test_register_policy_by_callable_or_string_and_duplicates(monkeypatch):
    monkeypatch.setattr(registry, "POLICIES", dict(registry.POLICIES))
    spec = registry.register_policy("mine", _factory, gain=2.0, name="mine")
    assert spec == PolicySpec("mine", f"{__name__}:_factory", (("gain", 2.0), ("name", "mine")))
    assert registry.POLICIES["mine"] is spec
    assert registry.register_policy("mine", f"{__name__}:_factory", name="mine", gain=2.0) == spec   # the same: no-op
    with pytest.raises(ConfigError, match=r"^policy = 'mine': registered already as .*:_factory with "
                                          r"\{'gain': 2\.0, 'name': 'mine'\}; pick another name$"):
        registry.register_policy("mine", _factory, gain=3.0)
    with pytest.raises(ConfigError, match=r"^policy = 'lqg': registered already as lvgym\.baselines\.lqg:smile_lqg"):
        registry.register_policy("lqg", _factory)
    with pytest.raises(ValueError, match="a module-level function"):
        registry.register_policy("anon", lambda env: None)
    assert registry.resolve_policy("mine") == spec


def test_the_built_in_names_are_the_registered_ones():
    assert registry.POLICIES["gs-pid"] == PolicySpec("gs-pid", "lvgym.baselines.pid:smile_scheduled_pid",
                                                     (("name", "gs-pid"), ("schedule", "smile")))
    assert registry.POLICIES["ppo-res-lqg"] == PolicySpec("ppo-res-lqg", "lvgym.agents.policies.sb3:shipped_policy",
                                                          (("file", "ppo_res_lqg_smile_v1"), ("name", "ppo-res-lqg")))
    assert registry.POLICIES["auto-lqg"] == PolicySpec("auto-lqg", "lvgym.baselines.designed:auto_policy",
                                                       (("kind", "lqg"), ("name", "auto-lqg")))
    assert registry.POLICIES["fixed-gs-pid-flex"] == PolicySpec(
        "fixed-gs-pid-flex", "lvgym.baselines.designed:fixed_policy", (("kind", "gs-pid-flex"), ("name", "fixed-gs-pid-flex")))
    assert sorted(registry.POLICIES) == ["aac", "aac-quiet", "auto-gs-pid", "auto-gs-pid-flex", "auto-lqg", "eso",
                                         "fixed-gs-pid-flex", "fixed-lqg", "gs-pd-relief", "gs-pid", "gs-pid-flex",
                                         "gs-pid-flex-quiet", "gs-pid-thesis", "indi", "inversion-id",
                                         "inversion-id-smile", "inversion-id-stratos", "lqg", "lqg-aw", "lqg-front",
                                         "lqi", "lqi-hold", "mpc", "pid", "pid-thesis", "ppo", "ppo-res-lqg", "privileged",
                                         "zero"]
