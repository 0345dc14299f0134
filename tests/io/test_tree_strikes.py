"""Tree strikes: distances, coordinates projected onto the flight, bad input."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fieldkit.errors import InputFileError
from fieldkit.io import geodesy
from fieldkit.io.gpx import write_gpx_waypoints
from fieldkit.io.impacts import read_impacts
from fieldkit.io.point_sets import point_set_from_section
from fieldkit.io.trees import read_trees

FOOT = 0.3048


@pytest.fixture()
def section_impacts():
    return point_set_from_section(
        ["A1", "A2", "A3"], [0.0, 12.0, 30.0], [100.0, 92.0, 80.0], source="imp.csv"
    )


@pytest.fixture()
def geographic_impacts(tmp_path):
    """Three impacts: 40 m at azimuth 120 deg, then 50 m at azimuth 150 deg."""
    lat, lon = [49.5], [-117.4]
    for azimuth, step in [(120.0, 40.0), (150.0, 50.0)]:
        next_lat, next_lon = geodesy.destination(lat[-1], lon[-1], azimuth, step)
        lat.append(float(next_lat))
        lon.append(float(next_lon))
    path = tmp_path / "impacts.gpx"
    write_gpx_waypoints(
        path,
        pd.DataFrame(
            {
                "point": ["B1", "B2", "B3"],
                "lat_deg": lat,
                "lon_deg": lon,
                "elev_m": [1500.0, 1480.0, 1450.0],
            }
        ),
    )
    return read_impacts(path)


def write(tmp_path, text, name="trees.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_distance_layout_with_optional_columns(tmp_path, section_impacts):
    text = (
        "after_impact,horizontal_distance_m,strike_height_m,species,dbh_mm,ground_z_m\n"
        "A1,5.5,2.5,Douglas-fir,420,96.1\n"
        "A2,10,1.25,,,\n"
        "A2,14,0.8,larch,300,\n"
    )
    trees = read_trees(write(tmp_path, text), section_impacts)
    frame = trees.frame
    assert frame["after_impact"].tolist() == ["A1", "A2", "A2"]
    assert frame["horizontal_distance_m"].tolist() == [5.5, 10.0, 14.0]
    assert frame["strike_height_m"].tolist() == [2.5, 1.25, 0.8]
    assert frame["ground_z_m"].iloc[0] == 96.1 and frame["ground_z_m"].isna()[1:].all()
    assert frame["species"].isna().tolist() == [False, True, False]
    assert frame["species"].iloc[0] == "Douglas-fir"
    assert frame["dbh_mm"].iloc[0] == 420.0 and np.isnan(frame["dbh_mm"].iloc[1])
    assert frame["row"].tolist() == [2, 3, 4]


def test_feet_and_dbh_in_inches(tmp_path, section_impacts):
    text = "after_impact,distance,height,dbh_in\nA2,20,8,12\n"
    frame = read_trees(write(tmp_path, text), section_impacts, units="ft").frame
    assert frame["horizontal_distance_m"].iloc[0] == pytest.approx(20 * FOOT)
    assert frame["strike_height_m"].iloc[0] == pytest.approx(8 * FOOT)
    assert frame["dbh_mm"].iloc[0] == pytest.approx(12 * 25.4)


def test_section_x_layout_finds_the_flight(tmp_path, section_impacts):
    text = "x_m,strike_height_m\n7,2\n20.5,3\n"
    frame = read_trees(write(tmp_path, text), section_impacts).frame
    assert frame["after_impact"].tolist() == ["A1", "A2"]
    assert frame["horizontal_distance_m"].tolist() == pytest.approx([7.0, 8.5])


def test_lat_lon_tree_projected_onto_the_flight(tmp_path, geographic_impacts):
    """A tree 15 m along the second flight and 2 m to its side.

    Independent truth: walk 15 m from B2 along the flight azimuth (150 deg), then 2 m
    at right angles (240 deg). Its along-line distance is 15 m and offset 2 m (the
    flight line is a geodesic; over 50 m the offset changes the along distance by
    2²/(2R) ~ 0).
    """
    b2 = geographic_impacts.frame.iloc[1]
    _, azimuth, _ = geodesy.geodesic_inverse(
        b2.lat_deg,
        b2.lon_deg,
        *geographic_impacts.frame.iloc[2][["lat_deg", "lon_deg"]],
    )
    lat, lon = geodesy.destination(b2.lat_deg, b2.lon_deg, float(azimuth), 15.0)
    lat, lon = geodesy.destination(float(lat), float(lon), float(azimuth) + 90.0, 2.0)
    text = f"tree,lat,lon,strike_height_m\nT1,{float(lat):.10f},{float(lon):.10f},4.2\n"
    trees = read_trees(write(tmp_path, text), geographic_impacts)
    frame = trees.frame
    assert frame["after_impact"].tolist() == ["B2"]
    assert frame["tree"].tolist() == ["T1"]
    assert frame["horizontal_distance_m"].iloc[0] == pytest.approx(15.0, abs=1e-3)
    assert frame["offset_m"].iloc[0] == pytest.approx(2.0, abs=1e-3)
    assert any("no after_impact given" in note and "B2" in note for note in trees.notes)
    # With after_impact given, no guess and no note.
    text = f"after_impact,lat,lon,strike_height_m\nB2,{float(lat)},{float(lon)},4.2\n"
    given = read_trees(write(tmp_path, text, "t2.csv"), geographic_impacts)
    assert given.notes == ()
    assert given.frame["horizontal_distance_m"].iloc[0] == pytest.approx(15.0, abs=1e-3)


# --- bad input -----------------------------------------------------------------------


def test_unknown_impact_names_row_and_impact(tmp_path, section_impacts):
    path = write(
        tmp_path,
        "after_impact,horizontal_distance_m,strike_height_m\nA1,3,1\nA7,2,1\n",
    )
    with pytest.raises(InputFileError) as error:
        read_trees(path, section_impacts)
    assert str(error.value) == (
        f"{path}: row 3: tree strike after impact 'A7', which is not an impact in "
        "imp.csv"
    )


def test_last_impact_has_no_flight(tmp_path, section_impacts):
    path = write(
        tmp_path, "after_impact,horizontal_distance_m,strike_height_m\nA3,2,1\n"
    )
    with pytest.raises(InputFileError, match="row 2: impact 'A3' is the last impact"):
        read_trees(path, section_impacts)


@pytest.mark.parametrize("distance", ["0", "-1", "12", "13.5"])
def test_distance_outside_the_flight(tmp_path, section_impacts, distance):
    path = write(
        tmp_path,
        f"after_impact,horizontal_distance_m,strike_height_m\nA1,{distance},1\n",
    )
    with pytest.raises(InputFileError, match="row 2: horizontal distance .* outside"):
        read_trees(path, section_impacts)


def test_negative_height_and_text_in_number(tmp_path, section_impacts):
    path = write(
        tmp_path, "after_impact,horizontal_distance_m,strike_height_m\nA1,3,-1\n"
    )
    with pytest.raises(InputFileError, match="row 2: strike height -1 m is negative"):
        read_trees(path, section_impacts)
    path = write(
        tmp_path, "after_impact,horizontal_distance_m,strike_height_m\nA1,3,2m\n"
    )
    with pytest.raises(
        InputFileError, match="row 2: column 'strike_height_m': '2m' is not a number"
    ):
        read_trees(path, section_impacts)


def test_layout_errors(tmp_path, section_impacts, geographic_impacts):
    with pytest.raises(InputFileError, match="need a strike_height_m column"):
        read_trees(
            write(tmp_path, "after_impact,horizontal_distance_m\nA1,3\n"),
            section_impacts,
        )
    with pytest.raises(InputFileError, match="needs an after_impact column"):
        read_trees(
            write(tmp_path, "horizontal_distance_m,strike_height_m\n3,1\n"),
            section_impacts,
        )
    with pytest.raises(InputFileError, match="impacts .* have only section"):
        read_trees(
            write(tmp_path, "lat,lon,strike_height_m\n49,-117,1\n"), section_impacts
        )
    with pytest.raises(InputFileError, match="not between two impacts"):
        read_trees(write(tmp_path, "x_m,strike_height_m\n31,1\n"), section_impacts)
    with pytest.raises(InputFileError, match="not between any two successive impacts"):
        read_trees(
            write(tmp_path, "lat,lon,strike_height_m\n49.6,-117.4,1\n"),
            geographic_impacts,
        )
    with pytest.raises(InputFileError, match="trees.csv: file is empty"):
        read_trees(write(tmp_path, ""), section_impacts)
