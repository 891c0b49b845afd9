"""Behaviour cloning (``lvgym bc``) from a Minari dataset of lvgym rollouts (:mod:`.datasets`): the minimal offline
baseline.

    lvgym dataset --policies lqg-front --suites smile-v2 --models nonrigid --episodes 50
    lvgym bc --dataset lvgym/smile-v2-nonrigid/lqg-front-v0 --out runs/bc_lqg_front.pt
    lvgym dataset --policies lqg-front --models nonrigid --episodes 50 --action-noise 0.05   # DART's data
    lvgym bc --dataset lvgym/smile-v2-nonrigid/lqg-front-noise0p05-v0 --out runs/bc_dart.pt
    python evaluate.py --suites smile-v2 --policies lqg-front bc=lvgym.agents.policies.bc:policy

A multilayer perceptron (torch; two hidden layers of ``--hidden`` units, tanh) maps the last ``--history``
observations of an episode (the oldest first, zeros before the first) to the action the dataset's policy
took (in a dataset recorded with ``--action-noise``, the action it asked for, ``infos["expert_action"]``,
not the perturbed one the env flew: DART), by least squares on every step of every episode, with Adam.
The classical designs it clones carry
state (a Kalman filter, an integrator): the history stands in for it. The trained file holds the weights,
the history, the observation's normalisation and the dataset it came from (the network:
:func:`lvgym.agents.policies.bc.network`). :func:`lvgym.agents.policies.bc.policy` flies it (its default path:
``runs/bc.pt``, or ``LVGYM_BC_PATH``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.commandline import arg, parse
from lvgym.errors import ConfigError

from ..policies.bc import network

__all__ = ["features", "train"]

PROG = "lvgym bc"


def features(observations: np.ndarray, history: int) -> np.ndarray:
    """The inputs of each step of one episode: its last ``history`` observations (N, n) stacked, the oldest
    first, zeros before the episode's first: (N, history * n)."""
    obs = np.asarray(observations, dtype=np.float32)
    n, width = obs.shape
    padded = np.concatenate([np.zeros((history - 1, width), np.float32), obs])
    return np.concatenate([padded[k:k + n] for k in range(history)], axis=1)


def train(dataset_id: str, out: str | Path, history: int = 8, hidden: int = 128, epochs: int = 30,
          batch: int = 512, lr: float = 1e-3, seed: int = 0) -> dict[str, Any]:
    """Fit the policy to every step of the Minari dataset ``dataset_id`` and save it to ``out``; returns the
    file's content (module docstring) with the training loss per epoch (``loss``)."""
    import minari
    import torch

    if history < 1:
        raise ConfigError("history", history, "an integer >= 1")
    data = minari.load_dataset(dataset_id)
    xs, ys = [], []
    for ep in data.iterate_episodes():
        xs.append(features(ep.observations[:-1], history))
        # a noise-injected dataset (lvgym dataset --action-noise) labels each step with the policy's own action
        labels = ep.infos.get("expert_action") if isinstance(ep.infos, dict) else None
        ys.append(np.asarray(ep.actions if labels is None else np.asarray(labels)[1:], dtype=np.float32))
    x, y = np.concatenate(xs), np.concatenate(ys)
    mean, std = x.mean(axis=0), x.std(axis=0) + 1e-6
    torch.manual_seed(seed)
    net = network(x.shape[1], y.shape[1], hidden)
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    xt, yt = torch.as_tensor((x - mean) / std), torch.as_tensor(y)
    gen = torch.Generator().manual_seed(seed)
    losses = []
    for _ in range(epochs):
        total = 0.0
        for idx in torch.randperm(len(xt), generator=gen).split(batch):
            opt.zero_grad()
            loss = torch.mean((net(xt[idx]) - yt[idx]) ** 2)
            loss.backward()
            opt.step()
            total += loss.item() * len(idx)
        losses.append(total / len(xt))
    content = {"state_dict": net.state_dict(), "history": history, "hidden": hidden, "mean": mean, "std": std,
               "n_obs": int(x.shape[1] // history), "n_act": int(y.shape[1]), "dataset": dataset_id,
               "steps": int(len(x)), "loss": losses}
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    torch.save(content, out)
    return content


@dataclass
class Args:
    """Command-line arguments (``lvgym bc --help``)."""

    dataset: str = arg("lvgym/smile-v2-nonrigid/lqg-front-v0", metavar="DATASET_ID")
    """the Minari dataset to clone (lvgym dataset writes them)"""
    out: str = arg("runs/bc.pt", metavar="FILE")
    """where to save the cloned policy"""
    history: int = arg(8, lo=1, hi=1000)
    """observations per input"""
    hidden: int = arg(128, lo=1, hi=100_000)
    """units per hidden layer"""
    epochs: int = arg(30, lo=1, hi=100_000)
    """passes over the dataset"""
    seed: int = arg(0, lo=0, hi=2**31 - 1)
    """the training's random seed"""


def main(argv: Sequence[str] | None = None) -> None:
    a = parse(Args, argv, PROG, __doc__)
    content = train(a.dataset, a.out, a.history, a.hidden, a.epochs, seed=a.seed)
    loss = content["loss"]
    print(f"{a.out}: {content['steps']} steps of {a.dataset}, loss {loss[0]:.3g} -> {loss[-1]:.3g}")


if __name__ == "__main__":
    main()
