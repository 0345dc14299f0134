"""Along-path observations in the path fit: flights against an independent geometric
reference, the weighted CRPS, the scored kinds, and recovery of a known e_t from
synthetic surveyed paths (runout, flight heights, impact spacing, speeds)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.fit.holdout import crps_ensemble, crps_ensemble_many
from fieldkit.fit.path_along import flights, observed_along
from fieldkit.fit.path_fit import PathObjective, fit_paths
from fieldkit.fit.path_runs import PathRun, section_runs
from fieldkit.fit.synthetic_paths import section_model
from fieldkit.model.simulate import simulate
from fieldkit.path_observations import PathObservations
from fieldkit.physics.constants import G

ET = "materials.talus.e_t"


def test_flight_height_is_the_greatest_distance_from_the_chord():
    # A parabola launched at (0, 0) with (10, 5) m/s lands at t = 1.5 s; the
    # reference is the brute-force largest perpendicular distance to the chord.
    t = 1.5
    x1, z1 = 10.0 * t, 5.0 * t - 0.5 * G * t * t
    cols = {
        "rock": np.array([0, 0, 1]),
        "x_m": np.array([0.0, x1, 30.0]),
        "z_m": np.array([0.0, z1, -20.0]),
        "vf_x_mps": np.array([10.0, 8.0, 1.0]),
        "vf_z_mps": np.array([5.0, 3.0, 1.0]),
    }
    launch, spacing, height = flights(cols)
    # the flight from rock 0 to rock 1 is no flight; nor one that misses its end
    assert launch.tolist() == [0.0] and spacing.tolist() == [pytest.approx(x1)]
    s = np.linspace(0.0, t, 200_001)
    px, pz = 10.0 * s, 5.0 * s - 0.5 * G * s * s
    chord = np.array([x1, z1]) / np.hypot(x1, z1)
    distance = np.abs(px * chord[1] - pz * chord[0])
    assert height[0] == pytest.approx(distance.max(), rel=1e-6)


def test_weighted_crps_is_that_of_the_repeated_ensemble():
    rng = np.random.default_rng(2)
    x, y = rng.normal(size=57), rng.normal(size=9) * 2.0
    w = rng.integers(1, 5, size=57)
    expected = [crps_ensemble(np.repeat(x, w), v) for v in y]
    assert crps_ensemble_many(x, y, w) == pytest.approx(expected, abs=1e-12)
    assert crps_ensemble_many(x, y) == pytest.approx(
        [crps_ensemble(x, v) for v in y], abs=1e-12
    )


def _surveyed_paths(truth: dict[str, float], n: int, seed: int) -> list[PathRun]:
    """``n`` runs, each one rock of the true model on a 35 deg / 12 deg section
    (e_n 0.6: 5-8 impacts a rock), observed as a survey would: impacts' chainage,
    the height of the uninterrupted flight leaving each impact, the impact speed,
    and the stop."""
    base = section_model(120.0, 30.0, upper_deg=35.0)
    base = base.with_parameters({"materials.talus.e_n": 0.6})
    truth_model = base.with_parameters(truth)
    result = simulate(truth_model, n, np.random.default_rng(seed), record_impacts=True)
    frame = result.impact_table.frame
    release = float(base.seeder.x_m)
    runs = []
    for rock in range(n):
        f = frame[frame["path_id"] == str(rock)]
        launch, _, height = flights(
            {k: f[k].to_numpy() for k in ("x_m", "z_m", "vf_x_mps", "vf_z_mps")}
            | {"rock": np.zeros(len(f), int)}
        )
        x = f["x_m"].to_numpy(float)
        h = np.full(x.size, np.nan)
        h[np.searchsorted(x, launch)] = height
        runs.append(
            PathRun(
                str(rock),
                base,
                float(result.runout_x_m[rock]) - release,
                observations={
                    "along_chainage_m": x - release,
                    "along_hmax_normal_m": h,
                    "along_vi_mps": np.hypot(f["vi_x_mps"], f["vi_z_mps"]).to_numpy(),
                },
            )
        )
    return runs


def test_objective_scores_every_kind_and_is_deterministic_for_a_seed():
    runs = _surveyed_paths({ET: 0.7}, 3, seed=4)
    a = PathObjective(runs, [ET], 60, seed=1)
    b = PathObjective(runs, [ET], 60, seed=1)
    assert a.kinds == ["runout_m", "flight_height_m", "impact_spacing_m", "speed_mps"]
    assert a.strata[0].tolist() == [0, 1, 2]  # units are runs when there are >= 2
    scales = a.set_scales(np.array([0.8]))
    assert b.set_scales(np.array([0.8])) == scales
    assert a(np.array([0.8])) == pytest.approx(4.0)  # each kind 1 at the start
    assert a(np.array([0.75])) == b(np.array([0.75]))
    runout_only = PathObjective(runs, [ET], 60, seed=1, kinds=["runout_m"])
    assert runout_only.kinds == ["runout_m"] and not runout_only.along
    # runout only: the objective is the mean CRPS in metres, as before
    assert runout_only(np.array([0.75])) == pytest.approx(
        float(np.mean(runout_only.per_run(np.array([0.75]))))
    )
    with pytest.raises(ArgumentError, match="unknown kinds"):
        PathObjective(runs, [ET], 60, seed=1, kinds=["runout_m", "bounce"])


def test_one_path_is_resampled_by_its_points():
    runs = _surveyed_paths({ET: 0.7}, 1, seed=4)
    objective = PathObjective(runs, [ET], 40, seed=1)
    assert len(objective.strata) == 4  # one stratum per kind
    assert sum(s.size for s in objective.strata) == objective.units([0.8]).size


def test_release_point_starts_no_scar_to_scar_flight():
    obs = observed_along(
        PathRun(
            "a",
            section_model(100.0, 50.0),
            60.0,
            observations={
                "along_chainage_m": np.array([0.0, 12.0, 30.0, 60.0]),
                "along_hmax_normal_m": np.array([3.0, 1.0, 2.0, np.nan]),
            },
        )
    )
    assert obs.values["impact_spacing_m"].tolist() == [18.0, 30.0]
    assert obs.values["flight_height_m"].tolist() == [1.0, 2.0]
    assert obs.weight("flight_height_m").tolist() == [18.0, 30.0]
    assert obs.launch_range_m == (12.0, 60.0)


@pytest.mark.slow
@pytest.mark.parametrize("paths", [4, 12])
def test_recovers_e_t_from_surveyed_paths(paths):
    """Synthetic truth e_t = 0.7 (start 0.8): the fit on the runs' runouts, flight
    heights, impact spacing and speeds lands within 3 of its bootstrap SEs, at two
    sample sizes."""
    runs = _surveyed_paths({ET: 0.7}, paths, seed=11)
    result = fit_paths(
        runs, runs[0].model, [ET], rocks=100, seed=2, bootstrap=12, screen=4
    )
    value, se = result.value(ET), result.error(ET)
    assert abs(value - 0.7) < 3.0 * se + 0.005, (value, se)
    assert result.objective_optimum < result.objective_start
    assert set(result.kinds) == {
        "runout_m",
        "flight_height_m",
        "impact_spacing_m",
        "speed_mps",
    }


def test_section_runs_refuse_plan_observations_and_points_off_the_profile():
    model = section_model(100.0, 50.0)
    runs = pd.DataFrame(
        {
            "path_id": ["a"],
            "release_x_m": [0.0],
            "release_y_m": [0.0],
            "release_z_m": [10.0],
            "deposit_x_m": [500.0],
            "deposit_y_m": [0.0],
            "deposit_z_m": [0.0],
        }
    )
    with pytest.raises(InputFileError, match="plan grid"):
        section_runs(PathObservations(runs, source="x.csv"), model)
    with pytest.raises(InputFileError, match=r"deposit \(x = 500 m\) is off"):
        section_runs(PathObservations(runs, coordinates="section"), model)
