"""The README's example and the docstring examples run."""

import doctest
import pathlib
import re

import lvgym.dynamics.model

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_readme_python_example_runs():
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks, "the README has no python example"
    spaces = []
    for block in blocks:
        namespace: dict = {}
        exec(compile(block, "README.md", "exec"), namespace)
        spaces.append(namespace)
    assert spaces[0]["traj"].t[-1] == 5.0
    vehicle = next(ns for ns in spaces if "mm" in ns)
    assert vehicle["state"].t == 45.0 and vehicle["props"].stages == ("stage2", "stage3")


def test_docstring_examples():
    result = doctest.testmod(lvgym.dynamics.model)
    assert result.attempted > 0 and result.failed == 0
