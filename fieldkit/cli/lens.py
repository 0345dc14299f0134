"""`fieldkit lens`: lens distortion from a checkerboard clip, for `track --lens`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import one_line_errors, warn
from fieldkit.cli.progress import report_written, step
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet


@one_line_errors
def lens(
    clip: Annotated[
        Path,
        typer.Argument(
            metavar="CLIP",
            help="A video of a flat checkerboard filmed with the camera, lens and "
            "zoom of the clips to track, in many positions and tilts across the "
            "frame.",
        ),
    ],
    out: Annotated[
        Path,
        typer.Option("-o", "--out", help="Lens file to write (.json), for --lens."),
    ],
    pattern: Annotated[
        str,
        typer.Option(
            "--pattern",
            metavar="COLSxROWS",
            help="Inner corners of the board, columns x rows: where four squares "
            "meet, not the squares (a board of 10 x 7 squares has 9x6).",
        ),
    ],
    samples: Annotated[
        int,
        typer.Option(
            "--samples",
            help="Frames searched for the board, spread evenly over the clip (every "
            "frame when it has fewer); at most 40 views with the board are used.",
        ),
    ] = 60,
) -> None:
    """Calibrate the lens from a checkerboard clip (OpenCV's pinhole model).

    Fits focal length, principal point and distortion k1, k2, p1, p2 (k3 is
    kept 0) with cv2.calibrateCamera, and writes a lens file that `fieldkit
    track --lens` reads: detections (and --homography points) are then
    undistorted before they become metres. Prints the views found and used, the
    RMS reprojection error (warned above 1 px), the intrinsics and how far the
    lens moves a point at the image corners. The board's square size is not
    needed: it does not change the lens, only the board's distance.

    Example (from the repository root; the first line renders a 16-frame
    checkerboard clip through the barrel lens of the hard_lens clip,
    k1 = -0.28, k2 = 0.09, f = 420 px):

        python video/render.py --out out/clips hard_lens_checker
        fieldkit lens out/clips/hard_lens_checker.avi --pattern 9x6 \\
          -o out/lens.json
    """
    from fieldkit.tracking.video.calibration import fit_lens_from_clip, parse_pattern

    outputs = OutputSet(inputs=[clip])
    outputs.plan(out, argument="-o")
    if out.suffix.lower() != ".json":
        raise ArgumentError(
            f"the lens file must be a .json file, got {out.name!r}", source="-o"
        )
    size = parse_pattern(pattern)
    with step(f"searching {samples} frames for the checkerboard", announce=False):
        fit = fit_lens_from_clip(clip, size, samples=samples)
    for line in fit.summary():
        typer.echo(line)
    for message in fit.warnings:
        warn(message)
    fit.write(out, outputs)
    report_written(outputs.commit())
