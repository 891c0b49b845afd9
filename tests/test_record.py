"""Trajectory recording: the columns, agreement with the simulator's read-outs, CSV and Parquet round
trips, atomic saves, the plot, and :func:`fly`'s interval and events."""

import math
import os

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from lvgym.simulator import Simulator, SimView, TimelineSpec
from lvgym.simulator.record import FORMATS, PANELS, Recorder, fly, load

DEG = math.degrees(1.0)
BASE = ["t_s", "r_x_m", "r_y_m", "r_z_m", "v_x_mps", "v_y_mps", "v_z_mps", "q0", "q1", "q2", "q3", "p_radps",
        "q_radps", "r_radps", "altitude_m", "mach", "qbar_pa", "alpha_deg", "beta_deg", "alpha_total_deg",
        "wind_n_mps", "wind_e_mps", "wind_d_mps", "gimbal_pitch_deg", "gimbal_yaw_deg", "cg_offset_y_m",
        "cg_offset_z_m", "mass_kg", "cg_x_m", "Ixx_kgm2", "Iyy_kgm2", "Izz_kgm2", "thrust_n", "stage", "events"]


def wobble(view: SimView) -> np.ndarray:
    """A small gimbal command that differs per row and over time [rad] (``view``: the rows' read-outs)."""
    rows = np.arange(view.batch)[:, None]
    return 0.002 * np.sin(3.0 * view.t[:, None] + rows) * np.array([[1.0, -0.5]])


@pytest.fixture(scope="module")
def flown():
    sim = Simulator("stratos3", "nonrigid", timeline=TimelineSpec(t_end=3.0))
    data = sim.reset(batch=2)
    return sim, fly(sim, data, 1.0, record_dt=0.1, step_dt=0.02, gimbal=wobble), data


def test_columns_present_and_finite(flown):
    sim, rec, _ = flown
    df = rec.frame()
    tank = sim.timeline.slosh_names[0]
    expected = BASE + [f"slosh_{tank}_y_deg", f"slosh_{tank}_z_deg", f"slosh_{tank}_mass_kg"]
    expected += [f"eta_{p}{k}" for p in "yz" for k in range(sim.dynamics.n_modes)]
    assert sim.dynamics.n_modes > 0 and sim.dynamics.n_slosh == 1
    assert set(expected) <= set(df.columns)
    assert len(df) == 11
    numbers = df.drop(columns=["stage", "events"])
    assert all(np.issubdtype(d, np.floating) for d in numbers.dtypes)
    assert np.isfinite(numbers.to_numpy()).all()
    assert (df["stage"] == sim.timeline.stage_names[0]).all()
    assert df["mass_kg"].is_monotonic_decreasing and df["altitude_m"].iloc[-1] > df["altitude_m"].iloc[0]
    np.testing.assert_allclose(np.linalg.norm(df[["q0", "q1", "q2", "q3"]].to_numpy(), axis=1), 1.0, atol=1e-9)


