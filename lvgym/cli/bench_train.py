"""``lvgym bench-train``: how fast training runs against the env it trains on, in one process on the same cores.

    lvgym bench-train                                    # smile-v2 non-rigid, 1,024 rows, 64x64 tanh networks
    lvgym bench-train --epochs 10 --minibatch 1024       # SB3's default update on the fast trainer
    lvgym bench-train --sb3                              # and stable-baselines3's PPO on the same condition
    lvgym bench-train --rows 8 --steps 4 --rollouts 1    # a tiny run (tests)

It prints, as a Markdown table:

- the env's raw batched rate: env steps per second of the native ``VectorEnv`` of the suite's condition
  (``lvgym.make_vec_env``) stepped with fixed random actions (drawn as the untrained policy draws them) and
  nothing else;
- ppo-fast's end-to-end rate (:mod:`lvgym.agents.training.ppo`: rollouts and their updates) and its ratio to
  the raw rate;
- where ppo-fast's time goes, in microseconds per sample (one env step of one row): the env's ``step``, the
  inference (forward passes, sampling, normalisation, buffers and episode accounting) and the update
  (advantages and the epochs), with the epochs and the minibatch;
- with ``--sb3``: stable-baselines3's PPO with the same rollout, networks, epochs and minibatch on the SB3
  ``VecEnv`` of the condition (with ``VecNormalize``), end to end, and its ratio.

On two cores the env (its simulator threads) and the learner take turns, so the end-to-end rate is
``1 / (env + inference + update)`` per sample: the learner's microseconds are the lever.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.commandline import arg, parse

__all__ = ["Args", "main", "measure"]


@dataclass
class Args:
    """Command-line arguments (``lvgym bench-train --help``)."""

    suite: str = arg("smile-v2", check=lambda option, value: _suite(option, value))
    """the benchmark suite whose condition is trained on"""
    model: str = arg("nonrigid", choices=("rigid", "slosh", "flex", "nonrigid"))
    """flight model of the condition"""
    rows: int = arg(1024, lo=1, hi=4096)
    """rows of the batched env"""
    steps: int = arg(32, lo=2, hi=100_000)
    """rollout steps per row (n_steps)"""
    rollouts: int = arg(4, lo=1, hi=10_000)
    """timed rollouts, each followed by its update (after the warm-up: WARM_STEPS steps of every row)"""
    epochs: int = arg(4, lo=1, hi=1000)
    """epochs of an update"""
    minibatch: int = arg(8192, lo=2, hi=10_000_000)
    """samples per minibatch (at most rows x steps)"""
    net: list[int] = arg(default_factory=lambda: [64, 64], lo=1, hi=4096, metavar="WIDTH")
    """hidden layers of the actor and of the critic (tanh)"""
    torch_threads: int = arg(1, lo=1, hi=1024)
    """torch CPU threads"""
    sb3: bool = False
    """also time stable-baselines3's PPO with the same settings"""


def _suite(option: str, value: str) -> str:
    from lvgym.benchmark.suites import SUITES
    from lvgym.errors import ConfigError

    if value not in SUITES:
        raise ConfigError(option, value, f"one of {sorted(SUITES)}")
    return value


def _config(args: Args, env_id: str) -> Any:
    from lvgym.agents.training.config import load_config

    return load_config("ppo-fast", env_id, {"n_envs": args.rows, "algo.n_steps": args.steps,
                                            "algo.batch_size": min(args.minibatch, args.rows * args.steps),
                                            "algo.n_epochs": args.epochs, "policy.net_arch": list(args.net)})


#: env steps of every row before a rate is timed: the flight off the pad with the controller on (as
#: ``lvgym bench-envs``), and the trainers' first compiles and allocations done
WARM_STEPS = 256


def raw_rate(venv: Any, steps: int, std: float) -> float:
    """Env steps per second (rows x steps over the wall time) of ``steps`` steps with fixed random actions drawn
    as the untrained policy draws them (a Gaussian of standard deviation ``std`` around 0, clipped)."""
    rng = np.random.default_rng(0)
    space = venv.single_action_space
    actions = np.clip(rng.normal(0.0, std, (8, venv.num_envs, space.shape[0])), space.low, space.high)
    actions = actions.astype(np.float32)
    t0 = time.perf_counter()
    for i in range(steps):
        venv.step(actions[i % 8])
    return venv.num_envs * steps / (time.perf_counter() - t0)


