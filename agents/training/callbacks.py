"""Training callbacks: crash-safe checkpoints with validation on the benchmark protocol (the progress bar
and line: :mod:`lvgym.agents.training.progress`).

A checkpoint ``checkpoints/step_<N>`` (N = env steps, 12 digits) is::

    step_<N>.zip, step_<N>_vecnormalize.pkl     model (weights, optimiser; carrying the normalisation
                                                statistics) and the statistics
    step_<N>_rng.pkl                            torch, numpy and random generator states
    step_<N>_replay_buffer.pkl                  SAC / TD3 replay buffer (kept for the latest checkpoint only)
    step_<N>.json                               state: algo, steps, evaluation history, best so far

each file written atomically and the JSON last: a checkpoint exists once its JSON does, so a run killed at
any moment resumes from a complete checkpoint (files of a half-written one are removed on resume).
Checkpoints are due every ``save_freq`` env steps and every ``interval_s`` seconds of wall time (so a
kill loses at most about that much work), and on SIGTERM or SIGINT (:class:`SignalStop`): training then
stops at the next env step, the checkpoint is written (without validation) and the run exits; a PPO
rollout cut short is not trained on (SAC and TD3 keep its transitions in the replay buffer). A spent
wall-time budget stops training the same way but ends the run as its last step does (a validated
checkpoint, ``final_model.*``, ``best_model.*``, ``evaluations.json``).
Checkpoints are taken at rollout boundaries (after a PPO update, before the next rollout), so the weights,
the optimiser, the step counter and the statistics agree. Validation (when due) runs at a checkpoint, on
the checkpointed model, with the protocol's validation seeds; its result is part of the checkpoint's JSON,
so the evaluation history and the best model are restored with it. ``best_model.*`` and ``final_model.*``
next to ``checkpoints/`` are copies in the :mod:`lvgym.agents.policies.saved` layout (loadable by ``evaluate.py``).
"""

from __future__ import annotations

import contextlib
import json
import pickle
import random
import re
import signal
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback

from lvgym.benchmark.flyability import applies
from lvgym.benchmark.metrics import summarize
from lvgym.benchmark.policy import Policy
from lvgym.benchmark.results import atomic_path, atomic_write_text, json_text
from lvgym.benchmark.runner import play_episode
from lvgym.benchmark.suites import Suite, family_validation_suite, get_suite

from ..policies.checkpoints import checkpoint_stem, list_checkpoints
from ..policies.saved import copy_policy, policy_files, save_model
from ..policies.sb3 import SB3Policy, adapt

#: what a validation's ``score`` is: compared lexicographically, lower is better (older runs' checkpoints
#: without this key ranked on ``[failure rate, rate error]``)
SELECTION = "failure_rate, score"
#: the same on a suite that charges flyability (protocol v2 on): the share of failed or unflyable
#: episodes, then the mean ``score_v2``
SELECTION_V2 = "failure_rate_v2, score_v2"
RNG_SUFFIX = "_rng.pkl"
BUFFER_SUFFIX = "_replay_buffer.pkl"


def save_rng(path: Path) -> None:
    import torch

    state = {"torch": torch.get_rng_state(), "numpy": np.random.get_state(), "random": random.getstate()}
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        pickle.dump(state, f)


def load_rng(path: Path) -> bool:
    """Restore the generator states saved by :func:`save_rng`; False when there is no file."""
    import torch

    if not path.is_file():
        return False
    with open(path, "rb") as f:
        state = pickle.load(f)
    torch.set_rng_state(state["torch"])
    np.random.set_state(state["numpy"])
    random.setstate(state["random"])
    return True


