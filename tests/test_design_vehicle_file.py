"""The design tools take a user's vehicle file as they take a shipped name (issue "Any vehicle").

The made-up vehicle is SMILE v1 with fins of 0.5 m span in place of 1.1 m (root chord 1.2 m, tip 0.6 m):
the same mass model, statically unstable in the atmosphere, so with the gimbal centred it leaves the
q-alpha limit near 10.6 s and only a stabilising controller flies it further.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from lvgym.errors import ConfigError

SMILE_V1 = Path(__file__).resolve().parents[1] / "lvgym" / "vehicles" / "smile_v1.yaml"


@pytest.fixture(scope="module")
def stubby(tmp_path_factory) -> str:
    text = SMILE_V1.read_text()
    text = text.replace("name: smile_v1", "name: stubby")
    old = "fins: {count: 4, root_chord: 2.2, tip_chord: 1.0, span: 1.1,"
    assert old in text
    text = text.replace(old, "fins: {count: 4, root_chord: 1.2, tip_chord: 0.6, span: 0.5,")
    path = tmp_path_factory.mktemp("vehicle") / "stubby.yaml"
    path.write_text(text)
    return str(path)


def test_linearize_a_vehicle_file(stubby):
    from lvgym.baselines.design import linearize as L

    for t in (3.0, 8.0):
        op = L.operating_point(stubby, t, "rigid", protocol="v1")
        mass = float(op.sim.timeline.interp("mass", [op.t])[0])
        assert mass == pytest.approx(10609.0 - 148.0 * t, abs=2.0)      # lift-off 10,609 kg, 148 kg/s
        assert op.task.vehicle == stubby
        g = L.linearize(op=op)
        assert g.A.shape == (3, 3) and g.state_labels == ["v_z", "theta_y", "omega_y"]
    # smaller fins: the same vehicle less stable (M_alpha larger, the fastest rigid pole further right)
    ref = L.operating_point("smile", 8.0, "rigid", protocol="v1")
    assert L.aero_slopes(op)[1] > L.aero_slopes(ref)[1]
    assert np.linalg.eigvals(L.linearize(op=op).A).real.max() > np.linalg.eigvals(L.linearize(op=ref).A).real.max()
    with pytest.raises(RuntimeError, match=r"flown with the gimbal centred ended at 10\.\d+ s before t = 12"):
        L.operating_point(stubby, 12.0, "rigid", protocol="v1")


def test_rigid_pid_flies_an_unstable_file_vehicle_past_where_centred_fails(stubby):
    from lvgym.baselines.design import tune

    lines: list[str] = []
    doc = tune.schedule(stubby, (3.0, 12.0), protocol="v1", log=lines.append)
    assert [r["time_s"] for r in doc["rows"]] == [3.0, 12.0]
    assert doc["rows"][1]["mass_kg"] == pytest.approx(10609.0 - 148.0 * 12.0, abs=2.0)
    assert all(r["kp"] > 0 and r["ki"] > 0 for r in doc["rows"])
    assert doc["operating_points"]["flown_with"].startswith("the rigid PID schedule of the rows designed so far")
    assert lines[0].startswith("operating points: the rigid PID schedule")
    # a file's default rows: 8 equal parts of its burning flight after the switch-on, the staging coast skipped
    times = tune.default_times(stubby, tune.VEHICLE_TIMES)
    assert len(times) == 8 and list(times) == sorted(times) and 2.0 < times[0] < times[-1] < 70.0
    assert times == (5.6, 12.7, 19.8, 26.9, 34.1, 41.2, 59.3, 66.4)                      # as smile_v1's
    assert not any(43.0 < t < 58.0 for t in times)
    assert tune.default_times("smile", tune.VEHICLE_TIMES) == tune.VEHICLE_TIMES["smile"]


def test_command_lines_design_for_a_file_vehicle(stubby, tmp_path, capsys):
    """``lvgym design pid`` then ``lvgym design pid-flex --fly <that schedule>`` on the file, one short row."""
    from lvgym.cli.main import main

    pid = tmp_path / "pid.yaml"
    assert main(["design", "pid", "--vehicle", stubby, "--protocol", "v1", "--times", "3", "12",
                 "--out", str(pid)]) == 0
    assert f"--vehicle {stubby} --protocol v1 --times 3 12 --out {pid}" in pid.read_text().splitlines()[0]
    assert doc_rows(pid) == [3.0, 12.0]
    flex = tmp_path / "flex" / "stubby_flex.yaml"
    assert main(["design", "pid-flex", "--vehicle", stubby, "--times", "12", "--starts", "0", "--fly", str(pid),
                 "--out", str(flex)]) == 0
    doc = yaml.safe_load(flex.read_text())
    assert doc["vehicle"] == stubby and [r["time_s"] for r in doc["rows"]] == [12.0]
    assert doc["operating_points"]["flown_with"].endswith(f"the gain-scheduled PID of the schedule {pid}")
    assert doc["rows"][0]["mass_kg"] == pytest.approx(10609.0 - 148.0 * 12.0, abs=2.0)
    table = flex.with_name("stubby_flex_margins.md").read_text()
    assert re.search(r"^\| 12(\.0)? \|.*\| yes \|$", table, re.M)
    out = capsys.readouterr().out
    assert f"wrote {flex}" in out and "replace it with --overwrite" not in out


def doc_rows(path: Path) -> list[float]:
    return [r["time_s"] for r in yaml.safe_load(path.read_text())["rows"]]


def test_a_bad_vehicle_path_is_one_line(tmp_path, capsys):
    from lvgym.baselines.design import linearize as L
    from lvgym.baselines.design.target import design_env, stem
    from lvgym.cli.main import main

    missing = tmp_path / "nowhere.yaml"
    with pytest.raises(ConfigError, match="there is no such file"):
        L.operating_point(str(missing), 3.0)
    with pytest.raises(ConfigError, match="one of the shipped vehicles"):
        design_env("falcon", "v1")
    bad = tmp_path / "bad.yaml"
    bad.write_text(SMILE_V1.read_text().replace("mass_flow: 148.0", "mass_flow: -148.0"))
    with pytest.raises(ConfigError) as err:
        design_env(str(bad), "v1")
    assert "bad.yaml" in str(err.value) and "mass_flow" in str(err.value)
    assert design_env("smile", "v0") == ("lvgym/SmileAscent-v0", {})
    assert design_env(str(SMILE_V1), "v1") == ("lvgym/SmileAscent-v1", {"vehicle": str(SMILE_V1)})
    assert stem(str(SMILE_V1)) == "smile_v1" and stem("slender") == "slender"
    for cmd in (["design", "pid"], ["design", "pid-flex"], ["design", "lqg"], ["design", "charts"]):
        with pytest.raises(SystemExit):
            main([*cmd, "--vehicle", str(missing), "--out", str(tmp_path / "o")])
        msg = capsys.readouterr().err.strip()
        assert "--vehicle" in msg and str(missing) in msg and "no such file" in msg and len(msg.splitlines()) <= 3
    with pytest.raises(SystemExit) as exc:                  # a row in the staging coast: refused before any flight
        main(["design", "lqg", "--vehicle", str(SMILE_V1), "--rows", "50"])
    assert "--rows" in str(exc.value.code) and "50" in str(exc.value.code)


def test_margins_command_flies_the_suite_with_a_vehicle_file(stubby, tmp_path, capsys):
    from lvgym.cli.flights import resolve_flights
    from lvgym.cli.margins import parse_args

    a = parse_args(["--vehicle", stubby, "--policies", "zero", "--seeds", "1"])
    assert a.vehicle == stubby
    _, suite, conds = resolve_flights("lvgym margins", a.policies, a.suite, vehicle=a.vehicle)
    assert suite.version.endswith("+override") and dict(suite.overrides)["vehicle"] == stubby
    assert conds and all(dict(c.options)["vehicle"] == stubby for c in conds)
    env = conds[0].make_env()
    assert env.unwrapped.task.vehicle == stubby
    with pytest.raises(SystemExit):
        parse_args(["--vehicle", str(tmp_path / "nowhere.yaml")])
    assert "--vehicle" in capsys.readouterr().err


def test_a_files_burning_flight_gives_the_lqg_phases_and_rows(stubby):
    from lvgym.baselines.design import target

    phases = target.burn_phases(stubby)
    assert phases == ((2.0, 43.0), (54.0, 70.0))          # SMILE v1's stages: the staging coast left out
    rows = target.file_times(stubby)
    assert all(any(a < t < b for a, b in phases) for t in rows)
    from lvgym.baselines.design.lqg_design import row_intervals
    assert len(row_intervals(rows, phases)) == len(rows)   # every row inside a phase, as the design needs


def test_a_relative_table_path_is_read_beside_the_yaml_file(tmp_path, monkeypatch):
    """``aerodynamics: {model: axisymmetric, table: aero.csv}`` in a vehicle file reads ``aero.csv`` from
    the file's folder, whatever the working directory; the tables equal the generator's they were written
    from; an absolute path stays as it is."""
    import yaml

    from lvgym.environment import make
    from lvgym.vehicle import clear_vehicle_cache, load_vehicle

    barrowman = make("aerodynamics", load_vehicle("smile_v1").aerodynamics)
    folder = tmp_path / "rocket"
    folder.mkdir()
    barrowman.to_csv(folder / "aero.csv")
    data = yaml.safe_load(SMILE_V1.read_text())
    data["aerodynamics"] = {"model": "axisymmetric", "table": "aero.csv", "ref_area": barrowman.ref_area,
                            "ref_length": barrowman.ref_length, "x_ref": barrowman.x_ref}
    (folder / "rocket.yaml").write_text(yaml.safe_dump(data))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    clear_vehicle_cache()
    v = load_vehicle(str(folder / "rocket.yaml"))
    assert v.aerodynamics["table"] == str(folder.resolve() / "aero.csv")
    tables = make("aerodynamics", v.aerodynamics)
    got, want = tables.coefficients(1.5, np.radians(4.0)), barrowman.coefficients(1.5, np.radians(4.0))
    assert want["CN"] > 0.0 and set(got) >= {"CA", "CN", "Cm"}
    for key in ("CA", "CN", "Cm"):
        assert got[key] == pytest.approx(want[key], rel=1e-6)
    data["aerodynamics"]["table"] = str(folder / "aero.csv")
    (folder / "absolute.yaml").write_text(yaml.safe_dump(data))
    assert load_vehicle(str(folder / "absolute.yaml")).aerodynamics["table"] == str(folder / "aero.csv")
