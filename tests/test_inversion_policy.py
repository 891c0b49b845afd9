"""The shipped disturbance-observer policy ``inversion-id`` (lvgym.agents.policies.inversion,
lvgym.agents.policies.observer): the observer's window, the law's terms and command by hand, the NumPy observer against
the torch network it was fitted as, the shipped file against its record, the envs it refuses, its batch against its
single env to the bit, and that it flies without torch."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys

import numpy as np
import pytest
import torch

import lvgym
import lvgym.cli.policies  # noqa: F401  (registers the built-in policies)
from lvgym.agents.policies.inversion import (A_MAX, SHIPPED, TERMS, TRAINED, InversionPolicy, Lead, command,
                                             env_record, from_file, law_terms)
from lvgym.agents.policies.observer import FEATURES, N_OBS, WINDOW, Observer, Window
from lvgym.agents.policies.observer_net import Ensemble, Estimator, load, save, to_observer
from lvgym.benchmark.headline import policy_kind
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.runner import build_policy, play_episode
from lvgym.errors import ConfigError


def _ensemble(outputs: int = len(TERMS), hidden: int = 8, k: int = 3) -> Ensemble:
    torch.manual_seed(0)
    rng = np.random.default_rng(1)
    return Ensemble([Estimator(rng.normal(0.0, 0.1, FEATURES), rng.uniform(0.5, 2.0, FEATURES), hidden=hidden,
                               outputs=outputs, label_mean=rng.normal(0.0, 0.1, outputs),
                               label_std=rng.uniform(0.05, 0.5, outputs)) for _ in range(k)])


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
    w.reset(rows)
    assert not w.x.any() and not w.last_action.any()


def test_the_terms_and_the_command_by_hand():
    limit = 0.1
    info = {"m_aero_b": np.array([[0.0, 2.0e4, -1.0e4], [0.0, 5.0, 5.0]]), "thrust": np.array([1.0e5, 0.0]),
            "vectored_share": np.array([1.0, 1.0]), "gimbal_arm": np.array([2.0, 2.0]),
            "actuator_effectiveness": np.array([[0.5, 1.0], [1.0, 1.0]]),
            "misalignment": np.array([[0.01, -0.02], [0.0, 0.0]]), "J_b_diag": np.array([[1.0, 4.0e4, 3.0e6]] * 2),
            "qalpha_pa_deg": np.array([1.0e5, 0.0]), "qalpha_limit_pa_deg": np.array([2.5e5, 2.5e5])}
    t = law_terms(info, 2, limit)
    lever = 2.0e5                                                    # T l [N m per rad]
    np.testing.assert_allclose(t[0, :4], [0.1 / 0.5 / limit, -0.05 / limit, 0.01 / 0.5 / limit, -0.02 / limit])
    np.testing.assert_allclose(t[0, 4:], [4.0e4 / lever / 0.5 / limit, A_MAX, 0.4])   # yaw's a at its ceiling
    assert np.all(t[1] == 0.0) and np.all(law_terms({}, 2, limit) == 0.0)      # no thrust; the reset's info
    ahead = np.zeros((2, 10, 3))
    ahead[0, 4] = [0.0, -4.0e4, 1.0e4]                              # the moment 5 periods ahead
    t5 = law_terms(dict(info, m_aero_ahead_b=ahead), 2, limit, ahead=5)
    np.testing.assert_allclose(t5[0, :2], [-0.2 / 0.5 / limit, 0.05 / limit])
    np.testing.assert_allclose(t5[:, 2:], t[:, 2:])                 # the other terms as they are
    obs = np.array([[0.1, -0.2, 0.01, 0.0]])                         # rate errors, attitude errors
    w, z = 1.5, 1.0
    alpha = np.array([-2 * z * w * 0.1 - w * w * 0.01, -2 * z * w * -0.2])
    terms = np.array([[0.3, -0.1, 0.05, 0.0, 2.0, 1.0, 0.4]])      # below the relief's onset (0.5)
    np.testing.assert_allclose(command(obs, terms, [0, 1, 2, 3], w, z)[0],
                               [2.0 * alpha[0] - 0.3 - 0.05, 1.0 * alpha[1] + 0.1], rtol=1e-6)
    terms[0, 6] = 0.7                                                # half-way: h = 0.5
    half = np.array([-2 * z * w * 0.1 - 0.5 * w * w * 0.01, alpha[1]])
    np.testing.assert_allclose(command(obs, terms, [0, 1, 2, 3], w, z)[0],
                               [2.0 * half[0] - 0.15 - 0.05, 1.0 * half[1] + 0.05], rtol=1e-6)


def test_an_ensemble_is_the_mean_of_its_members_and_saves_whole(tmp_path):
    ens = _ensemble(outputs=3)
    members = list(ens.members)
    x = torch.randn(4, WINDOW, FEATURES)
    with torch.no_grad():
        want = sum(m(x) for m in members) / 3
        assert torch.allclose(ens(x), want, atol=1e-6)
        save(ens, tmp_path / "e.pt")
        assert torch.allclose(load(tmp_path / "e.pt")(x), want, atol=1e-6)
        save(members[0], tmp_path / "one.pt")                     # one estimator: its own state
        assert torch.allclose(load(tmp_path / "one.pt")(x), members[0](x))


def test_the_numpy_observer_is_the_fitted_network(tmp_path):
    """The flight computer's fused NumPy forward against torch's, over windows of the features' scale; its
    file round trip to the bit."""
    ens = _ensemble(hidden=32)
    x = np.random.default_rng(2).normal(0.0, 1.0, (16, WINDOW, FEATURES)).astype(np.float32)
    with torch.no_grad():
        want = ens(torch.as_tensor(x)).numpy()
    obs = to_observer(ens)
    got = np.stack([obs(w) for w in x])
    assert got.shape == (16, len(TERMS)) and got.dtype == np.float64
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-6)
    obs.save(tmp_path / "o.npz")
    again = Observer.load(tmp_path / "o.npz")
    assert all(np.array_equal(again(w), obs(w)) for w in x)
    with pytest.raises(FileNotFoundError, match="no observer file"):
        Observer.load(tmp_path / "missing.npz")
    with pytest.raises(ValueError, match="features"):
        Observer([{k: (v[:, :10] if k == "w0" else v) for k, v in obs.members[0].items()}])


@pytest.mark.parametrize(("stem", "suite", "lead"), [(SHIPPED, "smile-v2-faults", 3),
                                                     ("inversion_id_stratos_tvc_v2", "stratos-tvc-v2", 3),
                                                     ("inversion_id_smile_v2", "smile-v2", 5)])
def test_the_shipped_observers_are_their_records(stem, suite, lead):
    """The weights are the file the record's SHA-256 names; the record names the env it was trained on, the
    training command, the validation of every candidate seed, the one chosen and the law's lead: trained with
    (``--lead``), or chosen after training with the other flight options (its ``flight``: the options, the
    commands that flew them on validation seeds, and what each scored)."""
    record = json.loads((TRAINED / f"{stem}.json").read_text())
    data = (TRAINED / f"{stem}.npz").read_bytes()
    assert hashlib.sha256(data).hexdigest() == record["sha256"]
    env = lvgym.make_env(suite, "nonrigid")
    assert record["env"] == env_record(env) and record["suite"] == suite
    command = record["training"]["command"]
    assert command.startswith("lvgym train --recipe teacher-student ") and record.get("lead", 0) == lead
    assert f"--suite {suite}" in command
    flight = record.get("flight", {}).get("options", {})
    trained = f"--lead {lead}" in command
    assert trained == (bool(lead) and "lead" not in flight) and (trained or flight.get("lead", 0) == lead)
    if flight:                                          # chosen after training: flown, and on validation seeds
        assert all(record[key] == value for key, value in flight.items())
        assert all("--seed-set validation" in c or c.startswith("lvgym train --recipe teacher-student ")
                   for c in record["flight"]["commands"])
        assert "as trained" in record["flight"]["validation"]
    chosen = record["validation"]["chosen"]
    assert str(chosen) in record["validation"]["candidates"] and len(record["validation"]["candidates"]) >= 3
    assert Observer.load(TRAINED / f"{stem}.npz").outputs == len(TERMS)


@pytest.mark.parametrize(("name", "suite", "lead", "average", "ignition_steps", "share"),
                         [("inversion-id", "smile-v2-faults", 3, 6, 200, 0.5),
                          ("inversion-id-stratos", "stratos-tvc-v2", 3, 1, 0, 1.0),
                          ("inversion-id-smile", "smile-v2", 5, 1, 0, 1.0)])
def test_the_shipped_policies_are_registered_learned_and_causal(name, suite, lead, average, ignition_steps, share):
    """Each flies its record's options: ``inversion-id`` its moment averaged over 6 steps and carried 3 ahead,
    and half the measured moment and half its estimate for 4 s (200 control steps) after the next stage's
    ignition."""
    spec = resolve_policy(name)
    assert policy_kind(spec) == "learned"
    assert name in lvgym.benchmark.get_suite(suite).policies
    pol = build_policy(spec, lvgym.make_env(suite, "rigid"))
    assert isinstance(pol, InversionPolicy) and pol.name == name and pol.lead == lead
    assert pol.average == average and pol.staging.steps == ignition_steps and pol.staging.share == share


@pytest.mark.parametrize(("name", "suite", "key"), [("inversion-id", "stratos-tvc-v2", "vehicle"),
                                                    ("inversion-id", "smile-v1", "history"),
                                                    ("inversion-id-stratos", "smile-v2", "vehicle"),
                                                    ("inversion-id-smile", "stratos-tvc-v2", "vehicle")])
def test_it_refuses_an_env_it_was_not_trained_on(name, suite, key):
    spec = resolve_policy(name)
    env = lvgym.make_env(suite, "nonrigid", **({"history": 4} if key == "history" else {}))
    with pytest.raises(ConfigError) as err:
        build_policy(spec, env)
    assert key in str(err.value)


def test_a_study_file_flies_on_its_torch_weights(tmp_path):
    """``from_file`` takes a training run's ``.pt`` as its ``.npz``: the same estimates to float32 rounding."""
    ens = _ensemble(hidden=16)
    save(ens, tmp_path / "run.pt")
    to_observer(ens).save(tmp_path / "run.npz")
    env = lvgym.make_env("smile-v2-faults", "nonrigid", mission_time_s=3.0)
    a = play_episode(from_file(env, tmp_path / "run.pt"), env, 3, flyability=True)
    b = play_episode(from_file(env, tmp_path / "run.npz"), env, 3, flyability=True)
    assert a["score_v2"] == pytest.approx(b["score_v2"], rel=1e-6)


