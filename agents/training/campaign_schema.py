"""A campaign file: read, checked whole, and made into frozen dataclasses before anything runs.

A campaign (``lvgym campaign FILE``, :mod:`lvgym.agents.training.campaign`) is training configurations x seeds,
then the evaluation of every run on the test seeds, then the comparison over the runs. Its YAML file::

    name: v2-example                     # the campaign's folder: <runs_dir>/<name>/
    runs_dir: runs                       # relative to the working folder of the command
    seeds: [0, 1, 2]                     # training seeds: one run per configuration and seed
    train: {total_timesteps: 2e6, max_wall_time_s: 3600}    # train.py options of every run
    configurations:                      # name -> train.py options (a configuration's own win over train:)
      res-lqg: {residual: lqg, residual_scale: 0.05, history: 4}
      plain: {residual: none, history: 0, hp: {algo.n_steps: 128}}
    evaluation: {suites: [smile-v2], episodes: 50, seed_set: test, baselines: [gs-pid-flex, lqg]}
    executor: local                      # local (train.py processes on this machine) or ray
    workers: 2                           # runs at once (local; a local Ray's CPUs)

A train option is named as ``train.py`` names it (``residual_scale`` or ``residual-scale``; ``hp`` and ``env_kwargs``
also take a mapping). Every value is checked here with ``train.py``'s own checks (its fields' ranges and choices,
:func:`~lvgym.agents.training.trainsetup.check_options`, :func:`~lvgym.agents.training.train.prepare` and the env's
keywords by building one env): a bad one is a :class:`~lvgym.errors.ConfigError` naming the file, the key path
(``configurations.res-lqg.hp``), the value and what is allowed.
"""

from __future__ import annotations

import dataclasses
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from lvgym.errors import MISSING, ConfigError, check_choice, check_number, did_you_mean

__all__ = ["TOP_KEYS", "Campaign", "Evaluation", "Run", "load_campaign", "observes_vehicle", "suites_flown",
           "train_fields"]

TOP_KEYS = ("name", "runs_dir", "seeds", "train", "configurations", "evaluation", "executor", "workers")
EVALUATION_KEYS = ("suites", "episodes", "seed_set", "baselines", "metric", "mission_time_s")
#: train options a campaign sets itself for every run
RESERVED = {"seed": "seeds", "name": "the run's name <configuration>-s<seed>", "runs_dir": "the campaign's folder",
            "resume": "a run folder without final_model.json"}
#: the metrics a comparison may rank by (auto: score_v2 on a suite of protocol v2 on, else score)
METRICS = ("auto", "score", "score_v2", "rate_error_rad")
CAMPAIGN_EXECUTORS = ("local", "ray")
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")


@dataclass(frozen=True)
class Evaluation:
    """The evaluation of every run: ``episodes`` seeds of ``seed_set`` on each condition of ``suites``, beside
    the classical ``baselines``; ``metric`` ranks them; ``mission_time_s`` shortens every episode (smoke tests)."""

    suites: tuple[str, ...] = ("smile-v2",)
    episodes: int = 50
    seed_set: str = "test"
    baselines: tuple[str, ...] = ("gs-pid-flex", "lqg")
    metric: str = "auto"
    mission_time_s: float | None = None


@dataclass(frozen=True)
class Run:
    """One training run: ``<configuration>-s<seed>`` in the campaign's folder, and the ``train.py`` options
    that start it (a run folder already there continues with ``--resume`` instead)."""

    name: str
    configuration: str
    seed: int
    folder: str
    argv: tuple[str, ...]


