"""Propagated uncertainties (e_n_sd, e_t_sd, vi_sd_mps) against simulated surveys.

The truth is a path whose impacts are known exactly. Surveying it many times with the
error model (independent normal errors of 0.5 m in plan and height) and reducing each
survey with the public reduction gives the real spread of e_n, e_t and vi; the
propagated standard uncertainty of the one exact survey must match it within the
sampling error of both estimates.
"""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.errors import ArgumentError, PhysicsError
from fieldkit.io.point_sets import point_set_from_section
from fieldkit.physics.bodies import resolve_body
from fieldkit.reduce.pipeline import (
    ReduceOptions,
    point_kinematics,
    reduce_path,
    reduce_survey,
)
from fieldkit.reduce.uncertainty import PositionError, propagate, sd_column
from fieldkit.survey import Survey

X = np.arange(0.0, 180.0, 20.0)
Z = 100.0 - 0.7 * X + 0.001 * X**2  # a slope flattening from 35° to 22°
NAMES = [f"P{i}" for i in range(len(X))]
BODY = resolve_body(mass_kg=1000.0, radius_m=0.5, gyration_m=0.3)
OUTPUTS = ("e_n", "e_t", "vi_mps")


def survey(x, z):
    return Survey(point_set_from_section(NAMES, x, z, source="truth.csv"), None)


def test_the_monte_carlo_repeats_the_reduction_itself():
    """point_kinematics (what each draw runs) gives what reduce_survey gives."""
    rng = np.random.default_rng(5)
    x, z = X + rng.normal(0, 0.5, X.size), Z + rng.normal(0, 0.5, Z.size)
    options = ReduceOptions("p", 25.0, BODY, position_error=None)
    full = reduce_survey(survey(x, z), options).frame
    fast = point_kinematics(survey(X, Z), options, x, z)
    for name in OUTPUTS:
        np.testing.assert_allclose(fast[name], full[name], rtol=1e-12)


def test_propagated_sd_matches_the_spread_of_simulated_surveys():
    draws = 400
    model = PositionError(0.5, 0.2, draws=draws, seed=11)
    options = ReduceOptions("truth", 25.0, BODY, position_error=model)
    reduction = reduce_path(survey(X, Z), options)
    assert reduction.uncertainty is not None and reduction.uncertainty.failed == 0
    table = reduction.table.frame

    # Survey the true path again and again with the same error, independently of the
    # propagation's own draws, and reduce each survey.
    rng = np.random.default_rng(99)
    runs = 400
    values = {name: [] for name in OUTPUTS}
    for _ in range(runs):
        x = X + rng.normal(0.0, 0.5, X.size)
        z = Z + rng.normal(0.0, 0.2, Z.size)
        out = point_kinematics(survey(X, Z), options, x, z)
        for name in OUTPUTS:
            values[name].append(out[name])
    impacts = slice(1, -1)
    for name in OUTPUTS:
        sample = np.vstack(values[name])[:, impacts]
        simulated = np.std(sample, axis=0, ddof=1)
        propagated = table[sd_column(name)].to_numpy(float)[impacts]
        assert np.all(np.isfinite(propagated)) and np.all(propagated > 0)
        # Standard error of a sample sd: sigma sqrt((kurtosis + 2) / 4N); four of
        # them, both estimates combined.
        centred = sample - sample.mean(axis=0)
        excess = np.maximum(
            (centred**4).mean(axis=0) / (centred**2).mean(axis=0) ** 2 - 3.0, 0.0
        )
        se = np.sqrt((excess + 2.0) / 4.0 * (1.0 / runs + 1.0 / draws))
        assert np.all(np.abs(propagated / simulated - 1.0) < 4.0 * se), (
            name,
            propagated,
            simulated,
        )
    # vi exists at the stopped point too; e_n there does not (no restitution)
    assert np.isfinite(table["vi_sd_mps"].iloc[-1])
    assert np.isnan(table["e_n_sd"].iloc[-1]) and np.isnan(table["e_n_sd"].iloc[0])


def test_the_error_scales_the_spread():
    """Halving the position error halves the spread (small errors: linear regime)."""
    options = ReduceOptions("p", 25.0, BODY)
    small = reduce_path(
        survey(X, Z),
        ReduceOptions("p", 25.0, BODY, position_error=PositionError(0.05, 0.05)),
    ).table.frame["e_n_sd"]
    smaller = reduce_path(
        survey(X, Z),
        ReduceOptions("p", 25.0, BODY, position_error=PositionError(0.025, 0.025)),
    ).table.frame["e_n_sd"]
    ratio = (small / smaller).to_numpy(float)[1:-1]
    np.testing.assert_allclose(ratio, 2.0, rtol=0.02)  # same seed, same draws
    assert options.position_error == PositionError()  # the default is on


