"""Reading Kinovea CSV exports (sample files: tests/io/data/README.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.kinovea import read_kinovea
from fieldkit.tracking.flights.ballistic_fit import fit_flight

DATA = Path(__file__).parent / "data"


def truth(t):
    return 0.2 + 1.5 * t, 1.0 + 2.0 * t - 0.5 * 9.81 * t**2


def test_raw_export_semicolon_decimal_comma_pixels_y_down():
    tr = read_kinovea(
        DATA / "kinovea_raw_semicolon_px.csv",
        unit="px",
        metres_per_pixel=0.002,
        y_down=True,
    )
    assert tr.meta["point"] == "Ball/Centre" and tr.meta["delimiter"] == ";"
    assert len(tr) == 50
    # times were written in ms with 2 decimals
    np.testing.assert_allclose(tr.t, np.arange(50) / 300.0, atol=6e-6)
    x, z = truth(np.arange(50) / 300.0)
    np.testing.assert_allclose(tr.x, x, atol=1e-5)
    np.testing.assert_allclose(tr.z, z - 1.2, atol=1e-5)  # image origin 1.2 m up
    assert fit_flight(tr.t, tr.x, tr.z).g_mps2 == pytest.approx(9.81, rel=2e-3)


def test_second_point_tracked_once_keeps_its_single_row():
    tr = read_kinovea(
        DATA / "kinovea_raw_semicolon_px.csv",
        point="net",
        unit="px",
        metres_per_pixel=0.002,
        y_down=True,
    )
    assert len(tr) == 1 and tr.x[0] == pytest.approx(1.224)


def test_kinematics_export_with_units_in_the_header():
    tr = read_kinovea(DATA / "kinovea_kinematics_cm.csv")  # unit from "(cm)"
    assert tr.meta["unit"] == "cm"
    np.testing.assert_allclose(tr.t, np.arange(80) / 500.0, atol=1e-9)
    x, z = truth(tr.t)
    np.testing.assert_allclose(tr.x, x, atol=1e-6)
    np.testing.assert_allclose(tr.z, z, atol=1e-6)


def test_time_unit_and_rate_overrides():
    tr = read_kinovea(DATA / "kinovea_kinematics_cm.csv", fps=1000.0, file_fps=500.0)
    assert tr.t[1] == pytest.approx(0.001)
    with pytest.raises(ArgumentError, match="`file_fps`"):
        read_kinovea(DATA / "kinovea_kinematics_cm.csv", fps=1000.0)


def test_unit_is_required_when_the_file_does_not_say(tmp_path):
    with pytest.raises(ArgumentError, match="does not name its length unit"):
        read_kinovea(DATA / "kinovea_raw_semicolon_px.csv")
    with pytest.raises(ArgumentError, match="metres per pixel"):
        read_kinovea(DATA / "kinovea_raw_semicolon_px.csv", unit="px")


@pytest.mark.parametrize(
    ("text", "message", "where"),
    [
        ('"Frame","A/X","A/Y"\n"1","2","3"\n', "is not the time", "row 1"),
        ('"Time","Speed"\n"1","2"\n', "no X and Y coordinate columns", "row 1"),
        ('"Time","A/X","A/Y"\n"0","1","2"\n"1","x1","2"\n', "not a number", "row 3"),
        ('"Time","A/X","A/Y"\n"5","1","2"\n"1","1","2"\n', "not increasing", "row 3"),
    ],
)
def test_bad_files_name_the_row(tmp_path, text, message, where):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(InputFileError) as err:
        read_kinovea(p, unit="m")
    assert message in str(err.value) and f": {where}: " in str(err.value)


def test_unknown_point_lists_the_points():
    with pytest.raises(InputFileError, match="holds Ball/Centre, Net/Top"):
        read_kinovea(DATA / "kinovea_raw_semicolon_px.csv", point="rock", unit="m")
