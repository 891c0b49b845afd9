"""The examples of the docs pages that were the README's run, and the docstring examples."""

import doctest
import pathlib
import re


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
