"""Every command's outputs through the command line (fieldkit.outputs.OutputSet).

Never an input overwritten (same path, symbolic link, hard link, a figure folder),
all or nothing (a failure midway leaves no output and no temporary file), FIFOs and
devices written through, file-system errors as one line, formula-like text kept as
text in the ImpactTable's CSV and XLSX.
"""

from __future__ import annotations

import csv
import errno
import os
import shutil
import socket
import stat
import threading
from pathlib import Path

import numpy as np
import openpyxl
import pytest

from fieldkit.impact_table import ImpactTable
from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball

POINTS = "point,x_m,z_m\nP0,0,100\nP1,10,94\nP2,20,88\nP3,30,82\nP4,40,76\n"
TREES = "after_impact,horizontal_distance_m,strike_height_m\nP1,5.0,1.2\n"
BODY = ("--mass", "1000", "--radius", "0.5", "--gyration", "0.3")
FENCE = ("fence", "--mass", "520", "--gyration", "0.35", "--speed-in", "22")
FENCE += ("--spin-in", "18", "--speed-out", "11.5", "--spin-out=-11.6")


@pytest.fixture()
def work(tmp_path, monkeypatch):
    """A folder holding a small survey (impacts.csv, trees.csv); the working dir."""
    (tmp_path / "impacts.csv").write_text(POINTS)
    (tmp_path / "trees.csv").write_text(TREES)
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture(scope="module")
def track_text():
    s = bouncing_ball(
        duration_s=0.8,
        start_velocity_mps=(1.5, 0.5),
        surface_angle_deg=12.0,
        omega0_radps=-20.0,
        noise_m=4e-4,
        angle_noise_rad=0.02,
        rng=np.random.default_rng(5),
    )
    return s.track.frame.to_csv(index=False)


def reduce(cli, *options):
    """``fieldkit reduce`` of the work folder's survey with OPTIONS."""
    survey = ("--impacts", "impacts.csv", "--trees", "trees.csv", "--theta0", "30")
    return cli("reduce", *survey, *BODY, *options)


def listing(root: Path) -> dict[str, object]:
    """Every entry below ``root`` -> its kind and content (links not followed)."""
    found: dict[str, object] = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            path = Path(folder) / name
            key = str(path.relative_to(root))
            if path.is_symlink():
                found[key] = ("link", os.readlink(path))
            elif path.is_dir():
                found[key] = "dir"
            elif path.is_file():
                found[key] = path.read_bytes()
            else:
                found[key] = stat.S_IFMT(path.lstat().st_mode)
    return found


def no_temporaries(root: Path) -> bool:
    return not [p for p in root.rglob(".fk-*")]


# ---------------------------------------------------------------- never an input
def _same_path(work):
    return ("-o", "impacts.csv")


def _symlink(work):
    (work / "link.csv").symlink_to(work / "impacts.csv")
    return ("-o", "link.csv")


def _hard_link(work):
    os.link(work / "trees.csv", work / "hard.csv")
    return ("-o", "hard.csv")


def _other_spelling(work):
    (work / "sub").mkdir()
    return ("-o", "sub/../impacts.csv")


def _linked_folder(work):
    (work / "view").symlink_to(work)
    return ("-o", "view/trees.csv")


def _figure_folder(work):
    # an input that is named like a figure in the --figures folder
    (work / "figs").mkdir()
    shutil.move(work / "trees.csv", work / "figs" / "en_theta.png")
    return ("--figures", "figs")


@pytest.mark.parametrize(
    ("setup", "survey_trees"),
    [
        (_same_path, "trees.csv"),
        (_symlink, "trees.csv"),
        (_hard_link, "trees.csv"),
        (_other_spelling, "trees.csv"),
        (_linked_folder, "trees.csv"),
        (_figure_folder, "figs/en_theta.png"),
    ],
)
def test_reduce_never_overwrites_an_input(cli, work, fails, setup, survey_trees):
    options = setup(work)
    before = listing(work)
    survey = ("--impacts", "impacts.csv", "--trees", survey_trees, "--theta0", "30")
    result = cli("reduce", *survey, *BODY, "-o", "t.csv", *options)
    fails(result, "overwrite an input file")
    assert listing(work) == before  # inputs unchanged, nothing written


