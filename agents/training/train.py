"""Train a TVC policy with stable-baselines3 (PPO, SAC, TD3; sb3-contrib's RecurrentPPO) on the batched lvgym envs.

    lvgym train                         # PPO on SmileAscent-v1 with its recipe (RECIPES): residual on lqg, history 4
    lvgym train --recipe plain          # PPO from scratch on v1's flight observation: no residual, no history
    lvgym train --env-id lvgym/SmileAscent-v0                    # v0: the ideal state, no recipe
    lvgym train --algo sac --model rigid --wind random --randomize all --total-timesteps 2e6 --name sac-rigid
    lvgym train --hp algo.n_steps=128 policy.net_arch=[32,32] --env-kwargs mission_time_s=20
    lvgym train --resume runs/sac-rigid                    # continue a stopped or killed run
    lvgym train --max-wall-time 3600                       # stop after an hour: validated, best and final models
    lvgym train --algo recurrent-ppo --history 0           # an LSTM policy, residual on lqg
    lvgym train --residual gs-pid-flex --residual-scale 0.2
    lvgym train --suite smile-v2-faults --residual lqg-front   # a v2 suite's condition, validated on it
    lvgym train --suite family-v2-informed --family-vehicles 8 --residual auto-lqg   # the family's train vehicles
    lvgym train --recipe teacher-student --help            # inversion-id's recipe: its own options

(``python train.py`` in a checkout is the same command.) A run lives in ``runs/<name>/``: ``config.yaml``
(every argument, the resolved hyperparameters and env keywords, lvgym version, git commit),
``segments.jsonl`` (one line per start or resume), ``tb/`` (TensorBoard: ``tensorboard --logdir runs``),
``progress_<step>.csv``, ``checkpoints/`` (model, VecNormalize statistics, generator states, replay
buffer; see ``agents/training/callbacks.py``), ``evaluations.json`` (validation on the benchmark protocol's
validation seeds), ``best_model.*`` and ``final_model.*`` (load with ``lvgym.agents.policies.sb3.SB3Policy`` or
pass the ``.zip`` to ``lvgym evaluate``). ``--resume`` restarts from the newest complete checkpoint with the
run's own configuration, the same target step count, the normalisation statistics and the step counter
(``reset_num_timesteps=False``), and says what it resumed from (or that there was no checkpoint yet).

Nothing is lost to a kill but the last minute: a checkpoint is written every ``--checkpoint-freq`` env
steps and every ``--checkpoint-interval-s`` seconds of wall time (60 s), and on SIGTERM or SIGINT (Ctrl-C)
the run writes one at the next env step and exits (status 128 + the signal; a second signal stops at
once). ``--max-wall-time`` is a budget for this process: once spent, the run stops at the next env step and
ends as a finished run does, with a checkpoint, a validation (when the run validates), ``final_model.*``,
``best_model.*`` and ``evaluations.json``, says so and exits normally (status 0; ``--resume`` continues it).
A line on stdout every ``--progress-interval-s`` seconds gives the step, the speed, the time spent and left
and the latest validation score. Every option is checked before the run folder is made: a bad value is a
one-line error and leaves nothing behind.

``--recipe`` chooses a preset: ``residual`` (the default) the env id's recipe (:data:`RECIPES`), ``plain`` learning
from scratch (no residual, no history, no teacher); an option given on the command line wins over the preset's.
``--recipe teacher-student`` hands the rest of the command line over to the recipe of the shipped
``inversion-id`` policies (:mod:`lvgym.agents.training.teacher_student`: a privileged teacher, DAgger rounds, a learned
disturbance observer, its flight options chosen on validation seeds), which has its own options.
"""

from __future__ import annotations

import datetime as dt
import json
import os
import sys
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

from lvgym.commandline import arg, command_name, fail, parse_given
from lvgym.errors import ConfigError
from lvgym.parallel import exit_on_sigterm

from .runfolder import create_run, make_logger, provenance
from .trainsetup import (DEFAULT_EVAL_SUITES, RECIPES, SB3_RECIPES, check_options, env_kwargs_of, eval_suite_option,
                         is_family, make_venv, protocol_training, recipe_options, suite_condition, suite_option,
                         training_seed)

