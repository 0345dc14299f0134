"""No silent misreads in delimited files, through `fieldkit reduce` and `view`.

The checks live once in fieldkit/io/csv_table.py (cell count, ambiguous columns,
units, quotes, encodings, line length); every case here is run through the command
line: exit code != 0, one line naming the file, row and cause, nothing written, the
inputs unchanged. The cases that read are run to the end and their values checked.
"""

from __future__ import annotations

import pandas as pd
import pytest

from fieldkit.io.gpx import write_gpx_waypoints
from fieldkit.io.trupulse import format_trupulse_hv

BODY = ["--theta0", "32.6", "--mass", "3750", "--radius", "0.725", "--gyration", "0.46"]
#: a section that reduces with BODY (four impacts down a 35 degree slope)
SECTION = [
    ("A", "0", "100"),
    ("B", "5.2", "96"),
    ("C", "10.4", "90"),
    ("D", "16", "83"),
]
STATION = "S1,49.9712,-114.6804,1700"


def section_text(sep: str = ",", header: str = "point,x_m,z_m", rows=SECTION) -> str:
    lines = [header.replace(",", sep)] + [sep.join(row) for row in rows]
    return "\n".join(lines) + "\n"


def reduce_fails(cli, tmp_path, args, *expected, inputs=()):
    """Run reduce; one error line holding every ``expected``; nothing written."""
    before = {p: p.read_bytes() for p in inputs}
    out = tmp_path / "out" / "table.csv"
    result = cli("reduce", *args, *BODY, "-o", out)
    assert result.exit_code not in (0, None), result.stdout
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    for text in expected:
        assert text in lines[0], (text, lines[0])
    assert not (tmp_path / "out").exists()
    for path, data in before.items():
        assert path.read_bytes() == data
    return lines[0]


def reduce_reads(cli, tmp_path, args) -> pd.DataFrame:
    out = tmp_path / "table.csv"
    result = cli("reduce", *args, *BODY, "-o", out)
    assert result.exit_code == 0, result.stderr
    return pd.read_csv(out)


def write(tmp_path, name, text, encoding="utf-8"):
    path = tmp_path / name
    path.write_bytes(text.encode(encoding) if isinstance(text, str) else text)
    return path


def gpx_impacts(tmp_path):
    path = tmp_path / "impacts.gpx"
    frame = pd.DataFrame(
        {
            "point": ["A", "B", "C", "D"],
            "lat_deg": [49.9712, 49.97112, 49.97100, 49.97085],
            "lon_deg": [-114.6804, -114.68025, -114.68008, -114.67990],
            "elev_m": [1702.0, 1696.5, 1690.2, 1683.0],
        }
    )
    write_gpx_waypoints(path, frame)
    return path


def fieldbook_files(tmp_path, header, stations_header="station,lat,lon,elev_m"):
    shots = [format_trupulse_hv(d, 120.0, -20.0, d / 0.9397) for d in (10, 20, 30)]
    book = write(
        tmp_path,
        "book.csv",
        header
        + "\n"
        + "".join(f'{p},S1,1.6,0,"{s}"\n' for p, s in zip("ABC", shots, strict=True)),
    )
    stations = write(tmp_path, "stations.csv", f"{stations_header}\n{STATION}\n")
    return book, stations


# --- every row has as many cells as the header ---------------------------------------


@pytest.mark.parametrize(
    ("row", "counts"),
    [
        (("B", "5.2", "96", "7"), "4 cells for 3 columns"),
        (("B", "5.2"), "2 cells for 3"),
    ],
)
def test_row_with_more_or_fewer_cells_than_the_header(cli, tmp_path, row, counts):
    rows = [SECTION[0], row, *SECTION[2:]]
    path = write(tmp_path, "impacts.csv", "# survey\n\n" + section_text(rows=rows))
    # comment, blank line and header are lines 1-3 (skipped but counted): B is line 5
    message = reduce_fails(
        cli, tmp_path, ["--impacts", path], f"{path}: row 5: {counts}", inputs=[path]
    )
    assert "(point, x_m, z_m)" in message


def test_trailing_separator_is_not_an_extra_cell(cli, tmp_path):
    text = section_text().replace("\n", ",\n")  # header and rows end with a comma
    table = reduce_reads(cli, tmp_path, ["--impacts", write(tmp_path, "t.csv", text)])
    assert table["x_m"].tolist() == [0.0, 5.2, 10.4, 16.0]


# --- decimal commas ------------------------------------------------------------------


