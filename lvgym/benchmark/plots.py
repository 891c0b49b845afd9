"""The benchmark's figures (PNG, matplotlib on the Agg canvas): the rate error per suite, the rigid-to-non-rigid
degradation and protocol v2's headline.

Each policy has one colour and one marker in every figure (:func:`styles`): the registered policies a fixed
one each (:data:`STYLES`: the privileged reference black, the zero policy grey, each family of designs in
one hue), any other label (a user's policy, a training run) one of :data:`SPARE_COLOURS` chosen from its name,
never a colour another policy of the same figure has. Every mean is drawn with its 95 % interval, and the
legend sits to the right of the axes, outside the data.
"""

from __future__ import annotations

import colorsys
import math
import zlib
from collections.abc import Iterable, Mapping, Sequence
from typing import IO, Any, NamedTuple

from ..errors import require

__all__ = ["SPARE_COLOURS", "STYLES", "Style", "plot_degradation", "plot_headline", "plot_rate_error", "styles"]


class Style(NamedTuple):
    """A policy's look in every figure: ``colour`` (``#rrggbb``) and matplotlib ``marker``."""

    colour: str
    marker: str


#: the registered policies' colours and markers (no two alike)
STYLES: dict[str, Style] = {
    "privileged": Style("#000000", "*"), "zero": Style("#7f7f7f", "X"),
    "pid": Style("#aec7e8", "v"), "gs-pid": Style("#1f77b4", "v"),
    "pid-thesis": Style("#9edae5", "<"), "gs-pid-thesis": Style("#17becf", "<"),
    "gs-pid-flex": Style("#ffbb78", "o"), "gs-pid-flex-quiet": Style("#ff7f0e", "o"),
    "aac": Style("#c5b0d5", "D"), "aac-quiet": Style("#9467bd", "D"), "gs-pd-relief": Style("#8c564b", "P"),
    "lqg": Style("#2ca02c", "s"), "lqg-front": Style("#637939", "s"), "lqg-aw": Style("#b5cf6b", "s"),
    "mpc": Style("#bcbd22", "h"),
    "ppo": Style("#f7b6d2", "^"), "ppo-res-lqg": Style("#e377c2", "^"),
    "inversion-id": Style("#d62728", "d"), "inversion-id-smile": Style("#ff9896", "d"),
    "inversion-id-stratos": Style("#843c39", "d"),
    "auto-gs-pid": Style("#393b79", ">"), "auto-gs-pid-flex": Style("#6b6ecf", ">"), "auto-lqg": Style("#8ca252", ">"),
    "fixed-gs-pid-flex": Style("#bd9e39", "p"), "fixed-lqg": Style("#e7ba52", "p"),
}
#: the colours of other labels (none of :data:`STYLES`'); past them, hues spread by the golden ratio
SPARE_COLOURS = ("#7b4173", "#ce6dbd", "#5254a3", "#8c6d31", "#ad494a", "#e7969c", "#9c9ede", "#a55194",
                 "#cedb9c", "#e7cb94", "#de9ed6", "#c49c94", "#dbdb8d")
_SPARE_MARKERS = ("o", "s", "^", "D", "v", "P", "h", "p", "<", ">")
#: the mark of a failed episode in the rate-error figure
_FAILED = {"marker": "x", "color": "black", "ms": 5, "mew": 0.8, "ls": "none"}


