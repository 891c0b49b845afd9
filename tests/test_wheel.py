"""The wheel: built from a copy of the checkout, it holds the one import name ``lvgym`` with all its package
data, and installed with only the core dependencies into a fresh virtual environment it flies
``lvgym/SmileAscent-v1`` like the checkout does, imports no extra, and every core module either imports or
says which extra it needs.

About a minute and a half on 2 cores, most of it numba compiling the kernels in the fresh environment (its
cache in ``tmp_path``); pip installs the core dependencies from its cache or the package index.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
#: what a build does not read (and must not pick up): environments, build output, caches, results, docs
SKIP = shutil.ignore_patterns(".git", ".venv", "venv", "build", "dist", "*.egg-info", "__pycache__", "*.pyc",
                              ".pytest_cache", "results", "runs", "docs")
#: the checkout's folders installed under ``lvgym`` (pyproject.toml's package-dir)
INSTALLED = {"lvgym": "lvgym", "agents": "lvgym/agents", "baselines": "lvgym/baselines"}
#: core modules that need an extra, with the package they miss and the extra their one-line error names
#: (the env reaches them only when asked to render or for an SB3 VecEnv); the studies name theirs too
NEEDS_EXTRA = {"lvgym.envs.render": "matplotlib", "lvgym.envs.frames": "matplotlib",
               "lvgym.envs.sb3": "stable_baselines3"}
EXTRA_OF = {"matplotlib": "benchmark", "stable_baselines3": "train"}
STUDIES_MESSAGE = "lvgym.studies needs pandas, which lvgym's core install leaves out: pip install 'lvgym[studies]'"


def _run(args: list, **kw) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env.update(PIP_DISABLE_PIP_VERSION_CHECK="1", **kw.pop("env", {}))
    proc = subprocess.run([str(a) for a in args], env=env, capture_output=True, text=True, timeout=900, **kw)
    assert proc.returncode == 0, f"{args[:4]} failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return proc


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> tuple[Path, Path]:
    """``(wheel, source copy)``: the wheel built from a clean copy of the checkout."""
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    shutil.copytree(ROOT, src, ignore=SKIP)
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "--wheel-dir", tmp / "dist", src])
    (wheel,) = (tmp / "dist").glob("lvgym-*.whl")
    return wheel, src


def test_wheel_holds_lvgym_and_its_data_only(built):
    wheel, src = built
    names = zipfile.ZipFile(wheel).namelist()
    info = [n for n in names if n.split("/")[0].endswith(".dist-info")]
    assert {n.split("/")[0] for n in names} - {info[0].split("/")[0]} == {"lvgym"}   # no agents, tests, ...
    top = [n for n in info if n.endswith("/top_level.txt")]
    assert not top or zipfile.ZipFile(wheel).read(top[0]).decode().split() == ["lvgym"]
    want = {f"{INSTALLED[folder]}/{p.relative_to(src / folder).as_posix()}"
            for folder in INSTALLED for p in (src / folder).rglob("*") if p.is_file()}
    assert sorted(want - set(names)) == []                       # every module and data file of the folders
    assert sorted(set(names) - want - set(info)) == []           # and nothing else
    data = [n for n in want if not n.endswith(".py")]
    for pattern in ("lvgym/vehicles/smile_v1.yaml", "lvgym/environment/data/", "lvgym/benchmark/data/v1.json",
                    "lvgym/baselines/schedules/smile_lqg.npz", "lvgym/agents/training/hyperparams/",
                    "lvgym/agents/training/campaigns/", "lvgym/agents/trained/"):
        assert any(n.startswith(pattern) for n in data), pattern


def test_wheel_with_the_core_only_flies_and_imports_no_extra(built, tmp_path):
    wheel, _ = built
    venv = tmp_path / "venv"
    _run([sys.executable, "-m", "venv", venv])
    python = venv / "bin" / "python"
    _run([python, "-m", "pip", "install", "--quiet", "--no-compile", wheel])       # no extras
    out = tmp_path / "probe.json"
    _run([python, ROOT / "tests" / "wheel_probe.py", out, "--all"], cwd=tmp_path,
         env={"NUMBA_CACHE_DIR": str(tmp_path / "numba")})
    report = json.loads(out.read_text(encoding="utf-8"))
    assert Path(report["lvgym_file"]).is_relative_to(venv)      # the installed wheel, not the checkout
    assert report["installed"] == []                             # a core-only environment
    assert report["loaded"] == [] and report["loaded_after_flight"] == []
    # side by side: the same episode flown here, from the checkout
    import gymnasium as gym

    import lvgym  # noqa: F401
    env = gym.make("lvgym/SmileAscent-v1")
    env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    for _ in range(report["steps"]):
        obs, *_ = env.step(zero)
    assert report["steps"] == 100
    # bit for bit when both environments hold the same numpy, scipy and numba (as when this was written); the
    # tolerance leaves room for a fresh environment that resolves newer releases than the checkout's
    np.testing.assert_allclose(report["obs"], np.asarray(obs, dtype=float), rtol=1e-9, atol=1e-12)
    failed = {m: e for m, e in report["imports"].items() if e is not None}
    assert {m: e["name"] for m, e in failed.items() if not m.startswith("lvgym.studies")} == NEEDS_EXTRA
    for module, package in NEEDS_EXTRA.items():
        assert failed[module]["message"].endswith(f"pip install 'lvgym[{EXTRA_OF[package]}]'"), failed[module]
    studies = {m: e["message"] for m, e in failed.items() if m.startswith("lvgym.studies")}
    assert "lvgym.studies.doe" in studies and set(studies.values()) == {STUDIES_MESSAGE}
    assert len(report["imports"]) > 100 and report["imports"]["lvgym.benchmark.runner"] is None
    assert report["run_map"] == [1, 4, 9]                        # no tqdm: no bar, the same results
    assert report["load_error"]["message"].endswith("pip install 'lvgym[studies]'")
