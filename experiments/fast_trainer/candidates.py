"""The fast trainer chosen by measurement: env steps per second end to end of each candidate on the same condition,
cores, rows and networks, beside the env's raw batched rate, in one process.

    python -m experiments.fast_trainer.candidates                       # smile-v2 non-rigid, 1,024 rows
    python -m experiments.fast_trainer.candidates --only sbx --rollouts 2

Candidates: ``ppo-fast`` (lvgym.agents.training.ppo on the native ``VectorEnv``, what ``lvgym bench-train`` times),
stable-baselines3's PPO and the JAX learner sbx's PPO (``sbx-rl``, the SB3 API in JAX: it takes an SB3 ``VecEnv``,
here lvgym's SB3 face of the same batch core with ``VecNormalize``). All with 1,024 rows x 32 steps per rollout,
4 epochs of minibatches of 8,192, separate 64x64 tanh actor and critic, the same warm-up (lvgym.cli.bench_train:
:data:`~lvgym.cli.bench_train.WARM_STEPS` steps of every row, jit compiles included) before the timed rollouts.
PufferLib 3 (``pufferlib==3.0.0``) does not install here (README.md). sbx is not a dependency of lvgym: install
it by hand (``pip install sbx-rl``) to run its row.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from lvgym.commandline import arg, parse


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fast_trainer.candidates --help``)."""

    rows: int = arg(1024, lo=1, hi=4096)
    """rows of the batched env"""
    steps: int = arg(32, lo=2, hi=100_000)
    """rollout steps per row"""
    rollouts: int = arg(4, lo=1, hi=10_000)
    """timed rollouts"""
    only: list[str] = arg(default_factory=lambda: ["ppo-fast", "sb3", "sbx"], choices=("ppo-fast", "sb3", "sbx"))
    """the candidates timed"""


def sbx_rate(bench: Any, cond: Any, cfg: Any, warm: int) -> float:
    """Env steps per second of sbx's PPO with ``cfg``'s settings on the SB3 ``VecEnv`` of ``cond``."""
    import flax.linen as nn
    from sbx import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    from lvgym.envs import make_sb3_vec_env

    h = cfg.hyper
    venv = VecNormalize(make_sb3_vec_env(cond.env_id, num_envs=bench.rows, seed=0, **cond.env_kwargs()),
                        gamma=h.gamma)
    model = PPO("MlpPolicy", venv, learning_rate=h.learning_rate, n_steps=h.n_steps, batch_size=h.batch_size,
                n_epochs=h.n_epochs, gamma=h.gamma, gae_lambda=h.gae_lambda, clip_range=h.clip_range,
                ent_coef=h.ent_coef, vf_coef=h.vf_coef, max_grad_norm=h.max_grad_norm, seed=0,
                policy_kwargs={"net_arch": list(cfg.policy.net_arch), "activation_fn": nn.tanh,
                               "log_std_init": cfg.policy.log_std_init, "ortho_init": True})
    model.learn(bench.rows * bench.steps * warm)
    t0 = time.perf_counter()
    model.learn(bench.rows * bench.steps * bench.rollouts, reset_num_timesteps=False)
    rate = bench.rows * bench.steps * bench.rollouts / (time.perf_counter() - t0)
    venv.close()
    return rate


def main(argv: list[str] | None = None) -> None:
    """Print the table (Markdown)."""
    from lvgym.bench_envs import cpu_name, load_average
    from lvgym.benchmark.suites import condition
    from lvgym.cli import bench_train

    args = parse(Args, argv, "python -m experiments.fast_trainer.candidates", __doc__)
    bench = bench_train.Args(rows=args.rows, steps=args.steps, rollouts=args.rollouts, sb3="sb3" in args.only)
    cond = condition(bench.suite, bench.model)
    cfg = bench_train._config(bench, cond.env_id)
    warm = -(-bench_train.WARM_STEPS // bench.steps)
    print(f"# candidates ({cpu_name()}, load {load_average()}): {bench.suite} {bench.model}, {bench.rows} rows x "
          f"{bench.steps} steps, {bench.rollouts} rollouts timed\n")
    m = bench_train.measure(bench)
    print("| trainer | end-to-end env steps/s | / raw |\n|---|---:|---:|")
    print(f"| env alone (raw) | {m['raw']:,.0f} | 100 % |")
    print(f"| ppo-fast | {m['fast']:,.0f} | {100 * m['ratio']:.0f} % |")
    if "sb3" in m:
        print(f"| stable-baselines3 PPO | {m['sb3']:,.0f} | {100 * m['sb3_ratio']:.0f} % |")
    if "sbx" in args.only:
        try:
            rate = sbx_rate(bench, cond, cfg, warm)
            print(f"| sbx PPO (JAX) | {rate:,.0f} | {100 * rate / m['raw']:.0f} % |")
        except ImportError as exc:
            print(f"| sbx PPO (JAX) | not installed: {exc} | |")
    print(f"\nload after: {load_average()}")


if __name__ == "__main__":
    main()
