"""Thesis studies (lvgym.studies, thesis 6.1-6.2, case D): responses by hand, the run cache, the executor,
the ANOVA layout, and the 4-run fractional DOE end to end (runs, resume from the cache, CLI). The full
studies (32-run DOE, L/D and T/W sweeps) are marked slow: ``pytest -m slow tests/test_studies.py``."""

import math

import numpy as np
import pandas as pd
import pytest

from lvgym.studies import RunSetup, doe_study, ld_sweep_study, responses, tw_sweep_study
from lvgym.studies.__main__ import main
from lvgym.studies.cache import RunCache, run_key
from lvgym.studies.doe import anova, design
from lvgym.parallel import run_map
from lvgym.studies.responses import deflection
from lvgym.studies.runs import case, run_cases


# ------------------------------------------------------------------------------ responses by hand
def test_responses_hand_numbers():
    t = np.array([0.0, 1.0, 2.0])
    # one mode per plane: |eta_y| + |eta_z| = 0, 3, 1 -> trapezoid 1.5 + 2.0 = 3.5, max 3
    eta = np.array([[0.0, 0.0], [1.0, -2.0], [-0.5, 0.5]]).reshape(3, 2, 1)
    cg = np.array([[0.0, 0.0], [0.1, 0.0], [0.0, -0.3]])            # 0, 0.1, 0.3 -> 0.05 + 0.2 = 0.25
    r = responses(t, eta, cg)
    assert r["flex_total"] == pytest.approx(3.5)
    assert r["flex_max"] == pytest.approx(3.0)
    assert r["cg_total"] == pytest.approx(0.25)
    assert r["cg_max"] == pytest.approx(0.3)
    assert math.isnan(r["defl_total"]) and math.isnan(r["defl_max"])


def test_responses_sum_modes_and_ignore_nan_cg_of_an_empty_tank():
    t = np.array([0.0, 2.0])
    eta = np.array([[[1.0, -1.0], [0.0, 2.0]], [[0.0, 0.0], [0.0, 0.0]]])     # 1 + 1 + 0 + 2 = 4, then 0
    r = responses(t, eta, np.array([[0.2, 0.0], [np.nan, np.nan]]))
    assert r["flex_max"] == pytest.approx(4.0) and r["flex_total"] == pytest.approx(4.0)
    assert r["cg_total"] == pytest.approx(0.2)


def test_deflection_is_the_largest_station_sum_of_mode_shapes_times_eta():
    # two stations, two modes; y plane eta (1, 2), z plane eta (0, -1)
    phi = np.array([[0.1, 0.2], [-0.3, 0.05]])
    eta = np.array([[[1.0, 2.0], [0.0, -1.0]]])
    # station 0: w_y = 0.1 + 0.4 = 0.5, w_z = -0.2 -> 0.7; station 1: w_y = -0.3 + 0.1 = -0.2, w_z = -0.05 -> 0.25
    assert deflection(phi, eta) == pytest.approx([0.7])
    r = responses(np.array([0.0, 1.0]), np.repeat(eta, 2, axis=0), np.zeros((2, 2)), deflection(phi, np.repeat(eta, 2, 0)))
    assert r["defl_max"] == pytest.approx(0.7) and r["defl_total"] == pytest.approx(0.7)


# ------------------------------------------------------------------------------ cache and executor
def test_run_key_is_stable_and_the_cache_is_a_file_per_run(tmp_path):
    a = run_key({"diameter": 0.1 + 0.2, "setup": {"t_end": 12.0}})
    assert a == run_key({"setup": {"t_end": 12.0}, "diameter": 0.3})
    assert a != run_key({"diameter": 0.31, "setup": {"t_end": 12.0}})
    cache = RunCache(tmp_path / "c")
    assert cache.get(a) is None and len(cache) == 0
    cache.put(a, {"flex_max": 1.5, "t_burnout": float("nan")})
    got = cache.get(a)
    assert got["flex_max"] == 1.5 and math.isnan(got["t_burnout"])
    assert [p.name for p in (tmp_path / "c").iterdir()] == [f"{a}.json"]      # no temporary file left


