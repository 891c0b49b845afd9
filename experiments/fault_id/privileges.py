"""Which privilege flies the fault suite: the privileged reference with one privilege taken away at a time, and
``lqg`` given what the reference knows of the fault.

    python -m experiments.fault_id.privileges --seeds 100

Flies every variant of :data:`VARIANTS` on ``smile-v2-faults``, rigid and non-rigid, validation seeds ``0 ..
seeds - 1``, and prints the mean ``score_v2`` with the failed or unflyable flights and their reasons. The
reference (:mod:`lvgym.baselines.privileged`) knows the true state, the plant (the true thrust misalignment and
each actuator's effectiveness), the wind 0.1 s ahead, and it relieves the load; the ``lqg-*`` variants add to
``lqg``'s command what the reference knows of the plant: ``delta = delta_lqg - misalignment`` (``mis``),
``delta_lqg / effectiveness`` (``eff``), the misalignment known late (``mis-late-*``), or only the first
step's (the dispersion's, never the fault's: ``mis-static``), or the present aerodynamic moment cancelled
(``aero``). The ``*-observed*`` variants fly the reference on the observation's rate and attitude errors
(:class:`Withheld`), with the aerodynamic moment known late or without the effectiveness: what the reference's
law needs that a flight computer could estimate (:mod:`.inversion`). A study: it flies no test seed.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.agents.policies.inversion import SPAN, carry
from lvgym.commandline import arg, parse

#: a relief that never acts (from five times the q-alpha limit)
NO_RELIEF = (5.0, 6.0)


#: the span [control steps] of the slope an extrapolated aerodynamic moment is drawn along (the shipped law's
#: :data:`lvgym.agents.policies.inversion.SPAN`)
SLOPE_STEPS = SPAN


def extrapolate(history: Sequence[np.ndarray], ahead: int, span: int = SLOPE_STEPS) -> np.ndarray:
    """The last of ``history`` carried ``ahead`` steps along its slope over the last ``span`` steps (over
    fewer at the start of a flight: none at its first step)."""
    return carry(history[-1], history[max(0, len(history) - 1 - span)], ahead, span)


def reference(env: Any, preview: bool = True, relief: bool = True, plant: bool = True, observed: bool = False,
              eff: bool = True, aero_late_steps: int = 0, aero_ahead_steps: int = 0, name: str = "privileged",
              bandwidth_radps: float | None = None, plant_late_steps: int = 0) -> Any:
    """The privileged reference with its wind preview, its load relief or its knowledge of the plant taken away;
    ``observed``: on the flight computer's rate and attitude errors (the observation's) instead of the true ones;
    ``eff`` False: without the actuators' effectiveness (the misalignment kept); ``aero_late_steps``: the
    aerodynamic moment as it acted that many control steps ago (without preview); ``aero_ahead_steps``: the
    moment as it acts extrapolated that many steps ahead along its slope over the last :data:`SLOPE_STEPS`
    (what a causal predictor of the moment ahead could do without learning; without preview);
    ``bandwidth_radps``: the attitude loop's (None: the reference's); ``plant_late_steps``: every entry of
    :data:`PLANT` (the aerodynamic moment, the misalignment, the effectiveness) as it was that many control
    steps ago (how soon a causal law must know what a fault changed; without preview)."""
    from lvgym.baselines.privileged import privileged

    law = privileged(env, bandwidth_radps, name=name, preview_periods=None if preview else 0,
                     relief=None if relief else NO_RELIEF, plant=plant)
    withheld = observed or not eff or aero_late_steps or aero_ahead_steps or plant_late_steps
    return (Withheld(law, env, observed, eff, aero_late_steps, aero_ahead_steps, plant_late=plant_late_steps)
            if withheld else law)


#: the privileged info of the moments a fault changes, which ``plant_late_steps`` delays; the thrust stays the
#: step's own (the accelerometers measure it within a step, and the sequencer knows the ignition), and so do
#: the vehicle's geometry and inertia, the state and the q-alpha
PLANT = ("m_aero_b", "misalignment", "actuator_effectiveness")


class Withheld:
    """A privileged law given less than the step's privileged info: the observation's rate and attitude errors
    in place of the true ones (``observed``), no effectiveness (``eff`` False), the aerodynamic moment of
    ``late`` steps ago, or the present one extrapolated ``ahead`` steps along its slope over ``span``, and
    every entry of :data:`PLANT` as it was ``plant_late`` steps ago (the first step's before there were so
    many)."""

    def __init__(self, law: Any, env: Any, observed: bool, eff: bool, late: int, ahead: int = 0,
                 span: int = SLOPE_STEPS, plant_late: int = 0) -> None:
        names = list(env.unwrapped.func.observation_layout.names)
        self.law, self.name, self.observed, self.eff, self.late = law, law.name, observed, eff, int(late)
        self.ahead, self.span, self.plant_late = int(ahead), int(span), int(plant_late)
        self.plant: list[dict[str, Any]] = []
        self.i = [names.index(n) for n in ("pitch_rate_error", "yaw_rate_error", "pitch_attitude_error",
                                            "yaw_attitude_error", "pitch_rate_reference")]
        self.m_aero: list[np.ndarray] = []

    def reset(self) -> None:
        self.law.reset()
        self.m_aero = []
        self.plant = []

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        if "omega_bi_b" in info:
            info = dict(info)
            if self.observed:
                q, r, th, ps, ref = (float(observation[i]) for i in self.i)
                info.update(omega_bi_b=np.array([0.0, q + ref, r]), attitude_error=np.array([th, ps]))
            if not self.eff:
                info["actuator_effectiveness"] = np.ones(2)
            self.m_aero.append(np.asarray(info["m_aero_b"], dtype=np.float64))
            info["m_aero_b"] = self.m_aero[max(0, len(self.m_aero) - 1 - self.late)]
            if self.ahead:                                  # along the slope of the last span steps
                info["m_aero_b"] = extrapolate(self.m_aero, self.ahead, self.span)
            if self.plant_late:
                self.plant.append({k: info[k] for k in PLANT if k in info})
                info.update(self.plant[max(0, len(self.plant) - 1 - self.plant_late)])
        return self.law.act(observation, info)


reference.privileged = True  # type: ignore[attr-defined]


class PlantKnown:
    """``lqg``'s action corrected by the true plant from the step's privileged info: less the misalignment
    (``mis``; known ``late_steps`` control steps late, or only its first value with ``static``), divided by
    the actuator's effectiveness (``eff``)."""

    def __init__(self, env: Any, mis: bool, eff: bool, late_steps: int, static: bool, name: str,
                 aero: bool = False) -> None:
        from .estimator import base_lqg

        self.base = base_lqg(env)
        self.limit = float(env.unwrapped.func.gimbal_limit)
        self.mis, self.eff, self.late, self.static, self.name = mis, eff, int(late_steps), static, name
        self.aero = aero
        self.seen: list[np.ndarray] = []

    def reset(self) -> None:
        self.base.reset()
        self.seen = []

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        a = np.asarray(self.base.act(observation, info), dtype=np.float64)
        if "misalignment" not in info:                       # the reset's info
            return a.astype(np.float32)
        self.seen.append(np.asarray(info["misalignment"], dtype=np.float64))
        if self.mis:
            known = self.seen[0] if self.static else self.seen[max(0, len(self.seen) - 1 - self.late)]
            a = a - known / self.limit
        if self.aero:
            from lvgym.baselines.privileged import control_lever
            from lvgym.benchmark.batch import ROW, OneRowInfo

            lever = float(control_lever(OneRowInfo(info), ROW)[0])
            a = a - np.asarray(info["m_aero_b"], dtype=np.float64)[1:] / max(lever, 1.0) / self.limit
        if self.eff:
            a = a / np.maximum(np.asarray(info["actuator_effectiveness"], dtype=np.float64), 0.1)
        return np.clip(a, -1.0, 1.0).astype(np.float32)


