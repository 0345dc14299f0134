"""Points CSV: section, geographic and projected layouts, aliases, units, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io import geodesy
from fieldkit.io.gpx import write_gpx_waypoints
from fieldkit.io.impacts import read_impacts
from fieldkit.io.points_csv import read_points_csv

FOOT = 0.3048
# Flinders Peak, published MGA zone 55 coordinates (GDA2020 Technical Manual Table C-1).
FLINDERS = (-(37 + 57 / 60 + 3.72030 / 3600), 144 + 25 / 60 + 29.52440 / 3600)
FLINDERS_UTM55 = (273741.297, 5796489.777)


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_section_csv_with_material_and_slope(tmp_path):
    path = write(
        tmp_path,
        "s.csv",
        "point,x_m,z_m,material,slope_deg\nA1,0,100,talus,35\nA2,12.5,91.25,rock,\n",
    )
    points = read_impacts(path)
    assert points.crs == "section"
    frame = points.frame
    assert frame["point"].tolist() == ["A1", "A2"]
    assert frame["x_m"].tolist() == [0.0, 12.5]
    assert frame["z_m"].tolist() == [100.0, 91.25]
    assert frame["material"].tolist() == ["talus", "rock"]
    assert frame["slope_deg"].iloc[0] == 35.0 and np.isnan(frame["slope_deg"].iloc[1])
    assert frame[["lat_deg", "easting_m"]].isna().all().all()


def test_section_csv_in_feet(tmp_path):
    path = write(tmp_path, "ft.csv", "name,x,z\n1,0,1000\n2,100,950\n")
    frame = read_impacts(path, units="ft").frame
    assert frame["x_m"].tolist() == [0.0, 100 * FOOT]
    assert frame["z_m"].tolist() == [1000 * FOOT, 950 * FOOT]


def test_geographic_csv_gnss_app_header(tmp_path):
    """Emlid-Flow-like header: Name, Longitude, Latitude, Elevation, Ellipsoidal h."""
    lat2, lon2 = geodesy.destination(*FLINDERS, 300.0, 40.0)
    text = (
        "Name,Code,Longitude,Latitude,Elevation,Ellipsoidal height\n"
        f"I1,imp,{FLINDERS[1]:.9f},{FLINDERS[0]:.9f},347.2,350.948\n"
        f"I2,imp,{float(lon2):.9f},{float(lat2):.9f},330.0,333.75\n"
    )
    points = read_impacts(write(tmp_path, "emlid.csv", text), units="m")
    frame = points.frame
    assert points.crs == "EPSG:32755"
    assert "'Elevation'" in points.height_reference
    assert frame["z_m"].tolist() == [347.2, 330.0]
    assert frame["x_m"].iloc[1] == pytest.approx(40.0, abs=1e-4)
    assert frame["easting_m"].iloc[0] == pytest.approx(FLINDERS_UTM55[0], abs=0.002)
    assert frame["northing_m"].iloc[0] == pytest.approx(FLINDERS_UTM55[1], abs=0.002)


def test_ellipsoidal_height_only_is_labelled(tmp_path):
    text = "id,lat,lon,hae\nA,49,-117,1510\nB,49.0005,-117,1490\n"
    points = read_impacts(write(tmp_path, "hae.csv", text), units="m")
    assert "ellipsoidal" in points.height_reference
    assert points.frame["z_m"].tolist() == [1510.0, 1490.0]


def test_projected_csv_published_utm_to_lat_lon(tmp_path):
    east2, north2 = FLINDERS_UTM55[0] + 30.0, FLINDERS_UTM55[1] - 40.0
    text = (
        "point,Easting,Northing,Elevation\n"
        f"F,{FLINDERS_UTM55[0]},{FLINDERS_UTM55[1]},347.2\n"
        f"G,{east2},{north2},330.1\n"
    )
    points = read_impacts(write(tmp_path, "en.csv", text), epsg=32755, units="m")
    frame = points.frame
    assert points.crs == "EPSG:32755"
    assert frame["lat_deg"].iloc[0] == pytest.approx(FLINDERS[0], abs=2e-8)
    assert frame["lon_deg"].iloc[0] == pytest.approx(FLINDERS[1], abs=2e-8)
    assert frame["easting_m"].tolist() == pytest.approx([FLINDERS_UTM55[0], east2])
    # Geodesic x = grid distance / point scale factor (1.00023056 at Flinders Peak).
    assert frame["x_m"].iloc[1] == pytest.approx(50.0 / 1.00023056, abs=2e-4)


def test_projected_csv_in_feet_on_a_metre_grid(tmp_path):
    e0, n0 = 500000.0, 5480000.0
    text = (
        f"pt,E,N,elev\na,{e0 / FOOT},{n0 / FOOT},5000\n"
        f"b,{e0 / FOOT},{(n0 + 30) / FOOT},4900\n"
    )
    frame = read_impacts(
        write(tmp_path, "enft.csv", text), epsg="EPSG:32611", units="ft"
    ).frame
    assert frame["easting_m"].tolist() == pytest.approx([e0, e0], abs=1e-6)
    assert frame["northing_m"].iloc[1] - frame["northing_m"].iloc[0] == pytest.approx(
        30.0
    )
    assert frame["z_m"].tolist() == pytest.approx([5000 * FOOT, 4900 * FOOT])


def test_projected_csv_in_a_us_survey_foot_crs(tmp_path):
    """EPSG:2229 is in US survey feet: coordinates are read in the CRS's own unit."""
    import pyproj

    to_2229 = pyproj.Transformer.from_crs(4326, 2229, always_xy=True)
    e, n = to_2229.transform(-118.25, 34.05)
    text = f"point,x,y,z_ft\nA,{e},{n},300\nB,{e + 100},{n},290\n"
    points = read_impacts(write(tmp_path, "sp.csv", text), epsg=2229)
    frame = points.frame
    assert frame["lat_deg"].iloc[0] == pytest.approx(34.05, abs=1e-9)
    assert frame["lon_deg"].iloc[0] == pytest.approx(-118.25, abs=1e-9)
    us_foot = 1200 / 3937
    assert frame["easting_m"].iloc[0] == pytest.approx(e * us_foot, abs=1e-6)
    assert any("US survey foot" in note for note in points.notes)