__all__ = ["Args", "DEFAULT_EVAL_SUITES", "RECIPES", "RESUME_OVERRIDABLE", "check_options", "create_run",
           "env_kwargs_of", "main", "make_venv", "parse_args", "prepare", "protocol_training", "train",
           "training_seed"]

PROG = "train.py"
#: the recipes ``--recipe`` chooses: stable-baselines3's presets (this module; :data:`SB3_RECIPES`) or the
#: teacher-student recipe (:mod:`lvgym.agents.training.teacher_student`, its own options)
TRAINERS = (*SB3_RECIPES, "teacher-student")
#: the recipe of a run folder made before the presets (``sb3``: the env id's recipe, today's ``residual``)
LEGACY_RECIPES = {"sb3": "residual"}
#: the options a resumed run takes from the command line (the rest from its config.yaml)
RESUME_OVERRIDABLE = ("resume", "progress", "torch_threads", "verbose", "total_timesteps", "checkpoint_interval_s",
                      "max_wall_time_s", "progress_interval_s")


def _choices(name: str) -> Any:
    """The allowed values of an option that names things, looked up when the parser is built."""
    def choices() -> tuple[str, ...]:
        import lvgym
        from lvgym.agents.policies.algos import ALGOS
        from lvgym.envs.spec import OBSERVATIONS, WIND_TIERS
        from lvgym.simulator import MODELS

        return {"env_id": tuple(lvgym.ENV_IDS), "model": tuple(MODELS), "wind": ("protocol", *WIND_TIERS),
                "observation": ("env", *OBSERVATIONS), "algo": tuple(ALGOS)}[name]
    return choices