def plant_known(env: Any, mis: bool = True, eff: bool = False, late_steps: int = 0, static: bool = False,
                name: str = "lqg-mis", aero: bool = False) -> PlantKnown:
    """:class:`PlantKnown` (it reads the privileged info, so the runner flies it with ``privileged_info``)."""
    return PlantKnown(env, mis, eff, late_steps, static, name, aero)


plant_known.privileged = True  # type: ignore[attr-defined]

_REF = "experiments.fault_id.privileges:reference"
_LQG = "experiments.fault_id.privileges:plant_known"
#: the variants by name: (factory, its keywords); ``lqg`` is the registered design
VARIANTS: dict[str, tuple[str, dict[str, Any]] | None] = {
    "privileged": (_REF, {}),
    "no-preview": (_REF, {"preview": False}),
    "no-relief": (_REF, {"relief": False}),
    "no-plant": (_REF, {"plant": False}),
    "no-plant-no-relief": (_REF, {"plant": False, "relief": False}),
    "true-state-only": (_REF, {"plant": False, "relief": False, "preview": False}),
    "no-preview-observed": (_REF, {"preview": False, "observed": True}),
    "observed": (_REF, {"observed": True}),
    "no-preview-observed-no-relief": (_REF, {"preview": False, "observed": True, "relief": False}),
    "no-preview-observed-no-eff": (_REF, {"preview": False, "observed": True, "eff": False}),
    "no-preview-observed-no-plant": (_REF, {"preview": False, "observed": True, "plant": False}),
    "no-preview-observed-aero-late-2": (_REF, {"preview": False, "observed": True, "aero_late_steps": 2}),
    "no-preview-observed-aero-late-5": (_REF, {"preview": False, "observed": True, "aero_late_steps": 5}),
    "no-preview-observed-aero-late-10": (_REF, {"preview": False, "observed": True, "aero_late_steps": 10}),
    "no-preview-observed-aero-extrapolated-5": (_REF, {"preview": False, "observed": True, "aero_ahead_steps": 5}),
    "lqg": None,
    "lqg-mis-aero": (_LQG, {"aero": True}),
    "lqg-mis-eff-aero": (_LQG, {"eff": True, "aero": True}),
    "lqg-mis-eff": (_LQG, {"eff": True}),
    "lqg-mis": (_LQG, {}),
    "lqg-eff": (_LQG, {"mis": False, "eff": True}),
    "lqg-mis-late-0.25s": (_LQG, {"late_steps": 12}),
    "lqg-mis-late-0.5s": (_LQG, {"late_steps": 25}),
    "lqg-mis-late-1s": (_LQG, {"late_steps": 50}),
    "lqg-mis-late-2s": (_LQG, {"late_steps": 100}),
    "lqg-mis-static": (_LQG, {"static": True}),
}


