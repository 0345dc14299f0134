"""Sections from a DEM: analytic surfaces, material ranges, Tschamut 2014 terrain."""

from __future__ import annotations

import doctest
import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.dem import INSIDE, DemGrid, read_dem
from fieldkit.model.dem_profile import (
    MaterialRange,
    Section,
    assign_materials,
    parse_material_ranges,
    profile_along_polyline,
    steepest_descent_line,
)


def surface_grid(func, *, n=41, cell=1.0, source="analytic.asc"):
    """An n x n grid of ``func`` at cell centres, centred on the origin."""
    half = n * cell / 2
    grid = DemGrid.from_corner(np.zeros((n, n)), x_left_m=-half, y_top_m=half,
                               cellsize_m=cell, source=source)  # fmt: skip
    x, y = np.meshgrid(grid.x_m, grid.y_m)
    return replace(grid, values=func(x, y))


def tilted(x, y):
    # fall line: direction (3, -4)/5, slope 0.5
    return 50.0 - 0.3 * x + 0.4 * y


# ------------------------------------------------------------------ polyline
def test_polyline_on_a_plane_is_exact_and_keeps_vertices():
    grid = surface_grid(tilted)
    vertices = [(-10.0, 5.0), (3.0, 5.0), (3.0, -12.0)]
    s = profile_along_polyline(grid, vertices, 0.75)
    # every vertex kept, chainage = plan length (13 + 17), z the plane
    for vx, vy in vertices:
        assert np.any((s.plan_x_m == vx) & (s.plan_y_m == vy))
    assert s.length_m == pytest.approx(30.0, abs=1e-12)
    np.testing.assert_allclose(s.z_m, tilted(s.plan_x_m, s.plan_y_m), atol=1e-10)
    steps = np.diff(s.chainage_m)
    assert steps.max() <= 0.75 + 1e-12 and steps.min() > 0.7  # equal steps per leg
    assert s.drop_m == pytest.approx(tilted(-10, 5) - tilted(3, -12))
    assert set(s.material) == {"ground"} and len(s.material) == len(s.z_m) - 1


def test_polyline_leaving_the_grid_names_file_and_point():
    grid = surface_grid(tilted)  # cell centres span -20..20
    with pytest.raises(InputFileError) as info:
        profile_along_polyline(grid, [(0.0, 0.0), (30.0, 0.0)], 1.0)
    text = str(info.value)
    assert text.startswith("analytic.asc: the line leaves the grid at (x, y) = (21.00")
    assert "chainage 21.0 m" in text and "x -20..20 m" in text


def test_polyline_over_nodata_names_the_cell():
    grid = surface_grid(tilted)
    values = grid.values.copy()
    values[20, 25] = np.nan  # the cell centred at (5, 0)
    grid = replace(grid, values=values, source="holes.asc")
    with pytest.raises(InputFileError, match=r"holes.asc: the line crosses nodata at "
                       r"\(x, y\) = \(4.50, 0.00\).*row 21, column 26"):  # fmt: skip
        profile_along_polyline(grid, [(0.0, 0.0), (10.0, 0.0)], 0.5)


@pytest.mark.parametrize(
    ("vertices", "spacing", "message"),
    [
        ([(0.0, 0.0)], 1.0, "vertices_xy needs at least 2 plan points"),
        ([(0.0, 0.0), (0.0, 0.0)], 1.0, "points 1 and 2 are the same point"),
        ([(0.0, 0.0), (1.0, np.nan)], 1.0, "must be finite"),
        ([(0.0, 0.0), (1.0, 1.0)], 0.0, "spacing_m must be > 0"),
    ],
)
def test_polyline_arguments(vertices, spacing, message):
    with pytest.raises(ArgumentError, match=message):
        profile_along_polyline(surface_grid(tilted), vertices, spacing)


# ------------------------------------------------------- steepest descent
def test_descent_on_a_tilted_plane_is_the_straight_fall_line():
    grid = surface_grid(tilted)
    s = steepest_descent_line(grid, (-6.0, 4.0), 0.5)
    direction = np.array([0.3, -0.4]) / 0.5
    offsets = np.c_[s.plan_x_m + 6.0, s.plan_y_m - 4.0]
    lateral = offsets @ np.array([-direction[1], direction[0]])
    assert np.abs(lateral).max() < 1e-9
    # it runs to the edge y = -20 (the last cell centres), dropping 0.5 m per metre
    assert s.ending == "grid edge"
    assert s.plan_y_m[-1] == pytest.approx(-20.0, abs=1e-5)
    assert s.length_m == pytest.approx(24.0 / 0.8, abs=1e-5)
    assert s.drop_m == pytest.approx(0.5 * s.length_m, rel=1e-9)
    assert np.all(np.diff(s.z_m) < 0)


def cone(x, y):
    """z = -r around a peak at the origin (a grid node): fall lines are radii."""
    return 30.0 - np.hypot(x, y)


def bowl(x, y):
    """z = r^2 / 20 around a pit at the origin: fall lines are radii, inward."""
    return 0.05 * (x**2 + y**2)


