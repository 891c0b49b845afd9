"""The examples of the docs pages that were the README's run, and the docstring examples."""

import doctest
import pathlib
import re

import pytest

import lvgym
import lvgym.dynamics.model

ROOT = pathlib.Path(__file__).resolve().parents[1]


def _python_blocks(page: str) -> list[str]:
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / page).read_text(encoding="utf-8"), re.S)
    assert blocks, f"docs/{page} has no python example"
    return blocks


def _run(page: str, block: str) -> dict:
    namespace: dict = {}
    exec(compile(block, f"docs/{page}", "exec"), namespace)
    return namespace


def test_dynamics_example_runs():
    (block,) = _python_blocks("dynamics.md")
    ns = _run("dynamics.md", block)
    assert ns["traj"].t[-1] == 5.0


def test_mass_model_example_runs():
    (block,) = _python_blocks("models.md")
    ns = _run("models.md", block)
    assert ns["state"].t == 45.0 and ns["props"].stages == ("stage2", "stage3")


def test_rl_examples_run():
    """The first steps and the state-as-data example of docs/rl.md."""
    from lvgym.envs.layouts import REWARD_TERMS

    first, _, snapshot = _python_blocks("rl.md")
    ns = _run("rl.md", first)
    assert set(ns["info"]["reward_terms"]) == set(REWARD_TERMS)
    _run("rl.md", snapshot)                 # it asserts the bit-for-bit replay itself


def test_rl_benchmark_env_example_runs():
    _, make_env, _ = _python_blocks("rl.md")
    ns = _run("rl.md", make_env)
    assert ns["obs"].shape == ns["env"].observation_space.shape


def test_family_example_runs():
    (block,) = _python_blocks("family.md")
    ns = _run("family.md", block)
    assert ns["obs"].shape == (22,) and ns["env"].unwrapped.observation_layout.names[-1] == "vehicle_slosh_hz"


def test_docstring_examples():
    result = doctest.testmod(lvgym.dynamics.model)
    assert result.attempted > 0 and result.failed == 0


def test_the_add_a_controller_example_flies_as_one_law():
    """docs/baselines.md's batch law: its one-row face and a batch of three agree, and the benchmark flies it."""
    import numpy as np

    from lvgym.benchmark import play_episode

    (block,) = _python_blocks("baselines.md")
    ns = _run("baselines.md", block)
    face, law = ns["MyPD"](), ns["MyPD"]().batch(3)
    obs = np.random.default_rng(0).normal(0.0, 0.1, (3, 14)).astype(np.float32)
    law.reset(np.arange(3))
    assert np.array_equal(law.act(np.arange(3), obs, {})[1], face.act(obs[1], {}))
    record = play_episode(face, lvgym.make_env("smile-v1", mission_time_s=4.0), 0)
    assert record["duration_s"] == pytest.approx(4.0) and not record["failed"]
