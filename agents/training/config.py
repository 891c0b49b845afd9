"""Per-env hyperparameters of the learning agents: ``agents/training/hyperparams/<algo>.yaml`` read into frozen,
validated dataclasses.

A YAML file maps env ids to one entry each::

    lvgym/SmileAscent-v0:
      n_envs: 32                      # rows of the batched SB3 VecEnv
      n_timesteps: 20_000_000         # default training length (train.py --total-timesteps overrides)
      normalize: {norm_obs: true, norm_reward: true, clip_obs: 10.0, clip_reward: 10.0}
      policy: {net_arch: [64, 64], activation: tanh, log_std_init: -1.0}
      algo: {learning_rate: 3.0e-4, lr_schedule: linear, n_steps: 256, ...}   # keywords of the SB3 class

An env id missing from the file falls back to the entry ``default`` (if there is one). Overrides
(``train.py --hp algo.batch_size=64 policy.net_arch=[8,8] n_envs=2``) are dotted keys applied before
validation. Any unknown key or impossible value raises :class:`lvgym.errors.ConfigError` naming the file,
the key path, the value and what is allowed.
"""

from __future__ import annotations

import copy
import difflib
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

import yaml

from lvgym.errors import ConfigError, check_bool, check_choice, check_number

from ..policies.algos import ALGOS

HYPERPARAMS_DIR = Path(__file__).resolve().parent / "hyperparams"
#: the on-policy algorithms (their ``algo:`` keys are :class:`PPOConfig`'s)
ON_POLICY = ("ppo", "recurrent-ppo", "ppo-fast")
ACTIVATIONS = ("tanh", "relu", "elu", "leaky_relu")
LR_SCHEDULES = ("constant", "linear")
ACTION_NOISES = ("none", "normal", "ornstein_uhlenbeck")


# ------------------------------------------------------------------------------------------ validation
def _num(key: str, value: Any, lo: float, hi: float, integer: bool = False, lo_open: bool = False,
         src: str | None = None) -> Any:
    return check_number(key, value, lo, hi, integer=integer, lo_open=lo_open, source=src)


def _layers(key: str, value: Any, src: str | None) -> tuple[int, ...]:
    if not isinstance(value, (list, tuple)) or not value or any(
            not isinstance(v, int) or isinstance(v, bool) or not 1 <= v <= 4096 for v in value):
        raise ConfigError(key, value, "a non-empty list of layer widths, integers in [1, 4096]", src)
    return tuple(int(v) for v in value)


def _unknown(key: str, allowed: list[str] | tuple[str, ...]) -> str:
    """``"unknown key; allowed: [...]"`` with ``"; did you mean 'x'?"`` when an allowed key is close."""
    near = difflib.get_close_matches(str(key).rpartition(".")[2], list(allowed), n=1, cutoff=0.7)
    return f"unknown key; allowed: {list(allowed)}" + (f"; did you mean {near[0]!r}?" if near else "")


def _known(prefix: str, data: Mapping[str, Any], cls: type, src: str | None) -> None:
    if not isinstance(data, Mapping):
        raise ConfigError(prefix.rstrip("."), data, f"a mapping of {sorted(f.name for f in fields(cls))}", src)
    allowed = sorted(f.name for f in fields(cls))
    for key, value in data.items():
        if key not in allowed:
            raise ConfigError(f"{prefix}{key}", value, _unknown(key, allowed), src)


# ------------------------------------------------------------------------------------------ dataclasses
@dataclass(frozen=True)
class NormalizeConfig:
    """SB3 ``VecNormalize``: running mean/std of observations (and of the discounted return for rewards)."""

    norm_obs: bool = True
    norm_reward: bool = True
    clip_obs: float = 10.0
    clip_reward: float = 10.0
    epsilon: float = 1e-8

    def validate(self, src: str | None = None) -> NormalizeConfig:
        check_bool("normalize.norm_obs", self.norm_obs, src)
        check_bool("normalize.norm_reward", self.norm_reward, src)
        _num("normalize.clip_obs", self.clip_obs, 0.0, 1e6, lo_open=True, src=src)
        _num("normalize.clip_reward", self.clip_reward, 0.0, 1e6, lo_open=True, src=src)
        _num("normalize.epsilon", self.epsilon, 0.0, 1.0, lo_open=True, src=src)
        return self


