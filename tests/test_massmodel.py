"""Mass model: slosh laws, depletion, thrust, staging and the rigid-equivalent stack (issue 3)."""

import numpy as np
import pytest

from lvgym.vehicle.config import load_vehicle, parse_vehicle
from lvgym.vehicle.definition import G0
from lvgym.vehicle.massmodel import MassModel, combine
from lvgym.vehicle.propulsion import EngineModel
from lvgym.vehicle.tanks import MIN_SLOSH_HEIGHT, XI, grain_properties, slosh_fraction, tank_properties
from lvgym.verify.mass_cases import case_m


@pytest.mark.parametrize("row", case_m(), ids=lambda r: r.quantity)
def test_case_m(row):
    assert row.passed, f"{row.quantity}: expected {row.expected}, got {row.got}"


def _two_stage(**over):
    """A two-stage vehicle: a kerosene/LOX booster and a monopropellant upper stage with a fairing."""
    data = {
        "name": "two-stage",
        "stages": [
            {"name": "booster", "top": -4.0, "length": 10.0, "outer_diameter": 1.0,
             "structure": {"mass": 200.0, "cg": -9.0, "inertia": [10.0, 800.0, 800.0]},
             "engines": [{"name": "e1", "mass": 50.0, "cg": -13.5, "gimbal": -13.0, "mass_flow": 10.0,
                          "isp": 280.0, "mixture_ratio": 2.5, "nozzle_exit_area": 0.1,
                          "nozzle_exit_pressure": 5e4, "throttle": [0.5, 1.0]}],
             "tanks": [{"name": "lox", "engine": "e1", "role": "oxidiser", "inner_radius": 0.45, "height": 3.0,
                        "top": -4.5, "density": 1141.0, "fill_ratio": 0.9},
                       {"name": "rp1", "engine": "e1", "role": "fuel", "inner_radius": 0.45, "height": 2.0,
                        "top": -7.6, "density": 810.0, "fill_ratio": 0.9}]},
            {"name": "upper", "top": 0.0, "length": 4.0, "outer_diameter": 1.0,
             "structure": {"mass": 60.0, "cg": -2.5, "inertia": [3.0, 60.0, 60.0]},
             "engines": [{"name": "e2", "mass": 10.0, "cg": -3.8, "gimbal": -3.7, "mass_flow": 2.0, "isp": 220.0}],
             "tanks": [{"name": "hydrazine", "engine": "e2", "role": "propellant", "inner_radius": 0.4,
                        "height": 1.5, "top": -1.0, "density": 1004.0, "fill_ratio": 0.8}]},
        ],
        "payload": {"mass": 30.0, "cg": -0.6, "inertia": [1.0, 2.0, 2.0]},
        "fairing": {"mass": 15.0, "cg": -0.5, "inertia": [1.0, 1.5, 1.5], "jettison_time": 50.0},
        "staging": [{"stage": "booster", "separation_delay": 2.0}, {"stage": "upper", "ignition_delay": 3.0}],
    }
    data.update(over)
    return parse_vehicle(data, source="two-stage")


