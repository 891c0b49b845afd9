"""The policies the benchmark's command lines know by name (``evaluate.py``, ``lvgym margins``,
``... budget``) and how a name or a saved model's path becomes a :class:`~.runner.PolicySpec`. The
options those commands share are declared in the command layer (:mod:`lvgym.cli.flights`).

A spec holds an import path as a string (``"lvgym.baselines.pid:smile_tuned_pid"``); the factory is imported in
the worker that flies the policy, so this module imports neither ``baselines`` nor ``agents`` (the layers
of DESIGN.md: the benchmark sits below the controllers and the agents).
"""

from __future__ import annotations

from pathlib import Path

from .runner import ZERO, PolicySpec

__all__ = ["POLICIES", "resolve_policy"]

#: policy names -> how a worker builds them (factories are imported lazily, in the workers)
POLICIES: dict[str, PolicySpec] = {
    "zero": ZERO,
    # our tuning on the rigid linearisation (lvgym.baselines.design.tune): one gain set, and the schedule on mass
    "pid": PolicySpec("pid", "lvgym.baselines.pid:smile_tuned_pid"),
    "gs-pid": PolicySpec("gs-pid", "lvgym.baselines.pid:smile_scheduled_pid", (("name", "gs-pid"), ("schedule", "smile"))),
    # designed on the non-rigid v1 flight loop (lvgym.baselines.design.flexdesign, docs/flex-design.md): structural
    # filters and gains scheduled on mass, the schedule of the env's vehicle (lvgym.baselines.pid.FLEX_SCHEDULES)
    "gs-pid-flex": PolicySpec("gs-pid-flex", "lvgym.baselines.pid:flex_pid", (("name", "gs-pid-flex"),)),
    # adaptive augmenting control on gs-pid-flex (lvgym.baselines.aac, docs/adaptive-control.md)
    "aac": PolicySpec("aac", "lvgym.baselines.aac:flex_aac", (("name", "aac"),)),
    # the thesis's gains (6.3.1) and its Table 6.10 schedule, as published
    "pid-thesis": PolicySpec("pid-thesis", "lvgym.baselines.pid:smile_single_pid"),
    "gs-pid-thesis": PolicySpec("gs-pid-thesis", "lvgym.baselines.pid:smile_scheduled_pid",
                                (("name", "gs-pid-thesis"), ("schedule", "smile_thesis"))),
    # LQG on the non-rigid flight plant, scheduled over the flight (lvgym.baselines.design.lqg_design, docs/lqg.md)
    "lqg": PolicySpec("lqg", "lvgym.baselines.lqg:smile_lqg", (("name", "lqg"),)),
    # lqg with its boost and max-q rows moved along the turbulence-against-margin trade: the design of lowest
    # turbulence rate error within 2 dB of gain margin and 60 % of the delay margin (experiments.lqg_headroom.headroom)
    "lqg-front": PolicySpec("lqg-front", "lvgym.baselines.lqg:smile_lqg",
                            (("name", "lqg-front"), ("schedule", "smile_lqg_front"))),
    # the shipped learned policies (agents/trained, docs/training.md): PPO of SmileAscent-v0 (the ideal state
    # observation), and protocol v1's: PPO residual on lqg, flight sensors, a 4-sample history
    "ppo": PolicySpec("ppo", "lvgym.agents.policy:shipped_policy"),
    "ppo-res-lqg": PolicySpec("ppo-res-lqg", "lvgym.agents.policy:shipped_policy",
                              (("file", "ppo_res_lqg_smile_v1"), ("name", "ppo-res-lqg"))),
}


def resolve_policy(name: str, prog: str = "evaluate.py") -> PolicySpec:
    """The :class:`PolicySpec` of a registered name, of a saved stable-baselines3 model (``.zip``; an
    optional ``<stem>_vecnormalize.pkl`` next to it normalises the observations) or of a ``train.py`` run
    folder (its best model). Checks here, in the main process, that the factory imports, so a missing
    package fails before any episode runs; a bad name exits with a one-line message starting ``prog:``."""
    if name in POLICIES:
        spec = POLICIES[name]
        try:
            spec.resolve()
        except ImportError as exc:
            raise SystemExit(f"{prog}: policy {name!r} needs {spec.factory} (the "
                             f"{spec.factory.split('.')[0].split(':')[0]} package), which is not available: {exc}")
        return spec
    path = Path(name)
    if path.suffix == ".zip" or path.exists():
        if not path.exists():
            raise SystemExit(f"{prog}: policy {name!r}: no such file")
        if path.is_dir():                       # a training run folder: its best (or final) model
            return PolicySpec(path.name, "lvgym.agents.policy:load_policy", (("path", str(path.resolve())),))
        return PolicySpec(path.stem, "lvgym.agents.policy:load_policy", (("path", str(path.resolve())),))
    raise SystemExit(f"{prog}: policy {name!r}: one of {sorted(POLICIES)}, a path to an SB3 .zip model or a "
                     "train.py run folder")