def lateral_offset(section: Section, angle_deg: float) -> float:
    """Largest distance of the line's vertices from the ray at ``angle_deg``."""
    a = math.radians(angle_deg)
    normal = np.array([-math.sin(a), math.cos(a)])
    return float(np.abs(np.c_[section.plan_x_m, section.plan_y_m] @ normal).max())


ANGLES = [0.0, 30.0, 45.0, 100.0, 217.0, 333.0]


@pytest.mark.parametrize("angle_deg", ANGLES)
def test_descent_on_a_cone_is_radial(angle_deg):
    cell = 0.5
    grid = surface_grid(cone, n=121, cell=cell)
    a = math.radians(angle_deg)
    s = steepest_descent_line(grid, (5 * math.cos(a), 5 * math.sin(a)), cell / 2)
    # the bilinear cells bend the gradient off radial by O(cell / r): measured at
    # most 0.15 m over 25-37 m (0.3 cell); exactly radial along grid lines and
    # diagonals (0, 45 deg), where the cells are symmetric about the line
    assert lateral_offset(s, angle_deg) < 0.4 * cell
    if angle_deg in (0.0, 45.0):
        assert lateral_offset(s, angle_deg) < 1e-9
    assert s.ending == "grid edge" and np.all(np.diff(s.z_m) < 0)
    assert math.hypot(s.plan_x_m[-1], s.plan_y_m[-1]) >= 30.0 - 1e-6


@pytest.mark.parametrize("angle_deg", ANGLES)
def test_descent_into_a_bowl_is_radial_and_stops_at_the_bottom(angle_deg):
    cell = 0.5
    grid = surface_grid(bowl, n=121, cell=cell)
    a = math.radians(angle_deg)
    s = steepest_descent_line(grid, (25 * math.cos(a), 25 * math.sin(a)), cell / 2)
    assert lateral_offset(s, angle_deg) < 0.4 * cell  # measured <= 0.15 m
    assert s.ending in ("local minimum", "flat area")
    assert math.hypot(s.plan_x_m[-1], s.plan_y_m[-1]) < cell / 2  # within a step
    assert np.all(np.diff(s.z_m) < 0)


def test_off_radial_error_shrinks_with_the_cell_size():
    # what is left of the deviation is the bilinear surface's, not the stepping's:
    # it falls in proportion to the cell size
    offsets = []
    for cell, n in ((1.0, 61), (0.5, 121), (0.25, 241)):
        grid = surface_grid(cone, n=n, cell=cell)
        a = math.radians(217.0)
        s = steepest_descent_line(grid, (5 * math.cos(a), 5 * math.sin(a)), cell / 2)
        offsets.append(lateral_offset(s, 217.0))
    assert offsets[1] < 0.6 * offsets[0] and offsets[2] < 0.6 * offsets[1], offsets


def test_smaller_steps_converge_on_the_same_surface():
    # the fixed-step midpoint method against a 16 times finer step on one grid
    grid = surface_grid(cone, n=61, cell=1.0)
    start = (5 * math.cos(2.0), 5 * math.sin(2.0))
    coarse = steepest_descent_line(grid, start, 0.5)
    fine = steepest_descent_line(grid, start, 0.5 / 16)

    # compare where each line crosses r = 20
    def at_radius(s, r):
        radius = np.hypot(s.plan_x_m, s.plan_y_m)
        return np.interp(r, radius, s.plan_x_m), np.interp(r, radius, s.plan_y_m)

    gap = np.hypot(*np.subtract(at_radius(coarse, 20.0), at_radius(fine, 20.0)))
    half = steepest_descent_line(grid, start, 0.125)
    gap_half = np.hypot(*np.subtract(at_radius(half, 20.0), at_radius(fine, 20.0)))
    # measured 0.049 m at step 0.5 (cell 1 m), 0.004 m at 0.125: first order across
    # the kinks of the bilinear surface at cell edges
    assert gap < 0.1 and gap_half < gap / 4, (gap, gap_half)


def test_descent_stops_at_maximum_length_and_on_flat_ground():
    grid = surface_grid(tilted)
    s = steepest_descent_line(grid, (0.0, 0.0), 0.5, max_length_m=7.25)
    assert s.ending == "maximum length" and s.length_m == pytest.approx(7.25)
    terrace = surface_grid(lambda x, y: np.where(x < 0, -x, 0.0))
    s = steepest_descent_line(terrace, (-10.0, 0.0), 0.5)
    assert s.ending in ("flat area", "local minimum")
    assert s.plan_x_m[-1] == pytest.approx(0.0, abs=0.5)
    with pytest.raises(InputFileError, match="does not fall"):
        steepest_descent_line(terrace, (5.0, 0.0), 0.5)


def test_descent_stops_at_nodata():
    grid = surface_grid(tilted)
    values = grid.values.copy()
    values[30:, :] = np.nan  # everything south of y = -9.5
    s = steepest_descent_line(replace(grid, values=values, source=""), (0.0, 0.0), 0.5)
    assert s.ending == "nodata" and s.plan_y_m[-1] == pytest.approx(-9.0, abs=1e-5)


