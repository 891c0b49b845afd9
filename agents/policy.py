"""A trained stable-baselines3 model as a benchmark :class:`~lvgym.benchmark.policy.Policy`, and the files
a saved policy is made of.

A saved policy is three files with one stem::

    <stem>.zip                  the SB3 model (``model.save``)
    <stem>_vecnormalize.pkl     the VecNormalize statistics (``VecNormalize.save``), if training normalised
    <stem>.json                 {"algo": "PPO", "env_id": ..., "env_kwargs": {...}, "num_timesteps": ...}

``evaluate.py`` loads saved models through :func:`load_policy`. :class:`SB3Policy` accepts such a ``.zip``, its stem, or a run folder of ``train.py`` (``runs/<name>``: its best model by
validation, else its final model, else its last checkpoint).

    lvgym export-policy runs/ppo-smile agents/trained/ppo_smile_ascent   # copy a run's policy
    python -m lvgym.agents.policy export runs/ppo-smile agents/trained/ppo_smile_ascent   # the same
"""

from __future__ import annotations

import dataclasses
import functools
import json
import pickle
import shutil
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.benchmark.results import atomic_path, atomic_write_text
from lvgym.commandline import arg

from .config import ALGOS, algo_class, algo_name

VECNORM_SUFFIX = "_vecnormalize.pkl"


def policy_files(stem: str | Path) -> tuple[Path, Path, Path]:
    """``(<stem>.zip, <stem>_vecnormalize.pkl, <stem>.json)`` of a stem (with or without ``.zip``)."""
    s = Path(stem)
    if s.suffix == ".zip":
        s = s.with_suffix("")
    return s.with_name(s.name + ".zip"), s.with_name(s.name + VECNORM_SUFFIX), s.with_name(s.name + ".json")


def save_policy(model: Any, vecnormalize: Any, stem: str | Path, meta: dict[str, Any]) -> Path:
    """Write the three files of ``stem``, each atomically, the JSON last (its presence means the others
    are complete). ``meta`` must hold ``algo``; returns the ``.zip`` path."""
    if "algo" not in meta:
        raise ValueError("save_policy: meta needs 'algo' (e.g. 'PPO')")
    zip_path, norm_path, json_path = policy_files(stem)
    with atomic_path(zip_path) as tmp:
        model.save(tmp)
    if vecnormalize is not None:
        with atomic_path(norm_path) as tmp:
            vecnormalize.save(tmp)
    atomic_write_text(json_path, json.dumps({**meta, "algo": algo_name(str(meta["algo"]))}, indent=1, sort_keys=True))
    return zip_path


def copy_policy(src_stem: str | Path, dst_stem: str | Path, extra: dict[str, Any] | None = None) -> Path:
    """Copy a saved policy's files to another stem (atomically, the JSON last)."""
    src, dst = policy_files(src_stem), policy_files(dst_stem)
    for s, d in zip(src[:2], dst[:2]):
        if s.is_file():
            with atomic_path(d) as tmp:
                shutil.copyfile(s, tmp)
        elif d.is_file():
            d.unlink()
    meta = json.loads(src[2].read_text(encoding="utf-8")) if src[2].is_file() else {}
    atomic_write_text(dst[2], json.dumps({**meta, **(extra or {})}, indent=1, sort_keys=True))
    return dst[0]


def resolve_model_path(path: str | Path) -> Path:
    """The ``.zip`` of a saved policy: ``path`` itself, ``path + '.zip'``, or in a run folder its best
    model, its final model or its latest checkpoint (``FileNotFoundError`` otherwise)."""
    p = Path(path)
    if p.is_dir():
        from lvgym.agents.checkpoints import latest_checkpoint

        for stem in ("best_model", "final_model"):
            if (p / f"{stem}.zip").is_file() and (p / f"{stem}.json").is_file():
                return p / f"{stem}.zip"
        ckpt = latest_checkpoint(p / "checkpoints")
        if ckpt is not None:
            return ckpt[0]
        raise FileNotFoundError(f"{str(p)!r}: a run folder without best_model.zip, final_model.zip or checkpoints")
    if p.is_file():
        return p
    if p.with_name(p.name + ".zip").is_file():
        return p.with_name(p.name + ".zip")
    raise FileNotFoundError(f"{str(p)!r}: no such SB3 model (.zip) or run folder")