@dataclass(frozen=True)
class Campaign:
    """A checked campaign file (module docstring); ``runs_dir`` is absolute."""

    name: str
    runs_dir: str
    seeds: tuple[int, ...]
    configurations: tuple[tuple[str, tuple[str, ...]], ...]     # name -> its train.py options (argv)
    evaluation: Evaluation
    executor: str = "local"
    workers: int | None = None
    source: str = ""
    #: configuration -> the evaluation suites its runs fly (:func:`suites_flown`); a configuration left out
    #: flies them all
    flies: tuple[tuple[str, tuple[str, ...]], ...] = ()

    def suites_of(self, configuration: str) -> tuple[str, ...]:
        """The evaluation suites the runs of ``configuration`` fly."""
        return dict(self.flies).get(configuration, self.evaluation.suites)

    @property
    def folder(self) -> Path:
        return Path(self.runs_dir) / self.name

    def runs(self) -> list[Run]:
        """Every run, configuration by configuration, seed by seed."""
        out = []
        for cfg, argv in self.configurations:
            for seed in self.seeds:
                name = f"{cfg}-s{seed}"
                out.append(Run(name, cfg, seed, str(self.folder / name),
                               (*argv, "--seed", str(seed), "--name", name, "--runs-dir", str(self.folder))))
        return out


# ------------------------------------------------------------------------------------ train options
def train_fields() -> dict[str, dataclasses.Field]:
    """``train.py``'s options by every name a campaign file may give them: the field name, with dashes, and
    the flag without its dashes (``max_wall_time`` for ``max_wall_time_s``)."""
    from lvgym.agents.training.train import Args

    from lvgym.commandline.options import _spec

    out = {}
    for f in dataclasses.fields(Args):
        flag = (_spec(f).flag or "--" + f.name.replace("_", "-"))[2:]
        for n in (f.name, f.name.replace("_", "-"), flag, flag.replace("-", "_")):
            out[n] = f
    return out


def _flag(f: dataclasses.Field) -> str:
    from lvgym.commandline.options import _spec

    return _spec(f).flag or "--" + f.name.replace("_", "-")


def _text(value: Any) -> str:
    """A YAML value as command-line text (numbers as they read back, the rest as YAML)."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool) or value is None or isinstance(value, (list, dict)):
        return yaml.safe_dump(value, default_flow_style=True, width=10**6).strip().removesuffix("...").strip()
    return repr(value)


def _option(path: str, f: dataclasses.Field, raw: Any, source: str) -> tuple[Any, list[str]]:
    """``raw`` of train option ``f`` (at ``path``) as train.py's value and its command-line words."""
    from lvgym.agents.training.train import Args

    from lvgym.commandline.options import _hints, _kind, _spec, _value

    kind, spec, flag = _kind(_hints(Args)[f.name]), _spec(f), _flag(f)
    if raw is None:
        raise ConfigError(path, raw, "a value (leave the key out for train.py's default)", source)
    if kind.many:
        if isinstance(raw, dict) and f.name in ("hp", "env_kwargs"):
            raw = [f"{k}={_text(v)}" for k, v in raw.items()]
        items = raw if isinstance(raw, list) else [raw]
        if kind.scalar is str:
            items = [_text(x) if isinstance(x, (int, float)) and not isinstance(x, bool) else x for x in items]
        bad = [x for x in items if isinstance(x, (dict, list, bool)) or x is None]
        if bad:
            raise ConfigError(path, raw, f"a list of {kind.scalar.__name__} values ({flag} takes them)", source)
        words = [_text(x) for x in items]
    else:
        if isinstance(raw, (dict, list)):
            raise ConfigError(path, raw, f"one {kind.scalar.__name__} value ({flag} takes one)", source)
        if kind.scalar is bool:
            if not isinstance(raw, bool):
                raise ConfigError(path, raw, "true or false", source)
            return raw, [flag if raw else "--no-" + flag[2:]]
        if kind.scalar is str and not isinstance(raw, str):
            raise ConfigError(path, raw, f"a string ({flag})", source)
        if isinstance(raw, bool):
            raise ConfigError(path, raw, f"a number ({flag})", source)
        items, words = raw, [_text(raw)]
    try:
        value = _value(flag, [str(x) for x in items] if kind.many else str(items), kind, spec)
    except ConfigError as exc:
        raise ConfigError(path, raw, exc.allowed, source) from None
    if kind.many:
        words = [repr(x) if isinstance(x, float) else str(x) for x in value]
        if not words:                           # an empty list or mapping: train.py's default, no flag
            return value, []
    elif kind.scalar in (int, float):
        words = [repr(value)]
    return value, [flag, *words]


