"""``lvgym train --algo ppo-fast``: a run of :class:`lvgym.agents.training.ppo.FastPPO` in the run folder every other
tool reads (docs/training.md, "The run folder").

:func:`lvgym.agents.training.train.train` prepares the run as for any algorithm (the options, the suite's condition,
the hyperparameters of ``hyperparams/ppo-fast.yaml``, the seeds, ``config.yaml``) and hands it here. The env is the
native Gymnasium ``VectorEnv`` of the run's env id and keywords (``lvgym.make_vector``: a suite's condition with
``--suite``), row ``i`` seeded ``seed + i``. The checkpoints, the validations on the protocol's validation seeds,
``evaluations.json``, ``best_model.*`` and ``final_model.*`` are :class:`~lvgym.agents.training.callbacks.CheckpointCallback`'s,
driven once per rollout: the files are an SB3 ``PPO`` ``.zip`` (weights and Adam's state), its
``_vecnormalize.pkl`` (the observation and return statistics) and the JSON record (``"trainer": "ppo-fast"``), so
``lvgym evaluate --policies runs/<name>`` flies the run as it flies an SB3 run, through the compiled actor.
``--resume`` continues from the newest checkpoint. SB3's logger writes ``progress_<step>.csv`` and ``tb/``: after
every rollout the step, the wall time, where the time went (``time/env_us``, ``time/inference_us``,
``time/update_us`` per sample) and the episodes that ended in it (``rollout/cost_mean``: minus the mean return,
which is ``score_v2`` when the reward is the score; ``rollout/failure_rate``, ``rollout/rate_error_mean``), which
``lvgym curves`` draws.

The residual, the loop dispersion, the training charges and the family's vehicles are wrappers of the SB3 VecEnv:
a ppo-fast run refuses them in one line (a plain run: ``--residual none``).
"""

from __future__ import annotations

import datetime as dt
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

from lvgym.commandline import command_name, fail
from lvgym.errors import ConfigError

__all__ = ["FAST_ALGOS", "check_fast", "train_fast"]

#: the algorithms this module trains (the others are stable-baselines3's own)
FAST_ALGOS = ("ppo-fast",)
#: the run options a ppo-fast run cannot take: config key -> the option that sets it
_UNSUPPORTED = {"residual": "--residual", "loop_dispersion": "--loop-gain-db / --loop-delay-periods",
                "load_margin": "--load-margin", "command_rate": "--command-rate-charge",
                "family_vehicles": "a family --suite"}


def check_fast(config: dict[str, Any]) -> None:
    """A ConfigError naming the first option of ``config`` that ppo-fast does not take (wrappers of SB3's VecEnv)."""
    for key, option in _UNSUPPORTED.items():
        if config.get(key):
            raise ConfigError("--algo", config["algo"], f"a plain run on the native VectorEnv, without {option} "
                              f"(it wraps stable-baselines3's VecEnv): use --algo ppo for it")