def _sidecar_algo(path: Path) -> str | None:
    side = path.with_suffix(".json")
    if side.is_file():
        algo = json.loads(side.read_text(encoding="utf-8")).get("algo")
        return algo_name(str(algo)) if algo else None
    return None


def _guess_algo(path: Path) -> str | None:
    """The algorithm suggested by the policy class module stored in the zip's ``data``."""
    try:
        with zipfile.ZipFile(path) as z:
            data = json.loads(z.read("data"))
        module = str(data.get("policy_class", {}).get("__module__", ""))
    except (KeyError, ValueError, zipfile.BadZipFile, AttributeError):
        return None
    for key, algo in (("recurrent", "RecurrentPPO"), ("sac", "SAC"), ("td3", "TD3"), ("ddpg", "DDPG"),
                      ("common.policies", "PPO")):
        if key in module:
            return algo
    return None


#: what a saved model's training schedules are replaced with when it is loaded to fly: a policy acts without
#: them, and a schedule is pickled by reference to the module that defined it (``agents.config`` in the
#: models saved before the package was installed as ``lvgym.agents``), which a flight should not need
FLY_ONLY = {"learning_rate": 0.0, "lr_schedule": lambda _: 0.0, "clip_range": lambda _: 0.0,
            "clip_range_vf": None, "exploration_schedule": lambda _: 0.0}


