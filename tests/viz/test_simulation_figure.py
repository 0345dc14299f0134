"""Simulation figures: what is drawn, with units, at the right values."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.collections import PolyCollection

from fieldkit.viz.simulation_figure import (
    Measured,
    envelope_figure,
    point_histograms_figure,
    runout_figure,
    simulation_figure_names,
    trajectories_figure,
    write_simulation_figures,
)


def _vlines(ax) -> dict[str, float]:
    return {
        line.get_label(): float(line.get_xdata()[0])
        for line in ax.get_lines()
        if len(set(np.atleast_1d(line.get_xdata()))) == 1
    }


def test_trajectories_over_the_section(synthetic_simulation):
    result = synthetic_simulation(rocks=200)
    ax, low = trajectories_figure(result).axes[:2]
    fills = [c for c in ax.collections if isinstance(c, PolyCollection)]
    labels = [c.get_label() for c in fills]
    assert labels == ["material: rock", "material: talus"]
    assert fills[0].get_facecolor().tolist() != fills[1].get_facecolor().tolist()
    paths = [ln for ln in ax.get_lines() if ln.get_linewidth() == 0.9]
    assert len(paths) == 3 and len({ln.get_color() for ln in paths}) == 3
    assert (
        _vlines(ax)["analysis points (x = 70 m: speeds and energies read there)"]
        == 70.0
    )
    assert "(m)" in low.get_xlabel() and "(m)" in ax.get_ylabel()
    # below: the same paths as the centre's height above the ground
    heights = [ln for ln in low.get_lines() if ln.get_linewidth() == 0.9]
    for path, line in zip(result.trajectories, heights, strict=True):
        ground = result.model.profile.ground_z(path[:, 0])
        np.testing.assert_allclose(line.get_ydata(), path[:, 1] - ground)


def test_histograms_mark_percentiles_and_the_measured_value(synthetic_simulation):
    result = synthetic_simulation(rocks=500)
    point = result.analysis[0]
    fig = point_histograms_figure(
        result, 0, measured=Measured(x_m=70.0, speed_mps=11.0, ke_j=600e3)
    )
    speed_ax, ke_ax, total_ax = fig.axes[:3]
    speeds = point.speed_mps[point.crossed]

    def lines(ax):
        return {
            ln.get_label().split(" =")[0]: ln.get_xdata()[0] for ln in ax.get_lines()
        }

    for q in (50, 90, 95, 99):
        assert lines(speed_ax)[f"{q}th percentile"] == pytest.approx(
            np.percentile(speeds, q)
        )
    assert lines(speed_ax)["measured speed"] == 11.0
    # the measured (translational) KE is drawn on the translational KE histogram
    ke = lines(ke_ax)
    assert ke["measured translational KE"] == pytest.approx(600.0)  # kJ
    assert ke["50th percentile"] == pytest.approx(
        np.percentile(point.ke_j[point.crossed], 50) / 1e3
    )
    assert "translational" in ke_ax.get_xlabel()
    total = lines(total_ax)
    assert "measured translational KE" not in total
    assert total["50th percentile"] == pytest.approx(
        np.percentile(point.total_j[point.crossed], 50) / 1e3
    )
    assert "(m/s)" in speed_ax.get_xlabel() and "(kJ)" in total_ax.get_xlabel()
    # the legend gives the measured value's percentile among the crossing rocks
    below = (speeds < 11.0).sum() + 0.5 * (speeds == 11.0).sum()
    label = next(
        ln.get_label() for ln in speed_ax.get_lines() if "measured" in ln.get_label()
    )
    assert f"percentile {100 * below / speeds.size:.0f} ± " in label
    heights = sum(p.get_height() for p in speed_ax.patches)
    assert heights == point.crossed.sum()


def test_envelope_lines_are_the_per_bin_statistics(synthetic_simulation):
    result = synthetic_simulation(rocks=300)
    ax = envelope_figure(result, measured=[Measured(x_m=70, height_m=1.5)]).axes[0]
    by = {ln.get_label().split(" of ")[0]: ln for ln in ax.get_lines()}
    env = result.envelope()
    np.testing.assert_allclose(by["maximum"].get_ydata(), env["max"])
    np.testing.assert_allclose(by["95th percentile"].get_xdata(), env["x_m"])
    assert list(by["measured mean bounce height, at its x"].get_ydata()) == [1.5]
    assert "(m)" in ax.get_ylabel()


def test_runout_histogram_and_files(synthetic_simulation, tmp_path):
    result = synthetic_simulation(rocks=300)
    ax = runout_figure(result).axes[0]
    p50 = np.percentile(result.runout_x_m, 50)  # no rock capped here
    assert (result.state != 3).all()
    label = f"runout 50th percentile = {p50:.4g} m"  # no capped rock: not said
    assert _vlines(ax)[label] == pytest.approx(p50)
    assert not any("capped" in lab for lab in ax.get_legend_handles_labels()[1])
    paths = write_simulation_figures(tmp_path, result)
    assert [p.name for p in paths] == simulation_figure_names(result)
    assert all(p.read_bytes()[:4] == b"\x89PNG" for p in paths)


def test_runout_figure_draws_capped_rocks_apart(synthetic_simulation):
    """Capped rocks are their own final state, never 'stopped or left': their own
    bars and legend entry, and the runout percentiles leave them out."""
    result = synthetic_simulation(rocks=300)
    result.state = result.state.copy()
    result.state[:30] = 3  # MAX_IMPACTS
    ax = runout_figure(result).axes[0]
    labels = ax.get_legend_handles_labels()[1]
    capped = [lab for lab in labels if lab.startswith("capped (30 rocks): still")]
    assert len(capped) == 1 and "left out of the percentiles" in capped[0]
    ended = result.runout_x_m[30:]
    p50 = np.percentile(ended, 50)
    assert _vlines(ax)[f"runout 50th percentile = {p50:.4g} m"] == pytest.approx(p50)
    assert sum("left out" in lab for lab in labels) == 1  # said once
