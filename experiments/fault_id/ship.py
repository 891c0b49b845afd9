"""Choose a shipped disturbance-observer policy among the training seeds on the validation seeds, and write it
with its record into ``agents/trained`` (``inversion-id``: :data:`lvgym.agents.inversion.SHIPPED`).

    python -m experiments.fault_id.ship --prefix inversion-gain6 --seeds 0 1 2 --validation 100
    python -m experiments.fault_id.ship --suite stratos-tvc-v2 --prefix inversion-stratos-tvc-v2-lead3-f200e16-gain6 \
        --lead 3 --loop-gain-db 6 --flights 200 --epochs 16 --tag f200e16 --stem inversion_id_stratos_tvc_v2 \
        --name inversion-id-stratos                          # inversion-id-stratos
    python -m experiments.fault_id.ship --suite smile-v2 --prefix inversion-smile-v2-lead5-f200e16-gain6 --lead 5 \
        --loop-gain-db 6 --flights 200 --epochs 16 --tag f200e16 --stem inversion_id_smile_v2 \
        --name inversion-id-smile                            # inversion-id-smile
    python -m experiments.fault_id.ship --suite smile-v2 --prefix inversion-smile-v2-lead5-w1.25-f200e16-gain6 \
        --lead 5 --bandwidth 1.25 --loop-gain-db 6 --flights 200 --epochs 16 --tag f200e16 \
        --stem inversion_id_smile_v2 --name inversion-id-smile   # inversion-id-smile, the law's bandwidth 1.25 rad/s

Each seed's observer (``results/fault_id/<prefix>-s<k>.pt``, written by :mod:`.train`) is converted to the
flight computer's NumPy form (``<prefix>-s<k>.npz``, :func:`lvgym.agents.observer_fit.to_observer`) and flown
by the benchmark (:func:`lvgym.benchmark.evaluate`, as the shipped policy flies, with its ``--lead``) on
validation seeds ``0 .. --validation - 1`` of ``--suite``, both flight models; the shipped one is the seed with
the fewest failed or unflyable non-rigid flights, then the lowest non-rigid mean ``score_v2``. The test seeds are
not flown. The record (``<stem>.json``) holds the training command, the validation of every candidate, the
choice, the env the observer was trained on (:func:`lvgym.agents.inversion.env_record`, which the policy
checks), the law's lead, gains, ``--average``, ``--ignition`` and ``--ignition-share`` (which the policy flies)
and the observer file's SHA-256.
"""

from __future__ import annotations

import datetime
import hashlib
import json
import shutil
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from lvgym.agents.inversion import SHIPPED, TRAINED, env_record
from lvgym.agents.observer_fit import load, to_observer
from lvgym.benchmark import PolicySpec, evaluate, get_suite
from lvgym.commandline import arg, parse

from .estimator import RESULTS
from .train import SUITE, condition, own_law, scored


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.ship --help``)."""

    prefix: str = arg("inversion-gain6")
    """the training runs' file prefix in results/fault_id (``inversion``: no loop dispersion)"""
    seeds: list[int] = arg(default_factory=lambda: [0, 1, 2], metavar="SEED")
    """the training seeds to choose from"""
    validation: int = arg(100, lo=10, hi=1000)
    """validation seeds flown per flight model"""
    loop_gain_db: float = arg(6.0, lo=0.0, hi=12.0)
    """the loop dispersion the runs were trained under (recorded)"""
    suite: str = arg(SUITE, choices=(SUITE, "smile-v2", "stratos-tvc-v2"))
    """the suite the runs were trained on and are validated on"""
    lead: int = arg(0, lo=0, hi=10)
    """the law's lead [control steps] the runs were trained with (``train.py --lead``), flown and recorded"""
    bandwidth: float = arg(0.0, lo=0.0, hi=10.0)
    """the non-rigid law's bandwidth [rad/s] the runs were trained with (``train.py --bandwidth``; 0: the
    reference's), flown and recorded"""
    ignition: float = arg(0.0, lo=0.0, hi=60.0)
    """the seconds after the next stage's ignition the law cancels the moment measured from the rigid body
    (:class:`lvgym.agents.inversion.Staging`; 0: never), flown and recorded"""
    ignition_share: float = arg(1.0, lo=0.01, hi=1.0)
    """the measured moment's share there, the rest the estimate's (:class:`lvgym.agents.inversion.Staging`; 1:
    the measured alone), flown and recorded"""
    average: int = arg(1, lo=1, hi=50)
    """the control steps the estimated moment is averaged over before its lead
    (:class:`lvgym.agents.inversion.Lead`; 1: none), flown and recorded"""
    flights: int = arg(100, lo=10, hi=2000)
    """the runs' ``--flights`` (recorded)"""
    epochs: int = arg(8, lo=1, hi=100)
    """the runs' ``--epochs`` (recorded)"""
    tag: str = arg("")
    """the runs' ``--tag`` (recorded)"""
    stem: str = arg(SHIPPED)
    """the shipped files' name in agents/trained (``<stem>.npz``, ``<stem>.json``)"""
    name: str = arg("inversion-id")
    """the registered policy's name (recorded)"""


