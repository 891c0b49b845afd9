"""Train a TVC policy with stable-baselines3 (PPO, SAC, TD3; sb3-contrib's RecurrentPPO) on the batched lvgym envs.

    python train.py                     # PPO on SmileAscent-v1 with its recipe (RECIPES): residual on lqg, history 4
    python train.py --residual none --history 0 --wind protocol      # plain PPO on v1's flight observation
    python train.py --env-id lvgym/SmileAscent-v0                    # v0: the ideal state, no recipe
    python train.py --algo sac --model rigid --wind random --randomize all --total-timesteps 2e6 --name sac-rigid
    python train.py --hp algo.n_steps=128 policy.net_arch=[32,32] --env-kwargs mission_time_s=20
    python train.py --resume runs/sac-rigid                    # continue a stopped or killed run
    python train.py --algo recurrent-ppo --history 0           # an LSTM policy, residual on lqg
    python train.py --residual gs-pid-flex --residual-scale 0.2

A run lives in ``runs/<name>/``: ``config.yaml`` (every argument, the resolved hyperparameters and env
keywords, lvgym version, git commit), ``segments.jsonl`` (one line per start or resume), ``tb/``
(TensorBoard: ``tensorboard --logdir runs``), ``progress_<step>.csv``, ``checkpoints/`` (model,
VecNormalize statistics, generator states, replay buffer; see ``agents/callbacks.py``),
``evaluations.json`` (validation on the benchmark protocol's validation seeds), ``best_model.*`` and
``final_model.*`` (load with ``lvgym.agents.policy.SB3Policy`` or pass the ``.zip`` to ``evaluate.py``).
``--resume`` restarts from the newest complete checkpoint with the run's own configuration, the same
target step count, the normalisation statistics and the step counter (``reset_num_timesteps=False``),
and says what it resumed from (or that there was no checkpoint yet).

Nothing is lost to a kill but the last minute: a checkpoint is written every ``--checkpoint-freq`` env
steps and every ``--checkpoint-interval-s`` seconds of wall time (60 s), and on SIGTERM or SIGINT (Ctrl-C)
the run writes one at the next env step and exits (status 128 + the signal; a second signal stops at
once). Every option is checked before the run folder is made: a bad value is a one-line error and
leaves nothing behind.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import sys
import time
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import yaml

from lvgym.agents.runfolder import create_run, make_logger, provenance
from lvgym.cli import fail, one_line_errors, option_number
from lvgym.errors import ConfigError
from lvgym.parallel import exit_on_sigterm

DEFAULT_EVAL_SUITES = {"lvgym/SmileAscent-v0": "smile-windy", "lvgym/SlenderAscent-v0": "slender-ld30",
                       "lvgym/SmileAscent-v1": "smile-v1", "lvgym/SlenderAscent-v1": "slender-v1"}
RESUME_OVERRIDABLE = ("resume", "progress", "torch_threads", "verbose", "total_timesteps", "checkpoint_interval_s")
PROG = "train.py"

#: what a run on an env id flies when the option is not on the command line (an option given wins, so
#: ``--residual none --history 0`` trains a plain PPO): the recipe of the policy shipped for the id
#: (docs/training.md, "The policy shipped for protocol v1"): residual on ``lqg`` with 5 % of the gimbal,
#: a 4-sample history, Dryden turbulence without the gust (trained with the gust it scored worse on the
#: suite's gusts: IQM 0.629 against 0.612 rad non-rigid, three seeds each)
RECIPES: dict[str, dict[str, Any]] = {
    "lvgym/SmileAscent-v1": {"residual": "lqg", "residual_scale": 0.05, "history": 4, "wind": "turbulence"},
}


@dataclass
class Args:
    """Command-line arguments (``python train.py --help``)."""

    env_id: str = "lvgym/SmileAscent-v1"
    """registered lvgym env id (the options an id's recipe sets, RECIPES, default to it)"""
    model: str = "nonrigid"
    """flight model: rigid, slosh, flex or nonrigid"""
    wind: str = "protocol"
    """wind tier (lvgym.envs.WIND_TIERS), or protocol: the env's protocol (turbulence for v0 ids; the wind of
    the id's v1 suite for v1 ids, turbulence_gust for SmileAscent-v1)"""
    randomize: list[str] = field(default_factory=lambda: ["protocol"])
    """names drawn per episode (lvgym.envs.RANDOMIZE), 'all', 'none' or 'protocol': the env's protocol
    (wind thrust_misalignment for v0 ids; every dispersion of protocol v1, V1_DISPERSIONS, for v1 ids)"""
    observation: str = "env"
    """state (ideal), sensors (IMU), flight (v1's flight computer) or env: the env's own (state for v0
    ids, flight for v1 ids)"""
    env_kwargs: list[str] = field(default_factory=list)
    """further env keywords KEY=VALUE (values in YAML), e.g. mission_time_s=20"""
    history: int = 0
    """observation history: the last K samples and actions stacked (lvgym.envs.history; 0: off)"""
    algo: str = "ppo"
    """ppo, sac, td3 or recurrent-ppo (sb3-contrib's RecurrentPPO with MlpLstmPolicy)"""
    residual: str | None = None
    """fly residual on this registered baseline, e.g. gs-pid-flex (lvgym.agents.residual; default: not residual)"""
    residual_scale: float = 0.2
    """with --residual: gimbal units per unit of learned action, in (0, 2]"""
    loop_gain_db: float = 0.0
    """train with the loop gain drawn per episode uniformly in +-this many dB (lvgym.agents.loop_dispersion; 0: off)"""
    loop_delay_periods: int = 0
    """train with an extra loop delay drawn per episode from 0 to this many control periods (0: off)"""
    total_timesteps: int | None = None
    """env steps of the whole run (default: n_timesteps of the hyperparameter file)"""
    seed: int = 0
    """seed of the networks and generators; env row i starts with seed + i (validation seeds)"""
    n_envs: int | None = None
    """rows of the batched VecEnv (default: the hyperparameter file's)"""
    hp: list[str] = field(default_factory=list)
    """hyperparameter overrides KEY=VALUE with dotted keys, e.g. algo.n_steps=128 policy.net_arch=[32,32]"""
    hyperparams: str | None = None
    """hyperparameter YAML file (default agents/hyperparams/<algo>.yaml)"""
    runs_dir: str = "runs"
    """folder of the run folders"""
    name: str | None = None
    """run name (default <algo>-<env>-<model>-s<seed>-<time>)"""
    checkpoint_freq: int = 200_000
    """env steps between checkpoints"""
    checkpoint_interval_s: float = 60.0
    """wall-clock seconds between checkpoints besides --checkpoint-freq (0: by steps only)"""
    keep_checkpoints: int = 3
    """newest checkpoints kept (plus the best)"""
    eval_freq: int = 1_000_000
    """env steps between validations (at checkpoints; 0: none); also at the end"""
    eval_episodes: int = 10
    """validation seeds per condition of the eval suite"""
    eval_suite: str | None = None
    """protocol suite of the validation (default by env: DEFAULT_EVAL_SUITES; 'none': no validation)"""
    eval_mission_time_s: float | None = None
    """shorten validation episodes (smoke tests only)"""
    eval_select: str = "trained"
    """conditions whose validation picks the best model: 'trained' (those of the training --model; all if
    the suite has none) or 'all' (every condition of the suite, which lets the other model into selection)"""
    torch_threads: int = 1
    """torch CPU threads (the env rows are one batched simulator on one core)"""
    progress: bool = True
    """show a progress bar"""
    verbose: int = 0
    """SB3 verbosity (1: tables on stdout)"""
    resume: str | None = None
    """continue the run in this folder from its newest checkpoint"""


def _number(text: str) -> int:
    value = float(text)
    if value != int(value):
        raise argparse.ArgumentTypeError(f"{text!r}: a whole number of steps")
    return int(value)


def build_parser(suppress: bool = False) -> argparse.ArgumentParser:
    """The argparse parser of :class:`Args` (``suppress``: omit the arguments not given)."""
    d = Args()
    p = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                argument_default=argparse.SUPPRESS if suppress else None)
    one_line_errors(p)
    doc = {f.name: "" for f in fields(Args)}
    import ast
    import inspect

    body = ast.parse(inspect.getsource(Args)).body[0].body
    for a, b in zip(body, body[1:]):
        if isinstance(a, ast.AnnAssign) and isinstance(b, ast.Expr) and isinstance(b.value, ast.Constant):
            doc[a.target.id] = str(b.value.value)
    choices = _choices()
    for f in fields(Args):
        flag, default = "--" + f.name.replace("_", "-"), getattr(d, f.name)
        kw: dict[str, Any] = {"help": f"{doc[f.name]} (default: {default})"}
        if not suppress:
            kw["default"] = default
        if f.name == "progress":
            p.add_argument("--no-progress", dest="progress", action="store_false", help="hide the progress bar")
            continue
        if isinstance(default, list):                  # --hp, --env-kwargs: a repeated flag adds to the list;
            kw["nargs"] = "*"                          # --randomize (a default of its own) is replaced
            if not default:
                kw["action"] = "extend"
        elif f.name in ("total_timesteps", "checkpoint_freq", "eval_freq"):
            kw["type"] = _number
        elif f.name in ("seed", "n_envs", "history", "keep_checkpoints", "eval_episodes", "torch_threads", "verbose",
                        "loop_delay_periods"):
            kw["type"] = int
        elif f.name in ("eval_mission_time_s", "checkpoint_interval_s", "residual_scale", "loop_gain_db"):
            kw["type"] = float
        if f.name == "algo":
            from lvgym.agents.config import ALGOS
            kw["choices"] = tuple(ALGOS)
        if f.name in choices:
            kw["choices"] = choices[f.name]
        if f.name == "eval_select":
            kw["choices"] = ("trained", "all")
        p.add_argument(flag, **kw)
    return p


