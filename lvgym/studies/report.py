"""Results of the studies as files: a CSV table, PNG figures and a Markdown report, each written atomically.

Figures are named ``studies_<study>_<what>.png`` so that they can be copied into ``docs/figures`` as they
are. Units: responses as in :mod:`.responses` (eta in sqrt(kg) m, CG offsets and deflections in m,
totals times s).
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .doe import THESIS_ORDER, FACTOR_LABELS, significant
from .sweeps import thesis_deflection, thesis_frequency_hz

__all__ = ["RESPONSE_LABELS", "anova_markdown", "doe_figures", "markdown_table", "sweep_figures", "write_csv",
           "write_text"]

RESPONSE_LABELS = {"flex_total": "total flex [sqrt(kg) m s]", "flex_max": "maximum flex [sqrt(kg) m]",
                   "cg_total": "total C.G. offset [m s]", "cg_max": "maximum C.G. offset [m]",
                   "defl_total": "total deflection [m s]", "defl_max": "maximum deflection [m]"}


def _atomic(path: Path, write: Any, binary: bool = False) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def write_csv(table: pd.DataFrame, path: str | os.PathLike[str], index: bool = False) -> Path:
    """``table`` as CSV at ``path`` (atomically)."""
    return _atomic(Path(path), lambda tmp: table.to_csv(tmp, index=index))


def write_text(text: str, path: str | os.PathLike[str]) -> Path:
    """``text`` at ``path`` (atomically, UTF-8)."""
    return _atomic(Path(path), lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def _fmt(x: Any) -> str:
    if isinstance(x, (bool, np.bool_)):
        return "yes" if x else "no"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    if isinstance(x, (float, np.floating)):
        if not math.isfinite(x):
            return "-"
        return f"{x:.4g}" if abs(x) >= 1e-3 or x == 0 else f"{x:.4E}"
    return str(x)


def markdown_table(table: pd.DataFrame, index: bool = True) -> str:
    """A pipe table of ``table`` (4 significant digits; NaN as ``-``)."""
    cols = ([table.index.name or ""] if index else []) + [str(c) for c in table.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for key, row in table.iterrows():
        cells = ([str(key)] if index else []) + [_fmt(v) for v in row.to_numpy()]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def anova_markdown(name: str, table: pd.DataFrame) -> str:
    """One response's ANOVA table (like Tables 6.5-6.8) with the list of significant effects."""
    t = table.copy()
    t["p"] = [round(p, 4) if math.isfinite(p) else p for p in t["p"]]
    sig = significant(table)
    sig_text = ", ".join(f"{k} (p = {p:.2g})" for k, p in sig) or "none"
    return f"### ANOVA for {RESPONSE_LABELS.get(name, name)}\n\n{markdown_table(t)}\n\nSignificant (p < 0.05): {sig_text}\n"


def _save(fig: Any, path: Path) -> Path:
    import matplotlib.pyplot as plt

    out = _atomic(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"), binary=True)
    plt.close(fig)
    return out


def doe_figures(table: pd.DataFrame, out: str | os.PathLike[str], responses: Sequence[str]) -> list[Path]:
    """``studies_doe_runs.png`` (each response per run, like Figures 6.1-6.2) and
    ``studies_doe_effects.png`` (each response grouped by factor level, like Figures 6.3-6.4)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    n = len(responses)
    fig, axes = plt.subplots(n, 1, figsize=(9, 1.9 * n), sharex=True, constrained_layout=True)
    for ax, r in zip(np.atleast_1d(axes), responses):
        ax.bar(table["run"], table[r], color="tab:blue")
        ax.set_ylabel(RESPONSE_LABELS[r].replace(" [", "\n["), fontsize=8)
    np.atleast_1d(axes)[-1].set_xlabel("run (Table 6.2 order: 1 all high ... 32 all low)")
    fig.suptitle("DOE responses per run")
    paths = [_save(fig, out / "studies_doe_runs.png")]
    fig, axes = plt.subplots(n, len(THESIS_ORDER), figsize=(12, 1.9 * n), sharey="row", constrained_layout=True)
    axes = np.asarray(axes).reshape(n, len(THESIS_ORDER))
    for i, r in enumerate(responses):
        for j, f in enumerate(THESIS_ORDER):
            ax = axes[i, j]
            groups = [table.loc[table[f"c_{f}"] > 0, r], table.loc[table[f"c_{f}"] < 0, r]]
            ax.boxplot(groups, tick_labels=["high", "low"])
            if i == 0:
                ax.set_title(FACTOR_LABELS[f], fontsize=9)
            if j == 0:
                ax.set_ylabel(RESPONSE_LABELS[r].replace(" [", "\n["), fontsize=8)
    fig.suptitle("DOE responses by factor level (16 runs per box)")
    paths.append(_save(fig, out / "studies_doe_effects.png"))
    return paths


def sweep_figures(table: pd.DataFrame, out: str | os.PathLike[str], study: str) -> list[Path]:
    """``studies_<study>_responses.png``: flex, deflection and C.G. offset against L/D (``ld``) or the
    initial thrust-to-weight (``tw``); for ``ld`` also ``studies_ld_beam.png``, the beam analysis's
    first frequency and mode-1 deflection against the thesis's eq. 6.2-6.3."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    x, xlabel = ("ld", "L/D [-]") if study == "ld" else ("tw0", "initial thrust-to-weight [-]")
    t = table.sort_values(x)
    dep = t["departed"].astype(bool)
    fig, axes = plt.subplots(3, 2, figsize=(10, 8), sharex=True, constrained_layout=True)
    for ax, r in zip(axes.ravel(), ("flex_total", "flex_max", "defl_total", "defl_max", "cg_total", "cg_max")):
        ax.plot(t[x], t[r], ".-", ms=2, lw=0.8)
        if dep.any():
            ax.plot(t.loc[dep, x], t.loc[dep, r], "rx", ms=4, label="departed")
            ax.legend(fontsize=7)
        ax.set_ylabel(RESPONSE_LABELS[r].replace(" [", "\n["), fontsize=8)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel(xlabel)
    title = "L = 8.5 m, diameter 0.2-0.5 m" if study == "ld" else "L/D = 30, mass flow 10-30 kg/s"
    fig.suptitle(f"Sensitivity sweep: {title}, 12 s uncontrolled")
    paths = [_save(fig, out / f"studies_{study}_responses.png")]
    if study == "ld":
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.5), constrained_layout=True)
        d = t["diameter"].to_numpy()
        axes[0].plot(d, t["f1_hz"], label="lvgym beam, loaded vehicle at lift-off")
        axes[0].plot(d, thesis_frequency_hz(d), "--", label="thesis eq. 6.2 (ANSYS, bare tube)")
        axes[0].set_ylabel("first bending frequency [Hz]")
        axes[1].plot(d, t["phi1_max"], label="lvgym beam, loaded vehicle")
        axes[1].plot(d, thesis_deflection(d), "--", label="thesis eq. 6.3 (bare tube)")
        axes[1].set_ylabel("mode-1 max |phi| [1/sqrt(kg)]")
        for ax in axes:
            ax.set_xlabel("diameter [m]")
            ax.legend(fontsize=7)
            ax.grid(alpha=0.3)
        paths.append(_save(fig, out / "studies_ld_beam.png"))
    return paths