@dataclass
class Args:
    """Command-line arguments (``lvgym train --help``)."""

    recipe: str = arg("residual", choices=TRAINERS)
    """residual: the env id's recipe (RECIPES; for lvgym/SmileAscent-v1 PPO residual on lqg at 5 % of the gimbal,
    a 4-sample history, turbulence without the gust; an id without one trains plain); plain: from scratch, no
    residual, no history, no teacher, the protocol's wind; teacher-student: the recipe of the shipped inversion-id
    policies, with its own options (lvgym train --recipe teacher-student --help). An option given wins over the
    preset's (default: residual)"""
    env_id: str = arg("lvgym/SmileAscent-v1", choices=_choices("env_id"))
    """registered lvgym env id (the options an id's recipe sets, RECIPES, default to it)"""
    suite: str | None = arg(None, check=suite_option)
    """train on this benchmark suite's condition of --model (its env id, wind, dispersions and options, e.g.
    smile-v2-faults' faults; rows reset with training seeds) and validate on the suite (default: --env-id's);
    a family suite trains on the family's train vehicles and validates on its validation vehicles; a v2 suite
    trains on the score reward (reward_kind=score_v2; --env-kwargs reward_kind=weighted: the weighted terms)"""
    family_vehicles: int = arg(8, lo=1, hi=1000)
    """with a family --suite: the rows fly the family's first N train vehicles (lvgym.agents.training.familytrain)"""
    model: str = arg("nonrigid", choices=_choices("model"))
    """flight model: rigid, slosh, flex or nonrigid"""
    wind: str = arg("protocol", choices=_choices("wind"))
    """wind tier (lvgym.envs.WIND_TIERS), or protocol: the env's protocol (turbulence for v0 ids; the wind of
    the id's v1 suite for v1 ids, turbulence_gust for SmileAscent-v1), with --suite the suite's (default: the
    --recipe's: turbulence for residual on lvgym/SmileAscent-v1 without --suite, else protocol)"""
    randomize: list[str] = arg(default_factory=lambda: ["protocol"], nargs="*")
    """names drawn per episode (lvgym.envs.RANDOMIZE), 'all', 'none' or 'protocol': the env's protocol
    (wind thrust_misalignment for v0 ids; every dispersion of protocol v1, V1_DISPERSIONS, for v1 ids)"""
    observation: str = arg("env", choices=_choices("observation"))
    """state (ideal), sensors (IMU), flight (v1's flight computer) or env: the env's own (state for v0
    ids, flight for v1 ids)"""
    env_kwargs: list[str] = arg(default_factory=list, nargs="*", extend=True)
    """further env keywords KEY=VALUE (values in YAML), e.g. mission_time_s=20 (a repeated flag adds)"""
    history: int = arg(0, lo=0, hi=64)
    """observation history: the last K samples and actions stacked (lvgym.envs.history; 0: off; default: the
    --recipe's: 4 for residual on lvgym/SmileAscent-v1, else 0)"""
    algo: str = arg("ppo", choices=_choices("algo"))
    """ppo, sac, td3, recurrent-ppo (sb3-contrib's RecurrentPPO with MlpLstmPolicy) or ppo-fast (PPO on the native
    VectorEnv at the env's speed, lvgym.agents.training.ppo: a plain run, never residual)"""
    residual: str | None = None
    """fly residual on this registered baseline, e.g. gs-pid-flex, or none (lvgym.agents.wrappers.residual;
    default: the --recipe's: lqg for residual on lvgym/SmileAscent-v1, else none)"""
    residual_scale: float = 0.2
    """with --residual: gimbal units per unit of learned action, in (0, 2] (default: the --recipe's: 0.05 for
    residual on lvgym/SmileAscent-v1, else 0.2)"""
    loop_gain_db: float = 0.0
    """train with the loop gain drawn per episode uniformly in +-this many dB (lvgym.agents.wrappers.loop_dispersion;
    0: off)"""
    loop_delay_periods: int = 0
    """train with an extra loop delay drawn per episode from 0 to this many control periods (0: off)"""
    load_margin: float = 0.0
    """train with the q-alpha load charged above --load-margin-threshold of its limit, this many rad/s per
    unit of ratio (lvgym.agents.wrappers.loadmargin; 0: off)"""
    load_margin_threshold: float = 0.8
    """with --load-margin: the load's ratio to its limit above which it is charged"""
    command_rate_charge: float = arg(0.0, lo=0.0, hi=100.0)
    """train with the gimbal command's rate charged as protocol v2's flyability rule measures it, this many
    rad/s per unit of (rate / rate limit)^2 (lvgym.agents.wrappers.commandrate; 0: off)"""
    total_timesteps: int | None = arg(None, lo=1, hi=10**12)
    """env steps of the whole run, e.g. 2e6 (default: n_timesteps of the hyperparameter file)"""
    seed: int = arg(0, lo=0, hi=99_999)
    """seed of the networks and generators; env row i starts with training seed 100,000 + 10,000 seed + i
    (lvgym.benchmark.suites.TRAINING_SEEDS: disjoint from the validation and test seeds)"""
    n_envs: int | None = arg(None, lo=1, hi=4096)
    """rows of the batched VecEnv (default: the hyperparameter file's)"""
    hp: list[str] = arg(default_factory=list, nargs="*", extend=True)
    """hyperparameter overrides KEY=VALUE with dotted keys, e.g. algo.n_steps=128 policy.net_arch=[32,32]"""
    hyperparams: str | None = None
    """hyperparameter YAML file (default agents/training/hyperparams/<algo>.yaml)"""
    runs_dir: str = "runs"
    """folder of the run folders"""
    name: str | None = None
    """run name (default <algo>-<env>-<model>-s<seed>-<time>)"""
    checkpoint_freq: int = arg(200_000, lo=1, hi=10**12)
    """env steps between checkpoints"""
    checkpoint_interval_s: float = arg(60.0, lo=0.0, hi=86_400.0)
    """wall-clock seconds between checkpoints besides --checkpoint-freq (0: by steps only)"""
    keep_checkpoints: int = arg(3, lo=1, hi=10**6)
    """newest checkpoints kept (plus the best)"""
    eval_freq: int = arg(1_000_000, lo=0, hi=10**12)
    """env steps between validations (at checkpoints; 0: none); also at the end"""
    eval_episodes: int = arg(10, lo=1, hi=10**6)
    """validation seeds per condition of the eval suite"""
    eval_suite: str | None = arg(None, check=eval_suite_option)
    """protocol suite of the validation (default by env: DEFAULT_EVAL_SUITES; 'none': no validation)"""
    eval_mission_time_s: float | None = arg(None, lo=0.0, lo_open=True, hi=3600.0)
    """shorten validation episodes (smoke tests only)"""
    eval_select: str = arg("trained", choices=("trained", "all"))
    """conditions whose validation picks the best model: 'trained' (those of the training --model; all if
    the suite has none) or 'all' (every condition of the suite, which lets the other model into selection)"""
    torch_threads: int = arg(1, lo=1, hi=1024)
    """torch CPU threads (the env rows are one batched simulator on one core)"""
    max_wall_time_s: float | None = arg(None, lo=0.0, lo_open=True, hi=1e8, flag="--max-wall-time",
                                        metavar="SECONDS")
    """wall-time budget of this process [s]: then a checkpoint, a message and a normal exit (--resume
    continues; default: none)"""
    progress: bool = True
    """show a progress bar (stderr)"""
    progress_interval_s: float = arg(60.0, lo=0.0, hi=1e8)
    """seconds between progress lines on stdout: step, steps/s, elapsed, the latest validation score (0: none)"""
    verbose: int = arg(0, lo=0, hi=2)
    """SB3 verbosity (1: tables on stdout)"""
    resume: str | None = None
    """continue the run in this folder from its newest checkpoint"""


