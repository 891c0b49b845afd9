"""The learned observer's network as torch holds it: :class:`Estimator` (a two-layer tanh MLP on standardised
features and labels), :class:`Ensemble` (the mean of several), their ``.pt`` files (:func:`save`, :func:`load`:
torch's ``state_dict``, loaded with ``weights_only``) and the flight computer's form of them, :func:`to_observer`
(:class:`lvgym.agents.policies.observer.Observer`, NumPy). The features are
:mod:`lvgym.agents.policies.observer`'s (:class:`~lvgym.agents.policies.observer.Window`).

A training run fits them (:mod:`lvgym.agents.training.observer_fit`); a policy flies a ``.pt`` file through
:func:`load` and :func:`to_observer` (:func:`lvgym.agents.policies.inversion.from_file`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch
from torch import nn

from .observer import FEATURES, LAYERS, WINDOW, Observer

__all__ = ["Ensemble", "Estimator", "load", "save", "to_observer"]


class Estimator(nn.Module):
    """``(B, WINDOW, FEATURES)`` features -> ``(B, outputs)`` labels; the features standardised by the training
    set's per-feature ``mean`` and ``std``, the labels by ``label_mean`` and ``label_std`` (none: as they
    are); ``hidden`` units in each of the two tanh layers."""

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


class Ensemble(nn.Module):
    """The mean of several estimators' outputs (the fits of a training seed's last DAgger rounds: each fit
    errs differently, and their mean errs less in closed loop)."""

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
    """An estimator, or an ensemble of them, saved by :func:`save` (in evaluation mode)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no observer file {str(path)!r}")
    state = torch.load(path, map_location="cpu", weights_only=True)
    out = Ensemble([_one(m) for m in state["members"]]) if "members" in state else _one(state)
    return out.eval()


def to_observer(estimator: Estimator | Ensemble) -> Observer:
    """``estimator`` as the flight computer's NumPy :class:`~lvgym.agents.policies.observer.Observer` (the same arrays;
    its estimates equal the network's to float32 rounding)."""
    members = list(estimator.members) if isinstance(estimator, Ensemble) else [estimator]
    names = {"w0": "net.0.weight", "b0": "net.0.bias", "w1": "net.2.weight", "b1": "net.2.bias",
             "w2": "net.4.weight", "b2": "net.4.bias"}
    return Observer([{k: m.state_dict()[names.get(k, k)].detach().cpu().numpy() for k in LAYERS} for m in members])
