"""A privileged reference for protocol v2: a controller that knows what no flight computer knows.

``privileged`` is not a design a vehicle could fly. It reads the env's ``privileged_info``
(:meth:`lvgym.envs.functional.AscentFuncEnv.privileged_info`): the true rigid-body rates (no gyro, no noise,
no bending in them), the true attitude error, the thrust, its lever arm, the inertia, the true thrust
misalignment and the share of the command each actuator still reaches (both moved by faults), and the wind
ahead of the vehicle: the aerodynamic moment about the CG that the wind and air it is about to fly into would
cause, up to :data:`~lvgym.envs.privileged.PREVIEW_PERIODS` control periods ahead (the turbulence is a frozen
field along the climb, so the wind ahead is known exactly). Per axis it commands the gimbal angle whose
thrust moment cancels the moment :data:`PREVIEW` periods ahead (the period of delay and the servo's lag
between a command and its moment) and adds the moment of a second-order attitude loop (natural frequency
``bandwidth_radps``, damping ``damping``) on the true rate and attitude errors (dynamic inversion of the
rigid body), then takes off the misalignment and divides by the actuator's effectiveness::

    delta = ((J (-2 z w e_rate - h w^2 e_att) - h M_aero_ahead) / (T l) - mis) / eff

where ``h`` is 1 up to half the q-alpha limit and falls linearly to 0 at 90 % of it (:data:`RELIEF`, the
``qalpha_pa_deg`` of the step's info): load relief, which lets the vehicle turn into the relative wind
when the structural load nears its limit, as a launch vehicle's load-relief mode does.

(pitch about +y_b, yaw about +z_b; a positive gimbal angle turns the vehicle positively about its axis). It
flies the protocol's actuator path like every policy: the action's period of delay, the servo and its
limits. It knows nothing of the slosh and the bending, and nothing of a fault but the misalignment and the
effectiveness, so it is a reference, not a bound: the room it shows is what knowing the state, the plant and
the wind ahead is worth to a controller on the same actuator (docs/benchmark.md). The runner flies it on its
conditions with ``privileged_info=True`` (the ``privileged`` attribute of its factory, :func:`privileged`);
that option adds keys to the info and changes nothing of the flight.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.envs.privileged import PREVIEW_PERIODS
from lvgym.errors import ConfigError

from .privkernel import PrivilegedGains, PrivilegedInfo, privileged_act_k

__all__ = ["PrivilegedLaw", "PrivilegedPolicy", "control_lever", "privileged", "relief_hold"]

#: (bandwidth [rad/s], damping) of the attitude loop per flight model, with :data:`RELIEF`: the lowest mean
#: ``score_v2`` over protocol v2's three SMILE suites on validation seeds 0-19 of a sweep of bandwidths 1, 1.5
#: and 2 /s (damping equal) and reliefs none, (0.5, 0.9) and (0.3, 0.7)
#: (``python -m experiments.protocol_v2_design.privileged_sweep``; docs/benchmark.md, "The privileged
#: reference"). The non-rigid vehicle takes a rate gain of only about 2 /s before the true rates' slosh content
#: destabilises the loop (the law knows nothing of the slosh). They were kept when the preview was chosen
#: (experiments/protocol_v2_design, part 7: on the SMILE suites they are still the best of 1 and 1.5 /s; over
#: all five suites at the shipped preview, the rigid 1 /s would score 0.224 against 0.238)
GAINS = {"rigid": (1.5, 1.5), "nonrigid": (1.0, 1.0)}
#: load relief (onset, full) as shares of the env's q-alpha limit: between them the attitude loop and the
#: cancellation of the aerodynamic moment fade out linearly, and the statically stable vehicle turns into the
#: relative wind (module docstring)
RELIEF = (0.5, 0.9)
#: how many control periods ahead the law reads the aerodynamic moment (the info's ``m_aero_ahead_b``; 0: the
#: moment as it acts): the lowest mean ``score_v2`` over protocol v2's five suites on validation seeds 0-19, at
#: the bandwidths of :data:`GAINS`, of previews 0, 5 and 7 on every suite (10 on the SMILE suites did worse
#: than 5), on both flight models; 0.1 s, about the period of delay plus the servo's lag
PREVIEW = 5


def relief_hold(share: float | np.ndarray, onset: float, full: float) -> float | np.ndarray:
    """The share of the attitude loop and of the moment's cancellation kept at ``share`` of the q-alpha limit
    (a number or an array of them): 1 up to ``onset``, falling linearly to 0 at ``full`` (:data:`RELIEF`)."""
    return 1.0 - np.clip((share - onset) / (full - onset), 0.0, 1.0)


def control_lever(info: Mapping[str, Any], rows: np.ndarray) -> np.ndarray:
    """The vectored thrust times its arm about the CG [N m per rad of gimbal] of the rows ``rows`` from a
    privileged step's batched info."""
    share = np.asarray(info["vectored_share"], dtype=float)[rows] if "vectored_share" in info else 1.0
    return np.asarray(info["thrust"], dtype=float)[rows] * share * np.asarray(info["gimbal_arm"], dtype=float)[rows]


