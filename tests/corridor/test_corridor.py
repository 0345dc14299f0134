"""Corridor scans: station geometry, sections on analytic DEMs, energy bounded by
the drop (conservation), and the same table on 1 process and a 2-worker cluster
for the Tschamut DEM (2-D sections and 3-D crossings)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from fieldkit.corridor.scan import scan2d, scan3d
from fieldkit.corridor.sections import SectionSetup, station_section
from fieldkit.corridor.stations import chainage_of, check_on_dem, stations_along
from fieldkit.corridor.table import etag027_class, station_numbers
from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.dem import DemGrid, read_dem
from fieldkit.model.model_file import model_from_dict, read_model
from fieldkit.parallel.engine import Engine, EngineSpec

ALIGNMENT = np.array([[0.0, 160.0], [45.0, 180.0], [100.0, 205.0]])
SLOPE_DEG = 40.0


@pytest.fixture(scope="module")
def tschamut(external_data):
    d = external_data / "tschamut2014"
    return read_dem(d / "terrain.asc")


def plane_dem(slope_deg: float = SLOPE_DEG, ny: int = 121, nx: int = 41) -> DemGrid:
    """A plane rising to +y (1 m cells; z = tan(slope) * y) up to y = 100 m, flat
    beyond that line's height below y = 20 m: x 0-40 m, y 0-120 m."""
    y = np.arange(ny, dtype=float)[::-1]  # row 0 north
    z = np.clip(y - 20.0, 0.0, None) * math.tan(math.radians(slope_deg))
    return DemGrid.from_corner(np.repeat(z[:, None], nx, axis=1), x_left_m=-0.5,
                               y_top_m=ny - 0.5, cellsize_m=1.0)  # fmt: skip


def base_model(e_n: float = 0.3):
    return model_from_dict({
        "profile": {"x_m": [0, 50], "z_m": [30, 0], "material": "rock"},
        "materials": {"rock": {"e_n": e_n, "e_t": 0.8, "friction_deg": 30,
                               "e_n_sd": 0.05}},
        "body": {"mass_kg": 500, "radius_m": 0.3},
        "seeder": {"x_m": 0, "z_m": 31.0, "vx_mps": 1.0},
    })  # fmt: skip


def test_stations_every_spacing_and_the_end():
    s = stations_along(np.array([[0.0, 0.0], [30.0, 0.0], [30.0, 25.0]]), 10.0)
    assert s.chainage_m.tolist() == [0, 10, 20, 30, 40, 50, 55]
    assert s.xy_m[4].tolist() == [30.0, 10.0]
    assert s.normal_xy[0].tolist() == [-0.0, 1.0] and s.normal_xy[4].tolist() == [-1, 0]
    assert s.edges_m.tolist() == [0, 5, 15, 25, 35, 45, 52.5, 55]
    assert chainage_of(s, np.array([15.0, 31.0]), np.array([0.5, 20.0])).tolist() == [
        15.0, 50.0]  # fmt: skip


@pytest.mark.parametrize("spacing", [0.0, -5.0, float("nan")])
def test_spacing_must_be_positive(spacing):
    with pytest.raises(ArgumentError, match="spacing_m must be a distance > 0"):
        stations_along(ALIGNMENT, spacing)


def test_an_alignment_off_the_dem_is_refused_naming_where(tschamut):
    s = stations_along(np.array([[0.0, 160.0], [250.0, 160.0]]), 10.0)
    with pytest.raises(InputFileError, match=r"terrain.asc: the alignment at chainage "
                       r"180.0 m, \(x, y\) = \(180.00, 160.00\), is not on the DEM: "
                       r"outside the grid"):
        check_on_dem(s, tschamut)


def test_section_runs_up_the_plane_from_its_top_to_the_alignment():
    grid = plane_dem()
    s = stations_along(np.array([[5.0, 40.0], [35.0, 40.0]]), 10.0)
    # the normal of a line running +x points +y: up the plane (left side)
    sec = station_section(grid, s, 1, base_model(), SectionSetup(30.0, 10.0))
    assert sec.side == "left" and sec.alignment_x_m == pytest.approx(30.0)
    z = np.asarray(sec.model.profile.z_m)
    assert z[0] == pytest.approx(50 * math.tan(math.radians(SLOPE_DEG)))
    assert sec.model.seeder.z_m == pytest.approx(z[0] + 1.0)  # the model's 1 m
    flipped = stations_along(np.array([[35.0, 40.0], [5.0, 40.0]]), 10.0)
    sec2 = station_section(grid, flipped, 1, base_model(), SectionSetup(30.0, 10.0))
    assert sec2.side == "right"
    np.testing.assert_allclose(sec2.model.profile.z_m, z)
    # the DEM ends 80 m upslope: the section is cut there, and says so
    cut = station_section(grid, s, 1, base_model(), SectionSetup(150.0, 10.0))
    assert cut.alignment_x_m == pytest.approx(80.0, abs=0.3)