def _prog() -> str:
    return command_name(PROG)


def _again(run_dir: Path) -> str:
    """The command that continues the run in ``run_dir``."""
    prog = _prog()
    return f"{'python ' if prog.endswith('.py') else ''}{prog} --resume {run_dir}"


def parse_args(argv: list[str] | None = None) -> tuple[Args, set[str]]:
    """The arguments and the names given on the command line (every value checked; a bad one exits)."""
    return parse_given(Args, argv, PROG, __doc__, epilog=True)


def prepare(args: Args, given: set[str]) -> tuple[Args, dict[str, Any], Path, bool]:
    """The run's arguments, its ``config.yaml`` content, its folder and whether it resumes: every option
    checked, nothing written (:func:`create_run` writes). Raises ConfigError or SystemExit (one line)."""
    from lvgym.agents.training.config import build_config, load_config, parse_overrides
    from lvgym.agents.wrappers.commandrate import command_rate_options
    from lvgym.agents.wrappers.loadmargin import load_margin_options
    from lvgym.agents.wrappers.loop_dispersion import loop_dispersion_options
    from lvgym.agents.wrappers.residual import residual_options

    check_options(args)
    if args.resume:
        run_dir = Path(args.resume)
        cfg_path = run_dir / "config.yaml"
        if not cfg_path.is_file():
            raise SystemExit(f"{_prog()}: --resume {args.resume}: no config.yaml there (not a run folder)")
        extra = sorted(given - set(RESUME_OVERRIDABLE))
        if extra:
            flags = [("--max-wall-time" if e == "max_wall_time_s" else "--" + e.replace("_", "-")) for e in extra]
            raise SystemExit(f"{_prog()}: --resume takes the run's own config.yaml; only "
                             f"{list(RESUME_OVERRIDABLE)} may be given with it, not {flags}")
        from lvgym.vehicle.yamlfile import read_yaml

        config = read_yaml(cfg_path)[0]
        old = config["args"].get("recipe", "residual")
        config["args"]["recipe"] = LEGACY_RECIPES.get(old, old)
        stored = Args(**{**config["args"], **{k: getattr(args, k) for k in given if k != "resume"}, "resume": None})
        if "total_timesteps" in given:
            config["total_timesteps"] = int(args.total_timesteps)
        build_config(stored.algo, stored.env_id, config["hyperparams"], str(cfg_path))  # still valid?
        return stored, config, run_dir, True
    if args.suite:
        cond = suite_condition(args.suite, args.model)
        if "env_id" in given and args.env_id != cond.env_id:
            raise ConfigError("--env-id", args.env_id, f"{cond.env_id!r} (suite {args.suite!r} flies it) or no --env-id")
        args = replace(args, env_id=cond.env_id)
    args = replace(args, **recipe_options(args, given))          # the --recipe's options where none is given
    overrides = parse_overrides(args.hp)
    if args.n_envs is not None:
        overrides["n_envs"] = args.n_envs
    cfg = load_config(args.algo, args.env_id, overrides, args.hyperparams)
    training_seed(args.seed, 0, cfg.n_envs, _prog())
    family = is_family(args.suite)
    if family:
        from lvgym.agents.training.familytrain import row_split

        row_split(cfg.n_envs, args.family_vehicles)                  # a row for every vehicle
    env_kwargs = env_kwargs_of(args)
    suite = args.eval_suite or args.suite or DEFAULT_EVAL_SUITES.get(args.env_id, "none")
    where = args.suite or args.env_id.split('/')[-1].split('-')[0].lower()
    name = args.name or f"{args.algo}-{where}-{args.model}-s{args.seed}-{dt.datetime.now().strftime('%Y%m%d-%H%M%S')}"
    run_dir = Path(args.runs_dir) / name
    if (run_dir / "config.yaml").exists():
        raise SystemExit(f"{_prog()}: {run_dir} exists; continue it with --resume {run_dir} or choose another --name")
    config = {"name": name, "args": asdict(args), "algo": args.algo, "env_id": args.env_id, "env_kwargs": env_kwargs,
              "total_timesteps": int(args.total_timesteps or cfg.n_timesteps), "seed": args.seed,
              "eval_suite": suite, "eval_select": args.eval_select, "hyperparams": cfg.to_dict(),
              **({"residual": res} if (res := residual_options(args.residual, args.residual_scale)) else {}),
              **({"loop_dispersion": loop} if (loop := loop_dispersion_options(args.loop_gain_db,
                                                                                 args.loop_delay_periods)) else {}),
              **({"load_margin": lm} if (lm := load_margin_options(args.load_margin,
                                                                   args.load_margin_threshold)) else {}),
              **({"command_rate": cr} if (cr := command_rate_options(args.command_rate_charge)) else {}),
              **({"family_vehicles": int(args.family_vehicles)} if family else {}),
              "hyperparams_source": cfg.source,
              "created_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"), **provenance()}
    return args, config, run_dir, False