def test_the_shipped_policy_flies_without_torch():
    code = ("import sys, lvgym, lvgym.cli.policies\n"
            "from lvgym.benchmark.registry import resolve_policy\n"
            "from lvgym.benchmark.runner import build_policy, play_episode\n"
            "env = lvgym.make_env('smile-v2-faults', 'nonrigid', mission_time_s=2.5)\n"
            "r = play_episode(build_policy(resolve_policy('inversion-id'), env), env, 0)\n"
            "print('torch' in sys.modules, r['duration_s'])\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out[0] == "False" and float(out[1]) == pytest.approx(2.5, abs=0.03)


def test_a_lead_carries_the_moment_along_its_slope_by_hand():
    """Two rows of ramps (0.01 and 0.02 per step): 3 steps ahead along the last 5 is the ramp 3 steps on, from
    the sixth step; before, along the slope from the first step (over 5); none at the first step; a row's
    reset starts it again without touching the other; lead 0 is the terms as they are."""
    lead, rows = Lead(2, 3), np.arange(2)
    slopes = np.array([[0.01, 0.0], [0.02, -0.01]])
    first = lead.push(rows, slopes * 1)
    np.testing.assert_allclose(first, slopes)                               # no slope yet
    second = lead.push(rows, slopes * 2)
    np.testing.assert_allclose(second, slopes * (2 + 3 * 1 / 5))            # one step's rise over 5
    for k in range(3, 9):
        out = lead.push(rows, slopes * k)
    np.testing.assert_allclose(out, slopes * (8 + 3))
    lead.reset(np.array([0]))
    out = lead.push(np.array([0, 1]), slopes * np.array([[1.0], [9.0]]))
    np.testing.assert_allclose(out, [slopes[0], slopes[1] * (9 + 3)])
    still = Lead(1, 0)
    np.testing.assert_array_equal(still.push(np.zeros(1, dtype=np.int64), [[0.3, -0.2]]), [[0.3, -0.2]])
    with pytest.raises(ConfigError, match="lead"):
        Lead(1, -1)


def test_an_average_before_the_lead_by_hand():
    """Averaged over 4 steps: the mean of the steps so far until the fourth, then of the last 4; an oscillation
    of period 4 is removed whole; with a lead of 2 over 5 the average of a ramp (1.5 steps behind it) is
    carried 2 steps along its own slope; a reset starts the average again; an average under 1 is refused."""
    avg, row = Lead(1, 0, average=4), np.zeros(1, dtype=np.int64)
    out = [avg.push(row, [[float(k), -float(k)]])[0, 0] for k in range(1, 7)]
    np.testing.assert_allclose(out, [1.0, 1.5, 2.0, 2.5, 3.5, 4.5])
    wave = [avg.push(row, [[v, 0.0]])[0, 0] for v in [1.0, 0.0, -1.0, 0.0] * 3]
    np.testing.assert_allclose(wave[4:], 0.0, atol=1e-12)
    both = Lead(1, 2, average=4)
    for k in range(1, 11):
        got = both.push(row, [[0.1 * k, 0.0]])[0, 0]
    np.testing.assert_allclose(got, 0.1 * (10 - 1.5) + 2 * 0.1)
    both.reset(row)
    np.testing.assert_allclose(both.push(row, [[0.7, 0.3]]), [[0.7, 0.3]])
    with pytest.raises(ConfigError, match="average"):
        Lead(1, 0, average=0)


@pytest.mark.parametrize("average", [1, 6])
def test_a_policy_with_a_lead_commands_the_law_on_the_moment_ahead_and_its_batch_is_its_rows(average):
    """A ramp of estimated moments: the action is the law's on the ramp 3 steps on (on its average over 6
    steps, 2.5 steps behind it, carried along its slope); the batch of two rows gives each row its single
    policy's actions, to the bit."""
    env = lvgym.make_env("smile-v2-faults", "rigid", mission_time_s=3.0)
    calls = []

    def ramp(window):
        calls.append(1)
        return np.array([0.01 * len(calls), 0.0, 0.0, 0.0, 1.0, 1.0, 0.0])

    p = InversionPolicy(env, ramp, name="x", lead=3, average=average)
    obs = np.zeros(14, np.float32)
    for _ in range(12):
        a = p.act(obs, {})
    moment = 0.12 - 0.01 * (average - 1) / 2 + 3 * 0.01
    want = command(obs[None], np.array([[moment, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0]]), p.index, p.w, p.z)[0]
    np.testing.assert_allclose(a, want, rtol=1e-6)
    observer = to_observer(_ensemble(hidden=16))
    single = [InversionPolicy(env, observer, lead=3, average=average) for _ in range(2)]
    batch = InversionPolicy(env, observer, lead=3, average=average).batch(2)
    batch.reset([0, 1])
    rng = np.random.default_rng(0)
    for step in range(30):
        o = rng.normal(0.0, 0.05, (2, 14)).astype(np.float32)
        rows = np.array([0, 1]) if step != 12 else np.array([1])            # row 0 sits out a step
        got = batch.act(rows, o[rows], {})
        for j, r in enumerate(rows):
            np.testing.assert_array_equal(got[j], single[r].act(o[r], {}))


def test_the_laws_own_gains_per_flight_model_by_hand_and_refused_by_name():
    """A record's ``law`` sets the bandwidth and damping of the flight model it names (as a dict or as a policy
    spec's pairs), the other keeps the reference's; the command is the law's with them (by hand: a rate error of
    0.1 rad/s with ``a`` = 0.5 commands -0.5 * 2 * z * w * 0.1); an unknown model or a bad value is refused by
    name, and a shipped record's ``law`` is what its policy flies."""
    from lvgym.agents.policies.inversion import gains
    from lvgym.baselines.privileged import GAINS

    rigid, nonrigid = (lvgym.make_env("smile-v2", m, mission_time_s=2.0) for m in ("rigid", "nonrigid"))
    law = {"nonrigid": [1.25, 0.9]}
    assert gains(nonrigid, law) == (1.25, 0.9) and gains(rigid, law) == GAINS["rigid"]
    assert gains(nonrigid, (("nonrigid", (1.25, 0.9)),)) == (1.25, 0.9) and gains(nonrigid) == GAINS["nonrigid"]
    p = InversionPolicy(nonrigid, lambda w: np.array([0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.0]), law=law)
    obs = np.zeros(14, np.float32)
    obs[p.index[0]] = 0.1
    np.testing.assert_allclose(p.act(obs, {}), [-0.5 * 2 * 0.9 * 1.25 * 0.1, 0.0], rtol=1e-6)
    with pytest.raises(ConfigError, match="law") as err:
        gains(nonrigid, {"non-rigid": [1.25, 1.0]})
    assert "non-rigid" in str(err.value) and "nonrigid" in str(err.value)
    for bad in ([0.0, 1.0], [1.25], "fast"):
        with pytest.raises(ConfigError, match="law nonrigid"):
            gains(nonrigid, {"nonrigid": bad})
    for stem, name in ((SHIPPED, "inversion-id"), ("inversion_id_stratos_tvc_v2", "inversion-id-stratos"),
                       ("inversion_id_smile_v2", "inversion-id-smile")):
        record = json.loads((TRAINED / f"{stem}.json").read_text())
        assert ("law" in record) == ("--bandwidth" in record["training"]["command"])
        pol = build_policy(resolve_policy(name), lvgym.make_env(record["suite"], "nonrigid", mission_time_s=2.0))
        assert (pol.w, pol.z) == gains(nonrigid, record.get("law"))
