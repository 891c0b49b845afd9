"""The learned observer's network as torch fits it: :class:`Estimator` (a two-layer tanh MLP on standardised
features and labels), :class:`Ensemble` (the mean of several), their ``.pt`` files (:func:`save`,
:func:`load`: torch's ``state_dict``, loaded with ``weights_only``) and the flight computer's form of them,
:func:`to_observer` (:class:`lvgym.agents.observer.Observer`, NumPy); the training rounds' windows, labels and
weights in arrays that grow in place (:class:`Data`) and the fit by weighted mean squared error (:func:`fit`).
The features are :mod:`lvgym.agents.observer`'s (:class:`~lvgym.agents.observer.Window`).

Training is ``lvgym train --recipe teacher-student`` (:mod:`lvgym.agents.teacher_student`, docs/teacher-student.md).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch
from torch import nn

from .observer import FEATURES, LAYERS, WINDOW, Observer

__all__ = ["Data", "Ensemble", "Estimator", "fit", "load", "row_std", "save", "to_observer"]


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
    """``estimator`` as the flight computer's NumPy :class:`~lvgym.agents.observer.Observer` (the same arrays;
    its estimates equal the network's to float32 rounding)."""
    members = list(estimator.members) if isinstance(estimator, Ensemble) else [estimator]
    names = {"w0": "net.0.weight", "b0": "net.0.bias", "w1": "net.2.weight", "b1": "net.2.bias",
             "w2": "net.4.weight", "b2": "net.4.bias"}
    return Observer([{k: m.state_dict()[names.get(k, k)].detach().cpu().numpy() for k in LAYERS} for m in members])


class Data:
    """The windows, labels and weights of every round, in one array each that grows in place: the fits see a
    contiguous view, the same numbers as the rounds' arrays concatenated, without a second copy (a round's
    data of the longer missions is gigabytes, and two runs share the machine)."""

    def __init__(self) -> None:
        self.x: np.ndarray | None = None
        self.y: np.ndarray | None = None
        self.w: np.ndarray | None = None
        self.n = 0

    def __len__(self) -> int:
        return self.n

    def reserve(self, capacity: int) -> None:
        """Room for ``capacity`` steps (a copy now rather than one per round)."""
        if self.x is not None and capacity > len(self.x):
            x = np.empty((capacity, *self.x.shape[1:]), dtype=self.x.dtype)
            y = np.empty((capacity, *self.y.shape[1:]), dtype=self.y.dtype)
            w = np.empty(capacity, dtype=np.float32)
            x[:self.n], y[:self.n], w[:self.n] = self.x[:self.n], self.y[:self.n], self.w[:self.n]
            self.x, self.y, self.w = x, y, w

    def add(self, x: np.ndarray, y: np.ndarray, w: np.ndarray | None = None) -> None:
        """Append a flight batch's windows ``x``, labels ``y`` and their weights in the fit ``w`` (None: 1)."""
        if self.x is None:
            self.x = np.empty((0, *x.shape[1:]), dtype=x.dtype)
            self.y = np.empty((0, *y.shape[1:]), dtype=y.dtype)
            self.w = np.empty(0, dtype=np.float32)
        if self.n + len(x) > len(self.x):
            self.reserve(max(self.n + len(x), len(self.x) + len(self.x) // 4))
        self.x[self.n:self.n + len(x)], self.y[self.n:self.n + len(y)] = x, y
        self.w[self.n:self.n + len(x)] = 1.0 if w is None else w
        self.n += len(x)

    def view(self) -> tuple[np.ndarray, np.ndarray]:
        """The windows and labels so far (views, not copies)."""
        return self.x[:self.n], self.y[:self.n]

    def weights(self) -> np.ndarray | None:
        """The windows' weights so far (a view), or None when every weight is 1 (the fit's plain mean)."""
        w = self.w[:self.n]
        return None if np.all(w == 1.0) else w


def row_std(flat: np.ndarray, mean: np.ndarray, rows: int = 1 << 16) -> np.ndarray:
    """``flat.std(0)`` (``flat`` ``(n, k)``, ``mean`` its ``flat.mean(0)``) to the bit, without NumPy's temporary
    of the whole array (gigabytes for a training run's windows): the squared deviations of ``rows`` rows at a
    time, summed row after row as NumPy's reduction over the first axis sums them."""
    total = None
    for i in range(0, len(flat), rows):
        d = flat[i:i + rows] - mean
        np.multiply(d, d, out=d)
        total = np.add.reduce(d if total is None else np.concatenate([total[None], d]), axis=0)
    return np.sqrt(np.true_divide(total, len(flat)))


def fit(x: np.ndarray, y: np.ndarray, seed: int, epochs: int, scaled: bool = False,
        weight: np.ndarray | None = None) -> Estimator:
    """The estimator fitted to windows ``x`` and labels ``y`` (torch seeded with ``seed``; ``scaled``: the
    labels standardised, each weighing the same in the error; ``weight``: each window's weight in a batch's
    mean error, None: all the same)."""
    torch.manual_seed(seed)
    flat = x.reshape(-1, x.shape[-1])
    mean = flat.mean(0)
    est = Estimator(mean, row_std(flat, mean) + 1e-6, outputs=y.shape[1],
                    label_mean=y.mean(0) if scaled else None, label_std=y.std(0) + 1e-6 if scaled else None)
    opt = torch.optim.Adam(est.parameters(), 1e-3)
    xt, yt = torch.as_tensor(x), torch.as_tensor(y)
    wt = None if weight is None else torch.as_tensor(np.asarray(weight, dtype=np.float32))
    g = torch.Generator().manual_seed(seed)
    for epoch in range(epochs):
        perm, total = torch.randperm(len(xt), generator=g), 0.0
        for i in range(0, len(xt), 1024):
            b = perm[i:i + 1024]
            error = ((est(xt[b]) - yt[b]) / est.label_std) ** 2
            loss = error.mean() if wt is None else (error.mean(1) * wt[b]).sum() / wt[b].sum()
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += float(loss.detach()) * len(b)
        print(f"  epoch {epoch}: mean squared error {total / len(xt):.3e} (labels' variance "
              f"{float((yt / est.label_std).var(0).mean()):.3e})",
              flush=True)
    return est
