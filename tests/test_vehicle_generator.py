"""The launcher family's generator (lvgym/vehicle/generator.py): reproducible from a seed, within its ranges,
physically consistent with the mass model that flies it, valid files, a nominal flight that passes, disjoint
seed splits and errors that name the key."""

from __future__ import annotations

import pytest

from lvgym.errors import ConfigError
from lvgym.vehicle import MassModel, load_vehicle
from lvgym.vehicle.generator import SPLITS, FamilyRanges, generate, split_seeds

G0 = 9.80665


def test_a_seed_gives_the_same_vehicle_and_seeds_differ():
    a, b = generate(7), generate(7)
    assert a.data == b.data and a.design == b.design and a.attempt == b.attempt
    assert generate(8).data != a.data


def test_the_draws_stay_in_their_ranges_and_the_mass_model_agrees_with_the_sizing(tmp_path):
    r = FamilyRanges()
    finned = 0
    for seed in range(12):
        g = generate(seed)
        d = g.design
        assert r.slenderness[0] <= d["slenderness"] <= r.slenderness[1]
        assert r.thrust_to_weight[0] <= d["thrust_to_weight"] <= r.thrust_to_weight[1]
        assert r.burn_time_s[0] <= d["burn_time_s"] <= r.burn_time_s[1]
        finned += d["finned"]
        mm = MassModel(load_vehicle(g.write(tmp_path)))
        lift_off = mm.initial_state()
        mass = mm.properties(lift_off).mass
        assert mass == pytest.approx(d["lift_off_mass_kg"], rel=2e-3)
        # the file's engine gives the drawn thrust-to-weight at sea level and burns the tanks in the sized time
        assert mm.thrust(lift_off, 1.0, 101325.0) / (mass * G0) == pytest.approx(d["thrust_to_weight"], rel=5e-3)
        assert mm.next_event(lift_off) == pytest.approx(d["burn_time_s"], rel=0.02)
        assert load_vehicle(tmp_path / f"family_{seed}.yaml").length == pytest.approx(d["length_m"], rel=1e-4)
    assert 0 < finned < 12                                    # both kinds come out


def test_a_vehicle_drawn_with_the_flight_check_flies_its_nominal_flight():
    from lvgym.baselines.family import flies_nominal, generate_flyable

    g = generate_flyable(split_seeds("test", 1)[0], seconds=20.0)
    assert g.seed == SPLITS["test"][0] and flies_nominal(g.data, seconds=20.0)
    with pytest.raises(ConfigError, match="in 50 attempts"):                   # a check nothing passes
        generate(SPLITS["test"][0], check=lambda data: data["stages"][0]["length"] > 1e3)
    seen = []
    g2 = generate(3, check=lambda data: seen.append(data) or len(seen) > 1)        # the first draw refused
    assert g2.attempt >= 1 and g2.data == seen[-1] != seen[0]


def test_the_splits_are_disjoint_and_bad_values_name_the_key():
    ranges = sorted(SPLITS.values())
    assert all(a[1] <= b[0] for a, b in zip(ranges, ranges[1:]))
    assert split_seeds("validation", 3) == [10_000, 10_001, 10_002]
    with pytest.raises(ConfigError, match="split = 'holdout'"):
        split_seeds("holdout", 3)
    with pytest.raises(ConfigError, match="seed = -1: an integer >= 0"):
        generate(-1)
    with pytest.raises(ConfigError, match=r"slenderness = \(40.0, 10.0\)"):
        FamilyRanges(slenderness=(40.0, 10.0))


def _first(kind, seeds=range(20_000, 20_040)):
    for seed in seeds:
        g = generate(seed)
        if kind(g.design):
            return g
    raise AssertionError("no such vehicle among the seeds")


def test_the_kinds_stay_in_their_ranges_and_are_reproducible(tmp_path):
    r = FamilyRanges()
    kinds = set()
    for seed in split_seeds("test", 20):
        g = generate(seed)
        d = g.design
        kinds.add((d["stages"], tuple(d["motors"])))
        assert r.slenderness[0] <= d["slenderness"] <= r.slenderness[1]
        assert r.thrust_to_weight[0] <= d["thrust_to_weight"] <= r.thrust_to_weight[1]
        assert all(r.burn_time_s[0] <= b <= r.burn_time_s[1] for b in d["burn_times_s"])
        assert len(d["motors"]) == d["stages"] == len(g.data["stages"]) == len(g.data["staging"])
        if d["stages"] == 2:
            assert r.upper_share[0] <= d["upper_share"] <= r.upper_share[1]
            assert r.upper_thrust_to_weight[0] <= d["upper_thrust_to_weight"] <= r.upper_thrust_to_weight[1]
        mm = MassModel(load_vehicle(g.write(tmp_path)))
        lift_off = mm.initial_state()
        assert mm.properties(lift_off).mass == pytest.approx(d["lift_off_mass_kg"], rel=2e-3)
        assert mm.next_event(lift_off) == pytest.approx(d["burn_times_s"][0], rel=0.02)
        assert (tmp_path / f"family_{seed}.yaml").read_text() == generate(seed).write(tmp_path / "again").read_text()
    assert {(1, ("liquid",)), (1, ("solid",))} <= kinds and any(k[0] == 2 for k in kinds)
    only_liquid = FamilyRanges(two_stage_share=0.0, solid_share=0.0)
    assert all(generate(s, only_liquid).design["motors"] == ["liquid"] for s in range(5))


def test_a_two_stage_and_a_solid_vehicle_pass_the_checks_and_fly():
    from lvgym.baselines.family import flies_nominal, nominal_flight

    solid = _first(lambda d: d["stages"] == 1 and d["motors"] == ["solid"])
    assert "thrust_table" in solid.data["stages"][0]["engines"][0]
    assert flies_nominal(solid.data, seconds=30.0)
    two = _first(lambda d: d["stages"] == 2 and d["burn_times_s"][0] < 70.0)
    seconds = two.design["upper_ignition_s"] + 10.0
    r = nominal_flight(two.data, seconds=seconds)
    assert r["duration_s"] > two.design["upper_ignition_s"]            # separated and lit the second stage
    assert flies_nominal(two.data, seconds=seconds)
