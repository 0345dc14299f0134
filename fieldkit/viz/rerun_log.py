"""Rerun recordings (.rrd) of tracks, flights, impacts and net contacts.

Every rerun call of fieldkit lives in this module (the rerun API changes between
minor versions; this file is pinned to rerun-sdk 0.41). Recordings are written
without a viewer: ``RecordingStream`` -> ``save`` -> log -> ``disconnect`` (the footer
is written only then). ``save`` writes to a path itself, so the recording is a writer
of a :class:`~fieldkit.outputs.OutputSet`: it is pointed at the set's temporary file,
which is renamed into place with the command's other outputs. Log and
tick times are disabled and the recording id is fixed, so the same input gives the
same content.

Entity layout
-------------
``video/frame``                  subsampled, downscaled frames (JPEG)
``video/frame/centre``, ``/marker``  detected centre and spin marker on each frame
``video/frame/flights``          fitted flights projected into the image
``world/track``                  tracked centre (x, 0, z) in metres, z up
``world/flights``                fitted parabolas; ``world/velocity`` vectors
``world/impacts``                impact points labelled with e_n, e_t
``plots/speed/{measured,fitted}``, ``plots/spin``, ``plots/residual_mm``  time series
``contacts/<i>/speed``           speed through each net contact
``section/{impacts,path,slope,vi,vf}``  an ImpactTable: every path's impacts (labelled
                                 path, point, e_n, e_t), polyline, slope ticks,
                                 velocity arrows, one row per path (``path``)
``section/plots/<column>``       e_n, e_t, vi, vf against ``impact`` (table row)
``simulation/profile``           a simulated slope profile (line strip, x, 0, z)
``simulation/trajectories/<i>``  the sampled trajectory of rock i
``simulation/impacts``           impacts of those rocks, coloured by impact speed

Timelines: ``frame`` (video frame index), ``t`` (seconds); ImpactTables use
``path`` (path number, in order of first appearance; the section view shows every
path) and ``impact`` (table row) -- written columnar, one ``send_columns`` per
entity, so 300 000 impacts of 2000 rocks take seconds; a simulation uses ``rock``
(rock index: the trajectories appear one by one) and ``t`` (time of each impact
since the rock's release).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pandas as pd
import rerun as rr
import rerun.blueprint as rrb

from fieldkit.impact_table import ImpactTable
from fieldkit.model.results import SimulationResult
from fieldkit.outputs import OutputSet, write_file
from fieldkit.physics.local_axes import to_section
from fieldkit.tracking.flights.pipeline import TrackAnalysis
from fieldkit.viz.image_projection import project, world_to_image

#: At most this many video frames go into a recording.
MAX_FRAMES = 120
#: Frames are downscaled so their longer side is at most this many pixels.
MAX_FRAME_SIDE_PX = 480
#: Frames are stored as JPEG of this quality (keeps a recording to a few MB).
JPEG_QUALITY = 80
#: Velocity arrows are drawn as the distance travelled in this time [s].
ARROW_TIME_S = 0.02

_FLIGHT_COLOUR = (40, 120, 220)
_TRACK_COLOUR = (230, 230, 230)
_IMPACT_COLOUR = (220, 60, 40)


def open_recording(path: Path, name: str) -> rr.RecordingStream:
    rec = rr.RecordingStream(
        "fieldkit", recording_id=f"fieldkit-{name}", send_properties=False
    )
    rr.set_log_time_enabled(False, recording=rec)
    rr.set_log_tick_enabled(False, recording=rec)
    rec.save(path)
    return rec


def write_recording(
    path: str | os.PathLike[str],
    analysis: TrackAnalysis,
    frames: Iterable[tuple[int, np.ndarray]] | None = None,
    detections: pd.DataFrame | None = None,
    *,
    outputs: OutputSet | None = None,
) -> Path:
    """Write a rerun recording of a track analysis (and optionally its video frames).

    Parameters
    ----------
    path
        Output ``.rrd`` file.
    analysis
        From :func:`fieldkit.tracking.flights.pipeline.analyse_track`.
    frames
        ``(frame_index, BGR image)`` pairs; at most :data:`MAX_FRAMES` evenly spaced
        frames are kept (every n-th over the track's frame range; the iterable is
        consumed lazily), downscaled to :data:`MAX_FRAME_SIDE_PX`.
    detections
        Per-frame detections with ``frame``, ``u_px``, ``v_px`` and optionally
        ``marker_du_px``, ``marker_dv_px`` (offset of the marker from the centre).
    outputs
        Add the recording to this set (recorded when it commits; ``frames`` is read
        then) instead of writing it at once.

    Returns
    -------
    Path
        ``path``.
    """

    def record(tmp: Path) -> None:
        rec = open_recording(tmp, "track")
        try:
            rec.send_blueprint(_track_blueprint(frames is not None))
            _log_world(rec, analysis)
            _log_series(rec, analysis)
            _log_contacts(rec, analysis)
            if frames is not None:
                _log_frames(rec, analysis, frames, detections)
        finally:
            rec.disconnect()

    return write_file(path, record, outputs)


def write_impact_recording(
    path: str | os.PathLike[str],
    table: ImpactTable,
    *,
    outputs: OutputSet | None = None,
) -> Path:
    """Write a rerun recording of an ImpactTable: the section view of every path.

    Impact points (labelled with point, e_n, e_t), impact and restitution velocity
    arrows, a short slope tick at each impact (``slope_deg``), and e_n, e_t, speeds
    against the impact order. Into ``outputs`` when given (recorded when it
    commits), else at once.
    """

    def record(tmp: Path) -> None:
        rec = open_recording(tmp, "impacts")
        try:
            rec.send_blueprint(_section_blueprint())
            rec.log("section", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
            _log_sections(rec, table.frame)
        finally:
            rec.disconnect()

    return write_file(path, record, outputs)


def write_simulation_recording(
    path: str | os.PathLike[str],
    result: SimulationResult,
    impacts: ImpactTable | None = None,
    *,
    outputs: OutputSet | None = None,
) -> Path:
    """Write a rerun recording of a simulation: profile, trajectories, impacts.

    The profile as a line strip, each sampled trajectory (``result.trajectories``)
    as a line strip on the ``rock`` timeline, and ``impacts`` (those of the same
    rocks, when given) as points coloured by impact speed (blue slow -> red fast)
    on the ``t`` timeline. Into ``outputs`` when given, else at once.
    """
    profile = result.model.profile

    def record(tmp: Path) -> None:
        rec = open_recording(tmp, "simulation")
        try:
            rec.log("simulation", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
            rec.log(
                "simulation/profile",
                rr.LineStrips3D(
                    [_xyz(profile.x_m, profile.z_m)], colors=[(90, 90, 90)]
                ),
                static=True,
            )
            for i, samples in enumerate(result.trajectories):
                rec.set_time("rock", sequence=i)
                rec.log(
                    f"simulation/trajectories/{i}",
                    rr.LineStrips3D(
                        [_xyz(samples[:, 0], samples[:, 1])], colors=[_FLIGHT_COLOUR]
                    ),
                )
            if impacts is not None and len(impacts):
                rec.reset_time()
                f = impacts.frame
                speed = impacts.column("vi_mps")
                colours = _speed_colours(speed)
                t = impacts.column("t_s")
                order = np.argsort(np.where(np.isfinite(t), t, 0.0), kind="stable")
                for j in order:
                    rec.set_time("t", duration=float(t[j]) if np.isfinite(t[j]) else 0)
                    rec.log(
                        f"simulation/impacts/{f['path_id'].iloc[j]}",
                        rr.Points3D(
                            _xyz(f["x_m"].iloc[j : j + 1], f["z_m"].iloc[j : j + 1]),
                            colors=colours[j : j + 1],
                            radii=0.2,
                            labels=[f"{speed[j]:.1f} m/s"],
                        ),
                    )
        finally:
            rec.disconnect()

    return write_file(path, record, outputs)


def _speed_colours(speed: np.ndarray) -> np.ndarray:
    """RGB from blue (slowest) to red (fastest) of the finite speeds."""
    v = np.where(np.isfinite(speed), speed, 0.0)
    span = np.ptp(v) if v.size else 0.0
    u = (v - v.min()) / span if span > 0 else np.zeros_like(v)
    return np.column_stack([40 + 200 * u, 80 * (1 - u), 220 * (1 - u)]).astype(np.uint8)


# ---------------------------------------------------------------- track pieces
def _track_blueprint(with_video: bool) -> rrb.Blueprint:
    views = [rrb.Spatial3DView(origin="world", name="section (x, z)")]
    if with_video:
        views.insert(0, rrb.Spatial2DView(origin="video", name="video"))
    plots = rrb.Vertical(
        rrb.TimeSeriesView(origin="plots/speed", name="speed [m/s]"),
        rrb.TimeSeriesView(origin="plots/spin", name="spin [rad/s]"),
        rrb.TimeSeriesView(origin="plots/residual_mm", name="flight residual [mm]"),
    )
    return rrb.Blueprint(rrb.Horizontal(rrb.Vertical(*views), plots))


def _xyz(x, z) -> np.ndarray:
    x = np.asarray(x, float)
    return np.column_stack([x, np.zeros_like(x), np.asarray(z, float)])


def _log_world(rec: rr.RecordingStream, analysis: TrackAnalysis) -> None:
    f = analysis.track.frame
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    ok = np.isfinite(f["x_m"]) & np.isfinite(f["z_m"])
    rec.log(
        "world/track",
        rr.Points3D(
            _xyz(f.loc[ok, "x_m"], f.loc[ok, "z_m"]), radii=0.002, colors=_TRACK_COLOUR
        ),
        static=True,
    )
    strips, labels = [], []
    for fl in analysis.flights:
        t = np.linspace(fl.t_start_s, fl.t_end_s, 60)
        strips.append(_xyz(*fl.position(t)))
        labels.append(f"flight {fl.index}: g = {fl.g_text()} m/s^2")
    if strips:
        rec.log(
            "world/flights",
            rr.LineStrips3D(strips, radii=0.001, labels=labels, colors=_FLIGHT_COLOUR),
            static=True,
        )
    imp = analysis.impacts.frame
    if len(imp):
        kinds = ["net contact" if net else "impact" for net in analysis.net_rows]
        labels = [
            f"{kind} {p}: e_n {en:.2f}, e_t {et:.2f}"
            for kind, p, en, et in zip(
                kinds, imp["point"], imp["e_n"], imp["e_t"], strict=True
            )
        ]
        sx = _table_mirror(analysis)
        rec.log(
            "world/impacts",
            rr.Points3D(
                _xyz(sx * imp["x_m"], imp["z_m"]),
                radii=0.006,
                colors=_IMPACT_COLOUR,
                labels=labels,
            ),
            static=True,
        )
        for kind, row in zip(kinds, imp.itertuples(), strict=True):
            rec.set_time("t", duration=float(row.t_s))
            rec.log(
                "events",
                rr.TextLog(
                    f"{kind} {row.point}: v_i {row.vi_mps:.2f} -> "
                    f"v_f {row.vf_mps:.2f} m/s, "
                    f"e_n {row.e_n:.2f}, e_t {row.e_t:.2f}, psi {row.slope_deg:.1f} deg"
                ),
            )
    for fl in analysis.flights:
        rows = fl.rows[:: max(1, fl.n_samples // 12)]
        for r in rows:
            t = float(f["t_s"].iloc[r])
            _set_times(rec, int(f["frame"].iloc[r]), t)
            vx, vz = fl.velocity(t)
            px, pz = fl.position(t)
            rec.log(
                "world/velocity",
                rr.Arrows3D(
                    origins=_xyz([px], [pz]),
                    vectors=_xyz(
                        [ARROW_TIME_S * float(vx)], [ARROW_TIME_S * float(vz)]
                    ),
                    colors=_FLIGHT_COLOUR,
                ),
            )


def _table_mirror(analysis: TrackAnalysis) -> float:
    return -1.0 if any("mirrored" in w for w in analysis.warnings) else 1.0


def _set_times(rec: rr.RecordingStream, frame: int, t_s: float) -> None:
    rec.set_time("frame", sequence=frame)
    rec.set_time("t", duration=t_s)


def _series(rec, entity: str, frames, t, values, name: str) -> None:
    ok = np.isfinite(values)
    if not ok.any():
        return
    rec.log(entity, rr.SeriesLines(names=name), static=True)
    rec.send_columns(
        entity,
        indexes=[
            rr.TimeColumn("frame", sequence=np.asarray(frames)[ok]),
            rr.TimeColumn("t", duration=np.asarray(t)[ok]),
        ],
        columns=rr.Scalars.columns(scalars=np.asarray(values)[ok]),
    )


def _log_series(rec: rr.RecordingStream, analysis: TrackAnalysis) -> None:
    f = analysis.track.frame
    frames = f["frame"].to_numpy(int)
    t = f["t_s"].to_numpy(float)
    measured = np.hypot(*analysis.measured_velocity)
    fitted = np.full(len(f), np.nan)
    for fl in analysis.flights:
        fitted[fl.rows] = fl.speed(t[fl.rows])
    _series(rec, "plots/speed/measured", frames, t, measured, "measured")
    _series(rec, "plots/speed/fitted", frames, t, fitted, "fitted flights")
    _series(rec, "plots/spin", frames, t, f["omega_radps"].to_numpy(float), "omega")
    if "residual_m" in f:
        _series(
            rec,
            "plots/residual_mm",
            frames,
            t,
            1e3 * f["residual_m"].to_numpy(float),
            "residual",
        )


def _log_contacts(rec: rr.RecordingStream, analysis: TrackAnalysis) -> None:
    for c in analysis.contacts:
        base = f"contacts/{c.index}"
        rec.log(
            base,
            rr.TextDocument(
                f"contact {c.index}: {c.duration_s * 1e3:.1f} ms, "
                f"v_i {c.vi_mps:.2f} -> "
                f"v_min {c.v_min_mps:.2f} -> v_f {c.vf_mps:.2f} m/s, "
                f"efficiency (eq. 8.1) {100 * c.efficiency:.0f} %"
            ),
            static=True,
        )
        frames = np.round((c.t_s - c.t_s[0]) / max(np.median(np.diff(c.t_s)), 1e-12))
        _series(rec, f"{base}/speed", frames.astype(int), c.t_s, c.speed_mps, "speed")
        _series(
            rec,
            f"{base}/impulse_absorbed_pct",
            frames.astype(int),
            c.t_s,
            100 * c.impulse_absorbed_fraction,
            "impulse absorbed %",
        )


def _log_frames(rec, analysis: TrackAnalysis, frames, detections) -> None:
    f = analysis.track.frame
    times = dict(zip(f["frame"].to_numpy(int), f["t_s"].to_numpy(float), strict=False))
    det = detections if detections is not None else f
    det = det.set_index("frame") if "frame" in det else det
    homography = world_to_image(f)
    # frames arrive lazily (a video decoder): keep every step-th, never hold them all
    span = f["frame"].to_numpy(int)
    expected = int(span.max() - span.min() + 1) if len(span) else MAX_FRAMES
    step = max(1, int(np.ceil(expected / MAX_FRAMES)))
    fps = analysis.track.fps or 1.0
    kept = 0
    for index, image in frames:
        if (
            int(index) - int(span.min() if len(span) else 0)
        ) % step or kept >= MAX_FRAMES:
            continue
        kept += 1
        h, w = image.shape[:2]
        s = min(1.0, MAX_FRAME_SIDE_PX / max(h, w))
        if s < 1.0:
            image = _downscale(image, s)
        _set_times(rec, int(index), times.get(int(index), index / fps))
        colour = "BGR" if image.ndim == 3 else "L"
        rec.log(
            "video/frame", rr.Image(image, color_model=colour).compress(JPEG_QUALITY)
        )
        if int(index) in det.index and {"u_px", "v_px"} <= set(det.columns):
            row = det.loc[int(index)]
            if isinstance(row, pd.DataFrame):
                row = row.iloc[0]
            u, v = float(row["u_px"]), float(row["v_px"])
            if np.isfinite(u) and np.isfinite(v):
                rec.log("video/frame/centre", rr.Points2D([[s * u, s * v]], radii=2.0))
                du, dv = (
                    row.get("marker_du_px", np.nan),
                    row.get("marker_dv_px", np.nan),
                )
                if np.isfinite(du) and np.isfinite(dv):
                    rec.log(
                        "video/frame/marker",
                        rr.Points2D(
                            [[s * (u + du), s * (v + dv)]],
                            radii=2.0,
                            colors=(255, 200, 0),
                        ),
                    )
        if homography is not None and analysis.flights:
            strips = []
            for fl in analysis.flights:
                t = np.linspace(fl.t_start_s, fl.t_end_s, 40)
                strips.append(s * project(homography, *fl.position(t)))
            rec.log(
                "video/frame/flights", rr.LineStrips2D(strips, colors=_FLIGHT_COLOUR)
            )


def _downscale(image: np.ndarray, s: float) -> np.ndarray:
    import cv2

    return cv2.resize(image, None, fx=s, fy=s, interpolation=cv2.INTER_AREA)


# ---------------------------------------------------------------- impact tables
#: Series of an ImpactTable recording, against the ``impact`` timeline.
SECTION_SERIES = ("e_n", "e_t", "vi_mps", "vf_mps")


def _section_blueprint() -> rrb.Blueprint:
    """The section (every path at once: the whole ``path`` timeline visible) beside
    the series against the impact order."""
    every_path = rrb.VisibleTimeRange(
        "path",
        start=rrb.TimeRangeBoundary.infinite(),
        end=rrb.TimeRangeBoundary.infinite(),
    )
    section = rrb.Spatial3DView(
        origin="section", name="section (x, z)", time_ranges=[every_path]
    )
    plots = rrb.Vertical(
        *(
            rrb.TimeSeriesView(origin=f"section/plots/{col}", name=col)
            for col in SECTION_SERIES
        )
    )
    return rrb.Blueprint(rrb.Horizontal(section, plots))


def _log_sections(rec: rr.RecordingStream, frame: pd.DataFrame) -> None:
    """Every path of an ImpactTable, columnar: one ``send_columns`` per entity.

    Rows are grouped by path (table order kept within a path) and each path is one
    row of the ``path`` timeline (path number in order of first appearance): its
    impacts, polyline, slope ticks and velocity arrows. The series of
    :data:`SECTION_SERIES` run against ``impact`` (the row number in the table) with
    ``path`` beside it. Sizes (point radius, tick length, arrow scale) follow each
    path's own extent.
    """
    codes, names = pd.factorize(frame["path_id"].astype(str), sort=False)
    order = np.argsort(codes, kind="stable")
    f = frame.iloc[order]
    codes = codes[order]
    rows = np.arange(len(frame))[order]
    lengths = np.bincount(codes, minlength=len(names))
    x, z = f["x_m"].to_numpy(float), f["z_m"].to_numpy(float)
    xyz = _xyz(x, z)
    extent = _extent_per_path(x, z, codes, len(names))[codes]
    path_index = [rr.TimeColumn("path", sequence=np.arange(len(names)))]
    labels = [
        f"{path} {p}: e_n {en:.2f}, e_t {et:.2f}"
        for path, p, en, et in zip(
            names[codes], f["point"].astype(str), f["e_n"], f["e_t"], strict=True
        )
    ]
    rec.log(
        "section/impacts", rr.Points3D.from_fields(colors=_IMPACT_COLOUR), static=True
    )
    rec.send_columns(
        "section/impacts",
        indexes=path_index,
        columns=rr.Points3D.columns(
            positions=xyz, radii=0.005 * extent, labels=labels
        ).partition(lengths),
    )
    rec.log(
        "section/path", rr.LineStrips3D.from_fields(colors=_TRACK_COLOUR), static=True
    )
    rec.send_columns(
        "section/path",
        indexes=path_index,
        columns=rr.LineStrips3D.columns(
            strips=np.split(xyz, np.cumsum(lengths)[:-1])
        ).partition(np.ones(len(names), int)),
    )
    length = 0.05 * extent
    t_x, t_z = to_section(1.0, 0.0, f["slope_deg"].to_numpy(float))  # local T axis
    tick = np.column_stack([t_x * length, np.zeros(len(f)), t_z * length])
    rec.log(
        "section/slope", rr.LineStrips3D.from_fields(colors=(120, 90, 60)), static=True
    )
    rec.send_columns(
        "section/slope",
        indexes=path_index,
        columns=rr.LineStrips3D.columns(
            strips=np.stack([xyz - tick, xyz + tick], axis=1)
        ).partition(lengths),
    )
    speeds = np.abs(f[["vi_x_mps", "vi_z_mps", "vf_x_mps", "vf_z_mps"]].to_numpy(float))
    vmax = pd.Series(np.nanmax(speeds, axis=1, initial=0.0)).groupby(codes).max()
    vmax = vmax.reindex(range(len(names))).to_numpy(float)[codes]
    k = np.where(
        np.isfinite(vmax) & (vmax > 0), length / np.where(vmax > 0, vmax, 1), 0
    )
    for key, colour in (("vi", (200, 80, 80)), ("vf", (80, 160, 80))):
        vec = _xyz(
            k * f[f"{key}_x_mps"].to_numpy(float), k * f[f"{key}_z_mps"].to_numpy(float)
        )
        origins = xyz - (vec if key == "vi" else 0.0)
        rec.log(f"section/{key}", rr.Arrows3D.from_fields(colors=colour), static=True)
        rec.send_columns(
            f"section/{key}",
            indexes=path_index,
            columns=rr.Arrows3D.columns(origins=origins, vectors=vec).partition(
                lengths
            ),
        )
    for col in SECTION_SERIES:
        values = f[col].to_numpy(float)
        ok = np.isfinite(values)
        if ok.any():
            entity = f"section/plots/{col}"
            rec.log(entity, rr.SeriesLines(names=col), static=True)
            sort = np.argsort(rows[ok], kind="stable")
            rec.send_columns(
                entity,
                indexes=[
                    rr.TimeColumn("impact", sequence=rows[ok][sort]),
                    rr.TimeColumn("path", sequence=codes[ok][sort]),
                ],
                columns=rr.Scalars.columns(scalars=values[ok][sort]),
            )


def _extent_per_path(x: np.ndarray, z: np.ndarray, codes: np.ndarray, n: int):
    """:func:`_scale` of each path: its largest horizontal or vertical extent [m]
    (at least 1 mm)."""
    frame = pd.DataFrame({"x": x, "z": z, "path": codes})
    span = frame.groupby("path").agg(["min", "max"]).reindex(range(n))
    extent = np.fmax(
        (span["x"]["max"] - span["x"]["min"]).to_numpy(float),
        (span["z"]["max"] - span["z"]["min"]).to_numpy(float),
    )
    return np.fmax(np.nan_to_num(extent, nan=1e-3), 1e-3)


def _scale(x: np.ndarray, z: np.ndarray) -> float:
    extent = max(np.nanmax(x) - np.nanmin(x), np.nanmax(z) - np.nanmin(z), 1e-3)
    return float(extent)