@pytest.mark.parametrize("sep", [";", "\t"])
def test_decimal_commas_read_with_a_semicolon_or_tab(cli, tmp_path, sep):
    rows = [(p, x.replace(".", ","), z + ",5") for p, x, z in SECTION]
    path = write(tmp_path, "eu.csv", section_text(sep, rows=rows))
    table = reduce_reads(cli, tmp_path, ["--impacts", path])
    assert table["x_m"].tolist() == [0.0, 5.2, 10.4, 16.0]
    assert table["z_m"].tolist() == [100.5, 96.5, 90.5, 83.5]


def test_decimal_comma_with_a_comma_separator_is_caught(cli, tmp_path):
    rows = [SECTION[0], ("B", "5,2", "96"), *SECTION[2:]]
    path = write(tmp_path, "c.csv", section_text(rows=rows))
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        "row 3: 4 cells for 3 columns",
        "decimal commas with a comma separator",
        inputs=[path],
    )


def test_quoted_decimal_comma_with_a_comma_separator_is_caught(cli, tmp_path):
    rows = [SECTION[0], ("B", '"5,2"', "96"), *SECTION[2:]]
    path = write(tmp_path, "q.csv", section_text(rows=rows))
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        "row 3: column 'x_m': '5,2' has a comma in a comma-separated file",
        inputs=[path],
    )


# --- two columns for one quantity ----------------------------------------------------


@pytest.mark.parametrize(
    ("header", "row", "both"),
    [
        ("point,x_m,x_ft,z_m", "{p},{x},0,{z}", "'x_m' and 'x_ft'"),
        ("point,x_m,elev,elevation_m", "{p},{x},{z},{z}", "'elev' and 'elevation_m'"),
        (
            "point,lat,latitude,lon,elev_m",
            "{p},49.97,49.97,-114.68,{z}",
            "'lat' and 'latitude'",
        ),
        ("point,name,x_m,z_m", "{p},{p},{x},{z}", "'point' and 'name'"),
    ],
)
def test_two_impact_columns_for_one_quantity(cli, tmp_path, header, row, both):
    text = (
        header + "\n" + "".join(row.format(p=p, x=x, z=z) + "\n" for p, x, z in SECTION)
    )
    path = write(tmp_path, "two.csv", text)
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: row 1: columns {both}",
        inputs=[path],
    )


def test_two_tree_columns_for_one_quantity(cli, tmp_path):
    impacts = gpx_impacts(tmp_path)
    trees = write(
        tmp_path,
        "trees.csv",
        "after_impact,horizontal_distance_m,distance_ft,strike_height_m\nA,5,16,1.2\n",
    )
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", impacts, "--trees", trees],
        f"{trees}: row 1: columns 'horizontal_distance_m' and 'distance_ft' both give",
        inputs=[impacts, trees],
    )


@pytest.mark.parametrize(
    ("book_header", "stations_header", "culprit", "both"),
    [
        (
            "point,station,instrument_height_m,ih,target_height_m,sentence",
            "station,lat,lon,elev_m",
            "book.csv",
            "'instrument_height_m' and 'ih'",
        ),
        (
            "point,station,instrument_height_m,target_height_m,sentence",
            "station,lat,lon,elev,elevation_m",
            "stations.csv",
            "'elev' and 'elevation_m'",
        ),
    ],
)
def test_two_fieldbook_or_station_columns_for_one_quantity(
    cli, tmp_path, book_header, stations_header, culprit, both
):
    book, stations = fieldbook_files(tmp_path, book_header, stations_header)
    if "ih" in book_header.split(","):  # give the extra column its cells
        book.write_text(book.read_text().replace(",S1,1.6,", ",S1,1.6,1.6,"))
    if "elevation_m" in stations_header:
        stations.write_text(stations.read_text().replace(",1700", ",1700,1700"))
    reduce_fails(
        cli,
        tmp_path,
        ["--fieldbook", book, "--stations", stations, "--declination", "0"],
        f"{culprit}: row 1: columns {both}",
        inputs=[book, stations],
    )


# --- lengths need a unit -------------------------------------------------------------


def test_section_without_units_needs_the_units_option(cli, tmp_path):
    path = write(tmp_path, "plain.csv", section_text(header="point,x,z"))
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: row 1: column 'x' has no length unit",
        "'x_m'",
        "--units",
        inputs=[path],
    )
    metres = reduce_reads(cli, tmp_path, ["--impacts", path, "--units", "m"])
    feet = reduce_reads(cli, tmp_path, ["--impacts", path, "--units", "ft"])
    assert metres["x_m"].tolist() == [0.0, 5.2, 10.4, 16.0]
    assert feet["x_m"].tolist() == pytest.approx(
        [0.0, 5.2 * 0.3048, 10.4 * 0.3048, 16 * 0.3048]
    )


