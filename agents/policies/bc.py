"""A policy cloned by ``lvgym bc`` (:mod:`lvgym.agents.training.clone`) from a Minari dataset of lvgym rollouts:
its network (:func:`network`), its batch law (:class:`BCLaw`) with its one-row face (:class:`BCPolicy`), and the
factory that flies a saved one (:func:`policy`).

    python evaluate.py --suites smile-v2 --policies lqg-front bc=lvgym.agents.policies.bc:policy

A multilayer perceptron (two hidden layers of ``hidden`` units, tanh) maps the last ``history`` observations of
an episode (the oldest first, zeros before the first) to an action. The trained file (torch's) holds the
weights, the history, the observation's normalisation and the dataset it came from. ``policy(env, path=...)``
flies it (its default path: ``runs/bc.pt``, or ``LVGYM_BC_PATH``), through the network's compiled forward.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.errors import ConfigError

from .mlp import MlpNet

__all__ = ["BCLaw", "BCPolicy", "network", "policy"]


def network(n_in: int, n_out: int, hidden: int) -> Any:
    """The cloned policy's torch network: ``n_in`` inputs, two tanh layers of ``hidden`` units, ``n_out``
    outputs."""
    import torch.nn as nn

    return nn.Sequential(nn.Linear(n_in, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(),
                         nn.Linear(hidden, n_out))


class BCLaw(BatchLaw):
    """A cloned policy (module docstring) flying ``n`` rows of an env of the ascent task: each row's last
    ``history`` observations (zeros before its first), normalised, through the cloned network's compiled
    forward (:mod:`lvgym.agents.policies.mlp`: each row on its own)."""

    def __init__(self, env: Any, path: str | Path, name: str = "bc", n: int = 1) -> None:
        import torch

        content = torch.load(path, weights_only=False)
        n_obs = int(np.prod(env.observation_space.shape))
        if n_obs != content["n_obs"]:
            raise ConfigError("bc path", str(path), f"a policy cloned on this env's observation ({n_obs} entries; "
                              f"the file's has {content['n_obs']})")
        self.name, self.history, self.n_obs = name, int(content["history"]), n_obs
        net = network(n_obs * self.history, content["n_act"], int(content["hidden"]))
        net.load_state_dict(content["state_dict"])
        self.net = MlpNet.from_torch(list(net))
        self.mean = np.asarray(content["mean"])
        self.std = np.asarray(content["std"])
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self.past = np.zeros((n, self.history, self.n_obs), np.float32)

    def reset(self, rows: Any) -> None:
        """The rows ``rows`` start an episode: no past observations."""
        self.past[np.asarray(rows, dtype=np.int64).reshape(-1)] = 0.0

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """The actions of the rows' last ``history`` observations."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        past = self.past[rows]
        past[:, :-1] = past[:, 1:]
        past[:, -1] = np.asarray(observations, np.float32).reshape(rows.size, -1)
        self.past[rows] = past
        x = ((past.reshape(rows.size, -1) - self.mean) / self.std).astype(np.float32)
        return self.net(x)


class BCPolicy(RowFace):
    """A cloned policy flying an env of the ascent task: one row of :class:`BCLaw`."""

    def __init__(self, env: Any, path: str | Path, name: str = "bc") -> None:
        self.law = BCLaw(env, path, name)


def policy(env: Any, path: str | Path | None = None, name: str | None = None) -> BCPolicy:
    """The cloned policy of ``path`` (default: ``LVGYM_BC_PATH``, else ``runs/bc.pt``), named ``name``
    (default: ``bc``; the file's stem when ``path`` is given, as ``evaluate.py --policies runs/bc_s0.pt``
    labels it)."""
    file = path or os.environ.get("LVGYM_BC_PATH", "runs/bc.pt")
    return BCPolicy(env, file, name or (Path(file).stem if path else "bc"))


policy.kind = "learned"  # type: ignore[attr-defined]
