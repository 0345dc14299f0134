"""A report per tracked clip that a lab engineer checks by eye.

:func:`write_track_report` writes into a folder:

* ``report.md`` -- the clip, its calibration (scale, capture rate and how they were
  given), counts, a table of flights (frames, g ± standard error, its distance from
  9.81 in standard errors), a table of contacts (frame, kind, e_n, e_t, ...), the
  refused frames with their reasons, every warning of the run, and the figures;
* ``frames.png``, ``time_height.png``, ``g_per_flight.png`` -- see
  :mod:`fieldkit.viz.track_report_figure`.

The g and its standard error are the flight fit's
(:class:`~fieldkit.tracking.flights.ballistic_fit.FlightFit`), the numbers
``fieldkit track`` prints; nothing is refitted here.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.outputs import OutputSet, write_text
from fieldkit.physics.constants import G
from fieldkit.tracking.flights.ballistic_fit import GRAVITY_WARNING_SIGMAS
from fieldkit.tracking.flights.pipeline import TrackAnalysis
from fieldkit.tracking.video.pipeline import frame_ranges
from fieldkit.tracking.video.reader import VideoReader
from fieldkit.viz.figure_files import save_png
from fieldkit.viz.track_report_figure import (
    contact_frames,
    flagged_frames,
    flight_frame_range,
    plot_frames,
    plot_g_per_flight,
    plot_time_height,
    refused_frames,
    sheet_frames,
)

#: The figures of a report, in the order report.md shows them.
REPORT_FIGURE_NAMES: tuple[str, ...] = (
    "frames.png",
    "time_height.png",
    "g_per_flight.png",
)
#: Every file a report writes.
REPORT_NAMES: tuple[str, ...] = ("report.md", *REPORT_FIGURE_NAMES)


def write_track_report(
    directory: str | os.PathLike[str],
    analysis: TrackAnalysis,
    detections: pd.DataFrame,
    *,
    video: str | os.PathLike[str],
    warnings: list[str] | None = None,
    reader: VideoReader | None = None,
    outputs: OutputSet | None = None,
) -> list[Path]:
    """Write the report of one tracked clip into ``directory``.

    Parameters
    ----------
    directory
        Output folder (created if needed).
    analysis
        From :func:`fieldkit.tracking.flights.pipeline.analyse_track` of the track
        :func:`fieldkit.tracking.video.pipeline.track_video` made of ``video``.
    detections
        The per-frame table ``track_video`` returns (``frame``, ``found``, ``u_px``,
        ``v_px``, ``radius_px``, ``partial``, ...; a status column a detector writes,
        :data:`~fieldkit.viz.track_report_figure.STATUS_COLUMNS`, is shown).
    video
        The clip: the contact sheet's frames are read from it.
    warnings
        Every warning of the run, in the order given; default the track's
        (``meta["warnings"]``) and the analysis's.
    reader
        An open :class:`~fieldkit.tracking.video.reader.VideoReader` of ``video``.
    outputs
        Add the files to this :class:`~fieldkit.outputs.OutputSet` (written when it
        commits) instead of writing them at once.

    Returns
    -------
    list of Path
        The files, :data:`REPORT_NAMES` in order.
    """
    out = Path(directory)
    video = Path(video)
    if warnings is None:
        warnings = [*analysis.track.meta.get("warnings", []), *analysis.warnings]
    title = video.name
    reader = reader or VideoReader(video)
    wanted = sheet_frames(analysis, detections)
    images = dict(reader.read_frames(wanted))
    into = OutputSet() if outputs is None else outputs
    text = markdown(analysis, detections, video=video, warnings=warnings)
    paths = [write_text(out / REPORT_NAMES[0], text, into)]
    drawings = (
        lambda: plot_frames(images, detections, analysis, title=title),
        lambda: plot_time_height(analysis, detections, title=title),
        lambda: plot_g_per_flight(analysis, title=title),
    )
    paths += [
        save_png(draw(), out / name, outputs=into)
        for name, draw in zip(REPORT_FIGURE_NAMES, drawings, strict=True)
    ]
    if outputs is None:
        into.commit()
    return paths


def _row(*cells: object) -> str:
    """One Markdown table row; a ``|`` inside a cell is escaped."""
    return "| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |"


def _num(x, fmt: str) -> str:
    try:
        x = float(x)
    except (TypeError, ValueError):
        return "—"
    return format(x, fmt) if math.isfinite(x) else "—"


def scale_mm_per_px(analysis: TrackAnalysis) -> float:
    """Median image scale at the detections [mm/px] (``radius_m / radius_px``), NaN
    for a track without them."""
    f = analysis.track.frame
    if not {"radius_m", "radius_px"} <= set(f.columns):
        return float("nan")
    ratio = (f["radius_m"] / f["radius_px"]).to_numpy(float)
    ratio = ratio[np.isfinite(ratio) & (ratio > 0)]
    return 1e3 * float(np.median(ratio)) if ratio.size else float("nan")


def flight_rows(analysis: TrackAnalysis) -> list[dict]:
    """One dict per flight, the numbers of report.md's flight table: ``flight``,
    ``first_frame``, ``last_frame``, ``t_start_s``, ``t_end_s``, ``samples``,
    ``g_mps2``, ``g_se_mps2`` (of the check against 9.81: the fit's and the stated
    calibration's, ``FlightFit.g_check_se_mps2``), ``g_sigmas`` (``|g - 9.81| / SE``),
    ``rms_mm``."""
    rows = []
    for fl in analysis.flights:
        a, b = flight_frame_range(analysis, fl)
        rows.append(
            dict(
                flight=fl.index,
                first_frame=a,
                last_frame=b,
                t_start_s=fl.t_start_s,
                t_end_s=fl.t_end_s,
                samples=fl.n_samples,
                g_mps2=fl.g_mps2,
                g_se_mps2=fl.g_check_se_mps2,
                g_sigmas=abs(fl.g_sigmas),
                rms_mm=1e3 * fl.rms_m,
            )
        )
    return rows


def _clip_section(analysis, detections, video) -> list[str]:
    meta, track = analysis.track.meta, analysis.track
    fps = track.fps
    container = meta.get("container_fps")
    size = (
        f"{meta['width_px']} × {meta['height_px']} px"
        if "width_px" in meta and "height_px" in meta
        else "size unknown"
    )
    decoded = len(detections) if detections is not None else "no per-frame table"
    f = track.frame
    partial = (
        int(f["partial"].fillna(False).astype(bool).sum()) if "partial" in f else 0
    )
    refused = len(refused_frames(detections)) if detections is not None else 0
    out = [
        "## Clip and calibration",
        "",
        f"* clip: `{video}` ({size}, codec {meta.get('codec', 'unknown')}, "
        f"{meta.get('frames_declared', '?')} frames declared, {decoded} decoded)",
        f"* capture rate: {fps:g} frames/s, as given (times are frame / {fps:g}); "
        + (
            f"the container's playback rate is {container:g} frames/s"
            if isinstance(container, int | float) and math.isfinite(container)
            else "the container states no rate"
        ),
        f"* calibration: {meta.get('calibration', 'not stated')}",
        f"* image scale at the detections: {_num(scale_mm_per_px(analysis), '.4g')} "
        "mm/px (median of body radius in metres over pixels)",
    ]
    if meta.get("mirrored_x"):
        out.append(
            "* x is mirrored (x → −x) so that it increases along travel; the "
            "ImpactTable is in that frame"
        )
    out += [
        "",
        "## Counts",
        "",
        f"* frames decoded: {decoded}; body detected in {len(f)} "
        f"({partial} partial: cut by the frame edge); refused (no accepted body): "
        f"{refused}",
        f"* events: {analysis.counts_text()}",
        "",
    ]
    flags = flagged_frames(detections) if detections is not None else {}
    if flags:
        out += ["| detection flag | frames | count |", "|---|---|---|"]
        out += [_row(k, frame_ranges(v), len(v)) for k, v in flags.items()]
        out.append("")
    return out


def _flight_section(analysis) -> list[str]:
    out = [
        "## Flights",
        "",
        "g is the free-gravity fit of each flight's samples; its standard error (SE) "
        "allows for detection errors correlated from frame to frame and a slow "
        "detection error of 0.05 px (as `fieldkit track` prints it). A flight more "
        f"than {GRAVITY_WARNING_SIGMAS:g} SE from {G:g} m/s² points at the capture "
        "rate or the scale.",
        "",
    ]
    rows = flight_rows(analysis)
    if not rows:
        return out + ["No ballistic flight was found.", ""]
    out += [
        "| flight | frames | t (s) | samples | g ± SE (m/s²) | g − 9.81 (m/s²) | "
        "\\|g − 9.81\\| / SE | RMS from the fit (mm) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r, fl in zip(rows, analysis.flights, strict=True):
        flag = " **(beyond 3 SE)**" if r["g_sigmas"] > GRAVITY_WARNING_SIGMAS else ""
        out.append(
            _row(
                r["flight"],
                f"{r['first_frame']}–{r['last_frame']}",
                f"{r['t_start_s']:.4f}–{r['t_end_s']:.4f}",
                r["samples"],
                fl.g_text().replace("+/-", "±"),
                f"{r['g_mps2'] - G:+.3f}",
                _num(r["g_sigmas"], ".2f") + flag,
                _num(r["rms_mm"], ".3f"),
            )
        )
    return out + [""]


#: ImpactTable columns of report.md's contact table: (column, heading, format).
CONTACT_COLUMNS = (
    ("t_s", "t (s)", ".4f"),
    ("slope_deg", "slope (deg)", ".2f"),
    ("vi_mps", "v_i (m/s)", ".3f"),
    ("vf_mps", "v_f (m/s)", ".3f"),
    ("e_n", "e_n", ".3f"),
    ("e_t", "e_t", ".3f"),
    ("omega_i_radps", "ω_i (rad/s)", ".1f"),
    ("omega_f_radps", "ω_f (rad/s)", ".1f"),
)


def _contact_section(analysis) -> list[str]:
    out = ["## Contacts", ""]
    imp = analysis.impacts.frame
    contacts = contact_frames(analysis)
    if not contacts:
        return out + ["No contact between two flights.", ""]
    columns = [c for c in CONTACT_COLUMNS if c[0] in imp.columns]
    has_sd = {"e_n_sd", "e_t_sd"} <= set(imp.columns)
    head = ["point", "kind", "frame", *(h for _, h, _ in columns)]
    if has_sd:
        head += ["SE of e_n", "SE of e_t"]
    head += ["slope from", "quality flags"]
    out += [_row(*head), "|" + "---|" * len(head)]
    for c, (_, row) in zip(contacts, imp.iterrows(), strict=True):
        frames = f"{c.first}" if c.first == c.last else f"{c.first}–{c.last}"
        cells = [c.point, c.kind, frames]
        cells += [_num(row[name], fmt) for name, _, fmt in columns]
        if has_sd:
            cells += [_num(row["e_n_sd"], ".3g"), _num(row["e_t_sd"], ".3g")]
        qa = row.get("qa_flags")
        cells += [
            row.get("slope_source", "") if pd.notna(row.get("slope_source")) else "",
            qa if isinstance(qa, str) and qa else "none",
        ]
        out.append(_row(*cells))
    out.append("")
    out += [f"* {c.summary()}" for c in analysis.contacts]
    out += [f"* {line}" for line in analysis.net_rows_text()]
    if analysis.contacts or analysis.net_rows.any():
        out.append("")
    return out


def _refusal_section(analysis, detections) -> list[str]:
    out = ["## Refused frames", ""]
    refused = refused_frames(detections) if detections is not None else None
    if refused is not None and len(refused):
        out += ["| reason | frames | count |", "|---|---|---|"]
        for reason, group in refused.groupby("reason", sort=False):
            out.append(
                _row(reason, frame_ranges(group["frame"].to_numpy()), len(group))
            )
    elif refused is None:
        out.append("No per-frame detections were given (not tracked from a video).")
    else:
        out.append("No frame was refused: a body was accepted in every frame.")
    more = getattr(analysis, "refusals", None)  # contacts the analysis refused
    if more:
        out += ["", "Refused by the analysis:", ""]
        out += [f"* {item}" for item in more]
    return out + [""]


def markdown(
    analysis: TrackAnalysis,
    detections: pd.DataFrame | None,
    *,
    video: str | os.PathLike[str],
    warnings: list[str],
) -> str:
    """report.md of one tracked clip (text only; see :func:`write_track_report`)."""
    name = Path(video).name
    out = [f"# Track report: {name}", ""]
    out += _clip_section(analysis, detections, video)
    out += ["## Warnings", ""]
    out += [f"* {w}" for w in warnings if w] or ["None."]
    out.append("")
    out += _flight_section(analysis)
    out += _contact_section(analysis)
    out += _refusal_section(analysis, detections)
    out += [
        "## Figures",
        "",
        "Detections drawn on sampled frames (the frames around each contact and "
        "some refused frames among them):",
        "",
        "![detections on sampled frames](frames.png)",
        "",
        "Height against time: detections, each flight's fit, apexes and contacts:",
        "",
        "![height against time](time_height.png)",
        "",
        f"Fitted g per flight against {G:g} m/s² (bars: 1 and 3 standard errors):",
        "",
        "![fitted g per flight](g_per_flight.png)",
        "",
    ]
    return "\n".join(out)
