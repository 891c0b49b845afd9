"""The files a saved stable-baselines3 policy is made of, and the model they load.

A saved policy is three files with one stem::

    <stem>.zip                  the SB3 model (``model.save``)
    <stem>_vecnormalize.pkl     the VecNormalize statistics (``VecNormalize.save``), if training normalised
    <stem>.json                 {"algo": "PPO", "env_id": ..., "env_kwargs": {...}, "num_timesteps": ...}

:func:`save_policy` writes them (``lvgym train``), :func:`resolve_model_path` finds the ``.zip`` of a stem or of a
run folder of ``train.py`` (``runs/<name>``: its best model by validation, else its final model, else its last
checkpoint, :mod:`lvgym.agents.policies.checkpoints`), :func:`load_model` and :func:`load_vecnormalize` load it
to fly (:class:`lvgym.agents.policies.sb3.SB3Policy`).

    lvgym export-policy runs/ppo-smile agents/trained/ppo_smile_ascent   # copy a run's policy
    python -m lvgym.agents.policies.saved export runs/ppo-smile agents/trained/ppo_smile_ascent   # the same
"""

from __future__ import annotations

import dataclasses
import json
import pickle
import shutil
import zipfile
from pathlib import Path
from typing import Any

from lvgym.benchmark.results import atomic_path, atomic_write_text
from lvgym.commandline import arg

from .algos import ALGOS, algo_class, algo_name

__all__ = ["FLY_ONLY", "VECNORM_SUFFIX", "copy_policy", "guess_and_load", "load_model", "load_vecnormalize",
           "policy_files", "read_meta", "resolve_model_path", "save_policy"]

VECNORM_SUFFIX = "_vecnormalize.pkl"


def policy_files(stem: str | Path) -> tuple[Path, Path, Path]:
    """``(<stem>.zip, <stem>_vecnormalize.pkl, <stem>.json)`` of a stem (with or without ``.zip``)."""
    s = Path(stem)
    if s.suffix == ".zip":
        s = s.with_suffix("")
    return s.with_name(s.name + ".zip"), s.with_name(s.name + VECNORM_SUFFIX), s.with_name(s.name + ".json")


def save_policy(model: Any, vecnormalize: Any, stem: str | Path, meta: dict[str, Any]) -> Path:
    """Write the three files of ``stem``, each atomically, the JSON last (its presence means the others
    are complete). ``meta`` must hold ``algo``; returns the ``.zip`` path."""
    if "algo" not in meta:
        raise ValueError("save_policy: meta needs 'algo' (e.g. 'PPO')")
    zip_path, norm_path, json_path = policy_files(stem)
    with atomic_path(zip_path) as tmp:
        model.save(tmp)
    if vecnormalize is not None:
        with atomic_path(norm_path) as tmp:
            vecnormalize.save(tmp)
    atomic_write_text(json_path, json.dumps({**meta, "algo": algo_name(str(meta["algo"]))}, indent=1, sort_keys=True))
    return zip_path


def copy_policy(src_stem: str | Path, dst_stem: str | Path, extra: dict[str, Any] | None = None) -> Path:
    """Copy a saved policy's files to another stem (atomically, the JSON last)."""
    src, dst = policy_files(src_stem), policy_files(dst_stem)
    for s, d in zip(src[:2], dst[:2]):
        if s.is_file():
            with atomic_path(d) as tmp:
                shutil.copyfile(s, tmp)
        elif d.is_file():
            d.unlink()
    meta = json.loads(src[2].read_text(encoding="utf-8")) if src[2].is_file() else {}
    atomic_write_text(dst[2], json.dumps({**meta, **(extra or {})}, indent=1, sort_keys=True))
    return dst[0]


def resolve_model_path(path: str | Path) -> Path:
    """The ``.zip`` of a saved policy: ``path`` itself, ``path + '.zip'``, or in a run folder its best
    model, its final model or its latest checkpoint (``FileNotFoundError`` otherwise)."""
    p = Path(path)
    if p.is_dir():
        from .checkpoints import latest_checkpoint

        for stem in ("best_model", "final_model"):
            if (p / f"{stem}.zip").is_file() and (p / f"{stem}.json").is_file():
                return p / f"{stem}.zip"
        ckpt = latest_checkpoint(p / "checkpoints")
        if ckpt is not None:
            return ckpt[0]
        raise FileNotFoundError(f"{str(p)!r}: a run folder without best_model.zip, final_model.zip or checkpoints")
    if p.is_file():
        return p
    if p.with_name(p.name + ".zip").is_file():
        return p.with_name(p.name + ".zip")
    raise FileNotFoundError(f"{str(p)!r}: no such SB3 model (.zip) or run folder")


def _sidecar_algo(path: Path) -> str | None:
    side = path.with_suffix(".json")
    if side.is_file():
        algo = json.loads(side.read_text(encoding="utf-8")).get("algo")
        return algo_name(str(algo)) if algo else None
    return None


