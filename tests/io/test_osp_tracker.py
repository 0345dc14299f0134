"""Reading Open Source Physics Tracker exports (samples: tests/io/data/README.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.osp_tracker import read_osp_tracker
from fieldkit.tracking.flights.ballistic_fit import fit_flight

DATA = Path(__file__).parent / "data"


def truth(t):
    return 0.2 + 1.5 * t, 1.0 + 2.0 * t - 0.5 * 9.81 * t**2


def test_tab_separated_decimal_comma_export():
    tr = read_osp_tracker(DATA / "osp_tracker_ball_tab_decimal_comma.txt")
    assert tr.meta["track_name"] == "ball" and tr.meta["delimiter"] == "\t"
    assert len(tr) == 60
    np.testing.assert_allclose(tr.t, np.arange(60) / 240.0, atol=1e-9)
    x, z = truth(tr.t)
    np.testing.assert_allclose(tr.x, x, atol=1e-8)
    np.testing.assert_allclose(tr.z, z, atol=1e-8)
    fit = fit_flight(tr.t, tr.x, tr.z)
    assert fit.g_mps2 == pytest.approx(9.81, rel=1e-6)


@pytest.mark.parametrize(
    ("name", "offset"), [(None, 0.0), ("ball", 0.0), ("marker", 0.0375)]
)
def test_multi_track_comma_export_in_centimetres(name, offset):
    tr = read_osp_tracker(
        DATA / "osp_tracker_multi_comma_cm.csv", track_name=name, unit="cm"
    )
    assert tr.meta["track_name"] == (name or "ball")
    x, z = truth(tr.t)
    # written with 6 significant digits in cm: rounding up to 5e-4 cm = 5e-6 m
    np.testing.assert_allclose(tr.x, x + offset, atol=6e-6)
    np.testing.assert_allclose(tr.z, z, atol=6e-6)


def test_playback_rate_correction():
    # the same file read as if Tracker had timed a 1205 fps clip at 240 fps
    tr = read_osp_tracker(
        DATA / "osp_tracker_ball_tab_decimal_comma.txt", fps=1205.0, file_fps=240.0
    )
    assert tr.t[1] == pytest.approx(1 / 1205.0)
    assert fit_flight(tr.t, tr.x, tr.z).g_mps2 == pytest.approx(
        9.81 * (1205 / 240) ** 2
    )


def test_pixels_need_a_scale(tmp_path):
    p = tmp_path / "px.txt"
    p.write_text("ball\nt\tx\ty\n0\t100\t200\n0.01\t110\t195\n")
    with pytest.raises(ArgumentError, match="metres per pixel"):
        read_osp_tracker(p, unit="px")
    tr = read_osp_tracker(p, unit="px", metres_per_pixel=0.001)
    np.testing.assert_allclose(tr.x, [0.1, 0.11])
    np.testing.assert_allclose(tr.z, [0.2, 0.195])


@pytest.mark.parametrize(
    ("text", "message", "where"),
    [
        ("ball\nt\tx\ty\n0\t1\t2\n0,1\tabc\t2\n", "'abc' is not a number", "row 4"),
        ("ball\nfoo\tbar\n1\t2\n", "no column header with 't'", "row 2"),
        ("ball\nt\tx\ty\n", "no data rows", None),
        ("ball\nt\tx\ty\n0,2\t1\t2\n0,1\t1\t2\n", "times are not increasing", "row 4"),
        ("ball\nt,x,y\n0,0,1,5,2\n", "decimal commas with a comma separator", "row 3"),
    ],
)
def test_bad_files_name_the_row(tmp_path, text, message, where):
    p = tmp_path / "bad.txt"
    p.write_text(text)
    with pytest.raises(InputFileError) as err:
        read_osp_tracker(p)
    assert message in str(err.value) and str(err.value).startswith(str(p))
    if where:
        assert f": {where}: " in str(err.value)


def test_missing_and_empty_files(tmp_path):
    with pytest.raises(InputFileError, match="file not found"):
        read_osp_tracker(tmp_path / "none.txt")
    (tmp_path / "empty.txt").write_text("")
    with pytest.raises(InputFileError, match="file is empty"):
        read_osp_tracker(tmp_path / "empty.txt")


def test_unknown_track_lists_the_tracks():
    with pytest.raises(InputFileError, match="holds ball, marker"):
        read_osp_tracker(DATA / "osp_tracker_multi_comma_cm.csv", track_name="rock")
