"""path_runs: every observed run on its own DEM section (fieldkit.fit.path_sections).

Analytic cases on a plane tilted along x (z = -x / 2): the steepest descent is the
straight line along +x at the release's y, so chainages and lateral offsets are
known exactly; the Tschamut calibration split shows the section endings and how
far the sections miss the deposits.
"""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fieldkit.errors import ArgumentError, FieldkitError, InputFileError
from fieldkit.fit.path_runs import simulated_runouts
from fieldkit.fit.path_sections import nearest_on_section, path_runs, path_sections
from fieldkit.io.dem import DemGrid, read_dem
from fieldkit.io.path_observations import read_release_deposit
from fieldkit.model.model_file import model_from_dict, read_model
from fieldkit.model.results import EXITED_DOWNSLOPE
from fieldkit.path_observations import PathObservations

ROOT = Path(__file__).resolve().parents[2]
SPLIT = ROOT / "tests" / "data" / "tschamut2014" / "calibration_split"
TERRAIN = ROOT / "tests" / "data" / "tschamut2014" / "terrain.asc"
BASE = ROOT / "examples" / "tschamut" / "model_base.json"
SLOPE = 0.5  # the plane falls 0.5 m per m toward +x


def plane() -> DemGrid:
    """z = -SLOPE * x on x 5..205 m, y 5..105 m (cell centres, 10 m cells)."""
    x = 5.0 + 10.0 * np.arange(21)
    return DemGrid.from_corner(
        np.add.outer(np.zeros(11), -SLOPE * x),
        x_left_m=0,
        y_top_m=110,
        cellsize_m=10,
        source="plane.asc",
    )


def base_model(**materials):
    mats = materials or {"meadow": {"e_n": 0.3, "e_t": 0.8, "friction_deg": 30}}
    return model_from_dict(
        {
            "profile": {"x_m": [0, 1], "z_m": [1, 0], "material": [next(iter(mats))]},
            "materials": mats,
            "body": {"mass_kg": 50.0, "radius_m": 0.2},
            "seeder": {"x_m": 0, "z_m": 1, "vx_mps": 0.7, "vz_mps": -0.1},
        }
    )


def observations(**columns) -> PathObservations:
    data = {
        "path_id": ["a"],
        "release_x_m": [15.0],
        "release_y_m": [55.0],
        "release_z_m": [-SLOPE * 15.0 + 0.25],
        "deposit_x_m": [115.0],
        "deposit_y_m": [52.0],
        "deposit_z_m": [-SLOPE * 115.0 + 0.2],
    }
    data.update({k: [v] for k, v in columns.items()})
    return PathObservations(pd.DataFrame(data), source="releases.csv")


def test_descent_on_a_tilted_plane_is_straight_and_offsets_are_exact():
    obs = observations(
        release_vx_mps=3.0, release_vy_mps=4.0, release_vz_mps=-1.0,
        mass_kg=40.0, radius_m=0.16, group="4",
    )  # fmt: skip
    (run,) = path_runs(obs, plane(), base_model())
    profile = run.model.profile
    # straight along +x from the release to the grid's last cell centre (x = 205);
    # upslope of it the ground back to the grid's first cell centre (x = 5: 10 m,
    # less than the two cells asked for)
    assert profile.x_m[0] == pytest.approx(-10.0, abs=1e-6)
    assert profile.x_m[-1] == pytest.approx(190.0, abs=1e-6)
    np.testing.assert_allclose(run.observations["section_y_m"], 55.0, atol=1e-9)
    np.testing.assert_allclose(profile.z_m, -SLOPE * (15.0 + profile.x_m), atol=1e-9)
    # the deposit 100 m down the line and 3 m beside it
    assert run.observed_runout_m == pytest.approx(100.0, abs=1e-9)
    assert run.lateral_offset_m == pytest.approx(3.0, abs=1e-9)
    # seeder: chainage 0, 0.25 m above the plane, plan velocity (3, 4) on +x -> 3
    assert run.model.seeder.x_m == 0.0
    assert run.model.seeder.z_m - float(profile.ground_z(0.0)) == pytest.approx(
        0.25, abs=1e-9
    )
    assert run.model.seeder.vx_mps == pytest.approx(3.0)
    assert run.model.seeder.vz_mps == pytest.approx(-1.0)
    # body: the run's block, a solid sphere's gyration
    assert run.model.body.mass_kg == 40.0
    assert run.model.body.radius_m == 0.16
    assert run.model.body.gyration_m == pytest.approx(math.sqrt(0.4) * 0.16)
    assert run.group == "4"
    assert set(run.model.profile.material) == {"meadow"}


