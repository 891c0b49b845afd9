"""The automatic design of a vehicle file (``lvgym design auto``) and what makes it fast: the Schur-form
frequency response, the margins' crossings solved on the loop itself, and the operating points' flights
continued instead of flown again."""

from __future__ import annotations

import warnings
from pathlib import Path

import control
import numpy as np
import pytest

from lvgym.errors import ConfigError

SMILE_V1 = Path(__file__).resolve().parents[1] / "lvgym" / "vehicles" / "smile_v1.yaml"
#: one weight set: the LQG search of a row is then one design
ONE_WEIGHT = {"q_int": (10.0,), "r_gimbal": (3.0,), "w_gimbal": (1e-7,), "q_modes": (1e-4,), "w_modes": (1e-4,)}


@pytest.fixture(scope="module")
def loop():
    """SMILE v1's non-rigid discrete flight loop at 28.8 s with a PID (34 states, the hold's and the
    delays' defective blocks among them)."""
    from lvgym.baselines.design.flightloop import flight_plant
    from lvgym.baselines.design.linearize import operating_point, pid_tf

    op = operating_point("smile", 28.8, "nonrigid", protocol="v1")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = flight_plant(op, "pitch")
        return control.series(g, control.ss(pid_tf(0.2, 0.5, 0.01, dt=g.dt)))


@pytest.fixture(scope="module")
def stubby(tmp_path_factory) -> str:
    """SMILE v1 with fins of 0.5 m span (tests/test_design_vehicle_file.py): unstable with the gimbal centred."""
    text = SMILE_V1.read_text().replace("name: smile_v1", "name: stubby")
    old = "fins: {count: 4, root_chord: 2.2, tip_chord: 1.0, span: 1.1,"
    assert old in text
    path = tmp_path_factory.mktemp("vehicle") / "stubby.yaml"
    path.write_text(text.replace(old, "fins: {count: 4, root_chord: 1.2, tip_chord: 0.6, span: 0.5,"))
    return str(path)


def test_the_schur_response_is_python_controls(loop):
    from lvgym.baselines.design.linearize import margin_grid
    from lvgym.baselines.design.response import frequency_response, ss_response

    w = margin_grid(loop.dt, 3000)
    ours = frequency_response(loop, w)
    theirs = np.asarray(loop(np.exp(1j * w * loop.dt)), complex).ravel()
    # relative 1e-8 near the integrator's pole at z = 1, where both lose digits to its conditioning
    assert np.all(np.abs(ours - theirs) <= 1e-7 * np.abs(theirs) + 1e-12 * np.max(np.abs(theirs)))
    assert np.median(np.abs(ours - theirs) / np.abs(theirs)) < 1e-10
    delay = control.ss(np.diag(np.ones(2), -1)[:3, :3], [[1.0], [0.0], [0.0]], [[0.0, 0.0, 1.0]], 0.0, 0.02)
    z = np.exp(1j * w[:50] * 0.02)                    # a pure 3-period delay: A nilpotent, no eigenvectors
    assert np.allclose(ss_response(delay, z), z ** -3, rtol=1e-12, atol=0.0)
    cont = control.ss(control.tf([1.0, 2.0], [1.0, 0.4, 9.0]))
    assert np.allclose(frequency_response(cont, w[:50]), (1j * w[:50] + 2) / ((1j * w[:50]) ** 2 + 0.4j * w[:50] + 9))
    with pytest.raises(ValueError, match="SISO"):
        ss_response(control.ss(np.eye(2), np.eye(2), np.eye(2), 0.0), z)


def test_the_crossings_are_those_of_python_controls_interpolated_response(loop):
    from lvgym.baselines.design.linearize import crossings, margin_grid, margins

    w = margin_grid(loop.dt)
    resp = np.asarray(loop(np.exp(1j * w * loop.dt)), complex).ravel()
    gm0, pm0, _, wpc0, wgc0, _ = control.stability_margins(control.frd(resp, w, smooth=True), returnall=True)
    gm, pm, wpc, wgc = crossings(loop)
    assert gm.shape == np.shape(gm0) and pm.shape == np.shape(pm0) and gm.size >= 1 and pm.size >= 1
    assert np.allclose(20 * np.log10(gm), 20 * np.log10(gm0), atol=1e-4)          # dB
    assert np.allclose(pm, pm0, atol=1e-3)                                       # deg
    assert np.allclose(wpc, wpc0, rtol=1e-6) and np.allclose(wgc, wgc0, rtol=1e-6)
    m = margins(loop)
    assert m["phase_margin_deg"] == pytest.approx(pm[np.argmin(np.abs(pm))], abs=1e-12)


def test_a_continued_flight_gives_the_operating_point_of_a_new_one():
    from lvgym.baselines.design.linearize import operating_point, reused_flights
    from lvgym.baselines.design.target import privileged_flyer

    fresh = operating_point("smile", 8.0, "nonrigid", protocol="v1", policy=privileged_flyer())
    with reused_flights():
        operating_point("smile", 5.0, "nonrigid", protocol="v1", policy=privileged_flyer())
        again = operating_point("smile", 8.0, "nonrigid", protocol="v1", policy=privileged_flyer())
        back = operating_point("smile", 3.0, "nonrigid", protocol="v1", policy=privileged_flyer())   # flown anew
    earlier = operating_point("smile", 3.0, "nonrigid", protocol="v1", policy=privileged_flyer())
    for a, b in ((fresh, again), (earlier, back)):
        assert a.t == b.t
        assert np.array_equal(a.x, b.x) and np.array_equal(a.p, b.p) and np.array_equal(a.c, b.c)
    assert again.env_options["privileged_info"] is True


