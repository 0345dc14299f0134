"""The figures of a track report a lab engineer checks by eye (:mod:`.track_report`).

* ``frames.png`` -- a contact sheet: video frames sampled across the clip (always the
  frames just before, at and after each contact, and some refused frames), each
  cropped around the body with the detected circle (centre and radius) drawn, its
  frame number, time and flags (partial, refused and why, any status a detector
  writes);
* ``time_height.png`` -- height z [m] against time t [s]: the detections, refused
  frames marked on the time axis, each flight's fitted curve in its own colour with
  its apex, the contacts as labelled vertical lines (impact) or bands (net) with
  their frames;
* ``g_per_flight.png`` -- each flight's fitted g with 1 and 3 standard errors (the
  fit's and the stated scale and rate uncertainty's, ``g_check_se_mps2`` of
  :class:`~fieldkit.tracking.flights.ballistic_fit.FlightFit`, as ``fieldkit track``
  prints it) against 9.81 m/s², with the flight's frames.

Every axis names its unit; titles name the clip.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from fieldkit.physics.constants import G
from fieldkit.tracking.flights.ballistic_fit import GRAVITY_WARNING_SIGMAS
from fieldkit.tracking.flights.pipeline import TrackAnalysis
from fieldkit.viz.figure_files import new_figure
from fieldkit.viz.marks import outside_legend

#: Frames on the contact sheet when the contacts and refusals leave room.
SHEET_FRAMES = 16
#: At most this many frames on the contact sheet, however many contacts.
MAX_SHEET_FRAMES = 24
#: Refused frames shown on the sheet (the first of each run of refusals).
SHEET_REFUSALS = 3
#: A crop spans this many body radii across (at least :data:`MIN_CROP_PX`).
CROP_RADII = 5.0
MIN_CROP_PX = 64
#: Colour of the detected circle and centre on the contact sheet (pure green: a
#: colour the rendered and filmed scenes rarely hold, so it stands out).
CIRCLE_COLOUR = "#00ff00"
REFUSED_COLOUR = "crimson"
#: Columns a detector may write with a per-frame status or refusal reason, read
#: when present (first found wins).
STATUS_COLUMNS = ("detect_status", "refusal_reason", "reason", "status")
#: Status values that mean a clean detection (no flag to show).
CLEAN_STATUS = ("", "ok", "found", "nan", "none")
#: Boolean detection columns that are not flags.
NOT_FLAGS = ("found", "marker_axial")


@dataclass(frozen=True)
class ContactFrames:
    """One contact (a row of the ImpactTable) in frames.

    Attributes
    ----------
    point
        The ImpactTable's ``point``.
    kind
        ``"impact"`` or ``"net"`` (an extended contact, ``contact_duration_s > 0``).
    first, last
        Frames of the contact's start and end (equal for an impact) [frame numbers,
        ``t * fps``, rounded].
    t_start_s, t_end_s
        Its start and end [s].
    """

    point: object
    kind: str
    first: int
    last: int
    t_start_s: float
    t_end_s: float

    @property
    def label(self) -> str:
        same = self.first == self.last
        frames = f"frame {self.first}" if same else f"frames {self.first}-{self.last}"
        return f"{self.kind} {self.point} ({frames})"


def contact_frames(analysis: TrackAnalysis) -> list[ContactFrames]:
    """The contacts of ``analysis.impacts`` in frames of the track's capture rate."""
    fps = analysis.track.fps
    imp = analysis.impacts.frame
    net = analysis.net_rows
    out = []
    duration = (
        pd.to_numeric(imp["contact_duration_s"], errors="coerce").fillna(0.0)
        if "contact_duration_s" in imp.columns
        else pd.Series(0.0, index=imp.index)
    )
    for (_, row), is_net, d in zip(imp.iterrows(), net, duration, strict=True):
        t0 = float(row["t_s"])
        t1 = t0 + (float(d) if is_net else 0.0)
        out.append(
            ContactFrames(
                point=row["point"],
                kind="net" if is_net else "impact",
                first=int(round(t0 * fps)),
                last=int(round(t1 * fps)),
                t_start_s=t0,
                t_end_s=t1,
            )
        )
    return out


def detection_status(detections: pd.DataFrame) -> pd.Series:
    """Each detection row's status text from the first of :data:`STATUS_COLUMNS`
    present ("" when none is, or the value is missing)."""
    for name in STATUS_COLUMNS:
        if name in detections.columns:
            return detections[name].fillna("").astype(str)
    return pd.Series("", index=detections.index)


