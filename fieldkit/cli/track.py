"""`fieldkit track`: a high-speed video -> track, flights, impacts (ImpactTable)."""

from __future__ import annotations

import dataclasses
import functools
import math
from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import (
    DimensionsOpt,
    GyrationOpt,
    MassOpt,
    RadiusOpt,
    ShapeOpt,
    UnitWeightOpt,
    body_from_options,
    command_flags,
    note,
    one_line_errors,
    print_body_notes,
    warn,
    with_flags,
)
from fieldkit.cli.progress import report_written, step
from fieldkit.errors import ArgumentError
from fieldkit.impact_table import table_format
from fieldkit.io.tracking_export import check_frame_rate
from fieldkit.outputs import OutputSet

#: show a progress bar for videos longer than this many frames
PROGRESS_MIN_FRAMES = 300

#: Body values `track` needs; a radius not given is measured from the video.
BODY_NEEDS = ("radius_m",)


#: Names of the ground's arguments (fieldkit.tracking.flights.ground) -> this
#: command's flags.
GROUND_FLAGS = {
    "ground_profile": "--surface-profile",
    "section_line": "--section",
    "footprint_m": "--footprint",
}


@one_line_errors(flags=GROUND_FLAGS)
def track(
    video: Annotated[
        Path,
        typer.Argument(
            help="High-speed video (AVI/MP4/MKV: MJPG, FFV1, mp4v, ...).",
            show_default=False,
        ),
    ],
    fps: Annotated[
        float | None,
        typer.Option(
            "--fps",
            help="Capture rate in frames/s (required: high-speed cameras store a "
            "different playback rate, e.g. 30).",
        ),
    ] = None,
    scale_points: Annotated[
        str | None,
        typer.Option(
            "--scale-points",
            metavar="U1,V1,U2,V2",
            help="Two image points (pixels) a known distance apart (level camera; the "
            "world origin is the first point).",
        ),
    ] = None,
    scale_length: Annotated[
        float | None,
        typer.Option("--scale-length", help="Distance between the scale points (m)."),
    ] = None,
    homography: Annotated[
        Path | None,
        typer.Option(
            "--homography",
            help="JSON or CSV of >= 4 image<->world points (u_px,v_px,x_m,z_m; z up) "
            "instead of --scale-points.",
        ),
    ] = None,
    scale_sd: Annotated[
        float,
        typer.Option(
            "--scale-sd",
            help="Standard uncertainty of the length scale (--scale-length or "
            "--homography), in percent (default 0: taken as exact). With --fps-sd "
            "it widens each flight's check of g against 9.81 (g scales with the "
            "length), not the velocities.",
        ),
    ] = 0.0,
    fps_sd: Annotated[
        float,
        typer.Option(
            "--fps-sd",
            help="Standard uncertainty of --fps (frames/s; default 0: exact). g "
            "scales with the square of the rate.",
        ),
    ] = 0.0,
    radius: RadiusOpt = None,
    surface_angle: Annotated[
        float | None,
        typer.Option(
            "--surface-angle",
            help="Dip of the impact surface (deg), positive descending along travel, "
            "one for every contact (default: estimated from the contact points; a "
            "slope per contact: --surface-profile or --surface-dem).",
        ),
    ] = None,
    surface_profile: Annotated[
        Path | None,
        typer.Option(
            "--surface-profile",
            help="Surveyed section of the ground in the calibrated frame (the "
            "homography's or scale points' x, z up, metres): a profile CSV "
            "(x_m,z_m[,material], as `fieldkit profile` writes) or a model file's "
            "profile. The slope at each contact is the dip of the segment nearest "
            "the body's centre.",
        ),
    ] = None,
    surface_dem: Annotated[
        Path | None,
        typer.Option(
            "--surface-dem",
            help="DEM of the ground (ESRI ASCII grid, GeoTIFF), with --section: the "
            "slope at each contact is a plane fitted over the block's footprint "
            "(--footprint), its dip along the section line.",
        ),
    ] = None,
    section: Annotated[
        str | None,
        typer.Option(
            "--section",
            metavar="E1,N1,E2,N2",
            help="--surface-dem: plan line of the section (DEM coordinates); the "
            "track's x is the plan distance from E1,N1 toward E2,N2.",
        ),
    ] = None,
    footprint: Annotated[
        float | None,
        typer.Option(
            "--footprint",
            help="--surface-dem: radius of the plane fit (m; default the body "
            "radius, at least one DEM cell).",
        ),
    ] = None,
    mass: MassOpt = None,
    gyration: GyrationOpt = None,
    shape: ShapeOpt = None,
    dimensions: DimensionsOpt = None,
    unit_weight: UnitWeightOpt = None,
    roi: Annotated[
        str | None,
        typer.Option(
            "--roi",
            metavar="U,V,WIDTH,HEIGHT",
            help="Search only this image region (pixels).",
        ),
    ] = None,
    first_box: Annotated[
        str | None,
        typer.Option(
            "--first-box",
            metavar="U,V,WIDTH,HEIGHT",
            help="A box around the body in frame --first-box-frame (pixels): its "
            "size, colour and place there, for when the automatic detection is "
            "unsure.",
        ),
    ] = None,
    first_box_frame: Annotated[
        int,
        typer.Option("--first-box-frame", min=0, help="Frame of --first-box."),
    ] = 0,
    body_colour: Annotated[
        str | None,
        typer.Option(
            "--body-colour",
            metavar="R,G,B",
            help="The body's colour (0-255): preferred among candidates, never "
            "taken for a shadow.",
        ),
    ] = None,
    stabilise: Annotated[
        bool | None,
        typer.Option(
            "--stabilise/--no-stabilise",
            help="Remove camera drift measured on background features (default: "
            "when the clip drifts by more than 0.3 px).",
            show_default=False,
        ),
    ] = None,
    lens: Annotated[
        Path | None,
        typer.Option(
            "--lens",
            help="Lens distortion JSON (`fieldkit lens` on a checkerboard clip): "
            "centres and calibration points are undistorted.",
        ),
    ] = None,
    path_id: Annotated[
        str | None,
        typer.Option("--path-id", help="Test identifier (default: the video's name)."),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            "-o",
            "--out",
            help="Track CSV (t_s, x_m, z_m, angle_rad, omega_radps, flight, "
            "residual_m, flight_model, body_radius_m, body_mass_kg, pixels).",
        ),
    ] = None,
    impacts: Annotated[
        Path | None,
        typer.Option("--impacts", help="ImpactTable: .csv, .parquet or .xlsx."),
    ] = None,
    rrd: Annotated[
        Path | None,
        typer.Option("--rrd", help="Rerun recording of frames, detections and fits."),
    ] = None,
    figures: Annotated[
        Path | None,
        typer.Option("--figures", help="Folder for PNG figures of the track."),
    ] = None,
    report: Annotated[
        Path | None,
        typer.Option(
            "--report",
            help="Folder for a report to check by eye: report.md (calibration, "
            "flights with g, contacts, refused frames, every warning), frames.png "
            "(detections drawn on sampled frames), time_height.png, "
            "g_per_flight.png.",
        ),
    ] = None,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="No progress bar.")
    ] = False,
) -> None:
    """Track a ball in a high-speed video; find its flights, impacts and net contacts.

    The body is found against the static background (median of frames), its
    centre to a fraction of a pixel; a marker spot gives its spin. Flights are
    fitted with ballistic parabolas; each flight's fitted g +/- standard error
    is printed and warned about, naming the flight, beyond 3 standard errors
    from 9.81 (a wrong --fps or scale shows there). The standard error allows
    for detection errors correlated from frame to frame and for a slow one of
    0.05 px, so a short flight checks g only loosely. Impact and restitution
    velocities come from the fits at each contact. A net contact is one event:
    counted as a net contact, with its energy efficiency.

    Example (from the repository root; the first line renders a 0.45 s test
    clip filmed at 1205 frames/s, `make video` renders the longer ones):

        python video/render.py --out out/clips bounce_short
        fieldkit track out/clips/bounce_short.avi --fps 1205 \\
          --homography out/clips/bounce_short.homography.json \\
          --radius 0.0375 --mass 0.14 --surface-angle 15 \\
          -o out/bounce_track.csv --impacts out/bounce_impacts.csv \\
          --figures out/bounce --report out/bounce_report
    """
    from fieldkit.tracking.flights.ballistic_fit import calibration_rel_sd
    from fieldkit.tracking.flights.pipeline import analyse_track
    from fieldkit.tracking.video.calibration import (
        parse_scale_points,
        read_homography_file,
        read_lens_file,
        two_point_scale,
    )
    from fieldkit.tracking.video.pipeline import parse_colour, parse_roi
    from fieldkit.tracking.video.reader import VideoReader, fps_mismatch_message

    if fps is None:
        raise ArgumentError(
            "the capture rate is required (the file's own rate is usually the "
            "playback rate)",
            source="--fps",
        )
    check_frame_rate(fps, "fps")
    for value, flag in ((scale_sd, "--scale-sd"), (fps_sd, "--fps-sd")):
        if not (math.isfinite(value) and value >= 0):
            raise ArgumentError(f"must be >= 0, got {value:g}", source=flag)
    if fps_sd >= fps:
        raise ArgumentError(
            f"{fps_sd:g} frames/s is not an uncertainty of --fps {fps:g}",
            source="--fps-sd",
        )
    stated_rel_sd = calibration_rel_sd(scale_sd / 100.0, fps_sd / fps)
    body = body_from_options(mass, radius, gyration, shape, dimensions, unit_weight)
    if surface_angle is not None and not (
        math.isfinite(surface_angle) and -90 < surface_angle < 90
    ):
        raise ArgumentError(
            f"must be between -90 and 90 degrees, got {surface_angle:g}",
            source="--surface-angle",
        )
    ground_options = [
        flag
        for flag, value in (
            ("--surface-angle", surface_angle),
            ("--surface-profile", surface_profile),
            ("--surface-dem", surface_dem),
        )
        if value is not None
    ]
    if len(ground_options) > 1:
        raise ArgumentError(
            f"give one of {' and '.join(ground_options)}: each is the ground",
            source=ground_options[1],
        )
    if surface_dem is None:
        for value, flag in ((section, "--section"), (footprint, "--footprint")):
            if value is not None:
                raise ArgumentError("applies to --surface-dem", source=flag)
    elif section is None:
        raise ArgumentError(
            "--surface-dem needs --section E1,N1,E2,N2 (the section's plan line)",
            source="--section",
        )
    if homography is not None and (scale_points or scale_length is not None):
        raise ArgumentError(
            "give either --homography or --scale-points/--scale-length, not both",
            source="--homography",
        )
    if homography is None and (scale_points is None or scale_length is None):
        missing = "--scale-points" if scale_points is None else "--scale-length"
        raise ArgumentError(
            "calibration needed: --scale-points U1,V1,U2,V2 with --scale-length L, "
            "or --homography FILE",
            source=missing,
        )
    if impacts is not None:
        table_format(impacts)  # CSV for /dev/null or a FIFO, else by its extension
    outputs = OutputSet(inputs=[video, homography, surface_profile, surface_dem])
    outputs.confine(figures)
    outputs.confine(report)
    for path, flag in ((out, "-o"), (impacts, "--impacts"), (rrd, "--rrd")):
        if path is not None:
            outputs.plan(path, argument=flag)
    if figures is not None:
        from fieldkit.viz.track_figure import TRACK_FIGURE_NAMES

        for name in TRACK_FIGURE_NAMES:
            outputs.plan(figures / name, argument="--figures")
    if report is not None:
        from fieldkit.viz.track_report import REPORT_NAMES

        for name in REPORT_NAMES:
            outputs.plan(report / name, argument="--report")
    if all(p is None for p in (out, impacts, rrd, figures, report)):
        note(
            "no -o, --impacts, --rrd, --figures or --report given; printing the "
            "summary only"
        )

    ground = read_ground(surface_profile, surface_dem, section, footprint, outputs)
    reader = VideoReader(video)
    info = reader.info
    size = (info.width, info.height)
    lens_model = read_lens_file(lens, size) if lens is not None else None
    if homography is not None:
        calibration = read_homography_file(homography, size, lens=lens_model)
    else:
        points = parse_scale_points(scale_points)
        calibration = two_point_scale(points, scale_length, size)  # inside the frame
        if lens_model is not None:  # undistorted, they may lie beyond the frame's edge
            u, v = lens_model.undistort(points[0::2], points[1::2])
            calibration = two_point_scale((u[0], v[0], u[1], v[1]), scale_length)
    search = parse_roi(roi, size)
    hints = {
        "first_box": parse_roi(first_box, size, source="first_box"),
        "first_box_frame": first_box_frame,
        "body_colour_rgb": parse_colour(body_colour),
        "stabilise": stabilise,
        "lens": lens_model,
    }

    track_data, detections = _run_tracking(
        video,
        reader,
        fps,
        calibration,
        search,
        body.radius_m,
        show=not quiet,
        **hints,
    )
    rate_message = fps_mismatch_message(info, fps)
    warned = [m for m in [rate_message, *track_data.meta.get("warnings", [])] if m]
    for message in warned:
        warn(message)
    if body.radius_m is None:
        whole = track_data.frame.loc[~track_data.frame["partial"], "radius_m"]
        if len(whole):
            body = body.with_measured_radius(float(whole.median()))
    body.require(*BODY_NEEDS, source="fieldkit track")
    ground = ground_for_body(ground, footprint is None, body.radius_m)
    analysis = analyse_track(
        track_data,
        radius_m=body.radius_m,
        surface_angle_deg=surface_angle,
        mass_kg=body.mass_kg,
        gyration_m=body.gyration_m,
        path_id=path_id or video.stem,
        ground=ground,
        calibration_rel_sd=stated_rel_sd,
    )
    if stated_rel_sd > 0:
        note(
            f"g is checked against 9.81 with the stated calibration: scale "
            f"+/- {scale_sd:g} %, rate +/- {fps_sd:g} frames/s "
            f"(g +/- {100 * stated_rel_sd:.3g} %)"
        )
    print_body_notes(body)
    later = list(analysis.warnings)
    if ground is not None:
        note(ground.description)
        later = ground_gap_warnings(ground, analysis, body.radius_m) + later
    for message in later:
        warn(message)
    warned += later
    for refusal in analysis.refusals:
        if refusal.kind != "surface":  # the impact table's own: warned above
            warn(refusal.message())
            warned.append(refusal.message())

    if out is not None:
        analysis.track.write(out, outputs=outputs)
    if impacts is not None:
        analysis.impacts.write(impacts, outputs=outputs)
    if rrd is not None:
        from fieldkit.viz.rerun_log import write_recording

        frames = reader.frames()  # read when the recording is written
        write_recording(
            rrd, analysis, frames=frames, detections=detections, outputs=outputs
        )
    if figures is not None:
        from fieldkit.viz.track_figure import write_track_figures

        middle = reader.read_frames([max(len(detections) // 2, 0)])
        background = middle[0][1] if middle else None
        write_track_figures(
            figures, analysis, background_frame=background, outputs=outputs
        )
    if report is not None:
        from fieldkit.viz.track_report import write_track_report

        write_track_report(
            report, analysis, detections, video=video, reader=reader,
            warnings=[with_flags(m, command_flags()) for m in warned],  # as printed
            outputs=outputs,
        )  # fmt: skip
    announce = rrd is not None or figures is not None or report is not None
    with step("writing the outputs", announce=announce):
        written = outputs.commit()
    _summary(video, track_data, detections, analysis, calibration.description)
    report_written(written)


def read_ground(surface_profile, surface_dem, section, footprint, outputs):
    """The ground the options describe (:mod:`fieldkit.tracking.flights.ground`), or
    None (one angle, ``--surface-angle``, or estimated); read and checked before the
    video is tracked. A DEM's footprint not given is set by :func:`ground_for_body`.
    """
    from fieldkit.tracking.flights.ground import DemSectionGround, ProfileGround

    if surface_profile is not None:
        if surface_profile.suffix.lower() in (".json", ".yaml", ".yml"):
            from fieldkit.model.model_file import read_model

            profile = read_model(surface_profile, outputs=outputs).profile
            x_m, z_m = profile.x_m, profile.z_m
        else:
            from fieldkit.io.profile_csv import read_profile_csv

            vertices = read_profile_csv(surface_profile)
            x_m, z_m = vertices.x_m, vertices.z_m
        return ProfileGround(x_m, z_m, name=surface_profile.name)
    if surface_dem is None:
        return None
    from fieldkit.io.dem import read_dem

    parts = section.replace(";", ",").split(",")
    try:
        e1, n1, e2, n2 = (float(p) for p in parts)
    except ValueError:
        raise ArgumentError(
            f"'{section}' is not E1,N1,E2,N2 (four numbers in metres)",
            source="--section",
        ) from None
    if not all(math.isfinite(v) for v in (e1, n1, e2, n2)):
        raise ArgumentError(f"'{section}' must be finite numbers", source="--section")
    grid = read_dem(surface_dem)
    return DemSectionGround(
        grid,
        (e1, n1),
        (e2, n2),
        footprint_m=grid.cellsize_m if footprint is None else footprint,
    )


def ground_for_body(ground, footprint_default: bool, radius_m: float):
    """``ground`` with a DEM footprint not given set to the body radius, at least
    one DEM cell (stated in a note)."""
    from fieldkit.tracking.flights.ground import DemSectionGround

    if not (isinstance(ground, DemSectionGround) and footprint_default):
        return ground
    footprint = max(radius_m, ground.grid.cellsize_m)
    note(
        f"--footprint not given: the DEM plane is fitted within {footprint:g} m "
        "(the body radius, at least one DEM cell)"
    )
    return dataclasses.replace(ground, footprint_m=footprint)


def ground_gap_warnings(ground, analysis, radius_m: float) -> list[str]:
    """A warning per impact whose centre lies off the known ground (a profile, a
    DEM) by more than one radius beyond contact (is it in the track's frame?)."""
    from fieldkit.tracking.flights.contact_impacts import travel_direction
    from fieldkit.tracking.flights.ground import in_track_frame

    ground = in_track_frame(ground, analysis.track.meta)
    if not hasattr(ground, "distance_m"):
        return []
    frame = analysis.impacts.frame
    messages = []
    sx = travel_direction(analysis.flights)  # the table's x is mirrored toward -x
    what = "surface profile" if ground.source == "profile" else "DEM's plane"
    for _, row in frame.iterrows():
        gap = ground.distance_m(sx * float(row["x_m"]), float(row["z_m"])) - radius_m
        if abs(gap) > radius_m:
            messages.append(
                f"impact {row['point']}: the body's centre is {gap:+.3f} m off "
                f"contact with the {what} (radius {radius_m:g} m): is it in the "
                "track's frame?"
            )
    return messages


def _run_tracking(video, reader, fps, calibration, roi, radius, *, show: bool, **hints):
    """track_video, shown as a progress step (:func:`fieldkit.cli.progress.step`)
    for long videos; ``hints``: its detection options (first box, colour, ...)."""
    from fieldkit.tracking.video.pipeline import track_video

    run = functools.partial(
        track_video,
        video,
        fps=fps,
        calibration=calibration,
        roi=roi,
        radius_m=radius,
        reader=reader,
        **hints,
    )
    total = reader.info.frame_count
    if not show or total < PROGRESS_MIN_FRAMES:
        return run()
    with step(f"tracking {total:,} frames", total=total) as advance:
        return run(progress=advance)


def _summary(video, track_data, detections, analysis, calibration_text) -> None:
    frame = analysis.impacts.frame
    typer.echo(
        f"{video}: {len(detections)} frames, body in {len(track_data)}; "
        f"{calibration_text}"
    )
    for line in detection_status_lines(track_data.meta):
        typer.echo(f"  {line}")
    typer.echo(analysis.counts_text())
    print_flight_gravity(analysis.flights)
    for (_, row), net in zip(frame.iterrows(), analysis.net_rows, strict=True):
        what = "net contact at point" if net else "impact"
        typer.echo(
            f"  {what} {row['point']}: t={row['t_s']:.4f} s  vi={row['vi_mps']:.3f} "
            f"vf={row['vf_mps']:.3f} m/s  e_n={row['e_n']:.3f} e_t={row['e_t']:.3f}  "
            f"omega {row['omega_i_radps']:.1f} -> {row['omega_f_radps']:.1f} rad/s  "
            f"slope {row['slope_deg']:.2f} deg"
        )
    for line in analysis.bridged:
        typer.echo(f"  {line}")
    for contact in analysis.contacts:
        typer.echo(f"  {contact.summary()}")
    for line in analysis.net_rows_text():
        typer.echo(f"  {line}")


def print_flight_gravity(flights) -> None:
    """One line per fitted flight: its fitted g with standard error and how far it
    lies from 9.81 (the check on the capture rate and the scale; flights beyond
    three standard errors are also warned about, by name)."""
    from fieldkit.tracking.flights.ballistic_fit import GRAVITY_WARNING_SIGMAS

    if flights:
        typer.echo(
            "fitted gravity per flight (free-g fit; warned beyond "
            f"{GRAVITY_WARNING_SIGMAS:g} standard errors from 9.81):"
        )
        slow_m = max(f.g_systematic_mps2 * f.duration_s**2 / 8.0 for f in flights)
        typer.echo(
            "  standard error: detection noise, correlated from frame to frame"
            + (
                f", and a slow detection error of {1e3 * slow_m:.2g} mm (0.05 px: "
                "compression, background) that bends a short flight like g does"
                if slow_m > 0
                else ""
            )
        )
    for flight in flights:
        typer.echo(f"  {flight.gravity_summary()}")


def detection_status_lines(meta: dict) -> list[str]:
    """One line per detection status: frames found how, frames refused why."""
    from fieldkit.tracking.video.detection import REFUSAL_REASONS

    counts = meta.get("detect_status") or {}
    lines = []
    for status, count in sorted(counts.items(), key=lambda item: -item[1]):
        why = REFUSAL_REASONS.get(status)
        text = f"no body ({status}: {why})" if why else f"body found ({status})"
        lines.append(f"{count} frames: {text}")
    drift = meta.get("camera_drift_px")
    if drift is not None and meta.get("stabilised"):
        lines.append(f"camera drift up to {drift:.1f} px removed (stabilised)")
    return lines
