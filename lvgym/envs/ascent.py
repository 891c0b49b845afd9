"""Gymnasium environments of thrust-vector (and roll) control in ascent.

Physics lives in the simulator; :class:`~.core.AscentBatch` shapes the task; these classes only adapt
one row of it to ``gymnasium.Env``. Options are keywords (see :class:`~.spec.TaskSpec`), e.g.
``gymnasium.make("lvgym/SmileAscent-v0", model="rigid", wind="turbulence", randomize=True)``.

Observation (``Box(-inf, inf, (14,), float32)``), for ``observation="state"`` (ideal) and ``"sensors"``:

===  ==========================  ===========================================================================
0    roll rate [rad/s]           true body rate; ``sensors``: gyro at the IMU station (sees the bending
                                 slope rate), with bias and noise when ``sensor_noise`` is randomised
1    pitch rate error [rad/s]    rate minus the reference rate
2    yaw rate error [rad/s]
3-4  pitch, yaw attitude error   body axis against the reference axis [rad] (``sensors``: with noise)
5-6  alpha, beta [rad]           ``sensors``: lateral specific force z, y over g0 (accelerometers)
7    Mach / 10
8    dynamic pressure / 1e5 Pa
9-10 gimbal pitch, yaw           actuator position over the gimbal limit
11   time / mission time
12   controller on (0 or 1)      off before ``controller_on_after_s`` and during staging coasts
13   reference pitch rate [rad/s]
===  ==========================  ===========================================================================

Reward: ``-sum_axis w_axis |rate - reference| dt`` (terms ``rate_roll``, ``rate_pitch``, ``rate_yaw``; so the
episode's sum is minus the weighted cumulative rate error in rad) ``- effort_weight * int |gimbal| dt``
(``effort``) ``- effort_rate_weight * int |gimbal rate| dt`` (``effort_rate``) and, on termination,
``- failure_penalty_rad_per_s * remaining time`` (``failure``). ``info["reward_terms"]`` holds each term;
they add up to the reward.

Termination: a non-finite state (``info["termination"] == "non-finite state"``, never an exception),
dynamic pressure times total angle of attack above ``qalpha_limit_pa_deg``, attitude error above
``attitude_limit_deg``. Truncation: at the end of ``mission_time_s`` only.

Version history: v0 (2026-11): first release.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from .core import OBS_NAMES, AscentBatch
from .spec import TaskSpec

#: Mach number at which SlenderAscent-v0 freezes the vehicle's aerodynamic tables by default [-]
DEFAULT_AERO_MACH = 2.0


def _row(info: dict[str, Any], b: int) -> dict[str, Any]:
    """The info of row ``b`` of a batch info dict (scalars as Python floats)."""
    out: dict[str, Any] = {}
    for key, value in info.items():
        if key == "reward_terms":
            out[key] = {k: float(v[b]) for k, v in value.items()}
        elif key == "events":
            out[key] = list(value[b])
        else:
            v = value[b]
            out[key] = v.item() if isinstance(v, np.generic) else v
    return out


def _rows(info: dict[str, Any], batch: int) -> list[dict[str, Any]]:
    """The infos of every row of a batch info dict, as :func:`_row` gives them, built column by column
    (one ``tolist`` per key instead of one look-up per key and row)."""
    columns: dict[str, list] = {}
    for key, value in info.items():
        if key == "reward_terms":
            names = list(value)
            columns[key] = [dict(zip(names, vals)) for vals in zip(*(value[k].tolist() for k in names))]
        elif key == "events":
            columns[key] = [list(e) for e in value]
        elif value.ndim == 1:
            columns[key] = value.tolist()
        else:
            columns[key] = list(value)
    keys = list(columns)
    return [dict(zip(keys, vals)) for vals in zip(*columns.values())] if keys else [{} for _ in range(batch)]


def make_spaces(task: TaskSpec) -> tuple[spaces.Space, spaces.Box]:
    """Action and observation spaces of one env of ``task``."""
    if task.control == "tvc":
        action = spaces.Box(-1.0, 1.0, (2,), np.float32)
    else:
        action = spaces.MultiDiscrete([3])
    return action, spaces.Box(-np.inf, np.inf, (len(OBS_NAMES),), np.float32)


class AscentEnv(gym.Env):
    """Base of the ascent envs: one row of an :class:`AscentBatch`. Subclasses set ``DEFAULTS``."""

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 25}
    DEFAULTS: dict[str, Any] = {}

    def __init__(self, render_mode: str | None = None, **options: Any) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode = {render_mode!r}: one of {self.metadata['render_modes']} or None")
        self.render_mode = render_mode
        self.task = TaskSpec.build(self.DEFAULTS, options)
        self.core = AscentBatch(self.task, 1)
        self.action_space, self.observation_space = make_spaces(self.task)
        self._renderer: Any = None
        self._rates: list[tuple[float, float, float]] = []

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        obs = self.core.reset_rows(np.array([0]), [self.np_random])[0]
        self._rates = []
        return obs, {"time": 0.0, "cumulative_rate_error": np.zeros(3)}

    def step(self, action):
        obs, reward, terminated, truncated, info = self.core.step(np.asarray(action)[None])
        row = _row(info, 0)
        w = self.core.sim.state("omega_bi_b")[0]
        self._rates.append((row["time"], float(w[1]), float(w[2])))
        if self.render_mode == "human":
            self.render()
        return obs[0], float(reward[0]), bool(terminated[0]), bool(truncated[0]), row

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode: pass render_mode='rgb_array' or 'human'")
            return None
        from .frames import render_frame
        return render_frame(self, self.render_mode)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


class SmileAscentEnv(AscentEnv):
    """``lvgym/SmileAscent-v0``: SMILE from lift-off through first-stage separation (thesis 6.3).

    60 s from Andøya, vertical launch; TVC of pitch and yaw (``Box(-1, 1, (2,))`` scaled to the 5 deg
    gimbal limit, second-order actuator 15 rad/s, 0.7, 30 deg/s); the controller is off for the first
    2 s and from first-stage burnout (43 s) until second-stage ignition (45 s); goal: zero pitch and yaw
    rate (``reference="gravity_turn"`` tracks a pitch program instead). Defaults: ``model="nonrigid"``,
    ``wind="none"``, no randomisation, ``observation="state"``, 50 Hz control over 100 Hz RK4, q-alpha
    limit 250 kPa deg, attitude limit 30 deg. See the module docstring for observation, reward and
    termination."""

    DEFAULTS = {"vehicle": "smile", "site": "andoya", "mission_time_s": 60.0, "rate_weights": (0.0, 1.0, 1.0)}


class StratosIIIEnv(AscentEnv):
    """``lvgym/StratosIII-v0``: Stratos III through its thrust drop (thesis 5.2-5.3).

    30 s from El Arenosillo, 85 deg elevation off a 10 m rail. Roll control with reaction-control pulses:
    ``MultiDiscrete([3])`` (0: negative, 1: none, 2: positive roll torque of ``rcs_torque_nm`` = 2 N m,
    an assumption: the thesis gives no thruster size), bang-bang as in thesis 5.3; ``control="tvc"`` gives
    the hypothetical TVC instead. Reward weights all three rates (roll, pitch, yaw). As shipped, the
    thrust after the drop stays above the drag and the N2O slosh mass is about 3 kg, so the nonrigid
    model does not depart at the drop as the thesis's did (docs/uncontrolled.md)."""

    DEFAULTS = {"vehicle": "stratos3", "site": "el_arenosillo", "elevation_deg": 85.0, "rail_length_m": 10.0,
                "mission_time_s": 30.0, "control": "rcs", "rate_weights": (1.0, 1.0, 1.0),
                "qalpha_limit_pa_deg": 150e3, "controller_on_after_s": 1.0}


