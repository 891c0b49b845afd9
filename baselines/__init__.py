"""PID and gain-scheduled PID TVC baselines (thesis 6.3), adaptive augmenting control on them (SLS-style,
docs/adaptive-control.md) and a bang-bang roll controller (thesis 5.3).

Every controller is a batch law (:class:`lvgym.benchmark.batch.BatchLaw`: ``reset(rows)``, ``act(rows,
observations, info)``) with a one-row face, the benchmark's policy interface (:class:`lvgym.benchmark.Policy`:
``reset()`` and ``act(observation, info) -> action``). ``lvgym design pid --vehicle smile``
tunes a gain schedule on the rigid linearisation (into ``results/schedules/``; ``--overwrite`` replaces
the shipped one in ``schedules/``); ``python -m experiments.control_study.study`` runs the
thesis's control study (docs/control-study.md).

Importing this package registers its controllers with the benchmark by name
(:func:`lvgym.benchmark.register_policy`): ``pid``, ``gs-pid``, ``gs-pid-flex``, ``aac``,
``gs-pid-flex-quiet``, ``aac-quiet``, ``pid-thesis``, ``gs-pid-thesis``, ``lqg``, ``lqg-front``, ``lqg-aw``,
``lqi``, ``lqi-hold``, ``mpc``, ``indi``, ``eso``, ``privileged`` (``evaluate.py --policies lqg``).
"""

from lvgym.benchmark.registry import register_policy

from .aac import AACParams, AdaptiveAugmentingPolicy, flex_aac, smile_aac
from .bangbang import BangBangRollPolicy
from .indi import smile_indi
from .lqg import smile_lqg
from .pid import (GainSchedule, GainScheduledPIDPolicy, PIDLaw, PIDPolicy, flex_pid, smile_scheduled_pid,
                  smile_single_pid, smile_tuned_pid)

# their kind in protocol v2's headline (lvgym.benchmark.headline): classical designs
for _factory in (smile_tuned_pid, smile_scheduled_pid, smile_single_pid, flex_pid, flex_aac, smile_aac, smile_lqg,
                 smile_indi):
    _factory.kind = "classical"  # type: ignore[attr-defined]

