"""The teacher-student recipe of the shipped ``inversion-id`` policies: the privileged reference's law on a learned
disturbance observer, trained, chosen and recorded in one command.

    lvgym train --recipe teacher-student --suite smile-v2-faults --seeds 0 1 2 --flights 100 --rounds 4 \\
        --validation 50 --loop-gain-db 6 --flight-options lead=3,average=6,ignition=4,ignition_share=0.5
    lvgym train --recipe teacher-student --suite smile-v2 --flights 200 --epochs 16 --lead 5 --bandwidth 1.25
    lvgym evaluate --suites smile-v2-faults \
        --policies results/teacher-student/smile-v2-faults/inversion_id_smile_v2_faults.json

1. **Per training seed** (:mod:`lvgym.agents.training.dagger`): the teacher (the law on the true terms from the env's
   privileged info, an exploration noise on its action; :mod:`lvgym.agents.training.teacher`) flies ``--flights`` per
   flight model under the loop dispersion (``--loop-gain-db``: a gain on each flight's action, uniform in dB);
   the observer (:mod:`lvgym.agents.training.observer_fit`) is fitted to every step's window and true terms; then
   ``--rounds`` DAgger rounds (the student flies half as many flights, labelled the same way, and the
   observer is fitted again). The observer is the mean of the last three fits. Training flights fly env seeds
   ``100,000 + 10,000 seed + 5,000 round + i``, none a validation or test seed of the suite.
2. **The seed that ships** (:mod:`lvgym.agents.training.flight_options`): each seed's observer, in the NumPy form the
   policy flies, on the suite's first ``--selection`` validation seeds through the benchmark: the fewest
   failed or unflyable non-rigid flights, then the lowest non-rigid mean ``score_v2``.
3. **Its flight options** (``--flight-options``, tried in order): a candidate replaces the options kept if it
   reaches the rule's margins (``--min-gain-margin-db``, ``--min-delay-margin-ms`` on ``--margin-suite``'s
   first ``--margin-seeds`` validation seeds) and on ``--option-validation`` validation seeds loses at most
   ``--max-extra-losses`` more non-rigid flights with a non-rigid mean at most ``--max-worse`` worse.
4. **The record**: ``<out>/<stem>.npz`` (:meth:`lvgym.agents.policies.observer.Observer.save`) and ``<out>/<stem>.json``
   (the env, the options the law flies, the validation numbers, this command, the file's SHA-256), which
   ``lvgym evaluate --policies <stem>.json`` flies (:func:`lvgym.agents.policies.inversion_record.from_record`).

The run folder (``--out``) keeps each round's fit (``seed<k>/round<r>.pt``), each seed's observer and record
(``seed<k>/observer.npz``, ``seed<k>/record.json``) and each candidate's options (``options/<label>.json``);
``--resume`` continues a stopped run from them. ``--observer FILE`` takes a trained observer (``.npz`` or
``.pt``) in place of training: its flight options chosen on validation seeds alone. One training seed of the
fault suite at ``--flights 100 --rounds 4 --validation 50`` takes about 19 minutes on one core and 8-10 GB at
its last fit (docs/teacher-student.md).
"""

from __future__ import annotations

import datetime
import json
import os
import shlex
import shutil
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lvgym.commandline import arg, command_name, fail, parse
from lvgym.errors import ConfigError

from ..policies.inversion_record import flown, sha256, write_record
from .flight_options import Rule, choose_options, choose_seed, parse_option

__all__ = ["Args", "NAMES", "SUITES", "TRAINING", "main", "run"]

#: the suites the recipe trains on, with the name of the policy it ships for each
NAMES = {"smile-v2-faults": "inversion-id", "smile-v2": "inversion-id-smile", "stratos-tvc-v2": "inversion-id-stratos",
         "smile-v2-maxq-gust": "inversion-id-maxq-gust"}
SUITES = tuple(NAMES)
#: the options that make a training run (a resumed run must give the same)
TRAINING = ("suite", "flights", "rounds", "epochs", "validation", "loop_gain_db", "lead", "bandwidth", "mission_time_s")
#: the suites the margins may be measured on (the recipe's env must be theirs)
MARGIN_SUITES = ("smile-v1", "smile-v2", "smile-v2-faults", "stratos-tvc-v1", "stratos-tvc-v2")
PROG = "train.py --recipe teacher-student"