# ------------------------------------------------------------------------------------------ validation
class ValidationEvaluator:
    """Episodes of a policy on every condition of a protocol suite, reset with the suite's validation
    seeds (``lvgym.benchmark``: same conditions, seeds, trajectory and metrics as ``evaluate.py``).
    ``overrides``: env keywords for every condition (e.g. ``mission_time_s`` in tests; the suite is then
    marked ``+override``). ``select_on``: the flight model (``rigid``, ``nonrigid``, ...) whose conditions
    make the selection score; None, or a model the suite does not fly: all conditions. A policy trained on
    one model and selected on every condition has seen the others through model selection. A family suite
    is flown on the family's validation vehicles (:func:`~lvgym.benchmark.suites.family_validation_suite`),
    never on its test vehicles."""

    def __init__(self, suite: str | Suite, episodes: int, overrides: dict[str, Any] | None = None,
                 select_on: str | None = None) -> None:
        s = family_validation_suite(get_suite(suite) if isinstance(suite, str) else suite)   # never test vehicles
        self.suite = s.with_options(**overrides) if overrides else s
        self.seeds = self.suite.seeds("validation", int(episodes))
        self.flyability = applies(self.suite.version)
        self.selection = SELECTION_V2 if self.flyability else SELECTION
        chosen = [c.name for c in self.suite.conditions if c.model == select_on]
        self.selected = chosen or [c.name for c in self.suite.conditions]
        self._envs: dict[Any, Any] = {}
        self._built: dict[Any, Policy] = {}

    def episode(self, policy: Policy, condition: Any, seed: int) -> dict[str, Any]:
        """One episode's record (as ``lvgym.benchmark.runner.run_episode`` returns it), flown by the
        protocol's :func:`~lvgym.benchmark.runner.play_episode`."""
        if condition not in self._envs:
            self._envs[condition] = condition.make_env()
        return {"suite": self.suite.name, "condition": condition.name, "group": condition.group,
                "policy": policy.name, "model": condition.model, "seed": int(seed),
                **play_episode(policy, self._envs[condition], seed, flyability=self.flyability)}

    def evaluate(self, policy: Policy) -> dict[str, Any]:
        """Per-condition means and failure rates, and the selection ``score``: ``[failure rate, score]``
        averaged over the selected conditions (``selected_on``), compared lexicographically (lower is
        better). The second entry is the episodes' failure-charged ``score`` of protocol v1
        (:func:`lvgym.benchmark.scoring.flight_metrics`: the rate error plus, for a failed episode, the
        failure penalty for the mission left), so among equal failure rates a policy that fails late is
        not preferred for its shorter rate-error integral. On a suite that charges flyability (v2 on) the
        episodes also carry v2's metrics and the selection ``score`` is ``[failed or unflyable rate, mean
        score_v2]`` (:data:`SELECTION_V2`). ``policy``: a Policy, or a callable that builds
        one for a condition's env (e.g. a residual policy whose baseline needs the env)."""
        self._built.clear()                          # a factory's policies live for this evaluation only
        records = [r for c in self.suite.conditions for r in self._fly(policy, c)]
        rows = summarize(records, ("rate_error_rad", "score", "max_rate_radps", "effort_rad_s", "episode_return")
                         + (("score_v2", "cmd_rate_rms") if self.flyability else ()))
        conds: dict[str, dict[str, float]] = {}
        for r in rows:
            conds[r["condition"]] = {k: float(r[k]) for k in r if isinstance(r[k], (int, float))
                                     and not isinstance(r[k], bool) and k != "n"}
        sel = [conds[name] for name in self.selected]
        fail = float(np.mean([c["failure_rate"] for c in sel]))
        err = float(np.mean([c["rate_error_rad_mean"] for c in sel]))
        charged = float(np.mean([c["score_mean"] for c in sel]))
        out = {"suite": self.suite.name, "version": self.suite.version, "seed_set": "validation",
               "episodes": len(self.seeds), "conditions": conds, "selected_on": list(self.selected),
               "failure_rate": fail, "rate_error_rad": err, "episode_score": charged, "score": [fail, charged],
               "selection": self.selection}
        if self.flyability:                  # v2: failed or unflyable, then score_v2
            bad = float(np.mean([c["failure_rate_v2"] for c in sel]))
            v2 = float(np.mean([c["score_v2_mean"] for c in sel]))
            out.update({"failure_rate_v2": bad, "score_v2": v2, "score": [bad, v2]})
        return out

    def _fly(self, policy: Any, condition: Any) -> list[dict[str, Any]]:
        """The records of every validation seed on ``condition``, in seed order: flown together as the rows
        of its batched env when the policy has ``batch(n)`` (:func:`lvgym.benchmark.rows.fly_rows`: each row's
        record is the single env's :meth:`episode` of its seed, to the bit), else one episode after another."""
        from lvgym.benchmark.rows import fly_rows

        first, n = self._policy(policy, condition), len(self.seeds)
        if n == 1 or not callable(getattr(first, "batch", None)):
            return [self.episode(first, condition, s) for s in self.seeds]
        key = ("rows", condition, n)
        if key not in self._envs:
            self._envs[key] = condition.make_vec_env(n)
        flown = fly_rows(self._envs[key], self.seeds, [(first.batch(n), np.arange(n))], flyability=self.flyability)
        return [{"suite": self.suite.name, "condition": condition.name, "group": condition.group,
                 "policy": first.name, "model": condition.model, "seed": int(seed), **r}
                for seed, r in zip(self.seeds, flown)]

    def _policy(self, policy: Any, condition: Any) -> Policy:
        """``policy`` itself, or the one the factory ``policy`` builds for ``condition``'s env (cached)."""
        if isinstance(policy, Policy):
            return policy
        if condition not in self._envs:
            self._envs[condition] = condition.make_env()
        key = ("policy", id(policy), condition)
        if key not in self._built:
            self._built[key] = policy(self._envs[condition])
        return self._built[key]

    def close(self) -> None:
        for env in self._envs.values():
            env.close()
        self._envs.clear()
        self._built.clear()