def _choices() -> dict[str, tuple[str, ...]]:
    """The allowed values of the options that name things (the lists of the envs and the simulator)."""
    import lvgym
    from lvgym.envs.spec import OBSERVATIONS, WIND_TIERS
    from lvgym.simulator import MODELS

    return {"env_id": tuple(lvgym.ENV_IDS), "model": tuple(MODELS), "wind": ("protocol", *WIND_TIERS),
            "observation": ("env", *OBSERVATIONS)}


def parse_args(argv: list[str] | None = None) -> tuple[Args, set[str]]:
    """The arguments and the names given on the command line."""
    given = set(vars(build_parser(suppress=True).parse_args(argv)))
    return Args(**vars(build_parser().parse_args(argv))), given


# ------------------------------------------------------------------------------------------ helpers
def protocol_training(env_id: str) -> tuple[str, list[str]]:
    """The wind and the randomisation that ``--wind protocol`` and ``--randomize protocol`` mean for
    ``env_id``: for a v1 id those of its v1 suite (:data:`DEFAULT_EVAL_SUITES`: the distribution it is
    validated and tested on, with training seeds), v0's training defaults otherwise (turbulence; wind and
    thrust misalignment drawn)."""
    suite = DEFAULT_EVAL_SUITES.get(env_id)
    if env_id.endswith("-v1") and suite is not None:
        from lvgym.benchmark.suites import get_suite
        condition = get_suite(suite).conditions[0]
        return condition.wind, list(condition.randomize)
    return "turbulence", ["wind", "thrust_misalignment"]


