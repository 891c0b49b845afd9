"""The fault-identification study (experiments.fault_id): the estimator's window and correction by hand, the
plant-knowing variants by hand, and the student flown in a batch against the benchmark's single env."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from experiments.fault_id.estimator import FEATURES, N_OBS, WINDOW, FaultIdPolicy, Window, corrected
from experiments.fault_id.privileges import VARIANTS, PlantKnown, specs
from experiments.fault_id.train import condition, fit, fly
from lvgym.benchmark.runner import play_episode
from lvgym.errors import ConfigError


def test_the_window_keeps_the_last_steps_oldest_first():
    w = Window(2)
    rows = np.array([1])
    for k in range(WINDOW + 2):
        w.push(rows, np.full((1, N_OBS), k, np.float32))
        w.sent(rows, np.array([[10.0 + k, -k]], np.float32))
    x = w.x[1]
    assert x[-1, 0] == WINDOW + 1 and x[0, 0] == 2                 # the last WINDOW steps' observations
    assert x[-1, N_OBS] == 10.0 + WINDOW and x[-1, N_OBS + 1] == -WINDOW   # with the action sent before them
    assert np.all(w.x[0] == 0.0) and x.shape == (WINDOW, FEATURES)  # row 0 untouched


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
    p.mis, p.eff, p.late, p.static = True, True, 1, False
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
    x, y, _ = fly("rigid", [0, 1], None, np.random.default_rng(0), **short)
    assert x.shape[1:] == (WINDOW, FEATURES) and y.shape == (len(x), 2)
    est = fit(x, y, seed=0, epochs=1)
    _, _, batch = fly("rigid", [5, 6], est, deadband=0.04, **short)
    env = condition("rigid", **short).make_env()
    for seed, rec in zip([5, 6], batch):
        single = play_episode(FaultIdPolicy(env, est, deadband=0.04), env, seed, flyability=True)
        assert single["score_v2"] == pytest.approx(rec["score_v2"], rel=1e-6)
        assert single["max_qalpha_pa_deg"] == pytest.approx(rec["max_qalpha_pa_deg"], rel=1e-6)
