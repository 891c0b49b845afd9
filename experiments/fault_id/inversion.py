"""A learned disturbance observer for the fault suite: the privileged reference's law flown on what a network
estimates of the plant and of the aerodynamic moment from the flight computer's signals.

The privileged reference (:mod:`lvgym.baselines.privileged`) inverts the rigid body: per axis it commands the
gimbal angle whose thrust moment gives a second-order attitude loop's angular acceleration and cancels the
aerodynamic moment, less the thrust misalignment, over the actuator's effectiveness, with load relief. Flown
on the observation's rate and attitude errors, without its wind preview, it needs per axis (pitch, yaw)
three numbers of the plant and one of the flight (:data:`TERMS`, :func:`law_terms`):

- ``f_aero = M_aero / (T l eff)`` and ``f_mis = misalignment / eff``, the gimbal angles that cancel the
  aerodynamic moment and the misalignment (over the gimbal limit);
- ``a = J / (T l eff)``, the gimbal angle per rad/s^2 of angular acceleration (the inverse of the control
  power, over the gimbal limit; 0 without thrust, where the law commands nothing);
- ``share``, the q-alpha over its limit (one for both axes);

and commands ``delta = a alpha - h f_aero - f_mis`` with ``alpha = -2 zeta w e_rate - h w^2 e_att``
(:func:`command`; ``w``, ``zeta``: the reference's :data:`~lvgym.baselines.privileged.GAINS` of the flight
model; ``h``: the reference's relief, 1 below half the q-alpha limit, 0 from 90 % of it). ``lvgym``'s env
knows the terms (``privileged_info``); a flight computer does not. :class:`InversionPolicy` flies the law with
them estimated by :class:`~.estimator.Estimator` from the last :data:`~.estimator.WINDOW` steps of
observations and actions sent (a learned disturbance observer, trained by :mod:`.train` with ``--scheme
inversion``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .estimator import N_OBS, RESULTS, Ensemble, Estimator, Window, load

#: the law's terms, in the order of :func:`law_terms`
TERMS = ("f_aero_pitch", "f_aero_yaw", "f_mis_pitch", "f_mis_yaw", "a_pitch", "a_yaw", "qalpha_share")
#: the labels' ceiling of ``a`` [gimbal limits per rad/s^2]: the thrust's tail-off would send it to infinity
A_MAX = 5.0
#: the observation's entries the law reads (SMILE's flight observation)
ERRORS = ("pitch_rate_error", "yaw_rate_error", "pitch_attitude_error", "yaw_attitude_error")
#: the lever [N m per rad of gimbal] under which the law commands nothing (the privileged reference's)
NO_THRUST = 1.0


def law_terms(info: dict[str, Any], n: int, limit: float) -> np.ndarray:
    """``(n, 7)``: :data:`TERMS` of the module docstring (``f_aero``, ``f_mis`` over the gimbal limit ``limit``
    [rad], ``a`` [gimbal limits per rad/s^2], ``share`` [-]) from a privileged step's info of ``n`` rows (zeros
    without thrust, or before the first step)."""
    out = np.zeros((n, len(TERMS)))
    if "m_aero_b" not in info:                               # the reset's info
        return out
    lever = (np.asarray(info["thrust"], dtype=float) * np.asarray(info.get("vectored_share", 1.0), dtype=float)
             * np.asarray(info["gimbal_arm"], dtype=float)).reshape(n)
    on = lever >= NO_THRUST
    eff = np.maximum(np.asarray(info["actuator_effectiveness"], dtype=float).reshape(n, 2), 0.1)
    m_aero = np.asarray(info["m_aero_b"], dtype=float).reshape(n, 3)[:, 1:]
    mis = np.asarray(info["misalignment"], dtype=float).reshape(n, 2)
    J = np.asarray(info["J_b_diag"], dtype=float).reshape(n, 3)[:, 1:]
    safe = np.where(on, lever, 1.0)[:, None]
    out[on, 0:2] = (m_aero / safe / eff / limit)[on]
    out[on, 2:4] = (mis / eff / limit)[on]
    out[on, 4:6] = np.minimum(J / (safe * eff) / limit, A_MAX)[on]
    out[:, 6] = (np.asarray(info["qalpha_pa_deg"], dtype=float) / np.asarray(info["qalpha_limit_pa_deg"], dtype=float)
                 ).reshape(n)
    return out


def command(observations: np.ndarray, terms: np.ndarray, index: list[int], w: float, z: float) -> np.ndarray:
    """The law's action (module docstring) within [-1, 1] for ``(n, 14)`` observations (``index``: the
    positions of :data:`ERRORS`) and ``(n, 7)`` terms (:func:`law_terms`, true or estimated)."""
    from lvgym.baselines.privileged import RELIEF, relief_hold

    o = np.asarray(observations, dtype=np.float64)
    e_rate, e_att = o[:, index[:2]], o[:, index[2:]]
    hold = relief_hold(terms[:, 6:7], *RELIEF)
    alpha = -2.0 * z * w * e_rate - hold * w * w * e_att
    return np.clip(terms[:, 4:6] * alpha - hold * terms[:, 0:2] - terms[:, 2:4], -1.0, 1.0).astype(np.float32)


def gains(env: Any) -> tuple[float, float]:
    """The reference's (bandwidth [rad/s], damping) for ``env``'s flight model."""
    from lvgym.baselines.privileged import GAINS

    return GAINS["rigid" if env.unwrapped.func.spec.model == "rigid" else "nonrigid"]


def error_index(env: Any) -> list[int]:
    """Where :data:`ERRORS` sit in ``env``'s observation."""
    names = list(env.unwrapped.func.observation_layout.names)
    return [names.index(n) for n in ERRORS]


class InversionPolicy:
    """The law of the module docstring on the estimator's ``f`` and ``a``; one env row (the benchmark's policy;
    it needs no privileged information)."""

    def __init__(self, env: Any, estimator: Estimator | Ensemble, name: str = "inversion-id") -> None:
        from lvgym.errors import ConfigError

        if tuple(env.observation_space.shape) != (N_OBS,):
            raise ConfigError("env observation", list(env.observation_space.shape),
                              f"({N_OBS},): the estimator reads SMILE's v1 observation")
        self.estimator = estimator.eval()
        self.name = name
        self.index, (self.w, self.z) = error_index(env), gains(env)
        self.window = Window(1)

    def reset(self) -> None:
        self.window = Window(1)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        import torch

        rows = np.zeros(1, dtype=np.int64)
        o = np.asarray(observation, dtype=np.float32)[None]
        with torch.no_grad():
            terms = self.estimator(torch.as_tensor(self.window.push(rows, o))).numpy().astype(np.float64)
        a = command(o, terms, self.index, self.w, self.z)
        self.window.sent(rows, a)
        return a[0]


def _seeded(k: int, prefix: str = "inversion", label: str = "inversion-id"):
    def factory(env: Any) -> InversionPolicy:
        return InversionPolicy(env, load(RESULTS / f"{prefix}-s{k}.pt"), name=f"{label}-s{k}")
    factory.__name__ = f"s{k}"
    return factory


#: the three training seeds' policies (``evaluate.py --policies experiments.fault_id.inversion:s0``)
s0, s1, s2 = (_seeded(k) for k in range(3))
#: seed 0 trained under the loop dispersion (``train.py --loop-gain-db 6``: inversion-gain6-s0.pt)
gain6_s0 = _seeded(0, "inversion-gain6", "inversion-id-gain6")
