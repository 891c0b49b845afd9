"""The three studies end to end: build the runs, run them (cached, in parallel), analyse, write files.

Each study writes into its output directory: ``runs.csv`` (one row per run: factors, vehicle
descriptors, responses, wall time), the figures ``studies_*.png``, ``report.md`` and, for the DOE,
``anova_<response>.csv``; the run cache lives in ``<out>/cache``.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from .doe import anova_all, design, significant
from .report import anova_markdown, doe_figures, markdown_table, sweep_figures, write_csv, write_text
from .responses import RESPONSES, RunSetup
from .runs import case, run_cases
from .sweeps import ld_cases, peak, rise_ld, thesis_deflection, thesis_frequency_hz, tw_cases

__all__ = ["StudyResult", "doe_study", "ld_sweep_study", "tw_sweep_study"]

#: the thesis's four responses (section 6.1); the deflections in metres are ours
THESIS_RESPONSES = ("flex_total", "flex_max", "cg_total", "cg_max")


@dataclass
class StudyResult:
    """``table`` one row per run; ``ran`` / ``cached`` runs; ``wall_s`` [s]; ``files`` written;
    ``summary`` the numbers the report states; ``anova`` per response (DOE only)."""

    table: pd.DataFrame
    ran: int
    cached: int
    wall_s: float
    files: list[Path]
    summary: dict[str, Any]
    anova: dict[str, pd.DataFrame] = field(default_factory=dict)


def _setup_text(setup: RunSetup, ran: int, cached: int, wall: float, table: pd.DataFrame) -> str:
    s = setup.as_dict()
    return (f"Set-up: {s['t_end']:g} s, model {s['model']}, RK4 {s['physics_dt']:g} s, uncontrolled (gimbal 0), "
            f"{s['site']} at {s['elevation_deg']:g} deg off a {s['rail_length']:g} m rail, wind {s['wind']}, "
            f"aerodynamics '{s['aero']}' frozen at Mach {s['aero_mach']:g} (see lvgym/studies/responses.py).\n\n"
            f"{len(table)} runs: {ran} run now, {cached} from the cache; wall time {wall:.1f} s; one run "
            f"{table['wall_s'].median():.2f} s (median). Departed runs (total angle of attack above 20 deg): "
            f"{int(table['departed'].sum())}.\n")


def doe_study(out: str | os.PathLike[str], fraction: bool = False, executor: str = "local",
              workers: int | None = None, progress: bool = True, setup: RunSetup | None = None) -> StudyResult:
    """The 2^5 full factorial of Table 6.3 (or the 4-run ``fraction``), 12 s runs, ANOVA of every response."""
    start = time.perf_counter()
    setup = setup or RunSetup()
    out = Path(out)
    runs = design(fraction)
    cases = [case(r.length, r.diameter, r.fill, r.mass_flow, r.slosh_damping, setup) | {"run": int(r.run)}
             for r in runs.itertuples()]
    res = run_cases(cases, out / "cache", executor, workers, progress, desc="doe")
    codes = runs[["run"] + [c for c in runs.columns if c.startswith("c_")]]
    table = res.table.merge(codes, on="run")
    anovas = anova_all(table, RESPONSES)
    wall = time.perf_counter() - start
    files = [write_csv(table, out / "runs.csv")]
    files += [write_csv(a, out / f"anova_{r}.csv", index=True) for r, a in anovas.items()]
    files += doe_figures(table, out, THESIS_RESPONSES)
    summary = {r: significant(a) for r, a in anovas.items()}
    cols = ["run", "length", "diameter", "slosh_damping", "mass_flow", "fill", "f1_hz", "tw0", "t_burnout",
            *RESPONSES]
    text = [f"# Design of experiments ({'4-run fraction' if fraction else '2^5 full factorial'}, thesis 6.1)\n",
            _setup_text(setup, res.ran, res.cached, wall, table), "## Runs\n", markdown_table(table[cols], False),
            "\n## ANOVA (main effects and two-factor interactions, coded factors)\n"]
    text += [anova_markdown(r, anovas[r]) for r in RESPONSES]
    files.append(write_text("\n".join(text), out / "report.md"))
    return StudyResult(table, res.ran, res.cached, wall, files, summary, anovas)


def _sweep(kind: str, out: Path, cases: list[dict], executor: str, workers: int | None, progress: bool,
           setup: RunSetup) -> StudyResult:
    start = time.perf_counter()
    res = run_cases(cases, out / "cache", executor, workers, progress, desc=f"{kind}-sweep")
    table = res.table
    wall = time.perf_counter() - start
    x = "ld" if kind == "ld" else "tw0"
    summary: dict[str, Any] = {f"peak_{r}": peak(table, x, r) for r in RESPONSES}
    if kind == "ld":
        summary |= {f"rise_ld_{r}": rise_ld(table, r) for r in ("flex_total", "flex_max", "defl_total", "defl_max")}
    files = [write_csv(table, out / "runs.csv")] + sweep_figures(table, out, kind)
    name = "L/D" if kind == "ld" else "initial thrust-to-weight"
    text = [f"# Sensitivity sweep over {name} (thesis 6.2)\n", _setup_text(setup, res.ran, res.cached, wall, table),
            f"## Peaks (over runs that did not depart)\n",
            markdown_table(pd.DataFrame([(r, *summary[f"peak_{r}"]) for r in RESPONSES],
                                        columns=["response", f"at {x}", "value"]), False)]
    if kind == "ld":
        text += ["\n## Where flex rises: smallest L/D from which the response stays above half its peak\n",
                 markdown_table(pd.DataFrame([(r, summary[f"rise_ld_{r}"]) for r in
                                              ("flex_total", "flex_max", "defl_total", "defl_max")],
                                             columns=["response", "L/D"]), False)]
        beam = table.iloc[:: max(1, len(table) // 6)][["diameter", "ld", "f1_hz", "phi1_max"]].copy()
        beam["thesis f1 eq 6.2 [Hz]"] = thesis_frequency_hz(beam["diameter"])
        beam["thesis phi eq 6.3"] = thesis_deflection(beam["diameter"])
        text += ["\n## Beam analysis against the thesis's fits\n", markdown_table(beam, False)]
    sample = table.iloc[:: max(1, len(table) // 12)]
    cols = ["diameter", "mass_flow", "ld", "tw0", "mass0", "f1_hz", "slosh_mass0", "t_burnout", *RESPONSES]
    text += ["\n## Every n-th run\n", markdown_table(sample[cols], False)]
    files.append(write_text("\n".join(text), out / "report.md"))
    return StudyResult(table, res.ran, res.cached, wall, files, summary)


def ld_sweep_study(out: str | os.PathLike[str], step: float = 0.001, executor: str = "local",
                   workers: int | None = None, progress: bool = True, setup: RunSetup | None = None) -> StudyResult:
    """Diameter 0.2 to 0.5 m every ``step`` [m] at L = 8.5 m (L/D 42.5 to 17)."""
    setup = setup or RunSetup()
    return _sweep("ld", Path(out), ld_cases(step, setup), executor, workers, progress, setup)


def tw_sweep_study(out: str | os.PathLike[str], step: float = 0.1, executor: str = "local",
                   workers: int | None = None, progress: bool = True, setup: RunSetup | None = None) -> StudyResult:
    """Mass flow 10 to 30 kg/s every ``step`` [kg/s] at L/D 30."""
    setup = setup or RunSetup()
    return _sweep("tw", Path(out), tw_cases(step, setup), executor, workers, progress, setup)
