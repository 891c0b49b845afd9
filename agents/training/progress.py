"""What a training run shows while it trains: a tqdm bar on stderr for a terminal
(:class:`ProgressBarCallback`, ``--no-progress`` hides it) and a progress line on stdout every so often for
a log (:class:`ProgressLineCallback`, ``--progress-interval-s``)::

    train.py: step 1,228,800 / 5,000,000 (24.6 %), 2,310 steps/s, elapsed 0:08:52, about 0:27:12 left;
    validation at step 1,000,000: score 0.7134, failure rate 0 %

On a protocol v2 suite the validation part reads ``score_v2 ..., failed or unflyable ... %``: what model
selection ranks on (an unflyable flight is charged like a failed one).
"""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback

__all__ = ["ProgressBarCallback", "ProgressLineCallback", "clock"]


def clock(seconds: float) -> str:
    """``seconds`` as ``H:MM:SS``."""
    s = max(0, int(round(seconds)))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"


class ProgressBarCallback(BaseCallback):
    """A tqdm bar of env steps towards the run's target (continuing from the resumed step), with the
    steps per second and the mean return of the last episodes (SB3's own bar needs ``rich``)."""

    def __init__(self, enabled: bool = True, refresh_s: float = 0.5) -> None:
        super().__init__()
        self.enabled = enabled
        self.refresh_s = refresh_s
        self.bar: Any = None
        self._last = 0.0

    def _on_training_start(self) -> None:
        from tqdm.auto import tqdm

        self.bar = tqdm(total=int(self.model._total_timesteps), initial=int(self.model.num_timesteps),
                        unit="step", unit_scale=True, dynamic_ncols=True, disable=not self.enabled,
                        file=sys.stderr, desc="training")

    def _advance(self) -> None:
        n = int(self.model.num_timesteps)
        if self.bar.total is not None and n > self.bar.total:     # the last rollout overshoots the target
            self.bar.total = n
        self.bar.update(n - self.bar.n)

    def _on_step(self) -> bool:
        now = time.monotonic()
        if self.bar is not None and now - self._last >= self.refresh_s:
            self._last = now
            self._advance()
            buf = self.model.ep_info_buffer
            if buf:
                self.bar.set_postfix(ep_return=f"{np.mean([e['r'] for e in buf]):.3g}", refresh=False)
        return True

    def _on_training_end(self) -> None:
        if self.bar is not None:
            self._advance()
            self.bar.close()


class ProgressLineCallback(BaseCallback):
    """One line on ``stream`` (stdout) at the end of the first rollout at least ``interval_s`` seconds of
    wall time after the last line, and one at the end of training: the step of the ``target``, the steps
    per second and the wall time of this segment, the time left at that rate, and the latest validation
    score of ``checkpoint`` (a :class:`lvgym.agents.training.callbacks.CheckpointCallback`) if any. ``interval_s``
    <= 0: no lines. Written through tqdm, so that a bar on stderr stays whole."""

    def __init__(self, interval_s: float, target: int, checkpoint: Any = None, prog: str = "train.py",
                 stream: TextIO | None = None) -> None:
        super().__init__()
        self.interval_s = float(interval_s)
        self.target = int(target)
        self.checkpoint = checkpoint
        self.prog = prog
        self.stream = stream
        self.lines = 0
        self.t0 = self.last = time.monotonic()
        self.step0 = 0

    def _on_training_start(self) -> None:
        self.t0 = self.last = time.monotonic()
        self.step0 = int(self.model.num_timesteps)

    def _on_step(self) -> bool:
        return True

    def _on_rollout_end(self) -> None:
        if self.interval_s > 0 and time.monotonic() - self.last >= self.interval_s:
            self.write()

    def _on_training_end(self) -> None:
        if self.interval_s > 0:
            self.write()

    def line(self) -> str:
        """The progress line as of now."""
        n = int(self.model.num_timesteps)
        elapsed = time.monotonic() - self.t0
        rate = (n - self.step0) / elapsed if elapsed > 0 else 0.0
        text = (f"{self.prog}: step {n:,} / {self.target:,} ({100.0 * n / max(self.target, 1):.1f} %), "
                f"{rate:,.0f} steps/s, elapsed {clock(elapsed)}")
        if 0 < rate and n < self.target:
            text += f", about {clock((self.target - n) / rate)} left"
        evaluations = getattr(self.checkpoint, "evaluations", None)
        if evaluations:
            last = evaluations[-1]                   # its "score" is [failure rate, score] (lexicographic)
            text += f"; validation at step {int(last['num_timesteps']):,}: "
            if "score_v2" in last:                   # protocol v2: what model selection ranks on
                text += (f"score_v2 {float(last['score_v2']):.4g}, failed or unflyable "
                         f"{100.0 * float(last['failure_rate_v2']):.0f} %")
            else:
                score = last.get("episode_score", last["score"][-1] if isinstance(last["score"], list) else last["score"])
                text += f"score {float(score):.4g}, failure rate {100.0 * float(last.get('failure_rate', 0.0)):.0f} %"
        return text

    def write(self) -> None:
        from tqdm import tqdm

        tqdm.write(self.line(), file=self.stream or sys.stdout)
        (self.stream or sys.stdout).flush()
        self.last = time.monotonic()
        self.lines += 1
