"""Speed of the shipped control laws: microseconds per row-step at 1 and 1,024 rows (``lvgym bench``, the
second table; ``lvgym bench --only laws``).

Each registered law flies its own condition (``smile-v2`` non-rigid, or the suite it is made for) as the rows
of the condition's batched env, from seed 0 up; after :data:`WARMUP_S` seconds of flight (the controller on,
its compiled code warm) each call of the law's ``act`` is timed over the next control steps and the median call
is divided by the rows (the median: a call the machine's other work interrupts does not count). Only the law is
timed, not the env. The figure is what the benchmark pays per
episode-step for the controller when it flies a condition's seeds as rows.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

__all__ = ["LAWS", "law_rates", "run"]

#: the shipped laws and the suite each flies here (its own where it is made for one)
LAWS: tuple[tuple[str, str], ...] = (
    ("zero", "smile-v2"), ("pid", "smile-v2"), ("pid-thesis", "smile-v2"), ("gs-pid", "smile-v2"),
    ("gs-pid-thesis", "smile-v2"), ("gs-pid-flex", "smile-v2"), ("gs-pid-flex-quiet", "smile-v2"),
    ("gs-pd-relief", "smile-v2"), ("aac", "smile-v2"), ("aac-quiet", "smile-v2"), ("lqg", "smile-v2"),
    ("lqg-front", "smile-v2"), ("lqg-aw", "smile-v2"), ("lqi", "smile-v2"), ("lqi-hold", "smile-v2"),
    ("mpc", "smile-v2"), ("indi", "smile-v2"), ("eso", "smile-v2"), ("privileged", "smile-v2"),
    ("ppo-res-lqg", "smile-v2"), ("ppo", "smile-windy"), ("inversion-id", "smile-v2-faults"),
    ("inversion-id-smile", "smile-v2"), ("inversion-id-stratos", "stratos-tvc-v2"),
)
#: the flight before the timed steps [s]: the controller on and every compiled function called once
WARMUP_S = 5.0


def law_rates(name: str, suite: str, rows: int, steps: int, model: str = "nonrigid") -> float:
    """Microseconds per row-step of the registered law ``name`` in ``rows`` rows of ``suite``'s ``model``
    condition: the median of ``steps`` calls after :data:`WARMUP_S` seconds of flight, over the rows."""
    from lvgym.benchmark.batch import as_batch
    from lvgym.benchmark.registry import POLICIES
    from lvgym.benchmark.runner import build_policy, policy_options
    from lvgym.benchmark.suites import SUITES

    spec = POLICIES[name]
    cond = next(c for c in SUITES[suite].conditions if c.model == model)
    options = policy_options(spec)
    cond = cond.with_options(**options) if options else cond
    env = cond.make_vec_env(rows)
    try:
        single = cond.make_env()
        law = as_batch(build_policy(spec, single), rows, lambda: build_policy(spec, single))
        all_rows = np.arange(rows, dtype=np.int64)
        obs, info = env.reset(seed=list(range(rows)))
        law.reset(all_rows)
        warmup = int(round(WARMUP_S / float(env.unwrapped.task.control_dt_s)))
        spent = []
        for k in range(warmup + steps):
            start = time.perf_counter()
            actions = np.asarray(law.act(all_rows, obs, info))
            if k >= warmup:
                spent.append(time.perf_counter() - start)
            obs, _, terminated, truncated, info = env.step(actions)
            if np.any(terminated | truncated):
                raise RuntimeError(f"{name} on {cond.name}: a row ended within {WARMUP_S + steps * 0.02:g} s")
        return 1e6 * float(np.median(spent)) / rows
    finally:
        env.close()


def run(rows: tuple[int, ...] = (1, 1024), steps: dict[int, int] | None = None,
        laws: tuple[tuple[str, str], ...] = LAWS, log: Any = print) -> list[dict[str, Any]]:
    """One line per law: its microseconds per row-step at each row count of ``rows`` (``steps``: the timed
    control steps per row count), each line given to ``log`` as a Markdown table row as it is measured."""
    import lvgym.agents  # noqa: F401  (registers the learned policies)
    import lvgym.baselines  # noqa: F401  (registers the classical ones)

    steps = steps or {1: 500, 1024: 50}
    log("| law | suite | " + " | ".join(f"us per row-step, {n} row{'s' if n > 1 else ''}" for n in rows) + " |")
    log("|---|---|" + "---:|" * len(rows))
    out = []
    for name, suite in laws:
        line: dict[str, Any] = {"law": name, "suite": suite}
        for n in rows:
            line[f"us_{n}"] = law_rates(name, suite, n, steps.get(n, 50))
        out.append(line)
        log(f"| {name} | {suite} | " + " | ".join(f"{line[f'us_{n}']:.2f}" for n in rows) + " |")
    return out
