"""Train the thrust-direction estimator (:mod:`.estimator`) of one training seed: a teacher-student scheme.

    python -m experiments.fault_id.train --seed 0            # results/fault_id/estimator-s0.pt

1. **Teacher's flights.** ``lqg`` flies ``smile-v2-faults`` (both flight models, ``--flights`` each, training
   seeds ``100000 + 10000 seed ...``: neither validation nor test seeds) with the true misalignment (the env's
   privileged info) subtracted from its command, known late by a delay drawn per flight from
   :data:`DELAYS` (never known, for one flight in six), so the flights cover the states before and after
   the correction. Every step is recorded as the student sees it (:class:`.estimator.Window`) with the true
   misalignment over the gimbal limit as its label.
2. **Regression.** :class:`.estimator.Estimator` fitted by mean squared error (Adam, ``--epochs``).
3. **DAgger rounds** (``--rounds``): the student flies half as many flights again, labelled the same way,
   added to the data, and the estimator is fitted again.

After each fit the student flies validation seeds ``0 .. --validation - 1`` of both flight models and the
mean ``score_v2`` and its failed or unflyable flights are printed (``lqg``: 0.994 (6) rigid, 1.109 (7)
non-rigid on seeds 0-99; ``lqg`` with the true misalignment 0.778 (2), 0.900 (2): README.md).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from lvgym.cli.args import arg, parse

from .estimator import RESULTS, Estimator, Window, base_lqg, corrected

#: the teacher's delays [control steps] of its knowledge of the misalignment (0-2 s at 0.02 s; the last: never)
DELAYS = (0, 12, 25, 50, 100, None)
SUITE = "smile-v2-faults"


def condition(model: str, **options: Any):
    """The fault suite's condition of ``model`` with env ``options`` (``privileged_info=True``: the info the
    teacher and the labels need, the same flight with the true state in the info)."""
    from lvgym.benchmark.suites import get_suite

    return {c.model: c for c in get_suite(SUITE).conditions}[model].with_options(**options)


def fly(model: str, seeds: Sequence[int], estimator: Estimator | None = None,
        rng: np.random.Generator | None = None, deadband: float = 0.0,
        **options: Any) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """Fly the rows seeded ``seeds`` of the batched env of ``model``: ``lqg`` corrected by the true
    misalignment known late by a delay drawn from ``rng`` (``estimator`` None: the teacher) or by the
    ``estimator`` (the student, its estimate shrunk by ``deadband``: :func:`.estimator.corrected`). Returns
    the windows ``(steps, WINDOW, FEATURES)``, their labels ``(steps, 2)`` and the flights' records
    (protocol v2's fields); ``options``: env keywords (tests shorten the mission)."""
    from lvgym.benchmark.batch import as_batch
    from lvgym.benchmark.rows import RowsLog

    c = condition(model, privileged_info=True, **options)
    n = len(seeds)
    env, env1 = c.make_vec_env(n), c.make_env()
    limit = float(env1.unwrapped.func.gimbal_limit)
    lqg = as_batch(base_lqg(env1), n, lambda: base_lqg(env1))
    delay = None if estimator is not None else [DELAYS[i] for i in rng.integers(0, len(DELAYS), n)]
    obs, info = env.reset(seed=[int(s) for s in seeds])
    lqg.reset(np.arange(n))
    window, log = Window(n), RowsLog(env)
    truth: list[np.ndarray] = []                      # the true misalignment of every row at every step [rad]
    xs, ys = [], []
    done, step = np.zeros(n, dtype=bool), 0
    while not done.all():
        live = np.flatnonzero(~done)
        base = np.asarray(lqg.act(live, obs[live], info), dtype=np.float64)
        truth.append(np.asarray(info["misalignment"], dtype=np.float64).reshape(n, 2) if "misalignment" in info
                     else np.zeros((n, 2)))
        w = window.push(live, obs[live])
        xs.append(w.copy())
        ys.append((truth[-1][live] / limit).astype(np.float32))
        if estimator is None:
            known = [truth[step - d][r] if d is not None and step >= d else np.zeros(2) for r, d in
                     zip(live, (delay[r] for r in live))]
            estimate = np.array(known) / limit
        else:
            with torch.no_grad():
                estimate = estimator(torch.as_tensor(w)).numpy().astype(np.float64)
        a = corrected(base, estimate, 0.0 if estimator is None else deadband)
        window.sent(live, a)
        actions = np.zeros((n, 2), dtype=np.float32)
        actions[live] = a
        obs, reward, term, trunc, info = env.step(actions)
        log.add(live, obs, reward, info, actions)
        ended = live[(np.asarray(term) | np.asarray(trunc))[live]]
        log.end(ended, info)
        done[ended] = True
        step += 1
    env.close()
    return np.concatenate(xs), np.concatenate(ys), log.records(True)


def fit(x: np.ndarray, y: np.ndarray, seed: int, epochs: int) -> Estimator:
    """The estimator fitted to windows ``x`` and labels ``y`` (torch seeded with ``seed``)."""
    torch.manual_seed(seed)
    flat = x.reshape(-1, x.shape[-1])
    est = Estimator(flat.mean(0), flat.std(0) + 1e-6)
    opt = torch.optim.Adam(est.parameters(), 1e-3)
    xt, yt = torch.as_tensor(x), torch.as_tensor(y)
    g = torch.Generator().manual_seed(seed)
    for epoch in range(epochs):
        perm, total = torch.randperm(len(xt), generator=g), 0.0
        for i in range(0, len(xt), 1024):
            b = perm[i:i + 1024]
            loss = ((est(xt[b]) - yt[b]) ** 2).mean()
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += float(loss.detach()) * len(b)
        print(f"  epoch {epoch}: mean squared error {total / len(xt):.3e} (labels' variance {float(yt.var()):.3e})",
              flush=True)
    return est


def validate(est: Estimator, episodes: int, deadband: float = 0.0) -> dict[str, tuple[float, int]]:
    """Mean ``score_v2`` and failed or unflyable flights of the student on validation seeds ``0 ..
    episodes - 1`` per flight model (:func:`fly`: the rows of one batched env; the benchmark flies the same
    law one row at a time through :class:`.estimator.FaultIdPolicy`)."""
    out = {}
    for model in ("rigid", "nonrigid"):
        rs = [r for k in range(0, episodes, 100)
              for r in fly(model, range(k, min(episodes, k + 100)), est, deadband=deadband)[2]]
        bad = sum(bool(r["failed"] or not r["flyable"]) for r in rs)
        out[model] = (float(np.mean([r["score_v2"] for r in rs])), bad)
    return out


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.train --help``)."""

    seed: int = arg(0, lo=0, hi=99)
    """the training seed (its flights' seeds, the teacher's delays, the fits)"""
    flights: int = arg(200, lo=10, hi=2000)
    """teacher's flights per flight model (in batches of 100 rows)"""
    rounds: int = arg(2, lo=0, hi=10)
    """DAgger rounds after the teacher's data"""
    epochs: int = arg(8, lo=1, hi=100)
    """epochs per fit"""
    validation: int = arg(100, lo=0, hi=1000)
    """validation seeds flown after each fit (0: none)"""


