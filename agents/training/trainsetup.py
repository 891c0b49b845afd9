"""What a training run is made of, besides its command line (:mod:`lvgym.agents.training.train`): the recipes of the
env ids, the protocol's wind and randomisation, the env keywords, the checks no field declares, the
training seeds and the vectorised env.

Nothing here imports stable-baselines3 at import time (:func:`make_venv` does).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from lvgym.errors import ConfigError

__all__ = ["DEFAULT_EVAL_SUITES", "RECIPES", "SB3_RECIPES", "check_options", "env_kwargs_of", "eval_suite_option",
           "is_family", "make_venv", "protocol_training", "recipe_options", "suite_condition", "suite_option",
           "training_seed"]

DEFAULT_EVAL_SUITES = {"lvgym/SmileAscent-v0": "smile-windy", "lvgym/SlenderAscent-v0": "slender-ld30",
                       "lvgym/SmileAscent-v1": "smile-v1", "lvgym/SlenderAscent-v1": "slender-v1"}

#: what a run of ``--recipe residual`` (the default) on an env id flies where the option is not on the command line
#: (an option given wins): the recipe of the policy shipped for the id (docs/training.md, "The policy shipped for
#: protocol v1"): residual on ``lqg`` with 5 % of the gimbal, a 4-sample history, Dryden turbulence without the
#: gust (trained with the gust it scored worse on the suite's gusts: IQM 0.629 against 0.612 rad non-rigid, three
#: seeds each). An id without an entry trains plain
RECIPES: dict[str, dict[str, Any]] = {
    "lvgym/SmileAscent-v1": {"residual": "lqg", "residual_scale": 0.05, "history": 4, "wind": "turbulence"},
}
#: the presets of ``lvgym train --recipe`` that train with stable-baselines3 (the third, ``teacher-student``, is
#: :mod:`lvgym.agents.training.teacher_student`, with its own options): ``plain`` learns from scratch, with no
#: residual baseline, no history and no teacher, in the protocol's (or the suite's) wind; ``residual`` flies the
#: env id's :data:`RECIPES`
SB3_RECIPES = ("plain", "residual")


def recipe_options(args: Any, given: set[str]) -> dict[str, Any]:
    """The options the run's ``--recipe`` sets (``args``: :class:`lvgym.agents.training.train.Args`), those given on
    the command line (``given``) left as they are: nothing for ``plain`` (the options' own defaults: no residual,
    no history, the protocol's wind), which refuses a ``--residual`` baseline; the env id's :data:`RECIPES` for
    ``residual``, without its wind on a ``--suite`` (the suite's wind is the suite's) and without its residual
    for ``--algo ppo-fast`` (which wraps no baseline). The recipe is one of
    :data:`SB3_RECIPES` (:func:`check_options`)."""
    if args.recipe == "plain":
        if args.residual not in (None, "none"):
            raise ConfigError("--residual", args.residual, "none with --recipe plain (it learns from scratch; "
                                                           "--recipe residual flies a baseline)")
        return {}
    return {k: v for k, v in RECIPES.get(args.env_id, {}).items()
            if k not in given and not (args.suite and k == "wind")
            and not (args.algo == "ppo-fast" and k in ("residual", "residual_scale"))}   # ppo-fast flies no residual


def suite_condition(suite: str, model: str) -> Any:
    """The condition of suite ``suite`` a run on ``--suite`` trains on: its condition of flight model
    ``model`` (its env id, wind, dispersions and options; the run's rows still reset with training
    seeds). For a family suite, whose conditions are its test vehicles, the condition without its
    ``vehicle``: the run's rows fly the family's train vehicles (:mod:`lvgym.agents.training.familytrain`)."""
    from lvgym.benchmark.suites import SUITES_FAMILY, condition, get_suite

    s = get_suite(suite)
    cond = condition(s.name, model)
    if s.name in SUITES_FAMILY:
        from dataclasses import replace

        cond = replace(cond, options=tuple((k, v) for k, v in cond.options if k != "vehicle"))
    return cond


def is_family(suite: str | None) -> bool:
    """Whether ``suite`` is one of the launcher family's suites (its runs fly the train vehicles)."""
    from lvgym.benchmark.suites import SUITES_FAMILY

    return bool(suite) and suite in SUITES_FAMILY


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


def env_kwargs_of(args: Any) -> dict[str, Any]:
    """The env keywords of a run (``args``: :class:`lvgym.agents.training.train.Args`): model, wind, randomisation,
    observation and the ``--env-kwargs``. With ``--suite``, ``--wind protocol`` and ``--randomize protocol``
    mean the suite condition's, whose further options (faults, a mission time, a vehicle) come first and
    ``--env-kwargs`` after them; a suite that charges flyability (v2 on) trains on the score reward
    (``reward_kind="score_v2"``, :mod:`lvgym.envs.scorereward`; ``--env-kwargs reward_kind=weighted`` turns it off)."""
    r: Any = list(args.randomize)
    wind, protocol_r = protocol_training(args.env_id)
    suite_options: dict[str, Any] = {}
    if getattr(args, "suite", None):
        cond = suite_condition(args.suite, args.model)
        wind, protocol_r = cond.wind, list(cond.randomize)
        suite_options = {k: v for k, v in cond.options}
        from lvgym.benchmark.flyability import applies
        from lvgym.benchmark.suites import get_suite

        if applies(get_suite(args.suite).version):
            suite_options["reward_kind"] = "score_v2"
    if r == ["protocol"]:
        r = protocol_r
    elif r in (["all"], ["true"], ["True"]):
        r = True
    elif r in ([], ["none"], ["false"], ["False"]):
        r = False
    out: dict[str, Any] = {"model": args.model, "wind": wind if args.wind == "protocol" else args.wind, "randomize": r,
                           **suite_options}
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


def check_options(args: Any) -> None:
    """The values of ``args`` (:class:`lvgym.agents.training.train.Args`) checked: the ranges and choices its fields
    declare (as on the command line, for Args built in Python) and what they cannot say (the residual,
    the loop dispersion, the randomisation's names); a ConfigError names the option."""
    from lvgym.agents.wrappers.commandrate import command_rate_options
    from lvgym.agents.wrappers.loadmargin import load_margin_options
    from lvgym.agents.wrappers.loop_dispersion import loop_dispersion_options
    from lvgym.agents.wrappers.residual import residual_options
    from lvgym.commandline import check_fields
    from lvgym.envs.spec import RANDOMIZE

    check_fields(args)
    if getattr(args, "recipe", "residual") not in SB3_RECIPES:
        raise ConfigError("--recipe", args.recipe, f"one of {list(SB3_RECIPES)} for a stable-baselines3 run (lvgym "
                                                   "train --recipe teacher-student takes its own options, not these)")
    residual_options(args.residual, args.residual_scale)
    loop_dispersion_options(args.loop_gain_db, args.loop_delay_periods)
    load_margin_options(args.load_margin, args.load_margin_threshold)
    command_rate_options(args.command_rate_charge)
    known = set(RANDOMIZE) | {"all", "none", "protocol", "true", "false", "True", "False"}
    for r in args.randomize:
        if r not in known:
            raise ConfigError("--randomize", r, f"names of {list(RANDOMIZE)}, or 'all', 'none' or 'protocol'")
    if "protocol" in args.randomize and len(args.randomize) > 1:
        raise ConfigError("--randomize", " ".join(args.randomize), "'protocol' alone, or names without it")


def eval_suite_option(option: str, value: str) -> str:
    """``--eval-suite``: a suite of the protocol or ``none``."""
    from lvgym.benchmark.suites import SUITES

    if value != "none" and value not in SUITES:
        raise ConfigError(option, value, f"one of {sorted(SUITES)} or 'none'")
    return value


def suite_option(option: str, value: str) -> str:
    """``--suite``: a suite of the benchmark (:data:`lvgym.benchmark.suites.SUITES`)."""
    from lvgym.benchmark.suites import SUITES

    if value not in SUITES:
        raise ConfigError(option, value, f"one of {sorted(SUITES)}")
    return value


def training_seed(seed: int, step: int, n_envs: int, prog: str = "train.py") -> int:
    """Seed of env row 0 for a run segment starting at ``step`` (rows get ``+ i``), always a training seed
    (:data:`lvgym.benchmark.suites.TRAINING_SEEDS`: disjoint from every validation and test seed, so model
    selection and reported numbers never fly an episode trained on): ``TRAINING_SEED0 + TRAINING_SEED_STRIDE *
    seed`` at the start (runs of different ``seed`` share no row), a fresh draw among the training seeds on
    resume."""
    from lvgym.benchmark.suites import N_TRAINING_SEEDS, TRAINING_SEED0, TRAINING_SEED_STRIDE

    most = N_TRAINING_SEEDS // TRAINING_SEED_STRIDE - 1
    if not 0 <= seed <= most:
        raise SystemExit(f"{prog}: --seed {seed}: an integer in [0, {most}] (rows start at training seed "
                         f"{TRAINING_SEED0:,} + {TRAINING_SEED_STRIDE:,} seed)")
    if n_envs > TRAINING_SEED_STRIDE:
        raise SystemExit(f"{prog}: {n_envs} envs: at most {TRAINING_SEED_STRIDE:,} rows per run (a training seed's "
                         "block of env seeds)")
    if step == 0:
        return TRAINING_SEED0 + TRAINING_SEED_STRIDE * int(seed)
    import numpy as np

    draw = int(np.random.SeedSequence([seed, step]).generate_state(2, dtype=np.uint64)[0])
    return TRAINING_SEED0 + draw % (N_TRAINING_SEEDS - n_envs + 1)


def make_venv(env_id: str, n_envs: int, seed: int, env_kwargs: dict[str, Any], norm: Any, gamma: float,
              stats: Path | None, residual: dict[str, Any] | None = None, loop: dict[str, Any] | None = None,
              vehicles: list[str] | None = None, charges: dict[str, Any] | None = None) -> Any:
    """Batched SB3 VecEnv (-> :class:`lvgym.agents.wrappers.loop_dispersion.LoopDispersedVecEnv` with ``loop`` ->
    :class:`lvgym.agents.wrappers.commandrate.CommandRateVecEnv` with ``charges["command_rate"]`` ->
    :class:`lvgym.agents.wrappers.residual.ResidualVecEnv` with ``residual`` ->
    :class:`lvgym.agents.wrappers.loadmargin.LoadMarginVecEnv` with ``charges["load_margin"]``) -> EnvClock (the env's
    wall time, :mod:`lvgym.agents.training.timing`) -> VecMonitor (episode returns) -> VecNormalize (new, or loaded
    from ``stats``). ``charges``: the run config's records of the training charges (absent: off).
    ``vehicles``: vehicle files whose rows share ``n_envs`` (one such stack per vehicle, joined by
    :class:`lvgym.agents.training.familytrain.ConcatVecEnv`)."""
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    import lvgym  # noqa: F401
    from lvgym.envs import make_sb3_vec_env

    from lvgym.agents.training.timing import EnvClock
    from lvgym.agents.wrappers.commandrate import command_rate_venv
    from lvgym.agents.wrappers.loadmargin import load_margin_venv
    from lvgym.agents.wrappers.loop_dispersion import loop_venv
    from lvgym.agents.wrappers.residual import residual_venv

    charges = dict(charges or {})

    def part(kwargs: dict[str, Any], rows: int, first: int) -> Any:
        base = make_sb3_vec_env(env_id, num_envs=rows, seed=first, **kwargs)
        commanded = command_rate_venv(loop_venv(base, loop, first), charges.get("command_rate"))
        return load_margin_venv(residual_venv(commanded, residual), charges.get("load_margin"),
                                base.task.control_dt_s)

    if vehicles:
        from lvgym.agents.training.familytrain import concat_venv

        inner = concat_venv(lambda v, rows, first: part({**env_kwargs, "vehicle": v}, rows, first), vehicles, n_envs,
                            seed)
    else:
        inner = part(env_kwargs, n_envs, seed)
    venv = VecMonitor(EnvClock(inner))
    if stats is not None and stats.is_file():
        return VecNormalize.load(str(stats), venv)
    if norm.norm_obs or norm.norm_reward:
        return VecNormalize(venv, norm_obs=norm.norm_obs, norm_reward=norm.norm_reward, clip_obs=norm.clip_obs,
                            clip_reward=norm.clip_reward, epsilon=norm.epsilon, gamma=gamma)
    return venv
