"""Design of experiments of thesis 6.1: the 2^5 full factorial of Table 6.3 and its N-way ANOVA.

Factors and levels (Table 6.3, :data:`lvgym.vehicle.slender.TABLE_6_3`): length 8.5 / 7.5 m, diameter
0.3 / 0.26 m, slosh damping 0.8 / 0.5, mass flow 30 / 20 kg/s, fill 1 / 0.8. :func:`design` lists the
32 runs in the order of Table 6.2 (run 1 all high, run 2 fill low, ..., run 32 all low); the
``fraction`` design is the 4 runs of the Table 6.4 beams (length x diameter, the other factors high),
the smoke test of the pipeline.

:func:`anova` fits ``y ~ (main effects + two-factor interactions)`` to the coded factors (-1 low, +1
high) with statsmodels OLS and returns the table laid out like Tables 6.5-6.8 (rows in the thesis's
order, then Error and Total). In a two-level full factorial every effect has one degree of freedom and
the effects are orthogonal, so type I, II and III sums of squares coincide; the 16 error degrees of
freedom of the full design are the ten three-factor, five four-factor and one five-factor
interactions pooled (the simulation is deterministic: there is no replicate error). When the design
has too few runs for the interactions (the fraction), only main effects are fitted.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import pandas as pd

from lvgym.vehicle.slender import TABLE_6_3

__all__ = ["FACTOR_LABELS", "THESIS_ORDER", "TABLE_6_2_ORDER", "anova", "anova_all", "design",
           "significant"]

#: Table 6.2's column order (run 1 = all high, the last factor changes fastest)
TABLE_6_2_ORDER = ("length", "diameter", "slosh_damping", "mass_flow", "fill")
#: row order of Tables 6.5-6.8
THESIS_ORDER = ("length", "fill", "mass_flow", "slosh_damping", "diameter")
FACTOR_LABELS = {"length": "Length", "fill": "Fill ratio", "mass_flow": "Mass flow rate",
                 "slosh_damping": "Damping ratio", "diameter": "Diameter"}
_SHORT = {"length": "Length", "fill": "Fill", "mass_flow": "Mass flow", "slosh_damping": "Damping",
          "diameter": "Diameter"}
_CODE = {"length": "L", "fill": "F", "mass_flow": "M", "slosh_damping": "Z", "diameter": "D"}
COLUMNS = ("Sum of squares", "D.o.F", "Mean square", "F", "p")


def design(fraction: bool = False) -> pd.DataFrame:
    """The runs: columns ``run`` (1-based), the five factors (physical values) and their codes
    ``c_<factor>`` (+1 high, -1 low)."""
    rows = []
    if fraction:
        combos = [dict(zip(("length", "diameter"), lv)) | {"slosh_damping": 1, "mass_flow": 1, "fill": 1}
                  for lv in itertools.product((1, -1), repeat=2)]
    else:
        combos = [dict(zip(TABLE_6_2_ORDER, lv)) for lv in itertools.product((1, -1), repeat=5)]
    for i, code in enumerate(combos, start=1):
        row: dict[str, Any] = {"run": i}
        for f in TABLE_6_2_ORDER:
            hi, lo = TABLE_6_3[f]
            row[f] = hi if code[f] > 0 else lo
        row |= {f"c_{f}": float(code[f]) for f in TABLE_6_2_ORDER}
        rows.append(row)
    return pd.DataFrame(rows)


def _terms(table: pd.DataFrame) -> tuple[list[str], list[tuple[str, str]]]:
    """Factors that vary in ``table`` (thesis order) and the two-factor interactions the runs can carry."""
    mains = [f for f in THESIS_ORDER if table[f"c_{f}"].nunique() > 1]
    pairs = list(itertools.combinations(mains, 2))
    if len(table) - 1 - len(mains) - len(pairs) < 1:
        pairs = []
    return mains, pairs


def anova(table: pd.DataFrame, response: str) -> pd.DataFrame:
    """N-way ANOVA of ``response`` on the coded factors of ``table`` (a :func:`design` joined with
    results), main effects and two-factor interactions; index ``Parameter`` like Tables 6.5-6.8
    ("Length", "Length*Fill", ..., "Error", "Total"), columns :data:`COLUMNS`."""
    import statsmodels.formula.api as smf
    from statsmodels.stats.anova import anova_lm

    mains, pairs = _terms(table)
    data = pd.DataFrame({_CODE[f]: table[f"c_{f}"].astype(float) for f in mains})
    data["y"] = table[response].astype(float).to_numpy()
    rhs = " + ".join([_CODE[f] for f in mains] + [f"{_CODE[a]}:{_CODE[b]}" for a, b in pairs])
    fit = smf.ols(f"y ~ {rhs}", data=data).fit()
    a = anova_lm(fit, typ=2)
    rows = []
    for name in [*mains, *pairs]:
        key = _CODE[name] if isinstance(name, str) else f"{_CODE[name[0]]}:{_CODE[name[1]]}"
        label = FACTOR_LABELS[name] if isinstance(name, str) else f"{_SHORT[name[0]]}*{_SHORT[name[1]]}"
        ss, dof = float(a.loc[key, "sum_sq"]), float(a.loc[key, "df"])
        rows.append((label, ss, dof, ss / dof, float(a.loc[key, "F"]), float(a.loc[key, "PR(>F)"])))
    ss_e, df_e = float(a.loc["Residual", "sum_sq"]), float(a.loc["Residual", "df"])
    rows.append(("Error", ss_e, df_e, ss_e / df_e if df_e > 0 else np.nan, np.nan, np.nan))
    y = data["y"].to_numpy()
    rows.append(("Total", float(((y - y.mean()) ** 2).sum()), float(len(y) - 1), np.nan, np.nan, np.nan))
    out = pd.DataFrame(rows, columns=("Parameter",) + COLUMNS).set_index("Parameter")
    out["D.o.F"] = out["D.o.F"].astype(int)
    return out


def anova_all(table: pd.DataFrame, responses: tuple[str, ...]) -> dict[str, pd.DataFrame]:
    """:func:`anova` of every response."""
    return {r: anova(table, r) for r in responses}


def significant(table: pd.DataFrame, alpha: float = 0.05) -> list[tuple[str, float]]:
    """``(parameter, p)`` of the effects of an :func:`anova` table with ``p < alpha``, smallest p first."""
    eff = table.drop(index=["Error", "Total"])
    sig = eff[eff["p"] < alpha]["p"].sort_values()
    return [(str(k), float(v)) for k, v in sig.items()]