def main(argv: Sequence[str] | None = None) -> None:
    a = parse(Args, argv, "python -m experiments.fault_id.train", __doc__)
    torch.set_num_threads(1)
    RESULTS.mkdir(parents=True, exist_ok=True)
    rng, t0 = np.random.default_rng(a.seed), time.time()
    first = 100_000 + 10_000 * a.seed
    xs, ys = [], []
    est: Estimator | None = None                      # the teacher flies round 0, the student the others
    for rnd in range(a.rounds + 1):
        count = a.flights if rnd == 0 else max(1, a.flights // 2)
        start = first + (0 if rnd == 0 else 5_000 * rnd)
        for model in ("rigid", "nonrigid"):
            for k in range(0, count, 100):
                seeds = list(range(start + k, start + min(count, k + 100)))
                x, y, _ = fly(model, seeds, est, rng)
                xs.append(x)
                ys.append(y)
        print(f"seed {a.seed} round {rnd}: {sum(len(x) for x in xs)} steps of data at {time.time() - t0:.0f} s",
              flush=True)
        est = fit(np.concatenate(xs), np.concatenate(ys), a.seed, a.epochs)
        torch.save(est.state_dict(), RESULTS / f"estimator-s{a.seed}-r{rnd}.pt")
        if a.validation:
            v = validate(est, a.validation)
            print(f"seed {a.seed} round {rnd} validation 0-{a.validation - 1}: " + ", ".join(
                f"{m} {s:.3f} ({b})" for m, (s, b) in v.items()) + f" at {time.time() - t0:.0f} s", flush=True)
    torch.save(est.state_dict(), RESULTS / f"estimator-s{a.seed}.pt")
    print(f"wrote {RESULTS / f'estimator-s{a.seed}.pt'} in {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main()