def test_the_automatic_design_of_a_vehicle_file(stubby, tmp_path):
    import lvgym
    from lvgym.baselines.design.auto import Budget, design_vehicle, latest_design, summary_text
    from lvgym.baselines.designed import auto_policy
    from lvgym.simulator.cache import using

    budget = Budget(flex_maxiter=20, workers=1, rows=2)
    with using(tmp_path / "cache"):
        d = design_vehicle(stubby, budget, grid=ONE_WEIGHT)
        assert not d.cached and d.folder.parent == tmp_path / "cache" / "designs"
        for kind in ("gs-pid", "gs-pid-flex", "lqg"):
            assert d.path(kind).is_file()
        s = d.summary
        assert s["operating_points"] == "the privileged reference" and s["budget"]["rows"] == 2
        assert len(s["gs-pid"]["rows"]) == len(s["gs-pid-flex"]["rows"]) == len(s["lqg"]["rows"]) == 2
        assert all(set(r) == {"time_s", "pitch", "yaw"} for r in s["lqg"]["rows"])
        assert "designed in" in summary_text(d) and "of 2 rows" in summary_text(d)
        again = design_vehicle(stubby, budget, grid=ONE_WEIGHT, out=tmp_path / "copy")
        assert again.cached and again.summary == s and (tmp_path / "copy" / "lqg.npz").is_file()
        assert "read from the cache" in summary_text(again)
        env = lvgym.make_env("smile-v2", model="nonrigid", vehicle=stubby, mission_time_s=3.0)
        assert latest_design(stubby).folder == d.folder            # the policies fly the last design
        for kind in ("gs-pid", "gs-pid-flex", "lqg"):
            policy = auto_policy(env, kind)
            obs, info = env.reset(seed=0)
            policy.reset()
            obs, _, _, _, info = env.step(policy.act(obs, info))
            assert np.isfinite(obs).all() and policy.name == f"auto-{kind}"
        assert latest_design(SMILE_V1) is None
    with pytest.raises(ConfigError, match="vehicle YAML file"):
        design_vehicle("smile")
    with pytest.raises(ConfigError, match="budget.flex_maxiter"):
        Budget(flex_maxiter=5)
    with pytest.raises(ConfigError, match="env vehicle"):
        auto_policy(lvgym.make_env("smile-v2", model="rigid"), "lqg")


def test_the_cache_key_is_the_vehicles_content(stubby, tmp_path):
    from lvgym.baselines.design.auto import Budget, design_key

    copy = tmp_path / "renamed.yaml"
    copy.write_text(Path(stubby).read_text())
    assert design_key(str(copy), Budget(), {}) == design_key(stubby, Budget(), {})
    assert design_key(stubby, Budget(rows=4), {}) != design_key(stubby, Budget(), {})
    copy.write_text(Path(stubby).read_text().replace("span: 0.5,", "span: 0.6,"))
    assert design_key(str(copy), Budget(), {}) != design_key(stubby, Budget(), {})


def test_the_fixed_baseline_flies_the_nominal_members_design_on_another_vehicle(stubby, tmp_path):
    import lvgym
    from lvgym.baselines.design.auto import Budget, design_vehicle
    from lvgym.baselines.designed import fixed_policy, nominal_file
    from lvgym.simulator.cache import using
    from lvgym.vehicle.generator import nominal

    g = nominal()
    assert (g.design["slenderness"], g.design["thrust_to_weight"], g.design["diameter_m"]) == (25.0, 1.85, 0.7)
    assert not g.design["finned"] and g.design["stages"] == 1 and g.design["motors"] == ["liquid"]
    assert nominal().data == g.data and g.data["name"] == "family_nominal"
    with using(tmp_path / "cache"):
        path = nominal_file()
        assert path.parent == tmp_path / "cache" / "designs" and path.read_text() == nominal_file().read_text()
        design_vehicle(path, Budget(flex_maxiter=20, workers=1, rows=2), grid=ONE_WEIGHT)
        env = lvgym.make_env("smile-v2", model="nonrigid", vehicle=stubby, mission_time_s=3.0)
        for kind in ("gs-pid-flex", "lqg"):
            policy = fixed_policy(env, kind)
            obs, info = env.reset(seed=0)
            policy.reset()
            obs, _, _, _, info = env.step(policy.act(obs, info))
            assert np.isfinite(obs).all() and policy.name == f"fixed-{kind}"


def test_a_vehicle_without_slosh_designs_too(tmp_path):
    """A solid motor has no liquid to slosh: the designs and their margin tables say '-' for its slosh."""
    from lvgym.baselines.design.auto import Budget, design_vehicle
    from lvgym.simulator.cache import using
    from lvgym.vehicle.generator import generate

    g = generate(20002)                                   # a single-stage solid of the test split
    assert g.design["motors"] == ["solid"]
    path = g.write(tmp_path)
    with using(tmp_path / "cache"):
        d = design_vehicle(path, Budget(flex_maxiter=20, workers=1, rows=2), grid=ONE_WEIGHT)
    table = (d.folder / "lqg_margins.md").read_text().splitlines()
    assert len(table) == 2 + 2 * 2 and all(row.split("|")[6].strip() == "-" for row in table[2:])


def test_a_crossing_bracket_without_a_sign_change_takes_its_nearer_end():
    from lvgym.baselines.design.linearize import _root

    assert _root(lambda x: x - 0.3, 0.0, 1.0) == pytest.approx(0.3, abs=1e-12)
    assert _root(lambda x: (x - 0.9) ** 2 + 1e-9, 0.0, 1.0) == 1.0     # touches zero near 0.9: the nearer end
    assert _root(lambda x: x, 0.0, 1.0) == 0.0