def _square(x: int) -> int:
    return x * x


@pytest.mark.parametrize("executor", ["serial", "local"])
def test_run_map_keeps_the_task_order_and_reports_each_result(executor):
    seen = {}
    out = run_map(_square, list(range(6)), executor=executor, workers=2, progress=False,
                  on_result=lambda i, r: seen.__setitem__(i, r))
    assert out == [0, 1, 4, 9, 16, 25]
    assert seen == dict(enumerate(out))
    with pytest.raises(ValueError, match="executor"):
        run_map(_square, [1], executor="dask")


# ------------------------------------------------------------------------------ design and ANOVA
def test_full_design_is_table_6_2_and_anova_has_the_layout_of_tables_6_5_to_6_8():
    d = design()
    assert len(d) == 32 and len(d.drop_duplicates(["length", "diameter", "slosh_damping", "mass_flow", "fill"])) == 32
    assert d.iloc[0][["length", "diameter", "slosh_damping", "mass_flow", "fill"]].tolist() == [8.5, 0.3, 0.8, 30, 1]
    assert d.iloc[1]["fill"] == 0.8 and d.iloc[-1][["length", "diameter", "slosh_damping", "mass_flow", "fill"]].tolist() == [7.5, 0.26, 0.5, 20, 0.8]
    rng = np.random.default_rng(1)
    d["y"] = 3.0 * d["c_length"] + 1.0 * d["c_length"] * d["c_diameter"] + 0.1 * rng.normal(size=32)
    a = anova(d, "y")
    assert list(a.index[:5]) == ["Length", "Fill ratio", "Mass flow rate", "Damping ratio", "Diameter"]
    assert list(a.index[-2:]) == ["Error", "Total"] and len(a) == 17
    assert list(a.columns) == ["Sum of squares", "D.o.F", "Mean square", "F", "p"]
    assert a.loc["Error", "D.o.F"] == 16 and a.loc["Total", "D.o.F"] == 31
    # orthogonal design: the effect sums of squares and the error add up to the total
    assert a["Sum of squares"].iloc[:-1].sum() == pytest.approx(a.loc["Total", "Sum of squares"])
    assert a.loc["Length", "Sum of squares"] == pytest.approx(32 * 9.0, rel=0.05)
    assert a.loc["Length", "p"] < 1e-10 and a.loc["Length*Diameter", "p"] < 1e-10
    assert a.loc["Damping ratio", "p"] > 0.001


# ------------------------------------------------------------------------------ 4-run fraction end to end
@pytest.fixture(scope="module")
def fraction_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("doe-fraction")


def test_fractional_doe_end_to_end_then_resumes_from_the_cache(fraction_dir):
    res = doe_study(fraction_dir, fraction=True, executor="local", workers=2, progress=False)
    assert (res.ran, res.cached, len(res.table)) == (4, 0, 4)
    t = res.table
    assert sorted(zip(t["length"], t["diameter"])) == [(7.5, 0.26), (7.5, 0.3), (8.5, 0.26), (8.5, 0.3)]
    for r in ("flex_total", "flex_max", "cg_total", "cg_max", "defl_total", "defl_max"):
        assert np.all(np.isfinite(t[r])) and np.all(t[r] > 0), r
    assert not t["departed"].any()
    # the beam analysis: the longer, thinner vehicle bends at the lowest frequency
    f1 = t.set_index(["length", "diameter"])["f1_hz"]
    assert f1[(8.5, 0.26)] == f1.min() and f1[(7.5, 0.3)] == f1.max()
    a = res.anova["flex_total"]
    assert list(a.index) == ["Length", "Diameter", "Error", "Total"] and a.shape == (4, 5)
    assert a.loc["Error", "D.o.F"] == 1
    for name in ("runs.csv", "report.md", "studies_doe_runs.png", "studies_doe_effects.png", "anova_cg_max.csv"):
        assert (fraction_dir / name).stat().st_size > 0, name
    assert len(pd.read_csv(fraction_dir / "runs.csv")) == 4
    again = doe_study(fraction_dir, fraction=True, executor="local", workers=2, progress=False)
    assert (again.ran, again.cached) == (0, 4)
    pd.testing.assert_frame_equal(again.table.drop(columns="wall_s"), res.table.drop(columns="wall_s"))


