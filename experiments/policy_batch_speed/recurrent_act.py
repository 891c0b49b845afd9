"""The cost of a recurrent learned policy's act per row and step in the benchmark's rows
(:class:`lvgym.agents.policybatch.SB3Batch`): ``model.predict`` per row against the LSTM's own ``_predict``
with each row's state kept as a tensor (``SB3Batch._recurrent_rows``).

    python -m experiments.policy_batch_speed.recurrent_act runs/v2-faults-budget/recurrent-res-lqg-front-s0

``rows`` rows of observations (drawn once, normal, seed 0) are acted on for ``steps`` steps by each path from
a fresh batch (one torch thread); both must give the same actions to the bit (checked). Printed: each path's
cost [us per row and step], the best of ``repeats``, and their ratio.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from lvgym.commandline import arg, parse


@dataclass
class Args:
    """Command-line arguments."""

    run: str = arg(positional=True)
    """a run folder of a recurrent policy (train.py --algo recurrent-ppo)"""
    rows: int = arg(50, lo=1, hi=4096)
    """rows acted on at each step"""
    steps: int = arg(40, lo=1, hi=100_000)
    """steps per replay"""
    repeats: int = arg(3, lo=1, hi=100)
    """replays per path (the best is printed)"""


def replay(policy, rows: int, steps: int, fast: bool) -> tuple[float, np.ndarray]:
    """Seconds per row and step, and the actions (steps, rows, n_a), of one replay from a fresh batch."""
    obs = np.random.default_rng(0).normal(size=(rows, *policy.model.observation_space.shape)).astype(np.float32)
    batch = policy.batch(rows)
    batch._lstm_rows = fast and batch._lstm_rows
    t0 = time.perf_counter()
    out = np.stack([batch.act(np.arange(rows), obs, {}) for _ in range(steps)])
    return (time.perf_counter() - t0) / (rows * steps), out


def main(argv: list[str] | None = None) -> dict[str, float]:
    import torch

    from lvgym.agents.policy import SB3Policy

    a = parse(Args, argv, "python -m experiments.policy_batch_speed.recurrent_act", __doc__)
    torch.set_num_threads(1)
    policy = SB3Policy(a.run)
    if not policy.recurrent:
        raise SystemExit(f"{a.run}: not a recurrent policy")
    best: dict[str, float] = {}
    actions: dict[str, np.ndarray] = {}
    for _ in range(a.repeats):
        for name, fast in (("model.predict", False), ("LSTM rows", True)):
            t, actions[name] = replay(policy, a.rows, a.steps, fast)
            best[name] = min(best.get(name, np.inf), t)
    if not np.array_equal(actions["model.predict"], actions["LSTM rows"]):
        raise SystemExit("the two paths gave different actions")
    for name, t in best.items():
        print(f"{name:14s} {t * 1e6:7.0f} us per row and step")
    print(f"ratio {best['model.predict'] / best['LSTM rows']:.2f} (the same actions to the bit)")
    return best


if __name__ == "__main__":
    main()
