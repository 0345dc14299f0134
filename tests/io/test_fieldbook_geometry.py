"""Rangefinder field book: target positions against independent geometry."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pyproj
import pytest

from fieldkit.errors import InputFileError
from fieldkit.io.fieldbook import read_fieldbook
from fieldkit.io.gpx import write_gpx_waypoints
from fieldkit.io.trupulse import format_trupulse_hv, nmea_checksum

STATION = {"station": "S1", "lat": 49.51234, "lon": -117.43210, "elev": 1602.40}
HEADER = "point,station,instrument_height_m,target_height_m,sentence\n"


def stations_csv(tmp_path, rows=None):
    rows = rows or [STATION]
    text = "station,lat,lon,elev_m\n" + "".join(
        f"{r['station']},{r['lat']},{r['lon']},{r['elev']}\n" for r in rows
    )
    path = tmp_path / "stations.csv"
    path.write_text(text)
    return path


def fieldbook(tmp_path, lines, name="book.csv"):
    path = tmp_path / name
    path.write_text(HEADER + "".join(lines))
    return path


def shot_line(point, station, ih, th, hd, az, inc, units="M", sd=True):
    slope = hd / math.cos(math.radians(inc)) if sd else math.nan
    sentence = format_trupulse_hv(hd, az, inc, slope, units=units)
    return f'{point},{station},{ih},{th},"{sentence}"\n'


def enu_offset(lat0, lon0, h0, lat, lon, h):
    """East/north/up of a point from a station via ECEF (independent of pyproj.Geod)."""
    to_ecef = pyproj.Transformer.from_crs(4979, 4978, always_xy=True)
    x0, y0, z0 = to_ecef.transform(lon0, lat0, h0)
    x1, y1, z1 = to_ecef.transform(lon, lat, h)
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    phi, lam = math.radians(lat0), math.radians(lon0)
    east = -math.sin(lam) * dx + math.cos(lam) * dy
    north = (
        -math.sin(phi) * math.cos(lam) * dx
        - math.sin(phi) * math.sin(lam) * dy
        + math.cos(phi) * dz
    )
    return east, north


def test_hand_case_hundred_metres_north(tmp_path):
    book = fieldbook(tmp_path, [shot_line("A1", "S1", 1.5, 0.0, 100.0, 0.0, 0.0)])
    points = read_fieldbook(book, stations_csv(tmp_path), declination_deg=0.0)
    frame = points.frame
    assert frame["lat_deg"].iloc[0] - STATION["lat"] == pytest.approx(0.0009, abs=2e-6)
    assert frame["lon_deg"].iloc[0] == pytest.approx(STATION["lon"], abs=1e-12)
    assert frame["z_m"].iloc[0] == pytest.approx(STATION["elev"] + 1.5, abs=1e-9)
    assert frame["x_m"].iloc[0] == 0.0
    assert points.crs == "EPSG:32611"


def test_targets_match_independent_positions(tmp_path):
    """Shots with known azimuths, distances and inclinations from a GPX station.

    Truth: Geod.fwd for the target, then an independent ECEF->ENU check of the
    horizontal offset, and the elevation from the definition z = zs + ih + SD sin(INC)
    - th. The sentences round to 0.01 m / 0.01 deg as the instrument does.
    """
    declination = 15.8
    rng = np.random.default_rng(7)
    shots = []
    for i in range(8):
        shots.append(
            (
                f"B{i + 1}",
                rng.uniform(1.2, 1.7),
                rng.uniform(0.0, 2.0),
                rng.uniform(15.0, 300.0),
                rng.uniform(0.0, 360.0),
                rng.uniform(-40, 20),
            )
        )
    gpx = tmp_path / "stations.gpx"
    write_gpx_waypoints(
        gpx,
        pd.DataFrame(
            {
                "point": ["S0", "S1"],
                "lat_deg": [49.6, STATION["lat"]],
                "lon_deg": [-117.5, STATION["lon"]],
                "elev_m": [np.nan, STATION["elev"]],
            }
        ),
    )
    lines = [
        shot_line(p, "S1", f"{ih:.3f}", f"{th:.3f}", hd, (az - declination) % 360, inc)
        for p, ih, th, hd, az, inc in shots
    ]
    points = read_fieldbook(
        fieldbook(tmp_path, lines), gpx, declination_deg=declination
    )
    frame = points.frame
    geod = pyproj.Geod(ellps="WGS84")
    for row, (_, ih, th, hd, az, inc) in zip(frame.itertuples(), shots, strict=True):
        lon_true, lat_true, _ = geod.fwd(STATION["lon"], STATION["lat"], az, hd)
        east, north = enu_offset(
            STATION["lat"], STATION["lon"], 0.0, row.lat_deg, row.lon_deg, 0.0
        )
        # 0.005 m of distance and 0.005 deg of azimuth rounding: < 0.03 m at 300 m.
        err = hd * math.radians(0.005) + 0.005 + 1e-3
        assert (
            math.hypot(
                east - hd * math.sin(math.radians(az)),
                north - hd * math.cos(math.radians(az)),
            )
            < err
        )
        _, _, miss = geod.inv(lon_true, lat_true, row.lon_deg, row.lat_deg)
        assert miss < err
        z_true = (
            STATION["elev"]
            + float(f"{ih:.3f}")
            + hd * math.tan(math.radians(inc))
            - float(f"{th:.3f}")
        )
        assert row.z_m == pytest.approx(z_true, abs=0.005 + hd * math.radians(0.005))
    steps = [
        geod.inv(a.lon_deg, a.lat_deg, b.lon_deg, b.lat_deg)[2]
        for a, b in zip(
            frame.iloc[:-1].itertuples(), frame.iloc[1:].itertuples(), strict=True
        )
    ]
    np.testing.assert_allclose(frame["x_m"].to_numpy()[1:], np.cumsum(steps), atol=1e-6)


def test_vertical_from_hd_tan_when_sd_missing_and_feet(tmp_path):
    hd_ft = 200.0
    body = f"PLTIT,HV,{hd_ft:.2f},F,90.00,D,-12.50,D,,"
    line = f'C1,S1,5.0,0.0,"${body}*{nmea_checksum(body)}"\n'
    points = read_fieldbook(
        fieldbook(tmp_path, [line]), stations_csv(tmp_path), declination_deg=0.0
    )
    rise = hd_ft * 0.3048 * math.tan(math.radians(-12.5))
    assert points.frame["z_m"].iloc[0] == pytest.approx(STATION["elev"] + 5.0 + rise)
    _, _, distance = pyproj.Geod(ellps="WGS84").inv(
        STATION["lon"],
        STATION["lat"],
        points.frame["lon_deg"].iloc[0],
        points.frame["lat_deg"].iloc[0],
    )
    assert distance == pytest.approx(hd_ft * 0.3048, abs=1e-6)


def test_unquoted_sentence_in_last_column(tmp_path):
    sentence = format_trupulse_hv(50.0, 45.0, 0.0, 50.0)
    book = fieldbook(tmp_path, [f"D1,S1,1.5,1.5,{sentence}\n"])
    points = read_fieldbook(book, stations_csv(tmp_path), declination_deg=0.0)
    assert points.frame["z_m"].iloc[0] == pytest.approx(STATION["elev"])


def test_ft_heights_and_notes(tmp_path):
    book = tmp_path / "ft.csv"
    book.write_text(
        "point,station,ih,th,sentence\n"
        + shot_line("E1", "S1", 5.0, 0.0, 30.0, 0.0, 0.0)
        + shot_line("E2", "S1", 5.0, 0.0, 60.0, 0.0, 0.0)
    )
    points = read_fieldbook(
        book, stations_csv(tmp_path), units="ft", declination_deg=0.0
    )
    assert points.frame["z_m"].tolist() == pytest.approx([STATION["elev"] + 1.524] * 2)
    assert any("TruPulse 200 has no compass" in note for note in points.notes)


# --- bad input -----------------------------------------------------------------------


def test_bad_checksum_names_row_and_point(tmp_path):
    good = format_trupulse_hv(40.0, 10.0, -5.0, 40.2)
    bad = good.replace("40.00", "41.00")
    book = fieldbook(
        tmp_path, [shot_line("A1", "S1", 1.5, 0, 20, 0, 0), f'A2,S1,1.5,0,"{bad}"\n']
    )
    with pytest.raises(InputFileError) as error:
        read_fieldbook(book, stations_csv(tmp_path), declination_deg=0.0)
    message = str(error.value)
    assert message.startswith(f"{book}: row 3 (point A2): bad TruPulse checksum")
    lenient = read_fieldbook(
        book, stations_csv(tmp_path), lenient=True, declination_deg=0.0
    )
    assert len(lenient) == 2
    assert any("checksum wrong, accepted" in note for note in lenient.notes)


def test_unknown_station_named(tmp_path):
    book = fieldbook(tmp_path, [shot_line("A1", "S9", 1.5, 0, 20, 0, 0)])
    stations = stations_csv(tmp_path)
    with pytest.raises(InputFileError) as error:
        read_fieldbook(book, stations, declination_deg=0.0)
    assert str(error.value) == (
        f"{book}: row 2 (point A1): station 'S9' is not in {stations} "
        "(stations there: S1)"
    )


def test_station_without_elevation_in_gpx(tmp_path):
    gpx = tmp_path / "st.gpx"
    write_gpx_waypoints(
        gpx, pd.DataFrame({"point": ["S1"], "lat_deg": [49.0], "lon_deg": [-117.0]})
    )
    book = fieldbook(tmp_path, [shot_line("A1", "S1", 1.5, 0, 20, 0, 0)])
    with pytest.raises(InputFileError, match="station 'S1' has no elevation"):
        read_fieldbook(book, gpx, declination_deg=0.0)


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ('A1,S1,1.5,0,"$PLTIT,HT,5.50,M*36"\n', "HT sentence gives no target position"),
        ('A1,S1,1.5,0,"$PLTIT,HV,,,0.00,D,29.10,D,,*5D"\n', "inclination-only"),
        (
            'A1,S1,one,0,"$PLTIT,HT,5.50,M*36"\n',
            "row 2: column 'instrument_height_m': 'one' is not a number",
        ),
    ],
)
def test_unusable_shots(tmp_path, line, message):
    with pytest.raises(InputFileError, match=message):
        read_fieldbook(
            fieldbook(tmp_path, [line]), stations_csv(tmp_path), declination_deg=0.0
        )


def test_duplicated_point_in_fieldbook(tmp_path):
    lines = [
        shot_line("A1", "S1", 1.5, 0, 20, 0, 0),
        shot_line("A1", "S1", 1.5, 0, 30, 0, 0),
    ]
    with pytest.raises(
        InputFileError, match="point 'A1' appears twice \\(row 2 and row 3\\)"
    ):
        read_fieldbook(
            fieldbook(tmp_path, lines), stations_csv(tmp_path), declination_deg=0.0
        )


def test_missing_columns_and_files(tmp_path):
    book = tmp_path / "short.csv"
    book.write_text("point,station,sentence\nA1,S1,x\n")
    with pytest.raises(
        InputFileError, match="missing instrument_height_m, target_height_m"
    ):
        read_fieldbook(book, stations_csv(tmp_path), declination_deg=0.0)
    with pytest.raises(InputFileError, match="nostations.csv: file not found"):
        read_fieldbook(
            fieldbook(tmp_path, [shot_line("A1", "S1", 1.5, 0, 20, 0, 0)]),
            tmp_path / "nostations.csv",
            declination_deg=0.0,
        )


def test_negative_heights_and_bad_declination(tmp_path):
    from fieldkit.errors import ArgumentError

    book = fieldbook(tmp_path, [shot_line("A1", "S1", -1.5, 0, 20, 0, 0)])
    with pytest.raises(InputFileError, match="row 2 \\(point A1\\): instrument and"):
        read_fieldbook(book, stations_csv(tmp_path), declination_deg=0.0)
    with pytest.raises(ArgumentError, match="declination_deg"):
        read_fieldbook(book, stations_csv(tmp_path), declination_deg=400.0)


def test_stations_csv_aliases_and_duplicates(tmp_path):
    from fieldkit.io.stations import read_stations

    path = tmp_path / "st.csv"
    path.write_text("Name;Latitude;Longitude;Elevation (ft)\nS1;49,5;-117,25;5000\n")
    stations = read_stations(path)
    row = stations.lookup("S1")
    assert (row["lat_deg"], row["lon_deg"]) == (49.5, -117.25)
    assert row["elev_m"] == pytest.approx(5000 * 0.3048)
    assert stations.lookup("S2") is None
    path.write_text("station,lat,lon,elev_m\nS1,49,-117,1\nS1,49.1,-117,2\n")
    with pytest.raises(
        InputFileError, match="'S1' appears twice \\(row 2 and row 3\\)"
    ):
        read_stations(path)
    path.write_text("station,lat,lon\nS1,49,-117\n")
    with pytest.raises(InputFileError, match="missing elev"):
        read_stations(path)