def _resume_note(run_dir: Path, state: dict[str, Any] | None, target: int) -> str:
    if state is None:
        return (f"{_prog()}: {run_dir} has no complete checkpoint to resume from (it was stopped before its first "
                "one): training starts again at step 0")
    step, wall = int(state["num_timesteps"]), state.get("train_wall_s")
    spent = f", after {wall / 60:.1f} min of training" if wall is not None else ""
    return (f"{_prog()}: resuming {run_dir} from checkpoint step_{step:012d}: step {step:,} of {target:,}, saved "
            f"{state.get('saved_utc', '?')}{spent}")


def train(argv: list[str] | None = None) -> Path:
    """Run (or resume) a training run; returns its folder. SIGTERM and SIGINT write a checkpoint and
    then exit with ``SystemExit(128 + signal)``; a spent ``--max-wall-time`` writes one and returns."""
    from lvgym.agents.training.callbacks import SignalStop

    t0 = time.monotonic()
    args, given = parse_args(argv)
    stop = SignalStop()
    with stop.installed():
        return _train(args, given, stop, t0)


def _train(args: Args, given: set[str], stop: Any, t0: float) -> Path:
    import torch

    from lvgym.agents.policies.algos import ALGOS, algo_class
    from lvgym.agents.policies.checkpoints import clean_incomplete, latest_checkpoint
    from lvgym.agents.policies.saved import policy_files
    from lvgym.agents.policies.sb3 import privileged_env_options
    from lvgym.agents.training.callbacks import CheckpointCallback, ValidationEvaluator, load_replay_buffer, load_rng
    from lvgym.agents.training.config import build_config
    from lvgym.agents.training.progress import ProgressBarCallback, ProgressLineCallback

    prog = _prog()
    try:                                             # everything checked before the run folder is made
        args, config, run_dir, resumed = prepare(args, given)
        cfg = build_config(config["algo"], config["env_id"], config["hyperparams"], str(run_dir / "config.yaml"))
        target = int(config["total_timesteps"])
        ckpt_dir = run_dir / "checkpoints"
        state: dict[str, Any] | None = None
        stem: Path | None = None
        if resumed:
            latest = latest_checkpoint(ckpt_dir)
            if latest is not None:
                stem, state = latest[0].with_suffix(""), latest[1]
        start = int(state["num_timesteps"]) if state else 0
        seed = training_seed(int(config["seed"]), start, cfg.n_envs, prog)
    except ConfigError as exc:
        fail(prog, exc)
    if config["algo"] == "ppo-fast":                 # the fast PPO on the native VectorEnv: its own loop
        from .fastrun import train_fast

        return train_fast(args, given, config, cfg, run_dir, resumed, stem, state, seed, stop, t0, prog)
    try:                                             # the env's keywords (--model, --wind, --env-kwargs, ...)
        vehicles = None
        if config.get("family_vehicles"):            # a family run: its train vehicles' files
            from lvgym.agents.training.familytrain import train_vehicle_files

            vehicles = [str(v) for v in train_vehicle_files(config["family_vehicles"])]
            config["vehicles"] = [Path(v).name for v in vehicles]
        venv = make_venv(config["env_id"], cfg.n_envs, seed, config["env_kwargs"], cfg.normalize, cfg.hyper.gamma,
                         policy_files(stem)[1] if stem is not None else None, config.get("residual"),
                         config.get("loop_dispersion"), vehicles,
                         {k: config[k] for k in ("load_margin", "command_rate") if config.get(k)})
    except (ConfigError, ValueError) as exc:
        fail(prog, f"{config['env_id']} option {exc}")
    try:
        if not resumed or "total_timesteps" in given:
            create_run(config, run_dir)
        if resumed:
            clean_incomplete(ckpt_dir)
            print(_resume_note(run_dir, state, target), file=sys.stderr)
        torch.set_num_threads(max(1, args.torch_threads))
        cls = algo_class(config["algo"])
        if stem is not None:
            model = cls.load(str(policy_files(stem)[0]), env=venv, device="cpu", custom_objects=cfg.schedules())
            load_rng(stem.with_name(stem.name + "_rng.pkl"))
            load_replay_buffer(model, stem)
            venv.seed(seed)                                      # fresh episodes for the new segment
        else:
            kw = cfg.sb3_kwargs()
            noise, sigma = kw.pop("action_noise_spec", ("none", 0.0))
            if noise != "none":
                import numpy as np
                from stable_baselines3.common.noise import NormalActionNoise, OrnsteinUhlenbeckActionNoise

                n = venv.action_space.shape[0]
                kw["action_noise"] = (NormalActionNoise if noise == "normal" else OrnsteinUhlenbeckActionNoise)(
                    np.zeros(n), sigma * np.ones(n))
            net = "MlpLstmPolicy" if config["algo"] == "recurrent-ppo" else "MlpPolicy"
            model = cls(net, venv, seed=int(config["seed"]), device="cpu", verbose=0, **kw)
        model.set_logger(make_logger(run_dir, start, args.verbose))
        with open(run_dir / "segments.jsonl", "a", encoding="utf-8") as f:
            f.write(json.dumps({"start_step": start, "env_seed": seed, "target": target, "resumed": resumed,
                                "started_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
                                "pid": os.getpid(), **provenance()}) + "\n")
        suite = config.get("eval_suite", "none")
        evaluator = None
        if suite != "none" and args.eval_freq > 0:
            # a teacher (privileged observations, e.g. fault_info) is validated seeing what it was trained on
            over = {**({"mission_time_s": args.eval_mission_time_s} if args.eval_mission_time_s else {}),
                    **privileged_env_options(config["env_kwargs"])} or None
            # runs made before eval_select existed selected on every condition
            select = config.get("eval_select", "all")
            evaluator = ValidationEvaluator(suite, args.eval_episodes, over,
                                            select_on=config["env_kwargs"].get("model") if select == "trained" else None)
        meta = {"algo": ALGOS[config["algo"]], "env_id": config["env_id"], "env_kwargs": config["env_kwargs"],
                "run": config["name"], "seed": config["seed"], "target_timesteps": target,
                "git_commit": config.get("git_commit"), "lvgym_version": config.get("lvgym_version"),
                **({"residual": config["residual"]} if config.get("residual") else {})}
        deadline = None if args.max_wall_time_s is None else t0 + float(args.max_wall_time_s)
        checkpoint = CheckpointCallback(run_dir, args.checkpoint_freq, meta, venv if hasattr(venv, "obs_rms") else None,
                                        evaluator, args.eval_freq, args.keep_checkpoints, state, verbose=args.verbose,
                                        interval_s=args.checkpoint_interval_s, stop=stop, deadline=deadline)
        lines = ProgressLineCallback(args.progress_interval_s, target, checkpoint, prog)
        remaining = target - start
        t_learn = time.perf_counter()
        with stop.armed():                           # from here a signal checkpoints first
            if remaining > 0:
                model.learn(total_timesteps=remaining, callback=[checkpoint, ProgressBarCallback(args.progress), lines],
                            reset_num_timesteps=not resumed or stem is None, log_interval=1, progress_bar=False)
            elif not (run_dir / "final_model.json").is_file():
                checkpoint.init_callback(model)
                checkpoint.on_training_end()
        wall = time.perf_counter() - t_learn
        done = int(model.num_timesteps) - start
        print(f"{run_dir}: {model.num_timesteps} / {target} steps ({done / max(wall, 1e-9):.0f} steps/s this segment)",
              file=sys.stderr)
        if evaluator is not None:
            evaluator.close()
    finally:
        venv.close()
    if stop.signum is not None or checkpoint.out_of_time:
        last = latest_checkpoint(ckpt_dir)
        where = f"checkpoint step_{int(last[1]['num_timesteps']):012d}" if last else "no checkpoint"
        if stop.signum is not None:
            why = f"stopped by {stop.name}"
        else:                                        # ended as a finished run: validated, final and best models
            why = f"the wall-time budget of {args.max_wall_time_s:g} s is spent: stopped"
            made = [n for n in ("final_model", "best_model") if (run_dir / f"{n}.json").is_file()]
            where += (", validated" if evaluator is not None else "") + "".join(f", {n}" for n in made)
        print(f"{prog}: {why} at step {model.num_timesteps:,} of {target:,}; {where} written; continue with "
              f"{_again(run_dir)}", file=sys.stderr)
        if stop.signum is not None:
            raise SystemExit(128 + stop.signum)
    return run_dir


def _recipe(argv: list[str]) -> tuple[str, list[str]]:
    """The ``--recipe`` named on ``argv`` (``residual`` when none) and ``argv`` without it."""
    for i, word in enumerate(argv):
        if word == "--":
            break
        if word == "--recipe" and i + 1 < len(argv):
            return argv[i + 1], argv[:i] + argv[i + 2:]
        if word.startswith("--recipe="):
            return word.partition("=")[2], argv[:i] + argv[i + 1:]
    return "residual", argv


def main(argv: list[str] | None = None) -> None:
    """``lvgym train`` / ``python train.py``: run (or resume) a training run; ``--recipe teacher-student``: the
    teacher-student recipe (:mod:`lvgym.agents.training.teacher_student`) with the rest of the command line."""
    argv = list(sys.argv[1:] if argv is None else argv)
    recipe, rest = _recipe(argv)
    if recipe == "teacher-student":
        from lvgym.commandline import running_as

        from .teacher_student import main as teacher_student

        with running_as(f"{_prog()} --recipe teacher-student"):
            teacher_student(rest)
        return
    exit_on_sigterm()                                # SIGTERM before training: clean up and exit
    train(argv)


if __name__ == "__main__":
    main()