def test_energy_at_the_alignment_never_exceeds_the_drop():
    """Conservation: the kinetic energy at the crossing is at most m g (drop of the
    centre) + the start's kinetic energy, rock by rock; on a 40 deg plane every
    rock crosses."""
    grid = plane_dem()
    model = base_model(e_n=0.6)
    with Engine(EngineSpec(workers=0)) as engine:
        scan = scan2d(grid, np.array([[5.0, 40.0], [35.0, 40.0]]), 10.0, model, 400,
                      3, engine, setup=SectionSetup(40.0, 10.0))  # fmt: skip
    f = scan.frame
    assert (f["passing_fraction"] == 1.0).all()
    tan = math.tan(math.radians(SLOPE_DEG))
    drop = (40.0 + 20.0) * tan - 20.0 * tan + 1.0  # start 1 m up; centre >= ground
    bound_kj = (500 * 9.81 * drop + 0.5 * 500 * 1.0**2) / 1e3
    assert (f["energy_max_kj"] <= bound_kj).all()
    assert (f["energy_p99_kj"] > 0.3 * bound_kj).all()  # a real fall, not zeros
    assert (f["height_p99_m"] >= 0).all()  # sliding down a plane: 0 is right


def test_station_numbers_and_classes():
    d = station_numbers(1000, np.linspace(0, 300e3, 101), np.linspace(0, 2, 101))
    assert d["passing"] == 101 and d["passing_fraction"] == pytest.approx(0.101)
    assert d["energy_p99_kj"] == pytest.approx(297.0)
    assert d["etag027_class_p99"] == 2
    few = station_numbers(1000, np.ones(5), np.ones(5))
    assert math.isnan(few["energy_p95_kj"]) and few["energy_max_kj"] == 0.001
    assert [etag027_class(e) for e in (100.0, 100.1, 4500.0, 4501.0)] == [0, 1, 7, 8]


@pytest.fixture(scope="module")
def two_workers():
    with Engine(EngineSpec(workers=2)) as engine:
        yield engine


def test_2d_scan_same_on_one_process_and_two_workers(tschamut, repo, two_workers):
    model = read_model(repo / "examples" / "tschamut" / "model_base.json")
    args = (tschamut, ALIGNMENT, 20.0, model, 300, 11)
    with Engine(EngineSpec(workers=0)) as here:
        one = scan2d(*args, here, setup=SectionSetup(upslope_m=80.0))
    two = scan2d(*args, two_workers, setup=SectionSetup(upslope_m=80.0))
    pd.testing.assert_frame_equal(one.frame, two.frame)
    assert one.frame["passing"].sum() > 0 and one.units == 7  # 0, 20, ..., 100, 109.7
    other = scan2d(tschamut, ALIGNMENT, 20.0, model, 300, 12, here,
                   setup=SectionSetup(upslope_m=80.0))  # fmt: skip
    assert not one.frame["energy_p99_kj"].equals(other.frame["energy_p99_kj"])


def test_3d_scan_same_on_one_process_and_two_workers(tschamut, repo, two_workers):
    model = read_model(repo / "examples" / "tschamut" / "model_3d.json", terrain=True)
    with Engine(EngineSpec(workers=0)) as here:
        one = scan3d(model, tschamut, ALIGNMENT, 10.0, 2500, 5, here)
    two = scan3d(model, tschamut, ALIGNMENT, 10.0, 2500, 5, two_workers)
    pd.testing.assert_frame_equal(one.frame, two.frame)
    assert one.units == 2
    f = one.frame
    # every crossing rock is counted at exactly one station
    assert f["passing"].sum() <= 2500 and f["passing_fraction"].sum() <= 1.0
    assert f["passing"].sum() > 2000  # the line lies across the runout
    assert f["stretch_from_m"].iloc[0] == 0 and f["stretch_to_m"].iloc[-1] == (
        pytest.approx(one.stations.length_m))  # fmt: skip


def test_3d_scan_needs_the_models_own_dem(repo):
    model = read_model(repo / "examples" / "tschamut" / "model_3d.json", terrain=True)
    with Engine(EngineSpec(workers=0)) as here, pytest.raises(
        ArgumentError, match="is not the DEM of the terrain model"
    ):
        scan3d(model, plane_dem(), ALIGNMENT, 10.0, 100, 1, here)