@dataclass(frozen=True)
class PolicyConfig:
    """The networks. ``net_arch``: hidden layers of actor and critic (separate networks of this shape);
    ``qf_arch`` (SAC/TD3): the critics' layers (None: ``net_arch``); ``log_std_init``, ``ortho_init``: PPO.
    Recurrent PPO only (sb3-contrib's ``MlpLstmPolicy``): ``lstm_hidden_size`` (units of the LSTM),
    ``n_lstm_layers``, ``shared_lstm`` (actor and critic share one LSTM) and ``enable_critic_lstm`` (the
    critic has its own LSTM; False with ``shared_lstm``: it then sees the observation only)."""

    net_arch: tuple[int, ...] = (64, 64)
    qf_arch: tuple[int, ...] | None = None
    activation: str = "tanh"
    log_std_init: float = 0.0
    ortho_init: bool = True
    lstm_hidden_size: int | None = None
    n_lstm_layers: int | None = None
    shared_lstm: bool | None = None
    enable_critic_lstm: bool | None = None

    def validate(self, src: str | None = None) -> PolicyConfig:
        object.__setattr__(self, "net_arch", _layers("policy.net_arch", self.net_arch, src))
        if self.qf_arch is not None:
            object.__setattr__(self, "qf_arch", _layers("policy.qf_arch", self.qf_arch, src))
        check_choice("policy.activation", self.activation, ACTIVATIONS, src)
        _num("policy.log_std_init", self.log_std_init, -10.0, 5.0, src=src)
        check_bool("policy.ortho_init", self.ortho_init, src)
        if self.lstm_hidden_size is not None:
            _num("policy.lstm_hidden_size", self.lstm_hidden_size, 1, 4096, integer=True, src=src)
        if self.n_lstm_layers is not None:
            _num("policy.n_lstm_layers", self.n_lstm_layers, 1, 16, integer=True, src=src)
        for key in ("shared_lstm", "enable_critic_lstm"):
            if getattr(self, key) is not None:
                check_bool(f"policy.{key}", getattr(self, key), src)
        if self.shared_lstm and self.enable_critic_lstm:
            raise ConfigError("policy.enable_critic_lstm", True, "false with policy.shared_lstm: true (the critic "
                              "then uses the shared LSTM)", src)
        return self

    def lstm_kwargs(self) -> dict[str, Any]:
        """The LSTM keywords of ``MlpLstmPolicy`` (defaults: 64 units, 1 layer, separate critic LSTM)."""
        return {"lstm_hidden_size": self.lstm_hidden_size or 64, "n_lstm_layers": self.n_lstm_layers or 1,
                "shared_lstm": bool(self.shared_lstm),
                "enable_critic_lstm": not self.shared_lstm if self.enable_critic_lstm is None
                else bool(self.enable_critic_lstm)}

    def sb3_kwargs(self, algo: str) -> dict[str, Any]:
        """``policy_kwargs`` of the SB3 model."""
        import torch.nn as nn

        act = {"tanh": nn.Tanh, "relu": nn.ReLU, "elu": nn.ELU, "leaky_relu": nn.LeakyReLU}[self.activation]
        pi = list(self.net_arch)
        if algo in ON_POLICY:
            kw = {"net_arch": {"pi": pi, "vf": pi}, "activation_fn": act, "log_std_init": self.log_std_init,
                  "ortho_init": self.ortho_init}
            return {**kw, **self.lstm_kwargs()} if algo == "recurrent-ppo" else kw
        return {"net_arch": {"pi": pi, "qf": list(self.qf_arch or self.net_arch)}, "activation_fn": act}


