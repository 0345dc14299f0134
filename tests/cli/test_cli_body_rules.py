"""The body rules hold for every command that takes a body (issue 7).

One table of rulings (mass, radius, gyration, shape, dimensions, unit weight) is run
against `reduce`, `impact`, `fence` and `track`: each case either fails with one
``error:`` line naming the flags at fault, or succeeds and prints its note. All go
through :func:`fieldkit.physics.bodies.resolve_body`; what each command needs when a
value is missing is its own (`BODY_NEEDS` in its module).
"""

from __future__ import annotations

import importlib.util
import sys
from dataclasses import dataclass

import numpy as np
import pytest

FPS = 1205.0
SCALE = ("--scale-points", "20,20,300,20", "--scale-length", "0.56")  # 2 mm/px

#: Boulder-sized bodies for reduce/impact/fence; `track` films a 37.5 mm ball, so its
#: bodies are these scaled by 0.05 (sphere 0.75 m -> 0.0375 m, the rendered ball).
SCALE_OF = {"reduce": 1.0, "impact": 1.0, "fence": 1.0, "track": 0.05}
COMMANDS = tuple(SCALE_OF)
ELLIPSOID = (1.6, 1.3, 1.3)  # Tornado boulder A: contact radius 0.65-0.8 m


@dataclass(frozen=True)
class Case:
    """A body given to every command, and what must happen."""

    ruling: str
    body: tuple  # option strings; numbers are lengths [m] scaled per command
    error: tuple[str, ...] = ()  # words of the one-line error; empty = success
    note: str | None = None  # text a successful run prints on stderr


def _dims(separator: str) -> tuple:
    return ("--shape", "ellipsoid", "--dimensions", ("dims", separator))


CASES = [
    Case(
        "weighed mass overrides the shape's",
        ("--shape", "sphere", "--dimensions", 0.75, "--mass", "3000"),
        note="note: --mass 3000 kg overrides the",
    ),
    Case(
        "gyration with a shape",
        ("--shape", "sphere", "--dimensions", 0.75, "--gyration", 0.4),
        error=("--gyration", "--shape", "--dimensions"),
    ),
    Case(
        "inside the shape's radius range",
        (*_dims(","), "--radius", 0.8),
        note="note: --radius",
    ),
    Case(
        "outside the shape's radius range",
        (*_dims(","), "--radius", 0.9),
        error=("--radius", "--shape ellipsoid", "must be between"),
    ),
    Case(
        "unit weight without a shape",
        ("--radius", 0.5, "--gyration", 0.3, "--mass", "500", "--unit-weight", "24"),
        error=("--unit-weight", "--shape"),
    ),
    Case(
        "dimensions without a shape",
        ("--dimensions", 0.75, "--mass", "500"),
        error=("--dimensions", "--shape"),
    ),
    Case("shape name in capitals", ("--shape", "SPHERE", "--dimensions", 0.75)),
    Case(
        "shape name mixed case",
        ("--shape", "Ellipsoid", "--dimensions", ("dims", ",")),
    ),
    Case("dimensions 1.6x1.3x1.3", _dims("x")),
    Case("dimensions 1.6 X 1.3 X 1.3", _dims(" X ")),
    Case("dimensions 1.6, 1.3, 1.3", _dims(", ")),
    Case(
        "k > r",
        ("--radius", 0.3, "--gyration", 0.35, "--mass", "500"),
        error=("--gyration must be <= --radius",),
    ),
    Case(
        "k <= 0",
        ("--radius", 0.3, "--gyration", -0.2, "--mass", "500"),
        error=("--gyration must be > 0",),
    ),
    Case(
        "r <= 0",
        ("--radius", 0.0, "--gyration", 0.2, "--mass", "500"),
        error=("--radius must be > 0",),
    ),
]