def test_slosh_laws_by_hand():
    # Abramson (NASA SP-106): m_s/m = 2 tanh(k) / ((xi^2 - 1) k); k -> 0 gives 2 / (xi^2 - 1) = 0.83683
    assert slosh_fraction(0.0) == pytest.approx(0.836825, rel=1e-5)
    assert slosh_fraction(1.0) == pytest.approx(2 * np.tanh(1.0) / ((XI**2 - 1) * 1.0))
    v = load_vehicle("thesis-verification")
    ox = v.tanks[0]
    # a shallow 0.2 m layer: Roberts' length 2 / (xi tanh(0.184)) = 5.98 m is capped at the 0.2 m height
    m = np.pi * 4.0 * 0.2 * 1400.0
    tp = tank_properties(ox, m)
    assert tp.height == pytest.approx(0.2)
    assert tp.pendulum_length_roberts == pytest.approx(2.0 / (XI * np.tanh(XI * 0.1)))
    assert tp.pendulum_length == pytest.approx(0.2)
    assert tp.hinge_station == pytest.approx(tp.slosh_station + 0.2)
    # static CG kept: fixed and slosh mass together sit at the liquid CG
    assert (tp.fixed_mass * tp.fixed_cg + tp.slosh_mass * tp.slosh_station) / m == pytest.approx(tp.liquid_cg)
    # an (almost) empty tank has no slosh degree of freedom, and no division by zero
    for m_left in (0.0, 0.5 * np.pi * 4.0 * MIN_SLOSH_HEIGHT * 1400.0):
        tp = tank_properties(ox, m_left)
        assert tp.slosh_mass == 0.0 and tp.pendulum_length == 0.0
        assert tp.fixed_mass == pytest.approx(m_left) and np.all(np.isfinite(tp.fixed_inertia))


def test_parallel_axis_by_hand():
    # two 1 kg points 2 m apart on x: CG in the middle, Iyy = Izz = 2 * 1 * 1^2, Ixx = 0
    m, cg, J = combine([(1.0, np.array([0.0, 0, 0]), np.zeros((3, 3))), (1.0, np.array([-2.0, 0, 0]), np.zeros((3, 3)))])
    assert m == 2.0 and cg == pytest.approx([-1.0, 0, 0])
    assert np.allclose(J, np.diag([0.0, 2.0, 2.0]))


def test_grain_thick_cylinder():
    from lvgym.vehicle.definition import Grain
    grain = Grain("grain", top=-1.0, length=1.0, outer_radius=0.1, port_radius=0.05, density=1000.0,
                  engine="e", key="g")
    assert grain.capacity == pytest.approx(np.pi * (0.01 - 0.0025) * 1000.0)
    m, x, J = grain_properties(grain, grain.capacity)
    assert x == -1.5
    assert J[0, 0] == pytest.approx(0.5 * m * (0.01 + 0.0025))
    assert J[1, 1] == pytest.approx(m * (3 * (0.01 + 0.0025) + 1.0) / 12)
    m, _, J = grain_properties(grain, 0.0)
    assert m == 0.0 and np.all(J == 0.0)


def test_rigid_equivalent_has_the_same_mass_cg_and_inertia():
    mm = MassModel(_two_stage())
    for t in (0.0, 20.0, 60.0):
        p = mm.properties(mm.advance(mm.initial_state(), t)[0])
        parts = [(p.m_b, p.r_cg_b, p.J_b)] + [(m, r, np.zeros((3, 3))) for m, r in zip(p.slosh_mass, p.slosh_rest)]
        m, cg, J = combine(parts)
        assert p.mass == pytest.approx(m) and np.allclose(p.cg, cg) and np.allclose(p.inertia, J)
        # static CG kept: the stack's CG is that of the dry parts with every liquid at its own centroid
        state = mm.advance(mm.initial_state(), t)[0]
        dry = [(s.structure.mass, s.structure.cg) for si, s in enumerate(mm.vehicle.stages)
               if state.phase[si] != "separated"]
        dry += [(e.part.mass, e.part.cg) for si, s in enumerate(mm.vehicle.stages) if state.phase[si] != "separated"
                for e in s.engines]
        dry += [(part.mass, part.cg) for part, on in ((mm.vehicle.payload, True), (mm.vehicle.fairing, state.fairing))
                if on]
        liquids = [(tp.liquid_mass, np.array([tp.liquid_cg, 0.0, 0.0])) for tp in p.tanks if tp]
        points = dry + liquids
        assert p.mass == pytest.approx(sum(m for m, _ in points))
        assert np.allclose(p.cg, sum(m * c for m, c in points) / p.mass, atol=1e-12)


