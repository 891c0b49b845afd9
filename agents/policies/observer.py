"""A learned observer as a flight computer flies it: the last half second of the flight computer's signals
(the env's observation and the actions sent) in, an estimate of what it cannot measure out, in NumPy (no
torch at flight time), as the shipped disturbance-observer policy uses it
(:mod:`lvgym.agents.policies.inversion`).

- :class:`Window`: the last :data:`WINDOW` control steps' features of each row of a batch (:data:`FEATURES`:
  the observation's :data:`N_OBS` entries, then the action sent the step before);
- :class:`Observer`: the trained network's forward pass (an ensemble of two-layer tanh MLPs on standardised
  features and labels, their outputs averaged) from a ``.npz`` file (:meth:`Observer.load`).

The networks are fitted with torch (:mod:`lvgym.agents.training.observer_fit`; their torch form:
:mod:`lvgym.agents.policies.observer_net`, which gives the ``.npz``'s arrays); training is ``lvgym train --recipe
teacher-student`` (:mod:`lvgym.agents.training.teacher_student`, docs/teacher-student.md).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

__all__ = ["ACTIONS", "FEATURES", "LAYERS", "N_OBS", "WINDOW", "Observer", "Window"]

#: the control steps the observer reads (0.5 s at SMILE's 0.02 s)
WINDOW = 25
#: one step's features: the env's observation (its ``observation_layout``: the 14 entries of SMILE's v1 env,
#: ``roll_rate`` .. ``pitch_rate_reference``) then the action sent the step before (pitch, yaw)
ACTIONS = ("action_pitch", "action_yaw")
N_OBS = 14
FEATURES = N_OBS + len(ACTIONS)
#: one member's arrays in an observer file (``m<k>_<name>``): the features' and labels' standardisation, and
#: the three linear layers' weights ``(out, in)`` and biases
LAYERS = ("mean", "std", "label_mean", "label_std", "w0", "b0", "w1", "b1", "w2", "b2")


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
        """Record the actions ``rows`` sent this step (the next step's features)."""
        self.last_action[rows] = actions

    def reset(self, rows: np.ndarray) -> None:
        """Forget the flights of ``rows`` (zeros)."""
        self.x[rows] = 0.0
        self.last_action[rows] = 0.0


class Observer:
    """The forward pass of an ensemble of estimators (``members``: one mapping of :data:`LAYERS` each) on one
    window at a time: ``(WINDOW, FEATURES)`` features -> the members' mean label ``(outputs,)`` (float64). Each
    member: ``tanh(w0 z + b0)``, ``tanh(w1 h + b1)``, ``w2 h + b2`` on the flattened window ``z`` standardised
    by its ``mean`` and ``std``, its output scaled by ``label_std`` and shifted by ``label_mean``.

    For speed (one window per row and step) the members are fused once, in float64, then kept in float32: the
    standardisations folded into the first layer and the members' first layers stacked (one product), the
    second layers as one batched product, the label scaling and the mean over members folded into one last
    product. The same window gives the same estimate to the bit, whichever row of whichever batch it comes
    from (:meth:`rows`)."""

    def __init__(self, members: list[Mapping[str, np.ndarray]]) -> None:
        if not members:
            raise ValueError("an observer needs at least one member")
        self.members = [{k: np.asarray(m[k], dtype=np.float32) for k in LAYERS} for m in members]
        n_in = WINDOW * FEATURES
        for m in self.members:
            if m["w0"].shape[1] != n_in:
                raise ValueError(f"observer input {m['w0'].shape[1]}: {n_in} features ({WINDOW} steps of {FEATURES})")
        f64 = [{k: v.astype(np.float64) for k, v in m.items()} for m in self.members]
        k = len(f64)
        scale = [np.broadcast_to(m["std"], (WINDOW, FEATURES)).reshape(-1) for m in f64]
        shift = [np.broadcast_to(m["mean"], (WINDOW, FEATURES)).reshape(-1) for m in f64]
        self.w0 = np.concatenate([m["w0"] / s for m, s in zip(f64, scale)]).astype(np.float32)
        self.b0 = np.concatenate([m["b0"] - m["w0"] @ (c / s) for m, c, s in zip(f64, shift, scale)]).astype(np.float32)
        self.w1 = np.stack([m["w1"] for m in f64]).astype(np.float32)
        self.b1 = np.stack([m["b1"] for m in f64]).astype(np.float32)
        self.w2 = (np.concatenate([m["w2"] * m["label_std"][:, None] for m in f64], axis=1) / k).astype(np.float32)
        self.b2 = sum(m["b2"] * m["label_std"] + m["label_mean"] for m in f64) / k
        self.hidden = self.w1.shape[1]
        self.outputs = int(self.b2.shape[0])

    def rows(self, windows: np.ndarray) -> np.ndarray:
        """The estimates ``(m, outputs)`` (float64) of ``m`` windows ``(m, WINDOW, FEATURES)``, one per row in one
        call: numpy's stacked products take each window's matrix-vector product on its own, so a window's estimate
        is the same bits in a batch of one as in any batch."""
        z = np.asarray(windows, dtype=np.float32).reshape(len(windows), -1)
        h = np.tanh(np.matmul(self.w0, z[:, :, None])[..., 0] + self.b0)
        h = h.reshape(len(z), len(self.members), self.hidden, 1)
        h = np.tanh(np.matmul(self.w1[None], h)[..., 0] + self.b1)
        return np.matmul(self.w2, h.reshape(len(z), -1, 1))[..., 0].astype(np.float64) + self.b2

    def __call__(self, window: np.ndarray) -> np.ndarray:
        """The estimate ``(outputs,)`` of one window ``(WINDOW, FEATURES)``."""
        return self.rows(np.asarray(window)[None])[0]

    def save(self, path: str | Path) -> None:
        """Write the members' arrays to ``path`` (``.npz``, :meth:`load`)."""
        np.savez(path, **{f"m{k}_{name}": m[name] for k, m in enumerate(self.members) for name in LAYERS})

    @classmethod
    def load(cls, path: str | Path) -> Observer:
        """The observer saved at ``path`` by :meth:`save`."""
        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"no observer file {str(path)!r}")
        with np.load(path, allow_pickle=False) as f:
            n = len({k.split("_", 1)[0] for k in f.files})
            return cls([{name: f[f"m{k}_{name}"] for name in LAYERS} for k in range(n)])
