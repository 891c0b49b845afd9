"""Observation history (a frame stack) of the ascent envs: the option ``history=k``.

With ``history=k`` (k >= 1; 0, the default, is off and leaves the observation as it is) the observation
is the last ``k`` samples of the observation mode and the last ``k`` actions, oldest first::

    [obs(t - k + 1), ..., obs(t - 1), obs(t), action(t - k), ..., action(t - 1)]

``obs(t)`` keeps the mode's names (``pitch_rate_error``, ...), so code that reads the observation by
name (the classical baselines do, through ``env.unwrapped.observation_layout``) reads the current sample;
the sample ``j`` control periods older is ``<name>_lag<j>``; the action ``j`` periods ago is
``action_pitch_lag<j>`` and ``action_yaw_lag<j>`` (TVC) or ``action_roll_lag<j>`` (RCS), recorded as
:data:`~.layouts.ACTIONS` says (the TVC command clipped to [-1, 1]; the RCS pulse minus 1). At a reset
every older sample and every action is zero. The layout (:func:`history_layout`) has one block per lag
(``observation_lag<j>``, ``action_lag<j>``), each with its entries' own names, units and meanings.

:class:`HistoryStack` shifts and fills the stacked rows; the functional env applies it to every row of
a batch after each transition (so the single env, the vector envs and the SB3 ``VecEnv`` share it), and
a saved policy's adapter applies it to a plain protocol observation (``lvgym.agents.policies.sb3``).
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from lvgym.packing import Field, Packed

from .layouts import ACTIONS

__all__ = ["HistoryStack", "history_layout", "lag_name", "recorded_action"]


def lag_name(name: str, lag: int) -> str:
    """The name of entry ``name`` ``lag`` control periods old (``lag`` 0: the name itself)."""
    return name if lag == 0 else f"{name}_lag{lag}"


def _lagged(base: Packed, lag: int, what: str) -> Packed:
    fields = [Field(lag_name(f.name, lag), f.size, f.unit, f"{f.doc} ({lag} control period(s) ago)" if lag else f.doc)
              for _, f in base.leaves()]
    return Packed(f"{what} lag {lag}", fields, interface=True)


@functools.lru_cache(maxsize=64)
def history_layout(base: Packed, actions: Packed, k: int) -> Packed:
    """The stacked observation of ``k`` samples of the observation layout ``base`` and ``k`` actions of
    the layout ``actions`` (see the module docstring), oldest first."""
    if not isinstance(k, int) or k < 1:
        raise ValueError(f"history = {k!r}: an integer >= 1 (0 is no history)")
    blocks = [Field(f"observation_lag{j}", base.size, "-", f"the observation {j} control period(s) ago",
                    sub=_lagged(base, j, "observation")) for j in range(k - 1, -1, -1)]
    blocks += [Field(f"action_lag{j}", actions.size, "-", f"the action {j} control period(s) ago",
                     sub=_lagged(actions, j, "action")) for j in range(k, 0, -1)]
    return Packed(f"observation ({base.title}, history {k})", blocks, interface=True)


def recorded_action(control: str, action: np.ndarray) -> np.ndarray:
    """Actions (B, n_a) as the history records them: ``tvc`` clipped to [-1, 1], ``rcs`` minus 1."""
    a = np.asarray(action, dtype=np.float64)
    return np.clip(a, -1.0, 1.0) if control == "tvc" else a - 1.0


class HistoryStack:
    """The rows of a stacked observation (float32, :attr:`layout`): :meth:`reset` and :meth:`push`
    write them in place. ``base``: the layout of one sample, ``actions``: of one recorded action."""

    def __init__(self, base: Packed, actions: Packed, k: int) -> None:
        self.base, self.actions, self.k = base, actions, int(k)
        self.layout = lay = history_layout(base, actions, self.k)
        self.size = lay.size
        self.newest_obs = lay.slice("observation_lag0")
        self.newest_action = lay.slice("action_lag1")
        # the blocks lie end to end (an interface layout is never padded): lags shift as one slice each
        obs = [lay.slice(f"observation_lag{j}") for j in range(self.k - 1, -1, -1)]
        act = [lay.slice(f"action_lag{j}") for j in range(self.k, 0, -1)]
        for blocks in (obs, act):
            if any(a.stop != b.start for a, b in zip(blocks, blocks[1:])):
                raise AssertionError(f"{lay.title}: the lag blocks are not contiguous")
        self._obs_from, self._obs_to = slice(obs[0].stop, obs[-1].stop), slice(obs[0].start, obs[-1].start)
        self._act_from, self._act_to = slice(act[0].stop, act[-1].stop), slice(act[0].start, act[-1].start)

    def zeros(self, batch: int) -> np.ndarray:
        """``batch`` zeroed rows."""
        return self.layout.zeros(batch, np.float32)

    def reset(self, rows_buf: np.ndarray, rows: Any, obs: np.ndarray) -> None:
        """Rows ``rows`` of ``rows_buf`` at a reset: ``obs`` (len(rows), n) the first sample, the rest zero."""
        rows_buf[rows] = 0.0
        rows_buf[rows, self.newest_obs] = obs

    def push(self, rows_buf: np.ndarray, obs: np.ndarray, action: np.ndarray) -> None:
        """Every row one control period on: the lags shift by one, ``obs`` (B, n) becomes the newest
        sample and ``action`` (B, n_a, as :func:`recorded_action` gives it) the newest action."""
        rows_buf[:, self._obs_to] = rows_buf[:, self._obs_from]
        rows_buf[:, self.newest_obs] = obs
        rows_buf[:, self._act_to] = rows_buf[:, self._act_from]
        rows_buf[:, self.newest_action] = action

    def table(self) -> str:
        """The stacked observation as a reStructuredText table (index, name, unit, meaning)."""
        return self.layout.table()
