"""``lqi`` against ``lqg-aw`` and ``lqg`` on the fault suite: the attitude offset a thrust-direction step leaves,
and the score and the losses by fault kind, on **validation** seeds.

    python -m experiments.lqi_faults.compare --first 0 --last 200                     # smile-v2-faults, both models
    python -m experiments.lqi_faults.compare --kind misalignment --last 100           # every flight a thrust step

Every flight is the benchmark's (the rows of one batched env per block of seeds, :func:`lvgym.benchmark.rows.fly_rows`:
each row its single env's flight, to the bit; its record gives ``score_v2``, ``failed``, ``flyable`` and the
``fault``). The policy is wrapped to keep, per control step, the **true** attitude error (the env's
``info["attitude_error"]``, pitch and yaw [rad]; the evaluation's view, which the controllers never read) and
the flight time; the fault's onset, size and axis are read from the env's rows after the reset (the
evaluation's view again). Per flight with a thrust-direction step (``misalignment``) on axis ``i``:

- ``step_deg``: the step [deg], signed;
- ``peak_deg``: the largest ``|attitude error_i|`` [deg] in the 10 s after the onset (within the boost, which
  burns out at 43 s);
- ``offset_deg``: the attitude error's change the step leaves at the end of the boost, the mean of
  ``attitude error_i`` over 40.5-42.5 s minus its mean over the second before the onset [deg], for steps
  struck by 35.5 s (5 s to settle; NaN otherwise or for a lost flight);
- ``end_offset_deg``: the mean ``attitude error_i`` over the last 2 s of the flight [deg] (the upper stage,
  which flies the misalignment from its ignition on; NaN for a lost flight).

``--kind`` draws every flight's fault from that kind alone (``fault_kinds=(kind,)``; onset, size, axis and sign
as the suite draws them). Writes ``episodes.csv`` and prints the tables of docs/lqi.md.
"""

from __future__ import annotations

import csv
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies)
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.rows import fly_rows
from lvgym.benchmark.runner import build_policy
from lvgym.benchmark.batch import as_batch
from lvgym.benchmark.suites import condition
from lvgym.commandline import arg, parse
from lvgym.envs.faults import FAULT, FAULT_NAMES

PROG = "python -m experiments.lqi_faults.compare"
SUITE = "smile-v2-faults"
#: the boost's end of the window of ``offset_deg`` [s] (SMILE v1 burns out at 43 s; its phase ends at 42.5 s)
BOOST_END_S = 42.5
WINDOW_S = 2.0
SETTLE_S = 5.0
PEAK_S = 10.0


class Recorder:
    """A batch policy with the true attitude error (n, 2) [rad] and the time (n,) [s] of every step kept for the
    rows it acts for (from the ``info`` it is handed), and the rows' faults (layout :data:`FAULT`) read from the
    env after its reset."""

    def __init__(self, policy: Any, env: Any) -> None:
        self.policy, self.env, self.name = policy, env, policy.name
        self.att: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self.fault = None

    def reset(self, rows: Any) -> None:
        self.policy.reset(rows)
        self.fault = np.array(self.env.unwrapped.state.task.fault, copy=True)

    def act(self, rows: Any, observations: np.ndarray, info: Any) -> np.ndarray:
        if "attitude_error" in info:
            rows = np.asarray(rows)
            self.att.append((rows, np.asarray(info["time"])[rows].copy(), np.asarray(info["attitude_error"])[rows].copy()))
        return self.policy.act(rows, observations, info)

    def series(self, row: int) -> tuple[np.ndarray, np.ndarray]:
        """The times (m,) [s] and the true attitude errors (m, 2) [rad] of one row."""
        t, a = [], []
        for rows, tt, aa in self.att:
            hit = np.flatnonzero(rows == row)
            if hit.size:
                t.append(tt[hit[0]])
                a.append(aa[hit[0]])
        return np.asarray(t), np.asarray(a).reshape(-1, 2)


def step_metrics(t: np.ndarray, att: np.ndarray, onset: float, axis: int, lost: bool) -> dict[str, float]:
    """``peak_deg``, ``offset_deg`` and ``end_offset_deg`` of one flight's true attitude error ``att`` (m, 2)
    [rad] at times ``t`` (m,) [s] after a step at ``onset`` [s] on ``axis`` (module docstring)."""
    e = np.degrees(att[:, axis]) if att.size else np.zeros(0)
    after = (t >= onset) & (t <= min(onset + PEAK_S, BOOST_END_S))
    peak = float(np.abs(e[after]).max()) if after.any() else math.nan
    offset = math.nan
    end = (t >= BOOST_END_S - WINDOW_S) & (t <= BOOST_END_S)
    before = (t >= onset - 1.0) & (t < onset)
    if onset <= BOOST_END_S - WINDOW_S - SETTLE_S + 1e-9 and end.any() and before.any() and not lost:
        offset = float(e[end].mean() - e[before].mean())
    last = t >= (t.max() - WINDOW_S if t.size else 0.0)
    end_offset = float(e[last].mean()) if (t.size and not lost) else math.nan
    return {"peak_deg": peak, "offset_deg": offset, "end_offset_deg": end_offset}


