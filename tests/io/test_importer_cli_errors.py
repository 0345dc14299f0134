"""Importer bad input through `fieldkit reduce`: one line, non-zero exit, no output.

Every case checks: exit code != 0, the specific message (file and row/point) on
stderr as a single line, no output file written, the input files unchanged.
"""

from __future__ import annotations

import pandas as pd
import pytest

from fieldkit.io.gpx import write_gpx_waypoints
from fieldkit.io.trupulse import format_trupulse_hv

BODY = ["--theta0", "32.6", "--mass", "3750", "--radius", "0.725", "--gyration", "0.46"]


def good_impacts(tmp_path, name="impacts.gpx", **changes):
    frame = pd.DataFrame(
        {
            "point": ["A", "B", "C", "D"],
            "lat_deg": [49.9712, 49.97112, 49.97100, 49.97085],
            "lon_deg": [-114.6804, -114.68025, -114.68008, -114.67990],
            "elev_m": [1702.0, 1696.5, 1690.2, 1683.0],
        }
    )
    for column, (row, value) in changes.items():
        frame.loc[row, column] = value
    path = tmp_path / name
    write_gpx_waypoints(path, frame)
    return path


def run_and_check(cli, tmp_path, args, expected, inputs):
    before = {p: p.read_bytes() for p in inputs if p.exists()}
    out = tmp_path / "out" / "table.csv"
    result = cli("reduce", *args, *BODY, "-o", out)
    assert result.exit_code not in (0, None), result.stdout
    message = result.stderr.strip()
    assert expected in message, message
    assert len(message.splitlines()) == 1, message
    assert not out.exists()
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
    for path, data in before.items():
        assert path.read_bytes() == data
    return message


def test_missing_file(cli, tmp_path):
    missing = tmp_path / "nowhere.gpx"
    run_and_check(
        cli, tmp_path, ["--impacts", missing], f"{missing}: file not found", []
    )


def test_empty_file(cli, tmp_path):
    empty = tmp_path / "empty.gpx"
    empty.write_text("")
    run_and_check(
        cli, tmp_path, ["--impacts", empty], "empty.gpx: file is empty", [empty]
    )


def test_truncated_gpx(cli, tmp_path):
    path = good_impacts(tmp_path)
    text = path.read_text()
    path.write_text(text[: len(text) // 2])
    line = text[: len(text) // 2].count("\n") + 1
    run_and_check(
        cli,
        tmp_path,
        ["--impacts", path],
        f"GPX is truncated or malformed (XML error at line {line})",
        [path],
    )


def test_binary_gpx(cli, tmp_path):
    path = tmp_path / "garbage.gpx"
    path.write_bytes(bytes(range(256)) * 4)
    run_and_check(
        cli, tmp_path, ["--impacts", path], "garbage.gpx: not a GPX file", [path]
    )


def test_waypoint_without_elevation(cli, tmp_path):
    path = good_impacts(tmp_path, elev_m=(2, float("nan")))
    run_and_check(
        cli,
        tmp_path,
        ["--impacts", path],
        "waypoint 3: waypoint 'C' has no elevation (<ele>)",
        [path],
    )


def test_duplicated_point(cli, tmp_path):
    path = good_impacts(tmp_path, point=(3, "B"))
    run_and_check(
        cli,
        tmp_path,
        ["--impacts", path],
        "point B: point 'B' appears twice (waypoint 2 and waypoint 4)",
        [path],
    )


def test_text_in_a_number(cli, tmp_path):
    path = tmp_path / "impacts.csv"
    path.write_text("point,x_m,z_m\nA,0,100\nB,5.2,96\nC,1O.4,90\n")
    run_and_check(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: row 4: column 'x_m': '1O.4' is not a number",
        [path],
    )


def test_tree_after_unknown_impact(cli, tmp_path):
    impacts = good_impacts(tmp_path)
    trees = tmp_path / "trees.csv"
    trees.write_text(
        "after_impact,horizontal_distance_m,strike_height_m\nA,5,1.2\nQ,4,1.5\n"
    )
    run_and_check(
        cli,
        tmp_path,
        ["--impacts", impacts, "--trees", trees],
        f"{trees}: row 3: tree strike after impact 'Q', which is not an impact",
        [impacts, trees],
    )


def test_bad_trupulse_checksum(cli, tmp_path):
    stations = tmp_path / "stations.csv"
    stations.write_text("station,lat,lon,elev_m\nS1,49.9712,-114.6804,1700\n")
    good = [format_trupulse_hv(d, 120.0, -20.0, d / 0.9397) for d in (10, 20, 30)]
    bad = good[1].replace("120.00", "121.00")  # checksum no longer matches
    book = tmp_path / "book.csv"
    book.write_text(
        "point,station,instrument_height_m,target_height_m,sentence\n"
        f'A,S1,1.6,0,"{good[0]}"\nB,S1,1.6,0,"{bad}"\nC,S1,1.6,0,"{good[2]}"\n'
    )
    message = run_and_check(
        cli,
        tmp_path,
        ["--fieldbook", book, "--stations", stations, "--declination", "0"],
        f"{book}: row 3 (point B): bad TruPulse checksum",
        [book, stations],
    )
    assert "*" in message


@pytest.mark.parametrize("which", ["impacts", "trees"])
def test_units_and_folder_inputs(cli, tmp_path, which):
    impacts = good_impacts(tmp_path)
    args = (
        ["--impacts", tmp_path]
        if which == "impacts"
        else ["--impacts", impacts, "--trees", tmp_path]
    )
    run_and_check(cli, tmp_path, args, "is a folder, not a file", [impacts])
