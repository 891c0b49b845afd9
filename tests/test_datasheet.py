"""Aerodynamic derivatives from a data sheet (lvgym/environment/datasheet.py): rows over flight time placed
at their Mach number, the table against hand numbers, the sheet's checks, a CSV beside the vehicle file, and
SMILE flown on its own Barrowman derivatives as a sheet."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import lvgym
from lvgym.environment import make
from lvgym.environment.barrowman import BarrowmanAero
from lvgym.environment.datasheet import ALPHA_DEG, DataSheetAero
from lvgym.errors import ConfigError

SHEET = [[0.0, 0.3, 2.0, -6.0, 0.40], [20.0, 1.5, 3.0, -5.0, 0.60], [50.0, 4.0, 2.5, -4.0, 0.30]]


def test_the_table_is_the_sheet_at_its_mach_numbers():
    aero = make("aerodynamics", {"model": "data_sheet", "table": SHEET, "ref_area": 0.5, "ref_length": 10.0})
    assert isinstance(aero, DataSheetAero) and list(aero.axes[0]) == [0.3, 1.5, 4.0]
    a = math.radians(4.0)
    c = aero.coefficients(1.5, a)                       # a row's Mach and a grid angle: exact
    assert c["CN"] == pytest.approx(3.0 * math.sin(a), rel=1e-12)
    assert c["Cm"] == pytest.approx(3.0 * math.sin(a) * (-5.0 - 0.0) / 10.0, rel=1e-12)   # restoring
    assert c["CA"] == pytest.approx(0.60) and c["Cmq"] == 0.0
    mid = aero.coefficients(0.9, a)                     # halfway between the first two rows: linear
    assert mid["CN"] == pytest.approx(2.5 * math.sin(a), rel=1e-12)
    assert mid["Cm"] == pytest.approx(0.5 * (2.0 * -6.0 + 3.0 * -5.0) * math.sin(a) / 10.0, rel=1e-12)
    held = aero.coefficients(6.0, a)                    # beyond the last row: held
    assert held["CN"] == pytest.approx(2.5 * math.sin(a), rel=1e-12)
    assert aero.coefficients(1.5, 0.0)["CN"] == 0.0 and ALPHA_DEG[-1] == 180.0


def test_rows_are_placed_by_mach_so_a_coast_can_come_back_down():
    coast = [[0.0, 0.5, 2.0, -6.0, 0.4], [30.0, 3.0, 2.4, -4.5, 0.3], [60.0, 2.0, 2.6, -4.8, 0.35]]
    aero = DataSheetAero(coast, 0.5, 10.0)
    assert list(aero.axes[0]) == [0.5, 2.0, 3.0]
    assert aero.coefficients(2.0, math.radians(2.0))["CN"] == pytest.approx(2.6 * math.sin(math.radians(2.0)))


@pytest.mark.parametrize("table, message", [
    (SHEET[:1], r"table = .*: at least 2 rows of \[t, mach, CN_alpha, x_cp, CA\]"),
    ([SHEET[0], [20.0, 1.5, 0.0, -5.0, 0.6]], r"table\[1\]: CN_alpha = 0\.0: a number in \(0, 100\] 1/rad"),
    ([SHEET[0], [20.0, 1.5, 3.0, 2.0, 0.6]], r"table\[1\]: x_cp = 2\.0: a number in \[-1000, 0\]"),
    ([SHEET[1], SHEET[0]], r"table\[1\]: t = 0\.0: times increasing from row to row"),
    ([SHEET[0], [20.0, 0.3, 3.0, -5.0, 0.6]], r"table: mach = 0\.3: one row per Mach number"),
    ([SHEET[0], [20.0, 1.5, 3.0]], r"table\[1\] = \[20\.0, 1\.5, 3\.0\]: 5 numbers: t, mach, CN_alpha, x_cp, CA"),
])
def test_a_bad_sheet_names_the_row_the_column_and_what_is_allowed(table, message):
    with pytest.raises(ConfigError, match=message):
        DataSheetAero(table, 0.5, 10.0)


def _smile_sheet(tmp_path: Path, csv: bool) -> Path:
    """SMILE's file with its Barrowman derivatives written as a data sheet over a made-up Mach history."""
    src = Path(lvgym.__file__).parent / "vehicles" / "smile.yaml"
    data = yaml.safe_load(src.read_text(encoding="utf-8"))
    spec = dict(data["aerodynamics"])
    spec.pop("model")
    barrowman = BarrowmanAero(**spec)
    rows = [[5.0 * k, m, barrowman.cn_alpha(m), barrowman.x_cp(m), barrowman.drag(m)["total"]]
            for k, m in enumerate((0.0, 0.3, 0.6, 0.9, 1.2, 1.6, 2.0, 3.0, 4.0, 5.0, 6.0))]
    table: object = rows
    if csv:
        (tmp_path / "sheet.csv").write_text("# made from SMILE's Barrowman tables\nt,mach,CN_alpha,x_cp,CA\n"
                                            + "".join(",".join(f"{v:.10g}" for v in r) + "\n" for r in rows))
        table = "sheet.csv"
    data["aerodynamics"] = {"model": "data_sheet", "table": table, "ref_area": barrowman.s_ref,
                            "ref_length": barrowman.length}
    for stage in data["stages"]:
        stage.pop("aerodynamics", None)
    path = tmp_path / "smile_sheet.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


@pytest.mark.parametrize("csv", [False, True])
def test_smile_flies_on_its_derivatives_as_a_sheet(tmp_path, csv):
    """Its own derivatives as a sheet: the same flight as on Barrowman's tables for the first seconds, within
    what the sheet leaves out (Barrowman's body lift at angle, its damping)."""
    path = _smile_sheet(tmp_path, csv)
    flown = []
    for vehicle in ("smile", str(path)):
        env = lvgym.make_env("smile-v2", "rigid", vehicle=vehicle, mission_time_s=8.0, randomize=[], wind="none")
        obs, info = env.reset(seed=0)
        done = False
        while not done:
            obs, _, terminated, truncated, info = env.step(np.zeros(2, np.float32))
            done = terminated or truncated
        flown.append((info["time"], info["mach"], info["qbar"], info["alpha_total"]))
    (t0, m0, q0, a0), (t1, m1, q1, a1) = flown
    assert t0 == t1 == pytest.approx(8.0)
    assert m1 == pytest.approx(m0, rel=0.01) and q1 == pytest.approx(q0, rel=0.02)
    assert abs(a1 - a0) < math.radians(0.5)


def test_the_tutorials_sheet_flies_kestrel(tmp_path):
    """docs/own-launcher.md section 8's data sheet, in place of Kestrel's Barrowman section, flies."""
    import re

    page = (Path(__file__).resolve().parents[1] / "docs" / "own-launcher.md").read_text(encoding="utf-8")
    kestrel = yaml.safe_load(re.findall(r"```yaml\n(.*?)```", page, re.DOTALL)[0])
    sheet = next(b for b in re.findall(r"```text\n(.*?)```", page, re.DOTALL) if "model: data_sheet" in b)
    kestrel["aerodynamics"] = yaml.safe_load(sheet)["aerodynamics"]
    path = tmp_path / "kestrel_sheet.yaml"
    path.write_text(yaml.safe_dump(kestrel, sort_keys=False), encoding="utf-8")
    env = lvgym.make_env("smile-v2", "rigid", vehicle=str(path), mission_time_s=3.0, randomize=[], wind="none")
    obs, info = env.reset(seed=0)
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(np.zeros(2, np.float32))
        done = terminated or truncated
    assert truncated and not terminated and info["time"] == pytest.approx(3.0) and info["mach"] > 0.05
