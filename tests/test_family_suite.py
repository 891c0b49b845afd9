"""The launcher family's suites: the shipped test vehicles, the ``vehicle_info`` observation of the informed
track (the design parameters by hand, the rest of the observation unchanged, the vector env against the
single env, Gymnasium's check), the tracks flying a classical policy alike, and the family table."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml
from gymnasium.utils.env_checker import check_env

import lvgym
import lvgym.cli.policies  # noqa: F401  (registers the built-in policies)
from lvgym.benchmark.family import crossed_interval, family_rows, family_table
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.runner import run_episode
from lvgym.benchmark.suites import FAMILY_VEHICLES, get_suite
from lvgym.envs.layouts import OBS_FLIGHT, VEHICLE_INFO
from lvgym.vehicle import MassModel, load_vehicle
from lvgym.vehicle.config import VEHICLE_DIR
from lvgym.vehicle.designinfo import design_parameters, design_vector


def test_the_design_parameters_of_smile_by_hand():
    v = load_vehicle("smile_v1")
    p = design_parameters(v)
    mm = MassModel(v)
    props = mm.properties(mm.initial_state())
    assert p["mass_kg"] == pytest.approx(float(props.mass)) and p["mass_kg"] == pytest.approx(10_608.7, abs=0.1)
    assert p["slenderness"] == pytest.approx(v.length / max(s.outer_diameter for s in v.stages))
    # the control power is the vectored thrust's moment arm over the pitch inertia; the thrust, T/W m g0
    thrust = p["thrust_to_weight"] * p["mass_kg"] * 9.80665
    arm = float(props.cg[0] - props.gimbal[0])
    assert p["control_power_per_s2"] == pytest.approx(thrust * arm / float(props.inertia[1, 1]), rel=1e-9)
    assert 9.0 < p["bending_hz"] < 10.0                    # SMILE's first bending mode, 9.4 Hz at lift-off
    # the largest slosh pendulum at the thrust acceleration: sqrt(a / l) / 2 pi
    k = int(np.argmax(props.slosh_mass))
    a = thrust / p["mass_kg"]
    assert p["slosh_hz"] == pytest.approx(math.sqrt(a / float(props.pendulum_length[k])) / (2 * math.pi))
    vec = design_vector(v)
    assert vec.dtype == np.float32 and vec.size == VEHICLE_INFO.size and not vec.flags.writeable
    assert vec[0] == pytest.approx(p["mass_kg"] / 1e3) and vec[1] == pytest.approx(math.log10(p["pitch_inertia_kgm2"]))


def test_the_informed_observation_adds_the_design_block_and_changes_nothing_else():
    blind = lvgym.make_env("family-v2", model="nonrigid", mission_time_s=3.0)
    informed = lvgym.make_env("family-v2-informed", model="nonrigid", mission_time_s=3.0)
    assert informed.observation_space.shape == (OBS_FLIGHT.size + VEHICLE_INFO.size,)
    lay = informed.unwrapped.observation_layout
    assert lay.names[:OBS_FLIGHT.size] == OBS_FLIGHT.names and lay.index("vehicle_slosh_hz") == lay.size - 1
    vec = design_vector(load_vehicle(FAMILY_VEHICLES[0]))
    o_b, _ = blind.reset(seed=7)
    o_i, _ = informed.reset(seed=7)
    rng = np.random.default_rng(0)
    for _ in range(40):
        assert np.array_equal(o_i[:OBS_FLIGHT.size], o_b) and np.array_equal(o_i[OBS_FLIGHT.size:], vec)
        a = rng.uniform(-0.3, 0.3, 2).astype(np.float32)
        o_b, r_b, *_ = blind.step(a)
        o_i, r_i, *_ = informed.step(a)
        assert r_i == r_b


def test_the_informed_vector_env_rows_are_the_single_envs_and_both_pass_the_checks():
    cond = get_suite("family-v2-informed").conditions[3].with_options(mission_time_s=2.0)
    single = cond.make_env()
    check_env(single.unwrapped, skip_render_check=True)
    vec = cond.make_vec_env(2)
    obs, _ = vec.reset(seed=5)
    for row in range(2):
        o, _ = single.reset(seed=5 + row)
        assert np.array_equal(obs[row], o)
    a = np.full((2, 2), 0.2, np.float32)
    obs, *_ = vec.step(a)
    o, _ = single.reset(seed=6)
    assert np.array_equal(obs[1], single.step(a[1])[0])


def test_the_family_suites_fly_the_shipped_test_vehicles():
    blind, informed = get_suite("family-v2"), get_suite("family-v2-informed")
    assert len(FAMILY_VEHICLES) == 20 and len(blind.conditions) == len(informed.conditions) == 40
    assert [c.group for c in blind.conditions[:2]] == ["family-v2/20000"] * 2
    for b, i in zip(blind.conditions, informed.conditions):
        assert dict(i.options) == {**dict(b.options), "vehicle_info": True} and b.model == i.model
    for name in FAMILY_VEHICLES:
        path = VEHICLE_DIR / f"{name}.yaml"
        assert path.read_text().startswith("# lvgym's launcher family: the test vehicle of seed")
        load_vehicle(name)                                 # the vehicle checks pass


def test_a_shipped_family_vehicle_is_the_generators():
    from lvgym.baselines.family import generate_flyable

    text = (VEHICLE_DIR / "family" / "test_20000.yaml").read_text()
    assert yaml.safe_load(text) == generate_flyable(20000).data


def test_a_classical_policy_flies_both_tracks_alike():
    spec = resolve_policy("gs-pid")                      # reads the observation by its entries' names
    runs = [run_episode(spec, get_suite(s).conditions[1].with_options(mission_time_s=4.0), 10_000)
            for s in ("family-v2", "family-v2-informed")]
    drop = ("condition", "group")
    assert {k: v for k, v in runs[0].items() if k not in drop} == {k: v for k, v in runs[1].items() if k not in drop}


def _records(bad: dict[tuple[str, int], list[int]]) -> list[dict]:
    out = []
    for (policy, vehicle), fails in bad.items():
        for seed in range(4):
            out.append({"suite": "family-v2", "model": "nonrigid", "policy": policy, "group": f"family-v2/{vehicle}",
                        "seed": 10_000 + seed, "failed": seed in fails, "flyable": True,
                        "score_v2": 1.0 + vehicle + (5.0 if seed in fails else 0.0)})
    return out


def test_the_family_table_by_hand():
    recs = _records({("a", 0): [], ("a", 1): [2], ("b", 0): [], ("b", 1): []})
    recs.append({"suite": "smile-v2", "model": "nonrigid", "policy": "a", "group": "smile-v2", "seed": 0,
                 "failed": True, "flyable": True, "score_v2": 9.0})                # not a family suite: left out
    rows = {r["policy"]: r for r in family_rows(recs)}
    a = rows["a"]
    assert (a["vehicles"], a["seeds"], a["held"]) == (2, 4, 1)
    assert a["failed"] == pytest.approx(1 / 8) and a["score_v2"] == pytest.approx((4 * 1.0 + 4 * 2.0 + 5.0) / 8)
    assert a["failed_low"] == 0.0 and a["failed_high"] <= 0.5
    assert rows["b"]["held"] == 2 and rows["b"]["bad"] == 0.0
    lines = family_table(list(rows.values()))
    assert lines[2].startswith("| family-v2 | nonrigid | b | 2 of 2 | 0 % [0, 0] |")
    # a constant matrix has a point interval; a vehicle effect widens it beyond the seeds' own
    assert crossed_interval(np.ones((3, 5))) == (1.0, 1.0)
    lo, hi = crossed_interval(np.array([[0.0] * 5, [1.0] * 5, [2.0] * 5]))
    assert lo < 0.7 and hi > 1.3


def test_the_familys_room_by_hand():
    from lvgym.benchmark.family import family_room

    recs = _records({("a", 0): [], ("a", 1): [], ("ref", 0): [], ("ref", 1): [], ("zero", 0): [], ("zero", 1): []})
    for r in recs:                                       # the reference scores half of a, zero scores 0
        r["score_v2"] = {"a": 1.0 + r["seed"], "ref": 0.5 * (1.0 + r["seed"]), "zero": 0.0}[r["policy"]]
    (room,) = family_room(recs, {"a": "classical", "ref": "privileged", "zero": "none"})
    assert (room["best"], room["reference"]) == ("a", "ref")
    assert room["room"] == pytest.approx(0.5) and room["room_low"] == pytest.approx(0.5)
    lines = family_table(family_rows(recs), [room])
    assert lines[-1] == "| family-v2 | nonrigid | a | 50 % [50, 50] |"
