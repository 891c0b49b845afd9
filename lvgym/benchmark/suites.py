"""The frozen evaluation protocol: named suites of conditions and the seed sets they are run on.

A *condition* is one env configuration (env id, flight model, wind tier, randomisation and a few fixed
options); a *suite* is a list of conditions that share a seed set. Episode ``i`` of a suite is reset
with the same seed under every condition and for every policy (common random numbers), so the rigid and
the non-rigid episode of a seed fly the same wind and dispersions and the comparison is paired.

Seeds: **training** seeds ``100_000 ..`` (:data:`TRAINING_SEEDS`) are what training runs fly; **validation**
seeds ``0 .. 9_999`` are for tuning and model selection; **test** seeds ``10_000 .. 19_999`` are for reported
numbers only, and every flight on them is logged (:mod:`.ledger`). The three ranges are disjoint: a policy is
never selected or scored on an episode it was trained on.
Episode ``i`` uses ``VALIDATION_SEED0 + i`` or ``TEST_SEED0 + i`` (from a named block's first seed on:
:data:`DEVELOPMENT_BLOCK`, the 50 seeds flown throughout development, and :data:`HEADLINE_BLOCK`, the 200
never-flown test seeds of the headline that decides).

The protocol is versioned: :data:`PROTOCOL_VERSION` is written into every result record. A change of a
suite's conditions, of a seed set or of a metric's definition is a new version (``v1``, ...) and leaves
the old suites untouched under their old names; results of different versions are not comparable.

=================  =====================  ==========================================================
suite              env                    conditions (each flown ``rigid`` and ``nonrigid``)
=================  =====================  ==========================================================
smile-calm         SmileAscent-v0         no wind; thrust misalignment and mass dispersed
smile-windy        SmileAscent-v0         moderate Dryden turbulence over a 10 m/s wind (drawn per
                                          seed); thrust misalignment dispersed. v0's main suite.
smile-dispersed    SmileAscent-v0         random jet stream + turbulence, every randomisation (mass,
                                          slosh damping, bending frequency, sensor noise), IMU sensors
slender-ld30       SlenderAscent-v0       L/D = 30 (8.5 m x 0.2833 m); turbulence drawn per seed,
                                          thrust misalignment and bending frequency dispersed
=================  =====================  ==========================================================

Protocol v1 (version ``v1``, frozen on 2026-12-02; :mod:`.fingerprint` holds it to its episodes) adds, on
``SmileAscent-v1``:

==================  ===============================================================================
smile-v1            70 s, v0's turbulence plus a random 1-cosine gust, every dispersion (``V1_DISPERSIONS``), the default
smile-v1-maxq-gust  35 s, a random jet stream plus a random gust in the max-q region, every dispersion
stratos-tvc-v1      Stratos III with TVC (StratosIII-v1), 30 s, turbulence, every dispersion
slender-v1          the L/D 30 slender vehicle with its aeroelastic loads (SlenderAscent-v1), 10 s, turbulence,
                    every dispersion; its baseline is gs-pid-flex with load relief (docs/flex-design.md:
                    on validation seeds 0-9 the gimbal at zero fails 2/10 rigid and 4/10 non-rigid on q-alpha)
==================  ===============================================================================

Protocol v2 (version ``v2``, frozen on 2026-12-05; :data:`SUITES_V2`, evaluate.py's default) charges the
flyability rule (``score_v2``) and names per suite a reference of the normalised score and the policies it
reports; docs/benchmark.md, "Protocol v2":

==================  ===============================================================================
smile-v2            smile-v1's conditions under the flyability rule (the main suite)
smile-v2-maxq-gust  smile-v1-maxq-gust's: 35 s through max q, a random jet stream and gust at 8-11.5 km
smile-v2-faults     smile-v1's with one in-flight fault per episode (``V2_FAULT_KINDS``), onset in 5-40 s
stratos-tvc-v2      stratos-tvc-v1's under the flyability rule
slender-v2          slender-v1's under the flyability rule
==================  ===============================================================================

``slender-ld30`` is provisional: there is no slender baseline yet. SlenderAscent-v0 freezes the vehicle's
aerodynamics at Mach 2 (the thesis's constant coefficients; with the full tables the vehicle turns
statically unstable above Mach 3.85 and no policy survives). Dynamic pressure reaches 500-700 kPa, so
the q-alpha limit asks for load relief against the zero-rate goal: on the 50 test seeds the gimbal at
zero fails 12-14 %, the SMILE-tuned PIDs 48-66 % and the SMILE-trained PPO 100 % (docs/vehicles.md).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from lvgym.errors import ConfigError, did_you_mean

PROTOCOL_VERSION = "v0"
#: first validation seed; validation seeds are ``VALIDATION_SEED0 + i`` for ``i < N_VALIDATION_SEEDS``
VALIDATION_SEED0 = 0
N_VALIDATION_SEEDS = 10_000
#: first test seed; test seeds are ``TEST_SEED0 + i`` (disjoint from the validation seeds)
TEST_SEED0 = 10_000
N_TEST_SEEDS = 10_000
SEED_SETS = ("test", "validation")
#: the faces of a condition's batched env (:meth:`Condition.make_vec_env`): Gymnasium's ``VectorEnv``, SB3's ``VecEnv``
VEC_APIS = ("gymnasium", "sb3")
#: first training seed; the training seeds are ``TRAINING_SEED0 + i`` for ``i < N_TRAINING_SEEDS``, above every
#: validation and test seed. Training seed ``k`` of a run (``lvgym train --seed k``, the teacher-student recipe's
#: ``--seeds``) starts its env rows at ``TRAINING_SEED0 + TRAINING_SEED_STRIDE * k``, so runs of different
#: training seeds share no row
TRAINING_SEED0 = 100_000
N_TRAINING_SEEDS = 1_000_000_000
TRAINING_SEED_STRIDE = 10_000
#: the training seeds, as a range (``seed in TRAINING_SEEDS``)
TRAINING_SEEDS = range(TRAINING_SEED0, TRAINING_SEED0 + N_TRAINING_SEEDS)


@dataclass(frozen=True)
class SeedBlock:
    """A named block of ``n`` consecutive seeds of ``seed_set``, from its ``first``-th seed on (the seeds
    ``TEST_SEED0 + first`` .. ``TEST_SEED0 + first + n - 1`` of the test set)."""

    name: str
    seed_set: str
    first: int
    n: int

    def seeds(self) -> list[int]:
        """The block's seeds, in order."""
        base = TEST_SEED0 if self.seed_set == "test" else VALIDATION_SEED0
        return [base + self.first + i for i in range(self.n)]

    def label(self) -> str:
        """``<name> (<seed_set> seeds <first>-<last>)``."""
        s = self.seeds()
        return f"{self.name} ({self.seed_set} seeds {s[0]:,}-{s[-1]:,})"