def test_view_refuses_a_figure_folder_holding_its_input(cli, work, track_text, fails):
    (work / "figs").mkdir()
    (work / "figs" / "track.png").write_text(track_text)  # the input, named so
    before = listing(work)
    result = cli(
        "view", "figs/track.png", "--radius", "0.0375", "-o", "rec.rrd",
        "--figures", "figs",
    )  # fmt: skip
    fails(result, "figs/track.png: output would overwrite an input file")
    assert listing(work) == before


def test_view_refuses_a_recording_linked_to_its_input(cli, work, track_text, fails):
    (work / "track.csv").write_text(track_text)
    (work / "rec.rrd").symlink_to(work / "track.csv")
    before = listing(work)
    fails(
        cli("view", "track.csv", "--radius", "0.0375", "-o", "rec.rrd"),
        "rec.rrd: output would overwrite an input file (track.csv)",
    )
    assert listing(work) == before


@pytest.mark.parametrize(
    ("options", "words"),
    [
        (("--rrd", "video.avi"), ("video.avi", "overwrite an input")),
        (("--rrd", "same.rrd"), ("same.rrd", "overwrite an input file (video.avi)")),
        (("--impacts", "hom.csv"), ("hom.csv", "overwrite an input")),
        (("--impacts", "hard.csv"), ("hard.csv", "overwrite an input file (hom.csv)")),
        (("-o", "out.csv", "--impacts", "out.csv"), ("-o and --impacts name",)),
        (("--figures", "figs"), ("figs/track.png", "overwrite an input")),
    ],
)
def test_track_never_overwrites_its_video_or_homography(
    cli, work, fails, options, words
):
    # refused before the video is opened: a few bytes stand for it
    (work / "video.avi").write_bytes(b"RIFF....AVI ")
    (work / "same.rrd").symlink_to(work / "video.avi")
    (work / "figs").mkdir()
    os.link(work / "video.avi", work / "figs" / "track.png")
    (work / "hom.csv").write_text("u_px,v_px,x_m,z_m\n0,0,0,0\n1,0,1,0\n")
    os.link(work / "hom.csv", work / "hard.csv")
    before = listing(work)
    homography = ("--homography", "hom.csv", "--fps", "1205")
    result = cli("track", "video.avi", *homography, "--radius", "0.03", *options)
    fails(result, *words)
    assert listing(work) == before


def test_two_options_naming_one_file_are_refused(cli, work, fails):
    impact = ("impact", "--speed", "22", "--angle", "25", "--en", "0.5", *BODY)
    result = cli(*impact, "--figure", "x.png", "--json", "x.png")
    fails(result, "x.png: --figure and --json name the same file")
    (work / "y.png").symlink_to(work / "x.png")
    result = cli(*FENCE, "--figure", "x.png", "--out", "y.png")
    fails(result, "y.png: --figure and --out name the same file")
    assert not (work / "x.png").exists()


# ---------------------------------------------------------------- all or nothing
def test_a_bad_second_output_leaves_no_first_one(cli, work, fails):
    (work / "blocker").write_text("a file, not a folder\n")
    before = listing(work)
    result = reduce(cli, "-o", "t.csv", "--figures", "blocker/figs")
    fails(result, "blocker/figs/section.png", "blocker is a file, not a folder")
    assert listing(work) == before


def _fail_rename_of(monkeypatch, name: str, error: OSError) -> None:
    real = os.replace

    def replace(src, dst, *args, **kwargs):
        if Path(dst).name == name and Path(src).name.startswith(".fk-"):
            raise error
        return real(src, dst, *args, **kwargs)

    monkeypatch.setattr(os, "replace", replace)


def test_a_failure_midway_restores_every_output(cli, work, fails, monkeypatch):
    (work / "t.csv").write_text("the old table\n")
    (work / "figs").mkdir()
    (work / "figs" / "section.png").write_bytes(b"old section")
    before = listing(work)
    # the table and the section figure are renamed into place, then the disk is full
    _fail_rename_of(monkeypatch, "et_impacts.png", OSError(errno.ENOSPC, "full"))
    result = reduce(cli, "-o", "t.csv", "--figures", "figs/new")
    fails(result, "figs/new/et_impacts.png: no space left on device")
    assert listing(work) == before  # old files back, new folder gone
    assert no_temporaries(work)
    result = reduce(cli, "-o", "t.csv", "--figures", "figs")
    fails(result, "figs/et_impacts.png: no space left on device")
    assert listing(work) == before


