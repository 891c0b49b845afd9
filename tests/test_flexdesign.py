"""gs-pid-flex: the structural filters, the filtered scheduled PID and its design on the v1 flight loop
(lvgym.baselines.filters, lvgym.baselines.pid, lvgym.baselines.design.flexdesign)."""

import math
import warnings

import control
import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.baselines.design import flexdesign as FD
from lvgym.baselines.design import linearize as L
from lvgym.baselines.filters import StructuralFilter
from lvgym.baselines.pidkernel import filter_reset_k, filter_row, filter_update_k
from lvgym.baselines.pid import SCHEDULES, GainSchedule, GainScheduledPIDPolicy

DT = 0.02
FILT = StructuralFilter(lead_zero_radps=5.0, lead_pole_radps=50.0, lowpass_radps=120.0, lowpass_damping=0.5,
                        notch_radps=71.0, notch_damping=0.1, notch_depth=0.2)


def _gain(g, w):
    return abs(complex(g(np.exp(1j * w * DT))))


def test_filter_sections_by_hand():
    """Each section has unit gain at zero frequency; the prewarped notch has exactly its depth at its
    centre, the low-pass 1 / (2 zeta) at its corner, the lead-lag w_p / w_z far above both."""
    assert _gain(FILT.tf(DT), 1e-6) == pytest.approx(1.0, rel=1e-9)
    notch = StructuralFilter(lead_zero_radps=1.0, lead_pole_radps=1.0, lowpass_radps=5000.0,
                             notch_radps=71.0, notch_damping=0.1, notch_depth=0.2)
    lp_only = StructuralFilter(lowpass_radps=5000.0)          # the low-pass far off: its prewarp is clamped
    ratio = _gain(notch.tf(DT), 71.0) / _gain(lp_only.tf(DT), 71.0)
    assert ratio == pytest.approx(0.2, rel=1e-9)
    lp = StructuralFilter(lowpass_radps=60.0, lowpass_damping=0.5, notch_depth=1.0)
    assert _gain(lp.tf(DT), 60.0) == pytest.approx(1.0, rel=1e-9)      # 1 / (2 * 0.5)
    lead = StructuralFilter(lead_zero_radps=2.0, lead_pole_radps=20.0, lowpass_radps=5000.0)
    hi = _gain(lead.tf(DT), 100.0) / _gain(lp_only.tf(DT), 100.0)
    assert hi == pytest.approx(abs((100j / 2 + 1) / (100j / 20 + 1)), rel=0.05)  # Tustin warps a little at 100 rad/s


def test_the_laws_filter_runs_the_transfer_function_and_starts_in_steady_state():
    x = np.random.default_rng(0).normal(size=80)
    f, sections = filter_row(FILT, DT)
    y = [filter_update_k(f, 0, v, sections) for v in x]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = np.ravel(control.forced_response(FILT.tf(DT), U=x).outputs)
    np.testing.assert_allclose(y, ref, atol=1e-12)
    filter_reset_k(f, 1, 0.3, sections)
    assert [filter_update_k(f, 1, 0.3, sections) for _ in range(5)] == pytest.approx([0.3] * 5, abs=1e-12)


def test_filter_values_are_checked():
    with pytest.raises(ValueError, match="notch_depth"):
        StructuralFilter(notch_depth=1.5)
    with pytest.raises(ValueError, match="lowpass_radps"):
        StructuralFilter(lowpass_radps=float("nan"))
    with pytest.raises(ValueError, match="allowed are"):
        StructuralFilter.from_dict({"notch_hz": 3.0})
    with pytest.raises(ValueError, match="bending1"):
        FD.Requirements(bending1="both")