#: the 50 test seeds 10,000-10,049 that every table of protocols v0-v2 was flown on during development, many
#: times (docs/data/test-flights.jsonl): the headline's continuity column, no longer a test
DEVELOPMENT_BLOCK = SeedBlock("development-50", "test", 0, 50)
#: the headline's test block: the 200 test seeds 12,000-12,199, never flown before it was named (2026-12-07; far
#: from the development block and from the 150 seeds a re-flight study flew once beyond it, whose range is not
#: recorded). ``lvgym headline fly`` flies the selected policies on it once per selection (docs/test-seeds.md,
#: "The headline's test block"); the frozen suites' own seeds are unchanged
HEADLINE_BLOCK = SeedBlock("headline-200", "test", 2_000, 200)
#: the named blocks of seeds, by name
SEED_BLOCKS = {b.name: b for b in (DEVELOPMENT_BLOCK, HEADLINE_BLOCK)}
#: the main suite: protocol v2's SMILE ascent (the conditions of v1's ``smile-v1``, under the flyability rule)
DEFAULT_SUITE = "smile-v2"


def _freeze(options: Mapping[str, Any]) -> tuple[tuple[str, Any], ...]:
    """Options as a sorted tuple of pairs (hashable; lists become tuples)."""
    return tuple(sorted((k, tuple(v) if isinstance(v, list) else v) for k, v in options.items()))


