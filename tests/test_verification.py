"""Thesis verification cases (chapter 4): every checked row of ``python -m lvgym.verify`` holds."""

import pytest

from lvgym.verify import ALL_CASES, table
from lvgym.verify.cases import CASE_E, energy_drift


@pytest.mark.parametrize("case", ALL_CASES, ids=lambda c: c.__name__)
def test_case(case):
    rows = case()
    assert rows, f"{case.__name__} produced no rows"
    failed = [r for r in rows if not r.passed]
    assert not failed, "\n" + table(failed)


def test_case_e_drift_regression():
    """Case E at 1 ms: 2.86e-5 of the internal energy was measured with the masses of CASE_E (the
    reference target of 1e-6 is not met there, see docs/verification.md); guard against growth."""
    assert CASE_E["m_slosh"] == (1.0, 2.0)
    assert energy_drift(1e-3) < 3.5e-5
    assert energy_drift(4e-4) < 1e-6
