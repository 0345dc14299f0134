"""`fieldkit reduce` on the command line: outputs, figures and one-line errors.

A small synthetic survey (section CSV, 10 m steps down a 31° slope) keeps these fast;
the thesis reproduction itself is in tests/reduce/test_tornado_table_2_4.py.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fieldkit.impact_table import ImpactTable

POINTS = "point,x_m,z_m\nP0,0,100\nP1,10,94\nP2,20,88\nP3,30,82\nP4,40,76\n"
BODY = ("--mass", "1000", "--radius", "0.5", "--gyration", "0.3")
BOULDER = ("--shape", "ellipsoid", "--dimensions", "1.6,1.3,1.3")


def reduce_with_trees(cli, impacts, trees, *options):
    """``fieldkit reduce`` of impacts with tree strikes, theta0 = 30° and BODY."""
    inputs = ("--impacts", impacts, "--trees", trees, "--theta0", "30")
    return cli("reduce", *inputs, *BODY, *options)


@pytest.fixture()
def survey(tmp_path):
    impacts = tmp_path / "impacts.csv"
    impacts.write_text(POINTS)
    trees = tmp_path / "trees.csv"
    trees.write_text("after_impact,horizontal_distance_m,strike_height_m\nP1,5.0,1.2\n")
    return impacts, trees


def test_help_has_a_runnable_example(cli):
    result = cli("reduce", "--help")
    assert result.exit_code == 0
    text = " ".join(result.stdout.split())
    assert (
        "fieldkit reduce --impacts surveys/tornado_mountain/boulder_a_impacts.gpx"
        in text
    )
    for option in (
        "--fieldbook",
        "--stations",
        "--trees",
        "--theta0",
        "--shape",
        "--units",
        "--path-id",
        "--declination",
        "--figures",
        "--out",
    ):
        assert option in text


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".xlsx"])
def test_every_output_format(cli, survey, tmp_path, suffix):
    impacts, trees = survey
    out = tmp_path / f"table{suffix}"
    result = reduce_with_trees(cli, impacts, trees, "-o", out)
    assert result.exit_code == 0, result.stderr
    table = ImpactTable.read(out).frame
    assert table["point"].tolist() == ["P0", "P1", "P2", "P3", "P4"]
    assert table["path_id"].iloc[0] == "impacts"  # default: the file name
    sources = table["theta0_source"].tolist()
    assert sources[:4] == ["assumed", "tree", "assumed", "assumed"]
    assert pd.isna(sources[4])  # the stopped point starts no flight
    assert np.isfinite(table["e_n"].iloc[1:4]).all()
    assert "e_n mean" in result.stdout and "lost on impacts" in result.stdout


def test_figures_are_written(cli, survey, tmp_path):
    impacts, trees = survey
    figures = tmp_path / "figs"
    result = reduce_with_trees(
        cli, impacts, trees, "--figures", figures, "-o", tmp_path / "t.csv"
    )
    assert result.exit_code == 0, result.stderr
    names = sorted(p.name for p in figures.iterdir())
    assert names == sorted(
        [
            "section.png",
            "en_theta.png",
            "et_impacts.png",
            "energy_partition.png",
            "energy_head.png",
        ]
    )
    for p in figures.iterdir():
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 10_000
    # one 'wrote <path>' line per file, the table's with its row count
    wrote = [x for x in result.stdout.splitlines() if x.startswith("wrote ")]
    assert wrote == [f"wrote {tmp_path / 't.csv'} (5 rows)"] + [
        f"wrote {figures / n}"
        for n in ("section.png", "en_theta.png", "et_impacts.png",
                  "energy_partition.png", "energy_head.png")
    ]  # fmt: skip


def test_shape_option_gives_the_table_4_1_body(cli, survey, tmp_path):
    impacts, _ = survey
    out = tmp_path / "t.csv"
    options = (*BOULDER, "--unit-weight", "26", "-o", out)
    result = cli("reduce", "--impacts", impacts, "--theta0", "30", *options)
    assert result.exit_code == 0, result.stderr
    t = pd.read_csv(out)
    assert t["mass_kg"].iloc[0] == pytest.approx(3752, abs=1)  # Table 4-1: ~3750 kg
    assert t["gyration_m"].iloc[0] == pytest.approx(0.46, abs=0.005)
    assert t["radius_m"].iloc[0] == pytest.approx(0.725)


def test_units_ft_converts_at_the_edge(cli, tmp_path):
    feet = tmp_path / "feet.csv"
    feet.write_text("point,x,z\nP0,0,328.084\nP1,32.8084,308.399\nP2,65.6168,288.714\n")
    out = tmp_path / "t.csv"
    result = cli(
        "reduce", "--impacts", feet, "--units", "ft", "--theta0", "30", "-o", out
    )
    assert result.exit_code == 0, result.stderr
    t = pd.read_csv(out)
    assert t["x_m"].tolist() == pytest.approx([0.0, 10.0, 20.0], abs=1e-4)
    assert t["z_m"].tolist() == pytest.approx([100.0, 94.0, 88.0], abs=1e-4)


# ------------------------------------------------------------------ bad input
def test_tree_strike_no_parabola_can_reach(cli, survey, tmp_path, digest):
    """A strike below the chord between the impacts: no downward parabola. That
    flight is kept unsolved, the path reduced (issue 18; it used to fail the path)."""
    impacts, _ = survey
    trees = tmp_path / "low_tree.csv"
    trees.write_text(
        "after_impact,horizontal_distance_m,strike_height_m,ground_z_m\n"
        "P2,5.0,1.0,80.0\n"
    )  # strike at 81 m, chord there at 85 m
    before = digest(trees), digest(impacts)
    out = tmp_path / "t.csv"
    result = reduce_with_trees(cli, impacts, trees, "-o", out)
    assert result.exit_code == 0, result.stderr
    reason = pd.read_csv(out)["flight_unsolved"]
    assert reason.notna().tolist() == [False, False, True, False, False]
    assert "tree row 2" in reason[2] and "P2" in reason[2]
    assert "no parabola" in reason[2]
    assert (digest(trees), digest(impacts)) == before


def test_uphill_flight_no_ballistic_path_makes(cli, tmp_path):
    """The flight P1 -> P2 rises above its launch line: unsolved, with its reason;
    the first flight is still reduced (it used to fail the whole path)."""
    impacts = tmp_path / "uphill.csv"
    impacts.write_text("point,x_m,z_m\nP0,0,100\nP1,10,94\nP2,20,97\n")
    out = tmp_path / "t.csv"
    result = cli("reduce", "--impacts", impacts, "--theta0", "30", *BODY, "-o", out)
    assert result.exit_code == 0, result.stderr
    t = pd.read_csv(out)
    assert t["flight_unsolved"][1].startswith("point P2: flight from point P1")
    assert "no ballistic path" in t["flight_unsolved"][1]
    assert np.isfinite(t["vi_x_mps"][1]) and np.isnan(t["vf_x_mps"][1])


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("--impacts", "missing.gpx"), ("missing.gpx",)),
        (("--theta0", "30"), ("--impacts",)),
        (("--fieldbook", "{impacts}"), ("--stations",)),
        (("--impacts", "{impacts}", "--theta0", "-5"), ("--theta0",)),
        (("--impacts", "{impacts}", "--theta0", "30", "--units", "yd"), ("--units",)),
        (("--impacts", "{impacts}", "--theta0", "30", "--mass", "-1"), ("--mass",)),
        (
            (
                "--impacts",
                "{impacts}",
                "--theta0",
                "30",
                "--shape",
                "egg",
                "--dimensions",
                "1",
            ),
            ("--shape", "egg"),
        ),
        (
            (
                "--impacts",
                "{impacts}",
                "--theta0",
                "30",
                "--shape",
                "cube",
                "--dimensions",
                "1,x",
            ),
            ("--dimensions",),
        ),
        (("--impacts", "{impacts}"), ("impacts.csv", "point P1", "--theta0")),
    ],
)
def test_bad_arguments(cli, survey, tmp_path, args, words, fails):
    impacts, _ = survey
    out = tmp_path / "t.csv"
    args = [a.format(impacts=impacts) for a in args]
    result = cli("reduce", *args, "-o", out)
    fails(result, *words)
    assert not out.exists()


def test_output_never_overwrites_an_input(cli, survey, digest, fails):
    impacts, trees = survey
    before = digest(impacts)
    result = cli("reduce", "--impacts", impacts, "--theta0", "30", "-o", impacts)
    fails(result, "impacts.csv", "overwrite")
    assert digest(impacts) == before


def test_unknown_output_format_writes_nothing(cli, survey, tmp_path, fails):
    impacts, _ = survey
    out = tmp_path / "t.txt"
    fails(cli("reduce", "--impacts", impacts, "--theta0", "30", "-o", out), "t.txt")
    assert not out.exists()


def test_empty_and_binary_inputs(cli, tmp_path, fails):
    empty = tmp_path / "empty.gpx"
    empty.write_text("")
    out = tmp_path / "t.csv"
    fails(cli("reduce", "--impacts", empty, "--theta0", "30", "-o", out), "empty.gpx")
    binary = tmp_path / "binary.gpx"
    binary.write_bytes(bytes(range(256)) * 4)
    fails(cli("reduce", "--impacts", binary, "--theta0", "30", "-o", out), "binary.gpx")
    assert not out.exists()


def test_two_tree_strikes_on_one_flight(cli, survey, tmp_path, fails):
    impacts, _ = survey
    trees = tmp_path / "two.csv"
    trees.write_text(
        "after_impact,horizontal_distance_m,strike_height_m\nP1,4.0,1.0\nP1,6.0,1.1\n"
    )
    out = tmp_path / "t.csv"
    result = cli(
        "reduce", "--impacts", impacts, "--trees", trees, "--theta0", "30", "-o", out
    )
    fails(result, "two.csv", "row 3", "P1")
    assert not out.exists()


def test_tree_after_unknown_impact(cli, survey, tmp_path, fails):
    impacts, _ = survey
    trees = tmp_path / "unknown.csv"
    trees.write_text("after_impact,horizontal_distance_m,strike_height_m\nQ9,4.0,1.0\n")
    out = tmp_path / "t.csv"
    result = cli(
        "reduce", "--impacts", impacts, "--trees", trees, "--theta0", "30", "-o", out
    )
    fails(result, "unknown.csv", "Q9")
    assert not out.exists()


def test_duplicated_point(cli, tmp_path, fails):
    impacts = tmp_path / "dup.csv"
    impacts.write_text("point,x_m,z_m\nP0,0,100\nP1,10,94\nP1,20,88\n")
    out = tmp_path / "t.csv"
    fails(
        cli("reduce", "--impacts", impacts, "--theta0", "30", "-o", out),
        "dup.csv",
        "P1",
    )
    assert not out.exists()


def test_reader_errors_reach_the_command_line_as_one_line(cli, repo, tmp_path, fails):
    """Issue 2 bad inputs handled by the readers: each stops `reduce` with one line."""
    out = tmp_path / "t.csv"
    no_ele = tmp_path / "no_ele.gpx"
    no_ele.write_text(
        '<?xml version="1.0"?><gpx version="1.1" '
        'xmlns="http://www.topografix.com/GPX/1/1">'
        '<wpt lat="49.0" lon="-114.0"><ele>1500</ele><name>A</name></wpt>'
        '<wpt lat="49.0001" lon="-114.0"><name>B</name></wpt></gpx>'
    )
    fails(
        cli("reduce", "--impacts", no_ele, "--theta0", "30", "-o", out),
        "no_ele.gpx",
        "B",
    )
    text = tmp_path / "text.csv"
    text.write_text("point,x_m,z_m\nP0,0,100\nP1,ten,94\n")
    fails(
        cli("reduce", "--impacts", text, "--theta0", "30", "-o", out),
        "text.csv",
        "row 3",
    )
    folder = repo / "surveys" / "tornado_mountain"
    book = tmp_path / "book.csv"
    lines = (folder / "boulder_a_fieldbook.csv").read_text().splitlines()
    lines[3] = lines[3][:-3] + '00"'  # corrupt the checksum of point C (row 4)
    book.write_text("\n".join(lines) + "\n")
    fails(
        cli(
            "reduce",
            "--fieldbook",
            book,
            "--stations",
            folder / "boulder_a_stations.gpx",
            "--declination",
            "14.2",
            "--theta0",
            "30",
            "-o",
            out,
        ),
        "book.csv",
        "row 4",
    )
    assert not out.exists()
