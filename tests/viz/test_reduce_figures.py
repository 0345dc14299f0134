"""Figures of a reduced survey: what they draw is the physics in the table."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fieldkit.physics.bodies import resolve_body
from fieldkit.physics.constants import G
from fieldkit.reduce.pipeline import ReduceOptions, reduce_survey
from fieldkit.survey import PointSet, Survey, TreeStrikes
from fieldkit.viz.energy_figure import energy_profile, plot_energy_partition
from fieldkit.viz.restitution_figure import plot_en_theta, plot_et_impacts
from fieldkit.viz.section_figure import _trees_xy, detail_row, flight_paths


@pytest.fixture(scope="module")
def reduced():
    x = np.array([0.0, 10.0, 22.0, 31.0, 45.0])
    z = np.array([60.0, 52.0, 44.0, 39.0, 30.0])
    points = PointSet(
        frame=pd.DataFrame({"point": list("abcde"), "x_m": x, "z_m": z}),
        source="p.csv",
    )
    trees = TreeStrikes(
        frame=pd.DataFrame(
            {
                "after_impact": ["b"],
                "horizontal_distance_m": [6.0],
                "strike_height_m": [1.5],
                "ground_z_m": [np.nan],
                "row": [2],
            }
        ),
        source="t.csv",
    )
    body = resolve_body(mass_kg=500.0, radius_m=0.36, gyration_m=0.295)
    survey = Survey(points, trees)
    return reduce_survey(survey, ReduceOptions("p", 30.0, body)), survey


def test_tree_strike_lies_on_the_drawn_flight(reduced):
    table, survey = reduced
    ((xt, ground, strike),) = _trees_xy(table, survey)
    assert xt == pytest.approx(16.0)
    assert ground == pytest.approx(52.0 - 8.0 * 6.0 / 12.0)  # on the chord b -> c
    xs, zs, source = flight_paths(table, n_samples=4001)[1]
    assert source == "tree"
    assert np.interp(xt, xs, zs) == pytest.approx(strike, abs=1e-4)


def test_detail_is_the_steepest_tree_defined_restitution(reduced):
    table, _ = reduced
    assert table.frame["point"].iloc[detail_row(table)] == "b"


def test_energy_profile_conserves_energy_in_flight(reduced):
    """PE + KE is constant along each flight (eq. 6.13 + KE, no drag)."""
    table, _ = reduced
    p = energy_profile(table, n_samples=20)
    total = p["pe_j"] + p["ke_j"]
    # Samples 0..19 are the source flight; no impact inside it.
    assert np.ptp(total[:20]) == pytest.approx(0.0, abs=1e-6 * total[0])
    np.testing.assert_allclose(p["head_m"], p["z_m"] + p["ke_j"] / (500.0 * G))


def test_energy_partition_without_mass_says_so():
    points = PointSet(
        frame=pd.DataFrame(
            {
                "point": ["a", "b", "c"],
                "x_m": [0.0, 10.0, 20.0],
                "z_m": [20.0, 14.0, 8.0],
            }
        ),
        source="p.csv",
    )
    table = reduce_survey(Survey(points, None), ReduceOptions("p", 30.0))
    fig = plot_energy_partition(table)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert any("no mass" in t for t in texts)


def test_en_theta_draws_the_requested_law():
    fig = plot_en_theta(
        [20.0, 40.0], [1.0, 0.5], material=["rock", "talus"], law=(10.0, 0.8)
    )
    line = [ln for ln in fig.axes[0].lines if len(ln.get_xdata()) > 10][0]
    t, e = line.get_xdata(), line.get_ydata()
    np.testing.assert_allclose(e, 10.0 * t**-0.8)
    assert {c.get_label() for c in fig.axes[0].collections} == {"rock (1)", "talus (1)"}


def test_et_legend_gives_the_mean_per_material():
    fig = plot_et_impacts([0.5, 0.7, 0.9], material=["rock", "rock", "talus"])
    labels = [ln.get_label() for ln in fig.axes[0].lines if ln.get_label()[0] != "_"]
    assert "rock: 2 impacts, mean $e_T$ = 0.60" in labels
    assert "talus: 1 impacts, mean $e_T$ = 0.90" in labels
