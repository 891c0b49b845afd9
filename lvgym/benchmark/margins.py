"""Time-domain margins of any policy in the nonlinear simulation: gain margins up and down [dB] and the
delay margin [ms] (docs/metrics.md, "Time-domain margins").

    lvgym margins                                          # the default policies on smile-v1, 5 validation seeds
    lvgym margins --policies zero pid gs-pid ppo --seeds 10 --models rigid
    lvgym margins --policies runs/ppo_smile --physics-dt-s 0.005   # 5 ms delay resolution


Between the policy and the actuator a multiplicative gain ``k`` (:func:`~.rows.scaled`), and
separately a pure delay (:class:`~.rows.RowDelay`, in whole physics steps), are raised, per seed,
outwards from the nominal in doubling steps and then by bisection (:func:`~.perturb.find_threshold`),
until the episode leaves the bound (:func:`verdict`): it fails (any failure of the metrics), its
cumulative pitch + yaw rate error ``rate_error_rad`` exceeds ``error_ratio`` (default 2) times that of the
nominal episode of the same seed (counted as at least ``RATE_ERROR_FLOOR_RADPS`` over its flight), or its
time at the gimbal rate limit ``gimbal_rate_limit_s`` exceeds ``rate_limit_ratio`` (default 2) times the
nominal's (counted as at least ``RATE_LIMIT_FLOOR_S``). The last is there because the servo's rate limit
turns a loop driven unstable into a bounded limit cycle of the gimbal that the rate error hardly sees. A seed's margin is the largest value tried that passed; the
threshold lies between it and the first that failed (the bracket: at most ``gain_tol_db`` wide in gain,
one physics step in delay). Reported per policy and condition: the smallest margin over the seeds (the
margin) with its bracket, and the median. A seed whose nominal episode fails has no margin (counted, left
out); a policy the injection never makes fail has a margin beyond the range searched (``>= gain_max_db``).

Seeds: the ``validation`` seeds by default: margins are what a design is tuned by, and a test seed looked at
during design is no test any more; ``--seed-set test`` measures on the test seeds on purpose, and every such
call is logged in the ledger of test flights (:mod:`.ledger`). Policies are names of :data:`~.registry.POLICIES`, SB3 ``.zip`` paths or ``train.py`` run
folders, as ``evaluate.py`` takes them. From Python: :func:`time_domain_margins` (one policy) and
:func:`run_margins` (several, one process pool).

The searches go on side by side: each round flies the next value of every search of a condition (every
policy, seed and experiment of a task) as the rows of one batched flight (:func:`run_margin_task`), and each
row is the episode the single env flies with that gain or delay, to the bit, so the margins do not depend on
how the searches are grouped, the executor or the worker count.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from lvgym.errors import ConfigError, check_number
from lvgym.parallel import check_workers, default_workers, run_map

from .perturb import db_to_gain, summary, threshold_search
from .results import atomic_write_text, csv_text, json_text
from .runner import PolicySpec, episode_objects, fly_block
from .suites import SEED_SETS, SUITES, Condition, Suite

__all__ = ["EXPERIMENTS", "MarginOptions", "MarginTask", "RATE_ERROR_FLOOR_RADPS", "RATE_LIMIT_FLOOR_S", "bounds",
           "margin_rows", "margins_table", "run_margin_task",
           "run_margins", "time_domain_margins", "verdict", "write_margins"]

#: what is injected: the gain raised (``gain_up``, dB > 0), lowered (``gain_down``, dB < 0), a delay (``delay``, ms)
EXPERIMENTS = ("gain_up", "gain_down", "delay")
UNITS = {"gain_up": "dB", "gain_down": "dB", "delay": "ms"}
DEFAULT_SUITE = "smile-v1"
#: every default policy of evaluate.py that has a loop to perturb (zero has none)
DEFAULT_POLICIES = ["gs-pid", "gs-pid-flex", "lqg", "lqg-front", "aac", "ppo-res-lqg"]
DEFAULT_SEEDS = 5
#: the nominal time at the gimbal rate limit counts as at least this in the rate-limit bound [s]
RATE_LIMIT_FLOOR_S = 1.0
#: the nominal rate error counts as at least this mean rate over the nominal flight in the rate-error bound
#: [rad/s] (a calm, undispersed flight flies within micro-radians per second: twice that is no bound)
RATE_ERROR_FLOOR_RADPS = 1e-3


@dataclass(frozen=True)
class MarginOptions:
    """The bound and the search. error_ratio: an episode leaves the bound when its ``rate_error_rad``
    exceeds this times the nominal one of its seed [-]; rate_limit_ratio: ... or its ``gimbal_rate_limit_s``
    this times the nominal's, counted as at least ``RATE_LIMIT_FLOOR_S`` [-] (``inf``: no such criterion);
    gain_max_db / gain_min_db: the range searched up and down [dB]; gain_tol_db: the bracket width the
    gain bisection ends at [dB]; gain_step_db: the first step of the outward search [dB] (then doubling);
    delay_max_s: the largest extra delay searched [s] (its resolution is the condition's physics step)."""

    error_ratio: float = 2.0
    rate_limit_ratio: float = 2.0
    gain_max_db: float = 20.0
    gain_min_db: float = -40.0
    gain_tol_db: float = 0.25
    gain_step_db: float = 1.0
    delay_max_s: float = 0.5

    def __post_init__(self) -> None:
        check_number("error_ratio", self.error_ratio, 1.0, 1e6, lo_open=True)
        if self.rate_limit_ratio != math.inf:
            check_number("rate_limit_ratio", self.rate_limit_ratio, 1.0, 1e6, lo_open=True)
        check_number("gain_max_db", self.gain_max_db, 0.0, 80.0, lo_open=True)
        check_number("gain_min_db", self.gain_min_db, -80.0, 0.0)
        if self.gain_min_db >= 0.0:
            raise ConfigError("gain_min_db", self.gain_min_db, "a number of dB in [-80, 0)")
        check_number("gain_tol_db", self.gain_tol_db, 0.0, 20.0, lo_open=True)
        check_number("gain_step_db", self.gain_step_db, 0.0, 80.0, lo_open=True)
        check_number("delay_max_s", self.delay_max_s, 0.0, 10.0, lo_open=True)


@dataclass(frozen=True)
class MarginTask:
    """The searches of ``experiments`` for every policy of ``policies`` and seed of ``seeds`` on ``condition``,
    flown together (:func:`run_margin_task`)."""

    policies: tuple[PolicySpec, ...]
    condition: Condition
    seeds: tuple[int, ...]
    experiments: tuple[str, ...]
    options: MarginOptions


def physics_dt_s(spec: PolicySpec, condition: Condition) -> float:
    """The physics step of ``condition``'s env [s]: the resolution of the delay."""
    task = episode_objects(spec, condition)[0].unwrapped.task
    return float(task.control_dt_s) / int(task.substeps)


def bounds(nominal: dict[str, Any], options: MarginOptions) -> dict[str, float]:
    """The bound of a seed from its nominal episode: ``rate_error_rad`` [rad] (``error_ratio`` times the
    nominal's, counted as at least ``RATE_ERROR_FLOOR_RADPS`` times its duration) and ``gimbal_rate_limit_s``
    [s] (``rate_limit_ratio`` times the nominal's, counted as at least ``RATE_LIMIT_FLOOR_S``)."""
    floor = RATE_ERROR_FLOOR_RADPS * nominal["duration_s"]
    return {"rate_error_rad": options.error_ratio * max(nominal["rate_error_rad"], floor),
            "gimbal_rate_limit_s": options.rate_limit_ratio * max(nominal["gimbal_rate_limit_s"], RATE_LIMIT_FLOOR_S)}


def verdict(record: dict[str, Any], bound: dict[str, float]) -> str:
    """Why an episode leaves the bound (``""``: it stays within): ``failure: <reason>``, ``rate error`` or
    ``rate limit``."""
    if record["failed"]:
        return f"failure: {record['failure_reason']}"
    if record["rate_error_rad"] > bound["rate_error_rad"]:
        return "rate error"
    if record["gimbal_rate_limit_s"] > bound["gimbal_rate_limit_s"]:
        return "rate limit"
    return ""


class _Search:
    """One seed's search of one experiment (its threshold_search and what it has flown)."""

    def __init__(self, out: dict[str, Any], options: MarginOptions, h: float) -> None:
        self.out, self.h, self.trials = out, h, []
        self.value: float | None = None
        if out["experiment"] == "delay":
            steps = max(1, int(round(options.delay_max_s / h)))
            self.search = threshold_search(0, steps, 1.0, 1, integer=True)
        else:
            limit = options.gain_max_db if out["experiment"] == "gain_up" else options.gain_min_db
            self.search = threshold_search(0.0, limit, options.gain_tol_db, options.gain_step_db)
        self._next(None)

    def _next(self, passed: bool | None) -> None:
        try:
            self.value = next(self.search) if passed is None else self.search.send(passed)
        except StopIteration as stop:
            self.value = None
            passed_at, failed, _ = stop.value
            if self.out["experiment"] == "delay":
                passed_at, failed = passed_at * self.h * 1e3, None if failed is None else failed * self.h * 1e3
            self.out.update(passed=passed_at, failed_at=failed, trials=self.trials,
                            status="bracketed" if failed is not None else "beyond range")

    def row(self) -> tuple[float, int]:
        """The gain [-] and the delay [physics steps] of the value to try."""
        if self.out["experiment"] == "delay":
            return 1.0, int(self.value)
        return db_to_gain(self.value), 0

    def tried(self, record: dict[str, Any]) -> None:
        """The episode of the value tried: its verdict, then the next value (None: the search ended)."""
        why = verdict(record, self.out["bounds"])
        shown = self.value * self.h * 1e3 if self.out["experiment"] == "delay" else self.value
        self.trials.append({"value": shown, "passed": why == "", "verdict": why or "pass", **record})
        self._next(why == "")


def run_margin_task(task: MarginTask) -> list[dict[str, Any]]:
    """Fly the nominal episodes of the task's policies and seeds, then search every experiment's threshold
    (module docstring), the searches side by side: each round flies the next value of every search that
    goes on as the rows of one batched flight (:func:`~.runner.fly_block`; each row the single env's
    episode with its gain or delay, :func:`~.perturb.fly`). Returns one result per policy, seed and
    experiment, in that order: ``passed`` (the margin, in ``unit``), ``failed_at`` (the smallest value tried
    that failed; None: none failed up to the range's end), ``nominal`` and every ``trials`` episode. With a
    failing nominal episode, ``passed`` is None and nothing is searched."""
    o, cond = task.options, task.condition
    pairs = [(spec, int(seed)) for spec in task.policies for seed in task.seeds]
    nominals = [summary(r) for r in fly_block(cond, pairs)]
    results, searches = [], []
    for (spec, seed), nominal in zip(pairs, nominals):
        h = physics_dt_s(spec, cond)
        for e in task.experiments:
            out: dict[str, Any] = {"policy": spec.name, "condition": cond.name, "model": cond.model, "seed": seed,
                                   "experiment": e, "unit": UNITS[e], "nominal": nominal, "bounds": bounds(nominal, o),
                                   "physics_dt_s": h, "passed": None, "failed_at": None, "trials": []}
            results.append(out)
            if nominal["failed"]:
                out["status"] = "nominal failed"
            else:
                searches.append((spec, seed, _Search(out, o, h)))
    while True:
        going = [(spec, seed, s) for spec, seed, s in searches if s.value is not None]
        if not going:
            return results
        perturbed = [s.row() for _, _, s in going]
        records = fly_block(cond, [(spec, seed) for spec, seed, _ in going], gains=[g for g, _ in perturbed],
                            delay_steps=[d for _, d in perturbed])
        for (_, _, s), record in zip(going, records):
            s.tried(summary(record))


def _describe(task: MarginTask) -> str:
    return (f"margins {list(task.experiments)} of policies {[p.name for p in task.policies]} on "
            f"{task.condition.name!r} seeds {list(task.seeds)}")


def _conditions(where: Suite | Condition | Sequence[Condition]) -> list[Condition]:
    if isinstance(where, Suite):
        return list(where.conditions)
    if isinstance(where, Condition):
        return [where]
    return list(where)


def _seeds(where: Suite | Condition | Sequence[Condition], seeds: int | Sequence[int], seed_set: str) -> list[int]:
    if not isinstance(seeds, int):
        return [int(s) for s in seeds]
    suite = where if isinstance(where, Suite) else next(iter(SUITES.values()))      # every suite has the same sets
    return suite.seeds(seed_set, seeds)


def _summary(seeds: list[dict[str, Any]], limit: float) -> dict[str, Any]:
    """The margin over the seeds of one experiment: the smallest in magnitude (the worst seed) with its
    bracket, the median, and the counts."""
    done = [s for s in seeds if s["passed"] is not None]
    out: dict[str, Any] = {"margin": None, "failed_at": None, "bracket_width": None, "median": None,
                           "worst_seed": None, "n_seeds": len(seeds), "n_nominal_failed": len(seeds) - len(done),
                           "n_bracketed": sum(s["failed_at"] is not None for s in done), "limit": limit,
                           "episodes": sum(len(s["trials"]) for s in seeds)}
    if done:
        worst = min(done, key=lambda s: (abs(s["passed"]), s["seed"]))
        out.update(margin=worst["passed"], failed_at=worst["failed_at"], worst_seed=worst["seed"],
                   median=statistics.median(s["passed"] for s in done),
                   bracket_width=None if worst["failed_at"] is None else abs(worst["failed_at"] - worst["passed"]))
    return out


def run_margins(policies: Sequence[PolicySpec], where: Suite | Condition | Sequence[Condition],
                seeds: int | Sequence[int] = DEFAULT_SEEDS, *, seed_set: str = "validation",
                options: MarginOptions | None = None, experiments: Sequence[str] = EXPERIMENTS,
                executor: str = "local", workers: int | None = None, progress: bool = False,
                purpose: str | None = None) -> list[dict[str, Any]]:
    """:func:`time_domain_margins` of every policy, their searches on one process pool (``executor``,
    ``workers`` as :func:`lvgym.parallel.run_map`); one result per policy, in order. A search on test seeds
    is logged in the ledger of test flights first (:func:`~.ledger.log_flight`, with ``purpose``)."""
    options = options or MarginOptions()
    names = [p.name for p in policies]
    if len(set(names)) != len(names):
        raise ValueError(f"policy names {names}: each must be distinct (they label the results)")
    for e in experiments:
        if e not in EXPERIMENTS:
            raise ValueError(f"experiment = {e!r}: one of {EXPERIMENTS}")
    if seed_set not in SEED_SETS:
        raise ValueError(f"seed_set = {seed_set!r}: one of {SEED_SETS}")
    from .ledger import log_flight, test_seeds

    conds, seed_list = _conditions(where), _seeds(where, seeds, seed_set)
    if not isinstance(seeds, int) and seed_list:                 # given seeds: the set they belong to
        tested = [bool(test_seeds([s])) for s in seed_list]
        seed_set = "test" if all(tested) else ("validation" if not any(tested) else "test and validation")
    if not conds or not seed_list:
        raise ValueError("margins need at least one condition and one seed")
    log_flight(seed_list, sorted({c.group or c.name for c in conds}), [c.model for c in conds], names,
               purpose, command="margins")
    n_workers = 1 if executor == "serial" else (check_workers(workers) or default_workers())
    parts = min(len(policies), max(1, math.ceil(n_workers / len(conds))))     # enough tasks for the workers
    chunks = [tuple(policies[i::parts]) for i in range(parts)]
    tasks = [MarginTask(chunk, c, tuple(seed_list), tuple(experiments), options) for c in conds for chunk in chunks]
    t0 = time.perf_counter()
    flown = run_map(run_margin_task, tasks, executor, workers, progress, desc="searches", unit="task",
                    describe=_describe)
    wall = time.perf_counter() - t0
    found = {(r["policy"], r["condition"], r["seed"], r["experiment"]): r for part in flown for r in part}
    done = [found[(p.name, c.name, s, e)] for p in policies for c in conds for s in seed_list for e in experiments]
    limits = {"gain_up": options.gain_max_db, "gain_down": options.gain_min_db, "delay": options.delay_max_s * 1e3}
    results = []
    for p in policies:
        mine = [r for r in done if r["policy"] == p.name]
        per_condition = {}
        for c in conds:
            rows = [r for r in mine if r["condition"] == c.name]
            h = rows[0]["physics_dt_s"]
            nominal = {r["seed"]: r["nominal"] for r in rows}
            per_condition[c.name] = {
                "condition": c.to_dict(), "delay_resolution_ms": h * 1e3, "physics_dt_s": h,
                "nominal": [{"seed": s, **nominal[s]} for s in seed_list],
                **{f"{e}_{UNITS[e]}": _summary([r for r in rows if r["experiment"] == e], limits[e])
                   for e in experiments},
                "seeds": rows}
        results.append({"policy": p.name, "factory": p.factory, "kwargs": dict(p.kwargs), "seed_set": seed_set,
                        "seeds": seed_list, "options": asdict(options), "experiments": list(experiments),
                        "conditions": per_condition, "episodes": sum(len(r["trials"]) + 1 for r in mine),
                        "wall_time_s": round(wall, 3)})
    return results


def time_domain_margins(policy_spec: PolicySpec, suite_or_condition: Suite | Condition | Sequence[Condition],
                        seeds: int | Sequence[int] = DEFAULT_SEEDS, **kwargs: Any) -> dict[str, Any]:
    """The time-domain margins of one policy on every condition of a suite (or on the given conditions).

    ``seeds``: a count (the first of ``seed_set``, default ``"validation"``) or the seeds themselves; keywords of
    :func:`run_margins` (``options``: a :class:`MarginOptions`, ``experiments``, ``executor``, ``workers``,
    ``progress``). Returns ``{"policy", "seeds", "options", "conditions": {name: {...}}, "episodes",
    "wall_time_s"}``; per condition ``gain_up_dB``, ``gain_down_dB`` and ``delay_ms`` each hold ``margin``
    (the smallest magnitude over the seeds; None when every nominal episode fails), ``failed_at`` (the
    smallest value tried that failed on that seed; None: beyond the range ``limit``), ``bracket_width``,
    ``median``, ``worst_seed``, the counts ``n_seeds``, ``n_nominal_failed``, ``n_bracketed``; ``seeds``
    holds every seed's search with its episodes, ``nominal`` the unperturbed episodes,
    ``delay_resolution_ms`` the physics step."""
    return run_margins([policy_spec], suite_or_condition, seeds, **kwargs)[0]


# ------------------------------------------------------------------------------------------------ output
def margin_rows(results: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """One flat row per policy, condition and experiment (the ``margins.csv`` rows)."""
    rows = []
    for res in results:
        for name, c in res["conditions"].items():
            for e in res["experiments"]:
                s = c[f"{e}_{UNITS[e]}"]
                rows.append({"policy": res["policy"], "condition": name, "model": c["condition"]["model"],
                             "experiment": e, "unit": UNITS[e], **{k: v for k, v in s.items()},
                             "error_ratio": res["options"]["error_ratio"],
                             "rate_limit_ratio": res["options"]["rate_limit_ratio"],
                             "delay_resolution_ms": c["delay_resolution_ms"], "seed_set": res["seed_set"]})
    return rows


def _cell(s: dict[str, Any], digits: int) -> str:
    if s["margin"] is None:
        return f"n/a (nominal fails {s['n_nominal_failed']}/{s['n_seeds']})"
    if s["failed_at"] is None:
        return f"{'<=' if s['limit'] < 0 else '>='} {s['limit']:.{digits}f} (none failed)"
    text = f"{s['margin']:.{digits}f} (fails {s['failed_at']:.{digits}f}), median {s['median']:.{digits}f}"
    if s["n_bracketed"] < s["n_seeds"] - s["n_nominal_failed"]:
        text += f", {s['n_seeds'] - s['n_nominal_failed'] - s['n_bracketed']} seed(s) beyond range"
    if s["n_nominal_failed"]:
        text += f"; nominal fails {s['n_nominal_failed']}/{s['n_seeds']}"
    return text


def _nominal_cell(nominal: list[dict[str, Any]]) -> str:
    """The nominal episodes: failures, and the medians of the rate error and the time at the rate limit of
    those that flew."""
    flown = [n for n in nominal if not n["failed"]]
    text = f"{len(nominal) - len(flown)}/{len(nominal)}"
    if flown:
        text += (f", {statistics.median(n['rate_error_rad'] for n in flown):.2f}, "
                 f"{statistics.median(n['gimbal_rate_limit_s'] for n in flown):.1f}")
    return text


def margins_table(results: Sequence[dict[str, Any]]) -> str:
    """The Markdown table of the margins, with the method's line under it."""
    lines = ["| policy | condition | nominal: fails, rate error [rad], at rate limit [s] | gain up [dB] | "
             "gain down [dB] | delay [ms] |", "|---|---|---|---|---|---|"]
    opts = results[0]["options"] if results else asdict(MarginOptions())
    res_ms = set()
    for res in results:
        for name, c in res["conditions"].items():
            res_ms.add(c["delay_resolution_ms"])
            cells = [_cell(c[f"{e}_{UNITS[e]}"], 1 if e == "delay" else 2) if e in res["experiments"] else "-"
                     for e in EXPERIMENTS]
            lines.append(f"| {res['policy']} | {name} | {_nominal_cell(c['nominal'])} | " + " | ".join(cells) + " |")
    if results:
        seeds = results[0]["seeds"]
        lines += ["", f"Margin: the smallest over {len(seeds)} {results[0]['seed_set']} seeds ({seeds[0]}-{seeds[-1]}) "
                  f"of the largest value that flew without failing, with rate_error_rad <= {opts['error_ratio']:g} x "
                  f"the seed's nominal (at least {RATE_ERROR_FLOOR_RADPS * 1e3:g} mrad/s over its flight) and time at "
                  f"the gimbal rate limit <= {opts['rate_limit_ratio']:g} x the nominal's (at least "
                  f"{RATE_LIMIT_FLOOR_S:g} s); 'fails': the next value tried on that seed, "
                  f"which failed; nominal: medians over the seeds that flew; gain bracket <= {opts['gain_tol_db']:g} "
                  f"dB, delay resolution {', '.join(f'{r:g}' for r in sorted(res_ms))} ms (the physics step)."]
    return "\n".join(lines) + "\n"


def write_margins(out: str | Path, results: Sequence[dict[str, Any]], meta: dict[str, Any]) -> list[Path]:
    """``margins.csv`` (:func:`margin_rows`), ``margin_trials.csv`` (every episode flown), ``margins.md``
    (:func:`margins_table`) and ``margins.json`` (all of it and ``meta``; written last), each atomically."""
    out = Path(out)
    trials = [{"policy": s["policy"], "condition": s["condition"], "seed": s["seed"], "experiment": s["experiment"],
               "unit": s["unit"], **{f"bound_{k}": v for k, v in s["bounds"].items()}, **t}
              for res in results for c in res["conditions"].values() for s in c["seeds"] for t in s["trials"]]
    return [atomic_write_text(out / "margins.csv", csv_text(margin_rows(results))),
            atomic_write_text(out / "margin_trials.csv", csv_text(trials)),
            atomic_write_text(out / "margins.md", margins_table(results)),
            atomic_write_text(out / "margins.json", json_text({"meta": meta, "results": list(results)}))]