@dataclass(frozen=True)
class PPOConfig:
    """Keywords of ``stable_baselines3.PPO`` (``learning_rate`` with ``lr_schedule``: constant or linear to 0)."""

    learning_rate: float = 3e-4
    lr_schedule: str = "linear"
    n_steps: int = 256
    batch_size: int = 512
    n_epochs: int = 10
    gamma: float = 0.99
    gae_lambda: float = 0.95
    clip_range: float = 0.2
    ent_coef: float = 0.0
    vf_coef: float = 0.5
    max_grad_norm: float = 0.5
    target_kl: float | None = None
    use_sde: bool = False

    def validate(self, src: str | None = None) -> PPOConfig:
        p = "algo."
        _num(p + "learning_rate", self.learning_rate, 0.0, 1.0, lo_open=True, src=src)
        check_choice(p + "lr_schedule", self.lr_schedule, LR_SCHEDULES, src)
        _num(p + "n_steps", self.n_steps, 2, 1_000_000, integer=True, src=src)
        _num(p + "batch_size", self.batch_size, 2, 10_000_000, integer=True, src=src)
        _num(p + "n_epochs", self.n_epochs, 1, 1000, integer=True, src=src)
        _num(p + "gamma", self.gamma, 0.0, 1.0, src=src)
        _num(p + "gae_lambda", self.gae_lambda, 0.0, 1.0, src=src)
        _num(p + "clip_range", self.clip_range, 0.0, 10.0, lo_open=True, src=src)
        _num(p + "ent_coef", self.ent_coef, 0.0, 10.0, src=src)
        _num(p + "vf_coef", self.vf_coef, 0.0, 10.0, src=src)
        _num(p + "max_grad_norm", self.max_grad_norm, 0.0, 1e6, lo_open=True, src=src)
        if self.target_kl is not None:
            _num(p + "target_kl", self.target_kl, 0.0, 10.0, lo_open=True, src=src)
        check_bool(p + "use_sde", self.use_sde, src)
        return self


@dataclass(frozen=True)
class OffPolicyConfig:
    """Keywords shared by ``SAC`` and ``TD3``; ``action_noise`` (a Gaussian or Ornstein-Uhlenbeck
    exploration noise of std ``action_noise_sigma``, TD3's usual choice); ``ent_coef`` ("auto", "auto_0.1"
    or a number) and ``use_sde`` are SAC's; ``policy_delay``, ``target_policy_noise`` and
    ``target_noise_clip`` are TD3's."""

    learning_rate: float = 3e-4
    lr_schedule: str = "constant"
    buffer_size: int = 1_000_000
    learning_starts: int = 10_000
    batch_size: int = 256
    tau: float = 0.005
    gamma: float = 0.99
    train_freq: int = 1
    gradient_steps: int = 1
    action_noise: str = "none"
    action_noise_sigma: float = 0.1
    ent_coef: Any = "auto"
    use_sde: bool = False
    policy_delay: int = 2
    target_policy_noise: float = 0.2
    target_noise_clip: float = 0.5

    def validate(self, src: str | None = None) -> OffPolicyConfig:
        p = "algo."
        _num(p + "learning_rate", self.learning_rate, 0.0, 1.0, lo_open=True, src=src)
        check_choice(p + "lr_schedule", self.lr_schedule, LR_SCHEDULES, src)
        _num(p + "buffer_size", self.buffer_size, 1, 100_000_000, integer=True, src=src)
        _num(p + "learning_starts", self.learning_starts, 0, 100_000_000, integer=True, src=src)
        _num(p + "batch_size", self.batch_size, 1, 1_000_000, integer=True, src=src)
        _num(p + "tau", self.tau, 0.0, 1.0, lo_open=True, src=src)
        _num(p + "gamma", self.gamma, 0.0, 1.0, src=src)
        _num(p + "train_freq", self.train_freq, 1, 1_000_000, integer=True, src=src)
        _num(p + "gradient_steps", self.gradient_steps, -1, 1_000_000, integer=True, src=src)
        check_choice(p + "action_noise", self.action_noise, ACTION_NOISES, src)
        _num(p + "action_noise_sigma", self.action_noise_sigma, 0.0, 10.0, src=src)
        e = self.ent_coef
        if not (isinstance(e, str) and (e == "auto" or e.startswith("auto_"))):
            _num(p + "ent_coef", e, 0.0, 100.0, src=src)
        check_bool(p + "use_sde", self.use_sde, src)
        _num(p + "policy_delay", self.policy_delay, 1, 1000, integer=True, src=src)
        _num(p + "target_policy_noise", self.target_policy_noise, 0.0, 10.0, src=src)
        _num(p + "target_noise_clip", self.target_noise_clip, 0.0, 10.0, src=src)
        return self