def test_values_agree_with_the_simulator_at_the_snapshot():
    sim = Simulator("stratos3", "nonrigid", timeline=TimelineSpec(t_end=3.0))
    data = sim.reset(batch=3)
    rec = Recorder(sim, data, rows=[2, 0])
    rec.snapshot(data)
    v = sim.view(data)
    for _ in range(40):
        rec.add_events(sim.step(data, wobble(v), 0.02))
    rec.snapshot(data)
    tl = sim.timeline
    sim = v                                                      # the rows' read-outs, by name
    for b in (2, 0):
        last = rec.frame(b).iloc[-1]
        assert last["t_s"] == sim.t[b]
        for col, name in (("altitude_m", "altitude"), ("mach", "mach"), ("qbar_pa", "qbar"),
                          ("airspeed_mps", "airspeed")):
            assert last[col] == sim.conditions(name)[b], col
        for col, name in (("alpha_deg", "alpha"), ("beta_deg", "beta"), ("alpha_total_deg", "alpha_total")):
            assert last[col] == pytest.approx(DEG * sim.conditions(name)[b], rel=1e-14, abs=1e-14), col
        np.testing.assert_array_equal(last[["wind_n_mps", "wind_e_mps", "wind_d_mps"]].to_numpy(float),
                                      sim.conditions("wind_n")[b])
        for cols, name in ((["r_x_m", "r_y_m", "r_z_m"], "r_zw_i"), (["v_x_mps", "v_y_mps", "v_z_mps"], "v_zw_i"),
                           (["q0", "q1", "q2", "q3"], "q_bi"), (["p_radps", "q_radps", "r_radps"], "omega_bi_b")):
            np.testing.assert_array_equal(last[cols].to_numpy(float), sim.state(name)[b])
        K = tl.dynamics.n_modes
        eta = sim.state("eta")[b]
        np.testing.assert_array_equal(last[[f"eta_y{k}" for k in range(K)]].to_numpy(float), eta[0])
        np.testing.assert_array_equal(last[[f"eta_z{k}" for k in range(K)]].to_numpy(float), eta[1])
        tank = tl.slosh_names[0]
        np.testing.assert_allclose(last[[f"slosh_{tank}_y_deg", f"slosh_{tank}_z_deg"]].to_numpy(float),
                                   DEG * sim.slosh_angles()[b, 0], rtol=1e-14)
        assert last[f"slosh_{tank}_mass_kg"] == pytest.approx(tl.interp("slosh_mass", sim.t[[b]])[0, 0], rel=1e-14)
        np.testing.assert_array_equal(last[["cg_offset_y_m", "cg_offset_z_m"]].to_numpy(float),
                                      sim.lateral_cg_offset()[b])
        np.testing.assert_allclose(last[["gimbal_pitch_deg", "gimbal_yaw_deg"]].to_numpy(float),
                                   DEG * sim.gimbal[b], rtol=1e-14)
        t = sim.t[[b]]
        assert last["mass_kg"] == pytest.approx(tl.interp("mass", t)[0], rel=1e-14)
        assert last["cg_x_m"] == pytest.approx(tl.interp("cg", t)[0, 0], rel=1e-14)
        np.testing.assert_allclose(last[["Ixx_kgm2", "Iyy_kgm2", "Izz_kgm2"]].to_numpy(float),
                                   np.diag(tl.interp("inertia", t)[0]), rtol=1e-14)
        thrust = tl.interp("thrust0", t)[0] - tl.interp("exit_area", t)[0] * sim.conditions("pressure")[b]
        assert last["thrust_n"] == pytest.approx(thrust, rel=1e-12) and thrust > 0.0
    with pytest.raises(ValueError, match="not recorded"):
        rec.frame(1)
    assert rec.frame().equals(rec.frame(2))                       # default: the first recorded row


def test_rigid_model_has_no_slosh_or_eta_columns():
    sim = Simulator("stratos3", "rigid", timeline=TimelineSpec(t_end=3.0))
    df = fly(sim, sim.reset(), 0.5, record_dt=0.1).frame()
    assert not [c for c in df.columns if c.startswith(("slosh_", "eta_"))]
    assert set(BASE) <= set(df.columns)
    assert (df[["cg_offset_y_m", "cg_offset_z_m"]].to_numpy() == 0.0).all()
    assert np.isfinite(df.drop(columns=["stage", "events"]).to_numpy()).all()


def test_fly_records_at_the_interval_and_carries_the_events(flown):
    sim, rec, data = flown
    for b in (0, 1):
        df = rec.frame(b)
        np.testing.assert_allclose(np.diff(df["t_s"].to_numpy()), 0.1, atol=1e-9)
        assert df["t_s"].iloc[0] == 0.0 and df["t_s"].iloc[-1] == pytest.approx(1.0, abs=1e-9)
        hits = df.index[df["events"].str.contains("lift-off")].tolist()
        assert len(hits) == 1 and (df["events"] != "").sum() == 1
        t_event = [t for t, e in rec.events[recorded(rec, b)] if e == "lift-off"]
        assert len(t_event) == 1
        assert df["t_s"][hits[0] - 1] < t_event[0] <= df["t_s"][hits[0]] + 1e-12
        assert df["events"][hits[0]] == f"{t_event[0]:.3f} s lift-off"
    # the gimbal callable was evaluated at every step: the column holds the last command of each interval
    df = rec.frame(1)
    np.testing.assert_allclose(df[["gimbal_pitch_deg", "gimbal_yaw_deg"]].to_numpy()[-1], DEG * sim.gimbal(data)[1])
    assert df["gimbal_pitch_deg"].iloc[1:].nunique() == 10


def recorded(rec: Recorder, row: int) -> int:
    return int(np.flatnonzero(rec.rows == row)[0])


