"""A trained stable-baselines3 model as a batch law (:class:`SB3Law`) with its one-row face, the benchmark
:class:`~lvgym.benchmark.policy.Policy` (:class:`SB3Policy`), and the factories that fly a saved one
(:func:`load_policy`) or a shipped one (:func:`shipped_policy`).

``evaluate.py`` loads saved models through :func:`load_policy`. :class:`SB3Policy` accepts a saved ``.zip``
(its files: :mod:`lvgym.agents.policies.saved`), its stem, or a run folder of ``train.py`` (``runs/<name>``: its
best model by validation, else its final model, else its last checkpoint).
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace

from .algos import algo_name
from .mlp import MlpNet
from .saved import load_model, read_meta, resolve_model_path, statistics


def actor_net(model: Any) -> MlpNet | None:
    """The deterministic actor of ``model`` as an :class:`~lvgym.agents.policies.mlp.MlpNet` when its ``predict`` of a
    flat observation is that network and a clip to the action's Box: an actor-critic MLP policy (PPO, A2C: a
    flattened observation, linear layers and :data:`~lvgym.agents.policies.mlp.ACTIVATIONS`, a diagonal Gaussian whose
    deterministic action is its mean; on the CPU, no squashing). None otherwise."""
    from gymnasium import spaces
    from stable_baselines3.common.distributions import DiagGaussianDistribution
    from stable_baselines3.common.policies import ActorCriticPolicy
    from stable_baselines3.common.torch_layers import FlattenExtractor, MlpExtractor

    pol = getattr(model, "policy", None)
    if (type(pol) is not ActorCriticPolicy or not isinstance(pol.action_dist, DiagGaussianDistribution)
            or type(pol.pi_features_extractor) is not FlattenExtractor or type(pol.mlp_extractor) is not MlpExtractor
            or not isinstance(model.action_space, spaces.Box) or not isinstance(model.observation_space, spaces.Box)
            or len(model.observation_space.shape) != 1 or getattr(pol, "squash_output", False)):
        return None
    return MlpNet.from_torch([*pol.mlp_extractor.policy_net, pol.action_net])


class SB3Law(BatchLaw):
    """A trained SB3 model flying ``n`` rows: each row's observation normalised with the training run's frozen
    VecNormalize statistics (``normalizer``) and, for a model trained with ``history`` flown on a plain
    observation, stacked per row with the action the row last applied (:meth:`note_applied`); the action is the
    model's deterministic one, inside the action space. An actor-critic MLP (every shipped policy) flies through
    its compiled forward (:func:`actor_net`, :mod:`lvgym.agents.policies.mlp`: each row on its own, the same bits in any
    batch); another model (a recurrent, SAC or TD3 model) through its own batched ``predict``, with each row's
    LSTM state kept (its rows then agree with a batch of one to float32 rounding)."""

    def __init__(self, model: Any, normalizer: Any = None, name: str = "agent", deterministic: bool = True,
                 meta: dict[str, Any] | None = None, path: str = "", n: int = 1) -> None:
        self.model, self.normalizer, self.name, self.path = model, normalizer, name, path
        self.meta = dict(meta or {})
        self.deterministic = bool(deterministic)
        self.recurrent = algo_name(type(model).__name__) == "RecurrentPPO"
        self.history = int((self.meta.get("env_kwargs") or {}).get("history", 0) or 0)
        self.expected = tuple(model.observation_space.shape)
        self.net = actor_net(model) if self.deterministic and not self.recurrent else None
        if self.net is not None:
            self.low, self.high = model.action_space.low, model.action_space.high
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self._fresh = np.ones(n, dtype=bool)
        self._last = np.zeros((n, 0), np.float32)
        self._stack: Any = None
        self._buf = np.zeros((n, 0), np.float32)
        self._lstm: tuple[np.ndarray, np.ndarray] | None = None     # (layers, n, hidden) each

    def reset(self, rows: Any) -> None:
        """The rows ``rows`` start an episode (their history and LSTM state restart)."""
        self._fresh[np.asarray(rows, dtype=np.int64).reshape(-1)] = True

    def note_applied(self, rows: Any, actions: np.ndarray) -> None:
        """The actions the env got this step for the rows ``rows`` (a residual policy's mix): the history
        records them."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        a = np.asarray(actions, dtype=np.float32).reshape(rows.size, -1)
        if self._last.shape[1] != a.shape[1]:
            self._last = np.zeros((self.n, a.shape[1]), np.float32)
        self._last[rows] = a

    def _stacked(self, rows: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """The rows' observations as the model saw them in training: themselves, or (a plain observation of a
        model trained with ``history``) the stack of each row's last samples and actions."""
        if obs.shape[1:] == self.expected or not self.history:
            return obs
        from lvgym.envs.history import HistoryStack, recorded_action
        from lvgym.envs.layouts import ACTIONS

        if self._stack is None:
            stack = HistoryStack(_plain_layout(int(obs.shape[1])), ACTIONS["tvc"], self.history)
            if (stack.size,) != self.expected:
                raise ValueError(f"policy {self.name!r}: observation of shape {obs.shape[1:]} with history "
                                 f"{self.history} stacks to ({stack.size},), trained on {self.expected}")
            self._stack, self._buf = stack, stack.zeros(self.n)
        fresh = self._fresh[rows]
        if fresh.any():
            self._stack.reset(self._buf, rows[fresh], obs[fresh])
        if not fresh.all():
            old = rows[~fresh]
            part = self._buf[old]
            self._stack.push(part, obs[~fresh], recorded_action("tvc", self._last[old]))
            self._buf[old] = part
        return self._buf[rows].copy()

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """Actions (len(rows), n_a) of the rows ``rows`` for their observations."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = self._stacked(rows, np.asarray(observations, dtype=np.float32).reshape(rows.size, -1))
        if obs.shape[1:] != self.expected:
            raise ValueError(f"policy {self.name!r}: observation of shape {obs.shape[1:]}, trained on {self.expected}")
        if self.normalizer is not None and getattr(self.normalizer, "norm_obs", True):
            obs = np.asarray(self.normalizer.normalize_obs(obs), dtype=np.float32)
        if self.net is not None:
            actions = np.clip(self.net(obs), self.low, self.high)
        elif self.recurrent:
            actions = self._recurrent(rows, obs)
        else:
            actions = np.asarray(self.model.predict(obs, deterministic=self.deterministic)[0])
        self._fresh[rows] = False
        self.note_applied(rows, actions)
        return actions

    def _recurrent(self, rows: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """A recurrent model's actions for the rows, each row's LSTM state kept (restarted at its first step)."""
        starts = self._fresh[rows].copy()
        state = None
        if self._lstm is not None:
            state = (self._lstm[0][:, rows], self._lstm[1][:, rows])
        action, (h, c) = self.model.predict(obs, state=state, episode_start=starts, deterministic=self.deterministic)
        if self._lstm is None:
            self._lstm = (np.zeros((h.shape[0], self.n, h.shape[2]), h.dtype), np.zeros((c.shape[0], self.n,
                                                                                         c.shape[2]), c.dtype))
        self._lstm[0][:, rows], self._lstm[1][:, rows] = h, c
        return np.asarray(action)


class SB3Policy(RowFace):
    """A trained SB3 model behind the benchmark's Policy interface: one row of :class:`SB3Law`. It accepts a
    saved ``.zip``, its stem, or a run folder of ``train.py`` (``runs/<name>``: its best model by validation,
    else its final model, else its last checkpoint); ``name`` defaults to the file stem (the run name for a run
    folder). It flies with the VecNormalize statistics the model was trained with (the file ``vecnormalize``, else
    its own: :func:`lvgym.agents.policies.saved.statistics`, which refuses a model trained under VecNormalize
    without them)."""

    def __init__(self, path: str | Path, name: str | None = None, deterministic: bool = True,
                 vecnormalize: str | Path | None = None) -> None:
        zip_path = resolve_model_path(path)
        p = Path(path)
        self.law = SB3Law(load_model(zip_path), statistics(zip_path, vecnormalize),
                          name or (p.resolve().name if p.is_dir() else zip_path.stem), deterministic,
                          read_meta(zip_path), str(zip_path))

    @classmethod
    def from_model(cls, model: Any, normalizer: Any = None, name: str = "agent",
                   deterministic: bool = True, meta: dict[str, Any] | None = None) -> SB3Policy:
        """A live model (and a VecNormalize whose statistics it was trained with) as a policy. The
        statistics are copied and frozen: later training does not change this policy. ``meta``: the
        run's sidecar fields (its ``env_kwargs`` say whether the observation has a ``history``)."""
        frozen = None
        if normalizer is not None:
            import copy

            frozen = copy.copy(normalizer)
            frozen.obs_rms = copy.deepcopy(normalizer.obs_rms)
            frozen.training = False
        self = cls.__new__(cls)
        self.law = SB3Law(model, frozen, name, deterministic, meta)
        return self


#: the folder of the shipped policies (each ``<file>.zip`` beside its ``_vecnormalize.pkl`` and its sidecar
#: JSON, which holds the training set-up; the commands that reproduce them are in docs/training.md)
TRAINED = Path(__file__).resolve().parents[1] / "trained"
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
    """``SB3Policy(path, name)``, or for a run trained residual on a baseline (its sidecar's ``residual``) the
    :class:`~lvgym.agents.policies.residual.ResidualPolicy` of it on that baseline, rebuilt on ``env``: a factory for
    ``lvgym.benchmark.PolicySpec("...", "lvgym.agents.policies.sb3:load_policy", (("path", ...),))``."""
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


__all__ = ["PRIVILEGED_OBSERVATIONS", "SB3Law", "SB3Policy", "actor_net", "adapt", "load_policy",
           "privileged_env_options", "privileged_options"]