def refused_frames(detections: pd.DataFrame) -> pd.DataFrame:
    """Frames without an accepted body: ``frame`` and ``reason`` (the detector's
    status when it writes one, else ``no body detected``)."""
    if detections is None or "found" not in detections.columns:
        return pd.DataFrame({"frame": pd.Series([], dtype=int), "reason": []})
    refused = ~detections["found"].fillna(False).astype(bool)
    status = detection_status(detections)[refused]
    reason = status.where(
        ~status.str.strip().str.lower().isin(CLEAN_STATUS), "no body detected"
    )
    return pd.DataFrame(
        {
            "frame": detections.loc[refused, "frame"].to_numpy(int),
            "reason": reason.to_numpy(str),
        }
    )


def frame_flags(row: pd.Series, status: str = "") -> list[str]:
    """The flags of one detection row in words: ``partial (52 % visible)``, any
    other True boolean column by name, and a status that is not clean."""
    flags = []
    if bool(row.get("found", True)) is False:
        flags.append(f"refused: {status or 'no body detected'}")
        return flags
    if bool(row.get("partial", False)):
        vis = row.get("visible_fraction", np.nan)
        flags.append(
            f"partial ({100 * float(vis):.0f} % visible)"
            if np.isfinite(vis)
            else "partial"
        )
    for name, value in row.items():
        if name in NOT_FLAGS or name == "partial":
            continue
        if isinstance(value, bool | np.bool_) and bool(value):
            flags.append(str(name))
    if status.strip().lower() not in CLEAN_STATUS:
        flags.append(status)
    return flags


def flagged_frames(detections: pd.DataFrame) -> dict[str, np.ndarray]:
    """Frames of accepted detections by flag: ``partial``, every other boolean
    column that is True (e.g. a detector's ``blurred``), and every status text that
    is not clean; flags no frame carries are left out."""
    found = detections[detections["found"].fillna(False).astype(bool)]
    frames = found["frame"].to_numpy(int)
    out: dict[str, np.ndarray] = {}
    for name in found.columns:
        if name in NOT_FLAGS:
            continue
        values = found[name]
        if not values.map(lambda x: isinstance(x, bool | np.bool_)).all():
            continue
        hit = values.to_numpy(bool)
        if hit.any():
            out[str(name)] = frames[hit]
    status = detection_status(found)
    clean = status.str.strip().str.lower().isin(CLEAN_STATUS).to_numpy(bool)
    for text in pd.unique(status[~clean]):
        out[str(text)] = frames[(status == text).to_numpy(bool)]
    return out


def sheet_frames(
    analysis: TrackAnalysis,
    detections: pd.DataFrame,
    count: int = SHEET_FRAMES,
) -> list[int]:
    """Frame numbers for the contact sheet, in order.

    First the frames just before, at and after every contact (start and end of a
    net contact), then the first frame of up to :data:`SHEET_REFUSALS` runs of
    refused frames, then frames evenly spread over the clip until ``count`` (at most
    :data:`MAX_SHEET_FRAMES` in all); only frames the video has.
    """
    frames = detections["frame"].to_numpy(int)
    have = set(frames.tolist())
    chosen: list[int] = []

    def add(k: int) -> None:
        if k in have and k not in chosen and len(chosen) < MAX_SHEET_FRAMES:
            chosen.append(k)

    for c in contact_frames(analysis):
        for k in (c.first - 1, c.first, c.first + 1):
            add(k)
        if c.last != c.first:
            for k in (c.last - 1, c.last, c.last + 1):
                add(k)
    refused = refused_frames(detections)["frame"].to_numpy(int)
    if refused.size:
        starts = refused[np.r_[True, np.diff(refused) > 1]]
        for k in starts[:SHEET_REFUSALS]:
            add(int(k))
    spare = max(count - len(chosen), 0)
    if spare and frames.size:
        for k in np.unique(np.linspace(0, frames.size - 1, spare + 2).round()):
            if len(chosen) >= count:
                break
            add(int(frames[int(k)]))
    return sorted(chosen)