# our tuning on the rigid linearisation (lvgym.baselines.design.tune): one gain set, and the schedule on mass
register_policy("pid", smile_tuned_pid)
register_policy("gs-pid", smile_scheduled_pid, name="gs-pid", schedule="smile")
# designed on the non-rigid v1 flight loop (lvgym.baselines.design.flexdesign, docs/flex-design.md): structural
# filters and gains scheduled on mass, the schedule of the env's vehicle (lvgym.baselines.pid.FLEX_SCHEDULES)
register_policy("gs-pid-flex", flex_pid, name="gs-pid-flex")
# adaptive augmenting control on gs-pid-flex (lvgym.baselines.aac, docs/adaptive-control.md)
register_policy("aac", flex_aac, name="aac")
# the same designs held to protocol v2's flyability: the gyro noise's commanded gimbal rate at most 20 % of the
# rate limit (flexdesign --noise-rate 0.2; lvgym.baselines.pid.QUIET_SCHEDULES, docs/flex-design.md), and aac on it
register_policy("gs-pid-flex-quiet", flex_pid, name="gs-pid-flex-quiet", quiet=True)
register_policy("aac-quiet", flex_aac, name="aac-quiet", quiet=True)
# a soft attitude loop without integral, placed on the rigid body's control power over the flight: load relief
# by design for protocol v2's max-q gust (lvgym.baselines.design.pdrelief, docs/baselines.md)
register_policy("gs-pd-relief", smile_scheduled_pid, name="gs-pd-relief", schedule="smile_pd_relief")
# protocol v2's privileged reference: the true state and the aerodynamic moment known (not a flyable design)
register_policy("privileged", "lvgym.baselines.privileged:privileged", name="privileged")
# the thesis's gains (6.3.1) and its Table 6.10 schedule, as published
register_policy("pid-thesis", smile_single_pid)
register_policy("gs-pid-thesis", smile_scheduled_pid, name="gs-pid-thesis", schedule="smile_thesis")
# LQG on the non-rigid flight plant, scheduled over the flight (lvgym.baselines.design.lqg_design, docs/lqg.md)
register_policy("lqg", smile_lqg, name="lqg")
# lqg with its boost and max-q rows moved along the turbulence-against-margin trade: the design of lowest
# turbulence rate error within 2 dB of gain margin and 60 % of the delay margin (experiments.lqg_headroom.headroom)
register_policy("lqg-front", smile_lqg, name="lqg-front", schedule="smile_lqg_front")
# lqg with anti-windup: the command held to the servo's rate limit as well, so that the filter carries what the
# servo can follow, and the integral back-calculated (lvgym.baselines.lqgkernel.AntiWindup, docs/mpc.md)
register_policy("lqg-aw", smile_lqg, name="lqg-aw", back_gain=0.1)
# lqg-aw's law with the pure integral of the strapdown attitude error in place of the rate's leaky one, so that a
# constant disturbance moment (a thrust-direction step) leaves no attitude offset; its flight time from the
# observation (lvgym.baselines.design.lqg_design --integral attitude, docs/lqi.md)
register_policy("lqi", smile_lqg, name="lqi", schedule="smile_lqi", back_gain=0.1, clock="observation")
# lqi with the attitude at the engagement as its reference: the attitude the vehicle drifted to before the law
# engages is held, as lqg's rate integral holds it, and only the offsets after it are integrated away (docs/lqi.md)
register_policy("lqi-hold", smile_lqg, name="lqi-hold", schedule="smile_lqi", back_gain=0.1, clock="observation",
                attitude_from="engagement")
# the automatic designs of the env's vehicle file (lvgym.baselines.design.auto; the control extra): the rigid
# design, the flexible design and the LQG, made the same way for any vehicle (a launcher family's baselines)
register_policy("auto-gs-pid", "lvgym.baselines.designed:auto_policy", name="auto-gs-pid", kind="gs-pid")
register_policy("auto-gs-pid-flex", "lvgym.baselines.designed:auto_policy", name="auto-gs-pid-flex", kind="gs-pid-flex")
register_policy("auto-lqg", "lvgym.baselines.designed:auto_policy", name="auto-lqg", kind="lqg")
# the family's fixed baseline: the automatic design of the launcher family's nominal member on any vehicle
register_policy("fixed-gs-pid-flex", "lvgym.baselines.designed:fixed_policy", name="fixed-gs-pid-flex", kind="gs-pid-flex")
register_policy("fixed-lqg", "lvgym.baselines.designed:fixed_policy", name="fixed-lqg", kind="lqg")
# constrained linear MPC on lqg's rows (its plants, filters and cost) under the gimbal's angle and rate limits,
# OSQP per control period (lvgym.baselines.mpc, docs/mpc.md; needs the control extra)
register_policy("mpc", "lvgym.baselines.mpc:smile_mpc", name="mpc")
# incremental nonlinear dynamic inversion: the filtered angular acceleration and the measured actuator position
# synchronised, the control power of the design tables, a rate and attitude outer loop (lvgym.baselines.indi,
# lvgym.baselines.design.indi_design, docs/indi.md)
register_policy("indi", smile_indi, name="indi")
# active disturbance rejection control: an extended-state observer of the total disturbance per plane and a PD on
# its estimates (lvgym.baselines.eso, docs/eso.md)
register_policy("eso", "lvgym.baselines.eso:smile_eso", name="eso")

__all__ = ["AACParams", "AdaptiveAugmentingPolicy", "BangBangRollPolicy", "GainSchedule", "PIDLaw",
           "GainScheduledPIDPolicy", "PIDPolicy", "smile_aac", "smile_scheduled_pid", "smile_single_pid"]