def fly(policies: Sequence[str], seeds: Sequence[int], model: str, kind: str | None = None,
        block: int = 50) -> list[dict[str, Any]]:
    """The records of ``policies`` on ``seeds`` of the fault suite's ``model`` condition (``kind``: every flight's
    fault of that kind), with :func:`step_metrics` on the flights of a thrust-direction step."""
    cond = condition(SUITE, model)
    if kind is not None:
        cond = cond.with_options(fault_kinds=(kind,))
    out = []
    for name in policies:
        spec = resolve_policy(name, PROG)
        for lo in range(0, len(seeds), block):
            part = [int(s) for s in seeds[lo:lo + block]]
            env = cond.make_vec_env(len(part))
            base = as_batch(build_policy(spec, env), len(part), lambda: build_policy(spec, env))
            rec = Recorder(base, env)
            records = fly_rows(env, part, [(rec, np.arange(len(part)))], flyability=True)
            f = FAULT.at
            for b, r in enumerate(records):
                fr = rec.fault[b]
                kind_name = FAULT_NAMES[int(fr[f.kind]) - 1] if fr[f.kind] > 0 else ""
                row = {"policy": name, "model": model, "seed": part[b], "kind": kind_name, "fault": r.get("fault", ""),
                       "onset_s": float(fr[f.onset_s]), "score_v2": float(r["score_v2"]), "failed": bool(r["failed"]),
                       "flyable": bool(r["flyable"]), "step_deg": math.nan, "peak_deg": math.nan,
                       "offset_deg": math.nan, "end_offset_deg": math.nan}
                if kind_name == "misalignment":
                    t, a = rec.series(b)
                    lost = bool(r["failed"]) or not bool(r["flyable"])
                    row.update(step_deg=math.degrees(float(fr[f.size])),
                               **step_metrics(t, a, float(fr[f.onset_s]), int(fr[f.axis]), lost))
                out.append(row)
            env.close()
    return out


def _ci(x: np.ndarray) -> str:
    if x.size == 0:
        return "-"
    if x.size == 1:
        return f"{x.mean():.4f}"
    h = 1.96 * x.std(ddof=1) / math.sqrt(x.size)
    return f"{x.mean():.4f} [{x.mean() - h:.4f}, {x.mean() + h:.4f}]"


def tables(rows: list[dict[str, Any]]) -> str:
    """The score and the losses by fault kind, and the attitude offsets of the thrust-direction steps."""
    lines = ["| model | kind | policy | flights | score_v2 mean [95 % CI] | lost (failed or unflyable) |",
             "|---|---|---|---:|---:|---:|"]
    pols = list(dict.fromkeys(r["policy"] for r in rows))
    for model in dict.fromkeys(r["model"] for r in rows):
        for kind in sorted({r["kind"] for r in rows}):
            for p in pols:
                sel = [r for r in rows if r["model"] == model and r["kind"] == kind and r["policy"] == p]
                if sel:
                    lost = sum(r["failed"] or not r["flyable"] for r in sel)
                    lines.append(f"| {model} | {kind or 'none'} | {p} | {len(sel)} | "
                                 f"{_ci(np.array([r['score_v2'] for r in sel]))} | {lost} |")
    lines += ["", "| model | policy | steps | peak mean / worst [deg] | boost offset mean / worst [deg] (n) | "
              "upper-stage end offset mean / worst [deg] |", "|---|---|---:|---:|---:|---:|"]
    for model in dict.fromkeys(r["model"] for r in rows):
        for p in pols:
            sel = [r for r in rows if r["model"] == model and r["policy"] == p and r["kind"] == "misalignment"]
            if not sel:
                continue
            pk = np.array([r["peak_deg"] for r in sel if not math.isnan(r["peak_deg"])])
            off = np.abs(np.array([r["offset_deg"] for r in sel if not math.isnan(r["offset_deg"])]))
            end = np.abs(np.array([r["end_offset_deg"] for r in sel if not math.isnan(r["end_offset_deg"])]))

            def mw(x: np.ndarray) -> str:
                return f"{x.mean():.3f} / {x.max():.3f}" if x.size else "-"
            lines.append(f"| {model} | {p} | {len(sel)} | {mw(pk)} | {mw(off)} ({off.size}) | {mw(end)} |")
    return "\n".join(lines) + "\n"


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.lqi_faults.compare --help``)."""

    policies: list[str] = arg(default_factory=lambda: ["lqg", "lqg-aw", "lqi"], metavar="POLICY")
    """policies as evaluate.py takes them"""
    models: list[str] = arg(default_factory=lambda: ["nonrigid", "rigid"], metavar="MODEL")
    """the flight models"""
    first: int = arg(0, lo=0, hi=9_999)
    """the first validation seed"""
    last: int = arg(100, lo=1, hi=10_000)
    """one past the last validation seed"""
    kind: str | None = arg(None, choices=FAULT_NAMES)
    """draw every flight's fault from this kind alone (default: the suite's kinds)"""
    block: int = arg(50, lo=1, hi=1000)
    """rows of one batched env"""
    out: str = "results/lqi_faults"
    """folder of episodes.csv and tables.md"""


def main(argv: Sequence[str] | None = None) -> list[dict[str, Any]]:
    a = parse(Args, argv, PROG, __doc__)
    seeds = list(range(a.first, a.last))              # validation seeds (0..9,999): never the test block
    rows = [r for m in a.models for r in fly(a.policies, seeds, m, a.kind, a.block)]
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "episodes.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    text = tables(rows)
    (out / "tables.md").write_text(text)
    print(text)
    return rows


if __name__ == "__main__":
    main(sys.argv[1:])