def test_fly_continues_from_the_current_time_with_uneven_intervals():
    sim = Simulator("stratos3", "rigid", timeline=TimelineSpec(t_end=3.0))
    data = sim.reset()
    first = fly(sim, data, 0.3, record_dt=0.1)
    second = fly(sim, data, 0.25, record_dt=0.07, step_dt=0.02, gimbal=np.array([[0.001, 0.0]]))
    t = second.frame()["t_s"].to_numpy()
    np.testing.assert_allclose(t, [0.3, 0.37, 0.44, 0.51, 0.55], atol=1e-9)
    assert first.frame()["t_s"].iloc[-1] == t[0]
    np.testing.assert_allclose(second.frame()["gimbal_pitch_deg"].iloc[1:], DEG * 0.001, rtol=1e-14)
    short = fly(sim, data, 0.03, record_dt=0.1)
    np.testing.assert_allclose(short.frame()["t_s"], [0.55, 0.58], atol=1e-9)
    with pytest.raises(ValueError):
        fly(sim, data, 0.0)


def test_snapshot_accumulates_the_events_of_several_steps():
    sim = Simulator("stratos3", "rigid", timeline=TimelineSpec(t_end=3.0))
    data = sim.reset(batch=2)
    rec = Recorder(sim, data, rows=[1])
    rec.snapshot(data)
    events = [sim.step(data, [[0.0, 0.0]], 0.02) for _ in range(10)]
    for ev in events[:-1]:
        rec.add_events(ev)
    rec.snapshot(data, events=events[-1])
    rec.snapshot(data, [[], []])
    df = rec.frame(1)
    assert df["events"].tolist()[0] == "" and "lift-off" in df["events"][1] and df["events"][2] == ""
    with pytest.raises(ValueError, match="batch of 2"):
        rec.snapshot(data, events=[[]])
    with pytest.raises(ValueError, match="rows"):
        Recorder(sim, data, rows=[2])


@pytest.mark.parametrize("suffix", FORMATS)
def test_saved_files_read_back_equal_to_the_frame(flown, tmp_path, suffix):
    _, rec, _ = flown
    path = rec.save(tmp_path / "sub" / f"run{suffix}", row=1)
    assert path.exists() and path.parent.name == "sub"
    df = rec.frame(1)
    if suffix == ".parquet":
        pd.testing.assert_frame_equal(pd.read_parquet(path), df, check_exact=True)
    else:
        exact = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}   # pandas 3: the default
        plain = pd.read_csv(path, keep_default_na=False, **exact)
        pd.testing.assert_frame_equal(plain, df, check_dtype=False, rtol=1e-15, atol=0.0)
    pd.testing.assert_frame_equal(load(path), df, check_exact=True)


def test_save_is_atomic(flown, tmp_path, monkeypatch):
    _, rec, _ = flown
    target = tmp_path / "run.parquet"
    rec.save(target)
    rec.save(tmp_path / "run.csv")
    assert sorted(os.listdir(tmp_path)) == ["run.csv", "run.parquet"]
    before = target.read_bytes()

    def half_written(self, path, *args, **kwargs):
        with open(path, "wb") as fh:
            fh.write(b"PAR1 half")
        raise KeyboardInterrupt("killed while writing")

    monkeypatch.setattr(pd.DataFrame, "to_parquet", half_written)
    with pytest.raises(KeyboardInterrupt):
        rec.save(target)
    assert target.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["run.csv", "run.parquet"]
    with pytest.raises(ValueError, match=r"'\.txt'.*\.csv.*\.parquet"):
        rec.save(tmp_path / "run.txt")
    assert sorted(os.listdir(tmp_path)) == ["run.csv", "run.parquet"]


def test_plot_has_the_panels_and_writes_a_png(flown, tmp_path):
    _, rec, _ = flown
    path = tmp_path / "run.png"
    fig = rec.plot(row=0, path=path)
    assert isinstance(fig, Figure)
    titles = [a.get_title() for a in fig.axes if a.get_title()]
    assert titles == list(PANELS)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    t_liftoff = [t for t, e in rec.events[0] if e == "lift-off"][0]
    altitude = fig.axes[0]
    assert any(np.allclose(line.get_xdata(), t_liftoff) for line in altitude.get_lines())
    slosh = fig.axes[PANELS.index("slosh angles")]
    assert len(slosh.get_lines()) >= 2
    rigid = Simulator("stratos3", "rigid", timeline=TimelineSpec(t_end=3.0))
    fig = fly(rigid, rigid.reset(), 0.2).plot()
    eta = fig.axes[PANELS.index("eta")]
    assert [t.get_text() for t in eta.texts] == ["none in this model"]
