"""An episode's whole state as one value: :class:`EpisodeState`, what ``env.unwrapped.get_state()`` returns.

It holds copies of the functional state's rows (:data:`~.functional.AscentState`: the simulator's time,
dynamics state and parameters, context, servo and effort, rail and stage flags, flight conditions; the
task's reference axis, cumulative errors, controller flag, sensor readings and bias, last reward and
termination; the last step's events), the state of each row's random generator and what the
Gymnasium adapter keeps besides (the vehicle variant of an env that draws one per episode, the
autoreset flags of a vector env, the rendered rate history). It pickles; restored with
``env.unwrapped.set_state(state)`` and given the same actions, the episode goes on bit for bit as it
did (MPC, model-based RL, what-if branches)::

    snap = env.unwrapped.get_state()
    a = [env.step(u) for u in actions]
    env.unwrapped.set_state(snap)
    b = [env.step(u) for u in actions]                   # identical to a
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .functional import AscentFuncEnv, AscentState
from .spec import TaskSpec

__all__ = ["EpisodeState", "rng_state", "set_rng_state"]


@dataclass
class EpisodeState:
    """The state of ``n`` rows (one for a single env): ``spec`` the task's options (a snapshot restores
    only into an env of the same options), ``state`` the rows' functional state (copies), ``rng`` each
    row's ``bit_generator.state`` (None for a row without a generator), ``extra`` the adapter's own
    per-row values (lists of length n)."""

    spec: TaskSpec
    state: AscentState
    rng: list[dict | None]
    extra: dict[str, list[Any]] = field(default_factory=dict)

    @property
    def n(self) -> int:
        """Rows held."""
        return len(self.rng)

    def row(self, i: int) -> EpisodeState:
        """Row ``i`` alone (e.g. to restore one row of a vector env into a single env)."""
        if not -self.n <= i < self.n:
            raise IndexError(f"row {i} of an EpisodeState of {self.n} rows")
        return EpisodeState(self.spec, AscentFuncEnv.take(self.state, [i % self.n]), [self.rng[i]],
                            {k: [v[i]] for k, v in self.extra.items()})

    def check(self, spec: TaskSpec, n: int) -> None:
        """Raise ``ValueError`` unless this state fits ``n`` rows of an env with options ``spec``."""
        if spec != self.spec:
            mine, theirs = self.spec.options(), spec.options()
            diff = sorted(k for k in mine if mine[k] != theirs[k])
            raise ValueError(f"the state is of another task: options {diff} differ ({ {k: mine[k] for k in diff} })")
        if n != self.n:
            raise ValueError(f"the state holds {self.n} rows for {n}")


def rng_state(g: np.random.Generator | None) -> dict | None:
    """A copy of ``g``'s bit generator state (None for None)."""
    return None if g is None else g.bit_generator.state


def set_rng_state(g: np.random.Generator, state: dict | None) -> None:
    """Put ``g`` in ``state`` (from :func:`rng_state`)."""
    if state is None:
        raise ValueError("the snapshot has no generator state for this row (it was taken before a reset)")
    g.bit_generator.state = state
