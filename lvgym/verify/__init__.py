"""Verification of the dynamics core against the thesis's cases (``python -m lvgym.verify``)."""

from .cases import ALL_CASES
from .report import Check, table

__all__ = ["ALL_CASES", "Check", "table", "run_all"]


def run_all() -> list[Check]:
    """Run every case and return all rows."""
    return [row for case in ALL_CASES for row in case()]
