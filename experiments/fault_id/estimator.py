"""The learned thrust-direction estimator and the policy that flies it: ``lqg`` with its command corrected by
the misalignment a network reads from the last half second of flight signals.

The fault suite's room for ``lqg`` is knowing the thrust's direction (README.md, :mod:`.privileges`): ``lqg``
given the true misalignment, ``delta = delta_lqg - misalignment``, fails 2 of 100 validation flights where
``lqg`` fails 7. :class:`Estimator` learns that misalignment from what a flight computer has: a window of
:data:`WINDOW` control steps of the env's observation (14 entries) and of the two actions it sent
(:data:`FEATURES`). :class:`FaultIdPolicy` flies ``lqg`` (its own Kalman filter sees its own command, as if
the thrust went where the gimbal points) and subtracts the estimate, in units of the gimbal limit, once past a
dead band (:data:`DEADBAND`, :func:`corrected`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

#: the control steps the estimator reads (0.5 s at SMILE's 0.02 s)
WINDOW = 25
#: one step's features: the env's observation (its ``observation_layout``: the 14 entries of SMILE's v1 env,
#: ``roll_rate`` .. ``pitch_rate_reference``) then the action sent (pitch, yaw)
ACTIONS = ("action_pitch", "action_yaw")
N_OBS = 14
FEATURES = N_OBS + len(ACTIONS)
#: where :mod:`.train` writes a training seed's estimator
RESULTS = Path("results") / "fault_id"
#: the dead band of the correction the seeded policies fly [over the gimbal limit]: the best of 0, 0.04 and
#: 0.08 for each of the three training seeds on validation seeds 0-99 (``python -m experiments.fault_id.deadband``)
DEADBAND = 0.04


class Estimator(nn.Module):
    """``(B, WINDOW, FEATURES)`` features -> ``(B, outputs)`` labels: the misalignment (pitch, yaw) over the
    gimbal limit (this module's policy), or the law's terms of :mod:`.inversion`; the features standardised by
    the training set's per-feature ``mean`` and ``std``, the labels by ``label_mean`` and ``label_std`` (none:
    as they are)."""

    def __init__(self, mean: np.ndarray, std: np.ndarray, hidden: int = 256, outputs: int = 2,
                 label_mean: np.ndarray | None = None, label_std: np.ndarray | None = None) -> None:
        super().__init__()
        self.register_buffer("mean", torch.as_tensor(mean, dtype=torch.float32))
        self.register_buffer("std", torch.as_tensor(std, dtype=torch.float32))
        self.register_buffer("label_mean", torch.as_tensor(np.zeros(outputs) if label_mean is None else label_mean,
                                                           dtype=torch.float32))
        self.register_buffer("label_std", torch.as_tensor(np.ones(outputs) if label_std is None else label_std,
                                                          dtype=torch.float32))
        self.net = nn.Sequential(nn.Linear(WINDOW * FEATURES, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(),
                                 nn.Linear(hidden, outputs))

    def forward(self, window: torch.Tensor) -> torch.Tensor:
        return self.net(((window - self.mean) / self.std).flatten(1)) * self.label_std + self.label_mean


class Window:
    """The last :data:`WINDOW` steps' features of ``n`` rows (zeros before the first), oldest first."""

    def __init__(self, n: int) -> None:
        self.x = np.zeros((n, WINDOW, FEATURES), dtype=np.float32)
        self.last_action = np.zeros((n, len(ACTIONS)), dtype=np.float32)

    def push(self, rows: np.ndarray, observations: np.ndarray) -> np.ndarray:
        """Add the step's observations of ``rows`` (with the actions they sent last) and return their windows."""
        self.x[rows, :-1] = self.x[rows, 1:]
        self.x[rows, -1, :N_OBS] = observations
        self.x[rows, -1, N_OBS:] = self.last_action[rows]
        return self.x[rows]

    def sent(self, rows: np.ndarray, actions: np.ndarray) -> None:
        self.last_action[rows] = actions


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


class Ensemble(nn.Module):
    """The mean of several estimators' outputs (the fits of a training seed's last DAgger rounds: each round's
    fit errs differently, and their mean errs less in closed loop, README.md)."""

    def __init__(self, members: list[Estimator]) -> None:
        super().__init__()
        self.members = nn.ModuleList(members)

    def forward(self, window: torch.Tensor) -> torch.Tensor:
        return torch.stack([m(window) for m in self.members]).mean(0)


def save(estimator: Estimator | Ensemble, path: str | Path) -> None:
    """Write ``estimator`` (an :class:`Ensemble`: its members' states in one file) for :func:`load`."""
    members = estimator.members if isinstance(estimator, Ensemble) else None
    torch.save({"members": [m.state_dict() for m in members]} if members is not None else estimator.state_dict(),
               path)


def _one(state: dict[str, torch.Tensor]) -> Estimator:
    outputs = int(state["net.4.bias"].shape[0])
    state.setdefault("label_mean", torch.zeros(outputs))          # saved before the labels were scaled
    state.setdefault("label_std", torch.ones(outputs))
    est = Estimator(state["mean"].numpy(), state["std"].numpy(), hidden=int(state["net.0.bias"].shape[0]),
                    outputs=outputs)
    est.load_state_dict(state)
    return est


def load(path: str | Path) -> Estimator | Ensemble:
    """An estimator, or an ensemble of them, saved by :mod:`.train` (:func:`save`)."""
    state = torch.load(path, map_location="cpu", weights_only=True)
    return Ensemble([_one(m) for m in state["members"]]) if "members" in state else _one(state)


def _seeded(k: int):
    def factory(env: Any) -> FaultIdPolicy:
        return FaultIdPolicy(env, load(RESULTS / f"estimator-s{k}.pt"), name=f"lqg-thrust-id-s{k}", deadband=DEADBAND)
    factory.__name__ = f"s{k}"
    return factory


#: the three training seeds' policies at :data:`DEADBAND`
#: (``evaluate.py --policies experiments/fault_id/estimator.py:s0``)
s0, s1, s2 = (_seeded(k) for k in range(3))


def from_file(env: Any, path: str, name: str = "lqg-thrust-id", deadband: float = DEADBAND) -> FaultIdPolicy:
    """The policy flying the estimator saved at ``path``."""
    return FaultIdPolicy(env, load(path), name=name, deadband=deadband)