def specs(names: Sequence[str]) -> list[Any]:
    """The policies of the variants ``names``."""
    import lvgym.baselines  # noqa: F401

    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import PolicySpec
    from lvgym.errors import ConfigError

    out = []
    for name in names:
        if name not in VARIANTS:
            raise ConfigError("variants", name, f"one of {list(VARIANTS)}")
        v = VARIANTS[name]
        out.append(resolve_policy(name) if v is None else
                   PolicySpec(name, v[0], tuple(sorted({**v[1], "name": name}.items()))))
    return out


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.privileges --help``)."""

    seeds: int = arg(100, lo=1, hi=10_000)
    """validation seeds per variant and flight model"""
    variants: list[str] = arg(default_factory=lambda: list(VARIANTS), metavar="NAME")
    """the variants to fly (default: all)"""


def main(argv: Sequence[str] | None = None) -> None:
    from lvgym.benchmark import evaluate, get_suite

    args = parse(Args, argv, "python -m experiments.fault_id.privileges", __doc__)
    try:
        policies = specs(args.variants)
    except ValueError as exc:
        raise SystemExit(f"python -m experiments.fault_id.privileges: {exc}") from None
    records = evaluate(policies, [get_suite("smile-v2-faults")], args.seeds, "validation", progress=False)
    cells: dict[tuple[str, str], list[dict]] = defaultdict(list)
    for r in records:
        cells[(r["policy"], r["model"])].append(r)
    print(f"\nsmile-v2-faults, validation seeds 0-{args.seeds - 1}: mean score_v2 [rad] (failed or unflyable: "
          "q-alpha / attitude / other or unflyable)\n")
    print("| variant | rigid | non-rigid |\n|---|---|---|")
    for p in policies:
        row = []
        for model in ("rigid", "nonrigid"):
            rs = cells[(p.name, model)]
            why = Counter(("q-alpha" if "q-alpha" in str(r["failure_reason"]) else "attitude"
                           if "attitude" in str(r["failure_reason"]) else "other") if r["failed"] else "unflyable"
                          for r in rs if r["failed"] or not r["flyable"])
            row.append(f"{np.mean([r['score_v2'] for r in rs]):.3f} ({sum(why.values())}: "
                       f"{why['q-alpha']} / {why['attitude']} / {why['other'] + why['unflyable']})")
        print(f"| {p.name} | " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
