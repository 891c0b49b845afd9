"""PID and gain-scheduled PID TVC baselines (thesis 6.3), adaptive augmenting control on them (SLS-style,
docs/adaptive-control.md) and a bang-bang roll controller (thesis 5.3).

Every controller implements the benchmark's policy interface (:class:`lvgym.benchmark.Policy`):
``reset()`` and ``act(observation, info) -> action``. ``lvgym design pid --vehicle smile``
tunes a gain schedule on the rigid linearisation (into ``results/schedules/``; ``--overwrite`` replaces
the shipped one in ``schedules/``); ``python -m experiments.control_study.study`` runs the
thesis's control study (docs/control-study.md).
"""

from .aac import AACParams, AdaptiveAugmentingPolicy, smile_aac
from .bangbang import BangBangRollPolicy
from .pid import (DiscretePID, GainSchedule, GainScheduledPIDPolicy, PIDPolicy, smile_scheduled_pid,
                  smile_single_pid)

__all__ = ["AACParams", "AdaptiveAugmentingPolicy", "BangBangRollPolicy", "DiscretePID", "GainSchedule",
           "GainScheduledPIDPolicy", "PIDPolicy", "smile_aac", "smile_scheduled_pid", "smile_single_pid"]