def _options(option: str, values: list[str]) -> list[str]:
    for text in values:
        parse_option(option, text)
    return list(values)


@dataclass
class Args:
    """Command-line arguments (``lvgym train --recipe teacher-student --help``)."""

    suite: str = arg("smile-v2-faults", choices=SUITES)
    """the suite whose condition the flights fly (both flight models) and whose validation seeds choose"""
    seeds: list[int] = arg(default_factory=lambda: [0, 1, 2], lo=0, hi=99, metavar="SEED")
    """training seeds, trained one after another (each: its flights' seeds, the teacher's exploration, the fits)"""
    flights: int = arg(100, lo=1, hi=2000)
    """the teacher's flights per flight model (in batches of 100 rows); each DAgger round flies half as many"""
    rounds: int = arg(4, lo=0, hi=10)
    """DAgger rounds after the teacher's data"""
    epochs: int = arg(8, lo=1, hi=100)
    """epochs per fit"""
    validation: int = arg(50, lo=0, hi=1000)
    """validation seeds flown per flight model after each fit, printed (0: none)"""
    loop_gain_db: float = arg(6.0, lo=0.0, hi=12.0)
    """the loop dispersion: a gain on every training flight's action drawn uniformly in dB within +- this,
    the labels as the action must carry them (0: none)"""
    lead: int = arg(0, lo=0, hi=10)
    """the law flies its estimated moment carried this many control periods along its slope over 5 (trained
    and flown with it; 0: the moment as estimated)"""
    bandwidth: float = arg(0.0, lo=0.0, hi=10.0)
    """the law's non-rigid bandwidth [rad/s], its damping the reference's (0: the privileged reference's gains)"""
    selection: int = arg(100, lo=1, hi=10_000)
    """validation seeds per flight model on which the seed that ships is chosen"""
    observer: Path | None = None
    """a trained observer (.npz or .pt) to choose flight options for, in place of training: --seeds and the
    training options are then not used (default: train)"""
    flight_options: list[str] = arg(default_factory=list, nargs="*", check=_options, metavar="KEY=VALUE,...")
    """candidate flight options tried in order, each comma-separated pairs of lead, average, ignition [s] and
    ignition_share (e.g. lead=3,average=6,ignition=4,ignition_share=0.5; default: none, the options as trained)"""
    option_validation: int = arg(2000, lo=1, hi=10_000)
    """validation seeds per flight model a candidate flight option is flown on"""
    margin_suite: str = arg("smile-v1", choices=MARGIN_SUITES)
    """the suite whose non-rigid condition measures a candidate's margins (its env must be --suite's)"""
    margin_seeds: int = arg(5, lo=1, hi=100)
    """validation seeds of the margins"""
    min_gain_margin_db: float = arg(6.0, lo=0.0, hi=40.0)
    """a candidate's non-rigid gain margin up must be at least this [dB]"""
    min_delay_margin_ms: float = arg(30.0, lo=0.0, hi=1000.0)
    """... and its delay margin at least this [ms]"""
    max_extra_losses: int = arg(2, lo=0, hi=10_000)
    """... and it may lose at most this many more non-rigid validation flights than the options kept"""
    max_worse: float = arg(0.02, lo=0.0, hi=1.0)
    """... with a non-rigid mean score_v2 at most this share above theirs"""
    name: str | None = None
    """the policy's name in its record (default: inversion-id on smile-v2-faults, inversion-id-smile on smile-v2,
    inversion-id-stratos on stratos-tvc-v2, inversion-id-maxq-gust)"""
    stem: str | None = None
    """the record's file name (default: inversion_id_<suite with underscores>, as agents/trained names them)"""
    out: Path | None = None
    """the run folder (default: results/teacher-student/<suite>)"""
    workers: int = arg(1, lo=1, hi=256)
    """worker processes of the benchmark's flights (the choices); the training is one process"""
    torch_threads: int = arg(1, lo=1, hi=256)
    """torch CPU threads of the fits"""
    mission_time_s: float | None = arg(None, lo=0.0, lo_open=True, hi=3600.0)
    """shorten every flight to this [s] (smoke tests only: not the suite's numbers; default: the suite's)"""
    resume: bool = False
    """continue the run in --out: finished seeds read, each finished round's fit read (its flights flown again)"""

    def __post_init__(self) -> None:
        if self.observer is not None and self.observer.suffix not in (".npz", ".pt"):
            raise ConfigError("--observer", str(self.observer), "an observer file .npz or .pt")
        if self.observer is not None and not self.observer.is_file():
            raise ConfigError("--observer", str(self.observer), "an existing file")
        if len(set(self.seeds)) != len(self.seeds):
            raise ConfigError("--seeds", self.seeds, "distinct training seeds")


