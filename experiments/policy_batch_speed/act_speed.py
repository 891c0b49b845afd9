"""The cost of a classical controller's act per row and step: one policy object per row in Python against
the batched, compiled act (``policy.batch(n)``, lvgym.baselines.batch).

    python -m experiments.policy_batch_speed.act_speed --rows 50 --steps 300

For each controller, ``rows`` rows of the suite's VectorEnv fly ``steps`` control steps (the controller
switches on after 2 s on smile-v1) with the batch's actions; the observations and infos are recorded,
then replayed through ``rows`` policy objects (one ``act`` per row and step, each fed its row's
observation and single-env info, built before the clock starts) and through the batch (one ``act`` of all
rows per step). Both replays must give the same actions to the bit (checked). Printed per controller: the
per-row Python act [us per call], the batched act [us per row and step] and [us per call], the speed-up;
the best of ``repeats`` replays.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

import lvgym
import lvgym.baselines  # noqa: F401  (registers the baselines)
from lvgym.baselines.batch import row_info
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.runner import build_policy
from lvgym.benchmark.suites import SUITES
from lvgym.commandline import arg, parse

__all__ = ["POLICY_NAMES", "record", "replay", "time_policy"]

POLICY_NAMES = ("pid", "pid-thesis", "gs-pid", "gs-pid-thesis", "gs-pid-flex", "aac", "lqg", "lqg-front")


def record(env: Any, batch: Any, steps: int, seed: int = 0) -> tuple[list[np.ndarray], list[dict[str, Any]]]:
    """The observations (rows, n_obs) and batched infos of ``steps`` steps of ``env`` flown by ``batch``."""
    n = env.num_envs
    rows = np.arange(n)
    obs, info = env.reset(seed=seed)
    batch.reset(rows)
    observations, infos = [], []
    for _ in range(steps):
        observations.append(obs)
        infos.append(info)
        obs, _, _, _, info = env.step(batch.act(rows, obs, info))
    return observations, infos


def replay(policies: list[Any] | Any, observations: list[np.ndarray], infos: list[Any]) -> tuple[float, np.ndarray]:
    """Wall time [s] and actions (steps, rows, 2) of ``policies`` (a list: one per row, ``infos`` the rows'
    single-env infos per step; else a batch, ``infos`` the batched ones) over the recorded steps."""
    n = observations[0].shape[0]
    rows = np.arange(n)
    out = np.empty((len(observations), n, 2), np.float32)
    if isinstance(policies, list):
        for p in policies:
            p.reset()
        t0 = time.perf_counter()
        for k, (obs, inf) in enumerate(zip(observations, infos)):
            for b in range(n):
                out[k, b] = policies[b].act(obs[b], inf[b])
        return time.perf_counter() - t0, out
    policies.reset(rows)
    t0 = time.perf_counter()
    for k, (obs, inf) in enumerate(zip(observations, infos)):
        out[k] = policies.act(rows, obs, inf)
    return time.perf_counter() - t0, out


def time_policy(name: str, suite: str, rows: int, steps: int, repeats: int) -> dict[str, Any]:
    """The per-row and batched act of the registered policy ``name`` on ``rows`` rows of ``suite``'s
    VectorEnv (module docstring): microseconds per row and step, and per batched call."""
    env = lvgym.make_vec_env(suite, model="nonrigid", num_envs=rows)
    spec = POLICIES[name]
    batch = build_policy(spec, env).batch(rows)
    observations, infos = record(env, batch, steps)
    singles = [build_policy(spec, env) for _ in range(rows)]
    row_infos = [[row_info(inf, b) for b in range(rows)] for inf in infos]
    t_rows, t_batch = [], []
    for _ in range(repeats):
        t, want = replay(singles, observations, row_infos)
        t_rows.append(t)
        t, got = replay(batch, observations, infos)
        t_batch.append(t)
        if not np.array_equal(got, want):
            raise AssertionError(f"{name}: the batch's actions are not the per-row policies'")
    calls = rows * steps
    return {"policy": name, "batch": type(batch).__name__, "row_us": 1e6 * min(t_rows) / calls,
            "batch_row_us": 1e6 * min(t_batch) / calls, "batch_call_us": 1e6 * min(t_batch) / steps}


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.policy_batch_speed.act_speed --help``)."""

    policies: list[str] = arg(default_factory=lambda: list(POLICY_NAMES), choices=POLICY_NAMES)
    """the registered controllers timed"""
    suite: str = arg("smile-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the suite whose VectorEnv is flown (lqg and lqg-front fly SMILE only)"""
    rows: int = arg(50, lo=1, hi=10_000)
    """rows of the VectorEnv (episodes flown at once)"""
    steps: int = arg(300, lo=1, hi=100_000)
    """control steps recorded and replayed"""
    repeats: int = arg(3, lo=1, hi=100)
    """replays of each; the best is printed"""


def main(argv: list[str] | None = None) -> int:
    a = parse(Args, argv, "python -m experiments.policy_batch_speed.act_speed", __doc__)
    print(f"{a.suite}, {a.rows} rows, {a.steps} steps, best of {a.repeats}: act [us]")
    print(f"{'policy':14s} {'batch':10s} {'per-row Python':>15s} {'batched, per row':>17s} {'per call':>9s} {'speed-up':>9s}")
    for name in a.policies:
        r = time_policy(name, a.suite, a.rows, a.steps, a.repeats)
        print(f"{name:14s} {r['batch']:10s} {r['row_us']:15.1f} {r['batch_row_us']:17.2f} {r['batch_call_us']:9.1f} "
              f"{r['row_us'] / r['batch_row_us']:9.0f}", flush=True)
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
