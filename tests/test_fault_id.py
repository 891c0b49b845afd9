"""The fault-identification study (experiments.fault_id): the estimator's correction by hand, the
plant-knowing variants by hand, the teachers and the students flown in a batch against the benchmark's single
env (the shipped observer and law: tests/test_inversion_policy.py)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from experiments.fault_id.estimator import FEATURES, WINDOW, FaultIdPolicy, corrected
from experiments.fault_id.privileges import VARIANTS, PlantKnown, specs
from experiments.fault_id.train import condition, fit, fly, lost
from lvgym.benchmark.runner import play_episode
from lvgym.errors import ConfigError


def test_the_correction_by_hand():
    np.testing.assert_allclose(corrected(np.array([0.5, -0.2]), np.array([0.1, -0.3])), [0.4, 0.1], rtol=1e-6)
    assert corrected(np.array([0.95]), np.array([-0.2]))[0] == 1.0
    # the dead band shrinks the estimate towards zero: 0.1 - 0.04 and nothing of -0.03
    np.testing.assert_allclose(corrected(np.array([0.5, -0.2]), np.array([0.1, -0.03]), 0.04), [0.44, -0.2], rtol=1e-6)


class _Base:
    def reset(self):
        pass

    def act(self, observation, info):
        return np.array([0.2, -0.1])


def test_lqg_given_the_plant_by_hand():
    p = PlantKnown.__new__(PlantKnown)
    p.base, p.limit, p.seen, p.name = _Base(), 0.1, [], "x"
    p.mis, p.eff, p.late, p.static, p.aero = True, True, 1, False, False
    assert np.allclose(p.act(np.zeros(14), {}), [0.2, -0.1])        # the reset's info: the law alone
    info = {"misalignment": np.array([0.01, 0.0]), "actuator_effectiveness": np.array([0.5, 1.0])}
    np.testing.assert_allclose(p.act(np.zeros(14), info), [(0.2 - 0.1) / 0.5, -0.1], rtol=1e-6)
    later = dict(info, misalignment=np.array([0.02, 0.0]))
    np.testing.assert_allclose(p.act(np.zeros(14), later), [(0.2 - 0.1) / 0.5, -0.1], rtol=1e-6)  # one step late
    p.static = True
    np.testing.assert_allclose(p.act(np.zeros(14), later), [(0.2 - 0.1) / 0.5, -0.1], rtol=1e-6)  # the first only


def test_the_variants_are_named():
    with pytest.raises(ConfigError, match="variants"):
        specs(["no-such-variant"])
    assert {"privileged", "no-plant", "lqg-mis", "lqg-mis-static"} <= set(VARIANTS)
    assert [s.name for s in specs(["lqg", "no-plant"])] == ["lqg", "no-plant"]


def test_the_student_in_a_batch_flies_as_the_benchmark_flies_it():
    """Two rows of :func:`fly` with an estimator (fitted for one epoch, seeded) and a dead band against the
    single env flying
    :class:`FaultIdPolicy`: the same flights (the estimator's batched and single forward may differ in the
    last bits, so the scores are compared to 1e-6)."""
    torch.manual_seed(0)
    short = {"mission_time_s": 3.0}
    x, y, _, _ = fly("rigid", [0, 1], None, np.random.default_rng(0), **short)
    assert x.shape[1:] == (WINDOW, FEATURES) and y.shape == (len(x), 2)
    est = fit(x, y, seed=0, epochs=1)
    _, _, batch, _ = fly("rigid", [5, 6], est, deadband=0.04, **short)
    env = condition("rigid", **short).make_env()
    for seed, rec in zip([5, 6], batch):
        single = play_episode(FaultIdPolicy(env, est, deadband=0.04), env, seed, flyability=True)
        assert single["score_v2"] == pytest.approx(rec["score_v2"], rel=1e-6)
        assert single["max_qalpha_pa_deg"] == pytest.approx(rec["max_qalpha_pa_deg"], rel=1e-6)


@pytest.mark.parametrize("bandwidth", [0.0, 1.25])
def test_the_inversion_teacher_is_the_reference_on_the_observation(monkeypatch, bandwidth):
    """The inversion scheme's teacher (the law on the true terms, batched; here without its exploration) flies
    as the privileged reference given the observation's errors, without its preview, one env row at a time;
    with ``--bandwidth``'s gains, as the reference of that bandwidth."""
    from experiments.fault_id import train
    from experiments.fault_id.privileges import reference
    monkeypatch.setattr(train, "NOISE", (0.0,))
    short = {"mission_time_s": 4.0}
    _, y, batch, _ = fly("nonrigid", [3, 4], None, np.random.default_rng(0), scheme="inversion",
                      law=train.own_law(bandwidth), **short)
    assert y.shape[1] == 7 and np.any(y[:, 4] > 0.0)
    env = condition("nonrigid", privileged_info=True, **short).make_env()
    for seed, rec in zip([3, 4], batch):
        law = reference(env, preview=False, observed=True, bandwidth_radps=bandwidth or None)
        single = play_episode(law, env, seed, flyability=True)
        assert single["score_v2"] == pytest.approx(rec["score_v2"], rel=1e-9)