@dataclass(frozen=True)
class AgentConfig:
    """Everything that defines an agent's training for one env: the algorithm, the number of env rows,
    the default length, normalisation, networks and the algorithm's keywords."""

    algo: str
    env_id: str
    n_envs: int = 16
    n_timesteps: int = 1_000_000
    normalize: NormalizeConfig = field(default_factory=NormalizeConfig)
    policy: PolicyConfig = field(default_factory=PolicyConfig)
    hyper: PPOConfig | OffPolicyConfig = field(default_factory=PPOConfig)
    source: str = ""

    def to_dict(self) -> dict[str, Any]:
        """The YAML entry (plain types) that reproduces this configuration."""
        d = asdict(self)
        out = {"n_envs": d["n_envs"], "n_timesteps": d["n_timesteps"], "normalize": d["normalize"],
               "policy": {**d["policy"], "net_arch": list(self.policy.net_arch),
                          "qf_arch": None if self.policy.qf_arch is None else list(self.policy.qf_arch)},
                          "algo": d["hyper"]}
        for key in _LSTM_KEYS if self.algo != "recurrent-ppo" else ():
            out["policy"].pop(key)
        if self.algo in ON_POLICY:
            out["policy"].pop("qf_arch")
        else:
            out["algo"] = {k: v for k, v in out["algo"].items() if k in _ALGO_KEYS[self.algo]}
        return out

    def sb3_kwargs(self) -> dict[str, Any]:
        """Keywords of the SB3 algorithm class (without ``env``, ``seed`` and the logger)."""
        h = asdict(self.hyper)
        lr, sched = h.pop("learning_rate"), h.pop("lr_schedule")
        kw: dict[str, Any] = {"learning_rate": linear_schedule(lr) if sched == "linear" else lr,
                              "policy_kwargs": self.policy.sb3_kwargs(self.algo)}
        if self.algo not in ON_POLICY:
            noise, sigma = h.pop("action_noise"), h.pop("action_noise_sigma")
            h = {k: v for k, v in h.items() if k in _ALGO_KEYS[self.algo]}
            kw["train_freq"] = (h.pop("train_freq"), "step")
            kw["action_noise_spec"] = (noise, sigma)        # built once the action space is known
        return {**kw, **h}

    def schedules(self) -> dict[str, Any]:
        """The learning rate and SB3's schedule of it as a resumed run loads them (``custom_objects``), rebuilt from
        this configuration rather than unpickled: a checkpoint pickles a schedule by reference to the module that
        defined it, and a run saved before :class:`LinearSchedule` moved here (from ``lvgym.agents.config``) names
        a module that is gone. SB3 rebuilds its schedule from the learning rate on loading, so ``lr_schedule`` is
        given as None: the values are those the run trained with."""
        return {"learning_rate": self.sb3_kwargs()["learning_rate"], "lr_schedule": None}


_COMMON = ("learning_rate", "lr_schedule", "buffer_size", "learning_starts", "batch_size", "tau", "gamma",
           "train_freq", "gradient_steps", "action_noise", "action_noise_sigma")
_ALGO_KEYS = {"sac": _COMMON + ("ent_coef", "use_sde"),
              "td3": _COMMON + ("policy_delay", "target_policy_noise", "target_noise_clip")}
_LSTM_KEYS = ("lstm_hidden_size", "n_lstm_layers", "shared_lstm", "enable_critic_lstm")
_ENTRY_KEYS = ("n_envs", "n_timesteps", "normalize", "policy", "algo")


class LinearSchedule:
    """Learning rate ``initial * progress_remaining`` (picklable, unlike a lambda in a saved model)."""

    def __init__(self, initial: float) -> None:
        self.initial = float(initial)

    def __call__(self, progress_remaining: float) -> float:
        return self.initial * progress_remaining

    def __repr__(self) -> str:
        return f"LinearSchedule({self.initial})"


def linear_schedule(initial: float) -> LinearSchedule:
    """A learning rate falling linearly from ``initial`` to 0 over the run."""
    return LinearSchedule(initial)


# --------------------------------------------------------------------------------------------- loading
def _set_dotted(entry: dict[str, Any], key: str, value: Any) -> None:
    parts = key.split(".")
    node = entry
    for part in parts[:-1]:
        nxt = node.setdefault(part, {})
        if not isinstance(nxt, dict):
            raise ConfigError(key, value, f"{part!r} is not a mapping, so it has no sub-keys")
        node = nxt
    node[parts[-1]] = value


