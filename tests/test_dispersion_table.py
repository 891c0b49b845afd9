"""The dispersions as data (lvgym/envs/dispersions.py): the table draws bit for bit what the hand-written
law before it drew (kept below as the reference), each row's law against its moments, and the docs
table against the table."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.envs.dispersions import (DISPERSIONS, IMU_STATION_SIGMA, OTHER_RANDOMIZATIONS, RANDOMIZE, RANDOMIZE_V0,
                                    VEHICLE_UNITS)
from lvgym.simulator.layouts import DISPERSION


def reference_dispersions(func, rng):
    """The if-chain ``AscentFuncEnv.dispersions`` was before the table (verbatim but for the indices, looked
    up here): the reference the table must reproduce to the bit."""
    lay, n_slosh = func.sim.layout, func.sim.dynamics.n_slosh
    i_mb, i_J, i_cg, i_om, i_zm = (lay.params[k] for k in ("m_b", "J_b", "r_cg", "omega_modes", "zeta_modes"))
    i_zeta = [lay.slosh_param(j, "zeta") for j in range(n_slosh)]
    i_slosh_m = [lay.slosh_param(j, "m") for j in range(n_slosh)]
    i_slosh_f = [(lay.slosh_param(j, "length"), lay.slosh_param(j, "omega")) for j in range(n_slosh)]
    spec = func.spec
    imu_sigma = IMU_STATION_SIGMA * func.vehicle.length if "imu_station" in spec.randomize and \
        spec.observation == "flight" else 0.0
    n_p = lay.n_p
    scale, offset, mis = np.ones(n_p), np.zeros(n_p), np.zeros(2)
    loads = DISPERSION.pack({"thrust_scale": 1.0, "normal_scale": 1.0, "axial_scale": 1.0})
    r = spec.randomize

    def normal(sigma, limit, n=None):
        return np.clip(rng.normal(0.0, sigma, n), -limit, limit)

    if "mass" in r:
        scale[i_mb] = 1.0 + normal(0.01, 0.03)
        offset[i_cg.start] = normal(0.02, 0.06)
        scale[i_J] = 1.0 + normal(0.03, 0.09)
    if "slosh_damping" in r:
        f = math.exp(rng.uniform(math.log(0.5), math.log(2.0)))
        for sl in i_zeta:
            scale[sl] = f
    if "bending_frequency" in r:
        scale[i_om] = 1.0 + normal(0.05, 0.15)
    if "thrust_misalignment" in r:
        mis = np.radians(normal(0.05, 0.15, 2))
    if "aerodynamics" in r:
        k = DISPERSION.index
        loads[k("normal_scale")] = 1.0 + normal(0.05, 0.15)
        loads[k("axial_scale")] = 1.0 + normal(0.05, 0.15)
        calibre = func.vehicle.stages[0].outer_diameter
        loads[k("cp_shift")] = normal(0.25 * calibre, 0.75 * calibre)
    if "thrust_level" in r:
        loads[DISPERSION.index("thrust_scale")] = 1.0 + normal(0.01, 0.03)
    if "slosh_mass" in r:
        f = 1.0 + normal(0.05, 0.15)
        for sl in i_slosh_m:
            scale[sl] *= f
    if "slosh_frequency" in r:
        f = 1.0 + normal(0.05, 0.15)
        tabulated = spec.slosh_frequency == "vacuum_thrust"
        for length, omega in i_slosh_f:
            scale[length] /= f * f
            if tabulated:
                scale[omega] *= f
    if "bending_damping" in r:
        scale[i_zm] = math.exp(rng.uniform(math.log(0.5), math.log(2.0)))
    servo = np.array([1.0, 0.0])
    if "servo_bandwidth" in r:
        servo[0] = 1.0 + normal(0.1, 0.3)
    if "servo_delay" in r:
        servo[1] = float(rng.integers(0, 2))
    station = float(normal(imu_sigma, 3.0 * imu_sigma)) if imu_sigma else 0.0
    return scale, offset, mis, loads, servo, station


#: every randomisation but protocol v2's fault, whose rows came after the hand-written law
BEFORE_FAULTS = tuple(r for r in RANDOMIZE if r != "fault")


@pytest.mark.parametrize("env_id, options", [
    ("lvgym/SmileAscent-v1", {"randomize": BEFORE_FAULTS}),
    ("lvgym/SmileAscent-v1", {"randomize": BEFORE_FAULTS, "slosh_frequency": "vacuum_thrust"}),
    ("lvgym/SmileAscent-v0", {"randomize": True, "observation": "sensors"}),
    ("lvgym/SmileAscent-v0", {"randomize": ["imu_station", "slosh_frequency", "mass"]}),
    ("lvgym/SlenderAscent-v1", {"randomize": BEFORE_FAULTS}),
])
def test_the_table_draws_what_the_hand_written_law_drew(env_id, options):
    func = gym.make(env_id, model="nonrigid", mission_time_s=1.0, **options).unwrapped.func
    assert func.sim.dynamics.n_slosh >= 1
    for seed in range(300):          # enough seeds that some normal draws are clipped (0.27 % of each)
        g_new, g_old = np.random.default_rng(seed), np.random.default_rng(seed)
        new, old = func.dispersions(g_new), reference_dispersions(func, g_old)
        for a, b in zip(new[:5], old[:5]):
            assert a.tobytes() == b.tobytes(), seed
        assert new[5] == old[5] and type(new[5]) is float
        assert not new[6].any()                                             # no fault drawn
        assert g_new.bit_generator.state == g_old.bit_generator.state      # the same calls, in the same order


def test_the_fault_rows_draw_last_and_move_nothing_else():
    """With ``fault`` added, every other draw of a seed is what it was, and the fault's five draws follow."""
    make = gym.make
    func = make("lvgym/SmileAscent-v1", mission_time_s=1.0, randomize=BEFORE_FAULTS).unwrapped.func
    with_fault = make("lvgym/SmileAscent-v1", mission_time_s=1.0, randomize=RANDOMIZE).unwrapped.func
    for seed in range(20):
        g0, g1 = np.random.default_rng(seed), np.random.default_rng(seed)
        a, b = func.dispersions(g0), with_fault.dispersions(g1)
        for x, y in zip(a[:5], b[:5]):
            assert x.tobytes() == y.tobytes()
        assert a[5] == b[5]
        want = [g0.uniform(0.0, 1.0), g0.uniform(0.0, 1.0), g0.uniform(0.0, 1.0), g0.integers(0, 2), g0.integers(0, 2)]
        np.testing.assert_array_equal(b[6], want)