def measure(args: Args) -> dict[str, Any]:
    """The numbers of the table (the module docstring). Each rate is timed from the same start: every row reset
    with seeds from 0, :data:`WARM_STEPS` steps flown (ppo-fast: whole rollouts and their updates), then the
    timed steps."""
    import torch

    from lvgym.agents.training.ppo import FastPPO, Timers, make_shell, make_stats
    from lvgym.benchmark.suites import condition

    torch.set_num_threads(args.torch_threads)
    cond = condition(args.suite, args.model)
    cfg = _config(args, cond.env_id)
    warm = -(-WARM_STEPS // args.steps)                            # whole rollouts
    venv = cond.make_vec_env(args.rows)
    std = math.exp(cfg.policy.log_std_init)
    venv.reset(seed=0)
    raw_rate(venv, warm * args.steps, std)
    raw = raw_rate(venv, args.steps * args.rollouts, std)
    model = make_shell(venv.single_observation_space, venv.single_action_space, cfg, 0)
    stats = make_stats(venv.single_observation_space, venv.single_action_space, cfg.normalize, cfg.hyper.gamma)
    ppo = FastPPO(venv, cfg, model, stats, seed=0)                 # resets every row with seeds from 0
    for _ in range(warm):
        ppo.collect()
        ppo.update(1.0)
    ppo.timers = Timers()
    t0 = time.perf_counter()
    for _ in range(args.rollouts):
        ppo.collect()
        ppo.update(1.0)
    fast = ppo.timers.samples / (time.perf_counter() - t0)
    venv.close()
    out = {"suite": args.suite, "model": args.model, "rows": args.rows, "steps": args.steps, "raw": raw,
           "fast": fast, "ratio": fast / raw, "us": ppo.timers.per_sample_us(), "epochs": cfg.hyper.n_epochs,
           "minibatch": cfg.hyper.batch_size, "net": list(cfg.policy.net_arch), "threads": args.torch_threads}
    if args.sb3:
        out["sb3"] = sb3_rate(args, cond, cfg, warm)
        out["sb3_ratio"] = out["sb3"] / raw
    return out


def sb3_rate(args: Args, cond: Any, cfg: Any, warm: int) -> float:
    """Env steps per second of stable-baselines3's PPO (``learn``) with ``cfg``'s settings on the SB3 ``VecEnv``
    of ``cond`` (with ``VecNormalize``), after ``warm`` rollouts and their updates."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    from lvgym.envs import make_sb3_vec_env

    venv = VecNormalize(make_sb3_vec_env(cond.env_id, num_envs=args.rows, seed=0, **cond.env_kwargs()),
                        gamma=cfg.hyper.gamma)
    kw = cfg.sb3_kwargs()
    model = PPO("MlpPolicy", venv, seed=0, device="cpu", verbose=0, **kw)
    model.learn(args.rows * args.steps * warm)                    # warm-up
    t0 = time.perf_counter()
    model.learn(args.rows * args.steps * args.rollouts, reset_num_timesteps=False)
    rate = args.rows * args.steps * args.rollouts / (time.perf_counter() - t0)
    venv.close()
    return rate


def table(m: dict[str, Any]) -> list[str]:
    """The Markdown lines of :func:`measure`'s numbers."""
    us = m["us"]
    net = "x".join(str(w) for w in m["net"])
    lines = [f"| {m['suite']} {m['model']}, {m['rows']:,} rows x {m['steps']} steps, {net} tanh, {m['epochs']} epochs, "
             f"minibatch {m['minibatch']:,}, torch threads {m['threads']} | value |", "|---|---:|",
             f"| env, raw batched steps/s | {m['raw']:,.0f} |",
             f"| ppo-fast, end-to-end steps/s | {m['fast']:,.0f} |",
             f"| ppo-fast / raw | {100 * m['ratio']:.0f} % |",
             f"| ppo-fast, us per sample in the env | {us['env']:.2f} |",
             f"| ppo-fast, us per sample in inference | {us['inference']:.2f} |",
             f"| ppo-fast, us per sample in the update ({m['epochs']} epochs, minibatch {m['minibatch']:,}) | "
             f"{us['update']:.2f} |"]
    if "sb3" in m:
        lines += [f"| stable-baselines3 PPO, end-to-end steps/s | {m['sb3']:,.0f} |",
                  f"| stable-baselines3 PPO / raw | {100 * m['sb3_ratio']:.0f} % |"]
    return lines


def main(argv: list[str] | None = None) -> None:
    """Print the table (Markdown)."""
    from lvgym.bench_envs import cpu_name, load_average

    args = parse(Args, argv, "lvgym bench-train", __doc__)
    if args.minibatch > args.rows * args.steps:
        args.minibatch = args.rows * args.steps
    m = measure(args)
    print(f"# training speed ({cpu_name()}, {os.cpu_count()} cores, load {load_average()})\n")
    print("\n".join(table(m)))


if __name__ == "__main__":
    main()