def crop_box(
    u_px: float, v_px: float, radius_px: float, size: tuple[int, int]
) -> tuple[int, int, int, int]:
    """A square crop ``(u0, v0, u1, v1)`` [px, end exclusive] around a body of
    centre ``(u_px, v_px)`` and ``radius_px`` in an image ``size = (width,
    height)``: :data:`CROP_RADII` radii across, at least :data:`MIN_CROP_PX`,
    shifted (not shrunk) to stay inside the image when it fits.

    Examples
    --------
    >>> crop_box(100.0, 50.0, 10.0, (480, 320))
    (68, 18, 132, 82)
    >>> crop_box(2.0, 300.0, 10.0, (480, 320))
    (0, 256, 64, 320)
    """
    width, height = size
    side = int(np.ceil(max(CROP_RADII * radius_px, MIN_CROP_PX)))
    side = min(side, width, height)
    u0 = int(np.floor(u_px - side / 2))
    v0 = int(np.floor(v_px - side / 2))
    u0 = min(max(u0, 0), width - side)
    v0 = min(max(v0, 0), height - side)
    return u0, v0, u0 + side, v0 + side


def _where_the_body_is(detections: pd.DataFrame, frame: int):
    """``(u, v, radius)`` [px] of the body in ``frame``: its detection, else the
    nearest detections' positions interpolated (None when nothing was found)."""
    found = detections[detections["found"].fillna(False).astype(bool)]
    if found.empty:
        return None
    k = found["frame"].to_numpy(float)
    u, v = found["u_px"].to_numpy(float), found["v_px"].to_numpy(float)
    r = found["radius_px"].to_numpy(float)
    return (
        float(np.interp(frame, k, u)),
        float(np.interp(frame, k, v)),
        float(np.interp(frame, k, r)),
    )


def plot_frames(
    images: dict[int, np.ndarray],
    detections: pd.DataFrame,
    analysis: TrackAnalysis,
    *,
    title: str,
    columns: int = 4,
) -> Figure:
    """``frames.png``: the frames ``images`` (frame number -> BGR or grey image)
    cropped around the body, the detected circle and centre drawn in
    :data:`CIRCLE_COLOUR` (a refused frame: the crop around where the neighbouring
    detections put the body, no circle), titled with frame, time and flags.

    Each axes keeps the image's pixel coordinates (u right, v down), so a drawn
    circle sits at the detection's ``u_px, v_px``.
    """
    fps = analysis.track.fps
    status = detection_status(detections)
    by_frame = detections.assign(_status=status).set_index("frame")
    contacts = contact_frames(analysis)
    order = sorted(images)
    rows = max(int(np.ceil(len(order) / columns)), 1)
    # fixed geometry [in] (constrained layout costs seconds on 16 image panels):
    # a 2.2 in panel, 0.7 in above it for its title, 0.6 in for the figure's title
    height = 2.9 * rows + 0.6 + 0.25
    fig = Figure(figsize=(2.6 * columns, height))
    fig.subplots_adjust(
        left=0.04,
        right=0.99,
        bottom=0.25 / height,
        top=1.0 - 1.15 / height,
        wspace=0.3,
        hspace=0.7 / 2.2,
    )
    axes = fig.subplots(rows, columns, squeeze=False)
    for ax in axes.flat[len(order) :]:
        ax.set_axis_off()
    for ax, k in zip(axes.flat, order, strict=False):
        image = images[k]
        rgb = image[..., ::-1] if image.ndim == 3 else image
        h, w = image.shape[:2]
        row = by_frame.loc[k] if k in by_frame.index else pd.Series({"found": False})
        found = bool(row.get("found", False))
        at = _where_the_body_is(detections, k)
        if found:
            at = (float(row["u_px"]), float(row["v_px"]), float(row["radius_px"]))
        if at is None:
            u0, v0, u1, v1 = 0, 0, w, h
        else:
            u0, v0, u1, v1 = crop_box(*at, (w, h))
        ax.imshow(
            rgb[v0:v1, u0:u1],
            cmap="gray",
            extent=(u0 - 0.5, u1 - 0.5, v1 - 0.5, v0 - 0.5),
            interpolation="nearest",
        )
        if found:
            u, v, r = at
            ax.add_patch(
                Circle((u, v), r, fill=False, ec=CIRCLE_COLOUR, lw=1.2, zorder=3)
            )
            ax.plot([u], [v], "+", color=CIRCLE_COLOUR, ms=8, mew=1.2, zorder=4)
        ax.set_xlim(u0 - 0.5, u1 - 0.5)
        ax.set_ylim(v1 - 0.5, v0 - 0.5)
        ax.tick_params(labelsize=6)
        near = [
            f"{'before' if k < c.first else 'after' if k > c.last else 'at'} " + c.label
            for c in contacts
            if c.first - 1 <= k <= c.last + 1
        ]
        flags = frame_flags(row, str(row.get("_status", "")))
        lines = [f"frame {k}, t = {k / fps:.4f} s"]
        if found:
            lines.append(f"r = {at[2]:.1f} px at ({at[0]:.1f}, {at[1]:.1f})")
        lines += near + flags
        ax.set_title(
            "\n".join(lines),
            fontsize=6.5,
            color=REFUSED_COLOUR if not found else "black",
            loc="left",
        )
        if not found:
            if at is not None:  # where the neighbouring detections put the body
                ax.add_patch(
                    Circle(at[:2], at[2], fill=False, ec=REFUSED_COLOUR, lw=1.0,
                           ls="--", zorder=3)
                )  # fmt: skip
            for side in ax.spines.values():
                side.set_color(REFUSED_COLOUR)
                side.set_linewidth(2)
    fig.suptitle(
        f"{title}: detections on sampled frames, image column u and row v [px]\n"
        "green: detected circle and centre; red: refused (dashed: where the "
        "neighbouring detections put the body)",
        fontsize=9,
        y=1.0 - 0.1 / height,
        va="top",
    )
    return fig


