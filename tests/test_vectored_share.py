"""A vectored share of thrust (an engine's ``vectored_share``): the key validated, the mass model's share,
the flight loads turning only that share with the rest along the body axis, and the linear design's control
derivative scaled by it. The shipped vehicles (share 1) fly bit for bit as before: the protocol fingerprints
(tests/test_protocol_fingerprint.py) hold them to it."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml

import lvgym
from lvgym.errors import ConfigError
from lvgym.vehicle import MassModel
from lvgym.vehicle.config import VEHICLE_DIR, parse_vehicle

SMILE = yaml.safe_load((VEHICLE_DIR / "smile_v1.yaml").read_text())


def _with_share(share: float) -> dict:
    data = copy.deepcopy(SMILE)
    data["stages"][0]["engines"][0]["vectored_share"] = share
    return data


def _file(tmp_path, share: float):
    path = tmp_path / f"smile_share_{share:g}.yaml"
    path.write_text(yaml.safe_dump(_with_share(share)), encoding="utf-8")
    return str(path)


def test_the_key_is_a_share_and_a_bad_one_is_named():
    v = parse_vehicle(_with_share(0.25), source="v.yaml")
    assert v.stages[0].engines[0].vectored_share == 0.25 and v.stages[1].engines[0].vectored_share == 1.0
    with pytest.raises(ConfigError, match=r"^v\.yaml: stages\[0\]\.engines\[0\]\.vectored_share = 1\.5: .*1"):
        parse_vehicle(_with_share(1.5), source="v.yaml")


def test_the_mass_model_weights_the_burning_engines_and_is_one_without_thrust():
    mm = MassModel(parse_vehicle(_with_share(0.4), source="v.yaml"))
    s0 = mm.initial_state()
    assert mm.vectored_share(s0) == pytest.approx(0.4) and mm.thrust(s0) > 0.0
    coast = mm.advance(s0, 48.0)[0]                              # the staging coast: nothing burns
    assert mm.thrust(coast) == 0.0 and mm.vectored_share(coast) == 1.0
    upper = mm.advance(coast, 60.0)[0]                           # the second stage's engine: share 1
    assert mm.thrust(upper) > 0.0 and mm.vectored_share(upper) == 1.0


def _fly(path: str, action: np.ndarray, steps: int = 20):
    env = lvgym.make_env("smile-v1", model="rigid", vehicle=path, wind="none", randomize=[], mission_time_s=2.0,
                         controller_on_after_s=0.0)
    env.reset(seed=0)
    for _ in range(steps):
        info = env.step(action)[4]
    flight = env.unwrapped.flight
    return flight.conditions("thrust")[0], flight.conditions("thrust_b")[0], info["gimbal"]


def test_the_flight_loads_turn_only_the_vectored_share(tmp_path):
    action = np.array([0.6, -0.4], np.float32)
    for share in (1.0, 0.5):
        thrust, thrust_b, (dp, dy) = _fly(_file(tmp_path, share), action)
        assert thrust > 1e5 and abs(dp) > 1e-3 and abs(dy) > 1e-3
        turned = share * thrust
        np.testing.assert_allclose(thrust_b, [turned * math.cos(dp) * math.cos(dy) + (thrust - turned),
                                              -turned * math.sin(dy), turned * math.sin(dp) * math.cos(dy)], rtol=1e-12)


def test_a_share_of_one_in_the_file_flies_the_shipped_vehicle_to_the_bit(tmp_path):
    action = np.array([0.3, 0.2], np.float32)
    shipped = _fly("smile_v1", action)
    written = _fly(_file(tmp_path, 1.0), action)
    assert shipped[0] == written[0] and np.array_equal(shipped[1], written[1])


def test_the_linear_design_scales_the_control_derivative(tmp_path):
    from lvgym.baselines.design.linearize import analytic_rigid, operating_point

    full = analytic_rigid(operating_point(_file(tmp_path, 1.0), 10.0, "rigid", protocol="v1"))
    half = analytic_rigid(operating_point(_file(tmp_path, 0.5), 10.0, "rigid", protocol="v1"))
    np.testing.assert_allclose(half.B[:, 0], 0.5 * full.B[:, 0], rtol=1e-9)
    np.testing.assert_allclose(half.A, full.A, rtol=1e-9)          # the gimbal centred: the same flight