@pytest.fixture(scope="module")
def clip(repo, tmp_path_factory):
    """A ball thrown across a 320x240 scene (2 mm/px) with video/render.py."""
    name = "fieldkit_video_render_for_body_rules"
    spec = importlib.util.spec_from_file_location(name, repo / "video" / "render.py")
    render = importlib.util.module_from_spec(spec)
    sys.modules[name] = render
    spec.loader.exec_module(render)
    camera = render.Camera(width=320, height=240, origin_u_px=20.0, origin_v_px=220.0)
    rng = np.random.default_rng(4)
    scene = render.BounceScene(plate_point_m=(0.0, -1.0))  # plate out of view
    bg = np.clip(render.background(camera, rng, scene) + 0.5, 0, 255).astype(np.uint8)
    t = np.arange(60) / FPS
    poses = np.column_stack(
        [0.05 + 2.5 * t, 0.25 + 1.0 * t - 0.5 * 9.81 * t**2, 0.2 - 40.0 * t]
    )
    path = tmp_path_factory.mktemp("clip") / "throw.avi"
    render.write_clip(path, camera, render.Ball(), bg, poses, rng, codec="MJPG")
    return path


def _command_args(command, repo, clip, tmp_path) -> list:
    """Everything a command needs except the body."""
    if command == "reduce":
        section = repo / "surveys" / "ehime" / "cube_section.csv"
        return [
            "reduce",
            "--impacts",
            section,
            "--theta0",
            "30",
            "-o",
            tmp_path / "t.csv",
        ]
    if command == "impact":
        return ["impact", "--speed", "22", "--angle", "25", "--en", "0.5"]
    if command == "fence":  # rebound computed from r and k
        return ["fence", "--speed-in", "22", "--angle-in", "50"]
    return ["track", clip, "--fps", FPS, *SCALE, "-o", tmp_path / "track.csv"]


def _body_args(body: tuple, scale: float) -> list[str]:
    """Option strings, with lengths (numbers) and dimensions scaled."""
    args = []
    for item in body:
        if isinstance(item, tuple):  # ("dims", separator)
            args.append(item[1].join(f"{d * scale:g}" for d in ELLIPSOID))
        elif isinstance(item, float):
            args.append(f"{item * scale:g}")
        else:
            args.append(item)
    return args


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("case", CASES, ids=lambda c: c.ruling)
def test_body_ruling_holds_for_every_command(
    cli, fails, repo, clip, tmp_path, command, case
):
    body = _body_args(case.body, SCALE_OF[command])
    result = cli(*_command_args(command, repo, clip, tmp_path), *body)
    if case.error:
        fails(result, *case.error)
    else:
        assert result.exit_code == 0, result.stderr
        # no error line ("standard errors" in a warning is not one)
        assert not any(
            line.startswith("error") for line in result.stderr.splitlines()
        ), result.stderr
        if case.note:
            assert case.note in result.stderr, result.stderr


#: What each command says when it lacks a body value it needs (its BODY_NEEDS); a
#: mass alone does not help `impact`.
MISSING = {
    "impact": "error: fieldkit impact: body needs --radius and --gyration (or --shape)",
    "fence": "error: fieldkit fence: body needs --mass (or --shape)",
}


def test_impact_with_a_mass_still_needs_radius_and_gyration(cli, fails):
    result = cli(
        "impact", "--speed", "22", "--angle", "25", "--en", "0.5", "--mass", "9"
    )
    fails(result)
    assert result.stderr.strip() == MISSING["impact"]


@pytest.mark.parametrize("command", COMMANDS)
def test_missing_body_values_are_named_in_one_line(
    cli, fails, repo, clip, tmp_path, command
):
    # reduce needs nothing (columns it cannot fill stay NaN); track measures the
    # radius it needs from the video and says so
    result = cli(*_command_args(command, repo, clip, tmp_path))
    if command in MISSING:
        fails(result)
        assert result.stderr.strip() == MISSING[command]
    else:
        assert result.exit_code == 0, result.stderr
    if command == "track":
        assert "note: --radius not given; using the measured" in result.stderr


def test_weighed_mass_and_given_radius_reach_the_table(cli, repo, tmp_path):
    import pandas as pd

    args = _command_args("reduce", repo, None, tmp_path)
    body = _body_args((*_dims("x"), "--mass", "3000", "--radius", 0.8), 1.0)
    result = cli(*args, *body)
    assert result.exit_code == 0, result.stderr
    table = pd.read_csv(tmp_path / "t.csv")
    assert (table["mass_kg"] == 3000).all() and (table["radius_m"] == 0.8).all()
    assert table["gyration_m"].iloc[0] == pytest.approx(0.461, abs=5e-4)  # shape's k