#: Flight colours: tab10 without its red (red marks impacts and flights beyond
#: 3 standard errors) and grey (detections outside flights).
FLIGHT_COLOURS = tuple(c for i, c in enumerate(
    ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
     "#7f7f7f", "#bcbd22", "#17becf")) if i not in (3, 7))  # fmt: skip


def _flight_colour(i: int) -> str:
    return FLIGHT_COLOURS[i % len(FLIGHT_COLOURS)]


def flight_apex(flight) -> tuple[float, float] | None:
    """``(t, z)`` of a flight's highest point on its fitted curve, when it lies
    inside the flight's time span."""
    g = flight.g_fixed_mps2
    if not g > 0:
        return None
    t = flight.t_ref_s + flight.vz_mps / g
    if not flight.t_start_s <= t <= flight.t_end_s:
        return None
    return t, float(flight.position(t)[1])


def plot_time_height(
    analysis: TrackAnalysis,
    detections: pd.DataFrame | None = None,
    *,
    title: str,
) -> Figure:
    """``time_height.png``: z [m] against t [s] (see the module docstring); a second
    time axis on top in frames."""
    f = analysis.track.frame
    fps = analysis.track.fps
    t, z = f["t_s"].to_numpy(float), f["z_m"].to_numpy(float)
    fig, ax = new_figure(9.0, 5.0)
    label = f["flight"].to_numpy(int) if "flight" in f.columns else np.full(len(f), -1)
    partial = (
        f["partial"].fillna(False).to_numpy(bool)
        if "partial" in f.columns
        else np.zeros(len(f), bool)
    )
    inside = label >= 0
    ax.plot(t[inside], z[inside], ".", ms=1.5, color="k", zorder=4,
            label="detection in a flight")  # fmt: skip
    ax.plot(t[~inside], z[~inside], ".", ms=3, color="0.5", zorder=4,
            label="detection outside the flights (in contact)")  # fmt: skip
    for fl in analysis.flights:
        colour = _flight_colour(fl.index)
        rows = np.zeros(len(f), bool)
        rows[fl.rows] = True
        tt = np.linspace(fl.t_start_s, fl.t_end_s, 200)
        ax.plot(
            tt,
            fl.position(tt)[1],
            "-",
            lw=3.0,
            alpha=0.55,
            color=colour,
            label=f"flight {fl.index} fit: g = {fl.g_text().replace('+/-', '±')} m/s²",
        )
        apex = flight_apex(fl)
        if apex is not None:
            ax.plot(*apex, "^", color=colour, mec="k", mew=0.6, ms=7, zorder=5)
    if any(flight_apex(fl) is not None for fl in analysis.flights):
        ax.plot([], [], "^", color="w", mec="k", mew=0.6, label="apex of a flight fit")
    if partial.any():
        ax.plot(
            t[partial],
            z[partial],
            "o",
            mfc="none",
            mec="k",
            ms=5,
            mew=0.8,
            label="partial detection (body cut by the frame edge)",
        )
    if detections is not None and "frame" in f.columns:
        flags = {k: v for k, v in flagged_frames(detections).items() if k != "partial"}
        if flags:
            hit = np.isin(
                f["frame"].to_numpy(int), np.concatenate(list(flags.values()))
            )
            ax.plot(
                t[hit],
                z[hit],
                "s",
                mfc="none",
                mec="crimson",
                ms=5,
                mew=0.8,
                label="flagged detection (" + ", ".join(sorted(flags)) + ")",
            )
    if detections is not None:
        refused = refused_frames(detections)
        if len(refused):
            ax.plot(
                refused["frame"].to_numpy(float) / fps,
                np.zeros(len(refused)),
                "|",
                color=REFUSED_COLOUR,
                ms=12,
                mew=1.0,
                transform=ax.get_xaxis_transform(),
                clip_on=False,
                label=f"refused frame ({len(refused)}: no accepted body)",
            )
    labelled = set()
    for c in contact_frames(analysis):
        colour = "crimson" if c.kind == "impact" else "purple"
        first = c.kind not in labelled
        labelled.add(c.kind)
        legend = (
            ("impact (fitted instant)" if c.kind == "impact" else "net contact")
            if first
            else None
        )
        if c.last > c.first:
            ax.axvspan(c.t_start_s, c.t_end_s, color=colour, alpha=0.15, label=legend)
        else:
            ax.axvline(c.t_start_s, color=colour, lw=0.9, ls="--", label=legend)
        ax.annotate(
            c.label,
            (c.t_start_s, 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(2, -4),
            textcoords="offset points",
            rotation=90,
            va="top",
            ha="left",
            fontsize=7,
            color=colour,
        )
    top = ax.secondary_xaxis("top", functions=(lambda s: s * fps, lambda k: k / fps))
    top.set_xlabel("frame", fontsize=8)
    top.tick_params(labelsize=7)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("height z of the centre [m]")
    ax.set_title(f"{title}: height against time, {analysis.counts_text()}", fontsize=9)
    outside_legend(ax, fontsize=7)
    return fig


def flight_frame_range(analysis: TrackAnalysis, flight) -> tuple[int, int]:
    """First and last frame of a flight's samples (the track's ``frame`` column,
    else ``t * fps`` rounded)."""
    f = analysis.track.frame
    if "frame" in f.columns:
        k = f["frame"].to_numpy(int)[flight.rows]
    else:
        k = np.round(f["t_s"].to_numpy(float)[flight.rows] * analysis.track.fps)
    return int(k.min()), int(k.max())


def plot_g_per_flight(analysis: TrackAnalysis, *, title: str) -> Figure:
    """``g_per_flight.png``: each flight's fitted g, thick bar 1 standard error,
    thin bar 3, against 9.81 m/s²; a flight beyond
    :data:`~fieldkit.tracking.flights.ballistic_fit.GRAVITY_WARNING_SIGMAS`
    standard errors is drawn red."""
    fig, ax = new_figure(max(5.0, 1.3 * len(analysis.flights) + 3.0), 4.5)
    ax.axhline(G, color="k", lw=1.0, label=f"g = {G:g} m/s²")
    names = []
    for i, fl in enumerate(analysis.flights):
        se = fl.g_check_se_mps2 if np.isfinite(fl.g_check_se_mps2) else 0.0
        off = np.isfinite(fl.g_sigmas) and abs(fl.g_sigmas) > GRAVITY_WARNING_SIGMAS
        colour = "crimson" if off else _flight_colour(fl.index)
        ax.errorbar(i, fl.g_mps2, yerr=3 * se, fmt="none", ecolor=colour, lw=0.9,
                    capsize=6)  # fmt: skip
        ax.errorbar(i, fl.g_mps2, yerr=se, fmt="o", color=colour, lw=3.0, ms=6,
                    capsize=0)  # fmt: skip
        a, b = flight_frame_range(analysis, fl)
        sig = f"{fl.g_sigmas:+.1f} SE" if np.isfinite(fl.g_sigmas) else "SE unknown"
        names.append(
            f"flight {fl.index}\nframes {a}-{b}\n{sig}"
            + ("\n(beyond 3 SE)" if off else "")
        )
    ax.errorbar([], [], yerr=[], fmt="o", color="0.3", lw=3.0,
                label="fitted g ± 1 standard error")  # fmt: skip
    ax.errorbar([], [], yerr=[], fmt="none", ecolor="0.3", lw=0.9, capsize=6,
                label="± 3 standard errors")  # fmt: skip
    ax.set_xticks(range(len(names)), names, fontsize=7)
    ax.set_xlim(-0.6, max(len(names), 1) - 0.4)
    ax.set_ylabel("fitted gravity g [m/s²]")
    ax.set_title(
        f"{title}: fitted g per flight (free-g fit; red beyond "
        f"{GRAVITY_WARNING_SIGMAS:g} SE from {G:g})",
        fontsize=9,
    )
    if not analysis.flights:
        ax.text(0.5, 0.5, "no flight fitted", transform=ax.transAxes, ha="center")
    outside_legend(ax, fontsize=7)
    return fig
