"""Thesis studies (chapter 6.1-6.2, reference case D): design of experiments with ANOVA and sensitivity
sweeps over L/D and thrust-to-weight of the parametric slender vehicle, run in parallel with a cache.

``python -m lvgym.studies doe|ld-sweep|tw-sweep`` (see :mod:`.__main__`); from Python
:func:`doe_study`, :func:`ld_sweep_study`, :func:`tw_sweep_study`. Findings: docs/studies.md.
"""

from ..errors import require

require("pandas", "studies", "lvgym.studies")
require("statsmodels", "studies", "lvgym.studies")

from .doe import anova, design  # noqa: E402  (after the check: the studies' modules import pandas)
from .responses import RESPONSES, RunSetup, responses, run_case  # noqa: E402
from .study import StudyResult, doe_study, ld_sweep_study, tw_sweep_study  # noqa: E402

__all__ = ["RESPONSES", "RunSetup", "StudyResult", "anova", "design", "doe_study", "ld_sweep_study",
           "responses", "run_case", "tw_sweep_study"]