def test_unit_in_the_header_needs_no_option(cli, tmp_path):
    header = "point,x (ft),Elevation (ft)"
    path = write(tmp_path, "ft.csv", section_text(header=header))
    table = reduce_reads(cli, tmp_path, ["--impacts", path])
    assert table["z_m"].tolist() == pytest.approx(
        [100 * 0.3048, 96 * 0.3048, 90 * 0.3048, 83 * 0.3048]
    )


def test_gpx_elevations_need_no_units(cli, tmp_path):
    table = reduce_reads(cli, tmp_path, ["--impacts", gpx_impacts(tmp_path)])
    assert table["z_m"].iloc[0] == 1702.0


def test_tree_lengths_need_a_unit(cli, tmp_path):
    impacts = gpx_impacts(tmp_path)
    trees = write(
        tmp_path,
        "trees.csv",
        "after_impact,horizontal_distance_m,strike_height\nA,5,1.2\n",
    )
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", impacts, "--trees", trees],
        f"{trees}: row 1: column 'strike_height' has no length unit",
        "--units",
        inputs=[impacts, trees],
    )


@pytest.mark.parametrize(
    ("book_header", "stations_header", "message"),
    [
        (
            "point,station,ih,target_height_m,sentence",
            "station,lat,lon,elev_m",
            "book.csv: row 1: column 'ih' has no length unit",
        ),
        (
            "point,station,instrument_height_m,target_height_m,sentence",
            "station,lat,lon,elev",
            "stations.csv: row 1: column 'elev' has no length unit",
        ),
    ],
)
def test_fieldbook_and_station_lengths_need_a_unit(
    cli, tmp_path, book_header, stations_header, message
):
    book, stations = fieldbook_files(tmp_path, book_header, stations_header)
    args = ["--fieldbook", book, "--stations", stations, "--declination", "0"]
    reduce_fails(cli, tmp_path, args, message, "--units", inputs=[book, stations])
    table = reduce_reads(cli, tmp_path, [*args, "--units", "m"])
    assert table["point"].tolist() == ["A", "B", "C"]


# --- quotes, sizes, encodings --------------------------------------------------------


def test_unterminated_quote_is_reported_where_it_opens(cli, tmp_path):
    rows = [SECTION[0], ('"B', "5.2", "96"), *SECTION[2:]]
    path = write(tmp_path, "quote.csv", section_text(rows=rows))
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: row 3: a quote opened in this row never closes",
        inputs=[path],
    )


def test_unterminated_quote_in_a_long_file_is_reported_where_it_opens(cli, tmp_path):
    rows = [SECTION[0], ('"B', "5.2", "96")] + [("P", "1", "2")] * 30_000
    path = write(tmp_path, "long.csv", section_text(rows=rows))
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: row 3: a quoted cell opened in this row runs on past line",
        inputs=[path],
    )


def test_text_after_a_closing_quote(cli, tmp_path):
    rows = [SECTION[0], ('"B"x', "5.2", "96"), *SECTION[2:]]
    path = write(tmp_path, "after.csv", section_text(rows=rows))
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: row 3: text after a closing quote",
        inputs=[path],
    )


def test_oversized_cell(cli, tmp_path):
    big = ("B" * 1_100_000, "5.2", "96")
    path = write(
        tmp_path, "big.csv", section_text(rows=[SECTION[0], big, *SECTION[2:]])
    )
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: row 3: line is {len(','.join(big))} characters long (at most 131072)",
        inputs=[path],
    )


def test_oversized_quoted_cell_spanning_lines(cli, tmp_path):
    long_note = "\n".join(["note " * 20] * 2000)  # 200 kB in one quoted cell
    rows = [SECTION[0], ("B", "5.2", "96", f'"{long_note}"'), *SECTION[2:]]
    header = "point,x_m,z_m,comment"
    rows = [r if len(r) == 4 else (*r, "") for r in rows]
    path = write(tmp_path, "note.csv", section_text(header=header, rows=rows))
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: row 3: a quoted cell opened in this row runs on past line",
        inputs=[path],
    )


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be", "utf-16-le", "utf-32"])
def test_utf16_csv_says_save_as_utf8(cli, tmp_path, encoding):
    path = write(tmp_path, "wide.csv", section_text(), encoding=encoding)
    name = "UTF-32" if "32" in encoding else "UTF-16"
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: {name} encoded; save it as UTF-8",
        inputs=[path],
    )


