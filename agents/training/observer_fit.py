"""The learned observer's fit: the training rounds' windows, labels and weights in arrays that grow in place
(:class:`Data`) and the fit of an :class:`~lvgym.agents.policies.observer_net.Estimator` by weighted mean squared
error (:func:`fit`). The network, its ``.pt`` files and its NumPy form are
:mod:`lvgym.agents.policies.observer_net`'s; the features are :mod:`lvgym.agents.policies.observer`'s.

Training is ``lvgym train --recipe teacher-student`` (:mod:`lvgym.agents.training.teacher_student`,
docs/teacher-student.md).
"""

from __future__ import annotations

import numpy as np
import torch

from ..policies.observer_net import Estimator

__all__ = ["Data", "fit", "row_std"]


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
