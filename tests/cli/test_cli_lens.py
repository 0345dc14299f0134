"""`fieldkit lens`: a checkerboard clip -> lens file for `track --lens`.

The clip is rendered here with an exact lens: each pixel of a distorted frame samples
the pinhole image (a planar checkerboard warped by its homography) at the pixel's
undistorted position, so the corners sit where the true lens puts them.
"""

from __future__ import annotations

import cv2
import numpy as np
import pandas as pd
import pytest

from fieldkit.tracking.video.calibration import (
    MAX_LENS_RMS_PX,
    Lens,
    LensCalibration,
    read_lens_file,
)

W, H = 320, 240
#: the true lens: barrel, f = 210 px (a wide angle on a 320 px frame)
TRUE = Lens(
    np.array([[210.0, 0.0, 161.0], [0.0, 210.0, 118.0], [0.0, 0.0, 1.0]]),
    np.array([-0.25, 0.06, 0.0, 0.0, 0.0]),
    (W, H),
)
VIEWS = 14


def _board_frames(lens: Lens, views: int, seed: int) -> list[np.ndarray]:
    """A board of 10 x 7 squares (9x6 inner corners, 0.1 m squares) in ``views``
    poses 1.4-1.7 m away, the first four centred, the rest toward the corners."""
    square = 20  # board pixels per square; 0.005 m per board pixel
    board = np.kron(
        (np.indices((7, 10)).sum(axis=0) % 2) * 255, np.ones((square, square))
    ).astype(np.uint8)
    board = cv2.copyMakeBorder(
        board, square, square, square, square, cv2.BORDER_CONSTANT, value=255
    )
    bh, bw = board.shape
    plane = np.array(
        [[0.005, 0, -0.005 * bw / 2], [0, 0.005, -0.005 * bh / 2], [0, 0, 1]]
    )
    vv, uu = np.mgrid[0:H, 0:W].astype(np.float64)
    map_u, map_v = lens.undistort(uu, vv)
    map_u, map_v = map_u.astype(np.float32), map_v.astype(np.float32)
    k, f = lens.camera_matrix, lens.camera_matrix[0, 0]
    rng = np.random.default_rng(seed)
    frames = []
    for i in range(views):
        rvec = rng.uniform([-0.5, -0.5, -0.3], [0.5, 0.5, 0.3])
        rot, _ = cv2.Rodrigues(rvec)
        z = rng.uniform(1.4, 1.7)
        corner = np.array([(-1) ** i, (-1) ** (i // 2)]) * (i >= 4)
        t = np.array([*(corner * (80.0, 60.0) / f * z), z])
        h = k @ np.column_stack([rot[:, 0], rot[:, 1], t]) @ plane
        ideal = cv2.warpPerspective(board, h, (W, H), borderValue=128)
        grey = cv2.remap(ideal, map_u, map_v, cv2.INTER_LINEAR, borderValue=128)
        frames.append(cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR))
    return frames


def _write_avi(path, frames) -> None:
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"MJPG"), 30.0, (W, H))
    writer.set(cv2.VIDEOWRITER_PROP_QUALITY, 95)
    for frame in frames:
        writer.write(frame)
    writer.release()


@pytest.fixture(scope="module")
def checker(tmp_path_factory):
    """A 14-frame MJPG clip of the board through :data:`TRUE`."""
    path = tmp_path_factory.mktemp("lens") / "checker.avi"
    _write_avi(path, _board_frames(TRUE, VIEWS, seed=3))
    return path


@pytest.fixture(scope="module")
def calibrated(checker, tmp_path_factory):
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("lens_out") / "lens.json"
    result = CliRunner().invoke(
        app, ["lens", str(checker), "--pattern", "9x6", "-o", str(out)]
    )
    return result, out


def test_lens_recovers_the_true_lens(calibrated):
    result, out = calibrated
    assert result.exit_code == 0, result.stderr
    assert result.stderr == ""  # no warning: RMS well below 1 px
    lens = read_lens_file(out, (W, H))
    k1, k2 = lens.distortion[:2]
    # measured: k1 -0.2526, fx 210.7 px, RMS 0.17 px (seeds 1-7 of this generator:
    # k1 within 0.0007-0.011 of the truth, fx within 0.6 %)
    assert k1 == pytest.approx(-0.25, abs=0.01)
    assert lens.camera_matrix[0, 0] == pytest.approx(210.0, rel=0.01)
    assert lens.camera_matrix[1, 1] == pytest.approx(210.0, rel=0.01)
    assert lens.frames_used == VIEWS
    assert lens.rms_px < 0.3
    # the lens moves the corner pixels by 66.4 px: the calibrated lens agrees to 2 px
    assert TRUE.corner_shift_px() == pytest.approx(66.37, abs=0.01)
    assert lens.corner_shift_px() == pytest.approx(TRUE.corner_shift_px(), abs=2.0)
    text = result.stdout
    assert f"found in {VIEWS} of {VIEWS} frames searched; {VIEWS} views used" in text
    assert f"RMS reprojection error {lens.rms_px:.3f} px" in text
    assert f"fx = {lens.camera_matrix[0, 0]:.2f} px" in text
    assert f"k1 = {k1:.5f}, k2 = {k2:.5f}" in text
    assert f"moves a point by up to {lens.corner_shift_px():.1f} px" in text
    assert text.rstrip().endswith(f"wrote {out}")


def test_lens_file_records_the_views(calibrated):
    import json

    _, out = calibrated
    data = json.loads(out.read_text())
    assert data["pattern_inner_corners"] == [9, 6]
    assert data["frames_searched"] == VIEWS and data["views_found"] == VIEWS
    assert data["view_frames"] == list(range(VIEWS))
    errors = np.array(data["view_rms_px"])
    # the overall RMS is the RMS of the per-view errors (each view has 54 corners)
    assert np.sqrt(np.mean(errors**2)) == pytest.approx(
        data["rms_reprojection_px"], rel=1e-6
    )