def env_kwargs_of(args: Args) -> dict[str, Any]:
    """The env keywords of a run: model, wind, randomisation, observation and the ``--env-kwargs``."""
    r: Any = list(args.randomize)
    wind, protocol_r = protocol_training(args.env_id)
    if r == ["protocol"]:
        r = protocol_r
    elif r in (["all"], ["true"], ["True"]):
        r = True
    elif r in ([], ["none"], ["false"], ["False"]):
        r = False
    out: dict[str, Any] = {"model": args.model, "wind": wind if args.wind == "protocol" else args.wind, "randomize": r}
    out.update({} if args.observation == "env" else {"observation": args.observation})
    out.update({"history": int(args.history)} if args.history else {})   # when on only: old runs unchanged
    for item in args.env_kwargs:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError("--env-kwargs", item, "KEY=VALUE, e.g. mission_time_s=20")
        try:
            out[key.strip()] = yaml.safe_load(text)
        except yaml.YAMLError:
            raise ConfigError("--env-kwargs", item, "KEY=VALUE with a YAML value, e.g. rate_weights=[0,1,1]") from None
    return out


def check_options(args: Args) -> None:
    """The numbers and names of the command line that nothing else checks (ConfigError naming the option)."""
    from lvgym.envs.spec import RANDOMIZE

    option_number("--total-timesteps", args.total_timesteps, 1, 10**12, integer=True)
    option_number("--checkpoint-freq", args.checkpoint_freq, 1, 10**12, integer=True)
    option_number("--checkpoint-interval-s", args.checkpoint_interval_s, 0.0, 86_400.0)
    option_number("--keep-checkpoints", args.keep_checkpoints, 1, 10**6, integer=True)
    option_number("--eval-freq", args.eval_freq, 0, 10**12, integer=True)
    option_number("--eval-episodes", args.eval_episodes, 1, 10**6, integer=True)
    option_number("--eval-mission-time-s", args.eval_mission_time_s, 0.0, 3600.0, lo_open=True)
    option_number("--torch-threads", args.torch_threads, 1, 1024, integer=True)
    option_number("--verbose", args.verbose, 0, 2, integer=True)
    option_number("--n-envs", args.n_envs, 1, 4096, integer=True)
    from lvgym.agents.residual import residual_options

    option_number("--history", args.history, 0, 64, integer=True)
    residual_options(args.residual, args.residual_scale)
    from lvgym.agents.loop_dispersion import loop_dispersion_options

    loop_dispersion_options(args.loop_gain_db, args.loop_delay_periods)
    known = set(RANDOMIZE) | {"all", "none", "protocol", "true", "false", "True", "False"}
    for r in args.randomize:
        if r not in known:
            raise ConfigError("--randomize", r, f"names of {list(RANDOMIZE)}, or 'all', 'none' or 'protocol'")
    if "protocol" in args.randomize and len(args.randomize) > 1:
        raise ConfigError("--randomize", " ".join(args.randomize), "'protocol' alone, or names without it")
    if args.eval_suite not in (None, "none"):
        from lvgym.benchmark.suites import SUITES

        if args.eval_suite not in SUITES:
            raise ConfigError("--eval-suite", args.eval_suite, f"one of {sorted(SUITES)} or 'none'")