def test_unit_in_column_name_wins_over_units_option(tmp_path):
    text = "point,lat,lon,Altitude (ft)\nA,49,-117,5000\nB,49.0005,-117,4950\n"
    frame = read_impacts(write(tmp_path, "alt.csv", text)).frame
    assert frame["z_m"].tolist() == pytest.approx([5000 * FOOT, 4950 * FOOT])
    path = write(tmp_path, "xm.csv", "point,x_m,z_m\nA,0,10\nB,5,8\n")
    points = read_impacts(path, units="ft")  # the column name says metres: it wins
    assert points.frame["x_m"].tolist() == [0.0, 5.0]
    assert any("not applied to x_m, z_m" in note for note in points.notes)
    with pytest.raises(ArgumentError, match="units must be"):
        read_impacts(path, units="yd")


def test_semicolon_and_decimal_comma(tmp_path):
    text = "Punkt;X;Z\nA;0;100,5\nB;12,25;90\n".replace("Punkt", "point")
    frame = read_impacts(write(tmp_path, "eu.csv", text), units="m").frame
    assert frame["x_m"].tolist() == [0.0, 12.25]
    assert frame["z_m"].tolist() == [100.5, 90.0]


def test_no_name_column_numbers_the_points(tmp_path):
    points = read_impacts(write(tmp_path, "n.csv", "x,z\n0,10\n3,8\n"), units="m")
    assert points.frame["point"].tolist() == ["1", "2"]
    assert any("no point-name column" in note for note in points.notes)