def test_utf16_trees_and_stations_say_save_as_utf8(cli, tmp_path):
    impacts = gpx_impacts(tmp_path)
    trees = write(
        tmp_path,
        "trees.csv",
        "after_impact,horizontal_distance_m,strike_height_m\nA,5,1.2\n",
        encoding="utf-16",
    )
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", impacts, "--trees", trees],
        f"{trees}: UTF-16 encoded; save it as UTF-8",
        inputs=[impacts, trees],
    )
    book, stations = fieldbook_files(
        tmp_path, "point,station,instrument_height_m,target_height_m,sentence"
    )
    stations.write_bytes(stations.read_text().encode("utf-16"))
    reduce_fails(
        cli,
        tmp_path,
        ["--fieldbook", book, "--stations", stations, "--declination", "0"],
        f"{stations}: UTF-16 encoded; save it as UTF-8",
        inputs=[book, stations],
    )


def test_binary_file_named_csv(cli, tmp_path):
    path = write(
        tmp_path, "photo.csv", b"\xff\xd8\xff\xe0\x00\x10JFIF" + bytes(range(256)) * 8
    )
    reduce_fails(
        cli,
        tmp_path,
        ["--impacts", path],
        f"{path}: not a text CSV file (binary",
        inputs=[path],
    )


# --- GPX entities --------------------------------------------------------------------

BILLION_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE gpx [
  <!ENTITY lol "lol">
  <!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
  <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
]>
<gpx version="1.1" xmlns="http://www.topografix.com/GPX/1/1">
  <wpt lat="49.97" lon="-114.68"><ele>1700</ele><name>&lol3;</name></wpt>
</gpx>
"""


@pytest.mark.parametrize("option", ["--impacts", "--stations"])
def test_gpx_with_entities_is_refused(cli, tmp_path, option):
    gpx = write(tmp_path, "laughs.gpx", BILLION_LAUGHS)
    if option == "--impacts":
        args, inputs = ["--impacts", gpx], [gpx]
    else:
        book, _ = fieldbook_files(
            tmp_path, "point,station,instrument_height_m,target_height_m,sentence"
        )
        args, inputs = (
            ["--fieldbook", book, "--stations", gpx, "--declination", "0"],
            [book, gpx],
        )
    reduce_fails(
        cli,
        tmp_path,
        args,
        f"{gpx}: line 2: GPX declares <!DOCTYPE",
        "not allowed",
        inputs=inputs,
    )


# --- Tracker exports through `view` --------------------------------------------------


def view_fails(cli, tmp_path, path, *expected, args=()):
    out = tmp_path / "out.rrd"
    before = path.read_bytes()
    result = cli("view", path, "--radius", "0.0375", *args, "-o", out)
    assert result.exit_code not in (0, None), result.stdout
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    for text in expected:
        assert text in lines[0], (text, lines[0])
    assert not out.exists() and path.read_bytes() == before


def test_tracker_export_without_y(cli, tmp_path):
    path = write(tmp_path, "ball.txt", "ball\nt\tx\tv_{x}\n0\t1\t2\n0,1\t1,5\t2\n")
    view_fails(
        cli,
        tmp_path,
        path,
        f"{path}: row 2: the y column is missing (columns found: t, x, v_{{x}})",
    )


def test_tracker_export_with_decimal_commas_and_comma_separator(cli, tmp_path):
    path = write(tmp_path, "ball.csv", "ball\nt,x,y\n0,0,1,5,2,0\n")
    view_fails(
        cli,
        tmp_path,
        path,
        f"{path}: row 3: 6 cells for 3 columns (t, x, y)",
        "decimal commas with a comma separator",
        args=["--format", "tracker"],
    )


def test_tracker_export_in_utf16(cli, tmp_path):
    path = write(tmp_path, "ball.txt", "ball\nt\tx\ty\n0\t1\t2\n", encoding="utf-16")
    view_fails(cli, tmp_path, path, f"{path}: UTF-16 encoded; save it as UTF-8")


def test_tracker_export_with_an_oversized_line(cli, tmp_path):
    line = "0\t" + "1" * 200_000 + "\t2"
    path = write(tmp_path, "ball.txt", f"ball\nt\tx\ty\n{line}\n")
    view_fails(
        cli,
        tmp_path,
        path,
        f"{path}: row 3: line is {len(line)} characters long (at most 131072)",
    )
