"""The one-off studies of ``experiments/`` keep working after a move: every command answers ``--help`` as
``python -m experiments.<folder>.<module>`` would run it, every folder has its README, and the two studies
no other test flies (the control study and the load-relief sweep) run a short case against hand numbers.

The studies' own tests: tests/test_aac.py, test_budget.py, test_cmdnoise.py, test_curves.py,
test_gust_relief.py, test_headroom.py, test_load_relief.py, test_robustness_cli.py, test_runcompare.py,
test_slender_aeroelastic.py, test_train_speed.py, test_uncontrolled.py.
"""

from __future__ import annotations

import importlib.util
import pkgutil
import re
import runpy
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import yaml

import experiments
import lvgym  # noqa: F401  (registers the envs)

ROOT = Path(__file__).resolve().parents[1]
#: commands whose command line has no ``--help`` yet, and why (a test below checks they parse no options)
NO_HELP = {"experiments.uncontrolled_departures.uncontrolled": "takes no options",
           "experiments.aeroelastic_divergence.structural_limit": "its arguments are flight times [s]"}


def _modules() -> dict[str, str]:
    """``module name -> source`` of every module of the experiments package."""
    return {m.name: Path(importlib.util.find_spec(m.name).origin).read_text(encoding="utf-8")
            for m in pkgutil.walk_packages(experiments.__path__, "experiments.")}


def _commands() -> list[str]:
    return sorted(name for name, src in _modules().items() if 'if __name__ == "__main__"' in src)


def _links(markdown: Path) -> list[Path]:
    """The files the relative links of ``markdown`` point at (anchors dropped)."""
    text = markdown.read_text(encoding="utf-8")
    return [(markdown.parent / link).resolve() for link in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", text)]


def test_every_command_is_checked_and_every_folder_has_its_readme():
    modules, commands = _modules(), _commands()
    assert "experiments.error_budget.budget" in commands and set(NO_HELP) <= set(commands)
    for name in NO_HELP:                     # when one gets a parser, it joins the --help test below
        assert "parse_args" not in modules[name], f"{name} parses options now: remove it from NO_HELP"
    folders = sorted(p for p in (ROOT / "experiments").iterdir() if (p / "__init__.py").exists())
    index = ROOT / "experiments" / "README.md"
    assert sorted(p for p in _links(index) if p.name == "README.md" and p.parent.parent == index.parent) == \
        [f / "README.md" for f in folders]
    for folder in folders:
        assert any(c.startswith(f"experiments.{folder.name}.") for c in commands), folder.name
        readme = folder / "README.md"
        text = readme.read_text(encoding="utf-8")
        assert f"python -m experiments.{folder.name}." in text and "**Result**" in text, folder.name
        assert any(p.parent == ROOT / "docs" or p == ROOT / "README.md" for p in _links(readme)), folder.name
    for markdown in [index] + [f / "README.md" for f in folders]:
        missing = [str(p) for p in _links(markdown) if not p.exists()]
        assert not missing, f"{markdown}: broken links {missing}"


@pytest.mark.parametrize("module", [m for m in _commands() if m not in NO_HELP])
def test_command_help(module, monkeypatch, capsys):
    """``python -m MODULE --help`` from the repository root: the module runs as ``__main__`` and its parser
    prints its usage and exits 0."""
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr(sys, "argv", [module, "--help"])
    monkeypatch.delitem(sys.modules, module, raising=False)     # as a new process: not imported yet
    with pytest.raises(SystemExit) as done:
        runpy.run_module(module, run_name="__main__", alter_sys=True)
    assert done.value.code in (0, None)
    assert "usage:" in capsys.readouterr().out


# ------------------------------------------------------------------------------ the control study
def test_control_study_flies_every_controller_and_draws_its_figures(tmp_path):
    from experiments.control_study import study

    made = study.controllers()
    assert list(made) == ["uncontrolled", "pid-thesis", "gs-pid-thesis", "pid-tuned", "gs-pid-tuned"]
    dt = 0.02                                       # SmileAscent-v0's control period [s]
    runs = {}
    for name, make in made.items():
        r = study.fly(make, "rigid", wind="profile", mission_time_s=3.0)
        assert r["t_end"] == pytest.approx(3.0) and r["termination"] == ""
        # the env's cumulative error is the sum of |rate error| dt over the steps (the observation is float32)
        np.testing.assert_allclose(r["cum_pitch"], np.cumsum(np.abs(r["pitch"])) * dt, rtol=1e-5, atol=1e-9)
        np.testing.assert_allclose(r["cum_yaw"], np.cumsum(np.abs(r["yaw"])) * dt, rtol=1e-5, atol=1e-9)
        runs[name] = r
    assert np.all(runs["uncontrolled"]["gimbal"] == 0.0)
    assert np.any(runs["gs-pid-tuned"]["gimbal"][runs["gs-pid-tuned"]["t"] > 2.1] != 0.0)   # on after 2 s
    study._plots("gs-pid-tuned_profile", {"rigid": runs["gs-pid-tuned"], "nonrigid": runs["pid-tuned"]}, tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["control_cumulative_gs-pid-tuned_profile.png",
                                                          "control_rates_gs-pid-tuned_profile.png"]


# ------------------------------------------------------------------------------ the load-relief sweep
def _slender_doc() -> dict:
    return yaml.safe_load((ROOT / "baselines" / "schedules" / "slender_flex.yaml").read_text(encoding="utf-8"))


def test_relief_sweep_variant_against_hand_numbers():
    from experiments.load_relief.relief_sweep import _keywords, variant

    doc = _slender_doc()
    n = len(doc["rows"])
    sched = variant(doc, ki_scale=[0.5] + [0.05] * (n - 1), kp_scale=2.0, accel_gain=0.002)
    assert sched.ki == tuple(r["ki"] * s for r, s in zip(doc["rows"], [0.5] + [0.05] * (n - 1)))
    assert sched.kp == tuple(r["kp"] * 2.0 for r in doc["rows"]) and sched.kd == tuple(r["kd"] * 2.0 for r in doc["rows"])
    assert sched.accel_gain == (0.002,) * n and sched.points == tuple(r["mass_kg"] for r in doc["rows"])
    assert doc == _slender_doc()                    # the document itself is not changed
    assert _keywords("ki_scale=0.05, accel_gain=[0.001, 0.002]") == {"ki_scale": 0.05, "accel_gain": [0.001, 0.002]}
    with pytest.raises(SystemExit, match="KEY=LITERAL"):
        _keywords("0.05")


def test_relief_sweep_evaluate_is_the_episodes_it_flies():
    from experiments.load_relief.relief_sweep import evaluate, variant
    from lvgym.baselines.pid import GainScheduledPIDPolicy
    from lvgym.benchmark.runner import play_episode

    doc = _slender_doc()
    env = gym.make("lvgym/SlenderAscent-v1", model="rigid", mission_time_s=2.5)
    got = evaluate(doc, seeds=2, envs={"rigid": env}, ki_scale=0.05, accel_gain=0.001)
    recs = [play_episode(GainScheduledPIDPolicy(variant(doc, ki_scale=0.05, accel_gain=0.001), env=env), env, s)
            for s in range(2)]
    peaks = [r["max_qalpha_pa_deg"] / 1e3 for r in recs]
    assert got == {"rigid": (sum(r["failed"] for r in recs), float(np.mean([r["score"] for r in recs])),
                             float(np.max(peaks)), float(np.median(peaks)))}
    assert got["rigid"][2] > 0.0
