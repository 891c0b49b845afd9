"""Gymnasium environments of thrust-vector (and roll) control in ascent.

Physics lives in the simulator; :class:`~.functional.AscentFuncEnv` is the task as pure functions of an
explicit state; :class:`~.core.BatchCore` resets and steps its rows; these classes are the
``gymnasium.Env`` face of one row of it. The episode's state is ``env.unwrapped.state`` (an
:data:`~.functional.AscentState` value); ``env.unwrapped.flight`` reads its simulator rows by name
(``flight.t[0]``, ``flight.conditions("qbar")[0]``, ``flight.state("omega_bi_b")[0]``,
``flight.gimbal[0]``: :class:`lvgym.simulator.SimView`); :meth:`AscentEnv.get_state` and
:meth:`AscentEnv.set_state` capture and restore it whole (see :mod:`.snapshot`). Each class flies its
protocol preset (``PRESET``, :mod:`.presets`) updated by keywords (see :class:`~.spec.TaskSpec`), e.g.
``gymnasium.make("lvgym/SmileAscent-v0", model="rigid", wind="turbulence", randomize=True)``.

Observation (``Box(-inf, inf, (14,), float32)``), for ``observation="state"`` (the ideal state of the
vehicle, a research option: no flight computer has its rates, attitude and angles of attack), ``"sensors"``
(v0: a gyro at the IMU station that sees the bending slope rate, with a constant bias and noise when
``sensor_noise`` is randomised, the true attitude plus noise, accelerometers) and ``"flight"`` (protocol v1:
what a flight computer samples, every entry a flight-computer signal: the IMU's gyros with bandwidth,
anti-aliasing, drifting bias and angle random walk, the attitude of their strapdown integration, the
accelerometers with lever arm and bending; see :mod:`lvgym.envs.flightcomputer` and docs/sensors.md); the
table is :data:`lvgym.envs.layouts.OBSERVATIONS` (``env.unwrapped.observation_layout`` names the entries;
with ``history=k`` the observation is the last k samples and the last k actions, oldest first, zero-padded
at a reset, the newest sample under the names below and the older ones as ``<name>_lag<j>``: see
:mod:`lvgym.envs.history`)::

%(observation)s

Reward: ``-sum_axis w_axis |rate - reference| dt`` (terms ``rate_roll``, ``rate_pitch``, ``rate_yaw``; so the
episode's sum is minus the weighted cumulative rate error in rad) ``- effort_weight * int |gimbal| dt``
(``effort``) ``- effort_rate_weight * int |gimbal rate| dt`` (``effort_rate``) and, on termination,
``- failure_penalty_rad_per_s * remaining time`` (``failure``). ``info["reward_terms"]`` holds each term;
they add up to the reward. ``info["rate_error"]`` holds the step's ``|rate - reference|`` [rad/s] (roll,
pitch, yaw), ``info["cumulative_rate_error"]`` its integral [rad], ``info["effort_rad_s"]`` the step's integral
of ``|gimbal pitch| + |gimbal yaw|`` (the reward's ``effort``), ``info["mass"]`` the stack's mass [kg]. With
``reward_kind="score_v2"`` the reward is minus each step's increment of protocol v2's score instead
(:mod:`.scorereward`).

Actions: a ``Box`` action outside [-1, 1] is clipped (Gymnasium's convention); an action of another shape,
a non-finite one, or an RCS action outside {0, 1, 2} raises a ``ValueError`` naming the action and the space.

Termination: a non-finite state (``info["termination"] == "non-finite state"``, never an exception),
dynamic pressure times total angle of attack above ``qalpha_limit_pa_deg``, attitude error above
``attitude_limit_deg``. Truncation: at the end of ``mission_time_s`` only.

Version history: v0 (2026-11): first release.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import gymnasium as gym
import numpy as np

from lvgym.errors import ConfigError
from lvgym.vehicle.slender import SlenderGeometry

from .core import BatchCore, row_info
from .functional import AscentFuncEnv, AscentState
from .layouts import observation_table
from .presets import DEFAULT_AERO_MACH, SLENDER_V0, SLENDER_V1, SMILE_V0, SMILE_V1, STRATOS3_V0, STRATOS3_V1
from .snapshot import EpisodeState
from .spec import TaskSpec, check_reset_options
from .views import FuncViews

__doc__ = __doc__ % {"observation": "\n".join("    " + line for line in observation_table().splitlines())}


class AscentEnv(FuncViews, gym.Env):
    """Base of the ascent envs: one row of an :class:`~.functional.AscentFuncEnv`. Subclasses set
    ``PRESET`` (without one, the keywords must name the ``vehicle``). ``vehicles``: several vehicles
    (names, paths or :class:`~lvgym.vehicle.slender.SlenderGeometry` values) of which each reset draws one
    from the env's generator (the episode's *variant*, part of its state)."""

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 25}
    #: the protocol preset the keywords update (:mod:`.presets`)
    PRESET: TaskSpec | None = None
    #: the keywords the class takes beside the :class:`~.spec.TaskSpec` fields (an unknown keyword's hint)
    KEYWORDS: tuple[str, ...] = ("render_mode", "vehicles")

    def __init__(self, render_mode: str | None = None, *, vehicles: Sequence[Any] | None = None,
                 **options: Any) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode = {render_mode!r}: one of {self.metadata['render_modes']} or None")
        self.render_mode = render_mode
        if vehicles is None:
            self.specs = (TaskSpec.build(self.PRESET, options, self.KEYWORDS),)
        else:
            self.specs = tuple(TaskSpec.build(self.PRESET, {**options, "vehicle": v}, self.KEYWORDS) for v in vehicles)
        self._cores: dict[int, BatchCore] = {}
        self._select(0)
        self.action_space, self.observation_space = self.func.action_space, self.func.observation_space
        self._renderer: Any = None
        self._rates: list[tuple[float, float, float, float]] = []     # (t, roll, pitch, yaw rate) for rendering

    def _select(self, variant: int) -> None:
        """Fly variant ``variant`` (its functional env and one-row core are built on first use and kept)."""
        if variant not in self._cores:
            self._cores[variant] = BatchCore(AscentFuncEnv(self.specs[variant]), 1)
        self.variant, self.core = variant, self._cores[variant]
        self.func, self.task = self.core.func, self.core.func.spec

    @property
    def state(self) -> AscentState | None:
        """The episode's state (one row; None before the first reset): the value the functional env
        steps. Read it through :attr:`flight` (the simulator's read-outs) or ``state.task``."""
        return self.core.state

    # facts of the task (sim, timeline, vehicle, observation_layout, gimbal_limit) and the current
    # flight (flight): .views.FuncViews

    # ------------------------------------------------------------------------------ Gymnasium
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Start an episode (``seed`` seeds the env's generator); ``options`` takes no key (an unknown one
        raises: the task's options are keywords of the constructor)."""
        check_reset_options(options)
        super().reset(seed=seed)
        if len(self.specs) > 1:
            self._select(int(self.np_random.integers(len(self.specs))))
        self.core.reset(rngs=[self.np_random])
        self._rates = []
        return self.core.observation()[0], row_info(self.core.reset_info(), 0)

    def step(self, action):
        if self.state is None:
            raise RuntimeError("call reset() before step()")
        a = self.func.check_action(action)
        out = self.core.step(a[None], checked=True)
        row = row_info(out.info, 0)
        w = self.state.sim.x[0, self.sim.layout.state["omega_bi_b"]]
        self._rates.append((row["time"], float(w[0]), float(w[1]), float(w[2])))
        if self.render_mode == "human":
            self.render()
        return out.obs[0], float(out.reward[0]), bool(out.terminated[0]), bool(out.truncated[0]), row

    # ------------------------------------------------------------------------------ state as data
    def get_state(self) -> EpisodeState:
        """The episode's whole state (a copy; see :mod:`.snapshot`)."""
        return self.core.get_state(extra={"variant": [self.variant], "rates": [list(self._rates)]})

    def set_state(self, state: EpisodeState) -> None:
        """Continue from ``state`` (from :meth:`get_state` of an env with the same options, or one row of
        a vector env's); the snapshot itself is not changed and can be restored again."""
        variant = int(state.extra.get("variant", [0])[0])
        if not 0 <= variant < len(self.specs):
            raise ValueError(f"the state flies vehicle variant {variant}; this env has {len(self.specs)}")
        state.check(self.specs[variant], 1)
        self._select(variant)
        self.core.rngs[0] = self.np_random
        self.core.set_state(state)
        self._rates = list(state.extra.get("rates", [[]])[0])

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

    PRESET = SMILE_V0


class SmileAscentV1Env(SmileAscentEnv):
    """``lvgym/SmileAscent-v1``: SMILE as protocol v1 flies it (frozen 2026-12-02).

    The vehicle ``smile_v1`` (lvgym/vehicles/smile_v1.yaml): the upper stack flies its own, finless
    aerodynamics after separation, which comes 10 s after the 43 s burnout at about 1.8 kPa (the finned
    stack coasts, statically stable); stage 2 ignites at 54 s; 70 s of mission. Through the coast the
    vehicle holds itself into the relative wind by reaction control (``coast_control``, 1,000 N m,
    3 rad/s) and settles its propellant with ullage thrust (``settling_thrust_n`` = 18 kN, 1.35 times the
    drag at burnout: docs/vehicles.md). The flight computer's computational delay is one control period
    (``action_delay_steps=1``) and the policy sees what the flight computer samples (``observation="flight"``:
    the IMU's gyros and accelerometers through their filters, a strapdown attitude, tactical-grade
    errors, docs/sensors.md); the gravity turn, when asked for, follows the Earth-relative velocity.
    The bending modes are recomputed every 2 s with the modal state projected across each change
    (``mode_interval_s``, ``mode_basis="projected"``), the slosh dampers take their frequency from the
    axial specific force (``slosh_frequency="specific_force"``) and the aeroelastic strip loads follow the
    vehicle file (``aeroelastic=None``; SMILE's flag is off). Everything else as ``SmileAscent-v0``."""

    PRESET = SMILE_V1


class StratosIIIEnv(AscentEnv):
    """``lvgym/StratosIII-v0``: Stratos III through its thrust drop (thesis 5.2-5.3).

    30 s from El Arenosillo, 85 deg elevation off a 10 m rail. Roll control with reaction-control pulses:
    ``MultiDiscrete([3])`` (0: negative, 1: none, 2: positive roll torque of ``rcs_torque_nm`` = 2 N m,
    an assumption: the thesis gives no thruster size), bang-bang as in thesis 5.3; ``control="tvc"`` gives
    the hypothetical TVC instead. Reward weights all three rates (roll, pitch, yaw). As shipped, the
    thrust after the drop stays above the drag and the N2O slosh mass is about 3 kg, so the nonrigid
    model does not depart at the drop as the thesis's did (docs/uncontrolled.md)."""

    PRESET = STRATOS3_V0


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

    PRESET = SLENDER_V0
    #: the geometry keywords (defaults: the preset's :class:`~lvgym.vehicle.slender.SlenderGeometry`):
    #: ``length`` [m], ``diameter`` [m] (or a ``(low, high)`` range), ``aero_mach`` [-] (None: the full
    #: tables), ``wall_thickness_m`` [m]
    GEOMETRY = ("length", "diameter", "aero_mach", "wall_thickness_m")
    KEYWORDS = AscentEnv.KEYWORDS + GEOMETRY

    def __init__(self, render_mode: str | None = None, **options: Any) -> None:
        geometry, diameter = self.geometry(options)
        d = np.atleast_1d(np.asarray(diameter, dtype=float))
        self.diameters = tuple(np.linspace(d[0], d[-1], 4 if d.size == 2 else 1).tolist())
        self.length = geometry.length
        self.aero_mach = geometry.aero_mach
        self.wall_thickness_m = geometry.wall_thickness
        super().__init__(render_mode, vehicles=[geometry.with_diameter(dia) for dia in self.diameters], **options)

    @classmethod
    def geometry(cls, options: dict[str, Any]) -> tuple[SlenderGeometry, Any]:
        """Pop the geometry keywords from ``options``: the geometry (the preset's where absent or None for
        the wall; with a ``diameter`` range, its low end) and the ``diameter`` given (a diameter [m] or a
        ``(low, high)`` range)."""
        base = cls.PRESET.vehicle
        given = {key: options.pop(key) for key in cls.GEOMETRY if key in options}
        diameter = given.pop("diameter", base.diameter)
        d = np.atleast_1d(np.asarray(diameter, dtype=float)) if np.ndim(diameter) <= 1 else np.zeros(0)
        if d.size not in (1, 2) or not np.all(d > 0):
            raise ConfigError("diameter", diameter, "a diameter [m] > 0 or a (low, high) pair")
        wall = given.pop("wall_thickness_m", None)
        if wall is not None:
            given["wall_thickness"] = wall
        return replace(base, **given, diameter=float(d[0])), diameter


class StratosIIIV1Env(StratosIIIEnv):
    """``lvgym/StratosIII-v1``: Stratos III with thrust-vector control (the hypothetical TVC of
    ``StratosIII-v0``'s ``control="tvc"``) and protocol v1's physics and timing (frozen 2026-12-02): one control period of delay, modes recomputed every 2 s and projected, slosh dampers on
    the specific force. Reward weights pitch and yaw; roll is left to the vehicle."""

    PRESET = STRATOS3_V1


class SlenderAscentV1Env(SlenderAscentEnv):
    """``lvgym/SlenderAscent-v1``: the slender vehicle with protocol v1's physics and timing (frozen):
    one control period of delay, modes recomputed every 2 s and projected, slosh dampers on the specific
    force, and the strip-theory aeroelastic loads its vehicle file asks for.

    Its tube's wall is 4.5 mm (``wall_thickness_m``), not the thesis's 2 mm: with the strip loads the
    2 mm tube diverges statically at 370-400 kPa, reached at 4.2-4.4 s, and from 6 s its unstable pole
    (13.7-18.5 1/s, beyond the 15 rad/s servo, with 30 ms of delay and hold) admits no TVC loop with
    useful margins; the 4.5 mm tube (+42 kg) diverges only above 1.6 times the flight's dynamic pressure
    and keeps its first mode at 13.6 Hz (docs/aerodynamics.md, "Aeroelastic divergence";
    ``experiments/aeroelastic_divergence/divergence.py`` checks it independently). ``wall_thickness_m=0.002`` flies the thesis's tube."""

    PRESET = SLENDER_V1
