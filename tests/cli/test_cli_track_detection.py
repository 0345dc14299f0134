"""`fieldkit track`'s detection options: hints, stabilisation, lens; refusal counts."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

FPS = 1205.0
SCALE = ("--scale-points", "20,20,300,20", "--scale-length", "0.56")  # 2 mm/px


@pytest.fixture(scope="module")
def clip(video_render, tmp_path_factory):
    """A ball thrown across a 320x240 scene (video/render.py), frames 40-42 empty."""
    render = video_render
    camera = render.Camera(width=320, height=240, origin_u_px=20.0, origin_v_px=220.0)
    rng = np.random.default_rng(4)
    scene = render.BounceScene(plate_point_m=(0.0, -1.0))  # plate out of view
    bg = np.clip(render.background(camera, rng, scene) + 0.5, 0, 255).astype(np.uint8)
    t = np.arange(80) / FPS
    poses = np.column_stack(
        [0.05 + 2.5 * t, 0.25 + 1.0 * t - 0.5 * 9.81 * t**2, 0.2 - 40.0 * t]
    )
    poses[40:43] = np.nan
    path = tmp_path_factory.mktemp("clip") / "throw.avi"
    render.write_clip(path, camera, render.Ball(), bg, poses, rng, codec="MJPG")
    return path, poses, camera


def test_refusal_counts_and_hints(cli, clip, tmp_path):
    video, poses, camera = clip
    u, v = camera.to_image(poses[0, 0], poses[0, 1])
    out = tmp_path / "t.csv"
    box = f"{u - 19:.0f},{v - 19:.0f},38,38"  # the ball's 37.5 mm at 2 mm/px
    result = cli(
        "track", video, "--fps", FPS, *SCALE, "--first-box", box,
        "--body-colour", "230,120,40", "--no-stabilise", "-o", out,
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "77 frames: body found (ok)" in result.stdout
    assert "3 frames: no body (no_candidate: nothing differs" in result.stdout
    track = pd.read_csv(out)
    assert len(track) == 77
    assert "detection unsure" not in result.stderr


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("--body-colour", "300,0,0"), ("--body-colour", "0 to 255")),
        (("--first-box", "1,2,3"), ("--first-box", "U,V,WIDTH,HEIGHT")),
        (("--first-box", "900,20,10,10"), ("--first-box", "outside")),
        (("--lens", "missing.json"), ("missing.json", "not found")),
    ],
)
def test_bad_hints_one_line(cli, clip, tmp_path, fails, args, words):
    out = tmp_path / "t.csv"
    fails(cli("track", clip[0], "--fps", FPS, *SCALE, *args, "-o", out), *words)
    assert not out.exists()


def test_lens_for_another_frame_size_is_refused(cli, clip, tmp_path, fails):
    lens = tmp_path / "lens.json"
    lens.write_text(
        json.dumps(
            {
                "camera_matrix": [[400, 0, 320], [0, 400, 240], [0, 0, 1]],
                "distortion": [-0.1, 0, 0, 0, 0],
                "image_size_px": [640, 480],
            }
        )
    )
    out = tmp_path / "t.csv"
    fails(
        cli("track", clip[0], "--fps", FPS, *SCALE, "--lens", lens, "-o", out),
        "lens.json", "640x480", "320x240",
    )  # fmt: skip