def guess_and_load(path: str | Path) -> Any:
    """The SB3 model at ``path`` when no sidecar names its algorithm: the algorithm suggested by the
    policy class stored in the zip first, then every algorithm train.py trains
    (:data:`lvgym.agents.config.ALGOS`) in turn."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"policy {str(path)!r}: no such SB3 model file")
    first = _sidecar_algo(path) or _guess_algo(path)
    known = list(ALGOS.values())
    order = [first] + [a for a in known if a != first] if first else known
    errors = []
    for algo in order:
        try:
            cls = algo_class(algo)
        except (ImportError, ValueError) as exc:
            errors.append(f"{algo}: {exc}")
            continue
        try:
            return cls.load(str(path), device="cpu", custom_objects=FLY_ONLY)
        except Exception as exc:  # noqa: BLE001 (a wrong algorithm fails in many ways)
            errors.append(f"{algo}: {type(exc).__name__}: {exc}")
    raise ValueError(f"policy {str(path)!r}: no SB3 algorithm loads it ({'; '.join(errors)}); "
                     f"add a sidecar {path.with_suffix('.json').name} with {{\"algo\": \"PPO\"}}")


def read_meta(zip_path: str | Path) -> dict[str, Any]:
    """The sidecar JSON of a saved policy (``{}`` when it has none)."""
    side = policy_files(zip_path)[2]
    return json.loads(side.read_text(encoding="utf-8")) if side.is_file() else {}


def load_model(zip_path: str | Path, algo: str | None = None) -> Any:
    """The SB3 model at ``zip_path`` on the CPU, to fly (its training schedules replaced, :data:`FLY_ONLY`):
    class from ``algo``, else from the sidecar JSON, else guessed by :func:`guess_and_load` (policies saved
    by other tools)."""
    algo = algo or read_meta(zip_path).get("algo")
    if algo is None:
        return guess_and_load(zip_path)
    try:
        cls = algo_class(str(algo))
    except ValueError:
        raise ValueError(f"{str(zip_path)!r}: algo = {algo!r}: one of {sorted(ALGOS.values())}") from None
    return cls.load(str(zip_path), device="cpu", custom_objects=FLY_ONLY)


def load_vecnormalize(zip_path: str | Path) -> Any:
    """The VecNormalize statistics saved next to ``zip_path`` (frozen: ``training = False``), or None."""
    norm = policy_files(zip_path)[1]
    if not norm.is_file():
        return None
    with open(norm, "rb") as f:
        vn = pickle.load(f)
    vn.training = False
    vn.norm_reward = False
    return vn


class SB3Policy:
    """A trained SB3 model behind the benchmark's Policy interface: ``act`` normalises the observation
    with the training run's frozen VecNormalize statistics and returns ``model.predict(...,
    deterministic=True)`` (actions inside the action space). ``name`` defaults to the file stem (the run
    name for a run folder)."""

    def __init__(self, path: str | Path, name: str | None = None, deterministic: bool = True) -> None:
        zip_path = resolve_model_path(path)
        self.path = str(zip_path)
        self.meta = read_meta(zip_path)
        self.model = load_model(zip_path)
        self.normalizer = load_vecnormalize(zip_path)
        self.deterministic = bool(deterministic)
        p = Path(path)
        self.name = name or (p.resolve().name if p.is_dir() else zip_path.stem)
        self._setup()

    @classmethod
    def from_model(cls, model: Any, normalizer: Any = None, name: str = "agent",
                   deterministic: bool = True, meta: dict[str, Any] | None = None) -> SB3Policy:
        """A live model (and a VecNormalize whose statistics it was trained with) as a policy. The
        statistics are copied and frozen: later training does not change this policy. ``meta``: the
        run's sidecar fields (its ``env_kwargs`` say whether the observation has a ``history``)."""
        self = cls.__new__(cls)
        self.path, self.meta, self.model, self.name = "", dict(meta or {}), model, name
        self.deterministic = bool(deterministic)
        self.normalizer = None
        if normalizer is not None:
            import copy

            self.normalizer = copy.copy(normalizer)
            self.normalizer.obs_rms = copy.deepcopy(normalizer.obs_rms)
            self.normalizer.training = False
        self._setup()
        return self

    def _setup(self) -> None:
        """What the model needs besides its weights: the observation history of its training env
        (``env_kwargs["history"]``: k samples and actions, stacked here from a plain observation with the
        env's own :class:`lvgym.envs.history.HistoryStack`) and, for a recurrent model, its LSTM state."""
        self.recurrent = algo_name(type(self.model).__name__) == "RecurrentPPO"
        self.history = int((self.meta.get("env_kwargs") or {}).get("history", 0) or 0)
        self._stack: Any = None
        self._buf = np.zeros((1, 0), np.float32)
        self._last = np.zeros(0, np.float32)
        self.reset()

    def reset(self) -> None:
        """A new episode: the LSTM state (recurrent models) and the stacked history start afresh."""
        self._lstm: Any = None
        self._starts = np.ones(1, dtype=bool)
        self._fresh = True

    def note_applied(self, action: np.ndarray) -> None:
        """The action the env got this step (a residual policy's mix): the history records it."""
        self._last = np.asarray(action, dtype=np.float32)

    def _stacked(self, obs: np.ndarray) -> np.ndarray:
        """``obs`` as the model saw it in training: itself, or (a plain observation of a model trained with
        ``history``) the stack of the last samples and actions."""
        expected = self.model.observation_space.shape
        if obs.shape == expected or not self.history:
            return obs
        if self._stack is None:
            from lvgym.envs.history import HistoryStack
            from lvgym.envs.layouts import ACTIONS

            base = _plain_layout(int(obs.shape[0]))
            stack = HistoryStack(base, ACTIONS["tvc"], self.history)
            if (stack.size,) != expected:
                raise ValueError(f"policy {self.name!r}: observation of shape {obs.shape} with history "
                                 f"{self.history} stacks to ({stack.size},), trained on {expected}")
            self._stack, self._buf = stack, stack.zeros(1)
        if self._fresh:
            self._stack.reset(self._buf, [0], obs[None])
        else:
            from lvgym.envs.history import recorded_action

            self._stack.push(self._buf, obs[None], recorded_action("tvc", self._last[None]))
        return self._buf[0].copy()

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """The action for one observation of the env's observation space (or, for a model trained with
        ``history``, of the plain observation: the history is stacked here)."""
        obs = self._stacked(np.asarray(observation, dtype=np.float32))
        self._fresh = False
        expected = self.model.observation_space.shape
        if obs.shape != expected:
            raise ValueError(f"policy {self.name!r}: observation of shape {obs.shape}, trained on {expected}")
        action = self._predict(obs)
        self._last = np.asarray(action, dtype=np.float32)
        return action

    def batch(self, n: int) -> Any:
        """The same policy for ``n`` rows of a batched env (:class:`lvgym.agents.policybatch.SB3Batch`, the
        interface of :mod:`lvgym.benchmark.batch`): each row's actions are the bits :meth:`act` gives it."""
        from .policybatch import SB3Batch

        return SB3Batch(self, n)

    def act_batch(self, observations: np.ndarray, episode_start: np.ndarray) -> np.ndarray:
        """Actions (B, n_a) for the observations (B, n_obs) of B env rows (a batched env's, with the
        model's own observation: a ``history`` env stacks natively); ``episode_start`` (B,) bool marks the
        rows whose episode begins with this observation (their LSTM state restarts)."""
        obs = np.asarray(observations, dtype=np.float32)
        if self.normalizer is not None and getattr(self.normalizer, "norm_obs", True):
            obs = np.asarray(self.normalizer.normalize_obs(obs), dtype=np.float32)
        starts = np.asarray(episode_start, dtype=bool)
        if not self.recurrent:
            return np.asarray(self.model.predict(obs, deterministic=self.deterministic)[0])
        if self._lstm is not None and np.shape(self._lstm[0])[1] != obs.shape[0]:
            self._lstm = None
        action, self._lstm = self.model.predict(obs, state=self._lstm, episode_start=starts,
                                                deterministic=self.deterministic)
        return np.asarray(action)

    def _predict(self, obs: np.ndarray) -> np.ndarray:
        if self.normalizer is not None and getattr(self.normalizer, "norm_obs", True):
            obs = np.asarray(self.normalizer.normalize_obs(obs), dtype=np.float32)
        if self.recurrent:                         # the LSTM state goes on, restarted at an episode's start
            action, self._lstm = self.model.predict(obs[None], state=self._lstm, episode_start=self._starts,
                                                    deterministic=self.deterministic)
            self._starts = np.zeros(1, dtype=bool)
            return np.asarray(action)[0]
        fast = self._fast_path()
        if fast is None:
            action, _ = self.model.predict(obs, deterministic=self.deterministic)
            return np.asarray(action)
        import torch

        policy, low, high = fast
        with torch.no_grad():                      # what model.predict does, without its per-call checks
            out = policy._predict(torch.as_tensor(obs[None]), deterministic=self.deterministic)
        return np.clip(out.cpu().numpy().reshape(low.shape), low, high)

    def _fast_path(self) -> tuple[Any, np.ndarray, np.ndarray] | None:
        """``(policy, low, high)`` when ``model.predict`` of one flat observation reduces to the policy's
        ``_predict`` and a clip to the Box (no image transposition, no squashing, on the CPU), else None.
        About three times faster per step than ``predict`` (tests/test_agents.py checks both agree)."""
        if not hasattr(self, "_fast"):
            from gymnasium import spaces

            m = self.model
            pol = getattr(m, "policy", None)
            ok = (pol is not None and isinstance(m.action_space, spaces.Box)
                  and isinstance(m.observation_space, spaces.Box) and len(m.observation_space.shape) == 1
                  and not getattr(pol, "squash_output", False) and str(getattr(m, "device", "cpu")) == "cpu"
                  and not self.recurrent)
            if ok:
                pol.set_training_mode(False)
            self._fast = (pol, m.action_space.low, m.action_space.high) if ok else None
        return self._fast


