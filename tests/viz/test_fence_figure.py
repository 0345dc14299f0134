"""Fence figures (thesis Figs. 8.6-8.8, worked example 8B)."""

from __future__ import annotations

import pytest

from fieldkit.physics.fences import fence_energy_split
from fieldkit.physics.structure_forces import THESIS_STRUCTURES
from fieldkit.viz.fence_figure import (
    plot_fence,
    plot_fence_energy,
    plot_time_force,
    write_fence_figure,
)

SPLIT_8B = fence_energy_split(520.0, 0.35, 22.0, 18.0, 11.5, -11.6)


def test_time_force_curves_end_at_contact_time_and_peak_force():
    fig = plot_time_force(11440.0)
    _, ax_force = fig.axes
    ends = {
        line.get_color(): line.get_xydata()[-1]
        for line in ax_force.lines
        if line.get_linestyle() == "-"
    }
    # section 8.3.2: rigid 0.15 s / 151 kN, flexible 0.95 / 36.1, stiff 0.73 / 24.9
    assert ends["#d62728"] == pytest.approx([0.151, 151.3], abs=0.05)
    assert ends["#1f77b4"] == pytest.approx([0.950, 36.1], abs=0.05)
    assert ends["#2ca02c"] == pytest.approx([0.734, 24.9], abs=0.05)
    labels = [t.get_text() for t in ax_force.texts]
    assert labels == ["151.3 kN", "36.1 kN", "24.9 kN"]


def test_energy_panel_shows_8b_split():
    fig = plot_fence_energy(SPLIT_8B)
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert "136.2 kJ" in texts and "38.7 kJ" in texts
    assert any(t.startswith("97.5 kJ\n(72%)") for t in texts)
    assert "28%" in fig.axes[0].get_title()


def test_combined_figure_panels(tmp_path):
    assert len(plot_fence(11440.0, THESIS_STRUCTURES.values(), SPLIT_8B).axes) == 3
    assert len(plot_fence(11440.0).axes) == 2
    path = write_fence_figure(tmp_path / "f.png", 11440.0, split=SPLIT_8B)
    assert path.read_bytes()[:4] == b"\x89PNG"