def test_comments_and_blank_lines_keep_row_numbers(tmp_path):
    text = "# survey 2023\npoint,x,z\n\nA,0,10\nB,abc,8\n"
    with pytest.raises(InputFileError) as error:
        read_impacts(write(tmp_path, "c.csv", text), units="m")
    assert str(error.value).endswith("c.csv: row 5: column 'x': 'abc' is not a number")


# --- bad input -----------------------------------------------------------------------


def test_text_in_a_number_names_column_value_and_row(tmp_path):
    path = write(
        tmp_path, "t.csv", "point,lat,lon,elev\nA,49,-117,1500\nB,49.1,-117,15O0\n"
    )
    with pytest.raises(InputFileError) as error:
        read_impacts(path, units="m")
    assert str(error.value) == f"{path}: row 3: column 'elev': '15O0' is not a number"


def test_duplicated_point_names_both_rows(tmp_path):
    path = write(tmp_path, "d.csv", "point,x,z\nA,0,10\nB,2,9\nA,4,8\n")
    with pytest.raises(InputFileError) as error:
        read_impacts(path)
    assert str(error.value) == (
        f"{path}: point A: point 'A' appears twice (row 2 and row 4)"
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("point,x,z\n", "no data rows"),
        ("\n\n  \n", "file is empty"),
        (
            "point,foo,bar\nA,1,2\n",
            "no coordinate columns found \\(have: point, foo, bar\\)",
        ),
        ("point,easting,northing,elev\nA,1,2,3\n", "need the EPSG code"),
        ("point,x\nA,1\n", "no elevation column"),
        ("point,lat,lon,elev\nA,91,0,3\n", "row 2: column 'lat': 91 is outside"),
        ("point,lat,lon,elev\nA,45,0,\n", "row 2: column 'elev' is empty"),
        ("point,x,z\nA,5,10\nB,3,9\n", "row 3: x goes backwards"),
        ("point,x,z,x\nA,5,10,1\n", "appears twice in the header"),
        ("point,x,z\n,5,10\n", "row 2: column 'point' \\(point name\\) is empty"),
    ],
)
def test_bad_csv(tmp_path, text, message):
    with pytest.raises(InputFileError, match=message):
        read_points_csv(write(tmp_path, "bad.csv", text), units="m")


def test_missing_empty_and_binary_csv(tmp_path):
    with pytest.raises(InputFileError, match="gone.csv: file not found"):
        read_impacts(tmp_path / "gone.csv")
    empty = write(tmp_path, "empty.csv", "")
    with pytest.raises(InputFileError, match="empty.csv: file is empty"):
        read_impacts(empty)
    binary = tmp_path / "b.csv"
    binary.write_bytes(b"PK\x03\x04" + bytes(300))  # a zip (xlsx) renamed .csv
    with pytest.raises(InputFileError, match="not a text CSV file"):
        read_impacts(binary)


def test_bad_epsg_argument(tmp_path):
    path = write(tmp_path, "e.csv", "point,easting,northing,elev\nA,1,2,3\n")
    with pytest.raises(ArgumentError, match="epsg: EPSG:4326 .* is not a projected"):
        read_impacts(path, epsg=4326)


def test_dispatch_by_content_not_extension(tmp_path):
    import pandas as pd

    gpx_as_txt = tmp_path / "impacts.txt"
    write_gpx_waypoints(
        gpx_as_txt,
        pd.DataFrame(
            {
                "point": ["A", "B"],
                "lat_deg": [49.0, 49.0005],
                "lon_deg": [-117.0] * 2,
                "elev_m": [1500.0, 1480.0],
            }
        ),
    )
    assert read_impacts(gpx_as_txt).frame["z_m"].tolist() == [1500.0, 1480.0]
    csv_no_ext = write(tmp_path, "impacts", "point,x,z\nA,0,1\nB,1,0\n")
    assert read_impacts(csv_no_ext, units="m").frame["x_m"].tolist() == [0.0, 1.0]