class PrivilegedLaw(BatchLaw):
    """The privileged reference (module docstring) for ``n`` rows of a TVC env of the ascent task:
    ``bandwidth_radps`` [rad/s] and ``damping`` [-] of its attitude loop (default: :data:`GAINS` of the env's
    flight model), ``relief`` (default :data:`RELIEF`), ``preview_periods``: how many control periods ahead it
    reads the aerodynamic moment (default :data:`PREVIEW`; 0: as it acts), ``plant``: whether it uses the true
    misalignment and actuator effectiveness; ``env``: the env it flies (its gimbal limit, its observation's
    reference pitch rate, its model). The law has no state: each row's action is a function of its
    observation and its row of the step's privileged info (elementwise, the same operations for any number of
    rows)."""

    def __init__(self, env: Any, bandwidth_radps: float | None = None, damping: float | None = None,
                 name: str = "privileged", relief: tuple[float, float] | None = None,
                 preview_periods: int | None = None, plant: bool = True, n: int = 1) -> None:
        func = env.unwrapped.func
        w0, z0 = GAINS["rigid" if func.spec.model == "rigid" else "nonrigid"]
        bandwidth_radps = w0 if bandwidth_radps is None else bandwidth_radps
        damping = z0 if damping is None else damping
        for key, value, lo, hi in (("bandwidth_radps", bandwidth_radps, 0.0, 100.0), ("damping", damping, 0.0, 10.0)):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo < value <= hi):
                raise ConfigError(f"privileged.{key}", value, f"a number in ({lo:g}, {hi:g}]")
        if func.spec.control != "tvc":
            raise ConfigError("privileged env control", func.spec.control, "tvc (the reference commands the gimbal)")
        if not func.spec.privileged_info:
            raise ConfigError("privileged env privileged_info", False, "True: the reference reads the true state "
                              "from the step's info (the benchmark's runner sets it for this policy)")
        preview_periods = PREVIEW if preview_periods is None else preview_periods
        if not (isinstance(preview_periods, int) and 0 <= preview_periods <= PREVIEW_PERIODS):
            raise ConfigError("privileged.preview_periods", preview_periods,
                              f"an integer from 0 (the moment as it acts) to {PREVIEW_PERIODS}")
        self.preview = int(preview_periods)
        self.plant = bool(plant)
        relief = RELIEF if relief is None else tuple(relief)
        if not (len(relief) == 2 and all(isinstance(x, (int, float)) and math.isfinite(x) for x in relief)
                and 0.0 < relief[0] < relief[1]):
            raise ConfigError("privileged.relief", relief, "two shares of the q-alpha limit, 0 < onset < full")
        self.name = name
        self.w, self.z = float(bandwidth_radps), float(damping)
        self.relief = (float(relief[0]), float(relief[1]))
        self.qalpha_limit = float(func.spec.qalpha_limit_pa_deg)
        self.limit = float(func.gimbal_limit)
        self.gains = PrivilegedGains(self.w, self.z, self.relief[0], self.relief[1], self.limit,
                                     1.0 if self.plant else 0.0)
        self._neutral: tuple[np.ndarray, ...] | None = None
        names = list(func.observation_layout.names)
        self._i_ref = names.index("pitch_rate_reference") if "pitch_rate_reference" in names else None
        self.allocate(n)

    def _rows(self, n: int) -> None:
        pass

    def reset(self, rows: Any) -> None:
        """Nothing to forget: the law has no state."""

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """The gimbal actions (len(rows), 2) in [-1, 1] of the rows ``rows`` from the step's privileged info
        (zero before the first step, whose info holds none, and for a row without thrust), computed by
        :func:`.privkernel.privileged_act_k`."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        out = np.zeros((rows.size, 2), dtype=np.float32)
        if "m_aero_b" not in info:                          # the reset's info
            return out
        obs = np.asarray(observations)
        ref = (obs[:, self._i_ref].astype(np.float64) if self._i_ref is not None
               else np.zeros(rows.size))
        privileged_act_k(rows, ref, self._info(info), self.gains, out)
        return out

    def _info(self, info: Mapping[str, Any]) -> PrivilegedInfo:
        """The kernel's view of a step's batched privileged info (the keys a step may lack at their neutral
        values: all thrust vectored, no q-alpha, the env's limit, no misalignment, full effectiveness)."""
        thrust = np.asarray(info["thrust"], dtype=np.float64)
        n = thrust.shape[0]
        if self._neutral is None or self._neutral[0].shape[0] != n:
            self._neutral = (np.ones(n), np.zeros(n), np.full(n, self.qalpha_limit), np.zeros((n, 2)),
                             np.ones((n, 2)))
        ones, zeros, limit, mis, eff = self._neutral

        def get(key: str, default: np.ndarray) -> np.ndarray:
            return np.asarray(info[key], dtype=np.float64) if key in info else default

        m_aero = info["m_aero_b"] if self.preview == 0 else info["m_aero_ahead_b"][:, self.preview - 1]
        return PrivilegedInfo(thrust, get("vectored_share", ones), np.asarray(info["gimbal_arm"], dtype=np.float64),
                              np.asarray(info["omega_bi_b"], dtype=np.float64),
                              np.asarray(info["attitude_error"], dtype=np.float64),
                              np.asarray(m_aero, dtype=np.float64), np.asarray(info["J_b_diag"], dtype=np.float64),
                              get("qalpha_pa_deg", zeros), get("qalpha_limit_pa_deg", limit),
                              get("misalignment", mis) if self.plant else mis,
                              get("actuator_effectiveness", eff) if self.plant else eff)


class PrivilegedPolicy(RowFace):
    """The privileged reference as a benchmark policy: one row of :class:`PrivilegedLaw` (its arguments)."""

    def __init__(self, env: Any, bandwidth_radps: float | None = None, damping: float | None = None,
                 name: str = "privileged", relief: tuple[float, float] | None = None,
                 preview_periods: int | None = None, plant: bool = True) -> None:
        self.law = PrivilegedLaw(env, bandwidth_radps, damping, name, relief, preview_periods, plant)


def privileged(env: Any, bandwidth_radps: float | None = None, damping: float | None = None,
               name: str = "privileged", relief: tuple[float, float] | None = None,
               preview_periods: int | None = None, plant: bool = True) -> PrivilegedPolicy:
    """``privileged``: the reference of :class:`PrivilegedPolicy` (module docstring), at :data:`GAINS`,
    :data:`RELIEF` and :data:`PREVIEW` unless given."""
    return PrivilegedPolicy(env, bandwidth_radps, damping, name, relief, preview_periods, plant)


#: the runner flies this factory's policies with the env option privileged_info=True
privileged.privileged = True  # type: ignore[attr-defined]
