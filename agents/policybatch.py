"""A trained SB3 model for the rows of a batched env (:meth:`lvgym.agents.policy.SB3Policy.batch`), acting as the
policy acts one row at a time, to the bit.

Torch's batched forward is not the per-row one: a linear layer of one observation runs as a matrix-vector
product, of many as a matrix-matrix product, and the two sum in other orders (float32: the actions differ
in the last bits for most rows). So the rows run one at a time, but without ``model.predict``'s per-call
work: for an actor-critic MLP policy (PPO, A2C: a flattened observation, linear layers and elementwise
activations, a diagonal Gaussian whose deterministic action is its mean) :class:`MlpRows` evaluates the
actor's layers on each row as ``addmv``, the matrix-vector product the one-observation forward runs,
checked against the policy's own ``_predict`` on probe observations when built (a torch whose products
differ falls back). Other models run the policy's ``_predict`` (or ``model.predict``) per row; recurrent
ones keep each row's LSTM state (a recurrent actor-critic as a tensor, its ``_predict`` called directly:
:meth:`SB3Batch._recurrent_rows`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["MlpRows", "SB3Batch"]

#: probe observations the compiled-per-row forward is checked on against ``_predict`` [-]
PROBES = 16


class MlpRows:
    """The deterministic actor of an SB3 ``ActorCriticPolicy`` MLP, one row at a time (the module docstring):
    ``__call__(obs (m, n) float32) -> (m, n_a)`` float32 means, before the clip to the action space.
    :meth:`build` gives None for a policy of another structure or whose products this one does not
    reproduce."""

    def __init__(self, layers: list[Any], out: tuple[Any, Any]) -> None:
        self.layers, self.out = layers, out

    @classmethod
    def build(cls, policy: Any) -> MlpRows | None:
        import torch
        from stable_baselines3.common.distributions import DiagGaussianDistribution
        from stable_baselines3.common.policies import ActorCriticPolicy
        from stable_baselines3.common.torch_layers import FlattenExtractor, MlpExtractor

        if type(policy) is not ActorCriticPolicy or not isinstance(policy.action_dist, DiagGaussianDistribution):
            return None
        if type(policy.pi_features_extractor) is not FlattenExtractor or len(policy.observation_space.shape) != 1:
            return None
        if type(policy.mlp_extractor) is not MlpExtractor:        # its forward_actor is policy_net's forward
            return None
        net = policy.mlp_extractor.policy_net
        elementwise = (torch.nn.Tanh, torch.nn.ReLU, torch.nn.ELU, torch.nn.LeakyReLU, torch.nn.Identity)
        if not isinstance(net, torch.nn.Sequential):
            return None
        layers: list[Any] = []
        for m in net:
            if isinstance(m, torch.nn.Linear) and m.bias is not None:
                layers.append((m.weight.detach(), m.bias.detach()))
            elif isinstance(m, elementwise):
                layers.append(m)
            else:
                return None
        a = policy.action_net
        if not isinstance(a, torch.nn.Linear) or a.bias is None:
            return None
        rows = cls(layers, (a.weight.detach(), a.bias.detach()))
        probe = np.random.default_rng(0).normal(0.0, 2.0, (PROBES, *policy.observation_space.shape)).astype(np.float32)
        with torch.no_grad():
            want = np.stack([policy._predict(torch.as_tensor(probe[i:i + 1]), deterministic=True).numpy()[0]
                             for i in range(PROBES)])
        return rows if np.array_equal(rows(probe), want.reshape(PROBES, -1)) else None

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        import torch

        x = torch.as_tensor(np.ascontiguousarray(obs, dtype=np.float32))
        W, b = self.out
        out = np.empty((x.shape[0], W.shape[0]), np.float32)
        with torch.no_grad():
            for i in range(x.shape[0]):
                h = x[i]
                for layer in self.layers:
                    h = torch.addmv(layer[1], layer[0], h) if isinstance(layer, tuple) else layer(h)
                out[i] = torch.addmv(b, W, h).numpy()
        return out


class SB3Batch:
    """:class:`~lvgym.agents.policy.SB3Policy` for ``n`` rows (the batched interface of
    :mod:`lvgym.benchmark.batch`): each row's actions are those the policy gives that row alone, its
    observation normalised and (for a model trained with ``history`` flown on a plain observation) stacked
    per row with the action the row last applied (:meth:`note_applied`)."""

    def __init__(self, policy: Any, n: int) -> None:
        self.policy, self.n, self.name = policy, int(n), policy.name
        self.model, self.normalizer = policy.model, policy.normalizer
        self.expected = tuple(self.model.observation_space.shape)
        self._fresh = np.ones(self.n, dtype=bool)
        self._last = np.zeros((self.n, 0), np.float32)
        self._stack: Any = None
        self._buf = np.zeros((self.n, 0), np.float32)
        self._lstm: list[Any] = [None] * self.n
        self._starts = np.ones(self.n, dtype=bool)
        fast = policy._fast_path()
        self._mlp = MlpRows.build(fast[0]) if fast is not None else None
        pol = getattr(self.model, "policy", None)
        self._lstm_rows = bool(policy.recurrent and hasattr(pol, "lstm_hidden_state_shape")
                               and not pol.squash_output and len(self.expected) == 1)

    def reset(self, rows: Any) -> None:
        """The rows ``rows`` start an episode (their history and LSTM state restart)."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        self._fresh[rows] = True
        self._starts[rows] = True
        for b in rows.tolist():
            self._lstm[b] = None

    def note_applied(self, rows: Any, actions: np.ndarray) -> None:
        """The actions the env got this step for the rows ``rows`` (a residual policy's mix)."""
        self._remember(np.asarray(rows, dtype=np.int64).reshape(-1), actions)

    def _remember(self, rows: np.ndarray, actions: Any) -> None:
        a = np.asarray(actions, dtype=np.float32).reshape(rows.size, -1)
        if self._last.shape[1] != a.shape[1]:
            self._last = np.zeros((self.n, a.shape[1]), np.float32)
        self._last[rows] = a

    def _stacked(self, rows: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """The rows' observations as the model saw them in training (as ``SB3Policy._stacked``, per row)."""
        if obs.shape[1:] == self.expected or not self.policy.history:
            return obs
        from lvgym.envs.history import HistoryStack, recorded_action
        from lvgym.envs.layouts import ACTIONS

        from .policy import _plain_layout

        if self._stack is None:
            stack = HistoryStack(_plain_layout(int(obs.shape[1])), ACTIONS["tvc"], self.policy.history)
            if (stack.size,) != self.expected:
                raise ValueError(f"policy {self.name!r}: observation of shape {obs.shape[1:]} with history "
                                 f"{self.policy.history} stacks to ({stack.size},), trained on {self.expected}")
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

    def act(self, rows: Any, observations: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """Actions (len(rows), n_a) of the rows ``rows`` for their observations."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = self._stacked(rows, np.asarray(observations, dtype=np.float32).reshape(rows.size, -1))
        self._fresh[rows] = False
        if obs.shape[1:] != self.expected:
            raise ValueError(f"policy {self.name!r}: observation of shape {obs.shape[1:]}, trained on {self.expected}")
        actions = self._predict(rows, obs)
        self._remember(rows, actions)
        return actions

    def _predict(self, rows: np.ndarray, obs: np.ndarray) -> np.ndarray:
        p = self.policy
        if self.normalizer is not None and getattr(self.normalizer, "norm_obs", True):
            obs = np.asarray(self.normalizer.normalize_obs(obs), dtype=np.float32)
        if p.recurrent and self._lstm_rows:
            return self._recurrent_rows(rows, obs)
        if p.recurrent:                                   # each row's LSTM state, as the policy keeps its own
            out = []
            for j, b in enumerate(rows.tolist()):
                action, self._lstm[b] = self.model.predict(obs[j][None], state=self._lstm[b],
                                                           episode_start=self._starts[b:b + 1].copy(),
                                                           deterministic=p.deterministic)
                self._starts[b] = False
                out.append(np.asarray(action)[0])
            return np.asarray(out)
        fast = p._fast_path()
        if fast is None:
            return np.asarray([np.asarray(self.model.predict(o, deterministic=p.deterministic)[0]) for o in obs])
        policy, low, high = fast
        if self._mlp is not None and p.deterministic:
            return np.clip(self._mlp(obs).reshape(rows.size, *low.shape), low, high)
        import torch

        with torch.no_grad():
            out = [policy._predict(torch.as_tensor(obs[j:j + 1]), deterministic=p.deterministic).cpu().numpy()
                   for j in range(rows.size)]
        return np.clip(np.concatenate(out).reshape(rows.size, *low.shape), low, high)

    def _recurrent_rows(self, rows: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """A recurrent actor-critic's actions row by row, as ``model.predict`` gives them for one row (the same
        ``_predict`` on the same float32 tensors, zero state at a row's first step, the clip to the action
        space), without its per-call conversions: each row's LSTM state stays a tensor."""
        import torch

        policy, space = self.model.policy, self.model.action_space
        policy.set_training_mode(False)
        out = np.empty((rows.size, *space.shape), np.float32)
        with torch.no_grad():
            for j, b in enumerate(rows.tolist()):
                state = self._lstm[b]
                if state is None:
                    zero = torch.zeros(policy.lstm_hidden_state_shape, dtype=torch.float32)
                    state = (zero, zero)
                start = torch.tensor([float(self._starts[b])], dtype=torch.float32)
                action, self._lstm[b] = policy._predict(torch.as_tensor(obs[j:j + 1]), lstm_states=state,
                                                        episode_starts=start, deterministic=self.policy.deterministic)
                self._starts[b] = False
                out[j] = action.cpu().numpy().reshape(space.shape)
        return np.clip(out, space.low, space.high)