# ------------------------------------------------------------------------------------------ signals
class SignalStop:
    """SIGTERM and SIGINT as a request to checkpoint and stop. While :meth:`installed`, a signal outside
    :meth:`armed` (nothing to save yet) or a second signal raises ``SystemExit(128 + signal)`` at once;
    inside :meth:`armed` the first one only sets :attr:`signum`, which :class:`CheckpointCallback` reads at
    the next env step. Outside the main thread (no signal handlers there) it does nothing."""

    SIGNALS = (signal.SIGTERM, signal.SIGINT)

    def __init__(self) -> None:
        self.signum: int | None = None
        self._armed = False

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name if self.signum is not None else ""

    def _handle(self, signum: int, frame: Any) -> None:
        if not self._armed or self.signum is not None:
            raise SystemExit(128 + signum)
        self.signum = signum
        print(f"\n{signal.Signals(signum).name}: writing a checkpoint at the next env step, then exiting "
              "(send it again to stop at once)", file=sys.stderr)

    @contextlib.contextmanager
    def installed(self) -> Iterator[SignalStop]:
        old = {}
        try:
            for s in self.SIGNALS:
                old[s] = signal.signal(s, self._handle)
        except ValueError:                              # not the main thread: leave the handlers alone
            pass
        try:
            yield self
        finally:
            for s, handler in old.items():
                signal.signal(s, handler)

    @contextlib.contextmanager
    def armed(self) -> Iterator[SignalStop]:
        self._armed = True
        try:
            yield self
        finally:
            self._armed = False


