"""PPO at the batched env's speed: one readable file in the style of CleanRL's ``ppo_continuous_action.py``, over
the native Gymnasium ``VectorEnv`` of the batch core (``lvgym.make_vec_env(suite, model, n)``, ``next_step``
autoreset) with no Python per row.

What it is: a diagonal Gaussian policy with a state-independent log standard deviation, generalised advantage
estimation, the clipped surrogate objective, a value loss, Adam with the gradient's norm clipped, minibatches
drawn from every sample of a rollout for a few epochs, the learning rate constant or falling linearly to 0. The
observations are normalised by their running mean and variance (updated every step with the batch, as
stable-baselines3's ``VecNormalize`` does) and the rewards, optionally, by the running standard deviation of the
discounted return (the same).

Why it is fast where SB3 is not, on two cores: the rollout's buffers are preallocated torch tensors written one
env step (all rows) at a time; the episode accounting is NumPy over the rows; no info dict per row is built;
an update is a few large minibatches (``batch_size`` is the minibatch, as in SB3), so the learner's cost per
sample is a few matrix products. ``lvgym bench-train`` reports where the time goes.

The networks and the statistics are stable-baselines3's containers (an ``ActorCriticPolicy`` inside a ``PPO``
object, a ``VecNormalize`` over a stand-in env): the trainer runs its own loops on them, and a run's files are
then an SB3 ``.zip`` and its ``_vecnormalize.pkl``, which ``lvgym evaluate --policies RUN_DIR``, ``lvgym
export-policy`` and the compiled actor (:mod:`lvgym.agents.policies.mlp`) take as they are
(:mod:`lvgym.agents.training.fastrun` writes the run folder).

The ``next_step`` autoreset. The step after a row's episode ended resets the row, ignores its action and returns
reward 0: that transition is no sample (``valid`` False) and is left out of the update. The step that ended an
episode returned the episode's last observation, and the next forward pass (on that observation) gives the value
that bootstraps a truncated episode (the mission's end); a terminated one (a failure) bootstraps nothing.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import torch

__all__ = ["EpisodeLog", "FastPPO", "Timers", "make_shell", "make_stats"]

LOG_2PI = math.log(2.0 * math.pi)


@dataclass
class Timers:
    """Wall seconds spent in the env's ``step`` (``env_s``), in the rest of the rollout (``infer_s``: the forward
    passes, sampling, normalisation, the buffers and the episode accounting) and in the updates (``update_s``:
    advantages and the epochs), and the env steps counted (``samples``, rows x steps)."""

    env_s: float = 0.0
    infer_s: float = 0.0
    update_s: float = 0.0
    samples: int = 0

    def per_sample_us(self) -> dict[str, float]:
        n = max(self.samples, 1)
        return {"env": 1e6 * self.env_s / n, "inference": 1e6 * self.infer_s / n, "update": 1e6 * self.update_s / n}


@dataclass
class EpisodeLog:
    """The episodes that ended in one rollout, as arrays over those episodes: ``returns`` (the env's own reward
    summed, unscaled), ``lengths`` [steps], ``failed`` (terminated: a failure, not the mission's end), and
    ``rate_error`` (the episode's integrated rate error [rad], ``info["cumulative_rate_error"]`` at its end)."""

    returns: list[np.ndarray] = field(default_factory=list)
    lengths: list[np.ndarray] = field(default_factory=list)
    failed: list[np.ndarray] = field(default_factory=list)
    rate_error: list[np.ndarray] = field(default_factory=list)

    def summary(self) -> dict[str, float]:
        """Per-rollout means (``episodes`` 0 and no other key when none ended)."""
        if not self.returns:
            return {"episodes": 0}
        r, n, f, e = (np.concatenate(x) for x in (self.returns, self.lengths, self.failed, self.rate_error))
        return {"episodes": int(r.size), "return_mean": float(r.mean()), "cost_mean": float(-r.mean()),
                "length_mean": float(n.mean()), "failure_rate": float(f.mean()), "rate_error_mean": float(e.mean())}


class _Spaces:
    """A stand-in env with the task's spaces, for building the SB3 containers (never stepped)."""

    def __init__(self, observation_space: Any, action_space: Any) -> None:
        import gymnasium as gym

        class Env(gym.Env):
            def __init__(self) -> None:
                self.observation_space, self.action_space = observation_space, action_space

            def reset(self, *, seed: int | None = None, options: dict | None = None):
                return np.zeros(observation_space.shape, observation_space.dtype), {}

            def step(self, action):
                return np.zeros(observation_space.shape, observation_space.dtype), 0.0, True, False, {}

        self.env_cls = Env

    def venv(self) -> Any:
        from stable_baselines3.common.vec_env import DummyVecEnv

        return DummyVecEnv([self.env_cls])


def make_shell(observation_space: Any, action_space: Any, cfg: Any, seed: int) -> Any:
    """An SB3 ``PPO`` with the networks of ``cfg`` (:class:`lvgym.agents.training.config.AgentConfig`) over a
    stand-in env of the task's spaces: the container of the weights and of Adam's state that
    :class:`FastPPO` trains and that saves and loads as any SB3 model."""
    from stable_baselines3 import PPO

    kw = cfg.sb3_kwargs()
    with warnings.catch_warnings():                  # its rollout buffer (one stand-in row) is never used
        warnings.simplefilter("ignore")
        return PPO("MlpPolicy", _Spaces(observation_space, action_space).venv(), seed=int(seed), device="cpu",
                   verbose=0, **kw)


def make_stats(observation_space: Any, action_space: Any, norm: Any, gamma: float) -> Any:
    """A ``VecNormalize`` over a stand-in env: the running statistics of the observations and of the
    discounted return, with the clips of ``norm`` (:class:`~lvgym.agents.training.config.NormalizeConfig`),
    saved as SB3 saves them (``lvgym.agents.policies.saved.load_vecnormalize`` reads them to fly)."""
    from stable_baselines3.common.vec_env import VecNormalize

    return VecNormalize(_Spaces(observation_space, action_space).venv(), norm_obs=norm.norm_obs,
                        norm_reward=norm.norm_reward, clip_obs=norm.clip_obs, clip_reward=norm.clip_reward,
                        epsilon=norm.epsilon, gamma=gamma)


class FastPPO:
    """PPO (the module docstring) on ``venv``, a Gymnasium ``VectorEnv`` with ``next_step`` autoreset of
    ``cfg.n_envs`` rows; ``cfg``: an :class:`~lvgym.agents.training.config.AgentConfig` (its ``hyper``: n_steps,
    batch_size (the minibatch), n_epochs, gamma, gae_lambda, clip_range, ent_coef, vf_coef, max_grad_norm,
    target_kl, learning_rate with lr_schedule). ``model`` and ``stats`` (from :func:`make_shell` and
    :func:`make_stats`, or loaded from a checkpoint) hold the weights, Adam's state and the statistics; the step
    counter is ``model.num_timesteps``. ``seed``: the env rows' first seed (row i: seed + i)."""

    def __init__(self, venv: Any, cfg: Any, model: Any, stats: Any, seed: int) -> None:
        h = cfg.hyper
        if h.use_sde:
            raise ValueError("algo.use_sde = True: ppo-fast samples a plain diagonal Gaussian (use_sde false)")
        self.venv, self.cfg, self.h, self.model, self.stats = venv, cfg, h, model, stats
        self.policy = model.policy
        self.policy.set_training_mode(False)
        self.rows, self.T = int(venv.num_envs), int(h.n_steps)
        space = venv.single_action_space
        self.low = torch.as_tensor(space.low, dtype=torch.float32)
        self.high = torch.as_tensor(space.high, dtype=torch.float32)
        n_obs, n_act = int(venv.single_observation_space.shape[0]), int(space.shape[0])
        T, B = self.T, self.rows
        self.obs_buf = torch.zeros((T, B, n_obs))
        self.act_buf = torch.zeros((T, B, n_act))
        self.logp_buf = torch.zeros((T, B))
        self.val_buf = torch.zeros((T + 1, B))
        self.rew_buf = torch.zeros((T, B))
        self.term_buf = torch.zeros((T, B))
        self.done_buf = torch.zeros((T, B))
        self.valid_buf = torch.zeros((T, B), dtype=torch.bool)
        self.timers = Timers()
        self.episodes = EpisodeLog()
        obs, _ = venv.reset(seed=int(seed))
        self.obs = np.asarray(obs, dtype=np.float32)
        self.reset_next = np.zeros(B, dtype=bool)        # the rows the next step resets (their action is ignored)
        self.ep_return = np.zeros(B)
        self.ep_length = np.zeros(B, dtype=np.int64)
        self.disc_return = np.zeros(B)                   # the reward scaling's discounted return per row

    # ------------------------------------------------------------------------------ the networks
    def _mean(self, x: torch.Tensor) -> torch.Tensor:
        p = self.policy
        return p.action_net(p.mlp_extractor.forward_actor(x))

    def _value(self, x: torch.Tensor) -> torch.Tensor:
        p = self.policy
        return p.value_net(p.mlp_extractor.forward_critic(x)).squeeze(-1)

    def _logp(self, mean: torch.Tensor, actions: torch.Tensor) -> torch.Tensor:
        log_std = self.policy.log_std
        z = (actions - mean) * torch.exp(-log_std)
        return -(0.5 * z.pow(2) + log_std + 0.5 * LOG_2PI).sum(-1)

    # ------------------------------------------------------------------------------ normalisation
    def _normalized_obs(self, obs: np.ndarray) -> np.ndarray:
        """``obs`` (B, n) with the running statistics updated first (as VecNormalize's step does)."""
        s = self.stats
        if not s.norm_obs:
            return obs
        s.obs_rms.update(obs)
        return np.clip((obs - s.obs_rms.mean) / np.sqrt(s.obs_rms.var + s.epsilon), -s.clip_obs,
                       s.clip_obs).astype(np.float32)

    def _scaled_reward(self, reward: np.ndarray, done: np.ndarray) -> np.ndarray:
        s = self.stats
        if not s.norm_reward:
            return reward
        self.disc_return = self.disc_return * self.h.gamma + reward
        s.ret_rms.update(self.disc_return)
        self.disc_return[done] = 0.0
        return np.clip(reward / np.sqrt(s.ret_rms.var + s.epsilon), -s.clip_reward, s.clip_reward)

    # ------------------------------------------------------------------------------ the rollout
    @torch.no_grad()
    def collect(self, stop: Any = None) -> int:
        """One rollout of ``n_steps`` steps of every row into the buffers; returns the steps taken (fewer when
        ``stop()`` turns true: the rollout is then not trained on)."""
        venv, t = self.venv, 0
        for t in range(self.T):
            if stop is not None and stop():
                return t
            t0 = time.perf_counter()
            x = torch.from_numpy(self._normalized_obs(self.obs))
            mean = self._mean(x)
            action = mean + torch.exp(self.policy.log_std) * torch.randn_like(mean)
            self.obs_buf[t] = x
            self.act_buf[t] = action
            self.logp_buf[t] = self._logp(mean, action)
            self.val_buf[t] = self._value(x)
            self.valid_buf[t] = torch.from_numpy(~self.reset_next)
            applied = torch.maximum(torch.minimum(action, self.high), self.low).numpy()
            t1 = time.perf_counter()
            obs, reward, terminated, truncated, info = venv.step(applied)
            t2 = time.perf_counter()
            self.obs = np.asarray(obs, dtype=np.float32)
            done = terminated | truncated
            self.rew_buf[t] = torch.from_numpy(np.asarray(self._scaled_reward(reward, done), dtype=np.float32))
            self.term_buf[t] = torch.from_numpy(terminated.astype(np.float32))
            self.done_buf[t] = torch.from_numpy(done.astype(np.float32))
            self._account(reward, terminated, done, info)
            self.reset_next = done
            self.timers.env_s += t2 - t1
            self.timers.infer_s += time.perf_counter() - t2 + t1 - t0
        t0 = time.perf_counter()
        self.val_buf[self.T] = self._value(torch.from_numpy(self._normalized_obs_frozen(self.obs)))
        self.timers.infer_s += time.perf_counter() - t0
        self.timers.samples += self.T * self.rows
        self.model.num_timesteps += self.T * self.rows
        return self.T

    def _normalized_obs_frozen(self, obs: np.ndarray) -> np.ndarray:
        """``obs`` normalised without updating the statistics (the value after the rollout's last step)."""
        s = self.stats
        if not s.norm_obs:
            return obs
        return np.clip((obs - s.obs_rms.mean) / np.sqrt(s.obs_rms.var + s.epsilon), -s.clip_obs,
                       s.clip_obs).astype(np.float32)

    def _account(self, reward: np.ndarray, terminated: np.ndarray, done: np.ndarray, info: dict[str, Any]) -> None:
        """The per-row episode sums, and the episodes that ended this step into :attr:`episodes`."""
        live = ~self.reset_next
        self.ep_return += np.where(live, reward, 0.0)
        self.ep_length += live
        if done.any():
            ended = np.flatnonzero(done)
            log = self.episodes
            log.returns.append(self.ep_return[ended].copy())
            log.lengths.append(self.ep_length[ended].copy())
            log.failed.append(terminated[ended].astype(float))
            log.rate_error.append(np.asarray(info["cumulative_rate_error"], dtype=float)[ended])
            self.ep_return[ended] = 0.0
            self.ep_length[ended] = 0

    # ------------------------------------------------------------------------------ the update
    @torch.no_grad()
    def advantages(self) -> tuple[torch.Tensor, torch.Tensor]:
        """GAE advantages and the value targets (T, B): a done step cuts the recursion, a terminated one
        bootstraps nothing (the module docstring)."""
        h = self.h
        adv = torch.zeros_like(self.rew_buf)
        last = torch.zeros(self.rows)
        for t in reversed(range(self.T)):
            delta = self.rew_buf[t] + h.gamma * self.val_buf[t + 1] * (1.0 - self.term_buf[t]) - self.val_buf[t]
            last = delta + h.gamma * h.gae_lambda * (1.0 - self.done_buf[t]) * last
            adv[t] = last
        return adv, adv + self.val_buf[:-1]

    def learning_rate(self, progress_remaining: float) -> float:
        h = self.h
        return h.learning_rate * (progress_remaining if h.lr_schedule == "linear" else 1.0)

    def update(self, progress_remaining: float) -> dict[str, float]:
        """``n_epochs`` passes over the rollout's valid samples in minibatches of ``batch_size`` (the last one of
        an epoch may be shorter); returns the losses of the last epoch, the approximate KL and the clip fraction."""
        t0 = time.perf_counter()
        h, p = self.h, self.policy
        adv, ret = self.advantages()
        valid = self.valid_buf.reshape(-1)
        obs = self.obs_buf.reshape(-1, self.obs_buf.shape[-1])[valid]
        act = self.act_buf.reshape(-1, self.act_buf.shape[-1])[valid]
        logp0 = self.logp_buf.reshape(-1)[valid]
        adv, ret = adv.reshape(-1)[valid], ret.reshape(-1)[valid]
        n = int(obs.shape[0])
        lr = self.learning_rate(progress_remaining)
        for group in p.optimizer.param_groups:
            group["lr"] = lr
        p.set_training_mode(True)
        stats: dict[str, float] = {}
        stop = False
        for _ in range(h.n_epochs):
            order = torch.randperm(n)
            pg_l, v_l, kl_l, clip_l = [], [], [], []
            for start in range(0, n, h.batch_size):
                mb = order[start:start + h.batch_size]
                if mb.numel() < 2:
                    continue
                x, a, b_adv = obs[mb], act[mb], adv[mb]
                b_adv = (b_adv - b_adv.mean()) / (b_adv.std() + 1e-8)
                mean = self._mean(x)
                log_ratio = self._logp(mean, a) - logp0[mb]
                ratio = log_ratio.exp()
                pg_loss = -torch.min(b_adv * ratio, b_adv * ratio.clamp(1.0 - h.clip_range, 1.0 + h.clip_range)).mean()
                v_loss = (self._value(x) - ret[mb]).pow(2).mean()
                entropy = (p.log_std + 0.5 * (1.0 + LOG_2PI)).sum()
                loss = pg_loss - h.ent_coef * entropy + h.vf_coef * v_loss
                with torch.no_grad():
                    approx_kl = ((ratio - 1.0) - log_ratio).mean().item()
                    clip_l.append(((ratio - 1.0).abs() > h.clip_range).float().mean().item())
                if h.target_kl is not None and approx_kl > 1.5 * h.target_kl:
                    stop = True
                    break
                p.optimizer.zero_grad(set_to_none=True)
                loss.backward()
                torch.nn.utils.clip_grad_norm_(p.parameters(), h.max_grad_norm)
                p.optimizer.step()
                pg_l.append(pg_loss.item())
                v_l.append(v_loss.item())
                kl_l.append(approx_kl)
            if pg_l:
                stats = {"policy_loss": float(np.mean(pg_l)), "value_loss": float(np.mean(v_l)),
                         "approx_kl": float(np.mean(kl_l)), "clip_fraction": float(np.mean(clip_l)),
                         "std": float(p.log_std.exp().mean().item()), "learning_rate": lr, "samples": n}
            if stop:
                break
        p.set_training_mode(False)
        with torch.no_grad():
            var = ret.var()
            stats["explained_variance"] = float(1.0 - (ret - self.val_buf[:-1].reshape(-1)[valid]).var() / var) \
                if var > 0 else float("nan")
        self.timers.update_s += time.perf_counter() - t0
        return stats

    def take_episodes(self) -> dict[str, float]:
        """The summary of the episodes ended since the last call (:class:`EpisodeLog`), then a fresh log."""
        out = self.episodes.summary()
        self.episodes = EpisodeLog()
        return out
