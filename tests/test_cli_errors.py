"""Command-line values are checked before any worker starts, in one line naming the option, the value and
what is allowed (issue 19): evaluate.py, ``python -m lvgym.studies``, ``python -m lvgym.baselines.design.tune``;
and the tuning command never overwrites a shipped gain schedule unless asked."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from lvgym.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]


def _evaluate_module():
    spec = importlib.util.spec_from_file_location("lvgym_evaluate_script_cli", ROOT / "evaluate.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


EVALUATE = _evaluate_module()


def _one_line(exc: pytest.ExceptionInfo, capsys) -> str:
    code = exc.value.code
    text = code if isinstance(code, str) else capsys.readouterr().err
    assert len(text.strip().splitlines()) == 1, text
    return text.strip()


@pytest.mark.parametrize("argv, message", [
    (["--mission-time-s", "-5"], r"error: --mission-time-s = -5\.0: a number of seconds in \(0, 3600\]"),
    (["--mission-time-s", "nan"], r"--mission-time-s = nan: a number of seconds"),
    (["--workers", "0"], r"error: --workers = 0: an integer >= 1"),
    (["--episodes", "0"], r"--episodes = 0: an integer >= 1"),
    (["--executor", "threads"], r"argument --executor: invalid choice: 'threads'"),
    (["--vehicle", "no_such_rocket.yaml", "--policies", "zero"], r"--vehicle = 'no_such_rocket\.yaml': an existing YAML"),
    (["--vehicle", "smile_v1"], r"--vehicle smile_v1: give --policies too: the shipped designs are made for the shipped"),
])
def test_evaluate_refuses_bad_values_before_any_episode(tmp_path, capsys, argv, message):
    import re

    with pytest.raises(SystemExit) as exc:
        EVALUATE.main([*argv, "--out", str(tmp_path / "out")])
    assert re.search(message, _one_line(exc, capsys))
    assert not (tmp_path / "out").exists()


SEE = r" \(see python -m lvgym\.studies --help\)$"


@pytest.mark.parametrize("argv, message", [
    (["doe", "--aero-mach", "-1"], r"^python -m lvgym\.studies: error: --aero-mach = -1\.0: a number in \[0\.0, 25\.0\]" + SEE),
    (["ld-sweep", "--step", "0"], r"^python -m lvgym\.studies: error: --step = 0\.0: a number in \(0\.0, 0\.3\]" + SEE),
    (["ld-sweep", "--step", "-0.1"], r"--step = -0\.1: a number in \(0\.0, 0\.3\]" + SEE),
    (["tw-sweep", "--step", "50"], r"--step = 50\.0: a number in \(0\.0, 20\.0\]" + SEE),
    (["tw-sweep", "--workers", "0"], r"--workers = 0: an integer in \[1, 100000\]" + SEE),
    (["doe", "--step", "0.01"], r"--step = 0\.01: only for ld-sweep and tw-sweep"),
    (["doe", "--aero", "fancy"], r"argument --aero: invalid choice: 'fancy'"),
])
def test_studies_refuse_bad_values_before_any_run(tmp_path, capsys, argv, message):
    import re

    from lvgym.studies.__main__ import main

    with pytest.raises(SystemExit) as exc:
        main([*argv, "--out", str(tmp_path / "out")])
    assert re.search(message, _one_line(exc, capsys))
    assert not (tmp_path / "out").exists()


def test_study_values_are_checked_in_the_library_too():
    from lvgym.studies.responses import RunSetup
    from lvgym.studies.sweeps import ld_cases, tw_cases

    for step in (0, -0.1, float("nan"), 1.0):
        with pytest.raises(ConfigError, match=r"^step = .*: a number in \(0, 0\.3\]: the diameter \[m\] between runs"):
            ld_cases(step)
    with pytest.raises(ConfigError, match=r"step = 0: a number in \(0, 20\]: the mass flow"):
        tw_cases(0)
    assert len(ld_cases(0.15)) == 3 and len(tw_cases(10.0)) == 3
    for kw, key in (({"aero_mach": -1.0}, "aero_mach"), ({"aero": "fancy"}, "aero"), ({"t_end": 0.0}, "t_end"),
                    ({"sample_dt": 0.007}, "sample_dt"), ({"site": "mars"}, "site"), ({"model": "soft"}, "model")):
        with pytest.raises(ConfigError) as err:
            RunSetup(**kw)
        assert err.value.key == key


# ------------------------------------------------------------------------------------------ tuning
def test_tune_never_overwrites_a_shipped_schedule_unless_asked(tmp_path, capsys):
    from lvgym.baselines.design import tune
    from lvgym.baselines.pid import SCHEDULES

    shipped = SCHEDULES / "smile.yaml"
    before = shipped.read_bytes()
    assert tune.output_path("smile", None, False) == Path("results") / "schedules" / "smile.yaml"
    assert tune.output_path("smile", None, True) == shipped
    assert tune.output_path("smile", str(shipped), True) == shipped
    with pytest.raises(SystemExit) as exc:                  # refused before the (slow) tuning starts
        tune.main(["--vehicle", "smile", "--out", str(shipped)])
    assert "--out" in _one_line(exc, capsys) and "add --overwrite to replace it" in str(exc.value.code)
    with pytest.raises(SystemExit) as exc:
        tune.main(["--bandwidth", "-3", "--out", str(tmp_path / "s.yaml")])
    assert "--bandwidth = -3.0: a number in (0.0, 10000.0]" in _one_line(exc, capsys)
    assert shipped.read_bytes() == before


def test_tune_writes_where_it_is_told(tmp_path, capsys):
    import yaml

    from lvgym.baselines.design import tune

    out = tmp_path / "tuned" / "smile.yaml"
    assert tune.main(["--vehicle", "smile", "--times", "28.8", "--out", str(out)]) == 0
    doc = yaml.safe_load(out.read_text())
    assert [r["time_s"] for r in doc["rows"]] == [28.8] and doc["rows"][0]["kp"] > 0
    assert f"--out {out}" in out.read_text().splitlines()[0]
    assert "replace it with --overwrite" in capsys.readouterr().out