def _spare(k: int) -> str:
    """The ``k``-th colour of the other labels: :data:`SPARE_COLOURS`, then golden-ratio hues."""
    if k < len(SPARE_COLOURS):
        return SPARE_COLOURS[k]
    hue = ((k - len(SPARE_COLOURS)) * 0.618033988749895) % 1.0
    r, g, b = colorsys.hsv_to_rgb(hue, 0.75, 0.55 + 0.3 * ((k // 7) % 2))
    return f"#{round(255 * r):02x}{round(255 * g):02x}{round(255 * b):02x}"


def styles(labels: Iterable[str]) -> dict[str, Style]:
    """Each label's :class:`Style`: a registered policy's from :data:`STYLES`; any other label (in sorted
    order) the first colour not yet taken in these labels, starting from one its name picks (CRC-32), so a
    label keeps its colour from run to run unless another label takes it; no two labels alike."""
    labels = list(dict.fromkeys(labels))
    out = {s: STYLES[s] for s in labels if s in STYLES}
    taken = {st.colour for st in out.values()}
    for label in sorted(s for s in labels if s not in STYLES):
        crc = zlib.crc32(label.encode())
        k = crc % len(SPARE_COLOURS)
        while _spare(k) in taken:
            k += 1
        out[label] = Style(_spare(k), _SPARE_MARKERS[crc % len(_SPARE_MARKERS)])
        taken.add(out[label].colour)
    return {s: out[s] for s in labels}


def _figure(width: float, height: float) -> Any:
    """A matplotlib Figure on the Agg canvas (no pyplot, no global backend change)."""
    require("matplotlib", "benchmark", "the benchmark's plots")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=110)
    FigureCanvasAgg(fig)
    return fig


def _handle(ax: Any, label: str, style: Style, **kw: Any) -> Any:
    """A legend entry of ``label`` in its colour and marker (drawn nowhere)."""
    (line,) = ax.plot([], [], ls="none", marker=style.marker, color=style.colour, mec="black", mew=0.5, ms=7,
                      label=label, **kw)
    return line


def _save(fig: Any, handles: Mapping[str, Any], write_to: IO[bytes]) -> None:
    """The figure with its legend to the right of the axes (outside the data), written as PNG."""
    if handles:
        fig.legend(list(handles.values()), list(handles), loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8,
                   frameon=False)
    fig.tight_layout()
    fig.savefig(write_to, format="png", bbox_inches="tight")


def _errorbar(ax: Any, x: float, mean: float, low: float, high: float, style: Style, size: float = 6) -> None:
    """``mean`` at ``x`` in the policy's marker with its interval ``[low, high]``."""
    if not math.isfinite(mean):
        return
    err = [[max(mean - low, 0.0)], [max(high - mean, 0.0)]] if math.isfinite(low) and math.isfinite(high) else None
    ax.errorbar([x], [mean], yerr=err, fmt=style.marker, color=style.colour, mec="black", mew=0.5, ms=size,
                ecolor="black", elinewidth=1.2, capsize=3.0, capthick=1.2, zorder=4)


def _log_if_positive(ax: Any, values: Iterable[float]) -> None:
    """A logarithmic y axis, its ticks in plain numbers, when ``values`` are positive and span over a factor 5."""
    from matplotlib.ticker import FuncFormatter

    v = [x for x in values if math.isfinite(x)]
    if v and min(v) > 0.0 and max(v) / min(v) > 5.0:
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{y:g}"))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda y, _: f"{y:g}" if f"{y:.0e}"[0] in "235" else ""))


def plot_rate_error(records: Sequence[Mapping[str, Any]], write_to: IO[bytes], summary: Sequence[Mapping[str, Any]] = (),
                    look: Mapping[str, Style] | None = None) -> dict[str, Style]:
    """Box plots of the cumulative rate error [rad], one panel per suite: a box per condition and policy in
    the policy's colour, its mean with the 95 % interval of ``summary`` (``rate_error_rad_mean``,
    ``_ci_low``, ``_ci_high``) in its marker, failed episodes (their error up to the failure) as black
    crosses. ``look``: the styles (default :func:`styles` of the records' policies). Returns the styles used."""
    suites = list(dict.fromkeys(r["suite"] for r in records))
    look = dict(look or styles(r["policy"] for r in records))
    means = {(r["suite"], r["condition"], r["policy"]): r for r in summary if "rate_error_rad_mean" in r}
    boxes = max(len({(r["condition"], r["policy"]) for r in records if r["suite"] == s}) for s in suites)
    fig = _figure(max(6.0, 0.32 * boxes + 2.0), 3.2 * len(suites))
    handles: dict[str, Any] = {}
    for k, suite in enumerate(suites):
        ax = fig.add_subplot(len(suites), 1, k + 1)
        recs = [r for r in records if r["suite"] == suite]
        conds = list(dict.fromkeys(r["condition"] for r in recs))
        pols = list(dict.fromkeys(r["policy"] for r in recs))
        width = 0.8 / len(pols)
        for j, pol in enumerate(pols):
            st = look[pol]
            data = [[r["rate_error_rad"] for r in recs if r["condition"] == c and r["policy"] == pol] for c in conds]
            pos = [i + (j - (len(pols) - 1) / 2) * width for i in range(len(conds))]
            bp = ax.boxplot(data, positions=pos, widths=width * 0.85, patch_artist=True, manage_ticks=False,
                            medianprops={"color": "black", "lw": 0.8}, whiskerprops={"color": st.colour},
                            capprops={"color": st.colour},
                            flierprops={"marker": ".", "ms": 3, "mfc": st.colour, "mec": st.colour})
            for box in bp["boxes"]:
                box.set_facecolor(st.colour)
                box.set_alpha(0.55)
            for x, c in zip(pos, conds):
                ys = [r["rate_error_rad"] for r in recs if r["condition"] == c and r["policy"] == pol and r["failed"]]
                ax.plot([x] * len(ys), ys, **_FAILED)
                m = means.get((suite, c, pol))
                if m is not None:
                    _errorbar(ax, x, *(float(m[f"rate_error_rad_{s}"]) for s in ("mean", "ci_low", "ci_high")),
                              st, size=5)
            handles.setdefault(pol, _handle(ax, pol, st))
        if any(r["failed"] for r in recs):
            handles.setdefault("failed episode (error up to the failure)", ax.plot([], [], **_FAILED)[0])
        _log_if_positive(ax, [r["rate_error_rad"] for r in recs])
        ax.set_xticks(range(len(conds)), [c.split("/")[-1] for c in conds])
        ax.set_title(f"{suite}: boxes of the episodes, mean with its 95 % interval", fontsize=9)
        ax.set_ylabel("pitch + yaw rate error [rad]", fontsize=8)
        ax.grid(alpha=0.3, axis="y")
    _save(fig, handles, write_to)
    return {p: look[p] for p in dict.fromkeys(r["policy"] for r in records)}


def plot_degradation(degradation: Sequence[Mapping[str, Any]], write_to: IO[bytes],
                     look: Mapping[str, Style] | None = None) -> dict[str, Style]:
    """Bars of the rigid-to-non-rigid ratio of the mean per suite and policy (1 = no change), one panel per
    metric of the rows (``score``, which counts failures, and ``rate_error_rad``), each bar with its paired
    95 % interval (``ratio_ci_low``, ``ratio_ci_high``, when the rows have them) and the policy's marker.
    Returns the styles used."""
    labels_of = {"score": "score", "rate_error_rad": "rate error"}
    metrics = list(dict.fromkeys(g.get("metric", "rate_error_rad") for g in degradation))
    pols_all = list(dict.fromkeys(g["policy"] for g in degradation))
    look = dict(look or styles(pols_all))
    groups = list(dict.fromkeys(f"{g['suite']}\n{g['condition'].split('/')[-1]}" for g in degradation))
    fig = _figure(max(6.0, 0.28 * len(groups) * max(1, len(pols_all)) + 2.0), 3.4 * max(1, len(metrics)))
    handles: dict[str, Any] = {}
    for k, metric in enumerate(metrics):
        rows = [g for g in degradation if g.get("metric", "rate_error_rad") == metric]
        ax = fig.add_subplot(len(metrics), 1, k + 1)
        labels = list(dict.fromkeys(f"{g['suite']}\n{g['condition'].split('/')[-1]}" for g in rows))
        pols = list(dict.fromkeys(g["policy"] for g in rows))
        width = 0.8 / max(1, len(pols))
        ratios = []
        for j, pol in enumerate(pols):
            st = look[pol]
            for g in (g for g in rows if g["policy"] == pol):
                x = labels.index(f"{g['suite']}\n{g['condition'].split('/')[-1]}") + (j - (len(pols) - 1) / 2) * width
                y = float(g["mean_ratio"])
                if not math.isfinite(y):
                    continue
                ratios += [y, float(g.get("ratio_ci_low", y)), float(g.get("ratio_ci_high", y))]
                ax.bar([x], [y - 1.0], width * 0.85, bottom=1.0, color=st.colour, alpha=0.75, edgecolor="black",
                       lw=0.4)                                      # from 1: no change
                _errorbar(ax, x, y, float(g.get("ratio_ci_low", math.nan)), float(g.get("ratio_ci_high", math.nan)),
                          st, size=5)
            handles.setdefault(pol, _handle(ax, pol, st))
        ax.axhline(1.0, color="k", lw=0.8)
        _log_if_positive(ax, ratios)
        ax.set_xticks(range(len(labels)), labels, fontsize=8)
        ax.set_ylabel(f"{labels_of.get(metric, metric)}, non-rigid / rigid", fontsize=8)
        ax.set_title(f"{labels_of.get(metric, metric)}: ratio of the means with its paired 95 % interval", fontsize=9)
        ax.grid(alpha=0.3, axis="y")
    _save(fig, handles, write_to)
    return {p: look[p] for p in pols_all}


#: the headline's kinds, left to right in each group
_KINDS = ("classical", "learned", "privileged")


def plot_headline(headline: Sequence[Mapping[str, Any]], write_to: IO[bytes], others: Sequence[Mapping[str, Any]] = (),
                  look: Mapping[str, Style] | None = None) -> dict[str, Style]:
    """Protocol v2's headline (:func:`~.headline.headline`): per suite and flight model, left to right, the
    best classical, the best learned and the privileged ``score_v2`` [rad] with their 95 % intervals, then
    each other policy flown (``others``: :func:`~.headline.others`); "none flyable" where a kind flew but no
    policy of it qualified; above a point, its failed or unflyable flights of the seeds when there are any.
    Returns the styles used."""
    keys = list(dict.fromkeys((h["suite"], h["condition"]) for h in headline))
    extra = {key: [o for o in others if (o["suite"], o["condition"]) == key] for key in keys}
    names = list(dict.fromkeys([h[k]["policy"] for h in headline for k in _KINDS if h.get(k)]
                               + [o["policy"] for o in others]))
    look = dict(look or styles(names))
    slots = len(_KINDS) + max([len(v) for v in extra.values()] or [0])
    fig = _figure(max(7.0, 0.45 * slots * len(keys) + 2.0), 4.4)
    ax = fig.add_subplot(1, 1, 1)
    width = 0.8 / slots
    handles: dict[str, Any] = {}
    values: list[float] = []
    for i, h in enumerate(headline):
        cells = [(k, h.get(k)) for k in _KINDS] + [(o["kind"], o) for o in extra[(h["suite"], h["condition"])]]
        for j, (kind, cell) in enumerate(cells):
            x = i + (j - (slots - 1) / 2) * width
            if not cell:
                if kind in h.get("none_flyable", "").split():
                    ax.annotate(f"no flyable {kind}", (x, 0.02), xycoords=("data", "axes fraction"), rotation=90,
                                fontsize=7, ha="center", va="bottom", color="0.3")
                continue
            st = look[cell["policy"]]
            _errorbar(ax, x, float(cell["mean"]), float(cell["low"]), float(cell["high"]), st)
            failed = round(float(cell["failed_or_unflyable"]) * int(cell["n"]))
            if failed:                                              # failed or unflyable of the seeds
                ax.annotate(f"{failed}/{cell['n']}", (x, float(cell["high"])), xytext=(0, 3),
                            textcoords="offset points", fontsize=7, ha="center", va="bottom", color="0.3")
            values += [float(cell["low"]), float(cell["high"])]
            label = f"{cell['policy']} ({kind})"
            handles.setdefault(label, _handle(ax, label, st))
        if i:
            ax.axvline(i - 0.5, color="0.85", lw=0.6)
    _log_if_positive(ax, values)
    where = [h["condition"].rsplit("/", 1)[0] if "/" in h["condition"] else h["suite"] for h in headline]
    ax.set_xticks(range(len(headline)), [f"{w}\n{h['model']}" for w, h in zip(where, headline)], fontsize=7)
    ax.set_xlim(-0.5, len(headline) - 0.5)
    ax.set_ylabel("score_v2 [rad], lower is better", fontsize=8)
    ax.set_xlabel("left to right in each: the best classical, the best learned, the privileged reference"
                  + (", the other policies" if others else "") + "; n/m: failed or unflyable of the seeds",
                  fontsize=8)
    ax.set_title("Headline (protocol v2): means with their 95 % intervals", fontsize=9)
    ax.grid(alpha=0.3, axis="y")
    _save(fig, handles, write_to)
    return {p: look[p] for p in names}

