"""Gain schedules with several structural filters per row (lvgym.baselines.filters.FilterSeries) and the
attitude channel (``attitude_gain``): the filters' transfer function, the YAML form, the compiled batch
against the per-row policy, validation, and the sign of the attitude channel in flight."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest

import lvgym
from lvgym.baselines.filters import FilterSeries, StructuralFilter, filter_from_yaml
from lvgym.baselines.pidkernel import filter_row, filter_update_k
from lvgym.baselines.pid import GainSchedule, GainScheduledPIDPolicy
from lvgym.errors import ConfigError

DT = 0.02
#: two notches, everything else off (lead-lag equal, low-pass far beyond Nyquist)
NOTCH_A = StructuralFilter(lead_zero_radps=1.0, lead_pole_radps=1.0, lowpass_radps=5000.0,
                           notch_radps=40.0, notch_damping=0.3, notch_depth=0.1)
NOTCH_B = StructuralFilter(lead_zero_radps=1.0, lead_pole_radps=1.0, lowpass_radps=5000.0,
                           notch_radps=100.0, notch_damping=0.2, notch_depth=0.2)


def _response(tf, w: float) -> complex:
    return complex(np.squeeze(tf(cmath.exp(1j * w * DT))))


def _notch_c(f: StructuralFilter, w: float) -> complex:
    """The continuous notch at the frequency ``w`` [rad/s] (by hand)."""
    wn, z, r = f.notch_radps, f.notch_damping, f.notch_depth
    s = 1j * w
    return (s * s + 2 * r * z * wn * s + wn * wn) / (s * s + 2 * z * wn * s + wn * wn)


def test_a_series_is_the_product_of_its_filters():
    pytest.importorskip("control")
    series = FilterSeries((NOTCH_A, NOTCH_B))
    assert len(series.discrete(DT)) == 6 and series.continuous()[3:] == NOTCH_B.continuous()
    prod = NOTCH_A.tf(DT) * NOTCH_B.tf(DT)
    for w in (0.5, 10.0, 40.0, 70.0, 100.0, 150.0):
        assert _response(series.tf(DT), w) == pytest.approx(_response(prod, w), rel=1e-9)
    assert abs(_response(series.tf(DT), 1e-6)) == pytest.approx(1.0, abs=1e-9)        # unit DC gain
    # known numbers: each notch sits at its own frequency (prewarped), with the other's continuous gain at
    # the frequency the bilinear map sends there (w' = k tan(w dt / 2), k = w_n / tan(w_n dt / 2))
    for f, other in ((NOTCH_A, NOTCH_B), (NOTCH_B, NOTCH_A)):
        w = f.notch_radps
        k = other.notch_radps / math.tan(0.5 * other.notch_radps * DT)
        want = f.notch_depth * abs(_notch_c(other, k * math.tan(0.5 * w * DT)))
        assert abs(_response(series.tf(DT), w)) == pytest.approx(want, rel=1e-6)


def test_a_chain_of_a_series_runs_its_filters_one_after_the_other():
    rng = np.random.default_rng(0)
    x = rng.normal(size=200)
    both, a, b = (filter_row(f, DT) for f in (FilterSeries((NOTCH_A, NOTCH_B)), NOTCH_A, NOTCH_B))
    for v in x:
        assert filter_update_k(*both[:1], 0, v, both[1]) == filter_update_k(b[0], 0, filter_update_k(a[0], 0, v, a[1]),
                                                                            b[1])


ROW = {"lead_zero_radps": 8.0, "lead_pole_radps": 200.0, "lowpass_radps": 120.0, "lowpass_damping": 0.5,
       "notch_radps": 60.0, "notch_damping": 0.5, "notch_depth": 0.05}
SECOND = {"lowpass_radps": 5000.0, "notch_radps": 140.0, "notch_damping": 0.2, "notch_depth": 0.1}


def _doc(interpolation: str = "nearest", attitude: float = 0.4, filters=(ROW, SECOND)) -> dict:
    rows = []
    for i, (t, m) in enumerate(((3.0, 10200.0), (15.0, 8500.0), (40.0, 6000.0))):
        rows.append({"time_s": t, "mass_kg": m, "kp": 0.4 + 0.05 * i, "ki": 0.6, "kd": 0.016,
                     "attitude_gain": attitude * (1 + 0.5 * i),
                     "filter": [{**f, "notch_radps": f["notch_radps"] * (1 + 0.1 * i)} for f in filters]})
    return {"vehicle": "smile", "variable": "mass", "interpolation": interpolation, "rows": rows}


def test_yaml_round_trip_of_several_filters_and_the_attitude_channel(tmp_path):
    s = GainSchedule.from_dict(_doc())
    assert s.filter_count == 2 and all(isinstance(f, FilterSeries) for f in s.filters)
    assert s.filters[1][1].notch_radps == pytest.approx(154.0) and s.attitude_gain == (0.4, 0.6000000000000001, 0.8)
    back = GainSchedule.load(s.save(tmp_path / "two.yaml", "two filters per row"))
    assert back == s and back.filters == s.filters and back.attitude_gain == s.attitude_gain
    assert (tmp_path / "two.yaml").read_text().startswith("# two filters per row\n")
    # one mapping per row loads as before: a StructuralFilter per row; the shipped flex schedule round-trips
    flex = GainSchedule.load("smile_flex")
    assert isinstance(flex.filters[0], StructuralFilter) and flex.filter_count == 1
    again = GainSchedule.load(flex.save(tmp_path / "flex.yaml"))
    assert again == flex and again.filters == flex.filters
    assert again.meta["rows"][0]["margins"] == flex.meta["rows"][0]["margins"]


def test_the_filters_of_a_series_interpolate_filter_by_filter():
    lin = GainSchedule.from_dict(_doc("linear"))
    mid = 0.5 * (lin.points[0] + lin.points[1])
    f = lin.filter_at(mid)
    assert isinstance(f, FilterSeries) and len(f) == 2
    assert f[0].notch_radps == pytest.approx(0.5 * (60.0 + 66.0))
    assert f[1].notch_radps == pytest.approx(0.5 * (140.0 + 154.0))
    assert f[0].lowpass_radps == pytest.approx(120.0) and f[1].lowpass_radps == pytest.approx(5000.0)
    assert lin.attitude_gain_at(mid) == pytest.approx(0.5) and lin.attitude_gain_at(1e9) == pytest.approx(0.4)
    near = GainSchedule.from_dict(_doc("nearest"))
    assert near.filter_at(mid + 1.0) is near.filters[0] and near.filter_at(mid - 1.0) is near.filters[1]


def _fly_both(schedule: GainSchedule, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """The actions of the one-row policy on the single env (seed 5) and of row 1 of the law for three rows
    on the batched env (seeds 4, 5, 6), on the same short non-rigid SMILE flight."""
    env = lvgym.make_env("smile-v1", model="nonrigid")
    pol = GainScheduledPIDPolicy(schedule, env=env)
    obs, info = env.reset(seed=5)
    pol.reset()
    single = []
    for _ in range(steps):
        single.append(pol.act(obs, info))
        obs, _, term, trunc, info = env.step(single[-1])
        assert not (term or trunc)
    venv = lvgym.make_vec_env("smile-v1", model="nonrigid", num_envs=3)
    law = pol.batch(3)
    rows = np.arange(3)
    obs, info = venv.reset(seed=[4, 5, 6])
    law.reset(rows)
    batch = []
    for _ in range(steps):
        a = law.act(rows, obs, info)
        batch.append(a[1])
        obs, *_, info = venv.step(a)
    return np.array(single), np.array(batch)


@pytest.mark.parametrize("interpolation", ["nearest", "linear"])
def test_the_batch_flies_two_filters_and_the_attitude_channel_as_the_policy(interpolation):
    s = GainSchedule.from_dict(_doc(interpolation))
    single, batch = _fly_both(s, 400)
    assert np.abs(single).max() > 1e-3                      # the loop acts
    np.testing.assert_array_equal(single, batch)


def test_more_filters_than_the_law_holds_are_refused_by_name():
    env = lvgym.make_env("smile-v1", model="nonrigid")
    s = GainSchedule.from_dict(_doc(filters=[ROW] + [SECOND] * 4))
    assert s.filter_count == 5
    with pytest.raises(ConfigError, match="filter = 5: at most 4 filters in series"):
        GainScheduledPIDPolicy(s, env=env)


@pytest.mark.parametrize("edit, key, allowed", [
    (lambda d: d["rows"][1].update(attitude_gain=-0.1), "attitude_gain", ">= 0"),
    (lambda d: d["rows"][1].update(attitude_gain=float("nan")), "attitude_gain", "finite"),
    (lambda d: d["rows"][1].update(attitude_gain="high"), "rows[1].attitude_gain", "a number"),
    (lambda d: d["rows"][2].pop("attitude_gain"), "attitude_gain", "every row or none"),
    (lambda d: d["rows"][1].update(accel_gain=-1.0) or [r.setdefault("accel_gain", 0.1) for r in d["rows"]],
     "accel_gain", ">= 0"),
    (lambda d: d["rows"][2]["filter"].pop(), "filter", "the same number of filters in every row"),
    (lambda d: d["rows"][0]["filter"][1].update(notch_hz=3.0), "rows[0].filter[1].notch_hz", "allowed"),
    (lambda d: d["rows"][0]["filter"][0].update(notch_depth=1.5), "rows[0].filter[0]", "notch_depth"),
    (lambda d: d["rows"][0].update(filter=[]), "rows[0].filter", "non-empty list"),
    (lambda d: d["rows"][0].update(filter="notch"), "rows[0].filter", "a filter mapping"),
])
def test_bad_values_are_refused_with_key_value_and_what_is_allowed(edit, key, allowed):
    d = _doc()
    edit(d)
    with pytest.raises(ConfigError) as err:
        GainSchedule.from_dict(d)
    assert err.value.key == key and allowed in err.value.allowed
    assert f"{key} = " in str(err.value)


def test_a_single_mapping_and_a_list_of_one_read_alike():
    one, listed = filter_from_yaml(ROW), filter_from_yaml([ROW])
    assert isinstance(one, StructuralFilter) and isinstance(listed, FilterSeries) and listed[0] == one
    assert [b.tolist() for b, _ in one.discrete(DT)] == [b.tolist() for b, _ in listed.discrete(DT)]


def test_a_positive_attitude_gain_pulls_the_attitude_error_towards_zero():
    """On the non-rigid SMILE flown by its flex schedule the rate loop lets the attitude drift; the same
    schedule with k_theta = 0.5 rad/s per rad holds it (so the error's sign in e = -(rate error) - k_theta
    (attitude error) is the stabilising one)."""
    base = GainSchedule.load("smile_flex")
    rms = {}
    for k in (0.0, 0.5):
        d = base.to_dict()
        for r in d["rows"]:
            r["attitude_gain"] = k
        env = lvgym.make_env("smile-v1", model="nonrigid")
        pol = GainScheduledPIDPolicy(GainSchedule.from_dict(d), env=env)
        lay = env.unwrapped.observation_layout
        i_att = [lay.index("pitch_attitude_error"), lay.index("yaw_attitude_error")]
        obs, info = env.reset(seed=1)
        pol.reset()
        att = []
        for _ in range(1000):
            obs, _, term, trunc, info = env.step(pol.act(obs, info))
            att.append(obs[i_att])
            assert not (term or trunc)
        att = np.array(att)
        rms[k] = float(np.sqrt(np.mean(att[-250:] ** 2)))
    assert rms[0.0] > 5e-3 and rms[0.5] < 0.3 * rms[0.0], rms


def test_the_controller_of_the_design_tools_takes_a_series():
    pytest.importorskip("control")
    from lvgym.baselines.design.flexproblem import _controller_poly, controller_tf
    from lvgym.baselines.design.linearize import pid_tf

    gains, series = (0.4, 0.6, 0.016), FilterSeries((NOTCH_A, NOTCH_B))
    want = pid_tf(*gains, None, DT) * NOTCH_A.tf(DT) * NOTCH_B.tf(DT)
    b, a = _controller_poly(gains, series, DT)
    for w in (0.3, 40.0, 100.0):
        z = cmath.exp(1j * w * DT)
        assert _response(controller_tf(gains, series, DT), w) == pytest.approx(_response(want, w), rel=1e-8)
        assert np.polyval(b, z) / np.polyval(a, z) == pytest.approx(_response(want, w), rel=1e-8)
