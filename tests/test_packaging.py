"""What pyproject.toml promises: every package folder listed, the package data there, and a core that loads
none of the extras (tests/test_wheel.py builds and installs the wheel itself)."""

from __future__ import annotations

import json
import pickle
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from lvgym.errors import require

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
SETUPTOOLS = PYPROJECT["tool"]["setuptools"]


def _package(folder: Path) -> str:
    """The import name of a folder of the checkout by the ``package-dir`` mapping (``baselines/design`` is
    ``lvgym.baselines.design``)."""
    rel = folder.relative_to(ROOT).parts
    name, base = max(((n, Path(d).parts) for n, d in SETUPTOOLS["package-dir"].items()
                      if Path(*rel[:len(Path(d).parts)]) == Path(d)), key=lambda nd: len(nd[1]))
    return ".".join([name, *rel[len(base):]])


def test_packages_list_every_package_folder():
    found = {_package(init.parent) for d in set(SETUPTOOLS["package-dir"].values())
             for init in (ROOT / d).rglob("__init__.py") if "__pycache__" not in init.parts}
    assert {"lvgym", "lvgym.envs", "lvgym.agents", "lvgym.agents.policies", "lvgym.baselines",
            "lvgym.baselines.design"} <= found
    assert sorted(found - set(SETUPTOOLS["packages"])) == [], "folders with an __init__.py missing from packages"
    assert sorted(set(SETUPTOOLS["packages"]) - found) == [], "packages listed without a folder"


def _folder(package: str) -> Path:
    """The folder of the checkout that holds ``package`` by the ``package-dir`` mapping (``lvgym.agents.training``
    is ``agents/training``): the inverse of :func:`_package`."""
    name = max((n for n in SETUPTOOLS["package-dir"] if package == n or package.startswith(n + ".")), key=len)
    return ROOT / SETUPTOOLS["package-dir"][name] / Path(*package[len(name):].split(".")[1:])


def test_package_data_globs_find_files():
    assert _folder("lvgym.agents.training") == ROOT / "agents" / "training"
    assert _package(_folder("lvgym.baselines.design")) == "lvgym.baselines.design"
    for package, globs in SETUPTOOLS["package-data"].items():
        assert package in SETUPTOOLS["packages"], package
        for pattern in globs:
            assert list(_folder(package).glob(pattern)), f"{package}: {pattern} matches no file"


def test_core_imports_load_no_extra(tmp_path):
    # in the development environment every extra is installed: importing lvgym and lvgym.envs and flying an
    # env must still not import them (the wheel test checks the same where they are absent)
    out = tmp_path / "probe.json"
    subprocess.run([sys.executable, str(ROOT / "tests" / "wheel_probe.py"), str(out)], cwd=tmp_path, check=True,
                   timeout=600)
    report = json.loads(out.read_text(encoding="utf-8"))
    assert report["steps"] == 100
    assert report["loaded"] == [] and report["loaded_after_flight"] == []


def test_require_names_the_extra_in_one_line():
    require("numpy", "benchmark", "anything")                      # installed: nothing happens
    with pytest.raises(ModuleNotFoundError) as exc:
        require("lvgym_no_such_package", "studies", "Recorder.frame")
    assert str(exc.value) == ("Recorder.frame needs lvgym_no_such_package, which lvgym's core install leaves out: "
                              "pip install 'lvgym[studies]'")
    assert exc.value.name == "lvgym_no_such_package"
    back = pickle.loads(pickle.dumps(exc.value))                   # as it comes back from a worker process
    assert str(back) == str(exc.value) and back.name == exc.value.name
    for extra in ("benchmark", "studies", "control", "dev"):         # the extras the messages name exist
        assert extra in PYPROJECT["project"]["optional-dependencies"]