#: the folder of the shipped policies (each ``<file>.zip`` beside its ``_vecnormalize.pkl`` and its sidecar
#: JSON, which holds the training set-up; the commands that reproduce them are in docs/training.md)
TRAINED = Path(__file__).resolve().parent / "trained"
#: the policy shipped for ``lvgym/SmileAscent-v0``
SHIPPED = TRAINED / "ppo_smile_ascent.zip"


def shipped_policy(name: str = "ppo", file: str = "ppo_smile_ascent", env: Any = None) -> Any:
    """A shipped policy, ``agents/trained/<file>.zip`` (default: the PPO of ``lvgym/SmileAscent-v0``), as
    :func:`load_policy` makes it: on its baseline, built on ``env``, when it was trained residual."""
    path = TRAINED / f"{file}.zip"
    if not path.is_file():
        raise FileNotFoundError(f"the shipped policy {str(path)!r} is missing (see docs/training.md)")
    return load_policy(path, name, env)


def load_policy(path: str | Path, name: str | None = None, env: Any = None) -> Any:
    """``SB3Policy(path, name)``, or for a run trained residual on a baseline (its sidecar's ``residual``)
    the :class:`~lvgym.agents.residual.ResidualPolicy` of it on that baseline, rebuilt on ``env``: a factory for
    ``lvgym.benchmark.PolicySpec("...", "lvgym.agents.policy:load_policy", (("path", ...),))``."""
    return adapt(SB3Policy(path, name), env)