def test_the_inversion_student_in_a_batch_flies_as_the_benchmark_flies_it():
    from experiments.fault_id.inversion import InversionPolicy
    from lvgym.agents.policies.observer_net import to_observer
    torch.manual_seed(0)
    short = {"mission_time_s": 3.0}
    x, y, _, _ = fly("rigid", [0, 1], None, np.random.default_rng(0), scheme="inversion", **short)
    est = fit(x, y, seed=0, epochs=1, scaled=True)
    assert est.label_std.shape == (7,)
    _, _, batch, _ = fly("rigid", [5, 6], est, scheme="inversion", **short)
    env = condition("rigid", **short).make_env()
    for seed, rec in zip([5, 6], batch):
        single = play_episode(InversionPolicy(env, to_observer(est)), env, seed, flyability=True)
        assert single["score_v2"] == pytest.approx(rec["score_v2"], rel=1e-6)


def test_a_loop_gain_labels_the_terms_as_the_action_must_carry_them(monkeypatch):
    """With a gain g after the action, the inversion teacher commands the law over g (the flight sees the
    undispersed law's gimbal angles) and its labels are the terms over g; the q-alpha share stays."""
    from experiments.fault_id import train
    monkeypatch.setattr(train, "NOISE", (0.0,))
    short = {"mission_time_s": 3.0}
    gain = np.array([2.0, 0.5])
    _, y1, r1, _ = fly("rigid", [7, 8], None, np.random.default_rng(0), scheme="inversion", **short)
    _, y2, r2, _ = fly("rigid", [7, 8], None, np.random.default_rng(0), scheme="inversion", loop_gain=gain, **short)
    assert y1.shape == y2.shape
    rows = np.resize([0, 1], len(y1))                 # the steps interleave the two rows while both fly
    np.testing.assert_allclose(y2[:, :6] * gain[rows][:, None], y1[:, :6], rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(y2[:, 6], y1[:, 6], rtol=1e-4, atol=1e-9)
    assert [r["score_v2"] for r in r2] == pytest.approx([r["score_v2"] for r in r1], rel=1e-6)
    with pytest.raises(ValueError, match="inversion"):
        fly("rigid", [7], None, np.random.default_rng(0), loop_gain=np.ones(1), **short)


def test_the_inversion_teacher_flies_a_family_vehicle_and_the_thrust_scheme_refuses_the_family():
    from experiments.fault_id.train import main
    from lvgym.benchmark.suites import FAMILY_VALIDATION_VEHICLES
    v = FAMILY_VALIDATION_VEHICLES[0]
    _, y, recs, _ = fly("nonrigid", [0, 1], None, np.random.default_rng(0), scheme="inversion", suite="family-v2",
                     vehicle=v, mission_time_s=3.0)
    assert y.shape[1] == 7 and np.any(y[:, 4] > 0.0) and len(recs) == 2
    assert condition("nonrigid", "family-v2", vehicle=v).make_env().unwrapped.func.spec.vehicle != "smile_v1"
    with pytest.raises(ConfigError, match="--suite"):
        main(["--suite", "family-v2", "--scheme", "thrust"])


def test_the_feasibility_study_lists_each_lost_flight_once_with_who_lost_it():
    from experiments.fault_id.feasible import failed
    recs = [{"suite": "smile-v2-faults", "condition": "smile-v2-faults/nonrigid", "seed": 7, "policy": p,
             "failed": f, "flyable": fl} for p, f, fl in (("a", True, True), ("b", False, False), ("c", False, True))]
    recs.append({"suite": "smile-v2-faults", "condition": "smile-v2-faults/rigid", "seed": 3, "policy": "a",
                 "failed": True, "flyable": True})
    recs.append({"suite": "smile-v2", "condition": "smile-v2/rigid", "seed": 1, "policy": "a", "failed": True,
                 "flyable": True})
    assert failed(recs) == {("nonrigid", 7): ["a", "b"], ("rigid", 3): ["a"]}


def test_the_law_room_study_flies_validation_seeds_and_the_familys_validation_vehicles():
    from experiments.fault_id.law_room import CLASSICAL, places
    from lvgym.benchmark.suites import FAMILY_VALIDATION_VEHICLES, get_suite
    fam = places("family-v2", 2)
    assert len(fam) == 2 * len(FAMILY_VALIDATION_VEHICLES) and fam[1] == ({"vehicle": FAMILY_VALIDATION_VEHICLES[0]}, 1)
    assert places("stratos-tvc-v2", 3) == [({}, k) for k in get_suite("stratos-tvc-v2").seeds("validation", 3)]
    assert all(get_suite(s).version.startswith("v2") or s == "family-v2" for s in CLASSICAL)


def test_the_moment_extrapolated_along_its_slope_by_hand():
    from experiments.fault_id.privileges import SLOPE_STEPS, Withheld

    class Seen:
        name = "seen"

        def reset(self):
            self.m = []

        def act(self, observation, info):
            self.m.append(np.asarray(info["m_aero_b"]))
            return np.zeros(2, np.float32)

    law = Seen()
    law.reset()
    w = Withheld.__new__(Withheld)
    w.law, w.name, w.observed, w.eff, w.late, w.ahead, w.m_aero = law, "x", False, True, 0, 5, []
    w.span, w.plant_late, w.plant = SLOPE_STEPS, 0, []
    for k in range(8):                                  # a moment growing by 2 N m per step
        w.act(np.zeros(14), {"omega_bi_b": np.zeros(3), "m_aero_b": np.array([0.0, 2.0 * k, 0.0])})
    assert SLOPE_STEPS == 5
    np.testing.assert_allclose(law.m[-1], [0.0, 14.0 + 5 * 2.0, 0.0])   # 5 steps ahead along the slope
    np.testing.assert_allclose(law.m[0], [0.0, 0.0, 0.0])               # the first step: no slope yet


def test_the_plant_known_late_by_hand():
    """``plant_late``: the moment, misalignment and effectiveness the law sees are those of that many steps before
    (the first step's before there were so many); the thrust, the state and the q-alpha are the step's own."""
    from experiments.fault_id.privileges import PLANT, Withheld

    class Seen:
        name = "seen"

        def reset(self):
            self.info = []

        def act(self, observation, info):
            self.info.append(dict(info))
            return np.zeros(2, np.float32)

    law = Seen()
    w = Withheld.__new__(Withheld)
    w.law, w.name, w.observed, w.eff, w.late, w.ahead, w.span, w.plant_late = law, "x", False, True, 0, 0, 5, 3
    w.reset()
    for k in range(6):
        w.act(np.zeros(14), {"omega_bi_b": np.full(3, float(k)), "qalpha_pa_deg": 10.0 * k, "m_aero_b": np.full(3, k),
                             "misalignment": np.full(2, -k), "actuator_effectiveness": np.full(2, 1.0 - k / 10),
                             "thrust": 100.0 * k, "vectored_share": 1.0})
    assert set(PLANT) == {"m_aero_b", "misalignment", "actuator_effectiveness"}
    seen = [(i["thrust"], i["misalignment"][0], i["m_aero_b"][1], i["actuator_effectiveness"][0], i["qalpha_pa_deg"],
             i["omega_bi_b"][0]) for i in law.info]
    assert seen[0] == (0.0, 0, 0, 1.0, 0.0, 0.0) and seen[3] == (300.0, 0, 0, 1.0, 30.0, 3.0)   # 3 late, from 0
    assert seen[5] == (500.0, -2, 2, 0.8, 50.0, 5.0)


def test_the_extrapolated_label_is_the_true_moment_carried_along_its_slope(monkeypatch):
    """``--extrapolated 5``: the moment terms labelled (and flown by the teacher) are the present ones carried 5
    steps along their last 5; the other terms, and the reset's zeros, stay."""
    from experiments.fault_id import train

    def ramp(info, n, limit, ahead=0):               # f_aero of row r at step k: (r + 1) k / 100
        out = np.zeros((n, 7))
        if "m_aero_b" in info:
            out[:, 0] = (np.arange(n) + 1) * info["k"] / 100.0
            out[:, 4] = 1.0
        return out

    monkeypatch.setattr(train, "law_terms", ramp)
    env = condition("rigid", mission_time_s=3.0).make_env()
    scheme = train.InversionScheme(env, 2, None, 0.0, extrapolated=5)
    assert not scheme.labels({}).any()                # the reset
    for k in range(1, 9):
        y = scheme.labels({"m_aero_b": None, "k": k})
    np.testing.assert_allclose(y[:, 0], [(8 + 5) / 100.0, 2 * (8 + 5) / 100.0])
    np.testing.assert_allclose(y[:, 4], 1.0)
    first = train.InversionScheme(env, 2, None, 0.0, extrapolated=5)
    np.testing.assert_allclose(first.labels({"m_aero_b": None, "k": 3})[:, 0], [0.03, 0.06])   # no slope yet
    with pytest.raises(ConfigError, match="--extrapolated"):
        train.main(["--extrapolated", "5"])           # the thrust scheme
    with pytest.raises(ConfigError, match="--extrapolated"):
        train.main(["--scheme", "inversion", "--ahead", "5", "--extrapolated", "5"])


def test_the_studys_students_are_learned_in_the_headline():
    """A student flown as ``module:factory`` enters the headline's learned column, not the causal "other"."""
    from lvgym.benchmark.headline import policy_kind
    from lvgym.benchmark.runner import PolicySpec
    for factory in ("experiments.fault_id.inversion:gain6_s0", "experiments.fault_id.inversion:stratos_lead3_s1",
                    "experiments.fault_id.inversion:smile_lead5_gain6_s2",
                    "experiments.fault_id.inversion:smile_lead5_w125_gain6_s0", "experiments.fault_id.estimator:s2"):
        assert policy_kind(PolicySpec("x", factory)) == "learned"


def test_a_configuration_of_the_study_is_a_row_of_factories_and_a_label_to_compare(monkeypatch, tmp_path):
    """Each row of ``STUDENTS`` gives a factory per training seed, which flies that run's file with the row's
    lead, average and non-rigid bandwidth under ``<label>-s<k>``; ``compare`` groups by the rows' labels."""
    from experiments.fault_id import inversion
    from experiments.fault_id.compare import configurations
    from lvgym.agents.policies.observer_net import Ensemble, Estimator, save
    from lvgym.baselines.privileged import GAINS
    rng = np.random.default_rng(0)
    save(Ensemble([Estimator(rng.normal(0.0, 0.1, FEATURES), np.ones(FEATURES), hidden=8, outputs=7)]),
         tmp_path / "inversion-smile-v2-lead5-w1.25-f200e16-gain6-s1.pt")
    monkeypatch.setattr(inversion, "RESULTS", tmp_path)
    env = condition("nonrigid", "smile-v2", mission_time_s=2.0).make_env()
    pol = inversion.smile_lead5_w125_gain6_s1(env)
    assert (pol.name, pol.lead, pol.w, pol.z) == ("inversion-smile-lead5-w125-gain6-s1", 5, 1.25, GAINS["nonrigid"][1])
    assert len(inversion.FACTORIES) == 3 * len(inversion.STUDENTS)
    assert inversion.STUDENTS["smile_lead5_w125_gain6_"].label in configurations()
    save(Ensemble([Estimator(rng.normal(0.0, 0.1, FEATURES), np.ones(FEATURES), hidden=8, outputs=7)]),
         tmp_path / "inversion-gain6-s2.pt")
    faults = inversion.gain6_avg6_lead3_s2(condition("nonrigid", mission_time_s=2.0).make_env())
    assert (faults.name, faults.lead, faults.average) == ("inversion-id-gain6-avg6-lead3-s2", 3, 6)
    save(Ensemble([Estimator(rng.normal(0.0, 0.1, FEATURES), np.ones(FEATURES), hidden=8, outputs=7)]),
         tmp_path / "inversion-ign10-gain6-s0.pt")
    staged = inversion.gain6_ign10_s0(condition("nonrigid", mission_time_s=2.0).make_env())
    assert (staged.name, staged.lead, staged.average) == ("inversion-id-gain6-ign10-s0", 0, 1)
    save(Ensemble([Estimator(rng.normal(0.0, 0.1, FEATURES), np.ones(FEATURES), hidden=8, outputs=7)]),
         tmp_path / "inversion-upset0.5-gain6-s1.pt")
    upset = inversion.gain6_upset_avg6_lead3_s1(condition("nonrigid", mission_time_s=2.0).make_env())
    assert (upset.name, upset.lead, upset.average) == ("inversion-id-gain6-upset-avg6-lead3-s1", 3, 6)
    assert configurations()[0] == "lqg-thrust-id" and len(set(configurations())) == len(configurations())


def test_the_rounds_data_grows_in_place_as_their_concatenation():
    """Batches of windows appended (past the room reserved, then grown by a quarter) read as the batches
    concatenated, as views of one array."""
    from lvgym.agents.training.observer_fit import Data

    rng = np.random.default_rng(0)
    xs = [rng.normal(size=(n, 3, 2)).astype(np.float32) for n in (5, 7, 2, 9)]
    ys = [rng.normal(size=(len(x), 4)).astype(np.float32) for x in xs]
    data = Data()
    data.add(xs[0], ys[0])
    assert len(data) == 5 and len(data.x) == 5                   # no room beyond the first batch
    data.reserve(14)
    data.add(xs[1], ys[1])
    assert len(data) == 12 and len(data.x) == 14
    data.add(xs[2], ys[2])
    data.add(xs[3], ys[3])                                       # 14 + 9 > 14: max(23, 14 + 3)
    assert len(data) == 23 and len(data.x) == 23
    x, y = data.view()
    assert np.array_equal(x, np.concatenate(xs)) and np.array_equal(y, np.concatenate(ys))
    assert x.base is data.x and x.dtype == np.float32 and y.shape == (23, 4)


def test_a_resumed_run_takes_the_finished_rounds_fits_and_ends_as_the_whole_run(monkeypatch, tmp_path, capsys):
    """``--resume``: the rounds' flights are flown again (the same data), each round whose fit was left on disk
    is read, not fitted, and the final ensemble is the uninterrupted run's to the bit."""
    from experiments.fault_id import train
    from lvgym.agents.policies.observer_net import load
    from lvgym.agents.training import dagger

    real = dagger.fly
    monkeypatch.setattr(dagger, "fly", lambda *a, **k: real(*a, mission_time_s=2.0, **k))
    monkeypatch.setattr(train, "RESULTS", tmp_path)
    argv = ["--scheme", "inversion", "--suite", "smile-v2", "--flights", "10", "--rounds", "2", "--epochs", "1",
            "--validation", "0"]
    train.main(argv)
    final = tmp_path / "inversion-smile-v2-s0.pt"
    whole = load(final)
    first = (tmp_path / "inversion-smile-v2-s0-r0.pt").stat().st_mtime_ns
    final.unlink()
    (tmp_path / "inversion-smile-v2-s0-r2.pt").unlink()              # stopped during round 2's fit
    capsys.readouterr()
    train.main([*argv, "--resume"])
    out = capsys.readouterr().out
    assert "round 0: loaded" in out and "round 1: loaded" in out and "round 2: loaded" not in out
    assert (tmp_path / "inversion-smile-v2-s0-r0.pt").stat().st_mtime_ns == first
    again = load(final)
    assert all(torch.equal(a, b) for m, n in zip(whole.members, again.members)
               for a, b in zip(m.state_dict().values(), n.state_dict().values()))


def test_the_bandwidth_names_the_runs_files_and_the_thrust_scheme_refuses_it(monkeypatch, tmp_path):
    from experiments.fault_id import train
    from lvgym.agents.training import dagger

    real = dagger.fly
    monkeypatch.setattr(dagger, "fly", lambda *a, **k: real(*a, mission_time_s=2.0, **k))
    monkeypatch.setattr(train, "RESULTS", tmp_path)
    train.main(["--scheme", "inversion", "--suite", "smile-v2", "--flights", "10", "--rounds", "0", "--epochs", "1",
                "--validation", "0", "--lead", "5", "--bandwidth", "1.25"])
    assert (tmp_path / "inversion-smile-v2-lead5-w1.25-s0.pt").is_file()
    assert train.own_law(1.25) == {"nonrigid": [1.25, 1.0]} and train.own_law(0.0) is None
    with pytest.raises(ConfigError, match="--bandwidth"):
        train.main(["--bandwidth", "1.25"])


@pytest.mark.parametrize(("n", "rows"), [(1, 4), (37, 5), (1000, 64), (20_001, 1 << 16)])
def test_the_fits_standard_deviation_is_numpys_to_the_bit(n, rows):
    """``row_std`` (chunks of ``rows`` rows, no temporary of the whole data) is ``std(0)`` bit for bit."""
    from lvgym.agents.training.observer_fit import row_std
    flat = np.random.default_rng(n).normal(3.0, 2.0, (n, 16)).astype(np.float32)
    assert np.array_equal(row_std(flat, flat.mean(0), rows), flat.std(0))


def test_the_law_gains_study_flies_the_causal_teacher_and_refuses_a_bad_variant():
    """Its variant of the reference's gains, lead 5 over 5, is the law_room's extrapolated teacher flight for
    flight; a bandwidth of 1.25 flies another law; a malformed variant is refused by name."""
    from experiments.fault_id.law_gains import flights, variant
    from experiments.fault_id.privileges import reference
    from lvgym.benchmark.suites import get_suite
    short = {"mission_time_s": 3.0}
    env = condition("nonrigid", "smile-v2", privileged_info=True, **short).make_env()
    teacher = reference(env, preview=False, observed=True, aero_ahead_steps=5)
    mine = flights("smile-v2", "nonrigid", 2, "1,1,0.5,0.9,5,5", **short)
    seeds = [int(k) for k in get_suite("smile-v2").seeds("validation", 2)]
    assert [r["score_v2"] for r in mine] == [play_episode(teacher, env, k, flyability=True)["score_v2"] for k in seeds]
    assert [r["score_v2"] for r in flights("smile-v2", "nonrigid", 2, "1.25,1,0.5,0.9,5,5", **short)] != \
        [r["score_v2"] for r in mine]
    assert variant("1.25,0.9,0.6,1,6,4") == (1.25, 0.9, (0.6, 1.0), 6, 4)
    for bad in ("1,1,0.5,0.9,5", "1,1,0.5,0.9,5,0", "a,1,0.5,0.9,5,5", "1,1,0.5,0.9,5.5,5"):
        with pytest.raises(ConfigError, match="--variants"):
            variant(bad)


def test_one_kind_of_fault_flies_validation_seeds_with_that_kind_only(capsys):
    """Every flight draws the one kind asked (``thrust``: no axis); the printed count is the lost flights';
    a range that ends before it starts is refused by name."""
    from experiments.fault_id.one_kind import main
    out = main(["--kind", "thrust", "--first", "3", "--last", "5", "--policies", "zero", "--model", "rigid"])
    records = out["zero"]
    assert len(records) == 2 and all(r["fault"] == "thrust" for r in records)
    printed = capsys.readouterr().out
    assert f"failed or unflyable {sum(lost(r) for r in records)}" in printed and "seeds 3-4" in printed
    with pytest.raises(ConfigError, match="--last"):
        main(["--first", "5", "--last", "5"])


def test_the_rounds_weights_grow_with_their_data_and_weigh_the_fits_mean_error(capsys):
    """The weights appended beside the windows (1 where none are given; None, the plain mean, when all are
    1), and a fit's first epoch in one batch reports the weighted mean of the initial network's errors:
    sum(w mean_j e_j^2) / sum(w), the network drawn from the same seed."""
    from lvgym.agents.policies.observer_net import Estimator
    from lvgym.agents.training.observer_fit import Data

    rng = np.random.default_rng(1)
    x = rng.normal(size=(40, WINDOW, FEATURES)).astype(np.float32)
    y = rng.normal(size=(40, 3)).astype(np.float32)
    data = Data()
    data.add(x[:10], y[:10])
    assert data.weights() is None
    data.add(x[10:], y[10:], np.where(np.arange(30) < 5, 10.0, 1.0))
    w = data.weights()
    assert w.dtype == np.float32 and np.array_equal(w, np.r_[np.ones(10), np.full(5, 10.0), np.ones(25)])
    capsys.readouterr()
    fit(*data.view(), seed=3, epochs=1, scaled=True, weight=w)
    reported = float(capsys.readouterr().out.split("mean squared error ")[1].split()[0])
    torch.manual_seed(3)
    flat = x.reshape(-1, FEATURES)
    from lvgym.agents.training.observer_fit import row_std
    first = Estimator(flat.mean(0), row_std(flat, flat.mean(0)) + 1e-6, outputs=3, label_mean=y.mean(0),
                      label_std=y.std(0) + 1e-6)
    with torch.no_grad():
        e = (((first(torch.as_tensor(x)) - torch.as_tensor(y)) / first.label_std) ** 2).mean(1).numpy()
    assert reported == pytest.approx(float((e * w).sum() / w.sum()), rel=1e-3)
    assert reported != pytest.approx(float(e.mean()), rel=1e-2)


def test_the_ignition_weight_names_the_runs_files_and_weighs_the_windows_after_ignition(monkeypatch, tmp_path):
    """``--ignition-weight 10 --ignition-s 1``: the windows fewer than 1 s after the next stage's ignition
    (the flights' times since it, here every other step 0.5 s after, the rest before) weigh 10 in the fit;
    the files end ``-ign10``."""
    from experiments.fault_id import train
    from lvgym.agents.training import dagger

    real, seen = dagger.fly, []

    def fly_short(*a, **k):
        x, y, r, _ = real(*a, mission_time_s=2.0, **k)
        return x, y, r, np.where(np.arange(len(x)) % 2 == 1, 0.5, -1.0)

    def fit_seen(x, y, seed, epochs, scaled=False, weight=None):
        seen.append(weight.copy())
        return real_fit(x, y, seed, epochs, scaled, weight)

    real_fit = dagger.fit
    monkeypatch.setattr(dagger, "fly", fly_short)
    monkeypatch.setattr(dagger, "fit", fit_seen)
    monkeypatch.setattr(train, "RESULTS", tmp_path)
    train.main(["--scheme", "inversion", "--suite", "smile-v2", "--flights", "10", "--rounds", "0", "--epochs", "1",
                "--validation", "0", "--ignition-weight", "10", "--ignition-s", "1"])
    assert (tmp_path / "inversion-smile-v2-ign10-s0.pt").is_file()
    (w,) = seen
    per_batch = np.where(np.arange(len(w) // 2) % 2 == 1, 10.0, 1.0)       # two batches (rigid, non-rigid)
    assert np.array_equal(w, np.r_[per_batch, per_batch])


def test_the_teachers_upset_cancels_a_drawn_share_of_the_moment_for_a_drawn_while_after_ignition(monkeypatch):
    """``upset=1``: every teacher flight draws a share of the aerodynamic moment in ``UPSET_GAIN`` and a
    duration in ``UPSET_S``; within it after ignition its action is the law on the moment times that share,
    before ignition (-1) and after it the law on the truth (without exploration noise); a student is never
    upset, and the thrust scheme refuses it."""
    from experiments.fault_id import train
    from lvgym.agents.policies.inversion import command, error_index, gains

    monkeypatch.setattr(train, "NOISE", (0.0,))
    env1 = condition("nonrigid", privileged_info=True, mission_time_s=2.0).make_env()
    pilot = train.InversionScheme(env1, 3, np.random.default_rng(4), 0.0, upset=1.0)
    assert np.all((pilot.upset_gain >= 0.3) & (pilot.upset_gain <= 0.8))
    assert np.all((pilot.upset_s >= 0.5) & (pilot.upset_s <= 2.0))
    truth = np.random.default_rng(5).uniform(0.1, 0.5, (3, 7))
    pilot.truth = truth.copy()
    obs = np.random.default_rng(6).normal(0.0, 0.01, (3, 14))
    since = np.array([0.2, -1.0, pilot.upset_s[2] + 0.02])
    got = pilot.act(np.arange(3), obs, {}, None, since)
    upset = truth.copy()
    upset[0, 0:2] *= pilot.upset_gain[0]
    w, z = gains(env1)
    want = np.clip(command(obs, np.r_[upset[:1], truth[1:]], error_index(env1), w, z), -1.0, 1.0)
    np.testing.assert_allclose(got, want, rtol=1e-6)
    assert np.all(train.InversionScheme(env1, 3, None, 0.0, upset=1.0).upset_gain == 1.0)
    with pytest.raises(ValueError, match="upset"):
        fly("rigid", [7], None, np.random.default_rng(0), upset=0.5, mission_time_s=1.0)
    with pytest.raises(ConfigError, match="--upset"):
        train.main(["--upset", "0.5"])