def test_no_board_found_names_frames_and_pattern(cli, checker, tmp_path, fails):
    out = tmp_path / "lens.json"
    fails(
        cli("lens", checker, "--pattern", "12x9", "-o", out),
        "checker.avi", "no 12x9 checkerboard", f"any of the {VIEWS} frames searched",
        "--pattern",
    )  # fmt: skip
    assert not out.exists()


def test_too_few_views_says_how_many(cli, tmp_path, fails):
    clip = tmp_path / "few.avi"
    board = _board_frames(TRUE, 3, seed=3)
    grey = np.full((H, W, 3), 128, np.uint8)
    _write_avi(clip, [*board, grey, grey, grey])
    out = tmp_path / "lens.json"
    fails(
        cli("lens", clip, "--pattern", "9x6", "-o", out),
        "few.avi", "found in only 3 of the 6 frames searched", "at least 5 views",
        "--pattern",
    )  # fmt: skip
    assert not out.exists()


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("missing.avi", "--pattern", "9x6"), ("missing.avi", "not found")),
        (("{clip}", "--pattern", "9"), ("--pattern", "COLUMNSxROWS")),
        (("{clip}", "--pattern", "2x6"), ("--pattern", "at least 3x3")),
        (("{clip}", "--pattern", "9x6", "--samples", "0"), ("--samples", ">= 1")),
    ],
)
def test_bad_input_one_line_nothing_written(cli, checker, tmp_path, fails, args, words):
    out = tmp_path / "lens.json"
    args = [str(checker) if a == "{clip}" else a for a in args]
    fails(cli("lens", *args, "-o", out), *words)
    assert not out.exists()


def test_output_must_be_json_and_an_existing_one_stays_on_error(
    cli, checker, tmp_path, fails
):
    fails(cli("lens", checker, "--pattern", "9x6", "-o", tmp_path / "l.csv"), "-o")
    assert not (tmp_path / "l.csv").exists()
    old = tmp_path / "old.json"
    old.write_text("{}\n")
    fails(cli("lens", checker, "--pattern", "12x9", "-o", old), "--pattern")
    assert old.read_text() == "{}\n"


def test_large_reprojection_error_is_warned():
    lens = Lens(TRUE.camera_matrix, TRUE.distortion, (W, H), 1.4, 6)
    fit = LensCalibration(lens, (9, 6), 30, 6, (0, 5, 9, 14, 20, 29),
                          (0.3, 0.4, 3.1, 0.5, 0.4, 0.3), 0.6)  # fmt: skip
    (message,) = fit.warnings
    assert f"1.40 px exceeds {MAX_LENS_RMS_PX:g} px" in message
    assert "frame 9, 3.10 px" in message
    ok = LensCalibration(TRUE, (9, 6), 30, 6, tuple(range(6)), (0.1,) * 6, 0.6)
    assert ok.warnings == []


def test_track_undistorts_with_the_lens_file(cli, calibrated, video_render, tmp_path):
    """One round trip: `track --lens` reads the file and its u_px, v_px are the
    undistorted centres of the run without it."""
    _, lens_file = calibrated
    render = video_render
    camera = render.Camera(width=W, height=H, origin_u_px=20.0, origin_v_px=220.0)
    rng = np.random.default_rng(4)
    scene = render.BounceScene(plate_point_m=(0.0, -1.0))  # plate out of view
    bg = np.clip(render.background(camera, rng, scene) + 0.5, 0, 255).astype(np.uint8)
    fps = 1205.0
    t = np.arange(30) / fps
    poses = np.column_stack(
        [0.05 + 2.5 * t, 0.25 + 1.0 * t - 0.5 * 9.81 * t**2, 0.2 - 40.0 * t]
    )
    clip = tmp_path / "throw.avi"
    render.write_clip(clip, camera, render.Ball(), bg, poses, rng, codec="MJPG")
    scale = ("--scale-points", "20,20,300,20", "--scale-length", "0.56")
    runs = {}
    for label, extra in (("raw", ()), ("lens", ("--lens", lens_file))):
        out = tmp_path / f"{label}.csv"
        result = cli("track", clip, "--fps", fps, *scale, *extra, "-o", out)
        assert result.exit_code == 0, result.stderr
        runs[label] = pd.read_csv(out)
    raw, undistorted = runs["raw"], runs["lens"]
    assert len(raw) == len(undistorted) > 20
    u, v = read_lens_file(lens_file).undistort(raw["u_px"], raw["v_px"])
    assert np.max(np.abs(undistorted["u_px"] - u)) < 1e-6
    assert np.max(np.abs(undistorted["v_px"] - v)) < 1e-6
    assert np.max(np.hypot(u - raw["u_px"], v - raw["v_px"])) > 5.0  # it did move


def test_board_seen_only_near_the_centre_is_warned():
    fit = LensCalibration(TRUE, (9, 6), 30, 8, tuple(range(8)), (0.1,) * 8, 0.22)
    (message,) = fit.warnings
    assert "cover only 22% of the frame" in message


def test_frames_of_two_sizes_are_refused():
    from fieldkit.errors import InputFileError
    from fieldkit.tracking.video.calibration import fit_lens

    frames = _board_frames(TRUE, 2, seed=3)
    with pytest.raises(InputFileError, match=r"frame 2: 160x120 px, the frames before"):
        fit_lens([*frames, cv2.resize(frames[0], (160, 120))], (9, 6))