def _train_options(path: str, options: Any, source: str) -> dict[str, tuple[str, Any, list[str]]]:
    """A mapping of train options: ``{field name: (key path, value, command-line words)}``."""
    if not isinstance(options, dict):
        raise ConfigError(path, options, "a mapping of train.py options (name: value)", source)
    fields = train_fields()
    out: dict[str, tuple[str, Any, list[str]]] = {}
    for key, raw in options.items():
        where = f"{path}.{key}"
        f = fields.get(key) if isinstance(key, str) else None
        if f is not None and f.name in RESERVED:
            raise ConfigError(where, raw, f"set by the campaign ({RESERVED[f.name]}): leave it out", source)
        if f is None:
            raise ConfigError(where, raw, "unknown train.py option; one of "
                              f"{sorted(n for n in {x.name for x in fields.values()} if n not in RESERVED)}"
                              f"{did_you_mean(key, fields)}", source)
        if f.name in out:
            raise ConfigError(where, raw, f"given twice (also as {out[f.name][0]})", source)
        value, words = _option(where, f, raw, source)
        out[f.name] = (where, value, words)
    return out


def _check_configuration(name: str, options: dict[str, tuple[str, Any, list[str]]], seeds: tuple[int, ...],
                         runs_dir: str, source: str, envs_checked: set[str]) -> None:
    """One configuration's options checked by train.py itself, for every seed (its ``prepare``: nothing is
    written), and its env's keywords by building one env. A refusal names the option's key path."""
    from lvgym.agents.training.train import Args, check_options, env_kwargs_of, prepare

    by_flag = {_flag(f): f.name for f in dataclasses.fields(Args)}
    values = {k: v for k, (_, v, _) in options.items()}

    def where(exc: ConfigError, seed: int) -> ConfigError:
        key = exc.key
        field = by_flag.get(key, key if key in options else None)
        if field == "seed":
            return ConfigError(f"seeds[{seeds.index(seed)}]", seed, f"{exc}", source)
        if field in options:
            return ConfigError(options[field][0], exc.value, exc.allowed, source)
        if "hp" in options and exc.key not in by_flag:            # a hyperparameter key: the hp list
            return ConfigError(options["hp"][0], options["hp"][1], str(exc), source)
        return ConfigError(f"configurations.{name}", exc.value, str(exc), source)

    for seed in seeds:
        args = Args(**values, seed=seed, name=f"{name}-s{seed}", runs_dir=os.path.join(runs_dir, ".check"))
        try:
            check_options(args)
            args, config, _, _ = prepare(args, set(values) | {"seed", "name", "runs_dir"})
        except ConfigError as exc:
            raise where(exc, seed) from None
        except SystemExit as exc:                                  # prepare's one-line refusals
            text = str(exc.code).split(": ", 1)[-1]
            if text.startswith("--seed "):
                raise ConfigError(f"seeds[{seeds.index(seed)}]", seed, f"configuration {name!r}: {text}",
                                  source) from None
            raise ConfigError(f"configurations.{name}", dict(values), text, source) from None
    if config.get("family_vehicles"):              # the family's vehicle files are built by its runs
        return
    kwargs = env_kwargs_of(args)
    key = repr((config["env_id"], sorted(kwargs.items(), key=str)))
    if key in envs_checked:
        return
    envs_checked.add(key)
    from lvgym.envs import make_sb3_vec_env

    try:
        make_sb3_vec_env(config["env_id"], num_envs=1, seed=0, **kwargs).close()
    except (ConfigError, ValueError, TypeError) as exc:
        path, given = options.get("env_kwargs", (f"configurations.{name}", dict(values)))[:2]
        raise ConfigError(path, given, f"{config['env_id']} option {exc}", source) from None