def _load(stem: Path, venv: Any, cfg: Any) -> tuple[Any, Any]:
    """The model and the statistics of the checkpoint ``stem``."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    from lvgym.agents.policies.saved import policy_files

    from .ppo import _Spaces

    spaces = _Spaces(venv.single_observation_space, venv.single_action_space)
    zip_path, norm_path, _ = policy_files(stem)
    model = PPO.load(str(zip_path), env=spaces.venv(), device="cpu", custom_objects=cfg.schedules())
    stats = VecNormalize.load(str(norm_path), spaces.venv())
    stats.training = True
    return model, stats


def _record(model: Any, ppo: Any, losses: dict[str, float], episodes: dict[str, float], checkpoint: Any,
            t_segment: float, start: int) -> None:
    """One row of the progress table (SB3's logger) after an update."""
    log = model.logger
    step = int(model.num_timesteps)
    elapsed = time.perf_counter() - t_segment
    log.record("time/total_timesteps", step)
    log.record("time/time_elapsed", round(elapsed, 3))
    log.record("time/fps", round((step - start) / max(elapsed, 1e-9), 1))
    log.record("time/train_wall_s", round(checkpoint.train_wall_s(), 3))
    for key, value in ppo.timers.per_sample_us().items():
        log.record(f"time/{key}_us", round(value, 3))
    for key, value in episodes.items():
        log.record(f"rollout/{key}", value)
    for key, value in losses.items():
        log.record(f"train/{key}", value)
    log.dump(step=step)


def train_fast(args: Any, given: set[str], config: dict[str, Any], cfg: Any, run_dir: Path, resumed: bool,
               stem: Path | None, state: dict[str, Any] | None, seed: int, stop: Any, t0: float, prog: str) -> Path:
    """Run (or resume) a ppo-fast run (the module docstring); ``args`` .. ``seed`` as
    :func:`lvgym.agents.training.train._train` prepared them. Returns the run folder."""
    import torch

    import lvgym
    from lvgym.agents.policies.checkpoints import clean_incomplete, latest_checkpoint
    from lvgym.agents.policies.sb3 import privileged_env_options
    from lvgym.agents.training.callbacks import CheckpointCallback, ValidationEvaluator, load_rng

    from .ppo import FastPPO, make_shell, make_stats
    from .runfolder import create_run, make_logger, provenance

    try:
        check_fast(config)
    except ConfigError as exc:
        fail(prog, exc)
    try:
        venv = lvgym.make_vector(config["env_id"], cfg.n_envs, **config["env_kwargs"])
    except (ConfigError, ValueError, TypeError) as exc:
        fail(prog, f"{config['env_id']} option {exc}")
    target = int(config["total_timesteps"])
    start = int(state["num_timesteps"]) if state else 0
    try:
        if not resumed or "total_timesteps" in given:
            create_run(config, run_dir)
        if resumed:
            clean_incomplete(run_dir / "checkpoints")
            print(f"{prog}: resuming {run_dir} from step {start:,} of {target:,}" if stem is not None else
                  f"{prog}: {run_dir} has no complete checkpoint to resume from: training starts again at step 0",
                  file=sys.stderr)
        torch.set_num_threads(max(1, args.torch_threads))
        if stem is not None:
            model, stats = _load(stem, venv, cfg)
            load_rng(stem.with_name(stem.name + "_rng.pkl"))
        else:
            torch.manual_seed(int(config["seed"]))
            model = make_shell(venv.single_observation_space, venv.single_action_space, cfg, int(config["seed"]))
            stats = make_stats(venv.single_observation_space, venv.single_action_space, cfg.normalize, cfg.hyper.gamma)
        model._total_timesteps = target
        model.set_logger(make_logger(run_dir, start, args.verbose))
        with open(run_dir / "segments.jsonl", "a", encoding="utf-8") as f:
            f.write(json.dumps({"start_step": start, "env_seed": seed, "target": target, "resumed": resumed,
                                "started_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
                                "pid": os.getpid(), "trainer": "ppo-fast", **provenance()}) + "\n")
        evaluator = None
        suite = config.get("eval_suite", "none")
        if suite != "none" and args.eval_freq > 0:
            over = {**({"mission_time_s": args.eval_mission_time_s} if args.eval_mission_time_s else {}),
                    **privileged_env_options(config["env_kwargs"])} or None
            select = config.get("eval_select", "all")
            evaluator = ValidationEvaluator(suite, args.eval_episodes, over,
                                            select_on=config["env_kwargs"].get("model") if select == "trained" else None)
        meta = {"algo": "PPO", "trainer": "ppo-fast", "env_id": config["env_id"], "env_kwargs": config["env_kwargs"],
                "run": config["name"], "seed": config["seed"], "target_timesteps": target,
                "git_commit": config.get("git_commit"), "lvgym_version": config.get("lvgym_version")}
        deadline = None if args.max_wall_time_s is None else t0 + float(args.max_wall_time_s)
        checkpoint = CheckpointCallback(run_dir, args.checkpoint_freq, meta, stats, evaluator, args.eval_freq,
                                        args.keep_checkpoints, state, verbose=args.verbose,
                                        interval_s=args.checkpoint_interval_s, stop=stop, deadline=deadline)
        ppo = FastPPO(venv, cfg, model, stats, seed)
        checkpoint.init_callback(model)
        checkpoint.clock, checkpoint.env_at_start = ppo.timers, 0.0      # env_wall_s: the env's step time
        halt = lambda: not checkpoint.on_step()                         # noqa: E731  (a signal or the deadline)
        t_segment = last_line = time.perf_counter()
        with stop.armed():
            while model.num_timesteps < target:
                if halt():
                    break
                checkpoint.on_rollout_start()                            # a checkpoint (and validation) when due
                taken = ppo.collect(halt)
                if taken < ppo.T:                                        # cut short: not trained on
                    model.num_timesteps += taken * ppo.rows
                    break
                checkpoint.on_rollout_end()
                losses = ppo.update(1.0 - min(1.0, model.num_timesteps / target))
                _record(model, ppo, losses, ppo.take_episodes(), checkpoint, t_segment, start)
                if args.progress_interval_s > 0 and time.perf_counter() - last_line >= args.progress_interval_s:
                    last_line = time.perf_counter()
                    _line(prog, model, target, start, t_segment, ppo, checkpoint)
            checkpoint.on_step()
            checkpoint.on_training_end()
        wall = time.perf_counter() - t_segment
        print(f"{run_dir}: {model.num_timesteps} / {target} steps ({(model.num_timesteps - start) / max(wall, 1e-9):.0f} "
              f"steps/s this segment)", file=sys.stderr)
        if evaluator is not None:
            evaluator.close()
    finally:
        venv.close()
    if stop.signum is not None or checkpoint.out_of_time:
        last = latest_checkpoint(run_dir / "checkpoints")
        where = f"checkpoint step_{int(last[1]['num_timesteps']):012d}" if last else "no checkpoint"
        why = (f"stopped by {stop.name}" if stop.signum is not None else
               f"the wall-time budget of {args.max_wall_time_s:g} s is spent: stopped")
        again = f"{'python ' if prog.endswith('.py') else ''}{command_name(prog)} --resume {run_dir}"
        print(f"{prog}: {why} at step {model.num_timesteps:,} of {target:,}; {where} written; continue with {again}",
              file=sys.stderr)
        if stop.signum is not None:
            raise SystemExit(128 + stop.signum)
    return run_dir


def _line(prog: str, model: Any, target: int, start: int, t_segment: float, ppo: Any, checkpoint: Any) -> None:
    """The progress line on stdout: step, speed, time, where the time goes and the latest validation."""
    elapsed = time.perf_counter() - t_segment
    us = ppo.timers.per_sample_us()
    latest = checkpoint.evaluations[-1] if checkpoint.evaluations else None
    val = "-" if latest is None else f"{latest['score']} at {int(latest['num_timesteps']):,}"
    print(f"{prog}: step {int(model.num_timesteps):,} / {target:,}, {(model.num_timesteps - start) / elapsed:,.0f} "
          f"steps/s, {elapsed / 60:.1f} min; us per sample: env {us['env']:.1f}, inference {us['inference']:.1f}, "
          f"update {us['update']:.1f}; validation {val}", flush=True)
