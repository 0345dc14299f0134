"""Spin from a marker on the body: marker angle per frame -> unwrapped angle -> omega.

The marker is a spot (or short stripe) off the body's centre, or a stripe across the
body through its centre, in a colour that differs from the body's. Its angle is the
direction from the body's centre to the marker's centroid (for a stripe through the
centre: its principal axis, known modulo half a turn and unwrapped with that period),
mapped into world axes (x right, z up, counter-clockwise positive), so a mirrored or
rotated camera still gives the thesis sign: omega < 0 is clockwise, the rolling sense
for travel toward +x (docs/architecture.md §2).

omega is the slope of a local straight-line fit to the unwrapped angle over a short
window (a smoothed derivative); its standard error comes from the scatter of the angle
about those fits. Frames where no marker is seen are NaN.
"""

from __future__ import annotations

import numpy as np

from fieldkit.tracking.video.calibration import Calibration

#: the marker must cover at least this share of the inner disc to be trusted
MIN_MARKER_SHARE = 0.015
#: a marker centroid closer to the centre than this (fraction of r) gives no angle
MIN_MARKER_OFFSET = 0.15


def _marker_weights(frame, u_px, v_px, radius_px, body_colour_bgr, min_difference):
    """Offsets (du, dv) [px] of the pixels inside 0.8 r and their marker weight."""
    colour = np.asarray(body_colour_bgr, dtype=np.float32)
    if not np.all(np.isfinite(colour)) or not np.isfinite(radius_px) or radius_px < 3:
        return None
    h, w = frame.shape[:2]
    reach = 0.8 * radius_px
    u0, u1 = max(int(np.floor(u_px - reach)), 0), min(int(np.ceil(u_px + reach)) + 1, w)
    v0, v1 = max(int(np.floor(v_px - reach)), 0), min(int(np.ceil(v_px + reach)) + 1, h)
    if u1 - u0 < 3 or v1 - v0 < 3:
        return None
    patch = frame[v0:v1, u0:u1].astype(np.float32)
    du = np.arange(u0, u1, dtype=np.float32)[None, :] - u_px
    dv = np.arange(v0, v1, dtype=np.float32)[:, None] - v_px
    inside = du * du + dv * dv <= reach * reach
    if patch.ndim == 3:
        difference = np.sqrt(np.sum((patch - colour[None, None, :]) ** 2, axis=2) / 3.0)
    else:
        difference = np.abs(patch - float(np.mean(colour)))
    weight = np.clip((difference - min_difference) / min_difference, 0.0, 1.0) * inside
    if float(weight.sum()) < MIN_MARKER_SHARE * np.pi * reach * reach:
        return None
    return du, dv, weight


def marker_offset_px(
    frame: np.ndarray,
    u_px: float,
    v_px: float,
    radius_px: float,
    body_colour_bgr,
    *,
    min_difference: float = 40.0,
) -> tuple[float, float]:
    """Image offset (du, dv) [px] of a marker spot's centroid from the body centre.

    Pixels inside 0.8 r whose colour differs from the body's by more than
    ``min_difference`` grey levels are weighted by how much they differ. Returns
    ``(nan, nan)`` when too few such pixels exist or their centroid is central.

    Examples
    --------
    >>> img = np.full((41, 41, 3), 200, np.uint8)
    >>> img[18:23, 26:31] = 20                     # a dark spot right of centre
    >>> [round(c, 3) for c in marker_offset_px(img, 20.0, 20.0, 15.0, (200, 200, 200))]
    [8.0, 0.0]
    """
    grid = _marker_weights(
        frame, u_px, v_px, radius_px, body_colour_bgr, min_difference
    )
    if grid is None:
        return np.nan, np.nan
    du, dv, weight = grid
    total = float(weight.sum())
    mu = float((weight * du).sum() / total)
    mv = float((weight * dv).sum() / total)
    if np.hypot(mu, mv) < MIN_MARKER_OFFSET * radius_px:
        return np.nan, np.nan
    return mu, mv