# ------------------------------------------------------------------------------------------ checkpoints
class CheckpointCallback(BaseCallback):
    """Checkpoint every ``save_freq`` env steps (at the first rollout boundary past it) and at the end;
    validate with ``evaluator`` at the checkpoints at least ``eval_freq`` steps after the last validation
    (and at the end; ``eval_freq <= 0`` or no evaluator: never). Also checkpoints (without validation) at
    the first rollout boundary ``interval_s`` seconds of wall time after the last checkpoint (0: never),
    and when ``stop`` (a :class:`SignalStop`) has a signal: training then ends at the next env step with a
    checkpoint and without ``final_model``. At the first env step past ``deadline`` (a ``time.monotonic()``
    value: the run's wall-time budget, :attr:`out_of_time`) training ends as at its last step: a checkpoint,
    validated (with an evaluator), ``final_model`` and ``best_model``. Keeps the newest ``keep`` checkpoints
    and the best one.
    ``meta``: written into every JSON (algo, env id and kwargs, ...). ``state``: the JSON of the
    checkpoint a resumed run starts from (restores the evaluation history, the best and the wall time
    spent, ``train_wall_s``)."""

    def __init__(self, run_dir: str | Path, save_freq: int, meta: dict[str, Any], vecnormalize: Any = None,
                 evaluator: ValidationEvaluator | None = None, eval_freq: int = 0, keep: int = 3,
                 state: dict[str, Any] | None = None, verbose: int = 0, interval_s: float = 0.0,
                 stop: SignalStop | None = None, deadline: float | None = None) -> None:
        super().__init__(verbose)
        self.run_dir = Path(run_dir)
        self.folder = self.run_dir / "checkpoints"
        self.save_freq = max(1, int(save_freq))
        self.meta = dict(meta)
        self.vecnormalize = vecnormalize
        self.evaluator = evaluator
        self.eval_freq = int(eval_freq)
        self.keep = max(1, int(keep))
        state = state or {}
        self.evaluations: list[dict[str, Any]] = list(state.get("evaluations", []))
        self.best: dict[str, Any] | None = state.get("best")
        self.last_save = int(state.get("num_timesteps", -1))      # any checkpoint
        self.last_step_save = self.last_save                        # the last one due by steps
        self.last_eval = int(self.evaluations[-1]["num_timesteps"]) if self.evaluations else 0
        self.interval_s = float(interval_s)
        self.stop = stop
        self.deadline = deadline
        self.out_of_time = False                     # the deadline passed: training stops as on a signal
        self.wall0 = float(state.get("train_wall_s", 0.0))
        self.t_start = self.last_save_time = time.monotonic()
        self.clock = None                   # the venv's EnvClock (lvgym.agents.training.timing), found at the start
        self.env0 = float(state.get("env_wall_s", 0.0))
        self.env_at_start = 0.0

    def _init_callback(self) -> None:
        from lvgym.agents.training.timing import find_clock

        self.folder.mkdir(parents=True, exist_ok=True)
        self.t_start = self.last_save_time = time.monotonic()
        self.clock = find_clock(self.training_env)
        self.env_at_start = self.clock.env_s if self.clock is not None else 0.0
        if self.last_save < 0:
            self.last_save = self.last_step_save = self.num_timesteps
        if self.best is not None:                   # a resumed run: best_model.* as of its checkpoint
            self._copy_best()

    @property
    def stopping(self) -> bool:
        return self.out_of_time or (self.stop is not None and self.stop.signum is not None)

    def _on_step(self) -> bool:
        if self.deadline is not None and not self.out_of_time and time.monotonic() >= self.deadline:
            self.out_of_time = True
        return not self.stopping                    # False ends model.learn (then _on_training_end)

    def train_wall_s(self) -> float:
        """Wall time [s] of the run so far, every segment of a resumed run included."""
        return self.wall0 + time.monotonic() - self.t_start

    def timing(self) -> dict[str, float]:
        """``train_wall_s`` and, with an :class:`lvgym.agents.training.timing.EnvClock` in the venv, ``env_wall_s``
        [s]."""
        out = {"train_wall_s": round(self.train_wall_s(), 3)}
        if self.clock is not None:
            out["env_wall_s"] = round(self.env_wall_s(), 3)
        return out

    def env_wall_s(self) -> float:
        """Wall time [s] spent in the env since learning started, every segment included."""
        return self.env0 + (self.clock.env_s - self.env_at_start if self.clock is not None else 0.0)

    def _on_rollout_end(self) -> None:
        if self.clock is not None:
            self.logger.record("time/env_share", self.env_wall_s() / max(self.train_wall_s(), 1e-9))
            self.logger.record("time/train_wall_s", self.train_wall_s())

    def _on_rollout_start(self) -> None:
        by_steps = self.num_timesteps - self.last_step_save >= self.save_freq     # the same steps on every run
        by_time = self.interval_s > 0 and time.monotonic() - self.last_save_time >= self.interval_s
        if (by_steps or by_time) and self.num_timesteps != self.last_save:
            due = by_steps and self.evaluator is not None and self.eval_freq > 0 and \
                self.num_timesteps - self.last_eval >= self.eval_freq
            self.save(evaluate=due)
            if by_steps:
                self.last_step_save = self.num_timesteps

    def _on_training_end(self) -> None:
        if self.out_of_time and self.num_timesteps >= int(getattr(self.model, "_total_timesteps", 0) or 0) > 0:
            self.out_of_time = False                 # the deadline came with the last step: the run is done
        if self.stop is not None and self.stop.signum is not None:   # a signal: checkpoint now, no validation,
            if self.num_timesteps != self.last_save or not list_checkpoints(self.folder):   # no final model
                self.save(evaluate=False)
            return
        # the end of the steps or of the wall-time budget: a validated checkpoint of the last step, the final model
        validate = self.evaluator is not None and self.eval_freq > 0
        if self.num_timesteps != self.last_save or not list_checkpoints(self.folder) or \
                (validate and self.last_eval != self.num_timesteps):
            self.save(evaluate=validate)
        last = list_checkpoints(self.folder)
        if last:
            copy_policy(last[-1][1], self.run_dir / "final_model")

    def save(self, evaluate: bool = False) -> Path:
        """Write a checkpoint of the model now (and validate it first if ``evaluate``)."""
        step = int(self.num_timesteps)
        stem = checkpoint_stem(self.folder, step)
        zip_path, json_path = save_model(self.model, self.vecnormalize, stem), policy_files(stem)[2]
        save_rng(stem.with_name(stem.name + RNG_SUFFIX))
        if hasattr(self.model, "save_replay_buffer") and self.model.replay_buffer is not None:
            with atomic_path(stem.with_name(stem.name + BUFFER_SUFFIX)) as tmp:
                with open(tmp, "wb") as f:
                    pickle.dump(self.model.replay_buffer, f, protocol=pickle.HIGHEST_PROTOCOL)
        new_best = False
        if evaluate:
            result = {**self._validate(step), **self.timing()}
            self.evaluations.append(result)
            self.last_eval = step
            if self.best is None or self.best.get("selection") != result["selection"] or result["score"] < self.best["score"]:
                self.best, new_best = {"num_timesteps": step, "score": result["score"], "stem": stem.name,
                                       "selection": result["selection"]}, True
        state = {**self.meta, "num_timesteps": step, "saved_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                 **self.timing(), "evaluations": self.evaluations, "best": self.best}
        atomic_write_text(json_path, json_text(state))            # the commit: the checkpoint now exists
        self.last_save = step
        self.last_save_time = time.monotonic()
        if evaluate:
            atomic_write_text(self.run_dir / "evaluations.json", json_text(self.evaluations))
        if new_best:
            self._copy_best()
        self._prune()
        if self.verbose:
            print(f"checkpoint {stem.name}" + (f" (validation score {self.evaluations[-1]['score']})"
                                               if evaluate else ""), file=sys.stderr)
        return zip_path

    def _validate(self, step: int) -> dict[str, Any]:
        assert self.evaluator is not None
        t0 = time.perf_counter()
        policy = SB3Policy.from_model(self.model, self.vecnormalize, name=f"step_{step}", meta=self.meta)
        flown = policy if "residual" not in self.meta else (lambda env: adapt(policy, env))
        result = {"num_timesteps": step, **self.evaluator.evaluate(flown),
                  "wall_s": round(time.perf_counter() - t0, 3)}
        self.logger.record("eval/failure_rate", result["failure_rate"])
        self.logger.record("eval/rate_error_rad", result["rate_error_rad"])
        for name, c in result["conditions"].items():
            tag = name.split("/")[-1]
            self.logger.record(f"eval/{tag}/rate_error_rad", c["rate_error_rad_mean"])
            self.logger.record(f"eval/{tag}/failure_rate", c["failure_rate"])
            self.logger.record(f"eval/{tag}/episode_return", c["episode_return_mean"])
        return result

    def _copy_best(self) -> None:
        if self.best is None:
            return
        stem = self.folder / self.best["stem"]
        if policy_files(stem)[2].is_file():
            copy_policy(stem, self.run_dir / "best_model", {"validation_score": self.best["score"]})

    def _prune(self) -> None:
        ckpts = list_checkpoints(self.folder)
        keep = {stem.name for _, stem in ckpts[-self.keep:]}
        if self.best is not None:
            keep.add(self.best["stem"])
        latest = ckpts[-1][1].name if ckpts else ""
        for _, stem in ckpts:
            if stem.name != latest:
                stem.with_name(stem.name + BUFFER_SUFFIX).unlink(missing_ok=True)
            if stem.name in keep:
                continue
            policy_files(stem)[2].unlink(missing_ok=True)          # the JSON first: no half checkpoint
            for suffix in (".zip", "_vecnormalize.pkl", RNG_SUFFIX, BUFFER_SUFFIX):
                stem.with_name(stem.name + suffix).unlink(missing_ok=True)


def load_replay_buffer(model: Any, stem: Path) -> bool:
    """Put a checkpoint's replay buffer (SAC / TD3) back into ``model``; False when it has none."""
    path = stem.with_name(stem.name + BUFFER_SUFFIX)
    if not path.is_file() or not hasattr(model, "replay_buffer"):
        return False
    with open(path, "rb") as f:
        model.replay_buffer = pickle.load(f)
    return True


def evaluate_saved(path: str | Path, suite: str = "smile-windy", episodes: int = 10,
                   overrides: dict[str, Any] | None = None) -> dict[str, Any]:
    """Validation of a saved policy (a ``.zip`` or a run folder) as the training run does it (a teacher with
    its privileged observation options)."""
    from ..policies.sb3 import privileged_options

    ev = ValidationEvaluator(suite, episodes, {**privileged_options(path), **(overrides or {})} or None)
    try:
        return ev.evaluate(SB3Policy(path))
    finally:
        ev.close()


__all__ = ["CheckpointCallback", "SignalStop", "ValidationEvaluator", "evaluate_saved",
           "load_replay_buffer", "load_rng", "save_rng"]