def test_a_deposit_on_the_line_has_its_distance_and_no_offset():
    obs = observations(deposit_x_m=72.5, deposit_y_m=55.0)
    (run,) = path_runs(obs, plane(), base_model())
    assert run.observed_runout_m == pytest.approx(57.5, abs=1e-9)
    assert run.lateral_offset_m == pytest.approx(0.0, abs=1e-9)


def test_release_deposit_section_runs_through_the_deposit_to_the_grid_edge():
    # deposit 60 m along x and 80 m along... y can only fall 50 m: use 30, 40
    obs = observations(deposit_x_m=45.0, deposit_y_m=95.0, deposit_z_m=-30.0)
    (run,) = path_runs(obs, plane(), base_model(), section="release-deposit")
    assert run.observed_runout_m == pytest.approx(50.0, abs=1e-9)
    assert run.lateral_offset_m == pytest.approx(0.0, abs=1e-9)
    # from (15, 55) along (0.6, 0.8) the line meets y = 105 after 62.5 m
    assert run.model.profile.x_m[-1] == pytest.approx(62.5, abs=1e-6)
    # on this section the ground falls 0.5 * 0.6 = 0.3 m per m of chainage
    np.testing.assert_allclose(
        np.diff(run.model.profile.z_m) / np.diff(run.model.profile.x_m), -0.3,
        atol=1e-9,
    )  # fmt: skip
    # the plan velocity is projected on (0.6, 0.8): without one, the base seeder's
    assert run.model.seeder.vx_mps == 0.7


def test_without_a_release_velocity_or_block_the_base_model_is_kept():
    (run,) = path_runs(observations(), plane(), base_model())
    assert (run.model.seeder.vx_mps, run.model.seeder.vz_mps) == (0.7, -0.1)
    assert run.model.body == base_model().body


def test_the_release_height_is_at_least_the_block_radius():
    obs = observations(release_z_m=-SLOPE * 15.0 - 0.3, radius_m=0.16)
    (run,) = path_runs(obs, plane(), base_model())
    assert run.model.seeder.z_m - float(
        run.model.profile.ground_z(0.0)
    ) == pytest.approx(0.16)


def test_along_path_points_get_chainage_and_offset():
    obs = observations()
    along = pd.DataFrame(
        {"path_id": ["a", "a"], "point": ["1", "2"], "x_m": [35.0, 65.0],
         "y_m": [55.0, 58.0], "z_m": [-17.5, -32.5], "vi_mps": [5.0, 7.0]}
    )  # fmt: skip
    obs = PathObservations(obs.runs, along, source="releases.csv")
    (run,) = path_runs(obs, plane(), base_model())
    np.testing.assert_allclose(run.observations["along_chainage_m"], [20.0, 50.0])
    np.testing.assert_allclose(run.observations["along_offset_m"], [0.0, 3.0])
    np.testing.assert_allclose(run.observations["along_vi_mps"], [5.0, 7.0])


