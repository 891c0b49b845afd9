"""A saved stable-baselines3 model as a benchmark :class:`~.policy.Policy`.

``SB3Policy("runs/ppo_smile.zip")`` loads the model on the CPU and acts with
``model.predict(observation, deterministic=True)``. The algorithm is read from a sidecar
``<stem>.json`` (``{"algo": "PPO"}``) when there is one, else guessed from the policy class stored in
the zip (``sac`` -> SAC, ``td3`` -> TD3, actor-critic -> PPO) and, failing that, found by trying PPO,
SAC, TD3, A2C and DDPG in turn. A ``<stem>_vecnormalize.pkl`` next to the zip (a pickled SB3
``VecNormalize``, as ``VecNormalize.save`` writes it) normalises the observations as in training.
"""

from __future__ import annotations

import json
import pickle
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

ALGOS = ("PPO", "SAC", "TD3", "A2C", "DDPG")


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


def load_model(path: str | Path) -> Any:
    """The SB3 model saved at ``path`` (see the module docstring for how the algorithm is chosen)."""
    import stable_baselines3 as sb3

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"policy {str(path)!r}: no such SB3 model file")
    first = _sidecar_algo(path) or _guess_algo(path)
    order = [first] + [a for a in ALGOS if a != first] if first else list(ALGOS)
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


class SB3Policy:
    """A saved SB3 model acting deterministically; ``name`` is the file stem unless given."""

    def __init__(self, path: str, name: str | None = None) -> None:
        p = Path(path)
        self.path = str(p)
        self.name = name or p.stem
        self.model = load_model(p)
        norm = p.with_name(f"{p.stem}_vecnormalize.pkl")
        self.normalizer: Any = None
        if norm.is_file():
            with open(norm, "rb") as f:
                self.normalizer = pickle.load(f)
            self.normalizer.training = False

    def reset(self) -> None:
        """Nothing to reset (feed-forward policies)."""

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """``model.predict(observation, deterministic=True)`` on the (normalised) observation."""
        obs = np.asarray(observation, dtype=np.float32)
        if self.normalizer is not None:
            obs = np.asarray(self.normalizer.normalize_obs(obs), dtype=np.float32)
        action, _ = self.model.predict(obs, deterministic=True)
        return np.asarray(action)