def training_seed(seed: int, step: int, n_envs: int) -> int:
    """Seed of env row 0 for a run segment starting at ``step`` (rows get ``+ i``): ``seed`` at the
    start, a fresh draw on resume; always a validation seed (the test seeds stay unseen)."""
    from lvgym.benchmark.suites import TEST_SEED0

    if step == 0:
        if not 0 <= seed <= TEST_SEED0 - n_envs:
            raise SystemExit(f"train.py: --seed {seed} with {n_envs} envs: rows seed .. seed + n_envs - 1 must "
                             f"be validation seeds (0 .. {TEST_SEED0 - 1}); the test seeds are for reported numbers")
        return seed
    import numpy as np

    return int(np.random.SeedSequence([seed, step]).generate_state(1)[0]) % (TEST_SEED0 - n_envs)


def make_venv(env_id: str, n_envs: int, seed: int, env_kwargs: dict[str, Any], norm: Any, gamma: float,
              stats: Path | None, residual: dict[str, Any] | None = None, loop: dict[str, Any] | None = None) -> Any:
    """Batched SB3 VecEnv (-> :class:`lvgym.agents.loop_dispersion.LoopDispersedVecEnv` with ``loop`` ->
    :class:`lvgym.agents.residual.ResidualVecEnv` with ``residual``) -> EnvClock (the env's wall time,
    :mod:`lvgym.agents.timing`) -> VecMonitor (episode returns) -> VecNormalize (new, or loaded from ``stats``)."""
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    import lvgym  # noqa: F401
    from lvgym.envs import make_sb3_vec_env

    from lvgym.agents.loop_dispersion import loop_venv
    from lvgym.agents.residual import residual_venv
    from lvgym.agents.timing import EnvClock

    base = loop_venv(make_sb3_vec_env(env_id, num_envs=n_envs, seed=seed, **env_kwargs), loop, seed)
    venv = VecMonitor(EnvClock(residual_venv(base, residual)))
    if stats is not None and stats.is_file():
        return VecNormalize.load(str(stats), venv)
    if norm.norm_obs or norm.norm_reward:
        return VecNormalize(venv, norm_obs=norm.norm_obs, norm_reward=norm.norm_reward, clip_obs=norm.clip_obs,
                            clip_reward=norm.clip_reward, epsilon=norm.epsilon, gamma=gamma)
    return venv


