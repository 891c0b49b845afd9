"""The laws of the gust-relief study (README.md): the privileged reference's rigid-body law with its
privileges switchable, ``lqg-front`` faded by the true q-alpha, and LQG schedules with the integral released
around max q. Study code: flown by :mod:`.sweep`, never by the benchmark."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from lvgym.baselines.lqg import SCHEDULES as LQG_SCHEDULES
from lvgym.baselines.privileged import PrivilegedPolicy, control_lever, relief_hold
from lvgym.benchmark.batch import ROW, OneRowInfo
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.runner import build_policy

NO_RELIEF = (10.0, 11.0)            # onset beyond the limit: no relief (a flight above the limit has failed)


class SoftLaw(PrivilegedPolicy):
    """``delta = (J / (s T l)) (-2 zeta w e_rate - w^2 e_att - ki w^3 int e_att) - moment M_aero / (s T l)``
    per plane, with the rigid terms (``J``, ``s T l``) read from the privileged info. ``signals``: ``true``
    (the true rates and attitude error) or ``obs`` (the flight computer's: the observation's gyro rate error
    and strapdown attitude error); ``moment``: 1 cancels the aerodynamic moment as it acts, 0 not; the
    integral (``ki`` > 0) is frozen while the dynamic pressure is above ``q_off`` [Pa]."""

    def __init__(self, env: Any, w: float = 2.0, z: float = 1.0, signals: str = "obs", moment: float = 0.0,
                 ki: float = 0.0, q_off: float = np.inf) -> None:
        super().__init__(env, w, z, name="soft-law", relief=NO_RELIEF, preview_periods=0, plant=False)
        if signals not in ("true", "obs"):
            raise ValueError(f"signals = {signals!r}: true or obs")
        names = list(env.unwrapped.func.observation_layout.names)
        self.i_rate = [names.index("pitch_rate_error"), names.index("yaw_rate_error")]
        self.i_att = [names.index("pitch_attitude_error"), names.index("yaw_attitude_error")]
        self.signals, self.moment, self.ki, self.q_off = signals, float(moment), float(ki), float(q_off)
        self.dt = float(env.unwrapped.func.spec.control_dt_s)
        self.integral = np.zeros(2)

    def reset(self) -> None:
        self.integral[:] = 0.0

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        if "m_aero_b" not in info:                          # the reset's info
            self.integral[:] = 0.0
            return np.zeros(2, dtype=np.float32)
        lever = float(control_lever(OneRowInfo(info), ROW)[0])
        if lever < 1.0:
            return np.zeros(2, dtype=np.float32)
        if self.signals == "true":
            omega, att = np.asarray(info["omega_bi_b"], float), np.asarray(info["attitude_error"], float)
            ref = float(observation[self._i_ref]) if self._i_ref is not None else 0.0
            e_rate = np.array([omega[1] - ref, omega[2]])
        else:
            e_rate = np.asarray(observation[self.i_rate], float)
            att = np.asarray(observation[self.i_att], float)
        if float(info.get("qbar", 0.0)) < self.q_off:
            self.integral += self.dt * att
        J = np.asarray(info["J_b_diag"], float)[1:]
        accel = -2.0 * self.z * self.w * e_rate - self.w ** 2 * att - self.ki * self.w ** 3 * self.integral
        delta = (J * accel - self.moment * np.asarray(info["m_aero_b"], float)[1:]) / lever
        return np.clip(delta / self.limit, -1.0, 1.0).astype(np.float32)


def soft_law(env: Any, w: float = 2.0, z: float = 1.0, signals: str = "obs", moment: float = 0.0, ki: float = 0.0,
             q_off: float = float("inf")) -> SoftLaw:
    """:class:`SoftLaw` (it reads the privileged info, so the runner flies it with ``privileged_info``)."""
    return SoftLaw(env, w, z, signals, moment, ki, q_off)


soft_law.privileged = True  # type: ignore[attr-defined]


#: the reference's relief factor (1 up to ``onset`` of the q-alpha limit, 0 from ``full``)
hold = relief_hold


class FadedPolicy:
    """A registered policy's action times :func:`hold` of the true q-alpha share (the info's
    ``qalpha_pa_deg``, which every step's info carries), never below ``floor``."""

    def __init__(self, env: Any, base: str = "lqg-front", onset: float = 0.5, full: float = 0.9,
                 floor: float = 0.0) -> None:
        self.inner = build_policy(resolve_policy(base), env)
        self.onset, self.full, self.floor = float(onset), float(full), float(floor)
        self.limit = float(env.unwrapped.func.spec.qalpha_limit_pa_deg)
        self.name = f"{base}-faded"

    def reset(self) -> None:
        self.inner.reset()

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        action = np.asarray(self.inner.act(observation, info), dtype=float)
        h = hold(float(info.get("qalpha_pa_deg", 0.0)) / self.limit, self.onset, self.full)
        return np.clip((self.floor + (1.0 - self.floor) * h) * action, -1.0, 1.0).astype(np.float32)


def faded(env: Any, base: str = "lqg-front", onset: float = 0.5, full: float = 0.9, floor: float = 0.0) -> FadedPolicy:
    """:class:`FadedPolicy` of ``base``."""
    import lvgym.baselines  # noqa: F401  (registers the classical designs)

    return FadedPolicy(env, base, onset, full, floor)


def released_schedule(base: str, rows: tuple[int, ...], ki_scale: float, leak_s: float, out: Path) -> Path:
    """A copy of the LQG schedule ``base`` (``smile_lqg``, ``smile_lqg_front``) with, in both planes at the
    rows ``rows``, the integral gain ``Ki`` times ``ki_scale`` and the integrator's leak set to a time constant
    of ``leak_s`` seconds (``a = exp(-dt / leak_s)``), written to ``out``."""
    data = dict(np.load(LQG_SCHEDULES / f"{base}.npz", allow_pickle=True))
    for plane in ("pitch", "yaw"):
        for r in rows:
            dt = float(data[f"{plane}_{r}_dt"])
            data[f"{plane}_{r}_Ki"] = np.array(float(data[f"{plane}_{r}_Ki"]) * ki_scale)
            data[f"{plane}_{r}_a"] = np.array(np.exp(-dt / leak_s))
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez(out, **data)
    return out
