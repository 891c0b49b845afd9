"""A trained multilayer perceptron flown for many rows at once, each row on its own (the learned laws' inner
loop, :mod:`lvgym.agents.policies.sb3` and :mod:`lvgym.agents.policies.bc`).

Torch's batched forward is not its one-row forward: a linear layer of one observation runs as a matrix-vector
product, of many as a matrix-matrix product, and the two sum in other orders, so a row's action would depend
on how many rows fly beside it. :func:`mlp_rows_k` evaluates the network one row after the other in one
compiled call: per unit the bias plus the weighted inputs summed in the inputs' order, in float32 (the
network's own precision), then the layer's activation. A row's action is then the same bits in a batch of one
as in a batch of a thousand. It agrees with torch's forward to float32 rounding (a few 1e-7 of the output;
``tests/test_agents.py``), not to the bit: the summation order is ours.

:class:`MlpNet` packs the layers (their weights and biases in one float32 vector, a table of their sizes,
offsets and activations); :meth:`MlpNet.from_torch` reads a torch ``nn.Sequential`` of ``nn.Linear`` layers
and the activations of :data:`ACTIVATIONS`, and gives None for any other structure (the caller then flies
the network with torch).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numba as nb
import numpy as np

__all__ = ["ACTIVATIONS", "MlpNet", "mlp_rows_k"]

#: the activations the compiled forward knows, by torch module name: the code it runs
ACTIVATIONS = {"Identity": 0, "Tanh": 1, "ReLU": 2}
#: the columns of :attr:`MlpNet.layout`: inputs, outputs, offset of the weights (out, in) row-major, offset of
#: the biases, activation code
N_IN, N_OUT, W_AT, B_AT, ACT = range(5)


class MlpNet(NamedTuple):
    """A network's layers: ``weights`` (float32) every layer's weights (out, in) row-major, then its biases;
    ``layout`` (L, 5) int64 per layer its inputs, outputs, the offsets of its weights and biases in
    ``weights`` and its activation (:data:`ACTIVATIONS`); ``width`` the widest layer."""

    weights: np.ndarray
    layout: np.ndarray
    width: int

    @property
    def n_out(self) -> int:
        return int(self.layout[-1, N_OUT])

    @classmethod
    def from_layers(cls, layers: list[tuple[np.ndarray, np.ndarray, str]]) -> MlpNet:
        """The network of ``layers``: (weight (out, in), bias (out,), activation name after it)."""
        parts, rows, at = [], [], 0
        for w, b, act in layers:
            w, b = np.asarray(w, np.float32), np.asarray(b, np.float32)
            rows.append((w.shape[1], w.shape[0], at, at + w.size, ACTIVATIONS[act]))
            parts += [w.ravel(), b.ravel()]
            at += w.size + b.size
        layout = np.asarray(rows, dtype=np.int64)
        width = int(max(layout[:, N_IN].max(), layout[:, N_OUT].max()))
        return cls(np.concatenate(parts).astype(np.float32), layout, width)

    @classmethod
    def from_torch(cls, modules: list[Any]) -> MlpNet | None:
        """The network of a sequence of torch modules (``nn.Linear`` with bias, each optionally followed by
        one activation of :data:`ACTIVATIONS`), or None for another structure."""
        import torch

        layers: list[tuple[np.ndarray, np.ndarray, str]] = []
        for m in modules:
            if isinstance(m, torch.nn.Linear) and m.bias is not None:
                layers.append((m.weight.detach().cpu().numpy(), m.bias.detach().cpu().numpy(), "Identity"))
            elif type(m).__name__ in ACTIVATIONS and layers and layers[-1][2] == "Identity":
                w, b, _ = layers[-1]
                layers[-1] = (w, b, type(m).__name__)
            else:
                return None
        return cls.from_layers(layers) if layers else None

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """The outputs (m, n_out) float32 of the rows of ``x`` (m, n_in)."""
        x = np.ascontiguousarray(x, dtype=np.float32)
        out = np.empty((x.shape[0], self.n_out), np.float32)
        mlp_rows_k(self, x, out)
        return out


@nb.njit(cache=True)
def mlp_rows_k(net, x, out):
    """``out`` (m, n_out) float32: the network ``net`` (:class:`MlpNet`) on each row of ``x`` (m, n_in) float32,
    one row after the other (the module docstring)."""
    w, layout = net.weights, net.layout
    a = np.zeros(net.width, np.float32)
    b = np.zeros(net.width, np.float32)
    for r in range(x.shape[0]):
        for k in range(x.shape[1]):
            a[k] = x[r, k]
        n = x.shape[1]
        for layer in range(layout.shape[0]):
            n_in, n_out = layout[layer, N_IN], layout[layer, N_OUT]
            wa, ba, act = layout[layer, W_AT], layout[layer, B_AT], layout[layer, ACT]
            for j in range(n_out):
                acc = w[ba + j]
                row = wa + j * n_in
                for k in range(n_in):
                    acc += w[row + k] * a[k]
                if act == 1:
                    acc = np.tanh(acc)
                elif act == 2 and acc < 0:
                    acc = np.float32(0.0)
                b[j] = acc
            for j in range(n_out):
                a[j] = b[j]
            n = n_out
        for j in range(n):
            out[r, j] = a[j]