def test_schedule_with_filters_interpolates_them():
    rows = [{"mass_kg": 100.0, "kp": 1.0, "ki": 0.0, "kd": 0.0, "filter": {"notch_radps": 60.0, "notch_depth": 0.2}},
            {"mass_kg": 50.0, "kp": 2.0, "ki": 0.0, "kd": 0.0, "filter": {"notch_radps": 80.0, "notch_depth": 1.0}}]
    s = GainSchedule.from_dict({"variable": "mass", "rows": rows})
    f = s.filter_at(75.0)
    assert f.notch_radps == pytest.approx(70.0) and f.notch_depth == pytest.approx(0.6)
    assert s.gains(75.0)[0] == pytest.approx(1.5) and math.isinf(s.gains(75.0)[3])
    near = GainSchedule.from_dict({"variable": "mass", "interpolation": "nearest", "rows": rows})
    assert near.filter_at(80.0).notch_radps == 60.0 and near.filter_at(70.0).notch_radps == 80.0
    assert near.gains(76.0)[0] == 1.0 and near.gains(74.0)[0] == 2.0
    with pytest.raises(ValueError, match="interpolation"):
        GainSchedule.from_dict({"variable": "mass", "interpolation": "cubic", "rows": rows})
    with pytest.raises(ValueError, match="every row or none"):
        GainSchedule.from_dict({"variable": "mass", "rows": [rows[0], {k: v for k, v in rows[1].items() if k != "filter"}]})


