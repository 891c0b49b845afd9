"""The files a saved stable-baselines3 policy is made of, and the model they load.

A saved policy is three files with one stem::

    <stem>.zip                  the SB3 model (``model.save``), carrying its VecNormalize statistics
                                (the member ``lvgym_vecnormalize.pkl``, which SB3's loader passes over)
    <stem>_vecnormalize.pkl     the same statistics (``VecNormalize.save``), if training normalised
    <stem>.json                 {"algo": "PPO", "env_id": ..., "env_kwargs": {...}, "num_timesteps": ...}

:func:`save_model` and :func:`save_policy` write them (``lvgym train``), :func:`resolve_model_path` finds the
``.zip`` of a stem or of a run folder of ``train.py`` (``runs/<name>``: its best model by validation, else its final
model, else its last checkpoint, :mod:`lvgym.agents.policies.checkpoints`; :func:`describe_saved` says which),
:func:`load_model` and :func:`statistics` load it to fly (:class:`lvgym.agents.policies.sb3.SB3Policy`).

**Normalisation statistics.** A model trained under ``VecNormalize`` flies only with the statistics it was trained
with. :func:`statistics` finds them: a file given, else ``<stem>_vecnormalize.pkl`` beside the ``.zip``, else the
copy inside it. A ``.zip`` saved by another tool carries none; one trained under ``VecNormalize`` is known by its
saved data (SB3 keeps the unnormalised observations, ``_last_original_obs``, only then), and without its statistics
it is refused in one line that says what to pass (:func:`trained_normalised`), never flown on raw observations.

    lvgym export-policy runs/ppo-smile agents/trained/ppo_smile_ascent   # copy a run's policy
    lvgym export-policy model.zip mine/model --vecnormalize vec_normalize.pkl   # a foreign model with its statistics
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

__all__ = ["FLY_ONLY", "VECNORM_MEMBER", "VECNORM_SUFFIX", "check_statistics", "copy_policy", "describe_saved",
           "guess_and_load", "load_model", "load_vecnormalize", "policy_files", "read_meta", "resolve_model_path",
           "save_model", "save_policy", "statistics", "trained_normalised"]

VECNORM_SUFFIX = "_vecnormalize.pkl"
#: the member of a saved ``.zip`` that carries its VecNormalize statistics (SB3's loader reads ``data`` and the
#: ``.pth`` members only)
VECNORM_MEMBER = "lvgym_vecnormalize.pkl"


def policy_files(stem: str | Path) -> tuple[Path, Path, Path]:
    """``(<stem>.zip, <stem>_vecnormalize.pkl, <stem>.json)`` of a stem (with or without ``.zip``)."""
    s = Path(stem)
    if s.suffix == ".zip":
        s = s.with_suffix("")
    return s.with_name(s.name + ".zip"), s.with_name(s.name + VECNORM_SUFFIX), s.with_name(s.name + ".json")


def _carry(zip_path: Path, statistics: bytes) -> None:
    """Put ``statistics`` (a pickled VecNormalize, as ``VecNormalize.save`` writes it) into the ``.zip`` at
    ``zip_path`` as :data:`VECNORM_MEMBER` (replacing any there), the other members as they are."""
    with zipfile.ZipFile(zip_path) as z:
        members = [(info, z.read(info.filename)) for info in z.infolist() if info.filename != VECNORM_MEMBER]
    with zipfile.ZipFile(zip_path, "w", zipfile.ZIP_DEFLATED) as z:
        for info, data in members:
            z.writestr(info, data)
        z.writestr(VECNORM_MEMBER, statistics)


def save_model(model: Any, vecnormalize: Any, stem: str | Path) -> Path:
    """``<stem>.zip`` (``model.save``, carrying ``vecnormalize``'s statistics) and, with statistics,
    ``<stem>_vecnormalize.pkl``, each written atomically; returns the ``.zip`` path."""
    zip_path, norm_path, _ = policy_files(stem)
    with atomic_path(zip_path) as tmp:
        model.save(tmp)
        if vecnormalize is not None:
            _carry(tmp, pickle.dumps(vecnormalize, protocol=pickle.HIGHEST_PROTOCOL))
    if vecnormalize is not None:
        with atomic_path(norm_path) as tmp:
            vecnormalize.save(tmp)
    return zip_path


def save_policy(model: Any, vecnormalize: Any, stem: str | Path, meta: dict[str, Any]) -> Path:
    """Write the three files of ``stem`` (:func:`save_model`), each atomically, the JSON last (its presence means
    the others are complete). ``meta`` must hold ``algo``; returns the ``.zip`` path."""
    if "algo" not in meta:
        raise ValueError("save_policy: meta needs 'algo' (e.g. 'PPO')")
    zip_path = save_model(model, vecnormalize, stem)
    atomic_write_text(policy_files(stem)[2], json.dumps({**meta, "algo": algo_name(str(meta["algo"]))}, indent=1,
                                                        sort_keys=True))
    return zip_path


def copy_policy(src_stem: str | Path, dst_stem: str | Path, extra: dict[str, Any] | None = None,
                vecnormalize: str | Path | None = None) -> Path:
    """Copy a saved policy's files to another stem (atomically, the JSON last); ``vecnormalize``: a file of
    VecNormalize statistics (``VecNormalize.save``'s) that the copy carries in place of the source's own."""
    src, dst = policy_files(src_stem), policy_files(dst_stem)
    given = None
    if vecnormalize is not None:
        _read_statistics(Path(vecnormalize))               # checked: VecNormalize statistics
        given = Path(vecnormalize).read_bytes()
    for s, d in zip(src[:2], dst[:2]):
        if given is not None:
            with atomic_path(d) as tmp:
                if d == dst[0]:
                    shutil.copyfile(s, tmp)
                    _carry(tmp, given)
                else:
                    shutil.copyfile(vecnormalize, tmp)
        elif s.is_file():
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


def _read_statistics(path: Path) -> Any:
    """The VecNormalize object pickled in the file ``path`` (``VecNormalize.save``'s), checked."""
    if not path.is_file():
        raise FileNotFoundError(f"{str(path)!r}: no such file of VecNormalize statistics")
    with open(path, "rb") as f:
        try:
            vn = pickle.load(f)
        except Exception as exc:  # noqa: BLE001  (not a pickle, or of a class not installed)
            raise ValueError(f"{str(path)!r}: not a file of VecNormalize statistics ({type(exc).__name__})") from None
    if not hasattr(vn, "normalize_obs") or not hasattr(vn, "obs_rms"):
        raise ValueError(f"{str(path)!r}: holds a {type(vn).__name__}, not VecNormalize statistics "
                         "(VecNormalize.save writes them)")
    return vn


def load_vecnormalize(zip_path: str | Path, stats: str | Path | None = None) -> Any:
    """The VecNormalize statistics a saved model flies with, frozen (``training`` and ``norm_reward`` off), or None:
    the file ``stats`` when given, else ``<stem>_vecnormalize.pkl`` beside ``zip_path``, else those the ``.zip``
    carries (:data:`VECNORM_MEMBER`). :func:`statistics` also refuses a model that needs them and has none."""
    beside = policy_files(zip_path)[1]
    if stats is not None or beside.is_file():
        vn = _read_statistics(Path(stats) if stats is not None else beside)
    else:
        try:
            with zipfile.ZipFile(zip_path) as z:
                vn = pickle.loads(z.read(VECNORM_MEMBER)) if VECNORM_MEMBER in z.namelist() else None
        except zipfile.BadZipFile:
            vn = None
        if vn is None:
            return None
    vn.training = False
    vn.norm_reward = False
    return vn


def trained_normalised(zip_path: str | Path) -> bool:
    """Whether the SB3 model at ``zip_path`` was trained under ``VecNormalize``: its saved data holds the last
    unnormalised observations (``_last_original_obs``), which SB3 keeps only for a ``VecNormalize`` env."""
    try:
        with zipfile.ZipFile(zip_path) as z:
            data = json.loads(z.read("data"))
    except (KeyError, ValueError, OSError, zipfile.BadZipFile):
        return False
    return data.get("_last_original_obs") is not None


def _carries_statistics(zip_path: Path) -> bool:
    """Whether the saved model at ``zip_path`` has statistics beside it or inside it (nothing unpickled)."""
    if policy_files(zip_path)[1].is_file():
        return True
    try:
        with zipfile.ZipFile(zip_path) as z:
            return VECNORM_MEMBER in z.namelist()
    except (OSError, zipfile.BadZipFile):
        return False


def check_statistics(zip_path: str | Path) -> None:
    """A one-line ``ValueError`` for a model trained under ``VecNormalize`` (:func:`trained_normalised`) that
    carries no statistics and has none beside it: it would fly on raw observations. The message says what to pass."""
    p = Path(zip_path)
    if not _carries_statistics(p) and trained_normalised(p):
        raise ValueError(f"{str(p)!r} was trained under VecNormalize and carries no statistics (none inside it, no "
                         f"{p.stem}{VECNORM_SUFFIX} beside it): give it the file VecNormalize.save wrote, as "
                         f"lvgym export-policy {p} STEM --vecnormalize FILE.pkl, and fly STEM.zip")


def statistics(zip_path: str | Path, stats: str | Path | None = None) -> Any:
    """:func:`load_vecnormalize`, after :func:`check_statistics` when no file ``stats`` is given."""
    if stats is None:
        check_statistics(zip_path)
    return load_vecnormalize(zip_path, stats)


def describe_saved(path: str | Path) -> str:
    """One line naming what the saved policy at ``path`` flies: for a run folder its best model (by validation),
    its final model or its newest checkpoint, with the step; ``""`` for a ``.zip`` given itself. Raises what
    :func:`check_statistics` raises (the main process of ``evaluate.py`` calls it before any episode flies)."""
    zip_path = resolve_model_path(path)
    check_statistics(zip_path)
    if not Path(path).is_dir():
        return ""
    step = read_meta(zip_path).get("num_timesteps")
    at = f"step {int(step):,}" if step is not None else "step not recorded"
    what = {"best_model": f"its best model by validation ({at})", "final_model": f"its final model ({at})"}
    return f"{zip_path}: " + what.get(zip_path.stem, f"its newest checkpoint {zip_path.stem} ({at}; no best or final "
                                                      "model)")


@dataclasses.dataclass
class ExportArgs:
    """Command-line arguments (``lvgym export-policy --help``)."""

    run: str = arg(positional=True, metavar="RUN")
    """run folder (runs/<name>: its best, else final, else latest model) or a .zip"""
    stem: str = arg(positional=True, metavar="STEM")
    """destination without suffix, e.g. agents/trained/ppo_smile_ascent"""
    vecnormalize: str | None = arg(None, metavar="FILE")
    """VecNormalize statistics (the file VecNormalize.save wrote) for the copy to carry: a model trained under
    VecNormalize by another tool flies only with them (default: the policy's own)"""


def export_main(argv: list[str] | None = None) -> None:
    """``lvgym export-policy RUN STEM``: copy a run's policy (best, else final, else latest) to STEM.zip,
    STEM_vecnormalize.pkl and STEM.json."""
    from lvgym.commandline import command_name, fail, parse

    prog = "python -m lvgym.agents.policies.saved export"
    args = parse(ExportArgs, argv, prog, export_main.__doc__)
    try:
        src = resolve_model_path(args.run)
        statistics(src, args.vecnormalize)           # the copy carries what it flies with, or nothing is written
    except (FileNotFoundError, ValueError) as exc:
        fail(command_name(prog), exc)
    dst = copy_policy(src, args.stem, {"exported_from": str(src)}, args.vecnormalize)
    print(f"{src} -> {dst}")


def main(argv: list[str] | None = None) -> None:
    """``python -m lvgym.agents.policies.saved export RUN STEM`` (``lvgym export-policy RUN STEM``)."""
    from lvgym.commandline import Command, dispatch

    dispatch([Command("export", "lvgym.agents.policies.saved:export_main", "copy a run's policy to STEM.zip, "
                      "STEM_vecnormalize.pkl, STEM.json")], argv, "python -m lvgym.agents.policies.saved")


if __name__ == "__main__":
    main()
