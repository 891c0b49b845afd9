"""Result rows of the verification cases and their table."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Check:
    """One verified quantity: ``status`` is PASS/FAIL when ``tol`` is set, otherwise INFO.

    ``error`` is ``|got - expected|`` (or ``got`` itself for a drift whose expected value is 0);
    ``relative`` says whether ``tol`` bounds ``error / |expected|``.
    """

    case: str
    quantity: str
    expected: float
    got: float
    unit: str = ""
    tol: float | None = None
    relative: bool = False
    note: str = ""

    @property
    def error(self) -> float:
        err = abs(self.got - self.expected)
        return err / abs(self.expected) if self.relative and self.expected != 0 else err

    @property
    def status(self) -> str:
        if self.tol is None:
            return "INFO"
        return "PASS" if self.error <= self.tol else "FAIL"

    @property
    def passed(self) -> bool:
        return self.status != "FAIL"


def _fmt(v: float) -> str:
    return f"{v:.6g}" if abs(v) < 1e5 or v == 0 else f"{v:.6e}"


def table(checks: list[Check]) -> str:
    """Markdown table of the checks."""
    rows = ["| case | quantity | expected | got | error | tolerance | status |",
            "|---|---|---|---|---|---|---|"]
    for c in checks:
        tol = "" if c.tol is None else f"{c.tol:.0e}" + (" rel" if c.relative else f" {c.unit}")
        unit = f" {c.unit}" if c.unit else ""
        err = f"{c.error:.2e}" + ("" if c.relative else unit)
        rows.append(f"| {c.case} | {c.quantity} | {_fmt(c.expected)}{unit} | {_fmt(c.got)}{unit} | "
                    f"{err} | {tol} | {c.status} |")
    notes = [f"- {c.case}, {c.quantity}: {c.note}" for c in checks if c.note]
    return "\n".join(rows + ([""] + notes if notes else []))