def parse_overrides(items: list[str] | tuple[str, ...]) -> dict[str, Any]:
    """``["algo.n_steps=64", "policy.net_arch=[8, 8]"]`` -> ``{"algo.n_steps": 64, ...}`` (values as YAML)."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError("--hp", item, "KEY=VALUE with a dotted key, e.g. algo.n_steps=64")
        try:
            out[key.strip()] = yaml.safe_load(text)
        except yaml.YAMLError:
            raise ConfigError("--hp", item, "KEY=VALUE with a YAML value, e.g. policy.net_arch=[32,32]") from None
    return out


def read_entries(algo: str, path: str | Path | None = None) -> tuple[dict[str, Any], str]:
    """The raw YAML mapping of ``algo``'s file and the file's name."""
    check_choice("algo", algo, tuple(ALGOS), None)
    p = Path(path) if path is not None else HYPERPARAMS_DIR / f"{algo}.yaml"
    src = str(p)
    if not p.is_file():
        raise ConfigError("hyperparams", src, "an existing YAML file", None)
    from lvgym.vehicle.yamlfile import read_yaml

    data = read_yaml(p, src)[0] or {}                # syntax errors, unsafe tags, duplicate keys: with the line
    if not isinstance(data, dict):
        raise ConfigError("<top level>", type(data).__name__, "a mapping of env ids to entries", src)
    return data, src


def build_config(algo: str, env_id: str, entry: Mapping[str, Any], source: str = "",
                 overrides: Mapping[str, Any] | None = None) -> AgentConfig:
    """Validate one entry (a plain mapping, e.g. from YAML or a run's ``config.yaml``) with dotted overrides."""
    check_choice("algo", algo, tuple(ALGOS), None)
    src = source or None
    raw = copy.deepcopy(dict(entry))
    for key, value in (overrides or {}).items():
        _set_dotted(raw, key, value)
        src = f"{source} with overrides" if source else "overrides"
    for key, value in raw.items():
        if key not in _ENTRY_KEYS:
            raise ConfigError(key, value, _unknown(key, _ENTRY_KEYS), src)
    hyper_cls: type = PPOConfig if algo in ON_POLICY else OffPolicyConfig
    algo_raw = raw.get("algo", {}) or {}
    if algo != "recurrent-ppo":
        for key in _LSTM_KEYS:
            if key in (raw.get("policy") or {}):
                raise ConfigError(f"policy.{key}", raw["policy"][key], "only with --algo recurrent-ppo", src)
    if algo not in ON_POLICY:
        _known("algo.", algo_raw, hyper_cls, src)
        allowed = _ALGO_KEYS[algo]
        for key, value in algo_raw.items():
            if key not in allowed:
                raise ConfigError(f"algo.{key}", value, f"not a {algo.upper()} key; allowed: {sorted(allowed)}", src)
    parts: dict[str, Any] = {}
    for name, cls in (("normalize", NormalizeConfig), ("policy", PolicyConfig), ("algo", hyper_cls)):
        sub = raw.get(name, {}) or {}
        _known(f"{name}.", sub, cls, src)
        parts[name] = cls(**sub).validate(src)
    n_envs = _num("n_envs", raw.get("n_envs", 16), 1, 4096, integer=True, src=src)
    n_timesteps = _num("n_timesteps", raw.get("n_timesteps", 1_000_000), 1, 10**12, integer=True, src=src)
    hyper = parts["algo"]
    if isinstance(hyper, PPOConfig) and hyper.batch_size > n_envs * hyper.n_steps:
        raise ConfigError("algo.batch_size", hyper.batch_size,
                          f"at most n_envs * algo.n_steps = {n_envs} * {hyper.n_steps} (one rollout)", src)
    return AgentConfig(algo=algo, env_id=env_id, n_envs=n_envs, n_timesteps=n_timesteps,
                       normalize=parts["normalize"], policy=parts["policy"], hyper=parts["algo"], source=source)


def load_config(algo: str, env_id: str, overrides: Mapping[str, Any] | None = None,
                path: str | Path | None = None) -> AgentConfig:
    """The validated configuration of ``algo`` on ``env_id`` from ``agents/training/hyperparams/<algo>.yaml``
    (or ``path``), the ``default`` entry standing in for env ids the file does not list."""
    data, src = read_entries(algo, path)
    if env_id in data:
        entry = data[env_id]
    elif "default" in data:
        entry = data["default"]
    else:
        raise ConfigError("env_id", env_id, f"an env id of {src} ({sorted(data)}) or a 'default' entry")
    if not isinstance(entry, dict):
        raise ConfigError(env_id, entry, "a mapping with keys " + str(list(_ENTRY_KEYS)), src)
    return build_config(algo, env_id, entry, src, overrides)


__all__ = ["ON_POLICY", "AgentConfig", "HYPERPARAMS_DIR", "LinearSchedule", "NormalizeConfig", "OffPolicyConfig",
           "PPOConfig", "PolicyConfig", "build_config", "linear_schedule", "load_config", "parse_overrides",
           "read_entries"]
