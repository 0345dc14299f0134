"""`fieldkit track` messages point at the real cause: the homography file and its
points, a file that is no video, a body of another size than the one looked for,
and nothing of FFmpeg's own output on stderr.

Each case: exit code != 0, one `error:` line naming the file at fault (not the video
when the calibration is to blame), nothing written, the inputs unchanged.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys

import numpy as np
import pytest

FPS = 1205.0
SCALE = ("--scale-points", "20,20,300,20", "--scale-length", "0.56")  # 2 mm/px
#: image <-> world corners of the 2 mm/px scene (world origin at (20, 220) px)
CORNERS = [(20, 220, 0.0, 0.0), (300, 220, 0.56, 0.0), (300, 20, 0.56, 0.4)]
CORNERS += [(20, 20, 0.0, 0.4)]


@pytest.fixture(scope="module")
def render(repo):
    name = "fieldkit_video_render_for_track_messages"
    spec = importlib.util.spec_from_file_location(name, repo / "video" / "render.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def clip(render, tmp_path_factory):
    """A ball of radius 0.0375 m (18.75 px) thrown across a 320x240 scene."""
    path = tmp_path_factory.mktemp("clip") / "throw.avi"
    camera = render.Camera(width=320, height=240, origin_u_px=20.0, origin_v_px=220.0)
    rng = np.random.default_rng(4)
    scene = render.BounceScene(plate_point_m=(0.0, -1.0))
    bg = np.clip(render.background(camera, rng, scene) + 0.5, 0, 255).astype(np.uint8)
    t = np.arange(80) / FPS
    poses = np.column_stack(
        [0.05 + 2.5 * t, 0.25 + 1.0 * t - 0.5 * 9.81 * t**2, 0.2 - 40.0 * t]
    )
    render.write_clip(path, camera, render.Ball(), bg, poses, rng)
    return path


def track_fails(cli, tmp_path, video, args, *expected, inputs=()):
    """One error line starting with ``expected[0]``, holding the rest; no output."""
    inputs = [video, *inputs]
    before = {p: p.read_bytes() for p in inputs}
    out = tmp_path / "out"
    result = cli(
        "track",
        video,
        "--fps",
        FPS,
        *args,
        "-o",
        out / "t.csv",
        "--impacts",
        out / "i.csv",
        "--figures",
        out / "figs",
    )
    assert result.exit_code not in (0, None), result.stdout
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"error: {expected[0]}"), lines[0]
    for text in expected[1:]:
        assert text in lines[0], (text, lines[0])
    assert not out.exists()
    for path, data in before.items():
        assert path.read_bytes() == data
    return lines[0]


def homography_csv(tmp_path, points, header="u_px,v_px,x_m,z_m"):
    path = tmp_path / "h.csv"
    path.write_text(
        header + "\n" + "".join(f"{u},{v},{x},{z}\n" for u, v, x, z in points)
    )
    return path


# --- the homography file is to blame -------------------------------------------------


@pytest.mark.parametrize(
    ("points", "words"),
    [
        (  # four image points on one line
            [
                (20, 220, 0, 0),
                (100, 170, 0.16, 0),
                (180, 120, 0.36, 0.2),
                (260, 70, 0.56, 0.4),
            ],
            ("the image points lie on one line",),
        ),
        (  # four world points on one line
            [(20, 220, 0, 0), (300, 220, 0.2, 0), (300, 20, 0.4, 0), (20, 20, 0.56, 0)],
            ("the world points lie on one line",),
        ),
        (  # three of four on a line: the mapping is undetermined
            [
                (20, 220, 0, 0),
                (300, 220, 0.56, 0),
                (160, 220, 0.28, 0),
                (20, 20, 0, 0.4),
            ],
            ("do not fix a homography", "points 1, 2, 3 on one line in the image"),
        ),
        (  # a point repeated
            [*CORNERS, CORNERS[3]],
            ("point 5: same position as point 4",),
        ),
        (  # world points 3 and 4 swapped: the mapping folds the picture
            [*CORNERS[:2], (300, 20, 0.0, 0.4), (20, 20, 0.56, 0.4)],
            ("not in the same arrangement", "points 3, 4"),
        ),
    ],
    ids=["image-line", "world-line", "three-on-a-line", "repeated", "swapped"],
)
def test_bad_homography_blames_the_file_and_its_points(
    cli, clip, tmp_path, points, words
):
    h = homography_csv(tmp_path, points)
    message = track_fails(
        cli,
        tmp_path,
        clip,
        ["--homography", h, "--radius", "0.0375"],
        f"{h}:",
        *words,
        inputs=[h],
    )
    assert clip.name not in message


def test_homography_world_columns_need_a_unit(cli, clip, tmp_path):
    h = homography_csv(tmp_path, CORNERS, header="u_px,v_px,x,z")
    track_fails(
        cli,
        tmp_path,
        clip,
        ["--homography", h],
        f"{h}: row 1: column 'x' has no length unit",
        inputs=[h],
    )


@pytest.mark.parametrize(
    ("content", "words"),
    [
        ("[" * 100_000 + "]" * 100_000, ("JSON nested too deeply",)),
        (
            '{"points": [{"u_px": 20, "v_px": 220, "x_m": 0, "z_m": 0, "note": "é"}]}',
            ("line 1: not UTF-8 (byte 0xe9)", "save it as UTF-8"),
        ),
        ('{"points": []}'.encode("utf-16"), ("UTF-16 encoded; save it as UTF-8",)),
        ('{"points": [1, 2', ("line 1: not valid JSON",)),
    ],
    ids=["deep", "latin-1", "utf-16", "truncated"],
)
def test_hostile_homography_json(cli, clip, tmp_path, content, words):
    h = tmp_path / "h.json"
    h.write_bytes(content if isinstance(content, bytes) else content.encode("latin-1"))
    track_fails(cli, tmp_path, clip, ["--homography", h], f"{h}:", *words, inputs=[h])


# --- the video file ------------------------------------------------------------------


def test_non_video_renamed_avi(cli, tmp_path):
    import zipfile

    text = tmp_path / "table.avi"
    text.write_text("point,x_m,z_m\nA,0,100\n" * 50)
    archive = tmp_path / "archive.avi"
    with zipfile.ZipFile(archive, "w") as handle:
        handle.writestr("a.txt", "hello " * 200)
    for video in (text, archive):
        track_fails(
            cli,
            tmp_path,
            video,
            SCALE,
            f"{video}: cannot open as a video",
            "not a container and codec OpenCV can decode",
        )


def test_still_image_renamed_avi(cli, tmp_path):
    import cv2

    image = (np.random.default_rng(1).random((240, 320, 3)) * 255).astype(np.uint8)
    png = tmp_path / "photo.png"
    cv2.imwrite(str(png), image)
    video = tmp_path / "photo.avi"
    video.write_bytes(png.read_bytes())
    track_fails(cli, tmp_path, video, SCALE, f"{video}: holds a single frame: a still")


# --- a body of another size ----------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "looked_for"),
    [
        ((*SCALE, "--radius", "0.075"), "no body of radius 37.5 px"),  # a diameter
        (
            (
                "--scale-points",
                "20,20,300,20",
                "--scale-length",
                "1.12",
                "--radius",
                "0.0375",
            ),
            "no body of radius 9.4 px",  # the scale twice too coarse
        ),
    ],
    ids=["diameter-as-radius", "wrong-scale"],
)
def test_no_body_of_the_expected_size_says_what_it_saw(
    cli, clip, tmp_path, args, looked_for
):
    message = track_fails(
        cli, tmp_path, clip, args, f"{clip}: frames 0-79: {looked_for} found", "mm/px"
    )
    seen = float(message.split("bodies seen have radius ")[1].split(" px")[0])
    assert seen == pytest.approx(18.75, abs=1.5)  # the ball drawn: 37.5 mm at 2 mm/px
    assert "a diameter given as the radius, or a wrong scale" in message


def test_no_body_at_all_says_nothing_moved(cli, render, tmp_path):
    path = tmp_path / "empty_scene.avi"
    camera = render.Camera(width=320, height=240, origin_u_px=20.0, origin_v_px=220.0)
    rng = np.random.default_rng(4)
    scene = render.BounceScene(plate_point_m=(0.0, -1.0))
    bg = np.clip(render.background(camera, rng, scene) + 0.5, 0, 255).astype(np.uint8)
    render.write_clip(path, camera, render.Ball(), bg, np.full((30, 3), np.nan), rng)
    track_fails(
        cli,
        tmp_path,
        path,
        (*SCALE, "--radius", "0.0375"),
        f"{path}: frames 0-29: no body of radius 18.7 px",
        "nor a moving body of any other size",
    )


# --- FFmpeg's own lines never reach the user -----------------------------------------


def _track_in_subprocess(repo, video, out):
    env = {k: v for k, v in os.environ.items() if not k.startswith("OPENCV_")}
    env["PYTHONPATH"] = os.pathsep.join([str(repo), env.get("PYTHONPATH", "")])
    env["MPLBACKEND"] = "Agg"
    return subprocess.run(
        [sys.executable, "-m", "fieldkit", "track", str(video), "--fps", str(FPS)]
        + [*SCALE, "--radius", "0.0375", "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )


def test_ffmpeg_messages_are_silenced(repo, clip, tmp_path):
    data = clip.read_bytes()
    damaged = tmp_path / "damaged.avi"
    body = bytearray(data[: len(data) * 2 // 3])  # truncated ...
    for i in range(20_000, len(body), 997):  # ... with corrupt JPEG data
        body[i] ^= 0x55
    damaged.write_bytes(bytes(body))
    # FFmpeg does complain about this file when OpenCV opens it directly
    read_all = (
        "import cv2, sys; c = cv2.VideoCapture(sys.argv[1], cv2.CAP_FFMPEG)\n"
        "while c.read()[0]: pass"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith("OPENCV_")}
    loud = subprocess.run(
        [sys.executable, "-c", read_all, str(damaged)],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert "[mjpeg @" in loud.stderr
    done = _track_in_subprocess(repo, damaged, tmp_path / "t.csv")
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert lines, done.stderr
    assert all(line.startswith(("error: ", "warning: ", "note: ")) for line in lines), (
        done.stderr
    )
    assert any("damaged.avi: frames" in line for line in lines), done.stderr


# --- the stated calibration uncertainty ----------------------------------------------


@pytest.mark.parametrize(
    ("args", "flag"),
    [
        (("--scale-sd", "-1"), "--scale-sd"),
        (("--fps-sd", "nan"), "--fps-sd"),
        (("--fps-sd", "2000"), "--fps-sd"),
    ],
    ids=["negative-scale-sd", "nan-fps-sd", "fps-sd-past-fps"],
)
def test_a_bad_stated_uncertainty_names_its_flag(cli, clip, tmp_path, args, flag):
    track_fails(cli, tmp_path, clip, [*SCALE, "--radius", "0.0375", *args], flag)


def test_the_stated_uncertainty_widens_the_printed_g(cli, clip, tmp_path):
    """The same clip with the scale stated to 5 %: each flight's printed SE is the
    fit's and 5 % of g in quadrature, and the note says what was stated."""
    base = [clip, "--fps", FPS, *SCALE, "--radius", "0.0375"]
    exact = cli("track", *base)
    stated = cli("track", *base, "--scale-sd", "5")
    assert exact.exit_code == 0 and stated.exit_code == 0, stated.stderr
    assert "scale +/- 5 %" in stated.stdout + stated.stderr

    def g_and_se(text):
        import re

        return [
            (float(g), float(se))
            for g, se in re.findall(r"g = ([0-9.]+) \+/- ([0-9.]+) m/s\^2", text)
        ]

    plain, wide = g_and_se(exact.stdout), g_and_se(stated.stdout)
    assert plain and len(plain) == len(wide)
    for (g0, se0), (g1, se1) in zip(plain, wide, strict=True):
        assert g1 == pytest.approx(g0, abs=0.01)
        assert se1 == pytest.approx(np.hypot(se0, 0.05 * g0), rel=0.05, abs=0.01)
