"""docs/own-launcher.md runs: the tutorial's vehicle file, its checks, its plant, the design commands, the
policy file, the margins and the benchmark's conditions, in order in one folder, each command shortened
(fewer design rows, no random starts, short flights) so that the whole page runs in about a minute."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = (ROOT / "docs" / "own-launcher.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"```(yaml|python|sh)\n(.*?)```", PAGE, re.S)

#: each command of the page -> the options appended to run it in seconds (documented options of the command)
SHORTEN = {
    "lvgym design pid --vehicle kestrel.yaml --protocol v1 --out results/kestrel_pid.yaml": "--times 14.8 31.8",
    "lvgym design pid-flex --vehicle kestrel.yaml --fly results/kestrel_pid.yaml --noise-rate 0.2 "
    "--out results/kestrel_flex.yaml": "--times 31.8 --starts 0",
    "lvgym margins --vehicle kestrel.yaml --policies kestrel-flex=kestrel_policy.py:make --seeds 3":
        "--seeds 1 --mission-time-s 4 --models nonrigid --executor serial --no-progress",
    "lvgym evaluate --vehicle kestrel.yaml --policies zero privileged kestrel-flex=kestrel_policy.py:make --episodes 20":
        "--episodes 2 --mission-time-s 4 --executor serial --no-plots --no-progress",
    "lvgym design auto --vehicle kestrel.yaml --out results/kestrel_auto": "--rows 2 --flex-maxiter 20 --workers 1",
    "lvgym evaluate --vehicle kestrel.yaml --policies zero privileged auto-gs-pid auto-gs-pid-flex auto-lqg "
    "--episodes 20": "--episodes 1 --mission-time-s 4 --executor serial --no-plots --no-progress",
}


def _blocks(lang: str) -> list[str]:
    return [code for kind, code in BLOCKS if kind == lang]


def _commands() -> list[str]:
    return [line.split("#", 1)[0].strip() for block in _blocks("sh") for line in block.splitlines()
            if line.split("#", 1)[0].strip()]


def _run(command: str, cwd: Path) -> subprocess.CompletedProcess:
    argv = shlex.split(command) + shlex.split(SHORTEN[command])
    argv = [sys.executable, "-m", "lvgym.cli.main", *argv[1:]]
    env = {**os.environ, "LVGYM_CACHE_DIR": str(cwd / "cache")}        # the automatic design's cache: the test's
    proc = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=600, env=env)
    assert proc.returncode == 0, f"{command}\n{proc.stdout[-2000:]}\n{proc.stderr[-3000:]}"
    return proc


def test_the_page_has_what_the_test_runs():
    assert len(_blocks("yaml")) == 1 and len(_blocks("python")) == 3
    assert _commands() == list(SHORTEN), "a command of the page without its shortened form, or the other way"


def test_the_tutorial_runs_from_the_vehicle_file_to_the_benchmark(tmp_path, capsys):
    (tmp_path / "kestrel.yaml").write_text(_blocks("yaml")[0], encoding="utf-8")
    check, plant, policy = _blocks("python")
    namespace: dict = {}
    old = Path.cwd()
    try:
        os.chdir(tmp_path)
        exec(compile(check, "own-launcher.md (check)", "exec"), namespace)
        out = capsys.readouterr().out
        assert "2248 kg, thrust-to-weight 1.67, burnout 118 s" in out and "flew the whole mission" in out
        exec(compile(plant, "own-launcher.md (plant)", "exec"), {})
        assert "11 states; oscillations [Hz]:" in capsys.readouterr().out
    finally:
        os.chdir(old)
    (tmp_path / "kestrel_policy.py").write_text(policy, encoding="utf-8")
    design_pid, design_flex, margins, evaluate, design_auto, evaluate_auto = _commands()
    _run(design_pid, tmp_path)
    _run(design_flex, tmp_path)
    flex = tmp_path / "results" / "kestrel_flex.yaml"
    assert flex.is_file() and (tmp_path / "results" / "kestrel_flex_margins.md").is_file()
    assert "kestrel-flex" in _run(margins, tmp_path).stdout
    table = _run(evaluate, tmp_path).stdout
    for label in ("| rigid | kestrel-flex |", "| nonrigid | privileged |", "| nonrigid | zero |"):
        assert label in table, table[-3000:]
    assert "designed in" in _run(design_auto, tmp_path).stdout
    for name in ("gs-pid.yaml", "gs-pid-flex.yaml", "lqg.npz", "design.json"):
        assert (tmp_path / "results" / "kestrel_auto" / name).is_file()
    table = _run(evaluate_auto, tmp_path).stdout                 # the policies fly that design (the cache's last)
    for label in ("| nonrigid | auto-gs-pid |", "| nonrigid | auto-gs-pid-flex |", "| nonrigid | auto-lqg |"):
        assert label in table, table[-3000:]


@pytest.mark.parametrize("bad, message", [("fill_ratio: 0.95, slip", "fill_ratio: 1.2, slip")])
def test_a_wrong_value_in_the_file_is_one_line(tmp_path, bad, message):
    text = _blocks("yaml")[0].replace(bad, message, 1)
    (tmp_path / "kestrel.yaml").write_text(text, encoding="utf-8")
    from lvgym.errors import ConfigError
    from lvgym.vehicle import load_vehicle

    with pytest.raises(ConfigError, match=r"kestrel\.yaml.*fill_ratio = 1\.2"):
        load_vehicle(str(tmp_path / "kestrel.yaml"))
