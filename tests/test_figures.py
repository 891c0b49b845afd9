"""The benchmark's figures (lvgym.benchmark.plots) from a small synthetic result list: each is a PNG of a
sensible size, each policy has one colour and marker in all of them and no two policies of a figure share a
colour, the legend sits outside the axes, and the degradation's ratio carries its paired interval."""

from __future__ import annotations

import io

import numpy as np
import pytest

from lvgym.benchmark import degradation, summarize, write_results
from lvgym.benchmark import plots as plots_mod
from lvgym.benchmark.headline import headline, others
from lvgym.benchmark.plots import SPARE_COLOURS, STYLES, plot_degradation, plot_headline, plot_rate_error, styles
from lvgym.benchmark.stats import ratio

#: a run like `make run`'s smile-v2 (11 policies) with a user's policy, and a slender suite whose design fails
SUITES = {
    "smile-v2": {"zero": 4.0, "gs-pid-flex": 1.0, "gs-pid-flex-quiet": 0.62, "aac-quiet": 0.6, "lqg": 0.63,
                 "lqg-front": 0.45, "gs-pd-relief": 0.7, "ppo-res-lqg": 0.57, "inversion-id": 0.5,
                 "inversion-id-smile": 0.34, "privileged": 0.18, "my-pd": 0.63},
    "slender-v2": {"zero": 4.0, "gs-pid-flex": 1.0, "privileged": 0.6},
}
KINDS = {"zero": "none", "privileged": "privileged", "ppo-res-lqg": "learned", "inversion-id": "learned",
         "inversion-id-smile": "learned", "my-pd": "other"}
UNFLYABLE = {"gs-pid-flex"}


def _records(seeds: int = 6) -> list[dict]:
    rng = np.random.default_rng(1)
    out = []
    for suite, means in SUITES.items():
        for model, scale in (("rigid", 1.0), ("nonrigid", 1.3)):
            for pol, mean in means.items():
                for seed in range(10_000, 10_000 + seeds):
                    failed = pol == "zero"
                    value = float(mean * scale * rng.uniform(0.8, 1.2))
                    flyable = pol not in UNFLYABLE
                    out.append({"suite": suite, "condition": f"{suite}/{model}", "group": suite, "model": model,
                                "policy": pol, "seed": seed, "failed": failed, "failure_reason": "x" if failed else "",
                                "flyable": flyable, "rate_error_rad": value, "score": value,
                                "score_v2": value if flyable else 6.7})
    return out


def _png(data: bytes) -> tuple[int, int]:
    """Width and height in pixels of a PNG file (its IHDR chunk)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR" and data[-8:-4] == b"IEND"
    w, h = np.frombuffer(data[16:24], dtype=">u4")
    return int(w), int(h)


@pytest.fixture(scope="module")
def results():
    recs = _records()
    summary = summarize(recs, metrics=("rate_error_rad", "score", "score_v2"))
    deg = degradation(summary, "score", records=recs) + degradation(summary, "rate_error_rad", records=recs)
    kinds = {p: KINDS.get(p, "classical") for means in SUITES.values() for p in means}
    reported = {s: [p for p in means if p != "my-pd"] for s, means in SUITES.items()}
    return recs, summary, deg, headline(summary, recs, kinds, reported), others(summary, recs, kinds, reported)


def test_every_figure_is_written_as_a_png_of_a_sensible_size(tmp_path, results):
    recs, summary, deg, rows, beside = results
    paths = write_results(tmp_path, recs, summary, deg, {}, headline=rows, others=beside)
    assert {"rate_error.png", "degradation.png", "headline.png", "headline_others.csv"} <= set(paths)
    for name in ("rate_error.png", "degradation.png", "headline.png"):
        data = paths[name].read_bytes()
        width, height = _png(data)
        assert 600 <= width <= 4000 and 300 <= height <= 4000, (name, width, height)
        assert 20_000 < len(data) < 3_000_000, (name, len(data))
    assert "headline.png" not in write_results(tmp_path / "v1", recs, summary, deg, {})   # no v2 headline: none


def test_one_colour_and_marker_per_policy_distinct_within_each_figure(monkeypatch, results):
    recs, summary, deg, rows, beside = results
    figures = []
    make = plots_mod._figure
    monkeypatch.setattr(plots_mod, "_figure", lambda w, h: figures.append(make(w, h)) or figures[-1])
    look = styles(r["policy"] for r in recs)
    used = [plot_rate_error(recs, io.BytesIO(), summary, look), plot_degradation(deg, io.BytesIO(), look),
            plot_headline(rows, io.BytesIO(), beside, look)]
    assert set(used[0]) == set(used[1]) == {p for means in SUITES.values() for p in means}
    assert set(used[2]) == {"lqg-front", "inversion-id-smile", "privileged", "my-pd"}     # slender: no classical
    for styles_of_figure in used:
        colours = [s.colour for s in styles_of_figure.values()]
        assert len(set(colours)) == len(colours)
        assert all(look[p] == s for p, s in styles_of_figure.items())                     # the same in every figure
    assert look["privileged"].colour == "#000000" and look["zero"].colour == "#7f7f7f"
    assert look["my-pd"].colour in SPARE_COLOURS
    for fig in figures:                                                                 # the legend beside the data
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        [legend] = fig.legends
        box = legend.get_window_extent(renderer)
        assert all(box.x0 >= ax.get_window_extent(renderer).x1 for ax in fig.axes)
    text = [t.get_text() for t in figures[2].axes[0].texts]
    assert text == ["no flyable classical", "no flyable classical"]                     # slender, both models


def test_the_colour_table():
    colours = [s.colour for s in STYLES.values()]
    assert len(set(colours)) == len(colours) and not set(colours) & set(SPARE_COLOURS)
    assert len({(s.colour, s.marker) for s in STYLES.values()}) == len(STYLES)
    mine = [f"user-{k}" for k in range(40)] + ["lqg", "zero"]
    a, b = styles(mine), styles(reversed(mine))
    assert a == b and a["lqg"] == STYLES["lqg"]                                        # deterministic, any order
    assert len({s.colour for s in a.values()}) == len(mine)                              # past the spare colours too
    assert styles(["my-pd"])["my-pd"] == styles(["my-pd", "lqg", "privileged"])["my-pd"]


def test_the_degradation_ratio_and_its_paired_interval(results):
    assert ratio([2.0, 4.0], [1.0, 2.0]) == pytest.approx((2.0, 2.0, 2.0))               # every resample: 2
    value, lo, hi = ratio([1.0, 3.0], [1.0, 1.0])                                      # resamples: 1, 2 or 3
    assert value == pytest.approx(2.0) and lo == pytest.approx(1.0) and hi == pytest.approx(3.0)
    assert all(np.isnan(ratio([1.0], [0.0])))
    _, summary, deg, _, _ = results
    [row] = [g for g in deg if g["metric"] == "score" and g["policy"] == "lqg" and g["suite"] == "smile-v2"]
    assert row["ratio_ci_low"] < row["mean_ratio"] < row["ratio_ci_high"]
    assert 1.0 < row["mean_ratio"] < 1.3 * 1.2 / 0.8