@dataclass(frozen=True)
class Condition:
    """One env configuration of a suite.

    env_id: a registered lvgym env id; model: ``rigid | slosh | flex | nonrigid``; wind: a wind tier
    (``lvgym.envs.WIND_TIERS``); randomize: names of ``lvgym.envs.RANDOMIZE`` drawn per seed (a sorted
    tuple, or ``()``); options: further env keywords as sorted ``(key, value)`` pairs (e.g.
    ``("mission_time_s", 3.0)``). ``name`` labels the condition in result tables; conditions of a suite
    that differ only in ``model`` share a ``group`` (the pairing of the rigid-to-non-rigid degradation).
    """

    name: str
    env_id: str
    model: str = "nonrigid"
    wind: str = "none"
    randomize: tuple[str, ...] = ()
    options: tuple[tuple[str, Any], ...] = ()
    group: str = ""

    def env_kwargs(self) -> dict[str, Any]:
        """Keywords of ``gymnasium.make(self.env_id, **kwargs)``."""
        return {"model": self.model, "wind": self.wind, "randomize": list(self.randomize), **dict(self.options)}

    def make_env(self) -> Any:
        """A fresh env of this condition (``gymnasium.make``: the package ``lvgym``, imported with this
        module, registered the ids)."""
        import warnings

        import gymnasium

        with warnings.catch_warnings():            # a frozen v0 suite flies its v0 env on purpose
            warnings.filterwarnings("ignore", message=".*is out of date", category=DeprecationWarning)
            return gymnasium.make(self.env_id, **self.env_kwargs())

    def make_vec_env(self, num_envs: int = 1, api: str = "gymnasium", seed: int | None = None) -> Any:
        """A batched env of ``num_envs`` rows of this condition, one simulator over all rows. ``api``
        (:data:`VEC_APIS`): ``gymnasium``, the id's ``vector_entry_point``, whose ``reset(seed=s)`` seeds row
        ``i`` with ``s + i``, the single env's episode of seed ``s + i``; ``sb3``, the same rows as a
        stable-baselines3 ``VecEnv`` (:func:`lvgym.envs.make_sb3_vec_env`), row ``i`` seeded ``seed + i``
        (``seed`` is for it alone: SB3's ``reset()`` takes none)."""
        import warnings

        import gymnasium

        if api not in VEC_APIS:
            raise ConfigError("api", api, f"one of {list(VEC_APIS)}{did_you_mean(api, VEC_APIS)}")
        if api == "gymnasium" and seed is not None:
            raise ConfigError("seed", seed, "None with api='gymnasium' (seed its rows with reset(seed=s): row i "
                                            "gets s + i)")
        with warnings.catch_warnings():            # a frozen v0 suite flies its v0 env on purpose
            warnings.filterwarnings("ignore", message=".*is out of date", category=DeprecationWarning)
            if api == "sb3":                      # the id's class, as gymnasium.make finds it (registered)
                from gymnasium.envs.registration import load_env_creator

                from lvgym.envs.sb3 import AscentSB3VecEnv

                env_cls = load_env_creator(gymnasium.spec(self.env_id).entry_point)
                return AscentSB3VecEnv(env_cls, int(num_envs), seed, **self.env_kwargs())
            return gymnasium.make_vec(self.env_id, num_envs=int(num_envs), vectorization_mode="vector_entry_point",
                                      **self.env_kwargs())

    def with_options(self, **options: Any) -> Condition:
        """This condition with env keywords added or replaced (e.g. a short ``mission_time_s`` for tests)."""
        return replace(self, options=_freeze({**dict(self.options), **options}))

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly description."""
        return {"name": self.name, "env_id": self.env_id, "model": self.model, "wind": self.wind,
                "randomize": list(self.randomize), "options": dict(self.options), "group": self.group}


@dataclass(frozen=True)
class Suite:
    """A named list of conditions evaluated on a common seed set."""

    name: str
    description: str
    conditions: tuple[Condition, ...]
    version: str = PROTOCOL_VERSION
    overrides: tuple[tuple[str, Any], ...] = field(default=())
    reference: str = ""
    """the named classical policy of the normalised score (the zero policy 0, it 1; :func:`~.metrics.normalise`);
    empty: none (v0 and v1)"""
    policies: tuple[str, ...] = ()
    """the registered policies the protocol reports on this suite (``evaluate.py``'s default for it; empty: the
    command's default list, as for v0 and v1)"""
    joined: tuple[tuple[str, str], ...] = ()
    """when each entry of ``policies`` joined the list: ``(policy, ISO date)`` pairs (empty: not recorded)"""

    def policies_joined(self) -> list[dict[str, str | None]]:
        """``policies`` in order, each with the date it joined the list (``None``: not recorded): what the
        result files record beside the list flown."""
        when = dict(self.joined)
        return [{"policy": p, "joined": when.get(p)} for p in self.policies]

    def seeds(self, seed_set: str, n: int, first: int = 0) -> list[int]:
        """``n`` seeds of ``seed_set`` (``"test"`` or ``"validation"``) from its ``first``-th on (default: its
        first ``n``; a named block such as :data:`HEADLINE_BLOCK` starts further on)."""
        if seed_set not in SEED_SETS:
            raise ValueError(f"seed_set = {seed_set!r}: one of {SEED_SETS}")
        limit = N_TEST_SEEDS if seed_set == "test" else N_VALIDATION_SEEDS
        if not 0 <= int(first) < limit:
            raise ValueError(f"first = {first!r}: 0 .. {limit - 1} for the {seed_set} seed set")
        if not 1 <= int(n) <= limit - int(first):
            raise ValueError(f"episodes = {n!r}: 1 .. {limit - int(first)} per condition for the {seed_set} seed set"
                             + (f" from its seed {first}" if first else ""))
        base = TEST_SEED0 if seed_set == "test" else VALIDATION_SEED0
        return [base + int(first) + i for i in range(int(n))]

    def with_options(self, **options: Any) -> Suite:
        """This suite with env keywords overridden in every condition. The overrides are recorded
        (``overrides``) and the version gets a ``+override`` suffix: such results are not protocol numbers."""
        if not options:
            return self
        conds = tuple(c.with_options(**options) for c in self.conditions)
        return replace(self, conditions=conds, version=f"{self.version}+override",
                       overrides=_freeze({**dict(self.overrides), **options}))


def _pair(suite: str, env_id: str, wind: str, randomize: tuple[str, ...],
          models: tuple[str, ...] = ("rigid", "nonrigid"), **options: Any) -> tuple[Condition, ...]:
    """The conditions of one group: the same env flown with each flight model."""
    return tuple(Condition(name=f"{suite}/{m}", env_id=env_id, model=m, wind=wind, randomize=tuple(sorted(randomize)),
                           options=_freeze(options), group=suite) for m in models)


SMILE, SLENDER = "lvgym/SmileAscent-v0", "lvgym/SlenderAscent-v0"

#: the frozen suites of protocol v0 (do not edit: add new suites or a new protocol version instead)
SUITES: dict[str, Suite] = {s.name: s for s in (
    Suite("smile-calm", "SMILE, 60 s, no wind; thrust misalignment and mass dispersed",
          _pair("smile-calm", SMILE, "none", ("thrust_misalignment", "mass"))),
    Suite("smile-windy", "SMILE, 60 s, moderate Dryden turbulence over a 10 m/s wind drawn per seed; "
          "thrust misalignment dispersed",
          _pair("smile-windy", SMILE, "turbulence", ("wind", "thrust_misalignment"))),
    Suite("smile-dispersed", "SMILE, 60 s, random jet stream and turbulence, every randomisation, IMU sensors",
          _pair("smile-dispersed", SMILE, "random", ("wind", "thrust_misalignment", "mass", "slosh_damping",
                                                     "bending_frequency", "sensor_noise"), observation="sensors")),
    Suite("slender-ld30", "Slender vehicle L/D = 30 (8.5 m x 0.2833 m), 10 s, turbulence drawn per seed; "
          "thrust misalignment and bending frequency dispersed",
          _pair("slender-ld30", SLENDER, "turbulence", ("wind", "thrust_misalignment", "bending_frequency"),
                length=8.5, diameter=0.2833)),
)}


#: protocol v1, frozen on 2026-12-02 (results before that carry ``v1-draft``: an earlier draft's numbers);
#: ``lvgym/benchmark/data/v1.json`` is its fingerprint (:mod:`.fingerprint`), tests/test_protocol_fingerprint.py
#: holds every later version of the code to it
PROTOCOL_V1 = "v1"
SMILE_V1 = "lvgym/SmileAscent-v1"
#: every randomisation of v1 (v0's and the Monte Carlo dispersions of docs/benchmark.md)
V1_DISPERSIONS = ("wind", "thrust_misalignment", "mass", "slosh_damping", "bending_frequency", "sensor_noise",
                  "aerodynamics", "thrust_level", "slosh_mass", "slosh_frequency", "bending_damping", "servo_bandwidth",
                  "servo_delay", "imu_station")

#: the suites of protocol v1 (frozen: a change of their definitions or of what they fly is a new version)
SUITES_V1: dict[str, Suite] = {s.name: s for s in (
    Suite("smile-v1", "SMILE v1 (own upper-stage aerodynamics, staging at 1.8 kPa, coast control, one period of "
          "delay), 70 s, turbulence and a random 1-cosine gust, every dispersion",
          _pair("smile-v1", SMILE_V1, "turbulence_gust", V1_DISPERSIONS), version=PROTOCOL_V1),
    Suite("stratos-tvc-v1", "Stratos III with TVC (StratosIII-v1), 30 s, turbulence drawn per seed; thrust "
          "misalignment, mass, aerodynamics, thrust level and the slosh and bending dispersions",
          _pair("stratos-tvc-v1", "lvgym/StratosIII-v1", "turbulence", V1_DISPERSIONS), version=PROTOCOL_V1),
    Suite("slender-v1", "Slender vehicle L/D = 30 (SlenderAscent-v1: aeroelastic strip loads, 4.5 mm wall), 10 s, "
          "turbulence, every dispersion (baseline: gs-pid-flex with load relief, docs/flex-design.md)",
          _pair("slender-v1", "lvgym/SlenderAscent-v1", "turbulence", V1_DISPERSIONS, length=8.5, diameter=0.2833),
          version=PROTOCOL_V1),
    Suite("smile-v1-maxq-gust", "SMILE v1 through max q, 35 s: a random jet stream and a random 1-cosine gust in "
          "the max-q region (8-11.5 km), every dispersion",
          _pair("smile-v1-maxq-gust", SMILE_V1, "maxq_gust", V1_DISPERSIONS, mission_time_s=35.0),
          version=PROTOCOL_V1),
)}
SUITES.update(SUITES_V1)

#: protocol v2, frozen on 2026-12-05 (results before that carry ``v2-draft``: a draft's numbers);
#: ``lvgym/benchmark/data/v2.json`` is its fingerprint. What it adds to v1 (docs/benchmark.md, "Protocol v2"):
#: the flyability rule (``score_v2``, :mod:`.flyability`), in-flight faults, a named reference per suite for the
#: normalised score, and the policies each suite reports (``policies``: evaluate.py's default for it)
PROTOCOL_V2 = "v2"
#: the kinds of fault of smile-v2-faults: ``stuck`` is left out (no design flies it: SMILE has no other
#: effector on a jammed axis; experiments/protocol_v2_design, part 5)
V2_FAULT_KINDS = ("effectiveness", "bandwidth", "thrust", "gyro_bias", "misalignment")
#: the policies v2 reports on SMILE: no control, the flex design that breaks the flyability rule and its quiet
#: redesigns, the LQG family, the soft loop without integral made for the max-q gust (added 2026-12-05 with
#: issue 35's finding; the suites, seeds and fingerprints unchanged), the shipped learned policies (v1's
#: residual PPO; ``inversion-id``, trained on the faults, and ``inversion-id-smile``, on smile-v2, added 2026-12-06
#: likewise) and the privileged reference
V2_SMILE_POLICIES = ("zero", "gs-pid-flex", "gs-pid-flex-quiet", "aac-quiet", "lqg", "lqg-front", "gs-pd-relief",
                     "ppo-res-lqg", "inversion-id", "inversion-id-smile", "privileged")
#: ... on Stratos III (no LQG is made for it; its learned policy ``inversion-id-stratos`` added 2026-12-06, the
#: suite, seeds and fingerprint unchanged)
V2_STRATOS_POLICIES = ("zero", "gs-pid-flex", "gs-pid-flex-quiet", "aac-quiet", "inversion-id-stratos", "privileged")
#: ... on the slender vehicle (its one design, the load-relief gs-pid-flex, has no quiet version that flies)
V2_SLENDER_POLICIES = ("zero", "gs-pid-flex", "privileged")
#: the day protocol v2 was frozen: the entries of its reported lists that joined with it
V2_FROZEN_ON = "2026-12-05"
#: when the entries of v2's reported lists that came after its suites joined them (the rest joined with v2,
#: :data:`V2_FROZEN_ON`); a new entry's date is added here with it
V2_JOINED = {"gs-pd-relief": "2026-12-05", "inversion-id": "2026-12-06", "inversion-id-smile": "2026-12-06",
             "inversion-id-stratos": "2026-12-06"}


def _joined(policies: tuple[str, ...]) -> tuple[tuple[str, str], ...]:
    return tuple((p, V2_JOINED.get(p, V2_FROZEN_ON)) for p in policies)


SUITES_V2: dict[str, Suite] = {s.name: s for s in (
    Suite("smile-v2", "smile-v1 under protocol v2's flyability rule",
          _pair("smile-v2", SMILE_V1, "turbulence_gust", V1_DISPERSIONS), version=PROTOCOL_V2, reference="lqg",
          policies=V2_SMILE_POLICIES, joined=_joined(V2_SMILE_POLICIES)),
    Suite("smile-v2-maxq-gust", "smile-v1-maxq-gust under protocol v2's flyability rule: 35 s through max q, a "
          "random jet stream and a random 1-cosine gust at 8-11.5 km, where holding the rate and holding the "
          "structural load conflict",
          _pair("smile-v2-maxq-gust", SMILE_V1, "maxq_gust", V1_DISPERSIONS, mission_time_s=35.0),
          version=PROTOCOL_V2, reference="lqg", policies=V2_SMILE_POLICIES, joined=_joined(V2_SMILE_POLICIES)),
    Suite("smile-v2-faults", "smile-v1 with one in-flight fault per episode (a loss of actuator effectiveness or "
          "bandwidth on one axis, a thrust loss, a gyro bias step or a thrust-direction step), its onset "
          "unannounced in 5-40 s",
          _pair("smile-v2-faults", SMILE_V1, "turbulence_gust", (*V1_DISPERSIONS, "fault"),
                fault_kinds=V2_FAULT_KINDS, fault_onset_s=(5.0, 40.0)), version=PROTOCOL_V2, reference="lqg",
          policies=V2_SMILE_POLICIES, joined=_joined(V2_SMILE_POLICIES)),
    Suite("stratos-tvc-v2", "stratos-tvc-v1 under protocol v2's flyability rule",
          _pair("stratos-tvc-v2", "lvgym/StratosIII-v1", "turbulence", V1_DISPERSIONS), version=PROTOCOL_V2,
          reference="gs-pid-flex-quiet", policies=V2_STRATOS_POLICIES, joined=_joined(V2_STRATOS_POLICIES)),
    Suite("slender-v2", "slender-v1 under protocol v2's flyability rule",
          _pair("slender-v2", "lvgym/SlenderAscent-v1", "turbulence", V1_DISPERSIONS, length=8.5, diameter=0.2833),
          version=PROTOCOL_V2, policies=V2_SLENDER_POLICIES, joined=_joined(V2_SLENDER_POLICIES)),
)}
SUITES.update(SUITES_V2)

#: the launcher family's suites, frozen as version ``v2-family`` (fingerprint ``data/v2-family.json``; protocol
#: v2 was frozen before them, so they are a version of their own; results made before carry
#: ``v2-family-draft``). Each test vehicle
#: (``lvgym/vehicles/family``: the first 20 test seeds of :mod:`lvgym.vehicle.generator` whose vehicles
#: pass the family's checks, written once by ``lvgym.baselines.family.write_family``) is a pair of
#: conditions, rigid and non-rigid, in smile-v2's conditions for 60 s; a policy flies every vehicle on the
#: same wind seeds. ``family-v2`` is the ``blind`` track (the flight computer's signals only),
#: ``family-v2-informed`` the ``informed`` one (the observation ends with the vehicle's design
#: parameters: the env option ``vehicle_info``). docs/family.md
PROTOCOL_FAMILY = "v2-family"
FAMILY_VEHICLES = tuple(f"family/test_{seed}" for seed in range(20_000, 20_020))
#: the family's shipped validation vehicles (the first 10 validation seeds that pass its checks): what
#: training selects and tunes on (:func:`family_validation_suite`), never reported
FAMILY_VALIDATION_VEHICLES = tuple(f"family/validation_{seed}" for seed in range(10_000, 10_010))
#: the family's baselines: none, the privileged reference, the nominal member's designs on every vehicle
#: (fixed), the per-vehicle rigid-body design (the thesis's practice) and flexible designs (the field's)
FAMILY_POLICIES = ("zero", "privileged", "fixed-gs-pid-flex", "fixed-lqg", "auto-gs-pid", "auto-gs-pid-flex",
                   "auto-lqg")
FAMILY_MISSION_S = 60.0


def _family(suite: str, vehicles: tuple[str, ...] = FAMILY_VEHICLES, **options: Any) -> tuple[Condition, ...]:
    """The conditions of a family suite: a rigid and a non-rigid one per vehicle of ``vehicles`` (default
    :data:`FAMILY_VEHICLES`; grouped per vehicle: ``<suite>/<seed>``)."""
    return tuple(c for v in vehicles for c in _pair(f"{suite}/{v.rsplit('_', 1)[1]}", SMILE_V1,
                                                    "turbulence_gust", V1_DISPERSIONS, vehicle=v,
                                                    mission_time_s=FAMILY_MISSION_S, **options))


def family_validation_suite(suite: Suite) -> Suite:
    """A family suite flown on the family's validation vehicles (:data:`FAMILY_VALIDATION_VEHICLES`) in
    place of its test vehicles, for training's model selection and tuning (with the validation seeds);
    any other suite as it is. Named ``<suite>@validation-vehicles``; not a suite of the benchmark."""
    if suite.name not in SUITES_FAMILY:
        return suite
    options = {k: v for k, v in suite.conditions[0].options if k not in ("vehicle", "mission_time_s")}
    return replace(suite, name=f"{suite.name}@validation-vehicles",
                   conditions=_family(suite.name, FAMILY_VALIDATION_VEHICLES, **options))


SUITES_FAMILY: dict[str, Suite] = {s.name: s for s in (
    Suite("family-v2", "the launcher family's 20 test vehicles, blind: each in smile-v2's conditions for 60 s, "
          "rigid and non-rigid, under the flyability rule", _family("family-v2"), version=PROTOCOL_FAMILY,
          reference="auto-lqg", policies=FAMILY_POLICIES),
    Suite("family-v2-informed", "family-v2 with the vehicle's design parameters at the end of the observation "
          "(vehicle_info)", _family("family-v2-informed", vehicle_info=True), version=PROTOCOL_FAMILY,
          reference="auto-lqg", policies=FAMILY_POLICIES),
)}
SUITES.update(SUITES_FAMILY)


def get_suite(name: str) -> Suite:
    """The suite called ``name``; a :class:`~lvgym.errors.ConfigError` (a ``ValueError``) lists the known
    names otherwise, with the closest one."""
    try:
        return SUITES[name]
    except (KeyError, TypeError):
        raise ConfigError("suite", name, f"one of {sorted(SUITES)}{did_you_mean(name, SUITES)}") from None


def condition(suite: str, model: str = "nonrigid", **overrides: Any) -> Condition:
    """The condition of suite ``suite`` flown with flight model ``model`` (what ``lvgym.make_env`` builds),
    with env keywords ``overrides`` added or replaced (:meth:`Condition.with_options`); a bad suite or
    model raises a one-line :class:`~lvgym.errors.ConfigError` naming what is allowed."""
    s = get_suite(suite)
    models = [c.model for c in s.conditions]
    if model not in models:
        raise ConfigError("model", model, f"one of {models} (the flight models of suite {s.name!r})"
                                          f"{did_you_mean(model, models)}")
    cond = s.conditions[models.index(model)]
    return cond.with_options(**overrides) if overrides else cond