# ------------------------------------------------------------------------------------------ main
def prepare(args: Args, given: set[str]) -> tuple[Args, dict[str, Any], Path, bool]:
    """The run's arguments, its ``config.yaml`` content, its folder and whether it resumes: every option
    checked, nothing written (:func:`create_run` writes). Raises ConfigError or SystemExit (one line)."""
    from lvgym.agents.config import build_config, load_config, parse_overrides
    from lvgym.agents.loop_dispersion import loop_dispersion_options
    from lvgym.agents.residual import residual_options

    check_options(args)
    if args.resume:
        run_dir = Path(args.resume)
        cfg_path = run_dir / "config.yaml"
        if not cfg_path.is_file():
            raise SystemExit(f"{PROG}: --resume {args.resume}: no config.yaml there (not a run folder)")
        extra = sorted(given - set(RESUME_OVERRIDABLE))
        if extra:
            raise SystemExit(f"{PROG}: --resume takes the run's own config.yaml; only {list(RESUME_OVERRIDABLE)} "
                             f"may be given with it, not {['--' + e.replace('_', '-') for e in extra]}")
        from lvgym.vehicle.yamlfile import read_yaml

        config = read_yaml(cfg_path)[0]
        stored = Args(**{**config["args"], **{k: getattr(args, k) for k in given if k != "resume"}, "resume": None})
        if "total_timesteps" in given:
            config["total_timesteps"] = int(args.total_timesteps)
        build_config(stored.algo, stored.env_id, config["hyperparams"], str(cfg_path))  # still valid?
        return stored, config, run_dir, True
    recipe = {k: v for k, v in RECIPES.get(args.env_id, {}).items() if k not in given}
    args = replace(args, **recipe)
    overrides = parse_overrides(args.hp)
    if args.n_envs is not None:
        overrides["n_envs"] = args.n_envs
    cfg = load_config(args.algo, args.env_id, overrides, args.hyperparams)
    training_seed(args.seed, 0, cfg.n_envs)
    env_kwargs = env_kwargs_of(args)
    suite = args.eval_suite or DEFAULT_EVAL_SUITES.get(args.env_id, "none")
    name = args.name or (f"{args.algo}-{args.env_id.split('/')[-1].split('-')[0].lower()}-{args.model}-s{args.seed}-"
                         f"{dt.datetime.now().strftime('%Y%m%d-%H%M%S')}")
    run_dir = Path(args.runs_dir) / name
    if (run_dir / "config.yaml").exists():
        raise SystemExit(f"{PROG}: {run_dir} exists; continue it with --resume {run_dir} or choose another --name")
    config = {"name": name, "args": asdict(args), "algo": args.algo, "env_id": args.env_id, "env_kwargs": env_kwargs,
              "total_timesteps": int(args.total_timesteps or cfg.n_timesteps), "seed": args.seed,
              "eval_suite": suite, "eval_select": args.eval_select, "hyperparams": cfg.to_dict(),
              **({"residual": res} if (res := residual_options(args.residual, args.residual_scale)) else {}),
              **({"loop_dispersion": loop} if (loop := loop_dispersion_options(args.loop_gain_db,
                                                                                 args.loop_delay_periods)) else {}),
              "hyperparams_source": cfg.source,
              "created_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"), **provenance()}
    return args, config, run_dir, False


def _resume_note(run_dir: Path, state: dict[str, Any] | None, target: int) -> str:
    if state is None:
        return (f"{PROG}: {run_dir} has no complete checkpoint to resume from (it was stopped before its first "
                "one): training starts again at step 0")
    step, wall = int(state["num_timesteps"]), state.get("train_wall_s")
    spent = f", after {wall / 60:.1f} min of training" if wall is not None else ""
    return (f"{PROG}: resuming {run_dir} from checkpoint step_{step:012d}: step {step:,} of {target:,}, saved "
            f"{state.get('saved_utc', '?')}{spent}")


