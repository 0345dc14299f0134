"""Video file -> Track: background model, detection, calibration, marker spin.

:func:`track_video` reads the clip once (plus a few random-access frames for the
background model), so tracking costs about as much as decoding. Times are
``frame / fps`` with the *capture* rate, never the container's playback rate.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import numpy as np
import pandas as pd

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.track import Track
from fieldkit.tracking.video.background import background_model, flickers
from fieldkit.tracking.video.calibration import Calibration, Lens
from fieldkit.tracking.video.detection import BallDetector
from fieldkit.tracking.video.reader import VideoReader
from fieldkit.tracking.video.spin import (
    angular_velocity,
    marker_angle_world,
    measure_marker,
    unwrap_angle,
)
from fieldkit.tracking.video.stabilisation import MIN_DRIFT_PX, Stabiliser

#: frames sampled across the clip for the median background
BACKGROUND_SAMPLES = 11
#: a body missing for more frames than this between detections is reported
MAX_SILENT_GAP = 2
#: frames decoded ahead in a background thread (0 = decode in the calling thread)
PREFETCH = 4


def frame_ranges(frames: np.ndarray) -> str:
    """Compact text for a set of frame numbers, e.g. ``"10-20, 31"``.

    Examples
    --------
    >>> frame_ranges(np.array([3, 4, 5, 9]))
    '3-5, 9'
    """
    frames = np.unique(np.asarray(frames, dtype=int))
    if frames.size == 0:
        return ""
    breaks = np.flatnonzero(np.diff(frames) > 1)
    starts = np.r_[frames[0], frames[breaks + 1]]
    ends = np.r_[frames[breaks], frames[-1]]
    parts = [
        f"{a}" if a == b else f"{a}-{b}" for a, b in zip(starts, ends, strict=True)
    ]
    if len(parts) > 6:
        parts = parts[:6] + [f"... ({len(parts) - 6} more)"]
    return ", ".join(parts)


def parse_colour(text: str | None) -> tuple[float, float, float] | None:
    """Parse a colour ``"R,G,B"`` (0-255).

    Examples
    --------
    >>> parse_colour("200, 40,10")
    (200.0, 40.0, 10.0)
    """
    if text is None:
        return None
    try:
        values = tuple(float(p) for p in str(text).split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(0.0 <= c <= 255.0 for c in values):
        raise ArgumentError(
            f"expected R,G,B from 0 to 255, got {text!r}", source="body_colour_rgb"
        )
    return values  # type: ignore[return-value]


def parse_roi(
    roi: str | None, image_size: tuple[int, int], source: str = "roi"
) -> tuple[int, int, int, int] | None:
    """Parse ``roi`` ``"U,V,WIDTH,HEIGHT"`` [px] and check it overlaps the frame.

    Examples
    --------
    >>> parse_roi("10,20,300,200", (800, 480))
    (10, 20, 300, 200)
    """
    if roi is None:
        return None
    text = roi
    try:
        values = [int(round(float(p))) for p in str(text).split(",")]
    except ValueError:
        values = []
    if len(values) != 4 or values[2] <= 0 or values[3] <= 0:
        raise ArgumentError(
            f"expected U,V,WIDTH,HEIGHT in pixels, got {text!r}", source=source
        )
    u, v, w, h = values
    width, height = image_size
    if u >= width or v >= height or u + w <= 0 or v + h <= 0:
        raise ArgumentError(f"lies outside the {width}x{height} frame", source=source)
    return u, v, w, h


def track_video(
    path: str | os.PathLike[str],
    *,
    fps: float,
    calibration: Calibration,
    roi: tuple[int, int, int, int] | None = None,
    radius_m: float | None = None,
    progress: Callable[[int, int], None] | None = None,
    reader: VideoReader | None = None,
    first_box: tuple[int, int, int, int] | None = None,
    first_box_frame: int = 0,
    body_colour_rgb: tuple[float, float, float] | None = None,
    stabilise: bool | None = None,
    lens: Lens | None = None,
) -> tuple[Track, pd.DataFrame]:
    """Track one ball through a video.

    Parameters
    ----------
    path
        Video file.
    fps
        Capture rate [frames/s] (the time base; the container's rate is ignored).
    calibration
        Pixels -> world metres (:mod:`fieldkit.tracking.video.calibration`).
    roi
        ``(u, v, width, height)`` [px] search region.
    radius_m
        Body radius [m] when known: sharpens the shape test.
    progress
        Called as ``progress(frames_done, frames_total)``.
    reader
        An already opened :class:`VideoReader` of ``path`` (saves reopening it).
    first_box
        ``(u, v, width, height)`` [px] around the body in frame ``first_box_frame``:
        the body's size and colour where the automatic detection is unsure, and its
        place in that frame.
    body_colour_rgb
        The body's colour (R, G, B, 0-255): preferred among candidates, never taken
        for a shadow (a ``first_box`` gives it too).
    stabilise
        Remove camera drift (:mod:`~fieldkit.tracking.video.stabilisation`): True,
        False, or None to do so when the background samples drift by more than
        :data:`MIN_DRIFT_PX` from the first frame.
    lens
        Lens distortion (:class:`~fieldkit.tracking.video.calibration.Lens`): the
        detected centres are undistorted before ``calibration`` maps them, so
        ``calibration`` must come from undistorted image points.

    Returns
    -------
    track, detections
        The :class:`~fieldkit.track.Track` (one row per frame with a body;
        extra columns ``omega_sd_radps, u_px, v_px, radius_px, radius_m, partial,
        visible_fraction, detect_status, blurred, position_sd_px``;
        ``meta["warnings"]`` lists one-line warnings, ``meta["detect_status"]``
        counts the frames by :attr:`BallDetector.status`) and a per-frame table
        (every decoded frame; ``found`` False where no body was seen and
        ``detect_status`` says why, a key of
        :data:`~fieldkit.tracking.video.detection.REFUSAL_REASONS`; pixel centre,
        radius, marker offset ``marker_du_px, marker_dv_px`` and ``marker_axial``;
        ``drift_px``, the camera drift removed).

    Raises
    ------
    InputFileError
        The video cannot be read, or no body is found in any frame.
    """
    if fps is None or not np.isfinite(fps) or fps <= 0:
        raise ArgumentError(
            f"the capture rate must be positive, got {fps}", source="fps"
        )
    reader = reader or VideoReader(path)
    info = reader.info
    warnings: list[str] = []

    declared = info.frame_count if info.frame_count > 0 else BACKGROUND_SAMPLES
    indices = np.unique(
        np.linspace(0, max(declared - 1, 0), BACKGROUND_SAMPLES).astype(int)
    )
    samples = [img for _, img in reader.read_frames(list(indices))]
    if len(samples) < 3:  # seeking failed (damaged index): read the first frames
        samples = [img for _, img in reader.frames(0, BACKGROUND_SAMPLES)]
    centre = (info.width / 2.0, info.height / 2.0)
    stabiliser = Stabiliser(samples[0])
    drifts = [stabiliser.drift_px(stabiliser.motion(img)) for img in samples[1:]]
    sample_drift = float(np.nanmax(drifts)) if np.isfinite(drifts).any() else 0.0
    if stabilise is None:
        stabilise = sample_drift > MIN_DRIFT_PX
    if stabilise:
        samples = [stabiliser.warp(img, stabiliser.motion(img)) for img in samples]
    expected = None
    if radius_m is not None and radius_m > 0:
        expected = float(radius_m / calibration.metres_per_pixel(*centre))
    body_colour = None
    if body_colour_rgb is not None:
        body_colour = tuple(float(c) for c in body_colour_rgb[::-1])
    box_prediction = None
    if first_box is not None:
        box_image = reader.read_frames([int(first_box_frame)])
        if not box_image:
            raise ArgumentError(
                f"frame {first_box_frame} of the first box cannot be read",
                source="first_box_frame",
            )
        box_colour, box_radius, box_prediction = _box_hint(box_image[0][1], first_box)
        body_colour = body_colour or box_colour
        expected = expected or box_radius
    background, threshold = background_model(
        samples, roi=roi, expected_radius_px=expected
    )
    detector = BallDetector(
        background,
        threshold,
        roi=roi,
        expected_radius_px=expected,
        compensate_flicker=flickers(samples, background),
        body_colour=body_colour,
    )

    rows = []
    last: list[tuple[int, float, float, float]] = []
    total = max(info.frame_count, 1)
    for index, image in reader.frames(prefetch=PREFETCH):
        prediction = velocity = None
        if last and index - last[-1][0] <= 3:
            k, u, v, r = last[-1]
            vu = vv = 0.0
            if len(last) >= 2 and last[-1][0] - last[-2][0] <= 3:
                dk = last[-1][0] - last[-2][0]
                vu, vv = (u - last[-2][1]) / dk, (v - last[-2][2]) / dk
            gap = index - k
            prediction = (
                u + vu * gap,
                v + vv * gap,
                2.5 * r + 3.0 * np.hypot(vu, vv) * gap + 8.0,
            )
            velocity = (vu, vv) if len(last) >= 2 else None
        elif box_prediction is not None and index == first_box_frame:
            prediction = box_prediction
        drift = 0.0
        if stabilise:
            matrix = stabiliser.motion(image, exclude=prediction)
            drift = stabiliser.drift_px(matrix)
            image = stabiliser.warp(image, matrix, fill=background)
        det = detector.detect(image, prediction, velocity)
        if det is None:
            rows.append(
                {
                    "frame": index,
                    "found": False,
                    "detect_status": detector.status,
                    "drift_px": drift,
                }
            )
        else:
            du, dv, axial = (np.nan, np.nan, False)
            if not det.partial:
                du, dv, axial = measure_marker(
                    image, det.u_px, det.v_px, det.radius_px, det.colour_bgr
                )
            rows.append(
                {
                    "frame": index,
                    "found": True,
                    "u_px": det.u_px,
                    "v_px": det.v_px,
                    "radius_px": det.radius_px,
                    "partial": det.partial,
                    "visible_fraction": det.visible_fraction,
                    "fit_residual_px": det.fit_residual_px,
                    "marker_du_px": du,
                    "marker_dv_px": dv,
                    "marker_axial": axial,
                    "detect_status": det.status,
                    "blurred": det.blurred,
                    "position_sd_px": det.position_sd_px,
                    "ambiguous": det.ambiguous,
                    "drift_px": drift,
                }
            )
            last = (last + [(index, det.u_px, det.v_px, det.radius_px)])[-2:]
        if progress is not None and (index % 25 == 0):
            progress(index + 1, total)
    if progress is not None:
        progress(total, total)
    message = reader.truncation_message()
    if message:
        warnings.append(message)
    detections = pd.DataFrame(rows)
    decoded = len(detections)
    if decoded == 0:
        raise InputFileError("no frame could be decoded", source=path)
    found = detections[detections["found"]].copy()
    if found.empty:
        raise InputFileError(
            _nothing_found(detector, radius_m, calibration.metres_per_pixel(*centre)),
            source=path,
            where=f"frames 0-{decoded - 1}",
        )
    first, last_frame = int(found["frame"].min()), int(found["frame"].max())
    missing = detections.loc[
        (detections["frame"] > first)
        & (detections["frame"] < last_frame)
        & ~detections["found"],
        "frame",
    ].to_numpy()
    lost, outside = _classify_gaps(missing, found)
    if lost.size:
        warnings.append(
            f"{path}: frames {frame_ranges(lost)}: body lost (not detected); "
            "those frames are left out of the track"
        )
    if outside.size:
        warnings.append(
            f"{path}: frames {frame_ranges(outside)}: body out of the frame; "
            "those frames are left out of the track"
        )

    counts = detections["detect_status"].value_counts()
    status_counts = {str(k): int(n) for k, n in counts.items()}
    warnings.extend(
        _unsure_messages(path, detections, hinted=first_box or body_colour_rgb)
    )
    u, v = found["u_px"].to_numpy(float), found["v_px"].to_numpy(float)
    if lens is not None:
        u, v = lens.undistort(u, v)
    x, z = calibration.to_world(u, v)
    scale = calibration.metres_per_pixel(u, v)
    angle = marker_angle_world(
        calibration,
        u,
        v,
        found["marker_du_px"].to_numpy(float),
        found["marker_dv_px"].to_numpy(float),
    )
    frames = found["frame"].to_numpy(int)
    t = frames / float(fps)
    radius_m_median = float(np.nanmedian(found["radius_px"].to_numpy(float) * scale))
    mirrored = _travels_toward_negative_x(x, min_shift_m=0.5 * radius_m_median)
    if mirrored:
        x = -x
        angle = np.pi - angle
        warnings.append(
            f"{path}: the body travels toward -x in the calibrated frame; x is "
            "mirrored (x -> -x, spin sign flipped) so x increases along travel"
        )
    # a stripe through the centre is known modulo half a turn: if most frames see
    # one, unwrap every marker angle with that period
    axial = found["marker_axial"].to_numpy(bool) & np.isfinite(angle)
    period = np.pi if axial.sum() > 0.5 * np.isfinite(angle).sum() else 2 * np.pi
    angle = unwrap_angle(angle, period=period)
    omega, omega_sd = angular_velocity(t, angle)
    whole = ~found["partial"].to_numpy(bool)
    no_marker = frames[whole & ~np.isfinite(angle)]
    if whole.any() and np.isfinite(angle[whole]).mean() < 0.2:
        warnings.append(
            f"{path}: no marker could be followed on the body; omega is NaN "
            "(needs a spot or stripe in a colour contrasting with the body)"
        )
        angle[:] = np.nan
        omega[:] = np.nan
        omega_sd[:] = np.nan
    elif no_marker.size:
        warnings.append(
            f"{path}: frames {frame_ranges(no_marker)}: marker not seen; "
            "angle and omega are NaN there"
        )
    frame = pd.DataFrame(
        {
            "frame": frames,
            "t_s": t,
            "x_m": x,
            "z_m": z,
            "angle_rad": angle,
            "omega_radps": omega,
            "omega_sd_radps": omega_sd,
            "u_px": u,
            "v_px": v,
            "radius_px": found["radius_px"].to_numpy(float),
            "radius_m": found["radius_px"].to_numpy(float) * scale,
            "partial": found["partial"].to_numpy(bool),
            "visible_fraction": found["visible_fraction"].to_numpy(float),
            "detect_status": found["detect_status"].to_numpy(str),
            "blurred": found["blurred"].to_numpy(bool),
            "position_sd_px": found["position_sd_px"].to_numpy(float),
        }
    )
    meta = {
        "video": str(path),
        "width_px": info.width,
        "height_px": info.height,
        "container_fps": info.container_fps,
        "codec": info.codec,
        "frames_declared": info.frame_count,
        "frames_decoded": decoded,
        "calibration": calibration.description,
        "threshold": threshold,
        "roi": list(roi) if roi else None,
        "marker": "stripe (angle modulo pi)" if period < 4 else "spot",
        "mirrored_x": mirrored,
        "detect_status": status_counts,
        "stabilised": bool(stabilise),
        "camera_drift_px": float(
            np.nanmax(detections["drift_px"]) if stabilise else sample_drift
        ),
        "lens": lens.description if lens is not None else None,
        "warnings": warnings,
    }
    return Track(frame, source=str(path), fps=float(fps), meta=meta), detections


def _box_hint(image: np.ndarray, box: tuple[int, int, int, int]):
    """Body colour (BGR), radius [px] and search (u, v, reach) from a box around it.

    The colour is the median of the box's central disc (60 % of the half-size), so
    the background in the box's corners and the rim's blend are left out.
    """
    u0, v0, bw, bh = (int(round(x)) for x in box)
    h, w = image.shape[:2]
    patch = image[max(v0, 0) : min(v0 + bh, h), max(u0, 0) : min(u0 + bw, w)]
    if patch.size == 0:
        raise ArgumentError(f"the box {box} lies outside the frame", source="first_box")
    uc, vc = u0 + (bw - 1) / 2.0, v0 + (bh - 1) / 2.0
    radius = min(bw, bh) / 2.0
    ph, pw = patch.shape[:2]
    uu = np.arange(pw)[None, :] + max(u0, 0) - uc
    vv = np.arange(ph)[:, None] + max(v0, 0) - vc
    core = uu * uu + vv * vv <= (0.6 * radius) ** 2
    colour = np.median(patch[core].reshape(-1, 3), axis=0) if core.any() else None
    return (
        None if colour is None else tuple(float(c) for c in colour),
        float(radius),
        (uc, vc, 1.5 * max(bw, bh)),
    )


def _unsure_messages(path, detections: pd.DataFrame, hinted) -> list[str]:
    """One line where the automatic detection was unsure, suggesting a hint."""
    messages = []
    unsure = []
    if "ambiguous" in detections:
        frames = detections.loc[detections["ambiguous"].fillna(False).astype(bool)]
        if len(frames):
            unsure.append(
                f"several candidates in frames {frame_ranges(frames['frame'])}"
            )
    status = detections["detect_status"]
    low = detections.loc[status == "low_contrast", "frame"]
    if len(low):
        unsure.append(f"low contrast in frames {frame_ranges(low)}")
    if unsure and not hinted:
        messages.append(
            f"{path}: detection unsure ({'; '.join(unsure)}); a box around the body "
            "in one frame (`first_box`) or its colour (`body_colour_rgb`) settles it"
        )
    return messages


def _nothing_found(
    detector: BallDetector, radius_m: float | None, metres_per_pixel: float
) -> str:
    """Why no frame had a body: the size looked for and the sizes seen, if any."""
    expected = detector.expected_radius_px
    if expected is None:
        return (
            "no body found in any frame (check `roi`, the contrast and that the body "
            "moves)"
        )
    looked = (
        f"no body of radius {expected:.1f} px found in any frame (`radius_m` "
        f"{radius_m:g} m at {metres_per_pixel * 1000:.3g} mm/px)"
    )
    seen = np.asarray(detector.off_size_radii, dtype=float)
    if seen.size == 0:
        return (
            f"{looked}, nor a moving body of any other size (check `roi`, the "
            "contrast and that the body moves)"
        )
    low, mid, high = np.percentile(seen, [5, 50, 95])
    sizes = f"{mid:.1f} px" if high - low < 1.0 else f"{low:.1f}-{high:.1f} px"
    return (
        f"{looked}; bodies seen have radius {sizes} ({mid * metres_per_pixel:.3g} m "
        "at that scale): a diameter given as the radius, or a wrong scale?"
    )


def _classify_gaps(missing: np.ndarray, found: pd.DataFrame):
    """Split missing frames into runs lost in view and runs beside the frame border.

    A run whose neighbouring detections both touch the frame border is the body
    leaving and re-entering the picture; any other run is a body lost in view.
    """
    if missing.size == 0:
        return missing, missing
    frames = found["frame"].to_numpy(int)
    partial = found["partial"].to_numpy(bool)
    breaks = np.flatnonzero(np.diff(missing) > 1)
    starts = np.r_[missing[0], missing[breaks + 1]]
    ends = np.r_[missing[breaks], missing[-1]]
    lost, outside = [], []
    for a, b in zip(starts, ends, strict=True):
        before = np.searchsorted(frames, a) - 1
        after = np.searchsorted(frames, b, side="right")
        edge = partial[before] and partial[min(after, len(frames) - 1)]
        (outside if edge else lost).extend(range(int(a), int(b) + 1))
    return np.array(lost, dtype=int), np.array(outside, dtype=int)


def _travels_toward_negative_x(x: np.ndarray, min_shift_m: float = 0.0) -> bool:
    """Whether the body moves toward -x over the first tenth of the track.

    At least 5 samples; the shift must exceed ``min_shift_m`` (half a radius), so a
    vertical drop is never mirrored by noise.

    Examples
    --------
    >>> _travels_toward_negative_x(np.linspace(1.0, 0.0, 50), 0.01)
    True
    >>> jitter = np.array([0.0, -0.001, 0.0005, -0.002, -0.001])  # a vertical drop
    >>> _travels_toward_negative_x(jitter, 0.01)
    False
    """
    if x.size < 2:
        return False
    n = max(5, x.size // 10)
    head = x[:n]
    shift = head[-1] - head[0]
    return bool(shift < 0 and abs(shift) > min_shift_m)