def _say(out: Path | None) -> Any:
    def say(line: str) -> None:
        print(line, flush=True)
        if out is not None:
            with open(out / "recipe.log", "a", encoding="utf-8") as f:
                f.write(line + "\n")
    return say


def _check_run(a: Args, out: Path) -> None:
    """Refuse a run folder of another run (or any, without ``--resume``), naming what differs."""
    mine = {k: getattr(a, k) for k in TRAINING}
    saved = out / "recipe.json"
    if not saved.is_file():
        return
    if not a.resume:
        raise ConfigError("--out", str(out), "a new folder (a run is there: continue it with --resume)")
    theirs = json.loads(saved.read_text(encoding="utf-8"))
    for key in TRAINING:
        if theirs.get(key) != mine[key]:
            raise ConfigError(f"--{key.replace('_', '-')}", mine[key], f"{theirs.get(key)!r}, the run's in {out}")


def run(a: Args, argv: Sequence[str]) -> Path:
    """The recipe of the module docstring with the arguments ``a`` (``argv``: the command line, recorded);
    returns the record's path."""
    import torch

    from lvgym.benchmark.suites import get_suite

    from ..policies.inversion import env_record
    from ..policies.observer import Observer
    from ..policies.observer_net import load, save, to_observer
    from .dagger import ROUND_STRIDE, SEED_STRIDE, TRAIN_SEED0, train_seed
    from .teacher import condition, own_law, scheme, validate

    env_opts = {"mission_time_s": a.mission_time_s} if a.mission_time_s else {}
    suite = get_suite(a.suite).with_options(**env_opts)
    margin_suite = get_suite(a.margin_suite).with_options(**env_opts)
    trained_env = env_record(condition("nonrigid", a.suite).make_env())
    if a.flight_options and env_record(margin_suite.conditions[-1].make_env()) != trained_env:
        raise ConfigError("--margin-suite", a.margin_suite, f"a suite of {a.suite}'s env {trained_env}")
    out = a.out or Path("results") / "teacher-student" / a.suite
    _check_run(a, out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "recipe.json").write_text(json.dumps({k: getattr(a, k) for k in TRAINING}, indent=1) + "\n")
    say, t0 = _say(out), time.time()
    torch.set_num_threads(a.torch_threads)
    law = own_law(a.bandwidth)
    base = {"lead": a.lead, "law": law}
    command = f"lvgym train --recipe teacher-student {shlex.join(argv)}".rstrip()
    stem, name = a.stem or f"inversion_id_{a.suite.replace('-', '_')}", a.name or NAMES[a.suite]

    def record(observer: Path, options: dict[str, Any], folder: Path, **more: Any) -> dict[str, Any]:
        return {"policy": name, "suite": a.suite, "env": trained_env, **flown(**options),
                "observer": Path(os.path.relpath(Path(observer).resolve(), folder.resolve())).as_posix(),
                "sha256": sha256(observer), **({"mission_time_s": a.mission_time_s} if a.mission_time_s else {}),
                **more}

    candidates, walls = {}, {}
    if a.observer is not None:                        # a trained observer: no training, no seed to choose
        npz = out / "observer" / "observer.npz"
        npz.parent.mkdir(exist_ok=True)
        if a.observer.suffix == ".pt":
            to_observer(load(a.observer)).save(npz)
        else:
            Observer.load(a.observer).save(npz)
        candidates["observer"] = write_record(npz.with_name("record.json"), record(npz, base, npz.parent))
    for k in ([] if a.observer is not None else a.seeds):
        folder = out / f"seed{k}"
        folder.mkdir(exist_ok=True)
        done = folder / "observer.pt"
        if a.resume and done.is_file():
            say(f"seed {k}: read {done}")
        else:
            t1 = time.time()
            pilot = scheme(a.lead, law)
            est = train_seed(k, a.flights, a.rounds, a.epochs, pilot, lambda r, f=folder: f / f"round{r}.pt",
                             suite=a.suite, validation=a.validation, loop_gain_db=a.loop_gain_db, resume=a.resume,
                             validate=lambda e: validate(e, a.validation, pilot, a.suite, **env_opts), log=say,
                             **env_opts)
            save(est, done)
            walls[str(k)] = round(time.time() - t1, 1)
            say(f"seed {k}: wrote {done} in {walls[str(k)]:.0f} s")
        npz = folder / "observer.npz"
        to_observer(load(done)).save(npz)
        candidates[str(k)] = write_record(folder / "record.json", record(npz, base, folder))
    say(f"validation seeds 0-{a.selection - 1} of {a.suite}, both flight models:")
    best, scores = choose_seed(candidates, suite, a.selection, a.workers, say)
    source = json.loads(candidates[best].read_text())
    weights = candidates[best].parent / source["observer"]
    flight = None
    options = dict(base)
    if a.flight_options:
        rule = Rule(a.min_gain_margin_db, a.min_delay_margin_ms, a.max_extra_losses, a.max_worse)
        text = rule.text(a.option_validation, a.margin_suite, a.margin_seeds)
        say(f"flight options on validation seeds 0-{a.option_validation - 1} ({text}):")
        kept = out / "options"

        def write(label: str, opts: dict[str, Any]) -> Path:
            return write_record(kept / f"{label}.json", record(weights, opts, kept))

        picked = choose_options(base, [parse_option("--flight-options", t) for t in a.flight_options], write,
                                suite, a.option_validation, margin_suite, a.margin_seeds, rule, a.workers, say)
        options = picked["options"]
        flight = {"options": {k: v for k, v in flown(**options).items() if k != "law"},
                  "rule": text,
                  "seeds": f"0-{a.option_validation - 1}", "chosen": picked["label"],
                  "candidates": {label: {k: v for k, v in flown(**o).items() if k != "law"}
                                 for label, o in picked["labels"].items()},
                  "validation": picked["validation"],
                  "margins": {label: {"nonrigid": m} for label, m in picked["margins"].items()},
                  "margin_suite": a.margin_suite, "margin_seeds": f"0-{a.margin_seeds - 1}",
                  "commands": [command],
                  "what": "chosen after training, on validation seeds only: the options the law flies "
                          "(lvgym.agents.policies.inversion.Lead's average and lead, Staging's ignition seconds "
                          "and share)"}
    target = out / f"{stem}.npz"
    shutil.copyfile(weights, target)
    training = ({"command": command, "observer": str(a.observer)} if a.observer is not None else
                {"command": command, "seeds": list(a.seeds), "file": f"seed{best}/observer.pt",
                 **{k: getattr(a, k) for k in ("flights", "rounds", "epochs", "loop_gain_db", "lead", "bandwidth")},
                 "env_seeds": f"{TRAIN_SEED0:,} + {SEED_STRIDE:,} seed + {ROUND_STRIDE:,} round + i (neither "
                              "validation nor test seeds)", **({"wall_time_s": walls} if walls else {})})
    final = {k: v for k, v in record(target, options, out).items() if k != "observer"}
    final.update(training=training, date=datetime.date.today().isoformat(),
                 validation={"seeds": f"0-{a.selection - 1}", "candidates": scores, "chosen": _key(best),
                             "selection": "fewest failed or unflyable non-rigid flights, then the lowest non-rigid "
                                          "mean score_v2"},
                 **({"flight": flight} if flight else {}))
    path = write_record(out / f"{stem}.json", final)
    say(f"wrote {path} and {target} (seed {best}) in {time.time() - t0:.0f} s")
    return path


def _key(k: str) -> int | str:
    return int(k) if k.isdigit() else k


def main(argv: Sequence[str] | None = None) -> Path:
    """``lvgym train --recipe teacher-student``: the recipe of the module docstring."""
    import sys

    argv = list(sys.argv[1:] if argv is None else argv)
    prog = command_name(PROG)
    a = parse(Args, argv, PROG, __doc__, epilog=True)
    try:
        return run(a, argv)
    except ConfigError as exc:
        fail(prog, exc)


if __name__ == "__main__":
    main()