def train(argv: list[str] | None = None) -> Path:
    """Run (or resume) a training run; returns its folder. SIGTERM and SIGINT write a checkpoint and
    then exit with ``SystemExit(128 + signal)``."""
    from lvgym.agents.callbacks import SignalStop

    args, given = parse_args(argv)
    stop = SignalStop()
    with stop.installed():
        return _train(args, given, stop)


def _train(args: Args, given: set[str], stop: Any) -> Path:
    import torch

    from lvgym.agents.callbacks import (CheckpointCallback, ProgressBarCallback, ValidationEvaluator, clean_incomplete,
                                  latest_checkpoint, load_replay_buffer, load_rng)
    from lvgym.agents.config import ALGOS, algo_class, build_config
    from lvgym.agents.policy import policy_files

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
        seed = training_seed(int(config["seed"]), start, cfg.n_envs)
    except ConfigError as exc:
        fail(PROG, exc)
    try:                                             # the env's keywords (--model, --wind, --env-kwargs, ...)
        venv = make_venv(config["env_id"], cfg.n_envs, seed, config["env_kwargs"], cfg.normalize, cfg.hyper.gamma,
                         policy_files(stem)[1] if stem is not None else None, config.get("residual"),
                         config.get("loop_dispersion"))
    except (ConfigError, ValueError) as exc:
        fail(PROG, f"{config['env_id']} option {exc}")
    try:
        if not resumed or "total_timesteps" in given:
            create_run(config, run_dir)
        if resumed:
            clean_incomplete(ckpt_dir)
            print(_resume_note(run_dir, state, target), file=sys.stderr)
        torch.set_num_threads(max(1, args.torch_threads))
        cls = algo_class(config["algo"])
        if stem is not None:
            model = cls.load(str(policy_files(stem)[0]), env=venv, device="cpu")
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
            over = {"mission_time_s": args.eval_mission_time_s} if args.eval_mission_time_s else None
            # runs made before eval_select existed selected on every condition
            select = config.get("eval_select", "all")
            evaluator = ValidationEvaluator(suite, args.eval_episodes, over,
                                            select_on=config["env_kwargs"].get("model") if select == "trained" else None)
        meta = {"algo": ALGOS[config["algo"]], "env_id": config["env_id"], "env_kwargs": config["env_kwargs"],
                "run": config["name"], "seed": config["seed"], "target_timesteps": target,
                "git_commit": config.get("git_commit"), "lvgym_version": config.get("lvgym_version"),
                **({"residual": config["residual"]} if config.get("residual") else {})}
        checkpoint = CheckpointCallback(run_dir, args.checkpoint_freq, meta, venv if hasattr(venv, "obs_rms") else None,
                                        evaluator, args.eval_freq, args.keep_checkpoints, state, verbose=args.verbose,
                                        interval_s=args.checkpoint_interval_s, stop=stop)
        remaining = target - start
        t0 = time.perf_counter()
        with stop.armed():                           # from here a signal checkpoints first
            if remaining > 0:
                model.learn(total_timesteps=remaining, callback=[checkpoint, ProgressBarCallback(args.progress)],
                            reset_num_timesteps=not resumed or stem is None, log_interval=1, progress_bar=False)
            elif not (run_dir / "final_model.json").is_file():
                checkpoint.init_callback(model)
                checkpoint.on_training_end()
        wall = time.perf_counter() - t0
        done = int(model.num_timesteps) - start
        print(f"{run_dir}: {model.num_timesteps} / {target} steps ({done / max(wall, 1e-9):.0f} steps/s this segment)",
              file=sys.stderr)
        if evaluator is not None:
            evaluator.close()
    finally:
        venv.close()
    if stop.signum is not None:
        last = latest_checkpoint(ckpt_dir)
        where = f"checkpoint step_{int(last[1]['num_timesteps']):012d}" if last else "no checkpoint"
        print(f"{PROG}: stopped by {stop.name} at step {model.num_timesteps:,}; {where} written; continue with "
              f"python train.py --resume {run_dir}", file=sys.stderr)
        raise SystemExit(128 + stop.signum)
    return run_dir


def main(argv: list[str] | None = None) -> None:
    exit_on_sigterm()                                # SIGTERM before training: clean up and exit
    train(argv)


if __name__ == "__main__":
    main()
