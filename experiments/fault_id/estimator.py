"""The learned thrust-direction estimator and the policy that flies it: ``lqg`` with its command corrected by
the misalignment a network reads from the last half second of flight signals.

The fault suite's room for ``lqg`` is knowing the thrust's direction (README.md, :mod:`.privileges`): ``lqg``
given the true misalignment, ``delta = delta_lqg - misalignment``, fails 2 of 100 validation flights where
``lqg`` fails 7. An :class:`~lvgym.agents.policies.observer_net.Estimator` learns that misalignment from what a flight
computer has: a window of :data:`~lvgym.agents.policies.observer.WINDOW` control steps of the env's observation (14
entries) and of the two actions it sent (the shipped observer's features, :mod:`lvgym.agents.policies.observer`;
the network of :mod:`lvgym.agents.policies.observer_net`).
:class:`FaultIdPolicy` flies ``lqg`` (its own Kalman filter sees its own command, as if the thrust went where
the gimbal points) and subtracts the estimate, in units of the gimbal limit, once past a dead band
(:data:`DEADBAND`, :func:`corrected`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import torch

from lvgym.agents.policies.observer import FEATURES, N_OBS, WINDOW, Window
from lvgym.agents.policies.observer_net import Ensemble, Estimator, load, save

__all__ = ["DEADBAND", "FEATURES", "N_OBS", "RESULTS", "WINDOW", "Ensemble", "Estimator", "FaultIdPolicy", "Window",
           "base_lqg", "corrected", "from_file", "load", "save"]

#: where :mod:`.train` writes a training seed's estimator
RESULTS = Path("results") / "fault_id"
#: the dead band of the correction the seeded policies fly [over the gimbal limit]: the best of 0, 0.04 and
#: 0.08 for each of the three training seeds on validation seeds 0-99 (``python -m experiments.fault_id.deadband``)
DEADBAND = 0.04


def corrected(base: np.ndarray, estimate: np.ndarray, deadband: float = 0.0) -> np.ndarray:
    """The action sent: the base law's action less the estimated misalignment (both over the gimbal limit),
    shrunk towards zero by ``deadband`` (a soft threshold: estimates smaller than it give no correction, larger
    ones lose it), within the action space."""
    e = np.sign(estimate) * np.maximum(np.abs(estimate) - deadband, 0.0)
    return np.clip(np.asarray(base, dtype=np.float64) - e, -1.0, 1.0).astype(np.float32)


def base_lqg(env: Any) -> Any:
    """``lqg`` built for ``env`` as the benchmark builds a registered policy (the law the study corrects)."""
    import lvgym.baselines  # noqa: F401  (registers lqg)

    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import build_policy

    return build_policy(resolve_policy("lqg"), env)


class FaultIdPolicy:
    """``lqg`` with the estimator's correction (module docstring); one env row (the benchmark's policy)."""

    def __init__(self, env: Any, estimator: Estimator | Ensemble, name: str = "lqg-thrust-id",
                 deadband: float = 0.0) -> None:
        from lvgym.errors import ConfigError

        if tuple(env.observation_space.shape) != (N_OBS,):
            raise ConfigError("env observation", list(env.observation_space.shape),
                              f"({N_OBS},): the estimator reads SMILE's v1 observation")
        self.base = base_lqg(env)
        self.estimator = estimator.eval()
        self.name = name
        self.deadband = float(deadband)
        self.window = Window(1)

    def reset(self) -> None:
        self.base.reset()
        self.window = Window(1)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        rows = np.zeros(1, dtype=np.int64)
        base = np.asarray(self.base.act(observation, info), dtype=np.float64)
        w = self.window.push(rows, np.asarray(observation, dtype=np.float32)[None])
        with torch.no_grad():
            estimate = self.estimator(torch.as_tensor(w)).numpy()[0].astype(np.float64)
        a = corrected(base, estimate, self.deadband)
        self.window.sent(rows, a[None])
        return a


def _seeded(k: int):
    def factory(env: Any) -> FaultIdPolicy:
        return FaultIdPolicy(env, load(RESULTS / f"estimator-s{k}.pt"), name=f"lqg-thrust-id-s{k}", deadband=DEADBAND)
    factory.__name__ = f"s{k}"
    factory.kind = "learned"                          # the headline's column (lvgym.benchmark.headline)
    return factory


#: the three training seeds' policies at :data:`DEADBAND`
#: (``evaluate.py --policies experiments/fault_id/estimator.py:s0``)
s0, s1, s2 = (_seeded(k) for k in range(3))


def from_file(env: Any, path: str, name: str = "lqg-thrust-id", deadband: float = DEADBAND) -> FaultIdPolicy:
    """The policy flying the estimator saved at ``path``."""
    return FaultIdPolicy(env, load(path), name=name, deadband=deadband)