def test_an_interrupted_study_runs_only_what_is_missing(fraction_dir, tmp_path):
    setup = RunSetup()
    cases = [case(r.length, r.diameter, r.fill, r.mass_flow, r.slosh_damping, setup) | {"run": int(r.run)}
             for r in design(fraction=True).itertuples()]
    src, dst = RunCache(fraction_dir / "cache"), RunCache(tmp_path / "cache")
    for c in cases[:3]:                                   # three runs had finished when it was stopped
        key = run_key({k: v for k, v in c.items() if k != "run"})
        dst.put(key, src.get(key))
    res = run_cases(cases, tmp_path / "cache", executor="serial", progress=False)
    assert (res.ran, res.cached) == (1, 3) and len(dst) == 4


def test_cli_reuses_the_cache(fraction_dir, capsys):
    assert main(["doe", "--fraction", "--executor", "serial", "--out", str(fraction_dir), "--no-progress"]) == 0
    assert "4 runs (0 run, 4 cached)" in capsys.readouterr().out


# ------------------------------------------------------------------------------ the full studies (slow)
@pytest.mark.slow
def test_full_doe_damping_never_significant_length_and_fill_always(tmp_path):
    res = doe_study(tmp_path, executor="local", progress=False)
    assert res.ran == 32 and not res.table["departed"].any()
    for r in ("flex_total", "flex_max", "cg_total", "cg_max"):
        a = res.anova[r]
        assert a.loc["Error", "D.o.F"] == 16
        assert a.loc["Damping ratio", "p"] > 0.2, r                       # thesis: never significant
        assert a.loc["Length", "p"] < 0.05 and a.loc["Fill ratio", "p"] < 0.05, r
    assert res.anova["flex_max"].loc["Length*Diameter", "p"] < 0.05      # thesis Table 6.6
    assert res.anova["cg_total"].loc["Mass flow rate", "p"] < 0.05       # thesis Table 6.7


@pytest.mark.slow
def test_ld_sweep_flex_rises_with_slenderness_and_slosh_offset_falls(tmp_path):
    res = ld_sweep_study(tmp_path, step=0.01, progress=False)
    t = res.table.sort_values("ld")
    assert len(t) == 31 and not t["departed"].any()
    lo, hi = t.iloc[0], t.iloc[-1]
    assert hi["defl_max"] > 3 * lo["defl_max"] and lo["cg_total"] > 3 * hi["cg_total"]
    assert np.all(np.diff(t["f1_hz"].to_numpy()) < 0)                  # thinner: lower first frequency


@pytest.mark.slow
def test_tw_sweep_runs_and_thrust_to_weight_grows_with_mass_flow(tmp_path):
    res = tw_sweep_study(tmp_path, step=2.0, progress=False)
    t = res.table.sort_values("mass_flow")
    assert len(t) == 11 and np.all(np.diff(t["tw0"].to_numpy()) > 0)


@pytest.mark.slow
def test_ray_executor_matches_serial():
    import ray  # noqa: F401  (a test dependency: a missing Ray fails here; tests/test_ray.py runs a real cluster)

    tasks = [{"diameter": d} for d in (0.2, 0.3, 0.4)]         # an lvgym function: Ray workers import it
    assert run_map(run_key, tasks, executor="ray", workers=2, progress=False) == [run_key(t) for t in tasks]
