"""Training with the loop's gain and delay dispersed: what the time-domain margins
(:mod:`lvgym.benchmark.margins`) insert between a policy and the actuator, drawn per episode, so that a
learned policy is trained to keep the margins it is judged on.

Per env row and episode: a gain ``k = 10 ** (g / 20)`` with ``g`` uniform in ``[-gain_db, +gain_db]``
[dB], and an extra delay of ``d`` whole control periods, ``d`` uniform in ``{0, ..., delay_periods}``
(``d * control_dt_s`` seconds; 20 ms per period on the v1 envs). The env gets ``k`` times the action the
policy (or, with ``--residual``, the residual's baseline plus the learned part) gave ``d`` periods
earlier, the neutral action (zeros) before that, and clips it to its action space as it clips any
action, exactly as the margins command's gain (:func:`lvgym.benchmark.rows.scaled`) and delay
(:class:`lvgym.benchmark.rows.RowDelay`) do (the latter also has a sub-period part, through the
servo's delay; training uses whole periods only). The dispersion is a training device, like the
``--randomize`` dispersions: validation and evaluation fly the nominal loop.

The draws come from a generator of their own, seeded from the run's env seed (``SeedSequence([seed,
LOOP_STREAM])``), so the env's own generators and their draws are the same with and without it.
"""

from __future__ import annotations

from collections import deque
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

from lvgym.errors import ConfigError, check_number

__all__ = ["LOOP_STREAM", "LoopDispersion", "LoopDispersedVecEnv", "loop_dispersion_options", "loop_venv"]

#: the second entry of the seed sequence of the loop's generator (the first is the env seed)
LOOP_STREAM = 0x100D


@dataclass(frozen=True)
class LoopDispersion:
    """``gain_db`` [dB]: the gain is drawn uniformly in dB within +-``gain_db`` (0 to 20);
    ``delay_periods`` [-]: the extra delay is drawn uniformly from 0 to this many control periods (0 to 10)."""

    gain_db: float = 0.0
    delay_periods: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "gain_db", check_number("loop_dispersion.gain_db", self.gain_db, 0.0, 20.0))
        object.__setattr__(self, "delay_periods",
                           check_number("loop_dispersion.delay_periods", self.delay_periods, 0, 10, integer=True))

    @property
    def active(self) -> bool:
        """Whether anything is drawn."""
        return self.gain_db > 0.0 or self.delay_periods > 0

    def draw(self, rng: np.random.Generator) -> tuple[float, int]:
        """One episode's gain [-] and extra delay [control periods], in this order from ``rng``."""
        gain = 10.0 ** (rng.uniform(-self.gain_db, self.gain_db) / 20.0)
        return float(gain), int(rng.integers(0, self.delay_periods + 1))

    def to_dict(self) -> dict[str, Any]:
        """What a run's config records."""
        return asdict(self)


def loop_dispersion_options(gain_db: float, delay_periods: int) -> dict[str, Any] | None:
    """``train.py``'s ``--loop-gain-db`` and ``--loop-delay-periods`` as a run records them (None: off);
    a bad value is a ConfigError naming the option."""
    try:
        d = LoopDispersion(gain_db, delay_periods)
    except ConfigError as exc:
        option = "--loop-gain-db" if exc.key.endswith("gain_db") else "--loop-delay-periods"
        raise ConfigError(option, exc.value, exc.allowed) from None
    return d.to_dict() if d.active else None


class LoopDispersedVecEnv(VecEnvWrapper):
    """An SB3 ``VecEnv`` whose rows fly their actions through a gain and a delay drawn per episode
    (:class:`LoopDispersion`); ``seed`` [-]: the env seed the generator is derived from. The drawn values
    of the running episodes are :attr:`gain` (rows,) and :attr:`delay` (rows,)."""

    def __init__(self, venv: Any, dispersion: LoopDispersion, seed: int) -> None:
        super().__init__(venv)
        if not hasattr(venv.action_space, "low"):
            raise ValueError("a loop dispersion needs a Box (TVC) action space")
        self.dispersion = dispersion
        self._neutral = np.zeros(venv.action_space.shape, dtype=np.float32)
        self.gain = np.ones(self.num_envs)
        self.delay = np.zeros(self.num_envs, dtype=int)
        self._queues: list[deque[np.ndarray]] = [deque() for _ in range(self.num_envs)]
        self._seed(seed)

    def _seed(self, seed: int | None) -> None:
        self._rng = np.random.default_rng(np.random.SeedSequence([int(seed or 0), LOOP_STREAM]))

    def seed(self, seed: int | None = None) -> Any:
        self._seed(seed)
        return self.venv.seed(seed)

    def _start(self, rows: Any) -> None:
        for b in rows:
            self.gain[b], self.delay[b] = self.dispersion.draw(self._rng)
            self._queues[b] = deque(self._neutral.copy() for _ in range(self.delay[b]))

    def reset(self) -> np.ndarray:
        obs = self.venv.reset()
        self.reset_infos = self.venv.reset_infos           # what a residual wrapper above reads
        self._start(range(self.num_envs))
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        out = np.array(np.reshape(actions, (self.num_envs, -1)), dtype=np.float32)
        for b, queue in enumerate(self._queues):
            if queue:
                queue.append(out[b].copy())
                out[b] = queue.popleft()
        self.venv.step_async((out * self.gain[:, None]).astype(np.float32))

    def step_wait(self):
        obs, reward, done, infos = self.venv.step_wait()
        self.reset_infos = self.venv.reset_infos
        self._start(np.flatnonzero(done))
        return obs, reward, done, infos


def loop_venv(venv: Any, loop: dict[str, Any] | None, seed: int) -> Any:
    """``venv`` wrapped with the loop dispersion ``loop`` records (``None``: ``venv`` itself)."""
    return venv if not loop else LoopDispersedVecEnv(venv, LoopDispersion(**loop), seed)
