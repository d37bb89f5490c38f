"""The main job's steady figures read as a report's: every axis with its quantity and a unit,
no text outside the figure, and the marked values the computed ones (rated wind, C_P optimum)."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

import linearize
from mpc_wt import plotting

_UNIT = re.compile(r"\[[^\]]+\]")


@pytest.fixture()
def figures(monkeypatch):
    """Each figure the plotting functions save, kept open for inspection."""
    kept = []
    real = plotting.save_figure

    def keep(fig, path):
        fig.canvas.draw()
        kept.append(fig)
        return path
    monkeypatch.setattr(plotting, "save_figure", keep)
    yield kept
    import matplotlib.pyplot as plt
    for f in kept:
        plt.close(f)
    assert real is not None


def _check(fig) -> None:
    renderer = fig.canvas.get_renderer()
    box = fig.bbox
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            if label:
                assert _UNIT.search(label), f"axis label without a unit: {label!r}"
        assert ax.get_ylabel() or ax.get_label() == "<colorbar>", "an axis without a y label"
    from matplotlib.text import Text

    hidden = set()            # labels of ticks outside the view: matplotlib does not draw them
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                if not lo - 1e-9 * abs(hi - lo) <= tick.get_loc() <= hi + 1e-9 * abs(hi - lo):
                    hidden.update((id(tick.label1), id(tick.label2)))
    for text in fig.findobj(Text):
        if not text.get_visible() or not text.get_text() or id(text) in hidden:
            continue
        ext = text.get_window_extent(renderer)
        assert ext.x0 >= box.x0 - 1 and ext.x1 <= box.x1 + 1 and ext.y0 >= box.y0 - 1 \
            and ext.y1 <= box.y1 + 1, f"text outside the figure: {text.get_text()!r}"


def test_operating_schedule_marks_the_computed_rated_wind(figures, turbine, tmp_path) -> None:
    points = linearize.operating_schedule(turbine, np.arange(4.0, 25.0, 1.0))
    v_rated = linearize.rated_wind_speed(turbine)
    plotting.plot_operating_schedule(points, tmp_path / "s.png", rated_wind_mps=v_rated)
    fig = figures[-1]
    _check(fig)
    marks = {round(float(line.get_xdata()[0]), 6) for ax in fig.axes for line in ax.lines
             if line.get_linestyle() == ":"}
    assert marks == {round(v_rated, 6)}


def test_cp_surface_labels_the_computed_optimum(figures, turbine, tmp_path) -> None:
    tsr = np.arange(2.0, 16.0 + 1e-9, 0.5)
    pitch = np.arange(-2.0, 24.0 + 1e-9, 1.0)
    cp, _ = linearize.steady_coefficients(turbine, tsr[None, :], pitch[:, None])
    lam, cp_max = linearize.optimal_tsr(turbine, 0.0)
    plotting.plot_cp_surface(tsr, pitch, cp, tmp_path / "c.png", optimum=(lam, 0.0, cp_max))
    fig = figures[-1]
    _check(fig)
    legend = fig.axes[0].get_legend().get_texts()[0].get_text()
    assert f"{cp_max:.3f}" in legend and f"lambda {lam:.2f}" in legend
    bar = fig.axes[-1]
    lo, hi = bar.get_ylim()
    assert lo == 0.0 and cp_max <= hi <= cp_max + 0.02      # the scale ends at the surface's top
    ticks = [t for t in bar.get_yticks() if lo <= t <= hi]
    assert len(ticks) >= 4
    assert all(abs(t * 20 - round(t * 20)) < 1e-9 for t in ticks)     # round steps of 0.05
    assert math.isfinite(cp_max)


def test_comparison_shows_power_and_a_readable_window(figures, tmp_path) -> None:
    """Stacked panels with power first, the last 120 s of a 600 s run, each run's mean and
    std in the legend with its unit."""
    t = np.arange(0.0, 600.0, 0.05)
    cols = {"gen_power": 5e6 + 1e5 * np.sin(t), "rotor_speed": 1.2 + 0.01 * np.sin(t),
            "pitch_1": 0.1 + 0.01 * np.sin(t), "flap_moment_1": 6e6 + 1e6 * np.sin(t),
            "tower_base_fa_moment": 5e7 + 5e6 * np.sin(t)}
    plotting.plot_comparison([("a", t, cols), ("b", t, cols)], tmp_path / "c.png",
                             case="NREL 5-MW, 18 m/s, turbulence A, seed 1")
    fig = figures[-1]
    _check(fig)
    axes = fig.axes
    assert axes[0].get_ylabel() == "power [MW]" and len(axes) == 5
    lo, hi = axes[-1].get_xlim()
    assert hi - lo < 130.0
    assert "MW" in axes[0].get_legend().get_texts()[0].get_text()
    # the case in the title; the statistics' window said; each legend beside its panel
    title = fig._suptitle.get_text()
    assert title.startswith("NREL 5-MW, 18 m/s, turbulence A, seed 1;") and "0-599.95 s" in title
    renderer = fig.canvas.get_renderer()
    for ax in axes:
        assert ax.get_legend().get_window_extent(renderer).x0 >= ax.bbox.x1


def test_cs_ellipses_show_the_measures_with_units(figures, tmp_path) -> None:
    """Worked by hand: samples whose covariance is [[5, 2], [2, 2]] x 1e12 (N m, W) have
    eigenvalues 6 and 1 x 1e12 and major axis (2, 1): CS1 = sqrt(6) MN m = 2.45 MN m,
    CS2 = 1 MW, CS5 = atan(1/2) = 26.57 deg (Do et al. eqs 21, 25, 26); the legend gives
    each with its unit."""
    from mpc_wt.assessment.performance import cs_measures

    n = 4000
    ph = 2 * np.pi * np.arange(n) / n
    u, v = np.sqrt(2) * np.sin(ph), np.sqrt(2) * np.cos(ph)   # mean 0, variance 1, uncorrelated
    load = 1e6 * np.sqrt(5) * u + 4e7
    power = 1e6 * (2 / np.sqrt(5) * u + np.sqrt(1.2) * v) + 5e6
    cs = cs_measures(load, power)
    k = n / (n - 1)                                           # eq. 22 divides by N - 1
    assert cs.cs1 == pytest.approx(np.sqrt(6e12 * k), rel=1e-9)
    assert cs.cs2 == pytest.approx(np.sqrt(1e12 * k), rel=1e-9)
    assert cs.cs5 == pytest.approx(math.degrees(math.atan(0.5)), abs=1e-9)
    plotting.plot_cs_ellipses([("run", cs, load, power)], tmp_path / "cs.png")
    fig = figures[-1]
    _check(fig)
    text = fig.axes[0].get_legend().get_texts()[0].get_text()
    assert text == "run: CS1 2.45 MN m, CS2 1.000 MW, CS5 27 deg"


def test_the_main_jobs_assessment_figures(figures, tmp_path) -> None:
    """``cs_ellipses.png`` and ``psd_flap_moment_1.png`` as the main job makes them, from two
    runs: each axis with a unit, no text outside, the 1P mark at the rotor's frequency."""
    t = np.arange(0.0, 300.0, 0.0125)
    rng = np.random.default_rng(3)
    runs = []
    for name, a in (("one", 1.0), ("two", 0.6)):
        cols = {"tower_base_fa_moment": 3e7 + 8e6 * a * rng.standard_normal(t.size),
                "gen_power": 5e6 + 4e4 * rng.standard_normal(t.size),
                "flap_moment_1": 6e6 + 2e6 * a * np.sin(2 * np.pi * 0.2 * t),
                "rotor_speed": np.full(t.size, 2 * np.pi * 0.2)}
        runs.append((name, t, cols))
    made = plotting.assess_plots(runs, tmp_path)
    assert [p.split("/")[-1] for p in made] == ["cs_ellipses.png", "psd_flap_moment_1.png"]
    assert len(figures) == 2
    for fig in figures:
        _check(fig)
    marks = [txt.get_text() for txt in figures[1].axes[0].texts]
    assert marks == ["1P", "3P", "6P"]
    assert figures[1].axes[0].texts[0].get_position()[0] == pytest.approx(0.2)
    renderer = figures[1].canvas.get_renderer()
    ax = figures[1].axes[0]
    for txt in ax.texts:                          # the marks' labels inside the frame
        assert txt.get_window_extent(renderer).y1 <= ax.bbox.y1
    ax = figures[0].axes[0]                       # the ellipses' legend below the samples
    assert ax.get_legend().get_window_extent(figures[0].canvas.get_renderer()).y1 <= ax.bbox.y0
    made = plotting.assess_plots(runs, tmp_path, case="NREL 5-MW, 18 m/s, seed 1, 60-300 s")
    assert figures[-2].axes[0].get_title().endswith("NREL 5-MW, 18 m/s, seed 1, 60-300 s")
    assert figures[-1].axes[0].get_title() == "NREL 5-MW, 18 m/s, seed 1, 60-300 s"