def test_depletion_throttle_and_staging_sequence():
    v = _two_stage()
    mm = MassModel(v)
    s0 = mm.initial_state()
    lox0, rp0, hyd0 = s0.tank_mass
    # O/F 2.5 at 10 kg/s: 7.143 kg/s of LOX, 2.857 of RP-1; the throttle scales the flow (clipped to 0.5)
    s = mm.advance(s0, 10.0, throttle=0.2)[0]
    assert lox0 - s.tank_mass[0] == pytest.approx(0.5 * 10 * 10 * 2.5 / 3.5)
    assert rp0 - s.tank_mass[1] == pytest.approx(0.5 * 10 * 10 / 3.5)
    # burnout when the first tank empties, separation 2 s later, ignition 3 s after that
    t_lox, t_rp = lox0 / (10 * 2.5 / 3.5), rp0 / (10 / 3.5)
    t_burn = min(t_lox, t_rp)
    end, events = mm.advance(s0, 1000.0)
    times = {e: t for t, e in events}
    assert times["stage 'booster' burnout"] == pytest.approx(t_burn)
    assert times["stage 'booster' separation"] == pytest.approx(t_burn + 2.0)
    assert times["stage 'upper' ignition"] == pytest.approx(t_burn + 5.0)
    assert times["fairing jettison"] == pytest.approx(50.0)
    assert times["stage 'upper' burnout"] == pytest.approx(t_burn + 5.0 + hyd0 / 2.0)
    p = mm.properties(end)
    assert p.stages == ("upper",)
    assert p.mass == pytest.approx(60 + 10 + 30 + end.tank_mass[2])
    assert p.slosh_mass[0] == 0.0 and p.slosh_mass[1] == 0.0  # booster tanks gone: pendulums inactive
    assert p.tanks[0] is None and p.tanks[1] is None
    # the upper stage's gimbal is the thrust point once the booster has gone
    assert p.gimbal[0] == -3.7
    # next_event predicts the burnout exactly
    assert mm.next_event(s0) == 50.0  # the fairing goes first
    assert mm.next_event(mm.advance(s0, 60.0)[0]) == pytest.approx(t_burn)


def test_thrust_equation_with_ambient_pressure():
    e = _two_stage().stages[0].engines[0]
    em = EngineModel(e)
    # T = mdot Isp g0 + Ae (pe - p0)
    assert em.thrust(1.0, 1.0, 101325.0) == pytest.approx(10 * 280 * G0 + 0.1 * (5e4 - 101325.0))
    assert em.thrust(1.0, 1.0, 0.0) == pytest.approx(10 * 280 * G0 + 0.1 * 5e4)


def test_thrust_table_flow_and_burnout():
    v = _two_stage()
    stages = [
        {"name": "solo", "top": 0.0, "length": 6.0, "outer_diameter": 0.3,
         "structure": {"mass": 40.0, "cg": -3.0, "inertia": [0.5, 100.0, 100.0]},
         "engines": [{"name": "m", "mass": 5.0, "cg": -5.8, "gimbal": -5.9, "mass_flow": 4.0,
                      "thrust_table": [[0.0, 0.0], [1.0, 10000.0], [9.0, 10000.0], [10.0, 0.0]]}],
         "tanks": [{"name": "p", "engine": "m", "role": "propellant", "inner_radius": 0.14, "height": 3.0,
                    "top": -1.0, "density": 800.0, "fill_ratio": 1.0}]}]
    v = _two_stage(stages=stages, staging=[{"stage": "solo"}], payload=None, fairing=None)
    mm = MassModel(v)
    em = mm.engines[0][1]
    # impulse 9e4 N s over 10 s: T_mean 9000 N; 4 kg/s mean flow -> 40 kg over the burn
    assert em.consumed(0.0, 10.0) == pytest.approx(40.0)
    assert em.consumed(0.0, 0.5) == pytest.approx(4.0 / 9000.0 * 0.5 * 0.5 * 5000.0)
    assert em.mass_flow(5.0) == pytest.approx(4.0 * 10000.0 / 9000.0)
    assert em.time_to_consume(0.0, 20.0) == pytest.approx(5.0)  # 5000 + 10000 (t - 1) = 45000 N s
    _, events = mm.advance(mm.initial_state(), 20.0)
    assert dict((e, t) for t, e in events)["stage 'solo' burnout"] == pytest.approx(10.0)