def observes_vehicle(options: Any) -> bool:
    """Whether an env of these keywords (a suite condition's options, or a run's env keywords) ends its
    observation with the vehicle's design parameters (the env option ``vehicle_info``)."""
    return bool(dict(options).get("vehicle_info", False))


def suites_flown(name: str, options: dict[str, tuple[str, Any, list[str]]], suites: tuple[str, ...],
                 source: str) -> tuple[str, ...]:
    """The evaluation ``suites`` configuration ``name`` (its merged train options) can fly: those whose
    observation is the one it trains on. A run trained with the vehicle's design parameters in view (the
    family's informed track, ``vehicle_info``) flies the suites that give them (``family-v2-informed``);
    any other run the suites that do not (``family-v2``, the blind track, and the one-vehicle suites).
    None of them: a ConfigError naming the configuration."""
    from lvgym.agents.training.train import Args, env_kwargs_of
    from lvgym.benchmark.suites import get_suite

    values = {k: v for k, (_, v, _) in options.items()}
    mine = observes_vehicle(env_kwargs_of(Args(**values, name=name)))
    out = tuple(s for s in suites if observes_vehicle(get_suite(s).conditions[0].options) == mine)
    if not out:
        track = ("with the vehicle's design parameters (vehicle_info)" if mine
                 else "without the vehicle's design parameters")
        raise ConfigError(f"configurations.{name}", values.get("suite", "(no suite)"), f"a configuration whose "
                          f"observation one of evaluation.suites {list(suites)} gives: it trains {track}", source)
    return out


# ------------------------------------------------------------------------------------ the file
def _keys(path: str, data: Any, allowed: tuple[str, ...], source: str, required: tuple[str, ...] = ()) -> dict:
    if not isinstance(data, dict):
        raise ConfigError(path or "<file>", data, f"a mapping with keys {list(allowed)}", source)
    for k in data:
        if k not in allowed:
            raise ConfigError(f"{path}.{k}" if path else str(k), data[k],
                              f"unknown key; one of {list(allowed)}{did_you_mean(k, allowed)}", source)
    for k in required:
        if k not in data:
            raise ConfigError(f"{path}.{k}" if path else k, MISSING, "required", source)
    return data


def _names(path: str, value: Any, source: str, check: Any = None) -> tuple[str, ...]:
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, list) or not items or not all(isinstance(x, str) for x in items):
        raise ConfigError(path, value, "a non-empty list of names", source)
    for i, x in enumerate(items):
        if check is not None:
            check(f"{path}[{i}]", x)
    if len(set(items)) != len(items):
        raise ConfigError(path, value, "each name once", source)
    return tuple(items)


def _evaluation(data: Any, source: str) -> Evaluation:
    from lvgym.benchmark.suites import SEED_SETS, SUITES

    d = _keys("evaluation", {} if data is None else data, EVALUATION_KEYS, source)
    base = Evaluation()

    def suite(path: str, name: str) -> None:
        if name not in SUITES:
            raise ConfigError(path, name, f"a suite of the protocol{did_you_mean(name, SUITES)}; one of "
                              f"{sorted(SUITES)}", source)

    def baseline(path: str, name: str) -> None:
        import lvgym.baselines  # noqa: F401  (registers the controllers by name)
        from lvgym.benchmark.headline import policy_kind
        from lvgym.benchmark.registry import resolve_policy

        try:
            spec = resolve_policy(name, "campaign")
        except SystemExit as exc:
            raise ConfigError(path, name, str(exc.code).split(": ", 1)[-1], source) from None
        if policy_kind(spec) != "classical":
            raise ConfigError(path, name, f"a classical baseline (this policy's kind is {policy_kind(spec)!r})",
                              source)

    suites = _names("evaluation.suites", d.get("suites", list(base.suites)), source, suite)
    episodes = check_number("evaluation.episodes", d.get("episodes", base.episodes), 1, 10**6, integer=True,
                            source=source)
    seed_set = check_choice("evaluation.seed_set", d.get("seed_set", base.seed_set), SEED_SETS, source)
    baselines = _names("evaluation.baselines", d.get("baselines", list(base.baselines)), source, baseline)
    metric = check_choice("evaluation.metric", d.get("metric", base.metric), METRICS, source)
    if metric == "score_v2":
        from lvgym.benchmark.flyability import applies

        for s in suites:
            if not applies(SUITES[s].version):
                raise ConfigError("evaluation.metric", metric, f"score or auto (suite {s!r} predates protocol v2's "
                                  "score_v2)", source)
    mt = d.get("mission_time_s")
    if mt is not None:
        mt = check_number("evaluation.mission_time_s", mt, 0.0, 3600.0, lo_open=True, source=source)
    return Evaluation(suites, episodes, seed_set, baselines, metric, mt)