def test_view_failure_midway_writes_no_recording(
    cli, work, track_text, fails, monkeypatch
):
    (work / "track.csv").write_text(track_text)
    before = listing(work)
    _fail_rename_of(monkeypatch, "residuals.png", PermissionError(errno.EACCES, "no"))
    result = cli(
        "view", "track.csv", "--radius", "0.0375", "--surface-angle", "12",
        "-o", "out/rec.rrd", "--figures", "out/figs",
    )  # fmt: skip
    fails(result, "out/figs/residuals.png: permission denied")
    assert listing(work) == before


@pytest.mark.parametrize(
    ("error", "reason"),
    [
        (PermissionError(errno.EACCES, "Permission denied"), "permission denied"),
        (PermissionError(errno.EPERM, "Operation not permitted"), "permission denied"),
        (OSError(errno.EROFS, "Read-only file system"), "read-only file system"),
        (OSError(errno.ENOSPC, "No space left on device"), "no space left on device"),
    ],
)
@pytest.mark.parametrize("where", ["rename", "temporary file"])
def test_file_system_errors_are_one_line(
    cli, work, fails, monkeypatch, error, reason, where
):
    if where == "rename":
        _fail_rename_of(monkeypatch, "t.csv", error)
    else:
        real = os.open

        def open_(path, flags, *args, **kwargs):
            if Path(os.fsdecode(path)).name.startswith(".fk-"):
                raise error
            return real(path, flags, *args, **kwargs)

        monkeypatch.setattr(os, "open", open_)
    before = listing(work)
    fails(reduce(cli, "-o", "out/t.csv"), f"out/t.csv: {reason}")
    assert listing(work) == before


@pytest.mark.skipif(os.geteuid() == 0, reason="root is never denied permission")
def test_a_read_only_folder_is_permission_denied(cli, work, fails):
    (work / "ro").mkdir()
    (work / "ro").chmod(0o500)
    try:
        fails(reduce(cli, "-o", "ro/t.csv"), "ro/t.csv: permission denied")
        assert list((work / "ro").iterdir()) == []
    finally:
        (work / "ro").chmod(0o700)


def test_a_folder_is_not_an_output(cli, work, fails):
    (work / "t.csv").mkdir()
    before = listing(work)
    fails(reduce(cli, "-o", "t.csv"), "t.csv: is a directory")
    fails(cli(*FENCE, "-o", "."), "is a directory")
    assert listing(work) == before


def test_an_output_below_a_file_names_the_file(cli, work, fails):
    fails(reduce(cli, "-o", "trees.csv/t.csv"), "trees.csv is a file, not a folder")
    assert (work / "trees.csv").read_text() == TREES


def test_a_long_file_name_fits_its_temporary_name(cli, work, fails):
    name = "a" * 246 + ".csv"  # 250 bytes: the longest names still fit
    result = reduce(cli, "-o", name)
    assert result.exit_code == 0, result.stderr
    assert len(ImpactTable.read(work / name)) == 5
    assert no_temporaries(work)
    long = "b" * 252 + ".csv"  # 256 bytes: over NAME_MAX
    fails(reduce(cli, "-o", long), "file name too long (256 bytes, at most 255)")
    assert not [p for p in work.iterdir() if p.name.startswith("b")]


def test_new_outputs_get_the_usual_permissions(cli, work):
    mask = os.umask(0o027)
    try:
        result = reduce(cli, "-o", "t.csv", "--figures", "figs")
    finally:
        os.umask(mask)
    assert result.exit_code == 0, result.stderr
    assert (work / "t.csv").stat().st_mode & 0o777 == 0o640
    assert (work / "figs" / "section.png").stat().st_mode & 0o777 == 0o640


# ---------------------------------------------------------------- special targets
def test_dev_null_is_written_through(cli):
    result = cli(*FENCE, "-o", "/dev/null")
    assert result.exit_code == 0, result.stderr
    assert "wrote /dev/null" in result.stdout.splitlines()
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


def test_a_symbolic_link_is_followed(cli, work):
    (work / "null.csv").symlink_to("/dev/null")
    (work / "real.csv").write_text("old\n")
    (work / "link.csv").symlink_to("real.csv")
    (work / "dangling.csv").symlink_to("new.csv")
    for name in ("null.csv", "link.csv", "dangling.csv"):
        result = reduce(cli, "-o", name)
        assert result.exit_code == 0, result.stderr
        assert (work / name).is_symlink()
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert len(ImpactTable.read(work / "real.csv")) == 5
    assert len(ImpactTable.read(work / "new.csv")) == 5
    assert no_temporaries(work)


