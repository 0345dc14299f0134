"""GPX reading and writing: round trips, real files from other software, bad input."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fieldkit.errors import InputFileError
from fieldkit.io import geodesy
from fieldkit.io.gpx import read_gpx_waypoints, write_gpx_waypoints
from fieldkit.io.impacts import read_impacts

GPXPY = "gpx_gpxpy"


def sample_frame() -> pd.DataFrame:
    lat, lon = [49.52], [-117.43]
    for azimuth, step in [(100.0, 20.0), (110.0, 45.0), (115.0, 80.0)]:
        next_lat, next_lon = geodesy.destination(lat[-1], lon[-1], azimuth, step)
        lat.append(float(next_lat))
        lon.append(float(next_lon))
    return pd.DataFrame(
        {
            "point": ["A1", "A2", "A3", "A4"],
            "lat_deg": lat,
            "lon_deg": lon,
            "elev_m": [1612.0, 1601.25, 1588.5, 1570.125],
        }
    )


@settings(max_examples=30, deadline=None)
@given(
    points=st.lists(
        st.tuples(
            st.floats(-89.9, 89.9), st.floats(-179.9, 179.9), st.floats(-420.0, 8848.0)
        ),
        min_size=1,
        max_size=12,
    )
)
def test_round_trip_precision(tmp_path_factory, points):
    frame = pd.DataFrame(
        {
            "point": [f"P{i}&<{i}>" for i in range(len(points))],  # XML escaping too
            "lat_deg": [p[0] for p in points],
            "lon_deg": [p[1] for p in points],
            "elev_m": [p[2] for p in points],
        }
    )
    path = tmp_path_factory.mktemp("gpx") / "round.gpx"
    write_gpx_waypoints(path, frame)
    back = read_gpx_waypoints(path)
    assert list(back["point"]) == list(frame["point"])
    assert np.max(np.abs(back["lat_deg"] - frame["lat_deg"])) <= 1e-9
    assert np.max(np.abs(back["lon_deg"] - frame["lon_deg"])) <= 1e-9
    assert np.max(np.abs(back["elev_m"] - frame["elev_m"])) <= 0.001


def test_round_trip_times_and_missing_elevation(tmp_path):
    frame = sample_frame()
    frame["time"] = pd.to_datetime(
        ["2023-07-05T14:23:59Z", None, "2023-07-05T14:25:01.5Z", None],
        utc=True,
        format="ISO8601",
    )
    frame.loc[1, "elev_m"] = np.nan
    path = tmp_path / "t.gpx"
    write_gpx_waypoints(path, frame, creator="test & co")
    text = path.read_text()
    assert text.count("<ele>") == 3
    assert 'creator="test &amp; co"' in text
    assert 'version="1.1"' in text and "http://www.topografix.com/GPX/1/1" in text
    back = read_gpx_waypoints(path)
    assert back["time"].iloc[0] == pd.Timestamp("2023-07-05T14:23:59Z")
    assert back["time"].iloc[2] == pd.Timestamp("2023-07-05T14:25:01.5Z")
    assert back["time"].isna().tolist() == [False, True, False, True]
    assert np.isnan(back["elev_m"].iloc[1])


def test_read_impacts_from_gpx_section_coordinates(tmp_path):
    frame = sample_frame()
    path = tmp_path / "impacts.gpx"
    write_gpx_waypoints(path, frame)
    points = read_impacts(path)
    assert points.crs == "EPSG:32611"
    assert "no geoid conversion" in points.height_reference
    np.testing.assert_allclose(points.frame["x_m"], [0, 20, 65, 145], atol=2e-4)
    np.testing.assert_allclose(points.frame["z_m"], frame["elev_m"], atol=5e-4)
    e, n, _ = geodesy.to_utm(frame["lat_deg"], frame["lon_deg"])
    np.testing.assert_allclose(points.frame["easting_m"], e, atol=1e-3)
    np.testing.assert_allclose(points.frame["northing_m"], n, atol=1e-3)
    assert list(points.frame.columns[:7]) == [
        "point",
        "x_m",
        "z_m",
        "lat_deg",
        "lon_deg",
        "easting_m",
        "northing_m",
    ]


def test_gpx_10_namespace_bom_and_extensions(tmp_path):
    text = (
        "\ufeff<?xml version='1.0' encoding='UTF-8'?>\n"
        '<gpx version="1.0" creator="x" xmlns="http://www.topografix.com/GPX/1/0">\n'
        ' <wpt lat="49.1" lon="-117.2"><ele>1500.5</ele><name>B1</name>'
        "<extensions><q:x xmlns:q='urn:q'>1</q:x></extensions></wpt>\n"
        ' <wpt lat="49.1001" lon="-117.2"><ele>1490</ele><name>B2</name></wpt>\n'
        "</gpx>\n"
    )
    path = tmp_path / "v10.gpx"
    path.write_bytes(text.encode("utf-8"))
    frame = read_gpx_waypoints(path)
    assert frame["point"].tolist() == ["B1", "B2"]
    assert frame["elev_m"].tolist() == [1500.5, 1490.0]


# --- real files written by other software (gpxpy test files, Apache-2.0) -----------

GPXPY_FILES = {
    # file: (kind read with points="auto", count)
    "Mojstrovka.gpx": ("trkpt", 184),
    "around-visnjan-with-car.gpx": ("trkpt", None),
    "cerknicko-jezero.gpx": ("wpt", 7),
    "cerknicko-without-times.gpx": ("wpt", 7),
    "korita-zbevnica.gpx": ("wpt", 2),
    "route.gpx": ("rtept", None),
    "track-with-empty-segment.gpx": ("trkpt", None),
    "track_with_dilution_errors.gpx": ("wpt", 1),
    "unicode_with_bom.gpx": ("wpt", 1),
}


@pytest.mark.parametrize("name", sorted(GPXPY_FILES))
def test_gpxpy_files_read(external_data, name):
    path = external_data / GPXPY / name
    kind, count = GPXPY_FILES[name]
    raw = path.read_bytes().decode("utf-8-sig")
    expected = len(re.findall(rf"<{kind}\s", raw))  # independent count
    if count is not None:
        assert expected == count
    frame = read_gpx_waypoints(path, points="auto")
    assert len(frame) == expected > 0
    assert frame["lat_deg"].between(-90, 90).all()
    assert frame["lon_deg"].between(-180, 180).all()
    first_lat = float(re.search(rf'<{kind}\s+lat="([-\d.]+)"', raw).group(1))
    assert frame["lat_deg"].iloc[0] == first_lat
    if kind != "wpt":
        with pytest.raises(InputFileError, match="no waypoints.*track points"):
            read_gpx_waypoints(path)


def test_gpxpy_track_as_impacts(external_data):
    path = external_data / GPXPY / "Mojstrovka.gpx"
    points = read_impacts(path, gpx_points="track")
    frame = points.frame
    assert len(frame) == 184
    assert points.crs == "EPSG:32633"  # Slovenia, 13.7° E
    steps, _, _ = geodesy.geodesic_inverse(
        frame["lat_deg"][:-1].to_numpy(),
        frame["lon_deg"][:-1].to_numpy(),
        frame["lat_deg"][1:].to_numpy(),
        frame["lon_deg"][1:].to_numpy(),
    )
    np.testing.assert_allclose(frame["x_m"].iloc[-1], steps.sum(), rtol=1e-12)
    assert frame["z_m"].iloc[0] == 1614.678
    # 7 fractional digits of a second in <time> parse (bogus 1901 date kept as given).
    assert frame["time"].iloc[0] == pd.Timestamp("1901-12-13T20:45:52.2073437Z")


def test_gpxpy_bom_file_as_impact(external_data):
    points = read_impacts(external_data / GPXPY / "unicode_with_bom.gpx")
    assert points.frame["point"].tolist() == ["test"]
    assert points.frame["z_m"].tolist() == [-14.6]
    assert points.frame["x_m"].tolist() == [0.0]


def test_gpxpy_waypoint_without_elevation_named(external_data):
    with pytest.raises(InputFileError) as error:
        read_impacts(external_data / GPXPY / "cerknicko-jezero.gpx")
    assert "waypoint '001' has no elevation (<ele>)" in str(error.value)
    assert "waypoint 1" in str(error.value)
    with pytest.raises(InputFileError, match="waypoint 'wpt1' has no elevation"):
        read_impacts(external_data / GPXPY / "track_with_dilution_errors.gpx")


def test_gpxpy_no_waypoints_says_what_there_is(external_data):
    with pytest.raises(InputFileError) as error:
        read_impacts(external_data / GPXPY / "route.gpx")
    message = str(error.value)
    assert "no waypoints" in message and "55 route points" in message
    assert "\n" not in message


# --- bad input -----------------------------------------------------------------------


def write(tmp_path, name, content):
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding="utf-8")
    return path


def test_missing_and_empty_files(tmp_path):
    with pytest.raises(InputFileError, match="nope.gpx: file not found"):
        read_impacts(tmp_path / "nope.gpx")
    with pytest.raises(InputFileError, match="empty.gpx: file is empty"):
        read_impacts(write(tmp_path, "empty.gpx", ""))
    with pytest.raises(InputFileError, match="is a folder"):
        read_impacts(tmp_path)


def test_truncated_gpx_names_the_line(tmp_path):
    path = tmp_path / "full.gpx"
    write_gpx_waypoints(path, sample_frame())
    text = path.read_text()
    cut = write(tmp_path, "cut.gpx", text[: text.index("<name>A3") + 4])
    with pytest.raises(InputFileError) as error:
        read_impacts(cut)
    line = text[: text.index("<name>A3")].count("\n") + 1
    assert str(error.value) == (
        f"{cut}: GPX is truncated or malformed (XML error at line {line})"
    )


def test_binary_gpx(tmp_path):
    binary = bytes(range(256)) * 8
    with pytest.raises(InputFileError, match="binary.gpx: not a GPX file"):
        read_impacts(write(tmp_path, "binary.gpx", binary))
    png = b"\x89PNG\r\n\x1a\n" + bytes(100)
    with pytest.raises(InputFileError, match="not a GPX file"):
        read_gpx_waypoints(write(tmp_path, "photo.gpx", png))
    kml = '<?xml version="1.0"?><kml xmlns="http://www.opengis.net/kml/2.2"></kml>'
    with pytest.raises(InputFileError, match="root element is <kml>"):
        read_impacts(write(tmp_path, "k.gpx", kml))


def test_unknown_extension_binary_says_what_was_tried(tmp_path):
    with pytest.raises(InputFileError) as error:
        read_impacts(write(tmp_path, "data.bin", bytes(range(256))))
    assert "tried GPX" in str(error.value) and "CSV" in str(error.value)


def test_duplicated_waypoint_named_with_both_places(tmp_path):
    frame = sample_frame()
    frame.loc[3, "point"] = "A2"
    path = tmp_path / "dup.gpx"
    write_gpx_waypoints(path, frame)
    with pytest.raises(InputFileError) as error:
        read_impacts(path)
    assert str(error.value) == (
        f"{path}: point A2: point 'A2' appears twice (waypoint 2 and waypoint 4)"
    )


@pytest.mark.parametrize(
    ("attributes", "message"),
    [
        ('lat="abc" lon="1"', "waypoint 1 \\('X'\\): lat 'abc' is not a number"),
        ('lat="95" lon="1"', "lat 95 is outside"),
        ('lon="1"', "no lat attribute"),
    ],
)
def test_bad_coordinates(tmp_path, attributes, message):
    text = (
        '<gpx xmlns="http://www.topografix.com/GPX/1/1">'
        f"<wpt {attributes}><ele>1</ele><name>X</name></wpt></gpx>"
    )
    with pytest.raises(InputFileError, match=message):
        read_impacts(write(tmp_path, "bad.gpx", text))


def test_text_in_elevation_named(tmp_path):
    text = (
        '<gpx xmlns="http://www.topografix.com/GPX/1/1">'
        '<wpt lat="49" lon="-117"><ele>12O5.3</ele><name>B12</name></wpt></gpx>'
    )
    with pytest.raises(InputFileError, match="waypoint 1 \\('B12'\\): <ele> '12O5.3'"):
        read_impacts(write(tmp_path, "ele.gpx", text))


def test_waypoint_type_round_trips_as_material(tmp_path):
    frame = sample_frame()
    frame["material"] = ["rock", "talus", None, "rock"]
    path = tmp_path / "typed.gpx"
    write_gpx_waypoints(path, frame)
    assert path.read_text().count("<type>") == 3
    assert read_gpx_waypoints(path)["type"].isna().tolist() == [
        False,
        False,
        True,
        False,
    ]
    points = read_impacts(path)
    assert points.frame["material"].tolist()[:2] == ["rock", "talus"]
    assert pd.isna(points.frame["material"].iloc[2])
    assert any("<type>" in note for note in points.notes)


def test_bundled_tornado_survey_reads(repo):
    folder = repo / "surveys" / "tornado_mountain"
    if not (folder / "boulder_a_impacts.gpx").exists():
        pytest.skip("surveys not generated")
    points = read_impacts(folder / "boulder_a_impacts.gpx")
    section = read_impacts(folder / "boulder_a_section.csv")
    assert points.names == section.names
    assert "material" in points.frame and points.frame["material"].notna().all()
    # GPX positions were placed from the section x: x must come back to 1 cm.
    np.testing.assert_allclose(points.frame["x_m"], section.frame["x_m"], atol=0.01)


def test_whitespace_only_gpx_is_empty(tmp_path):
    with pytest.raises(InputFileError, match="blank.gpx: file is empty"):
        read_gpx_waypoints(write(tmp_path, "blank.gpx", "  \n\n"))