def load_campaign(path: str | os.PathLike[str], check_train: bool = True) -> Campaign:
    """The campaign of the YAML file at ``path``, every value checked (``check_train``: each configuration by
    train.py's own checks too); a bad one raises a ConfigError naming the file and the key path."""
    from lvgym.parallel import check_workers

    source = str(path)
    try:
        data = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise ConfigError("<file>", source, f"a readable campaign file ({exc.strerror})") from None
    except yaml.YAMLError as exc:
        raise ConfigError("<file>", source, f"valid YAML ({str(exc).splitlines()[0]})") from None
    d = _keys("", data, TOP_KEYS, source, required=("name", "seeds", "configurations"))
    name = d["name"]
    if not isinstance(name, str) or not NAME.match(name):
        raise ConfigError("name", name, "a folder name: letters, digits and . _ + - (not first)", source)
    runs_dir = d.get("runs_dir", "runs")
    if not isinstance(runs_dir, str) or not runs_dir:
        raise ConfigError("runs_dir", runs_dir, "a folder path", source)
    seeds = d["seeds"]
    if isinstance(seeds, int) and not isinstance(seeds, bool):
        seeds = [seeds]
    if not isinstance(seeds, list) or not seeds:
        raise ConfigError("seeds", seeds, "a non-empty list of training seeds (integers)", source)
    for i, s in enumerate(seeds):
        check_number(f"seeds[{i}]", s, 0, 10**6, integer=True, source=source)
    if len(set(seeds)) != len(seeds):
        raise ConfigError("seeds", seeds, "each seed once", source)
    common = _train_options("train", d.get("train") or {}, source)
    configs = d["configurations"]
    if not isinstance(configs, dict) or not configs:
        raise ConfigError("configurations", configs, "a non-empty mapping of name: train.py options", source)
    executor = check_choice("executor", d.get("executor", "local"), CAMPAIGN_EXECUTORS, source)
    try:
        workers = check_workers(d.get("workers"), "workers")
    except ConfigError as exc:
        raise ConfigError(exc.key, exc.value, exc.allowed, source) from None
    evaluation = _evaluation(d.get("evaluation"), source)
    folder = os.path.abspath(os.path.join(runs_dir, name))
    out, flies, envs_checked = [], [], set()
    for cname, options in configs.items():
        if not isinstance(cname, str) or not NAME.match(cname):
            raise ConfigError(f"configurations.{cname}", options, "a name: letters, digits and . _ + - (not "
                              "first)", source)
        own = _train_options(f"configurations.{cname}", options if options is not None else {}, source)
        merged = {**common, **own}
        if check_train:
            _check_configuration(cname, merged, tuple(seeds), folder, source, envs_checked)
        out.append((cname, tuple(w for _, _, words in merged.values() for w in words)))
        flies.append((cname, suites_flown(cname, merged, evaluation.suites, source)))
    clash = sorted({f"{c}-s{s}" for c, _ in out for s in seeds} & set(evaluation.baselines))
    if clash:
        raise ConfigError("evaluation.baselines", list(evaluation.baselines), f"names other than the runs' ({clash} "
                          "is both: a run is labelled <configuration>-s<seed>)", source)
    return Campaign(name, os.path.abspath(runs_dir), tuple(int(s) for s in seeds), tuple(out), evaluation, executor,
                    workers, source, tuple(flies))