def measure_marker(
    frame: np.ndarray,
    u_px: float,
    v_px: float,
    radius_px: float,
    body_colour_bgr,
    *,
    min_difference: float = 40.0,
) -> tuple[float, float, bool]:
    """Marker direction as an image offset (du, dv) [px] and whether it is axial.

    A spot (or any marker off the centre) gives the offset of its centroid
    (``axial`` False). A stripe through the centre has a central centroid; its
    direction is then the principal axis of the marker pixels, known only modulo
    half a turn (``axial`` True, offset of length 0.5 r along the axis). NaN when
    neither can be measured.

    Examples
    --------
    >>> img = np.full((41, 41, 3), 200, np.uint8)
    >>> img[19:22, 6:35] = 20                      # a horizontal stripe
    >>> du, dv, axial = measure_marker(img, 20.0, 20.0, 15.0, (200, 200, 200))
    >>> round(du, 3), round(dv, 3), axial
    (7.5, 0.0, True)
    """
    du, dv = marker_offset_px(
        frame, u_px, v_px, radius_px, body_colour_bgr, min_difference=min_difference
    )
    if np.isfinite(du):
        return du, dv, False
    grid = _marker_weights(
        frame, u_px, v_px, radius_px, body_colour_bgr, min_difference
    )
    if grid is None:
        return np.nan, np.nan, False
    gu, gv, weight = grid
    total = float(weight.sum())
    suu = float((weight * gu * gu).sum() / total)
    svv = float((weight * gv * gv).sum() / total)
    suv = float((weight * gu * gv).sum() / total)
    spread = np.sqrt((suu - svv) ** 2 + 4 * suv * suv)
    major, minor = 0.5 * (suu + svv + spread), 0.5 * (suu + svv - spread)
    if major < 4.0 * max(minor, 1e-9):  # not elongated: a blob at the centre
        return np.nan, np.nan, False
    axis = 0.5 * np.arctan2(2 * suv, suu - svv)
    return (
        0.5 * radius_px * float(np.cos(axis)),
        0.5 * radius_px * float(np.sin(axis)),
        True,
    )


def marker_angle_world(
    calibration: Calibration, u_px, v_px, du_px, dv_px
) -> np.ndarray:
    """World angle [rad] (counter-clockwise from +x, z up) of image offsets (du, dv)."""
    x0, z0 = calibration.to_world(u_px, v_px)
    x1, z1 = calibration.to_world(np.asarray(u_px) + du_px, np.asarray(v_px) + dv_px)
    return np.arctan2(z1 - z0, x1 - x0)


def unwrap_angle(angle_rad: np.ndarray, period: float = 2 * np.pi) -> np.ndarray:
    """Unwrap an angle series over its valid (finite) samples; NaN stay NaN.

    The rotation between consecutive valid samples must stay below half a
    ``period`` (use ``period=pi`` for an axial stripe, known modulo half a turn).

    Examples
    --------
    >>> a = np.array([3.0, -3.0, np.nan, -2.5])
    >>> np.round(unwrap_angle(a), 3).tolist()
    [3.0, 3.283, nan, 3.783]
    """
    angle = np.asarray(angle_rad, dtype=float)
    out = np.full_like(angle, np.nan)
    ok = np.isfinite(angle)
    if ok.any():
        scale = 2 * np.pi / period
        out[ok] = np.unwrap(angle[ok] * scale) / scale
    return out


def angular_velocity(
    t_s: np.ndarray, angle_rad: np.ndarray, window: int = 15
) -> tuple[np.ndarray, np.ndarray]:
    """Smoothed derivative of an unwrapped angle: local straight-line fits.

    Parameters
    ----------
    t_s
        Times [s] (need not be uniform).
    angle_rad
        Unwrapped marker angle [rad]; NaN where unknown.
    window
        Samples in each local fit (odd; about 12 ms at 1205 frames/s for 15).

    Returns
    -------
    omega_radps, omega_sd_radps
        Slope of the local fit [rad/s] and its standard error from the robust scatter
        of the angle about the fits; NaN where fewer than ``window // 2 + 1`` valid
        samples are in the window.

    Examples
    --------
    >>> t = np.arange(40) / 1000.0
    >>> w, sd = angular_velocity(t, 2.0 - 30.0 * t)
    >>> round(float(w[20]), 6), bool(sd[20] < 1e-6)
    (-30.0, True)
    """
    t = np.asarray(t_s, dtype=float)
    a = np.asarray(angle_rad, dtype=float)
    n = len(t)
    omega = np.full(n, np.nan)
    sd = np.full(n, np.nan)
    if n < 3:
        return omega, sd
    window = max(3, min(int(window), n if n % 2 else n - 1) | 1)
    half = window // 2
    ok = np.isfinite(a) & np.isfinite(t)
    kernel = np.ones(window)

    def run(x):
        return np.convolve(np.where(ok, x, 0.0), kernel, mode="same")

    t_ref = np.where(ok, t - np.nanmean(t[ok]) if ok.any() else t, 0.0)
    cnt = np.convolve(ok.astype(float), kernel, mode="same")
    st, sa = run(t_ref), run(np.where(ok, a, 0.0))
    stt, sta = run(t_ref * t_ref), run(t_ref * np.where(ok, a, 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        sxx = stt - st * st / cnt
        slope = (sta - st * sa / cnt) / sxx
        intercept = (sa - slope * st) / cnt
    enough = cnt >= half + 1
    omega[enough] = slope[enough]
    # scatter of each sample about the fit centred on it
    resid = np.where(ok & enough, a - (intercept + slope * t_ref), np.nan)
    finite = resid[np.isfinite(resid)]
    if finite.size >= 3:
        sigma = 1.4826 * float(np.median(np.abs(finite - np.median(finite))))
        sigma *= np.sqrt(window / max(window - 2, 1))
        with np.errstate(invalid="ignore", divide="ignore"):
            sd[enough] = sigma / np.sqrt(sxx[enough])
    return omega, sd
