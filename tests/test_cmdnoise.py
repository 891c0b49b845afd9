"""The gimbal rate the gyro's noise commands through a policy, measured in the nonlinear simulation
(experiments.command_noise.cmdnoise), against the linear loop's value (lvgym.baselines.design.noise) and for the zero policy."""

import math
import warnings

import control
import numpy as np
import pytest

from lvgym.baselines.filters import StructuralFilter
from lvgym.baselines.design.flexdesign import controller_tf, row_plants
from lvgym.baselines.design.noise import command_noise_rate
from lvgym.baselines.pid import GainSchedule
from experiments.command_noise import cmdnoise
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.suites import get_suite


def _rigid(mission_time_s: float):
    cond = [c for c in get_suite("smile-v1").conditions if c.model == "rigid"][0]
    return cond.with_options(mission_time_s=mission_time_s)


def test_zero_policy_commands_no_rate_and_the_table_says_so():
    rec = cmdnoise.command_noise_episode(cmdnoise.NoiseTask(POLICIES["zero"], _rigid(4.0), 0))
    assert rec["samples"] == 200 and rec["noise"] == 0.0 and rec["noise_boost"] == 0.0
    assert np.isnan(rec["noise_upper"])                       # no upper stage in 4 s
    table = cmdnoise.noise_table([rec])
    assert "| zero | smile-v1/rigid | 1 | 0.00 (0.00-0.00) | 0.00 | 0.00 | - |" in table


def test_gs_pid_flex_noise_in_flight_is_the_linear_loops():
    """Over 7-12 s the shipped gs-pid-flex flies its 10 s row (stretch 6.5-12.5 s): the RMS of the
    gimbal rate its command's response to the gyro noise asks for, flown (two validation seeds, both
    axes), against lvgym.baselines.design.noise.command_noise_rate of that row on the rigid pitch plant at 10 s, within
    15 % (250 samples per axis and seed)."""
    sched = GainSchedule.load("smile_flex")
    r = min(sched.meta["rows"], key=lambda r: abs(r["time_s"] - 10.0))
    assert r["time_s"] == 10.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        C = control.ss(controller_tf((r["kp"], r["ki"], r["kd"]), StructuralFilter.from_dict(r["filter"]), 0.02))
        plants, _, info = row_plants("smile", 10.0, None)
        linear = command_noise_rate(C, plants["pitch"]["rigid"], *info["noise"])
    cond, spec = _rigid(12.5), POLICIES["gs-pid-flex"]
    flown = []
    for seed in (0, 1):
        loud = cmdnoise._fly(spec, cond, seed)
        quiet = cmdnoise._fly(spec, cond.with_options(gyro_arw_rad_per_sqrt_s=0.0), seed)
        m = (loud["t"] > 7.0) & (loud["t"] <= 12.0)
        rate = np.diff((loud["action"] - quiet["action"]) * loud["limit"], axis=0) / loud["dt"]
        flown.extend(np.sqrt(np.mean(rate[m[1:]] ** 2, axis=0)) / loud["rate_limit"])
    assert loud["rate_limit"] == pytest.approx(math.radians(30.0))
    assert np.mean(flown) == pytest.approx(linear, rel=0.15), (flown, linear)