def test_no_position_error_no_sd_columns():
    table = reduce_survey(
        survey(X, Z), ReduceOptions("p", 25.0, BODY, position_error=None)
    ).frame
    assert "e_n_sd" not in table and "vi_sd_mps" not in table


def test_same_seed_same_sd_and_the_model_is_stated():
    options = ReduceOptions("p", 25.0, BODY)
    a = reduce_path(survey(X, Z), options)
    b = reduce_path(survey(X, Z), options)
    np.testing.assert_array_equal(
        a.table.frame["e_n_sd"].to_numpy(), b.table.frame["e_n_sd"].to_numpy()
    )
    text = a.uncertainty.describe()
    assert "0.5 m in plan and 0.5 m in height" in text and "(the default)" in text
    assert "100 Monte Carlo draws, seed 2004" in text
    assert "e_n_sd, e_t_sd, vi_sd_mps" in text
    assert "(given)" in PositionError(0.1, 0.2).describe()


def test_draws_without_a_solution_are_counted_not_hidden():
    """Points 0.6 m apart in plan: a 0.5 m error often puts one behind the other.
    Such a draw leaves only that flight unsolved (it used to throw the whole draw
    away): the draw still counts for the other points, and how often each flight was
    unsolved is counted and said."""
    x = np.array([0.0, 10.0, 10.6, 20.0])
    z = np.array([30.0, 24.0, 23.5, 17.0])
    names = ["a", "b", "c", "d"]
    points = point_set_from_section(names, x, z, source="close.csv")
    reduction = reduce_path(Survey(points, None), ReduceOptions("p", 30.0, BODY))
    spread = reduction.uncertainty
    assert spread.failed == 0 and spread.used == spread.model.draws
    assert spread.unsolved[0] == 0 and spread.unsolved[3] == 0
    assert 0 < spread.unsolved[1] < spread.model.draws  # the flight b -> c
    assert "had no ballistic solution and only its values were left out" in (
        spread.describe()
    )
    # the first flight (a -> b) solves in every draw: b's impact sd uses all draws
    assert np.isfinite(reduction.table.frame["vi_sd_mps"][1])


def test_a_draw_every_flight_of_which_fails_is_left_out_and_counted():
    x, z = np.array([0.0, 0.3]), np.array([30.0, 30.0])

    def reduction(xs, zs):
        if xs[1] <= xs[0]:
            raise PhysicsError("behind", source="close.csv", where="point b")
        return {"k": np.full(2, zs[1] - zs[0])}

    spread = propagate(reduction, x, z, PositionError(0.5, 0.5), outputs=("k",))
    assert 0 < spread.failed < spread.model.draws
    assert spread.used + spread.failed == spread.model.draws
    assert "had no ballistic solution and were left out" in spread.describe()
    assert "close.csv" in spread.first_failure


def test_propagate_on_a_known_linear_case():
    """sd of a chord slope (z1 - z0)/L from two heights: sqrt(2) sigma / L."""

    def chord(x, z):
        return {"k": np.full(2, (z[1] - z[0]) / (x[1] - x[0]))}

    out = propagate(
        chord,
        [0.0, 50.0],
        [0.0, 0.0],
        PositionError(0.0, 0.2, draws=5000, seed=3),
        outputs=("k",),
    )
    expected = np.sqrt(2) * 0.2 / 50.0
    assert out.sd["k_sd"][0] == pytest.approx(expected, rel=4 / np.sqrt(2 * 4999))


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"position_sigma_m": -0.1}, "position_sigma_m"),
        ({"elevation_sigma_m": float("nan")}, "elevation_sigma_m"),
        ({"strike_height_sigma_m": float("inf")}, "strike_height_sigma_m"),
        ({"strike_height_sigma_m": -1.0}, "strike_height_sigma_m"),
        ({"draws": 3}, "draws"),
    ],
)
def test_bad_error_models(kwargs, name):
    with pytest.raises(ArgumentError, match=name):
        PositionError(**kwargs)


def test_sd_column_names_follow_the_contract():
    assert [sd_column(n) for n in ("e_n", "e_t", "vi_mps")] == [
        "e_n_sd",
        "e_t_sd",
        "vi_sd_mps",
    ]