@pytest.mark.parametrize(
    ("start", "step", "kind", "message"),
    [
        ((50.0, 0.0), 0.5, InputFileError, "the start .* outside the grid"),
        ((0.0, 0.0), 0.6, ArgumentError, "step_m must be <= half the cell size"),
        ((0.0, 0.0), -1.0, ArgumentError, "step_m must be > 0"),
    ],
)
def test_descent_arguments(start, step, kind, message):
    with pytest.raises(kind, match=message):
        steepest_descent_line(surface_grid(tilted), start, step)


# --------------------------------------------------------------- materials
def test_assign_materials_by_segment_midpoint():
    chainage = np.array([0.0, 10.0, 38.0, 41.0, 80.0])
    assert assign_materials(chainage, "0-40:rock,40-:talus") == (
        "rock", "rock", "rock", "talus")  # fmt: skip
    ranges = [MaterialRange(0, 20, "a"), MaterialRange(20, 100, "b")]
    assert assign_materials(chainage, ranges) == ("a", "b", "b", "b")


def test_with_materials_cuts_at_the_boundaries():
    s = Section(np.array([0.0, 30.0, 50.0]), np.array([30.0, 10.0, 0.0]),
                np.array([0.0, 30.0, 50.0]), np.zeros(3), ("g", "g"))  # fmt: skip
    t = s.with_materials("0-40:rock,40-45:scree,45-:talus")
    assert t.chainage_m.tolist() == [0.0, 30.0, 40.0, 45.0, 50.0]
    assert t.z_m.tolist() == [30.0, 10.0, 5.0, 2.5, 0.0]
    assert t.plan_x_m.tolist() == [0.0, 30.0, 40.0, 45.0, 50.0]
    assert t.material == ("rock", "rock", "scree", "talus")


@pytest.mark.parametrize(
    ("ranges", "message"),
    [
        ("0-40:rock,50-:talus", "no material between chainage 40 and 50 m"),
        ("0-50:rock,40-:talus", "overlap"),
        ("0-:rock,40-:talus", "overlap"),
        ("5-40:rock,40-:talus", "must start at chainage 0"),
        ("0-40:rock,40-30:talus", "ends before it starts"),
        ("0-40 rock", "is not START-END:MATERIAL"),
        ("0-x:rock", "'x' in '0-x:rock' is not a chainage"),
        ("0-40:rock,,40-:talus", "is not START-END:MATERIAL"),
        ("0-:=cmd", "material name '=cmd'"),
    ],
)
def test_bad_material_ranges(ranges, message):
    with pytest.raises(ArgumentError, match=message) as info:
        parse_material_ranges(ranges)
    assert info.value.source == "ranges"


def test_closed_last_range_shorter_than_the_section():
    with pytest.raises(ArgumentError, match="no material beyond chainage 40 m"):
        assign_materials(np.array([0.0, 30.0, 60.0]), "0-40:rock")
    assert assign_materials(np.array([0.0, 30.0]), "0-40:rock") == ("rock",)


# ------------------------------------------------- Tschamut 2014 real terrain
RUNS = ["v020", "v023", "v028", "v032", "v033", "v034"]  # the first calibration runs


@pytest.fixture(scope="module")
def tschamut(external_data):
    folder = external_data / "tschamut2014"
    grid = read_dem(folder / "terrain.asc")
    release = pd.read_csv(folder / "release_points.csv").set_index("trajectory_id")
    deposit = pd.read_csv(folder / "observed_deposition.csv").set_index("trajectory_id")
    return grid, release, deposit


@pytest.mark.parametrize("run", RUNS)
def test_tschamut_descent_falls_and_stays_in_the_grid(tschamut, run):
    grid, release, deposit = tschamut
    start = (release.at[run, "x_m"], release.at[run, "y_m"])
    s = steepest_descent_line(grid, start, grid.cellsize_m / 2)
    assert np.all(np.diff(s.z_m) < 0)
    z, _, _, status = grid.sample(s.plan_x_m, s.plan_y_m)
    assert np.all(status == INSIDE)
    np.testing.assert_allclose(z, s.z_m)
    assert s.ending in ("local minimum", "flat area", "grid edge")
    # reported, not asserted: how far the fall line ends from where the rock stopped
    end = np.hypot(s.plan_x_m[-1] - deposit.at[run, "x_m"],
                   s.plan_y_m[-1] - deposit.at[run, "y_m"])  # fmt: skip
    print(f"{run}: descent {s.length_m:.1f} m, drop {s.drop_m:.1f} m, {s.ending}; "
          f"end {end:.1f} m from the deposit (observed runout "
          f"{deposit.at[run, 'observed_runout_m']:.1f} m)")  # fmt: skip


def test_doctests():
    import fieldkit.model.dem_profile as module

    result = doctest.testmod(module)
    assert result.attempted > 0 and result.failed == 0
