"""The 3-D plan fit (fieldkit.fit.plan_fit) on a synthetic DEM with known truth."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.fit.plan_fit import (
    HOLDOUT_STREAM,
    PlanRun,
    fit_plan,
    parameters3d,
    plan_ensembles,
    plan_objective_terms,
    read_plan_runs,
    with_parameters3d,
)
from fieldkit.fit.tracked_extent import Extent, clip_model
from fieldkit.model.kernel3d import SLIDE_STEP_CELLS
from fieldkit.model.materials import Material
from fieldkit.model.model3d import Model3D, Seeder3D
from fieldkit.model.model_file import Body
from fieldkit.model.terrain import Terrain

SPLIT = Path(__file__).parents[1] / "data" / "tschamut2014" / "calibration_split"
SLOPE_DEG = 35.0
TOE_Y_M = 40.0
RELEASE_Y_M = 75.0
TRUE_FRICTION_DEG = 27.0


def bent_plane_model(friction_deg: float) -> Model3D:
    """A 35 deg plane dipping to -y onto a flat floor at y = 40 m (1 m cells,
    x 0-20 m, y 0-80 m); rocks released at rest on the plane slide down and stop
    on the floor at a distance set by the friction angle (about 7 m past the toe
    at 30 deg, 30 m at 20 deg)."""
    y = np.arange(81) + 0.5
    z = np.maximum(y - TOE_Y_M, 0.0) * math.tan(math.radians(SLOPE_DEG))
    grid = np.repeat(z[:, None], 21, axis=1)
    material = Material("ground", 0.3, 0.8, friction_deg, friction_deg_sd=2.0)
    return Model3D(
        terrain=Terrain(0.0, 0.0, 1.0, grid),
        materials={"ground": material},
        material_index=np.zeros(grid.shape, np.int64),
        effects={},
        body=Body(100.0, 0.2, 0.126),
        releases=np.array([[10.0, RELEASE_Y_M, 0.0]]),
        release_weights=np.ones(1),
        seeder=Seeder3D(),
    )


def observed_runs(model: Model3D, n: int = 10) -> list[PlanRun]:
    """``n`` runs released across the plane, each observed as one rock of the
    true model on a stream no fit uses."""
    runs = [
        PlanRun(
            f"r{i}",
            np.array([3.0 + 1.5 * i, RELEASE_Y_M - (i % 3)]),
            np.zeros(2),
            100.0,
            0.2,
        )
        for i in range(n)
    ]
    ens = plan_ensembles(model, runs, 1, 99, stream=7)
    return [
        PlanRun(r.run_id, r.release_xy, e[0], r.mass_kg, r.radius_m)
        for r, e in zip(runs, ens.deposits_xy, strict=True)
    ]


def test_the_truth_stops_on_the_floor_beyond_the_toe():
    truth = bent_plane_model(TRUE_FRICTION_DEG)
    runs = observed_runs(truth)
    deposits = np.array([r.deposit_xy for r in runs])
    assert np.all(deposits[:, 1] < TOE_Y_M)  # on the floor
    assert np.all(deposits[:, 1] > 0.0)  # not off the DEM
    np.testing.assert_allclose(
        deposits[:, 0], [r.release_xy[0] for r in runs], atol=1e-6
    )  # straight down the fall line


def test_fit_from_a_wrong_start_recovers_the_friction_angle():
    truth = bent_plane_model(TRUE_FRICTION_DEG)
    runs = observed_runs(truth)
    start = bent_plane_model(15.0)
    result = fit_plan(
        runs,
        start,
        ["materials.ground.friction_deg"],
        rocks=40,
        seed=1,
        bounds={"materials.ground.friction_deg": (5.0, 34.0)},
    )
    assert result.value("materials.ground.friction_deg") == pytest.approx(
        TRUE_FRICTION_DEG, abs=1.5
    )
    assert result.objective < 0.5 * result.objective_start
    assert result.model.materials["ground"].friction_deg == pytest.approx(
        result.value("materials.ground.friction_deg")
    )
    assert result.exited_share == 0.0
    assert "0.0 % (scored at their exit point)" in "\n".join(result.lines())


def test_the_objective_is_deterministic_for_a_seed():
    model = bent_plane_model(22.0)
    runs = observed_runs(bent_plane_model(TRUE_FRICTION_DEG), 4)
    a = plan_ensembles(model, runs, 30, 5)
    b = plan_ensembles(model, runs, 30, 5)
    for x, y in zip(a.deposits_xy, b.deposits_xy, strict=True):
        np.testing.assert_array_equal(x, y)
    other = plan_ensembles(model, runs, 30, 6)
    assert not np.array_equal(a.deposits_xy[0], other.deposits_xy[0])
    # common random numbers: a nearby friction angle moves every rock a little,
    # it does not redraw them (the same rocks, shorter runs)
    near = plan_ensembles(
        with_parameters3d(model, {"materials.ground.friction_deg": 22.5}), runs, 30, 5
    )
    for x, y in zip(a.deposits_xy, near.deposits_xy, strict=True):
        assert np.all(y[:, 1] >= x[:, 1] - 1e-9)  # more friction: stops higher up
    es, crps = plan_objective_terms(a.deposits_xy, runs)
    es2, crps2 = plan_objective_terms(b.deposits_xy, runs)
    np.testing.assert_array_equal(es, es2)
    np.testing.assert_array_equal(crps, crps2)


def test_held_out_streams_differ_from_the_calibration_streams():
    model = bent_plane_model(22.0)
    runs = observed_runs(bent_plane_model(TRUE_FRICTION_DEG), 3)
    cal = plan_ensembles(model, runs, 50, 1)
    held = plan_ensembles(model, runs, 50, 1, stream=HOLDOUT_STREAM)
    again = plan_ensembles(model, runs, 50, 1, stream=HOLDOUT_STREAM)
    for c, h, g in zip(
        cal.deposits_xy, held.deposits_xy, again.deposits_xy, strict=True
    ):
        assert not np.any(np.isin(h[:, 1], c[:, 1]))  # no rock reused
        np.testing.assert_array_equal(h, g)  # but reproducible
    # and no calibration seed's stream is the held-out one of another run
    assert not np.array_equal(
        held.deposits_xy[0],
        plan_ensembles(model, runs, 50, HOLDOUT_STREAM).deposits_xy[1],
    )


def test_with_parameters3d_sets_and_checks_values():
    model = bent_plane_model(20.0)
    assert parameters3d(model)["materials.ground.e_t"] == 0.8
    new = with_parameters3d(model, {"materials.ground.e_t": 0.6})
    assert new.materials["ground"].e_t == 0.6
    assert model.materials["ground"].e_t == 0.8  # the base model is not changed
    with pytest.raises(ArgumentError, match=r"materials.ground.e_t: must be in "):
        with_parameters3d(model, {"materials.ground.e_t": 3.0})
    with pytest.raises(ArgumentError, match="unknown parameter"):
        with_parameters3d(model, {"materials.rock.e_t": 0.5})
    with pytest.raises(ArgumentError, match="not parameters of the model"):
        fit_plan(observed_runs(model, 2), model, ["materials.rock.e_t"])


def test_read_plan_runs_joins_the_tschamut_split():
    runs = read_plan_runs(
        SPLIT / "holdout_release_points.csv", SPLIT / "holdout_observed_deposition.csv"
    )
    assert len(runs) == 18
    assert runs[0].run_id == "v006"
    np.testing.assert_allclose(runs[0].release_xy, [37.142, 241.62])
    np.testing.assert_allclose(runs[0].deposit_xy, [76.367, 156.24])
    assert (runs[0].mass_kg, runs[0].radius_m, runs[0].group) == (69.0, 0.176667, "1")


def test_read_plan_runs_refuses_bad_rows_in_one_line(tmp_path):
    rel = tmp_path / "rel.csv"
    dep = tmp_path / "dep.csv"
    rel.write_text(
        "trajectory_id,x_m,y_m,mass_kg,radius_m\na,1,2,50,0.2\nb,1,x,50,0.2\n"
    )
    dep.write_text("trajectory_id,x_m,y_m\na,5,6\nb,5,6\n")
    with pytest.raises(InputFileError) as err:
        read_plan_runs(rel, dep)
    assert str(err.value).count("\n") == 0
    assert "row 3" in str(err.value) and "y_m" in str(err.value)
    dep.write_text("trajectory_id,x_m\na,5\n")
    with pytest.raises(InputFileError, match="missing column"):
        read_plan_runs(rel, dep)
    dep.write_text("trajectory_id,x_m,y_m\na,5,6\n")
    rel.write_text("trajectory_id,x_m,y_m,mass_kg,radius_m\nb,1,2,50,0.2\n")
    with pytest.raises(InputFileError, match="b has no deposit"):
        read_plan_runs(rel, dep)


def test_fit_plan_refuses_one_rock():
    model = bent_plane_model(20.0)
    with pytest.raises(ArgumentError, match="two members"):
        fit_plan(
            observed_runs(model, 2), model, ["materials.ground.friction_deg"], rocks=1
        )


def test_a_release_off_the_dem_is_named_in_one_line():
    model = bent_plane_model(20.0)
    runs = [PlanRun("far", np.array([500.0, 75.0]), np.zeros(2), 100.0, 0.2)]
    with pytest.raises(ArgumentError) as err:
        fit_plan(runs, model, ["materials.ground.friction_deg"], rocks=5)
    assert "run far: release (x 500, y 75) is off the DEM" in str(err.value)
    assert "\n" not in str(err.value)


def test_rocks_leaving_the_tracked_extent_end_on_its_edge():
    """Without the extent every rock stops on the floor (y < 40 m); clipped to
    y >= 45 m (centres from 45.5 m) each ends where it crosses y = 45.5 m."""
    model = bent_plane_model(TRUE_FRICTION_DEG)
    runs = [PlanRun(f"r{i}", np.array([4.0 + 3 * i, 75.0]), np.zeros(2), 100.0, 0.2)
            for i in range(4)]  # fmt: skip
    free = plan_ensembles(model, runs, 20, 1)
    assert free.exited == 0
    assert max(float(e[:, 1].max()) for e in free.deposits_xy) < 40.0
    clipped, edge = clip_model(model, Extent(0.0, 45.0, 21.0, 81.0))
    assert edge == Extent(0.5, 45.5, 20.5, 80.5)
    ens = plan_ensembles(clipped, runs, 20, 1)
    assert ens.exited == 80
    y = np.concatenate([e[:, 1] for e in ens.deposits_xy])
    # a sliding rock's exit point is its last position on the surface: within
    # one slide step (kernel3d.SLIDE_STEP_CELLS = 0.1 cell) of the edge
    assert y.min() >= 45.5 and y.max() <= 45.5 + SLIDE_STEP_CELLS * 1.0
    with pytest.raises(ArgumentError, match="fewer than 2 x 2"):
        clip_model(model, Extent(0.0, 0.0, 1.2, 1.2))