def test_nearest_on_section_at_a_corner():
    from fieldkit.model.dem_profile import Section

    s = Section(
        np.array([0.0, 10.0, 20.0]), np.array([2.0, 1.0, 0.0]),
        np.array([0.0, 10.0, 10.0]), np.array([0.0, 0.0, 10.0]), ("g", "g"),
    )  # fmt: skip
    assert nearest_on_section(s, 13.0, -4.0) == (10.0, 5.0)
    assert nearest_on_section(s, 12.0, 6.0) == (16.0, 2.0)


def test_a_rock_leaving_the_section_has_the_section_length_as_runout():
    """What the simulator does at the end of a section (path_sections docstring)."""
    smooth = {"meadow": {"e_n": 0.1, "e_t": 0.95, "friction_deg": 1.0}}
    (run,) = path_runs(observations(), plane(), base_model(**smooth))
    runouts = simulated_runouts(run, run.model, 20, seed=1, index=0)
    from fieldkit.model.simulate import simulate

    result = simulate(run.model, 20, np.random.default_rng([1, 0]))
    assert (result.state == EXITED_DOWNSLOPE).all()
    np.testing.assert_allclose(runouts, run.model.profile.x_m[-1], atol=1e-9)


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (
            {"release_x_m": 300.0},
            "releases.csv: a: the release (x, y) = (300, 55) has no ground in the "
            "DEM plane.asc",
        ),
        (
            {"release_z_m": -SLOPE * 15.0 - 0.6},
            "releases.csv: a: the release (z = -8.10 m) is 0.60 m below the ground "
            "of the DEM plane.asc (z = -7.50 m; at most 0.5 m accepted)",
        ),
        (
            {"release_z_m": -9.0, "release_ground_z_m": -8.0},
            "releases.csv: a: the release (z = -9.00 m) is 1.00 m below its "
            "release_ground_z_m",
        ),
        (
            {"deposit_z_m": 0.0},
            "releases.csv: a: the deposit (z = 0.00 m) is higher than its release "
            "(z = -7.25 m): upslope",
        ),
    ],
)
def test_bad_runs_give_one_line_naming_the_file_and_the_run(change, expected):
    with pytest.raises(InputFileError) as info:
        path_runs(observations(**change), plane(), base_model())
    assert str(info.value).startswith(expected)
    assert "\n" not in str(info.value)


def test_too_few_runs_says_how_many_are_needed():
    with pytest.raises(InputFileError, match=r"^releases.csv: 1 run\(s\); at least "
                       r"5 are needed$"):  # fmt: skip
        path_runs(observations(), plane(), base_model(), min_runs=5)


def test_several_materials_need_ranges():
    mats = {
        "rock": {"e_n": 0.3, "e_t": 0.8, "friction_deg": 30},
        "talus": {"e_n": 0.2, "e_t": 0.7, "friction_deg": 35},
    }
    with pytest.raises(ArgumentError, match="has 2 materials"):
        path_runs(observations(), plane(), base_model(**mats))
    (run,) = path_runs(
        observations(), plane(), base_model(**mats), materials="0-40:rock,40-:talus"
    )
    profile = run.model.profile
    assert profile.material[int(np.searchsorted(profile.x_m, 39.0)) - 1] == "rock"
    assert profile.material[int(np.searchsorted(profile.x_m, 41.0)) - 1] == "talus"
    with pytest.raises(ArgumentError, match="scree, not a material"):
        path_runs(observations(), plane(), base_model(**mats), materials="0-:scree")


def test_section_observations_and_unknown_sections_are_refused():
    obs = observations()
    sect = PathObservations(obs.runs, coordinates="section", source="t.csv")
    with pytest.raises(InputFileError, match="along a section"):
        path_runs(sect, plane(), base_model())
    with pytest.raises(ArgumentError, match="section must be one of"):
        path_runs(obs, plane(), base_model(), section="straight")


# --------------------------------------------------------------------- Tschamut


@pytest.fixture(scope="module")
def tschamut():
    obs = read_release_deposit(
        SPLIT / "calibration_release_points.csv",
        SPLIT / "calibration_observed_deposition.csv",
    )
    return obs, read_dem(TERRAIN), read_model(BASE)