def test_policy_law_is_the_designed_controller():
    """The gimbal the filtered scheduled PID commands from a sequence of rate errors equals the output
    of C(z) = PID(z) F(z) (:func:`lvgym.baselines.design.flexdesign.controller_tf`) for the same sequence."""
    env = gym.make("lvgym/SmileAscent-v1")
    row = {"mass_kg": 6000.0, "kp": 0.3, "ki": 0.4, "kd": 0.01, "filter": FILT.as_dict()}
    pol = GainScheduledPIDPolicy(GainSchedule.from_dict({"variable": "mass", "rows": [row]}), env=env)
    lay = env.unwrapped.observation_layout
    obs = np.zeros(env.observation_space.shape, np.float32)
    obs[lay.index("controller_on")] = 1.0
    e = np.r_[np.zeros(3), 1e-3 * np.random.default_rng(1).normal(size=60)]   # rate error [rad/s], small: no limit
    e = e.astype(np.float32).astype(float)                # as the observation carries it
    u = []
    for v in e:
        obs[lay.index("pitch_rate_error")] = v
        pol.act(obs, {"mass": 6000.0, "time": 10.0})
        u.append(pol.last_gimbal[0])
    C = FD.controller_tf((0.3, 0.4, 0.01), FILT, DT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = np.ravel(control.forced_response(C, U=-e).outputs)
    np.testing.assert_allclose(u, ref, atol=1e-12)


def test_folded_frequency_by_hand():
    assert FD.folded(196.68, DT) == pytest.approx(2 * math.pi / DT - 196.68)
    assert FD.folded(71.0, DT) == pytest.approx(71.0)
    assert FD.folded(561.6, DT) == pytest.approx(2 * 2 * math.pi / DT - 561.6)


def test_row_problem_with_a_fixed_integral_and_the_vehicle_drift():
    """A first-order plant ``0.02 / (z - 1.01)`` (rigid and non-rigid alike, no modes) grows by
    ln(1.01) / 0.02 = 0.49752 1/s with the gimbal held (:func:`open_loop_growth`). With
    ``drift="vehicle"`` the drift penalty allows exactly that growth, with ``"requirement"`` 0.8 times
    0.02 = 0.016 1/s. A fixed integral stays out of the optimiser's vector and in every parameter set it
    gives; a fixed name or value outside the parameters is refused, naming it."""
    g = control.ss(control.tf([0.02], [1.0, -1.01], DT))
    cases = [({"rigid": g, "nonrigid": g}, {})]
    assert FD.open_loop_growth(g.A, DT) == pytest.approx(math.log(1.01) / DT, rel=1e-12)
    assert FD.open_loop_growth(np.diag([1.0, 0.5]), DT) == pytest.approx(math.log(0.5) / DT)   # z = 1 left out
    free = FD.RowProblem(cases, FD.Requirements(), n_grid=200)
    held = FD.RowProblem(cases, FD.Requirements(), n_grid=200, fixed={"ki": 0.0384}, drift="vehicle")
    assert free.allowed_growth == [{"rigid": pytest.approx(0.016), "nonrigid": pytest.approx(0.016)}]
    assert held.allowed_growth[0]["rigid"] == pytest.approx(0.49752, abs=1e-5)
    assert len(free.params) == 9 and len(held.params) == 8 and "ki" not in [p[0] for p in held.params]
    v = held.values(held.to_unit(FD.START))
    assert v["ki"] == 0.0384 and v["kp"] == pytest.approx(FD.START["kp"], rel=1e-9)
    # the same loop's drift excess against the two allowances differs by exactly their difference
    e_free, e_held = free.evaluate(dict(FD.START, ki=0.0384)), held.evaluate(v)
    for m in ("rigid", "nonrigid"):
        assert e_free[m][3] == pytest.approx(e_held[m][3], rel=1e-9)
        assert e_free["drift_excess"][m] - e_held["drift_excess"][m] == pytest.approx(0.49752 - 0.016, abs=1e-5)
    with pytest.raises(ValueError, match="'kq'"):
        FD.RowProblem(cases, FD.Requirements(), fixed={"kq": 1.0})
    with pytest.raises(ValueError, match="ki = -1"):
        FD.RowProblem(cases, FD.Requirements(), fixed={"ki": -1.0})
    with pytest.raises(ValueError, match="drift"):
        FD.RowProblem(cases, FD.Requirements(), drift="none")


@pytest.fixture(scope="module")
def row288():
    plants, modes, info = FD.row_plants("smile", 28.8, None)
    return plants, modes, info


def test_grid_margins_agree_with_the_exact_ones(row288):
    """The optimiser's margins read on its grid agree with :func:`lvgym.baselines.design.linearize.margins` (a
    dense interpolated response) at the shipped 28.8 s row."""
    plants, modes, _ = row288
    sched = GainSchedule.load("smile_flex")
    r = min(sched.meta["rows"], key=lambda r: abs(r["time_s"] - 28.8))
    prob = FD.RowProblem([(plants["pitch"], modes)], FD.Requirements())
    gains, filt = (r["kp"], r["ki"], r["kd"]), StructuralFilter.from_dict(r["filter"])
    C = control.ss(FD.controller_tf(gains, filt, DT))
    b, a = FD._controller_poly(gains, filt, DT)
    Cw = np.polyval(b, prob.z) / np.polyval(a, prob.z)
    for model in ("rigid", "nonrigid"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = L.margins(control.series(plants["pitch"][model], C))
        up, down, pm = prob.grid_margins(Cw * prob.cases[0][0][model])
        assert up == pytest.approx(m["gain_margin_db"], abs=0.3)
        assert pm == pytest.approx(abs(m["phase_margin_deg"]), abs=1.5)
        # the growth rates agree where a loop grows; a decaying loop may keep a pole within 1e-6 of z = 1
        # (the integrator's, cancelled by the plant's zero there), which growth() leaves out and
        # margins() reports as about 0 1/s, so they are compared clipped at 0
        assert max(prob.growth(b, a, model), 0.0) == pytest.approx(max(m["max_pole_real_per_s"], 0.0), abs=1e-6)


def test_shipped_row_meets_the_requirements(row288):
    """The shipped schedule's 28.8 s row, checked again here on freshly built plants (pitch and yaw,
    rigid and non-rigid): rigid 6 dB / 30 deg, non-rigid 6 dB / 30 deg, every bending mode at least
    6 dB below 0 dB over +-15 % of its frequency."""
    plants, modes, _ = row288
    sched = GainSchedule.load("smile_flex")
    r = min(sched.meta["rows"], key=lambda r: abs(r["time_s"] - 28.8))
    chk = FD.check_loops(plants, (r["kp"], r["ki"], r["kd"]), StructuralFilter.from_dict(r["filter"]), modes,
                         FD.Requirements())
    assert chk["meets"], chk
    for key in ("rigid_pitch", "nonrigid_pitch", "rigid_yaw", "nonrigid_yaw"):
        assert chk[key]["gain_margin_db"] >= 5.95 and abs(chk[key]["phase_margin_deg"]) >= 29.5
    assert all(m["loop_gain_db"] <= -6.0 for m in chk["modes"] if m["mode"] == "bending")


def test_shipped_schedule_record():
    """What the shipped schedule's file records for every row and both ends of its stretch: the rigid
    requirements met everywhere, the non-rigid closed loop stable everywhere (no growth beyond the
    drift), and the rows that miss a non-rigid requirement listed as such (docs/flex-design.md)."""
    sched = GainSchedule.load("smile_flex")
    assert sched.interpolation == "nearest" and sched.filters is not None
    for row in sched.meta["rows"]:
        for chk in [row] + row["ends"]:
            for plane in ("pitch", "yaw"):
                m = chk["margins"][f"rigid_{plane}"]
                assert m["gain_margin_db"] >= 5.95 and abs(m["phase_margin_deg"]) >= 29.5, (row["time_s"], m)
                assert chk["margins"][f"nonrigid_{plane}"]["max_pole_real_per_s"] < 0.025
        if row["meets"]:
            assert all(c["meets"] for c in row["ends"])
    assert all(r["meets"] for r in sched.meta["rows"])           # the 12-row schedule meets at every row


def test_stratos3_schedule_was_designed_and_meets_in_both_planes():
    """The shipped Stratos III schedule was designed with the yaw loops in the optimiser
    (``--planes pitch yaw``) and records every row and stretch end meeting the requirements in pitch
    and yaw; a plane list without pitch first is refused."""
    sched = GainSchedule.load("stratos3_flex")
    assert sched.meta["design"]["planes"] == ["pitch", "yaw"]
    for row in sched.meta["rows"]:
        assert row["meets"] and all(c["meets"] for c in row["ends"]), row["time_s"]
        for chk in [row] + row["ends"]:
            for key, m in chk["margins"].items():
                assert m["gain_margin_db"] >= 5.95 and abs(m["phase_margin_deg"]) >= 29.5, (row["time_s"], key, m)
    with pytest.raises(ValueError, match="planes"):
        FD.design_schedule("stratos3", times=(2.0,), planes=("yaw",))


def test_gs_pid_flex_flies_the_nonrigid_v1_vehicle():
    """gs-pid-flex flies SMILE v1 non-rigid through both burns on a validation seed without failure."""
    from lvgym.benchmark.registry import POLICIES
    from lvgym.benchmark.runner import build_policy

    env = gym.make("lvgym/SmileAscent-v1", model="nonrigid")
    pol = build_policy(POLICIES["gs-pid-flex"], env)
    obs, info = env.reset(seed=3)
    pol.reset()
    term = trunc = False
    while not (term or trunc):
        obs, _, term, trunc, info = env.step(pol.act(obs, info))
    assert trunc and not term, info.get("termination")
    assert info["time"] == pytest.approx(70.0, abs=0.03)


def test_design_command_never_overwrites_the_shipped_schedule(tmp_path):
    from lvgym.errors import ConfigError

    from lvgym.baselines.design.tune import output_path

    assert output_path("smile", None, False, stem="smile_flex").name == "smile_flex.yaml"
    assert output_path("smile", None, False, stem="smile_flex").parent != SCHEDULES
    with pytest.raises(ConfigError, match="--overwrite"):
        output_path("smile", str(SCHEDULES / "smile_flex.yaml"), False, stem="smile_flex")
    with pytest.raises(ConfigError, match="--overwrite"):
        output_path("smile", str(SCHEDULES / "smile.yaml"), False)
    with pytest.raises(SystemExit):
        FD.main(["--vehicle", "smile", "--starts", "-1", "--out", str(tmp_path / "x.yaml")])


def test_the_noise_requirement_is_reported_and_held_when_asked(row288):
    """check_loops reports the gimbal rate the gyro's noise commands on every loop (lvgym.baselines.design.noise); by
    default it is not a requirement (the shipped 28.8 s row commands about six times the servo's rate limit
    from the noise, docs/flex-design.md), with ``noise_rate_fraction`` set it is one, and the design
    problem then penalises it (its violations get one more entry, positive here)."""
    from lvgym.baselines.design.noise import command_noise_rate

    plants, modes, info = row288
    r = min(GainSchedule.load("smile_flex").meta["rows"], key=lambda r: abs(r["time_s"] - 28.8))
    gains, filt = (r["kp"], r["ki"], r["kd"]), StructuralFilter.from_dict(r["filter"])
    chk = FD.check_loops(plants, gains, filt, modes, FD.Requirements(), info["noise"])
    assert chk["meets"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        C = control.ss(FD.controller_tf(gains, filt, DT))
        for key in ("rigid_pitch", "nonrigid_yaw"):
            plane = key.split("_")[1]
            expected = command_noise_rate(C, plants[plane][key.split("_")[0]], *info["noise"])
            assert chk[key]["noise_rate_fraction"] == pytest.approx(expected, rel=1e-12)
    assert 4.0 < chk["rigid_pitch"]["noise_rate_fraction"] < 8.0
    held = FD.check_loops(plants, gains, filt, modes, FD.Requirements(noise_rate_fraction=0.2), info["noise"])
    assert held["misses"] == ["sensor noise"] and not held["meets"]
    values = {"kp": r["kp"], "ki": r["ki"], "kd": r["kd"], "lead_zero_radps": r["filter"]["lead_zero_radps"],
              "lead_ratio": r["filter"]["lead_pole_radps"] / r["filter"]["lead_zero_radps"],
              "lowpass_radps": r["filter"]["lowpass_radps"], "lowpass_damping": r["filter"]["lowpass_damping"],
              "notch_damping": r["filter"]["notch_damping"], "notch_depth": r["filter"]["notch_depth"]}
    loose = FD.RowProblem([(plants["pitch"], modes)], FD.Requirements(), noise=info["noise"])
    tight = FD.RowProblem([(plants["pitch"], modes)], FD.Requirements(noise_rate_fraction=0.2), noise=info["noise"])
    v_loose, v_tight = loose.violations(loose.evaluate(values)), tight.violations(tight.evaluate(values))
    assert len(v_tight) == len(v_loose) + 1 and v_tight[-1] > 1.0 and v_tight[:-1] == v_loose


@pytest.mark.parametrize("vehicle, fraction, rows", [("smile", 0.2, 12), ("stratos3", 0.1, 7)])
def test_the_quiet_schedule_holds_the_noise_in_every_loop(vehicle, fraction, rows):
    """``gs-pid-flex-quiet``'s schedules (flexdesign --noise-rate): every row meets every requirement, and
    the gimbal rate the gyro noise commands is at most the fraction of the rate limit in every loop, at its
    row and at both ends of its stretch (the shipped flex schedules command several times the limit)."""
    quiet = GainSchedule.load(f"{vehicle}_flex_quiet")
    assert quiet.meta["requirements"]["noise_rate_fraction"] == fraction
    assert len(quiet.meta["rows"]) == len(GainSchedule.load(f"{vehicle}_flex").meta["rows"]) == rows
    for row in quiet.meta["rows"]:
        assert row["meets"] and all(c["meets"] for c in row["ends"])
        for chk in [row] + row["ends"]:
            noise = [m["noise_rate_fraction"] for m in chk["margins"].values() if "noise_rate_fraction" in m]
            assert noise and max(noise) <= fraction * 1.005, (row["time_s"], noise)