def test_a_fifo_is_written_through(cli, work):
    fifo = work / "fifo.csv"
    os.mkfifo(fifo)
    received: list[bytes] = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_bytes()))
    reader.start()
    try:
        result = reduce(cli, "-o", "fifo.csv")
    finally:
        reader.join(5)
        if reader.is_alive():  # nothing opened the FIFO: unblock the reader
            os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
            reader.join(5)
    assert result.exit_code == 0, result.stderr
    assert stat.S_ISFIFO(fifo.lstat().st_mode)  # still a FIFO
    lines = received[0].decode().splitlines()
    assert lines[0].startswith("path_id,point,x_m") and len(lines) == 6
    assert no_temporaries(work)


def test_a_socket_is_refused(cli, work, fails):
    server = socket.socket(socket.AF_UNIX)
    try:
        server.bind("s.csv")  # relative: a socket path must be short
        fails(reduce(cli, "-o", "s.csv"), "s.csv: is a socket")
        assert stat.S_ISSOCK((work / "s.csv").lstat().st_mode)
    finally:
        server.close()


# ---------------------------------------------------------------- spreadsheets
FORMULAS = ['=HYPERLINK("x")', "+1", "-2", "@SUM(A1)", "'=x"]


@pytest.fixture()
def formula_survey(work):
    rows = [[name, 10.0 * i, 100.0 - 6.0 * i] for i, name in enumerate(FORMULAS)]
    with open(work / "formulas.csv", "w", newline="") as f:
        csv.writer(f).writerows([["point", "x_m", "z_m"], *rows])
    return ("--impacts", "formulas.csv", "--theta0", "30", "--path-id", FORMULAS[0])


def test_formula_text_stays_text_in_xlsx(cli, work, formula_survey):
    result = cli("reduce", *formula_survey, *BODY, "-o", "t.xlsx")
    assert result.exit_code == 0, result.stderr
    sheet = openpyxl.load_workbook(work / "t.xlsx")["impacts"]
    header = [c.value for c in sheet[1]]
    rows = list(sheet.iter_rows(min_row=2))
    for name in ("path_id", "point"):
        cells = [row[header.index(name)] for row in rows]
        assert all(c.data_type == "s" for c in cells), name  # never a formula
    assert [row[header.index("point")].value for row in rows] == FORMULAS
    assert {row[header.index("path_id")].value for row in rows} == {FORMULAS[0]}
    vz = [row[header.index("vi_z_mps")] for row in rows[1:]]
    assert all(c.data_type == "n" and c.value < 0 for c in vz)  # numbers untouched
    table = ImpactTable.read(work / "t.xlsx").frame
    assert table["point"].tolist() == FORMULAS


def test_formula_text_is_quoted_in_csv_and_read_back(cli, work, formula_survey):
    result = cli("reduce", *formula_survey, *BODY, "-o", "t.csv")
    assert result.exit_code == 0, result.stderr
    with open(work / "t.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["point"] for r in rows] == [
        "'=HYPERLINK(\"x\")", "'+1", "'-2", "'@SUM(A1)", "''=x",
    ]  # fmt: skip
    assert {r["path_id"] for r in rows} == {'\'=HYPERLINK("x")'}
    assert all(float(r["vi_z_mps"]) < 0 for r in rows[1:])  # a number, not "'-..."
    table = ImpactTable.read(work / "t.csv").frame
    assert table["point"].tolist() == FORMULAS  # lossless round trip
    assert set(table["path_id"]) == {FORMULAS[0]}


def test_xlsx_refuses_a_control_character_in_one_line(cli, tmp_path):
    """openpyxl cannot store control characters: one line naming the cell, no file."""
    table = tmp_path / "bell.csv"
    table.write_text(
        "path_id,point,x_m,z_m,slope_deg,vi_x_mps,vi_z_mps,vf_x_mps,vf_z_mps\n"
        'p,"a\x07b",0,10,30,5,-5,4,2\n'
    )
    from fieldkit.errors import FieldkitError
    from fieldkit.impact_table import ImpactTable

    out = tmp_path / "bell.xlsx"
    with pytest.raises(
        FieldkitError, match=r"bell.xlsx: row 1: column point: .*control"
    ):
        ImpactTable.read(table).write(out)
    assert not out.exists()