def test_the_base_model_loads():
    model = read_model(BASE)
    assert list(model.materials) == ["meadow"]
    assert model.provenance["profile"].startswith("placeholder")


def test_all_18_tschamut_calibration_runs_build(tschamut):
    obs, grid, base = tschamut
    runs = path_runs(obs, grid, base, min_runs=18)
    sections = path_sections(obs, grid)
    assert [r.path_id for r in runs] == obs.path_ids()
    lateral = np.array([r.lateral_offset_m for r in runs])
    chainage = np.array([r.observed_runout_m for r in runs])
    lengths = np.array([s.length_m for s in sections.values()])
    straight = obs.straight_runout_m()
    print("lateral offsets [m]:", np.round(lateral, 2).tolist())
    print("section lengths [m]:", np.round(lengths, 1).tolist())
    print("endings:", Counter(s.ending for s in sections.values()))
    print("chainage - straight runout [m]:", np.round(chainage - straight, 2).tolist())
    # measured on terrain.asc with steps of 2.5 m: every descent line ends in a
    # local minimum of the proxy 88-107 m from the release, ~47 m lower, and goes
    # on straight to the grid edge (172-253 m) so rocks can run through the dip
    assert {s.ending for s in sections.values()} == {
        "local minimum, then straight on to the grid edge"
    }
    assert 170.0 < lengths.min() and lengths.max() < 255.0
    # the 2-D sections miss the deposits by 1.2-42 m in plan (median 14.1 m)
    assert lateral.min() == pytest.approx(1.20, abs=0.01)
    assert np.median(lateral) == pytest.approx(14.14, abs=0.01)
    assert lateral.max() == pytest.approx(42.07, abs=0.01)
    # so the observed chainage differs from the straight release-deposit distance
    # (-26.5 to +17.0 m, median -2.4 m), and is never beyond the section
    assert np.median(chainage - straight) == pytest.approx(-2.40, abs=0.01)
    assert (chainage <= lengths + 1e-9).all()
    # the bodies are the runs' blocks; the seeders start the radius above ground
    for run, (_, row) in zip(runs, obs.runs.iterrows(), strict=True):
        assert run.model.body.mass_kg == row["mass_kg"]
        height = run.model.seeder.z_m - float(run.model.profile.ground_z(0.0))
        assert height == pytest.approx(row["radius_m"], abs=1e-5)


def test_release_deposit_sections_reproduce_the_straight_runouts(tschamut):
    obs, grid, base = tschamut
    runs = path_runs(obs, grid, base, section="release-deposit")
    chainage = np.array([r.observed_runout_m for r in runs])
    np.testing.assert_allclose(chainage, obs.runs["reported_runout_m"], atol=1e-5)
    np.testing.assert_allclose([r.lateral_offset_m for r in runs], 0.0, atol=1e-9)


def test_the_full_tschamut_files_are_below_the_proxy_dem_elsewhere(tschamut):
    """The split's z are the proxy's trend plane + radius; terrain.asc is higher at
    every calibration release (1.1-5.1 m): measured on its own ground each run is
    accepted, measured on the DEM each would be refused."""
    obs, grid, _ = tschamut
    runs = obs.runs
    ground = grid.sample(runs["release_x_m"].to_numpy(), runs["release_y_m"].to_numpy())
    gap = ground[0] - runs["release_ground_z_m"].to_numpy()
    assert gap.min() == pytest.approx(1.14, abs=0.01)
    assert gap.max() == pytest.approx(5.07, abs=0.01)
    no_ground = PathObservations(
        runs.assign(release_ground_z_m=np.nan), source=obs.source
    )
    with pytest.raises(FieldkitError, match="v020: the release .* below the ground"):
        path_runs(no_ground, grid, read_model(BASE))