def per_model(records: list[dict]) -> dict[str, dict[str, float]]:
    """Per flight model (the last part of a record's ``condition``), the mean ``score_v2`` and the failed or
    unflyable flights of ``records``."""
    out = {}
    for model in ("rigid", "nonrigid"):
        mean, bad = scored([r for r in records if r["condition"].rsplit("/", 1)[-1] == model])
        out[model] = {"score_v2_mean": mean, "failed_or_unflyable": bad}
    return out


def flown(lead: int = 0, law: dict[str, list[float]] | None = None, ignition: float = 0.0, average: int = 1,
          ignition_share: float = 1.0) -> dict[str, Any]:
    """The options the policy flies (:func:`lvgym.agents.inversion.from_file`'s), those at their defaults left
    out but the lead: what a candidate's validation flies and what the record names."""
    return {"lead": lead, **({"law": law} if law else {}), **({"ignition": ignition} if ignition else {}),
            **({"average": average} if average > 1 else {}),
            **({"ignition_share": ignition_share} if ignition and ignition_share != 1.0 else {})}


def validation(path: str, episodes: int, suite: str = SUITE, lead: int = 0,
               law: dict[str, list[float]] | None = None, ignition: float = 0.0,
               average: int = 1, ignition_share: float = 1.0) -> dict[str, dict[str, float]]:
    """:func:`per_model` of the observer at ``path`` (``.npz``, flown with ``lead`` after an ``average`` over
    that many steps, the gains ``law``, :func:`lvgym.agents.inversion.gains`, and the measured moment for
    ``ignition`` seconds after the next stage's ignition, ``ignition_share`` of it) on ``suite``'s first
    ``episodes`` validation seeds, flown by the benchmark."""
    options = dict(flown(lead, law, ignition, average, ignition_share), path=path)
    if "law" in options:                                  # a spec's options hash
        options["law"] = tuple((model, tuple(v)) for model, v in sorted(options["law"].items()))
    spec = PolicySpec("inversion-id", "lvgym.agents.inversion:from_file", tuple(sorted(options.items())))
    return per_model(evaluate([spec], [get_suite(suite)], episodes, seed_set="validation", progress=False))


def main(argv: Sequence[str] | None = None) -> None:
    a = parse(Args, argv, "python -m experiments.fault_id.ship", __doc__)
    candidates, law = {}, own_law(a.bandwidth)
    for k in a.seeds:
        npz = RESULTS / f"{a.prefix}-s{k}.npz"
        to_observer(load(RESULTS / f"{a.prefix}-s{k}.pt")).save(npz)
        candidates[k] = validation(str(npz.resolve()), a.validation, a.suite, a.lead, law, a.ignition, a.average,
                                   a.ignition_share)
        print(f"seed {k}: " + ", ".join(f"{m} {v['score_v2_mean']:.3f} ({v['failed_or_unflyable']})"
                                         for m, v in candidates[k].items()), flush=True)
    best = min(candidates, key=lambda k: (candidates[k]["nonrigid"]["failed_or_unflyable"],
                                          candidates[k]["nonrigid"]["score_v2_mean"]))
    source = RESULTS / f"{a.prefix}-s{best}.npz"
    target = TRAINED / f"{a.stem}.npz"
    shutil.copyfile(source, target)
    options = ((f" --suite {a.suite}" if a.suite != SUITE else "") + (f" --lead {a.lead}" if a.lead else "")
               + (f" --bandwidth {a.bandwidth:g}" if a.bandwidth else "")
               + (f" --epochs {a.epochs}" if a.epochs != 8 else "") + (f" --tag {a.tag}" if a.tag else "")
               + (f" --loop-gain-db {a.loop_gain_db:g}" if a.loop_gain_db else ""))
    record = {
        "policy": a.name,
        "suite": a.suite,
        "env": env_record(condition("nonrigid", a.suite).make_env()),
        **flown(a.lead, law, a.ignition, a.average, a.ignition_share),
        "training": {"command": f"python -m experiments.fault_id.train --scheme inversion --seed {best} "
                                f"--flights {a.flights} --rounds 4 --validation 50{options}",
                     "seeds": list(a.seeds), "file": f"{a.prefix}-s{best}.pt"},
        "validation": {"seeds": f"0-{a.validation - 1}", "candidates": {str(k): v for k, v in candidates.items()},
                       "selection": "fewest failed or unflyable non-rigid flights, then the lowest non-rigid mean "
                                    "score_v2", "chosen": best},
        "sha256": hashlib.sha256(target.read_bytes()).hexdigest(),
        "date": datetime.date.today().isoformat(),
    }
    (TRAINED / f"{a.stem}.json").write_text(json.dumps(record, indent=1, sort_keys=True) + "\n")
    print(f"shipped seed {best} as {target} (record {a.stem}.json)")


if __name__ == "__main__":
    main()
