"""`fieldkit reduce`: no silent defaults that change results (issue 8, items 5 and 6).

Declination never assumed; local x, y grids use both plan axes; a CRS must contain the
points; several GPX tracks are several paths; impossible numbers are refused naming
the file and row; every table carries quality flags, its position error and the
uncertainty that error gives; the summary says when its numbers mean nothing.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from pyproj import Geod

from fieldkit.io.gpx import write_gpx_waypoints
from fieldkit.io.trupulse import format_trupulse_hv, parse_trupulse

TORNADO = "surveys/tornado_mountain"
BODY = ("--mass", "1000", "--radius", "0.5", "--gyration", "0.3")
GEOD = Geod(ellps="WGS84")


def reduce_ok(cli, *args):
    result = cli("reduce", *args)
    assert result.exit_code == 0, result.stderr
    return result


def fails_cleanly(cli, fails, digest, tmp_path, args, inputs, *words):
    """Run `reduce ... -o out`: one-line error naming every word, nothing written."""
    before = {p: digest(p) for p in inputs}
    out = tmp_path / "out" / "table.csv"
    result = cli("reduce", *args, "-o", out)
    fails(result, *words)
    assert not out.exists() and not out.parent.exists()
    assert {p: digest(p) for p in inputs} == before
    return result


# ------------------------------------------------------------------ declination
def book_lines(repo):
    return (repo / TORNADO / "boulder_a_fieldbook.csv").read_text().splitlines()


def true_azimuth_book(repo, tmp_path, declination=14.2, reference="true"):
    """The bundled book with every azimuth turned true and the column saying so."""
    lines = book_lines(repo)
    out = [lines[0]]
    for line in lines[1:]:
        head, sentence = line.rsplit(',"', 1)
        shot = parse_trupulse(sentence.rstrip('"'))
        turned = format_trupulse_hv(
            shot.horizontal_distance_m,
            shot.azimuth_deg + declination,
            shot.inclination_deg,
            shot.slope_distance_m,
        )
        head = head.rsplit(",", 1)[0] + f",{reference}"
        out.append(f'{head},"{turned}"')
    path = tmp_path / "true_book.csv"
    path.write_text("\n".join(out) + "\n")
    return path


def test_the_bundled_book_says_magnetic_and_needs_the_declination(
    cli, repo, tmp_path, fails, digest
):
    book = repo / TORNADO / "boulder_a_fieldbook.csv"
    stations = repo / TORNADO / "boulder_a_stations.gpx"
    args = ("--fieldbook", book, "--stations", stations, "--theta0", "32.6")
    fails_cleanly(
        cli,
        fails,
        digest,
        tmp_path,
        args,
        [book, stations],
        "boulder_a_fieldbook.csv",
        "row 2",
        "magnetic",
        "--declination",
    )
    out = tmp_path / "t.csv"
    result = reduce_ok(cli, *args, "--declination", "14.2", "-o", out)
    assert "declination +14.2° added to every azimuth" in result.stderr
    assert len(pd.read_csv(out)) == 50


def test_true_azimuths_need_no_declination_and_give_the_same_points(
    cli, repo, tmp_path
):
    stations = repo / TORNADO / "boulder_a_stations.gpx"
    common = ("--stations", stations, "--theta0", "32.6")
    magnetic, true = tmp_path / "m.csv", tmp_path / "t.csv"
    reduce_ok(
        cli,
        "--fieldbook",
        repo / TORNADO / "boulder_a_fieldbook.csv",
        *common,
        "--declination",
        "14.2",
        "-o",
        magnetic,
    )
    book = true_azimuth_book(repo, tmp_path)
    reduce_ok(cli, "--fieldbook", book, *common, "-o", true)
    a, b = pd.read_csv(magnetic), pd.read_csv(true)
    np.testing.assert_allclose(b["x_m"], a["x_m"], atol=1e-6)
    np.testing.assert_allclose(b["z_m"], a["z_m"], atol=1e-9)
    # a declination given for a true book is not applied, and the output says so
    again = tmp_path / "again.csv"
    result = reduce_ok(
        cli, "--fieldbook", book, *common, "--declination", "9", "-o", again
    )
    assert "every azimuth is true: declination not applied" in result.stderr
    np.testing.assert_allclose(pd.read_csv(again)["x_m"], b["x_m"], atol=1e-9)


def test_a_book_that_does_not_say_needs_an_explicit_zero(
    cli, repo, tmp_path, fails, digest
):
    lines = book_lines(repo)
    plain = tmp_path / "plain.csv"
    plain.write_text(
        "\n".join(line.replace(",magnetic,", ",") for line in lines).replace(
            ",azimuth_reference,", ","
        )
        + "\n"
    )
    stations = repo / TORNADO / "boulder_a_stations.gpx"
    args = ("--fieldbook", plain, "--stations", stations, "--theta0", "32.6")
    fails_cleanly(
        cli,
        fails,
        digest,
        tmp_path,
        args,
        [plain, stations],
        "plain.csv",
        "row 2",
        "does not say whether its azimuths are true or magnetic",
        "--declination",
    )
    result = reduce_ok(cli, *args, "--declination", "0", "-o", tmp_path / "z.csv")
    assert "declination +0° added to every azimuth" in result.stderr


def test_a_bad_azimuth_reference_names_the_row(cli, repo, tmp_path, fails, digest):
    lines = book_lines(repo)
    lines[5] = lines[5].replace(",magnetic,", ",grid,")
    book = tmp_path / "grid_north.csv"
    book.write_text("\n".join(lines) + "\n")
    stations = repo / TORNADO / "boulder_a_stations.gpx"
    args = ("--fieldbook", book, "--stations", stations, "--declination", "14.2")
    fails_cleanly(
        cli,
        fails,
        digest,
        tmp_path,
        args,
        [book],
        "grid_north.csv",
        "row 6",
        "'grid' is not true or magnetic",
    )


def test_declination_without_a_field_book_is_refused(cli, tmp_path, fails, digest):
    points = tmp_path / "p.csv"
    points.write_text("point,x_m,z_m\nA,0,10\nB,10,4\n")
    args = ("--impacts", points, "--theta0", "30", "--declination", "14")
    fails_cleanly(
        cli, fails, digest, tmp_path, args, [points], "--declination", "--fieldbook"
    )


# ------------------------------------------------------------------ local grids
def test_local_grid_x_y_z_uses_both_plan_axes(cli, tmp_path):
    """An L-shaped path on a site grid: section x is the plan distance walked."""
    grid = tmp_path / "grid.csv"
    grid.write_text(
        "point,x_m,y_m,z_m\nA,100,200,60\nB,106,208,54\nC,106,218,48\nD,114,224,42\n"
    )
    section = tmp_path / "section.csv"
    section.write_text("point,x_m,z_m\nA,0,60\nB,10,54\nC,20,48\nD,30,42\n")
    out_grid, out_section = tmp_path / "g.csv", tmp_path / "s.csv"
    result = reduce_ok(cli, "--impacts", grid, "--theta0", "30", "-o", out_grid)
    assert "local plan grid" in result.stderr
    reduce_ok(cli, "--impacts", section, "--theta0", "30", "-o", out_section)
    g, s = pd.read_csv(out_grid), pd.read_csv(out_section)
    np.testing.assert_allclose(g["x_m"], [0.0, 10.0, 20.0, 30.0], atol=1e-12)
    for column in ("slope_deg", "e_n", "e_t", "vi_mps", "vf_mps"):
        np.testing.assert_allclose(g[column], s[column], rtol=1e-12)


def test_a_path_along_y_is_not_a_vertical_drop(cli, tmp_path):
    """x constant, y increasing: the old reader took x alone (every point at x 0)."""
    grid = tmp_path / "along_y.csv"
    grid.write_text("point,x_m,y_m,z_m\nA,5,0,30\nB,5,10,24\nC,5,20,18\n")
    out = tmp_path / "t.csv"
    reduce_ok(cli, "--impacts", grid, "--theta0", "30", "-o", out)
    assert pd.read_csv(out)["x_m"].tolist() == [0.0, 10.0, 20.0]


def test_x_z_alone_stays_a_section(cli, tmp_path):
    section = tmp_path / "s.csv"
    section.write_text("point,x_m,z_m\nA,3,30\nB,13,24\nC,23,18\n")
    out = tmp_path / "t.csv"
    reduce_ok(cli, "--impacts", section, "--theta0", "30", "-o", out)
    assert pd.read_csv(out)["x_m"].tolist() == [3.0, 13.0, 23.0]


def test_trees_on_a_local_grid_are_placed_in_plan(cli, tmp_path, fails, digest):
    grid = tmp_path / "grid.csv"
    grid.write_text("point,x_m,y_m,z_m\nA,0,0,60\nB,0,10,54\nC,8,16,48\n")
    trees = tmp_path / "trees.csv"
    trees.write_text(
        "x_m,y_m,strike_height_m\n0.5,4,1.5\n"
    )  # 4 m along A->B, 0.5 m off
    out = tmp_path / "t.csv"
    reduce_ok(cli, "--impacts", grid, "--trees", trees, "--theta0", "30", "-o", out)
    table = pd.read_csv(out)
    assert table["theta0_source"].tolist()[:2] == ["tree", "assumed"]
    # a grid x without y is not a section x: refused
    only_x = tmp_path / "only_x.csv"
    only_x.write_text("after_impact,x_m,strike_height_m\nA,4,1.5\n")
    args = ("--impacts", grid, "--trees", only_x, "--theta0", "30")
    fails_cleanly(
        cli, fails, digest, tmp_path, args, [grid, only_x], "only_x.csv", "local x, y"
    )


# ------------------------------------------------------------------ CRS area of use
def test_a_crs_that_does_not_contain_the_points_is_refused(
    cli, repo, tmp_path, fails, digest
):
    gpx = repo / TORNADO / "boulder_a_impacts.gpx"
    args = ("--impacts", gpx, "--theta0", "32.6", "--epsg", "32755")
    fails_cleanly(
        cli,
        fails,
        digest,
        tmp_path,
        args,
        [gpx],
        "--epsg",
        "EPSG:32755 (WGS 84 / UTM zone 55S)",
        "144°E to 150°E, 80°S to 0°N",
        "point A of",
        "boulder_a_impacts.gpx",
        "49.97120°N, 114.68040°W",
    )
    reduce_ok(cli, "--impacts", gpx, "--theta0", "32.6", "--epsg", "32611")


def test_easting_northing_in_the_wrong_crs_is_refused(cli, tmp_path, fails, digest):
    """UTM 11N coordinates read as Swiss CH1903+ (EPSG:2056) land far outside it."""
    en = tmp_path / "en.csv"
    en.write_text(
        "name,easting,northing,elevation_m\nA,680000,5500000,1000\n"
        "B,680020,5499980,985\nC,680040,5499960,972\n"
    )
    args = ("--impacts", en, "--theta0", "30", "--epsg", "2056")
    fails_cleanly(
        cli, fails, digest, tmp_path, args, [en], "EPSG:2056", "point A of", "en.csv"
    )


# ------------------------------------------------------------------ GPX tracks
def track_gpx(path, tracks, tag="trk"):
    """A GPX 1.1 file with one <trk> (or <rte>) per (name, points) pair."""
    inner = {"trk": "trkseg", "rte": None}[tag]
    point = {"trk": "trkpt", "rte": "rtept"}[tag]
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<gpx version="1.1" creator="test" xmlns="http://www.topografix.com/GPX/1/1">',
    ]
    for name, points in tracks:
        lines.append(f"<{tag}><name>{name}</name>")
        if inner:
            lines.append(f"<{inner}>")
        for lat, lon, ele in points:
            lines.append(f'<{point} lat="{lat:.9f}" lon="{lon:.9f}"><ele>{ele}</ele>')
            lines.append(f"</{point}>")
        if inner:
            lines.append(f"</{inner}>")
        lines.append(f"</{tag}>")
    lines.append("</gpx>")
    path.write_text("\n".join(lines) + "\n")
    return path


def walk(lat, lon, steps, azimuth=200.0, z0=1500.0, drop=6.0):
    out = [(lat, lon, z0)]
    for k in range(steps):
        lon, lat, _ = GEOD.fwd(lon, lat, azimuth, 10.0)
        out.append((lat, lon, z0 - drop * (k + 1)))
    return out


@pytest.mark.parametrize("tag", ["trk", "rte"])
def test_several_tracks_are_several_paths_never_joined(
    cli, tmp_path, fails, digest, tag
):
    upper = walk(49.9712, -114.6804, 3)
    lower = walk(49.9650, -114.6700, 4, z0=1400.0)
    gpx = track_gpx(tmp_path / "two.gpx", [("upper", upper), ("lower", lower)], tag)
    kind = "track" if tag == "trk" else "route"
    args = ("--impacts", gpx, "--gpx-points", kind, "--theta0", "30")
    fails_cleanly(
        cli,
        fails,
        digest,
        tmp_path,
        args,
        [gpx],
        "two.gpx",
        f"2 {kind}s with points",
        f"{kind} 1 'upper' (4 points)",
        f"{kind} 2 'lower' (5 points)",
        "never joined",
        "--gpx-track",
    )
    out = tmp_path / "lower.csv"
    reduce_ok(cli, *args, "--gpx-track", "lower", "-o", out)
    table = pd.read_csv(out)
    assert len(table) == 5 and table["z_m"].iloc[0] == 1400.0
    assert table["x_m"].iloc[-1] == pytest.approx(40.0, abs=1e-3)  # 1e-9° in the GPX
    reduce_ok(cli, *args, "--gpx-track", "1", "-o", out)
    assert len(pd.read_csv(out)) == 4
    fails_cleanly(
        cli,
        fails,
        digest,
        tmp_path,
        (*args, "--gpx-track", "middle"),
        [gpx],
        "--gpx-track",
        f"no {kind} 'middle'",
        "'upper'",
    )


def test_gpx_track_only_for_gpx_tracks(cli, tmp_path, fails, digest):
    points = tmp_path / "p.csv"
    points.write_text("point,x_m,z_m\nA,0,10\nB,10,4\n")
    args = ("--impacts", points, "--theta0", "30", "--gpx-track", "1")
    fails_cleanly(cli, fails, digest, tmp_path, args, [points], "--gpx-track", "GPX")
    gpx = tmp_path / "w.gpx"
    write_gpx_waypoints(
        gpx,
        pd.DataFrame(
            {
                "point": ["A", "B"],
                "lat_deg": [49.0, 48.9999],
                "lon_deg": [-114.0] * 2,
                "elev_m": [1500.0, 1494.0],
            }
        ),
    )
    args = ("--impacts", gpx, "--theta0", "30", "--gpx-track", "1")
    fails_cleanly(cli, fails, digest, tmp_path, args, [gpx], "--gpx-track", "waypoints")


def test_a_real_multi_track_file(cli, external_data, tmp_path, fails, digest):
    gpx = external_data / "gpx_gpxpy" / "cerknicko-jezero.gpx"
    args = ("--impacts", gpx, "--gpx-points", "track", "--theta0", "30")
    fails_cleanly(
        cli,
        fails,
        digest,
        tmp_path,
        args,
        [gpx],
        "7 tracks with points",
        "track 2 'ACTIVE LOG #2' (173 points)",
    )


# ------------------------------------------------------------------ hostile numbers
SECTION = "point,x_m,z_m\nP0,0,100\nP1,10,94\nP2,20,88\n"
GEOGRAPHIC = "point,lat,lon,elev_m\nA,49.9712,-114.6804,1500\nB,49.9711,-114.6805,{}\n"


@pytest.mark.parametrize(
    ("name", "text", "words"),
    [
        ("x.csv", SECTION.replace("10,94", "1e308,94"), ("row 3", "x 1e+308 m")),
        ("z.csv", SECTION.replace("10,94", "10,-1e300"), ("row 3", "z -1e+300 m")),
        ("inf.csv", SECTION.replace("10,94", "10,inf"), ("row 3", "not a finite")),
        ("nan.csv", SECTION.replace("10,94", "10,NaN"), ("row 3", "not a finite")),
        ("feet.csv", SECTION.replace("10,94", "10,35000"), ("row 3", "35000 m")),
        ("elev.csv", GEOGRAPHIC.format("1e308"), ("row 3", "elevation 1e+308")),
        ("grid.csv", "x_m,y_m,z_m\n0,0,9\n3,1e308,5\n", ("row 3", "y 1e+308")),
        (
            "slope.csv",
            "point,x_m,z_m,slope_deg\nA,0,10,\nB,10,4,1e308\nC,20,0,\n",
            ("row 3", "'slope_deg'", "not a ground dip"),
        ),
        (
            "theta.csv",
            "point,x_m,z_m,theta0_deg\nA,0,10,\nB,10,4,400\nC,20,0,\n",
            ("row 3", "'theta0_deg'", "not a restitution angle"),
        ),
    ],
)
def test_impossible_numbers_in_points_name_the_row(
    cli, tmp_path, fails, digest, name, text, words
):
    path = tmp_path / name
    path.write_text(text)
    args = ("--impacts", path, "--theta0", "30", *BODY)
    fails_cleanly(cli, fails, digest, tmp_path, args, [path], name, *words)


def test_impossible_gpx_elevation_names_the_waypoint(cli, tmp_path, fails, digest):
    gpx = tmp_path / "big.gpx"
    write_gpx_waypoints(
        gpx,
        pd.DataFrame(
            {
                "point": ["A", "B"],
                "lat_deg": [49.0, 48.9999],
                "lon_deg": [-114.0] * 2,
                "elev_m": [1500.0, 1494.0],
            }
        ),
    )
    gpx.write_text(gpx.read_text().replace("<ele>1494.000</ele>", "<ele>1e308</ele>"))
    args = ("--impacts", gpx, "--theta0", "30")
    fails_cleanly(
        cli, fails, digest, tmp_path, args, [gpx], "big.gpx", "waypoint 2", "1e+308"
    )


@pytest.mark.parametrize(
    ("trees", "words"),
    [
        (
            "after_impact,horizontal_distance_m,strike_height_m\nP1,5,1e308\n",
            ("row 2", "strike height 1e+308 m", "taller than any tree"),
        ),
        (
            "after_impact,horizontal_distance_m,strike_height_m,ground_z_m\n"
            "P1,5,1,1e308\n",
            ("row 2", "ground elevation 1e+308"),
        ),
        (
            "after_impact,horizontal_distance_m,strike_height_m\nP1,1e308,1\n",
            ("row 2", "horizontal distance 1e+308 m is outside the flight"),
        ),
    ],
)
def test_impossible_tree_strikes_name_the_row(
    cli, tmp_path, fails, digest, trees, words
):
    points = tmp_path / "p.csv"
    points.write_text(SECTION)
    tree_file = tmp_path / "trees.csv"
    tree_file.write_text(trees)
    args = ("--impacts", points, "--trees", tree_file, "--theta0", "30", *BODY)
    result = fails_cleanly(
        cli, fails, digest, tmp_path, args, [points, tree_file], "trees.csv", *words
    )
    assert len(result.stderr) < 400  # numbers are printed short, not 300 digits


def test_impossible_instrument_height_names_the_book_row(cli, tmp_path, fails, digest):
    stations = tmp_path / "st.csv"
    stations.write_text("station,lat,lon,elev_m\nS1,49.9712,-114.6804,1700\n")
    shots = [format_trupulse_hv(d, 120.0, -20.0, d / 0.9397) for d in (10, 20, 30)]
    book = tmp_path / "book.csv"
    book.write_text(
        "point,station,instrument_height_m,target_height_m,azimuth_reference,sentence\n"
        f'A,S1,1.6,0,true,"{shots[0]}"\nB,S1,1e308,0,true,"{shots[1]}"\n'
        f'C,S1,1.6,0,true,"{shots[2]}"\n'
    )
    args = ("--fieldbook", book, "--stations", stations, "--theta0", "30")
    fails_cleanly(
        cli,
        fails,
        digest,
        tmp_path,
        args,
        [book, stations],
        "book.csv",
        "row 3 (point B)",
        "elevation",
    )


# ------------------------------------------------------------------ flags and summary
@pytest.fixture(scope="module")
def tornado(repo, tmp_path_factory):
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("tornado") / "t.csv"
    folder = repo / TORNADO
    result = CliRunner().invoke(
        app,
        [
            "reduce",
            "--impacts",
            str(folder / "boulder_a_impacts.gpx"),
            "--trees",
            str(folder / "boulder_a_trees.csv"),
            "--theta0",
            "32.6",
            "--mass",
            "3750",
            "--radius",
            "0.725",
            "--gyration",
            "0.46",
            "-o",
            str(out),
        ],
    )
    assert result.exit_code == 0, result.stderr
    return result.stdout, pd.read_csv(out)


def flagged(table, flag):
    return table["qa_flags"].fillna("").str.split(";").apply(lambda f: flag in f)


def test_tornado_flags_agree_with_the_table_and_the_summary_counts_them(tornado):
    stdout, table = tornado
    impacts = table["e_n"].notna()
    assert (
        flagged(table, "energy_gained") == (table["vf_mps"] > table["vi_mps"])
    ).all()
    assert (flagged(table, "e_t_above_1") == (table["e_t"] > 1)).all()
    assert flagged(table, "slope_from_chord")[impacts].all()  # no surveyed slope
    assert flagged(table, "spin_estimated").all()  # omega = v/r everywhere
    assert not flagged(table, "speed_high").any()  # the fastest is 28 m/s
    assert flagged(table, "energy_gained").sum() == 3  # points 22, 32, 42
    counts = {
        name: int(flagged(table, name).sum())
        for name in ("energy_gained", "e_t_above_1", "slope_sensitive")
    }
    line = next(s for s in stdout.splitlines() if s.startswith("quality flags"))
    for name, count in counts.items():
        assert f"{name} {count}" in line


def test_tornado_summary_states_the_error_model_and_the_slope_warning(tornado):
    stdout, table = tornado
    assert (
        "uncertainty: position error 0.5 m in plan and 0.5 m in height per point "
        "(the default), 0.25 m per tree-strike height (the default), 100 Monte Carlo "
        "draws, seed 2004 -> e_n_sd, e_t_sd, vi_sd_mps, vf_sd_mps, vin_sd_mps, "
        "vit_sd_mps, vfn_sd_mps, vft_sd_mps, theta_i_sd_deg" in stdout
    )
    for column in ("e_n_sd", "e_t_sd", "vi_sd_mps", "e_n_next_chord"):
        assert table[column].notna().sum() >= 47, column
    sensitive = flagged(table, "slope_sensitive")
    shift = (table["e_n_next_chord"] - table["e_n"]).abs()
    assert (sensitive == (shift > table["e_n_sd"])).all()
    assert f"warning: at {int(sensitive.sum())} of 48 impacts" in stdout


def test_tornado_theory_share_is_not_given_as_a_median(tornado):
    """Half the losing impacts have e_n > 1: the theory predicts a gain there."""
    stdout, table = tornado
    assert "impact mechanics explains a median" not in stdout
    line = next(s for s in stdout.splitlines() if s.startswith("impact mechanics"))
    lost = table["dke_j"] < 0
    fraction = table.loc[lost, "theory_loss_fraction"].dropna()
    outside = int(((fraction < 0) | (fraction > 1)).sum())
    assert f"no median given, at {outside} of the {len(fraction)} impacts" in line


def uniform_slope(tmp_path, n=10, slope=0.6, bend_at=None):
    x = np.arange(n) * 10.0
    z = 100.0 - slope * x
    if bend_at is not None:  # the slope steepens to 55° beyond point bend_at
        z = np.where(x > x[bend_at], z - 0.83 * (x - x[bend_at]), z)
    path = tmp_path / "slope.csv"
    path.write_text(
        "point,x_m,z_m\n"
        + "".join(f"P{i},{a},{b}\n" for i, (a, b) in enumerate(zip(x, z, strict=True)))
    )
    return path


def test_a_meaningful_theory_share_says_what_it_is_the_median_of(cli, tmp_path):
    out = tmp_path / "t.csv"
    result = reduce_ok(
        cli, "--impacts", uniform_slope(tmp_path), "--theta0", "20", *BODY, "-o", out
    )
    table = pd.read_csv(out)
    fraction = table.loc[table["dke_j"] < 0, "theory_loss_fraction"].dropna()
    assert len(fraction) == 8
    assert (
        f"explains a median {100 * fraction.median():.0f} % (quartiles "
        in result.stdout
    )
    assert "median over the 8 of 8 impacts that lost kinetic energy" in result.stdout
    # a uniform slope: both chords agree, e_n does not hang on the choice
    assert "warning:" not in result.stdout
    assert not flagged(table, "slope_sensitive").any()


def test_too_few_impacts_for_a_median(cli, tmp_path):
    path = tmp_path / "short.csv"
    path.write_text("point,x_m,z_m\nA,0,100\nB,10,94\nC,20,88\n")
    result = reduce_ok(cli, "--impacts", path, "--theta0", "20", *BODY)
    assert (
        "no median given, only 1 impact lost kinetic energy and has a theory value "
        "(a median needs 5)" in result.stdout
    )


def test_a_bend_in_the_slope_is_flagged_and_warned(cli, tmp_path):
    out = tmp_path / "t.csv"
    path = uniform_slope(tmp_path, bend_at=5)
    result = reduce_ok(cli, "--impacts", path, "--theta0", "20", *BODY, "-o", out)
    table = pd.read_csv(out)
    sensitive = flagged(table, "slope_sensitive")
    assert sensitive.iloc[5]  # the last point before the bend: next chord is 55°
    assert not sensitive.iloc[2]  # mid-slope: both chords are 31°
    assert f"warning: at {int(sensitive.sum())} of 8 impacts" in result.stdout
    assert math.isclose(
        table["e_n_next_chord"].iloc[2], table["e_n"].iloc[2], rel_tol=1e-9
    )