class SlenderAscentEnv(AscentEnv):
    """``lvgym/SlenderAscent-v0``: the parametric slender vehicle of thesis chapter 6 (10 s, vertical).

    ``length`` [m] and ``diameter`` [m] set L/D (defaults 8.5 m, 0.3 m); ``diameter`` may be a pair
    ``(low, high)``: each reset then draws one of 4 diameters evenly spaced in that range from the env's
    generator (vehicles and their timelines are cached). This is where bending matters: the first mode
    drops towards the control bandwidth as L/D grows.

    ``aero_mach`` [-]: the vehicle's Barrowman tables are frozen at this Mach number (default 2.0), as the
    thesis's chapter-6 studies held the aerodynamic coefficients constant and as ``lvgym.studies`` does;
    ``None`` flies the full Mach-dependent tables. With the full tables the vehicle (Mach 5.7 and 1 MPa
    by 7.5 s, its fins losing lift above Mach 3) is statically unstable above Mach 3.85, with an
    open-loop pole near +21 1/s at 8 s, beyond what the 15 rad/s actuator can stabilise: every policy
    then fails on q-alpha between 5 and 7.5 s. Other options as SmileAscent-v0.

    Version history: v0 (2026-11): first release; before the first tagged release the default
    ``aero_mach`` became 2.0 (it flew the full tables, which no policy survives)."""

    DEFAULTS = {"site": "andoya", "mission_time_s": 10.0, "rate_weights": (0.0, 1.0, 1.0)}

    def __init__(self, render_mode: str | None = None, length: float = 8.5, diameter: Any = 0.3,
                 aero_mach: float | None = DEFAULT_AERO_MACH, **options: Any) -> None:
        d = np.atleast_1d(np.asarray(diameter, dtype=float))
        if d.size not in (1, 2) or np.any(d <= 0):
            raise ValueError(f"diameter = {diameter!r}: a diameter [m] > 0 or a (low, high) pair")
        self.diameters = tuple(np.linspace(d[0], d[-1], 4 if d.size == 2 else 1).tolist())
        self.length = float(length)
        self.aero_mach = None if aero_mach is None else float(aero_mach)
        self._cores: dict[float, AscentBatch] = {}
        super().__init__(render_mode, vehicle=self._key(self.diameters[0]), **options)
        self._cores[self.diameters[0]] = self.core

    def _key(self, diameter: float) -> tuple:
        """The vehicle key of :func:`~.core.cached_vehicle` for one diameter [m]."""
        return ("slender", self.length, diameter, self.aero_mach)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        gym.Env.reset(self, seed=seed)
        if len(self.diameters) > 1:
            dia = self.diameters[int(self.np_random.integers(len(self.diameters)))]
            if dia not in self._cores:
                task = TaskSpec.build(self.DEFAULTS, {**{k: getattr(self.task, k) for k in TaskSpec.__dataclass_fields__},
                                                      "vehicle": self._key(dia)})
                self._cores[dia] = AscentBatch(task, 1)
            self.core = self._cores[dia]
        return super().reset(seed=None, options=options)
