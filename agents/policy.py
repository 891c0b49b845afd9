"""A trained stable-baselines3 model as a benchmark :class:`~lvgym.benchmark.policy.Policy`, and the files
a saved policy is made of.

A saved policy is three files with one stem::

    <stem>.zip                  the SB3 model (``model.save``)
    <stem>_vecnormalize.pkl     the VecNormalize statistics (``VecNormalize.save``), if training normalised
    <stem>.json                 {"algo": "PPO", "env_id": ..., "env_kwargs": {...}, "num_timesteps": ...}

``evaluate.py`` loads saved models through :func:`load_policy`. :class:`SB3Policy` accepts such a ``.zip``, its stem, or a run folder of ``train.py`` (``runs/<name>``: its best model by
validation, else its final model, else its last checkpoint).

    python -m agents.policy export runs/ppo-smile agents/trained/ppo_smile_ascent   # copy a run's policy
"""

from __future__ import annotations

import argparse
import json
import pickle
import shutil
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.benchmark.results import atomic_path, atomic_write_text

from .config import ALGOS

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
    atomic_write_text(json_path, json.dumps({**meta, "algo": str(meta["algo"]).upper()}, indent=1, sort_keys=True))
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
        from agents.callbacks import latest_checkpoint

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
        return str(algo).upper() if algo else None
    return None


def _guess_algo(path: Path) -> str | None:
    """The algorithm suggested by the policy class module stored in the zip's ``data``."""
    try:
        with zipfile.ZipFile(path) as z:
            data = json.loads(z.read("data"))
        module = str(data.get("policy_class", {}).get("__module__", ""))
    except (KeyError, ValueError, zipfile.BadZipFile, AttributeError):
        return None
    for key, algo in (("sac", "SAC"), ("td3", "TD3"), ("ddpg", "DDPG"), ("common.policies", "PPO")):
        if key in module:
            return algo
    return None


def guess_and_load(path: str | Path) -> Any:
    """The SB3 model at ``path`` when no sidecar names its algorithm: the algorithm suggested by the
    policy class stored in the zip first, then every algorithm train.py trains
    (:data:`agents.config.ALGOS`) in turn."""
    import stable_baselines3 as sb3

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"policy {str(path)!r}: no such SB3 model file")
    first = _sidecar_algo(path) or _guess_algo(path)
    known = list(ALGOS.values())
    order = [first] + [a for a in known if a != first] if first else known
    errors = []
    for algo in order:
        cls = getattr(sb3, algo, None)
        if cls is None:
            errors.append(f"{algo}: not in stable_baselines3")
            continue
        try:
            return cls.load(str(path), device="cpu")
        except Exception as exc:  # noqa: BLE001 (a wrong algorithm fails in many ways)
            errors.append(f"{algo}: {type(exc).__name__}: {exc}")
    raise ValueError(f"policy {str(path)!r}: no SB3 algorithm loads it ({'; '.join(errors)}); "
                     f"add a sidecar {path.with_suffix('.json').name} with {{\"algo\": \"PPO\"}}")


def read_meta(zip_path: str | Path) -> dict[str, Any]:
    """The sidecar JSON of a saved policy (``{}`` when it has none)."""
    side = policy_files(zip_path)[2]
    return json.loads(side.read_text(encoding="utf-8")) if side.is_file() else {}


def load_model(zip_path: str | Path, algo: str | None = None) -> Any:
    """The SB3 model at ``zip_path`` on the CPU: class from ``algo``, else from the sidecar JSON, else
    guessed by :func:`guess_and_load` (policies saved by other tools)."""
    import stable_baselines3 as sb3

    algo = algo or read_meta(zip_path).get("algo")
    if algo is None:
        return guess_and_load(zip_path)
    name = ALGOS.get(str(algo).lower(), str(algo).upper())
    cls = getattr(sb3, name, None)
    if cls is None:
        raise ValueError(f"{str(zip_path)!r}: algo = {algo!r}: one of {sorted(ALGOS.values())}")
    return cls.load(str(zip_path), device="cpu")


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

    @classmethod
    def from_model(cls, model: Any, normalizer: Any = None, name: str = "agent",
                   deterministic: bool = True) -> SB3Policy:
        """A live model (and a VecNormalize whose statistics it was trained with) as a policy. The
        statistics are copied and frozen: later training does not change this policy."""
        self = cls.__new__(cls)
        self.path, self.meta, self.model, self.name = "", {}, model, name
        self.deterministic = bool(deterministic)
        self.normalizer = None
        if normalizer is not None:
            import copy

            self.normalizer = copy.copy(normalizer)
            self.normalizer.obs_rms = copy.deepcopy(normalizer.obs_rms)
            self.normalizer.training = False
        return self

    def reset(self) -> None:
        """Nothing to reset (feed-forward networks)."""

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """The action for one observation of the env's observation space."""
        obs = np.asarray(observation, dtype=np.float32)
        expected = self.model.observation_space.shape
        if obs.shape != expected:
            raise ValueError(f"policy {self.name!r}: observation of shape {obs.shape}, trained on {expected}")
        if self.normalizer is not None and getattr(self.normalizer, "norm_obs", True):
            obs = np.asarray(self.normalizer.normalize_obs(obs), dtype=np.float32)
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
                  and not getattr(pol, "squash_output", False) and str(getattr(m, "device", "cpu")) == "cpu")
            if ok:
                pol.set_training_mode(False)
            self._fast = (pol, m.action_space.low, m.action_space.high) if ok else None
        return self._fast


#: the policy shipped for ``lvgym/SmileAscent-v0`` (its sidecar JSON holds the training set-up; the command
#: that reproduces it is in docs/training.md)
SHIPPED = Path(__file__).resolve().parent / "trained" / "ppo_smile_ascent.zip"


def shipped_policy(name: str = "ppo") -> SB3Policy:
    """The shipped PPO policy of ``lvgym/SmileAscent-v0`` (``agents/trained/ppo_smile_ascent``)."""
    if not SHIPPED.is_file():
        raise FileNotFoundError(f"the shipped policy {str(SHIPPED)!r} is missing (see docs/training.md)")
    return SB3Policy(SHIPPED, name)


def load_policy(path: str | Path, name: str | None = None) -> SB3Policy:
    """``SB3Policy(path, name)``: a factory for ``lvgym.benchmark.PolicySpec("...", "agents.policy:load_policy",
    (("path", ...),))``."""
    return SB3Policy(path, name)


def _export(args: argparse.Namespace) -> None:
    src = resolve_model_path(args.run)
    dst = copy_policy(src, args.stem, {"exported_from": str(src)})
    print(f"{src} -> {dst}")


def main(argv: list[str] | None = None) -> None:
    """``python -m agents.policy export RUN STEM``: copy a run's policy (best, else final, else latest)."""
    p = argparse.ArgumentParser(prog="python -m agents.policy", description=main.__doc__)
    sub = p.add_subparsers(dest="cmd", required=True)
    e = sub.add_parser("export", help="copy a run's policy to STEM.zip, STEM_vecnormalize.pkl, STEM.json")
    e.add_argument("run", help="run folder (runs/<name>) or a .zip")
    e.add_argument("stem", help="destination without suffix, e.g. agents/trained/ppo_smile_ascent")
    args = p.parse_args(argv)
    _export(args)


if __name__ == "__main__":
    main()


__all__ = ["SB3Policy", "copy_policy", "load_model", "load_policy", "load_vecnormalize", "policy_files",
           "read_meta", "resolve_model_path", "save_policy"]