def _guess_algo(path: Path) -> str | None:
    """The algorithm suggested by the policy class module stored in the zip's ``data``."""
    try:
        with zipfile.ZipFile(path) as z:
            data = json.loads(z.read("data"))
        module = str(data.get("policy_class", {}).get("__module__", ""))
    except (KeyError, ValueError, zipfile.BadZipFile, AttributeError):
        return None
    for key, algo in (("recurrent", "RecurrentPPO"), ("sac", "SAC"), ("td3", "TD3"), ("ddpg", "DDPG"),
                      ("common.policies", "PPO")):
        if key in module:
            return algo
    return None


#: what a saved model's training schedules are replaced with when it is loaded to fly: a policy acts without
#: them, and a schedule is pickled by reference to the module that defined it (``agents.config`` in the
#: models saved before the package was installed as ``lvgym.agents``, ``lvgym.agents.config`` in those saved
#: before its sub-packages, ``lvgym.agents.training.config`` now), which a flight should not need
FLY_ONLY = {"learning_rate": 0.0, "lr_schedule": lambda _: 0.0, "clip_range": lambda _: 0.0,
            "clip_range_vf": None, "exploration_schedule": lambda _: 0.0}


def guess_and_load(path: str | Path) -> Any:
    """The SB3 model at ``path`` when no sidecar names its algorithm: the algorithm suggested by the
    policy class stored in the zip first, then every algorithm train.py trains
    (:data:`lvgym.agents.policies.algos.ALGOS`) in turn."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"policy {str(path)!r}: no such SB3 model file")
    first = _sidecar_algo(path) or _guess_algo(path)
    known = list(ALGOS.values())
    order = [first] + [a for a in known if a != first] if first else known
    errors = []
    for algo in order:
        try:
            cls = algo_class(algo)
        except (ImportError, ValueError) as exc:
            errors.append(f"{algo}: {exc}")
            continue
        try:
            return cls.load(str(path), device="cpu", custom_objects=FLY_ONLY)
        except Exception as exc:  # noqa: BLE001 (a wrong algorithm fails in many ways)
            errors.append(f"{algo}: {type(exc).__name__}: {exc}")
    raise ValueError(f"policy {str(path)!r}: no SB3 algorithm loads it ({'; '.join(errors)}); "
                     f"add a sidecar {path.with_suffix('.json').name} with {{\"algo\": \"PPO\"}}")


def read_meta(zip_path: str | Path) -> dict[str, Any]:
    """The sidecar JSON of a saved policy (``{}`` when it has none)."""
    side = policy_files(zip_path)[2]
    return json.loads(side.read_text(encoding="utf-8")) if side.is_file() else {}


def load_model(zip_path: str | Path, algo: str | None = None) -> Any:
    """The SB3 model at ``zip_path`` on the CPU, to fly (its training schedules replaced, :data:`FLY_ONLY`):
    class from ``algo``, else from the sidecar JSON, else guessed by :func:`guess_and_load` (policies saved
    by other tools)."""
    algo = algo or read_meta(zip_path).get("algo")
    if algo is None:
        return guess_and_load(zip_path)
    try:
        cls = algo_class(str(algo))
    except ValueError:
        raise ValueError(f"{str(zip_path)!r}: algo = {algo!r}: one of {sorted(ALGOS.values())}") from None
    return cls.load(str(zip_path), device="cpu", custom_objects=FLY_ONLY)


def load_vecnormalize(zip_path: str | Path) -> Any:
    """The VecNormalize statistics saved next to ``zip_path`` (frozen: ``training = False``), or None."""
    norm = policy_files(zip_path)[1]
    if not norm.is_file():
        return None
    with open(norm, "rb") as f:
        vn = pickle.load(f)
    vn.training = False
    vn.norm_reward = False
    return vn


@dataclasses.dataclass
class ExportArgs:
    """Command-line arguments (``lvgym export-policy --help``)."""

    run: str = arg(positional=True, metavar="RUN")
    """run folder (runs/<name>: its best, else final, else latest model) or a .zip"""
    stem: str = arg(positional=True, metavar="STEM")
    """destination without suffix, e.g. agents/trained/ppo_smile_ascent"""


def export_main(argv: list[str] | None = None) -> None:
    """``lvgym export-policy RUN STEM``: copy a run's policy (best, else final, else latest) to STEM.zip,
    STEM_vecnormalize.pkl and STEM.json."""
    from lvgym.commandline import command_name, fail, parse

    prog = "python -m lvgym.agents.policies.saved export"
    args = parse(ExportArgs, argv, prog, export_main.__doc__)
    try:
        src = resolve_model_path(args.run)
    except (FileNotFoundError, ValueError) as exc:
        fail(command_name(prog), exc)
    dst = copy_policy(src, args.stem, {"exported_from": str(src)})
    print(f"{src} -> {dst}")


def main(argv: list[str] | None = None) -> None:
    """``python -m lvgym.agents.policies.saved export RUN STEM`` (``lvgym export-policy RUN STEM``)."""
    from lvgym.commandline import Command, dispatch

    dispatch([Command("export", "lvgym.agents.policies.saved:export_main", "copy a run's policy to STEM.zip, "
                      "STEM_vecnormalize.pkl, STEM.json")], argv, "python -m lvgym.agents.policies.saved")


if __name__ == "__main__":
    main()