#: the env options that give a policy privileged observations (a teacher's: lvgym.envs.options)
PRIVILEGED_OBSERVATIONS = ("fault_info",)


def privileged_env_options(env_kwargs: dict[str, Any] | None) -> dict[str, Any]:
    """The privileged observation options among a run's env keywords (e.g. ``{"fault_info": True}``)."""
    kwargs = env_kwargs or {}
    return {k: kwargs[k] for k in PRIVILEGED_OBSERVATIONS if kwargs.get(k)}


def privileged_options(path: str | Path, **_: Any) -> dict[str, Any]:
    """The privileged observation options the saved policy at ``path`` was trained with (its sidecar's
    ``env_kwargs``, e.g. ``{"fault_info": True}`` for a teacher): the benchmark flies it with them, and
    counts it as privileged (:func:`lvgym.benchmark.runner.policy_options`). Empty for a causal policy."""
    return privileged_env_options(read_meta(resolve_model_path(path)).get("env_kwargs"))


#: their kind in protocol v2's headline (lvgym.benchmark.headline): trained models
shipped_policy.kind = load_policy.kind = "learned"  # type: ignore[attr-defined]
load_policy.condition_options = privileged_options  # type: ignore[attr-defined]


def adapt(policy: SB3Policy, env: Any) -> Any:
    """``policy`` as the env flies it: on its baseline when its meta records a residual run (built on
    ``env``, which must then be given), else itself."""
    from .residual import ResidualConfig, ResidualPolicy

    residual = ResidualConfig.from_meta(policy.meta)
    if residual is None:
        return policy
    if env is None:
        raise ValueError(f"policy {policy.name!r} is residual on {residual.baseline!r}: its baseline needs the env")
    return ResidualPolicy(policy, residual, env)


@functools.lru_cache(maxsize=8)
def _plain_layout(n: int) -> Any:
    """A layout of ``n`` unnamed observation entries (what the adapter stacks without the env's names)."""
    from lvgym.packing import Field, Packed

    return Packed("observation", [Field("entry", n, "-", "observation entries")], interface=True)


@dataclasses.dataclass
class ExportArgs:
    """Command-line arguments (``lvgym export-policy --help``)."""

    run: str = arg(positional=True, metavar="RUN")
    """run folder (runs/<name>: its best, else final, else latest model) or a .zip"""
    stem: str = arg(positional=True, metavar="STEM")
    """destination without suffix, e.g. agents/trained/ppo_smile_ascent"""


def export_main(argv: list[str] | None = None) -> None:
    """``lvgym export-policy RUN STEM``: copy a run's policy (best, else final, else latest) to STEM.zip,
    STEM_vecnormalize.pkl and STEM.json."""
    from lvgym.commandline import command_name, fail, parse

    prog = "python -m lvgym.agents.policy export"
    args = parse(ExportArgs, argv, prog, export_main.__doc__)
    try:
        src = resolve_model_path(args.run)
    except (FileNotFoundError, ValueError) as exc:
        fail(command_name(prog), exc)
    dst = copy_policy(src, args.stem, {"exported_from": str(src)})
    print(f"{src} -> {dst}")


def main(argv: list[str] | None = None) -> None:
    """``python -m lvgym.agents.policy export RUN STEM`` (``lvgym export-policy RUN STEM``)."""
    from lvgym.commandline import Command, dispatch

    dispatch([Command("export", "lvgym.agents.policy:export_main", "copy a run's policy to STEM.zip, "
                      "STEM_vecnormalize.pkl, STEM.json")], argv, "python -m lvgym.agents.policy")


if __name__ == "__main__":
    main()


__all__ = ["PRIVILEGED_OBSERVATIONS", "SB3Policy", "adapt", "copy_policy", "load_model", "load_policy",
           "load_vecnormalize", "policy_files", "privileged_env_options", "privileged_options", "read_meta", "resolve_model_path", "save_policy"]