@pytest.mark.parametrize("row", DISPERSIONS, ids=lambda r: f"{r.name}:{r.what[:20]}")
def test_each_row_draws_its_law(row):
    rng = np.random.default_rng(1)
    dim = 0.4                                                   # a vehicle dimension [m] for the rows given in one
    scale = dim if row.unit in VEHICLE_UNITS else 1.0
    x = np.array([row.sample(rng, scale) for _ in range(20000)], dtype=float).reshape(20000, -1)
    assert x.shape[1] == row.size
    if row.law == "normal":
        d = x - 1.0 if row.effect == "factor" else x
        to_unit = math.radians(1.0) if row.unit == "deg" else scale
        sigma, clip = row.sigma * to_unit, row.clip * to_unit
        assert row.clip == pytest.approx(3.0 * row.sigma)               # 3 sigma throughout
        assert np.abs(d).max() <= clip * (1 + 1e-12) and np.abs(d).max() > 0.9 * clip
        # a normal clipped at 3 sigma keeps 99.3 % of its standard deviation
        assert d.std() == pytest.approx(0.9934 * sigma, rel=0.03)
        assert abs(d.mean()) < 5.0 * sigma / math.sqrt(d.size)
    elif row.law == "log_uniform":
        lx = np.log(x)
        lo, hi = math.log(row.low), math.log(row.high)
        assert x.min() >= row.low and x.max() <= row.high
        assert lx.mean() == pytest.approx((lo + hi) / 2, abs=0.02)
        assert lx.std() == pytest.approx((hi - lo) / math.sqrt(12.0), rel=0.03)
        assert x.min() < row.low * 1.01 and x.max() > row.high * 0.99
    elif row.law == "uniform":
        assert x.min() >= row.low and x.max() < row.high
        assert x.mean() == pytest.approx((row.low + row.high) / 2, abs=0.01 * (row.high - row.low))
        assert x.std() == pytest.approx((row.high - row.low) / math.sqrt(12.0), rel=0.03)
    else:
        values = set(np.unique(x).tolist())
        assert values == set(float(k) for k in range(int(row.low), int(row.high) + 1))
        assert x.mean() == pytest.approx((row.low + row.high) / 2, abs=0.02)


def test_the_table_is_the_randomisations():
    names = list(dict.fromkeys(r.name for r in DISPERSIONS))
    assert set(names) | set(OTHER_RANDOMIZATIONS) == set(RANDOMIZE)
    assert RANDOMIZE[:len(RANDOMIZE_V0)] == RANDOMIZE_V0
    # v0's rows come first: a row added later never moves a v0 draw
    v0 = [i for i, r in enumerate(DISPERSIONS) if r.name in RANDOMIZE_V0]
    assert v0 == list(range(len(v0)))
    assert [r.what for r in DISPERSIONS if r.name == "mass"] == ["body mass", "CG station", "inertia"]


def test_a_row_added_to_the_table_is_drawn_last(monkeypatch):
    """Adding a dispersion is adding a row: the plan draws it after the others and moves what it names."""
    from lvgym.envs import dispersions as disp

    func = gym.make("lvgym/SmileAscent-v0", model="rigid", mission_time_s=1.0, randomize=["mass"]).unwrapped.func
    before = func.dispersions(np.random.default_rng(3))
    extra = disp._normal("mass", "gimbal station (an example row)", (disp.Move("params.r_cg[1]"),), 0.01, 0.03,
                         "a test", effect="offset", unit="m")
    monkeypatch.setattr(disp, "DISPERSIONS", disp.DISPERSIONS + (extra,))
    plan = disp.DispersionPlan(func.spec, func.sim.layout, func.sim.dynamics.n_slosh, func.vehicle)
    g = np.random.default_rng(3)
    after = plan.draw(g)
    np.testing.assert_array_equal(after[0], before[0])
    i = func.sim.layout.params["r_cg"].start
    changed = np.flatnonzero(after[1] != before[1])
    assert changed.tolist() == [i + 1] and 0.0 < abs(after[1][i + 1]) <= 0.03


def test_the_docs_table_is_the_table():
    import importlib.util
    from pathlib import Path

    docs = Path(__file__).resolve().parents[1] / "docs"
    spec = importlib.util.spec_from_file_location("gen_tables", docs / "gen_tables.py")
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    text = (docs / "benchmark.md").read_text(encoding="utf-8")
    block = text.split("<!-- generated: dispersions -->\n")[1].split("<!-- end: dispersions -->")[0]
    assert block.strip() == gen.dispersions().strip()
    for row in DISPERSIONS:
        assert f"| {row.what}".replace("*", "\\*") in block and row.law_text() in block
    for name in OTHER_RANDOMIZATIONS:
        assert f"`{name}`" in block