def test_hybrid_grain_burns_the_fuel_share_the_fuel_tanks_leave():
    stages = [{"name": "hybrid", "top": 0.0, "length": 6.0, "outer_diameter": 0.3,
               "structure": {"mass": 40.0, "cg": -3.0, "inertia": [0.5, 100.0, 100.0]},
               "engines": [{"name": "m", "mass": 5.0, "cg": -5.8, "gimbal": -5.9, "mass_flow": 3.0, "isp": 200.0,
                            "mixture_ratio": 2.0}],
               "tanks": [{"name": "n2o", "engine": "m", "role": "oxidiser", "inner_radius": 0.13, "height": 2.0,
                          "top": -0.5, "density": 800.0, "fill_ratio": 1.0},
                         {"name": "paraffin", "engine": "m", "role": "fuel", "share": 0.4, "inner_radius": 0.1,
                          "height": 0.5, "top": -2.6, "density": 900.0, "fill_ratio": 1.0}],
               "grain": {"name": "grain", "engine": "m", "top": -3.5, "length": 1.5, "outer_radius": 0.12,
                         "port_radius": 0.04, "density": 900.0}}]
    v = _two_stage(stages=stages, staging=[{"stage": "hybrid"}], payload=None, fairing=None)
    mm = MassModel(v)
    s0 = mm.initial_state()
    s1 = mm.advance(s0, 2.0)[0]
    # 3 kg/s at O/F 2: 2 kg/s oxidiser, 1 kg/s fuel of which the tank gives 40 % and the grain 60 %
    assert s0.tank_mass[0] - s1.tank_mass[0] == pytest.approx(4.0)
    assert s0.tank_mass[1] - s1.tank_mass[1] == pytest.approx(0.8)
    assert s0.grain_mass[0] - s1.grain_mass[0] == pytest.approx(1.2)


@pytest.mark.parametrize("name", ["stratos3", "smile", "thesis-verification"])
def test_a_batch_is_the_states_one_at_a_time(name):
    """history() and the batched properties give, to the last bit, what advance() through one time after
    the other and the single-state properties give (thrust tables, a grain, three stages, separations)."""
    mm = MassModel(load_vehicle(name))
    event_times = [t for t, _ in mm.advance(mm.initial_state(), 80.0)[1]]
    times = np.unique(np.concatenate([np.linspace(0.0, 80.0, 161), event_times]))
    stretches, events = mm.history(times)
    assert events == mm.advance(mm.initial_state(), 80.0)[1]
    state, i = mm.initial_state(), 0
    for batch in stretches:
        props = mm.properties(batch)
        thrust, flow = mm.thrust(batch, 1.0, 2e4), mm.mass_flow(batch)
        for k in range(batch.t.size):
            state, _ = mm.advance(state, times[i])
            i += 1
            one = mm.properties(state)
            assert state.phase == batch.phase and state.engine_on == batch.engine_on
            assert np.array_equal(state.tank_mass, batch.tank_mass[k]) and np.array_equal(state.grain_mass,
                                                                                       batch.grain_mass[k])
            row = props.row(k)
            for field in ("m_b", "r_cg_b", "J_b", "slosh_mass", "pendulum_length", "hinge", "slosh_rest", "mass", "cg",
                          "inertia", "gimbal", "mass_flow"):
                assert np.array_equal(getattr(one, field), getattr(row, field)), field
            assert thrust[k] == mm.thrust(state, 1.0, 2e4) and flow[k] == mm.mass_flow(state)
    assert i == times.size
