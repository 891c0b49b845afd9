"""The teacher-student recipe from the installed wheel: built from a copy of the checkout and installed without its
dependencies into a fresh virtual environment that sees this interpreter's packages (torch, stable-baselines3,
numba, ...) after its own, ``lvgym train --recipe teacher-student`` trains, chooses and records an observer on a
short mission, and ``lvgym evaluate --policies <record>.json`` flies the policy the record names.

Numba's cache of a compiled function sits where its source file sits (or under ``NUMBA_CACHE_DIR``, in a folder
named by the source's folder) and is keyed by a hash of the source's content: the installed wheel's files would
compile again (a single env's first reset and step: 163 s on a cold cache, the whole test 179-412 s, on 2 shared
cores with other runs). So the test first flies a short flight here, which compiles the development tree's kernels
or finds them cached, and copies those caches to where the fresh environment looks for its own files' (the same
content, so the same keys): the installed code then runs without compiling (a first env step in about 5 s). The
recipe itself at this budget takes about 15 s (tests/test_teacher_student.py runs it in the development
environment).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: what a build does not read: environments, build output, caches, results, docs
SKIP = shutil.ignore_patterns(".git", ".venv", "venv", "build", "dist", "*.egg-info", "__pycache__", "*.pyc",
                              ".pytest_cache", "results", "runs", "docs")
SHORT = "2"


def _run(args: list, cwd: Path, **env: str) -> subprocess.CompletedProcess:
    clean = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    clean.update(PIP_DISABLE_PIP_VERSION_CHECK="1", **env)
    proc = subprocess.run([str(a) for a in args], env=clean, cwd=cwd, capture_output=True, text=True, timeout=1200)
    assert proc.returncode == 0, f"{args[:5]} failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return proc


def _warm_caches() -> None:
    """Compile (or load) the development tree's flight kernels: a step of a single and of a batched env."""
    import numpy as np

    import lvgym

    for env in (lvgym.make_env("smile-v2", model="nonrigid", mission_time_s=0.1),
                lvgym.make_vec_env("smile-v2", model="nonrigid", num_envs=2, mission_time_s=0.1)):
        env.reset(seed=0)
        env.step(np.zeros(env.action_space.shape, np.float32))
        env.close()


def _copy_caches(purelib: Path, cache_dir: Path) -> int:
    """Copy each development source file's numba caches (its ``__pycache__``'s ``.nbi``/``.nbc``) to the folder
    numba looks in for the installed copy of that file under ``cache_dir`` (numba's own naming: the source
    folder's name and the SHA-1 of its absolute path). Returns how many files were copied."""
    where = {"agents": ROOT / "agents", "baselines": ROOT / "baselines"}
    copied = 0
    for py in (purelib / "lvgym").rglob("*.py"):
        rel = py.relative_to(purelib / "lvgym")
        src = where[rel.parts[0]].joinpath(*rel.parts[1:]) if rel.parts[0] in where else ROOT / "lvgym" / rel
        caches = sorted((src.parent / "__pycache__").glob(src.stem + ".*.nb[ic]"))
        if not caches:
            continue
        folder = str(py.parent.resolve())
        target = cache_dir / f"{os.path.basename(folder)}_{hashlib.sha1(folder.encode()).hexdigest()}"
        target.mkdir(parents=True, exist_ok=True)
        for f in caches:
            shutil.copy2(f, target / f.name)
            copied += 1
    return copied


def test_the_installed_recipe_trains_records_and_its_record_flies(tmp_path):
    src = tmp_path / "src"
    shutil.copytree(ROOT, src, ignore=SKIP)
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "--wheel-dir", tmp_path / "dist", src],
         tmp_path)
    (wheel,) = (tmp_path / "dist").glob("lvgym-*.whl")
    venv = tmp_path / "venv"
    _run([sys.executable, "-m", "venv", venv], tmp_path)
    python = venv / "bin" / "python"
    _run([python, "-m", "pip", "install", "--no-deps", "--no-compile", "--quiet", wheel], tmp_path)
    purelib = Path(_run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], tmp_path)
                   .stdout.strip())
    # this interpreter's packages after the venv's own (a .pth line is appended to sys.path): the wheel's lvgym
    # is found first, torch and the rest here
    (purelib / "zz_development_packages.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    _warm_caches()
    assert _copy_caches(purelib, tmp_path / "numba") > 20
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    where = json.loads(_run([python, "-c", "import json, lvgym, torch, lvgym.agents.training.teacher_student as t; "
                                           "print(json.dumps([lvgym.__file__, t.__file__]))"], tmp_path).stdout)
    assert all(Path(f).is_relative_to(venv) for f in where), where

    argv = ["--suite", "smile-v2", "--seeds", "0", "--flights", "2", "--rounds", "1", "--epochs", "1",
            "--validation", "1", "--selection", "2", "--flight-options", "average=6", "--option-validation", "1",
            "--margin-suite", "smile-v2", "--margin-seeds", "1", "--mission-time-s", SHORT, "--out", "run"]
    out = _run([venv / "bin" / "lvgym", "train", "--recipe", "teacher-student", *argv], tmp_path, **env).stdout
    assert "seed 0 round 1 validation 0-0" in out and "wrote run/inversion_id_smile_v2.json" in out
    record = json.loads((tmp_path / "run" / "inversion_id_smile_v2.json").read_text())
    assert {"policy", "suite", "env", "lead", "sha256", "date", "training", "validation", "flight",
            "mission_time_s"} <= set(record)
    assert record["training"]["command"] == "lvgym train --recipe teacher-student " + " ".join(argv)
    assert record["env"] == {"vehicle": "smile_v1", "observation": "flight", "history": 0, "control": "tvc",
                             "control_dt_s": 0.02}
    weights = (tmp_path / "run" / "inversion_id_smile_v2.npz").read_bytes()
    assert hashlib.sha256(weights).hexdigest() == record["sha256"]
    assert record["validation"]["chosen"] == 0 and set(record["validation"]["candidates"]) == {"0"}
    flight = record["flight"]
    assert flight["chosen"] in flight["validation"] and set(flight["margins"]) == {"average6"}

    # the record is a policy of the installed evaluate: one short flight per flight model, validation seed 0,
    # the same numbers as the recipe's own validation of the options it chose
    _run([venv / "bin" / "lvgym", "evaluate", "--policies", "run/inversion_id_smile_v2.json", "--suites", "smile-v2",
          "--seed-set", "validation", "--episodes", "1", "--mission-time-s", SHORT, "--executor", "serial",
          "--no-plots", "--no-progress", "--only", "--out", "flown"], tmp_path, **env)
    flown = json.loads((tmp_path / "flown" / "results.json").read_text())
    episodes = flown["episodes"]
    assert sorted(e["model"] for e in episodes) == ["nonrigid", "rigid"]
    assert {e["policy"] for e in episodes} == {"inversion_id_smile_v2"}
    for e in episodes:
        assert e["seed"] == 0 and e["score_v2"] == pytest.approx(
            flight["validation"][flight["chosen"]][e["model"]]["score_v2_mean"], rel=1e-12)
