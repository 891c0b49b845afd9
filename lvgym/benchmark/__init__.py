"""The frozen benchmark protocol: named suites of conditions with fixed seeds, metrics, and the runner.

- :mod:`.batch`, :mod:`.policy`: the controllers' one interface, the batch law (``reset(rows)``,
  ``act(rows, observations, info)``), and its one-row face, the :class:`Policy` (``name``, ``reset()``,
  ``act(observation, info)``) that a user's controller implements;
- :mod:`.suites`: :data:`SUITES` (conditions and seed sets, :data:`PROTOCOL_VERSION`);
- :mod:`.metrics`: per-episode metrics of v0, per-suite mean with its interval / std / CVaR10 / failure
  rate, ranks, degradation;
- :mod:`.scoring`: v1's per-episode metrics (failure-charged score, phases, flexibility, q-alpha cost);
- :mod:`.stats`: bootstrap intervals, paired tests, the IQM and probability of improvement (stratified bootstrap),
  the normalised score and the room;
- :mod:`.flyability`, :mod:`.headline`: protocol v2's flyability rule and ``score_v2``; its headline (the
  best flyable classical and learned policies the suite reports, the privileged reference and the room
  between them) and a row for each other policy flown;
- :mod:`.compare`: the paired comparison of policies and agents over training runs;
- :mod:`.decide`, :mod:`.selection`: the statistics that decide between two policies (exact failed and
  unflyable rates, the paired relative gain, the score on flights both survived, the table by fault kind) and
  the headline chosen on validation seeds, flown once on the named test block;
- :mod:`.ledger`: the ledger of test flights (every flight on test seeds, one line per call);
- :mod:`.runner`: :func:`run_episode` and :func:`evaluate` (serial, local process pool or Ray);
- :mod:`.tables`, :mod:`.results`, :mod:`.plots`: the Markdown tables; atomic CSV / JSON / Markdown / PNG result
  files; the figures (each policy in one colour and marker, means with their intervals);
- :mod:`.registry`: the policies the command lines know by name (:func:`register_policy`: the controllers
  and agents register themselves; the command layer imports them) and how ``--policies`` resolves;
- :mod:`.margins`, :mod:`.perturb`: time-domain gain and delay margins of any policy
  (``lvgym margins``; import ``lvgym.benchmark.margins`` for :func:`~.margins.time_domain_margins`).
"""

from .compare import compare, protocol_metric, run_groups
from .metrics import (CVAR_LEVEL, SUMMARY_METRICS, V1_METRICS, Trajectory, cvar, degradation,
                      episode_metrics, normalise, rank, summarize)
from .batch import BatchLaw, BatchPolicy, RowFace
from .policy import Policy, ZeroPolicy
from .results import atomic_write, atomic_write_text, markdown_table, write_results
from .registry import register_policy, register_policy_loader
from .runner import (EXECUTORS, ZERO, PolicyError, PolicySpec, build_policy, evaluate, make_tasks, play_episode,
                     run_episode)
from .suites import (DEFAULT_SUITE, PROTOCOL_VERSION, SEED_SETS, SUITES, TEST_SEED0, VALIDATION_SEED0, Condition,
                     Suite, condition, get_suite)

__all__ = ["BatchLaw", "BatchPolicy", "RowFace", "CVAR_LEVEL", "Condition", "DEFAULT_SUITE", "EXECUTORS", "PROTOCOL_VERSION", "Policy", "PolicySpec",
           "SEED_SETS", "SUITES", "SUMMARY_METRICS", "Suite", "TEST_SEED0", "Trajectory",
           "V1_METRICS", "VALIDATION_SEED0", "ZERO", "ZeroPolicy", "atomic_write", "atomic_write_text", "build_policy",
           "compare", "condition", "cvar", "degradation", "episode_metrics", "evaluate", "get_suite", "make_tasks",
           "protocol_metric", "markdown_table", "normalise", "play_episode", "rank", "register_policy",
           "register_policy_loader", "run_episode", "run_groups", "summarize", "write_results", "PolicyError"]
