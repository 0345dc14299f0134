"""Find a ball in a video frame against a static background, to a fraction of a pixel.

Three stages, each cheap enough to run at more than decoding speed:

1. **Background model** (:mod:`fieldkit.tracking.video.background`): the per-pixel
   median of frames sampled across the clip, repaired where a slow or resting body
   spoils it. A moving body vanishes from it; a static textured scene (plate, net
   anchors, scale bars) stays.
2. **Candidates**: colour difference to the background (largest channel difference,
   so a coloured ball on a grey scene of the same brightness still stands out), a
   threshold set from the measured noise, a morphological opening (removes sensor
   noise, compression specks and thin strands such as a net), outer contours. Each
   contour gets a circle fit to its edge points that are not on the frame border
   (a body entering or leaving the frame is only partly visible) and a shape test:
   fit residual, radius range, fill ratio and the arc of the circle that is visible.
   The background is scaled by the frame's overall brightness first (lamps on mains
   power flicker at 100/120 Hz, which a 1000+ frames/s camera sees).
3. **Sub-pixel centre**: the pixels near the rim are unmixed into a coverage
   ``alpha = (I - B)·(C - B) / |C - B|^2`` between the background ``B`` and the body's
   colour ``C``; the coverage-weighted centroid is the centre of the disc to a few
   hundredths of a pixel on anti-aliased images. For a partly visible body the circle
   fit with the known radius is used instead (flagged ``partial``).

Search windows follow the body (constant-velocity prediction), falling back to the
whole region of interest when it is lost.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from fieldkit.tracking.video.image_difference import (
    brightness_gain,
    colour_difference,
    scaled,
    shadow_mask,
)

#: kernel for the opening that removes specks and 1-2 px strands
_OPEN_KERNEL = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))


@dataclass(frozen=True)
class Detection:
    """One body found in one frame (pixels; ``u`` right, ``v`` down)."""

    u_px: float
    v_px: float
    radius_px: float
    partial: (
        bool  # touches the frame border: centre from a circle fit to the visible arc
    )
    visible_fraction: float  # share of the rim inside the frame, 0..1
    fit_residual_px: float
    colour_bgr: tuple[float, float, float]  # the body's own colour (median of its ring)
    #: a motion streak: the centre is the streak's centroid (mid-exposure position)
    blurred: bool = False
    #: standard deviation of the centre [px]: 0.05 px for a whole sharp disc, the
    #: circle fit's for a partial one, a tenth of the streak length for a blurred one
    position_sd_px: float = 0.05
    #: "ok", "blurred", "partial" or "low_contrast" (found below the threshold)
    status: str = "ok"
    #: other bodies in the search as plausible as this one (no prediction to choose)
    ambiguous: bool = False


#: why a frame has no detection (:attr:`BallDetector.status`)
REFUSAL_REASONS = {
    "no_candidate": "nothing differs from the background",
    "too_small": "blobs smaller than a body",
    "too_large": "blobs larger than a body",
    "not_round": "blobs neither round nor a motion streak",
    "partial_arc": "too little of the rim visible",
    "shadow": "only a shadow",
    "outside_roi": "only outside the region of interest",
    "off_size": "bodies of another radius than the given one",
}


@dataclass
class Candidate:
    """A blob that passed the shape test (pixels)."""

    u: float
    v: float
    r: float
    rms: float
    partial: bool
    visible: float
    area: float = 0.0
    blurred: bool = False
    streak_px: float = 0.0  # streak length beyond the body's diameter
    colour: np.ndarray | None = None  # mean BGR inside the blob (with a body colour)
    twin: bool = False  # the streak reading of a blob also read as a larger circle
    #: radius [px] of the blob's half-contrast core (NaN when not measured): a soft
    #: edge (defocus, chroma subsampling, compression) widens the low-threshold
    #: silhouette by a few pixels, not the core
    core_r: float = float("nan")


@dataclass(frozen=True)
class DetectorSettings:
    """Tuning of :class:`BallDetector` (defaults suit a ball of 5-100 px radius)."""

    threshold: float | None = (
        None  # colour difference [grey levels]; None = 5 sigma + 10
    )
    min_radius_px: float = 4.0
    max_radius_px: float = 200.0
    max_fit_residual: float = 0.12  # RMS circle-fit residual / radius
    min_visible_fraction: float = 0.35  # shorter visible arcs are ignored
    radius_tolerance: float = (
        0.35  # accepted relative radius change from the expected one
    )
    suppress_shadows: bool = True  # leave cast shadows out (:func:`shadow_mask`)
    low_contrast: bool = True  # search again at 5 sigma of the noise when nothing found


def _hysteresis(
    diff: np.ndarray, seeds: np.ndarray, level: float, exclude: np.ndarray | None = None
) -> np.ndarray:
    """Blobs of ``diff > level`` that hold a seed pixel (uint8 mask, 255 = body).

    Examples
    --------
    >>> d = np.array([[0, 9, 30, 9, 0, 9]], np.uint8)
    >>> seeds = (d > 20).astype(np.uint8) * 255
    >>> (_hysteresis(d, seeds, 5) > 0).astype(int).tolist()
    [[0, 1, 1, 1, 0, 0]]
    """
    low = diff > level
    if exclude is not None:
        low &= ~exclude
    low |= seeds > 0
    count, labels = cv2.connectedComponents(low.astype(np.uint8), connectivity=8)
    if count <= 1:
        return seeds
    keep = np.zeros(count, bool)
    keep[np.unique(labels[seeds > 0])] = True
    keep[0] = False
    return keep[labels].astype(np.uint8) * 255


def _closed(mask: np.ndarray, size: int) -> np.ndarray:
    """Morphological closing with a disc ``size`` px wide (no-op for size < 3)."""
    if size < 3:
        return mask
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (size, size))
    return cv2.morphologyEx(mask, cv2.MORPH_CLOSE, kernel)


def _core_radius(part, bg, contour, inner=None) -> float:
    """Radius [px] of a blob's half-contrast core: the pixels that differ from the
    background by more than half the blob's contrast (its 95th-percentile colour
    difference), the body's edge when its rim is soft.

    The radius is that of the disc of the core's area or, when ``inner`` (a callable
    telling which ``(u, v)`` points of ``part`` lie inside the frame) is given for a
    body cut by the frame border, of a circle fitted to the core's rim inside it.

    Examples
    --------
    >>> bg = np.zeros((40, 40, 3), np.uint8)
    >>> img = bg.copy()
    >>> _ = cv2.circle(img, (20, 20), 10, (200, 200, 200), -1)
    >>> soft = cv2.GaussianBlur(img, (0, 0), 2.0)
    >>> mask = (soft.max(axis=2) > 10).astype(np.uint8) * 255
    >>> c = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[-2][0]
    >>> bool(abs(_core_radius(soft, bg, c) - 10.0) < 0.8)
    True
    >>> cut = lambda u, v: u < 35  # the frame ends at u = 35
    >>> bool(abs(_core_radius(soft[:, :36], bg[:, :36], c, cut) - 10.0) < 0.8)
    True
    """
    x, y, w, h = cv2.boundingRect(contour)
    fill = np.zeros((h, w), np.uint8)
    cv2.drawContours(fill, [contour], -1, 255, -1, offset=(-x, -y))
    diff = colour_difference(part[y : y + h, x : x + w], bg[y : y + h, x : x + w])
    inside = diff[fill > 0].astype(np.float64)
    if inside.size < 12:
        return float("nan")
    contrast = float(np.percentile(inside, 95))
    core = (fill > 0) & (diff > 0.5 * contrast)
    if inner is None:
        return float(np.sqrt(np.count_nonzero(core) / np.pi))
    rims = cv2.findContours(
        core.astype(np.uint8) * 255, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE
    )[-2]
    if not rims:
        return float("nan")
    pts = max(rims, key=cv2.contourArea).reshape(-1, 2).astype(np.float64) + (x, y)
    keep = inner(pts[:, 0], pts[:, 1])
    if keep.sum() < 10:
        return float("nan")
    _, _, r, _ = fit_circle(pts[keep, 0], pts[keep, 1])
    return float(r + 0.5)


def _is_shadow(part, bg, contour, detector) -> bool:
    """Whether a blob is a cast shadow: mostly shadow-like pixels (:func:`shadow_mask`)
    over background texture the frame preserves (correlation > 0.6); an opaque body
    hides the texture behind it. Over a plain background a grey body and a shadow
    look alike: the blob is kept (its shape and the prediction decide)."""
    fill = np.zeros(part.shape[:2], np.uint8)
    cv2.drawContours(fill, [contour], -1, 255, -1)
    inside = fill > 0
    dimmed = shadow_mask(part[inside], bg[inside], noise=detector.noise_sd)
    if np.count_nonzero(dimmed) < 0.7 * dimmed.size:
        return False
    f = part[inside].astype(np.float32).mean(axis=1)
    b = bg[inside].astype(np.float32).mean(axis=1)
    if b.std() > 3.0 * detector.noise_sd and f.std() > 0:
        return float(np.corrcoef(f, b)[0, 1]) > 0.6
    return False


def fit_circle(u: np.ndarray, v: np.ndarray) -> tuple[float, float, float, float]:
    """Algebraic (Kasa) least-squares circle; returns (uc, vc, r, rms residual).

    Examples
    --------
    >>> a = np.linspace(0, np.pi, 50)
    >>> [round(float(x), 6) for x in fit_circle(3 + 2 * np.cos(a), 4 + 2 * np.sin(a))]
    [3.0, 4.0, 2.0, 0.0]
    """
    u0, v0 = float(np.mean(u)), float(np.mean(v))
    du, dv = u - u0, v - v0
    a = np.column_stack([du, dv, np.ones_like(du)])
    b = du * du + dv * dv
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    uc, vc = sol[0] / 2.0, sol[1] / 2.0
    r = float(np.sqrt(max(sol[2] + uc * uc + vc * vc, 0.0)))
    resid = np.hypot(du - uc, dv - vc) - r
    return uc + u0, vc + v0, r, float(np.sqrt(np.mean(resid * resid)))


class BallDetector:
    """Detect one ball per frame against a fixed background.

    Parameters
    ----------
    background
        uint8 BGR image of the empty scene (:func:`median_background`).
    threshold
        Colour-difference threshold [grey levels] (:func:`noise_threshold`).
    roi
        ``(u0, v0, width, height)`` [px]: only bodies centred inside are found.
    expected_radius_px
        Body radius in pixels when known (``radius_m`` and the calibration); otherwise
        learnt from the first confident detections.
    compensate_flicker
        Scale the background by each frame's brightness (:func:`brightness_gain`);
        :func:`flickers` tells whether a clip needs it.
    body_colour
        The body's BGR colour when known (from a user-given box): its pixels are never
        taken for shadow and candidates of that colour are preferred.

    After each :meth:`detect`, ``status`` says why nothing was found (a key of
    :data:`REFUSAL_REASONS`) or how the body was found (:attr:`Detection.status`).
    """

    def __init__(
        self,
        background: np.ndarray,
        threshold: float,
        *,
        roi: tuple[int, int, int, int] | None = None,
        expected_radius_px: float | None = None,
        settings: DetectorSettings | None = None,
        compensate_flicker: bool = True,
        body_colour: tuple[float, float, float] | None = None,
    ) -> None:
        self.background = background
        self.compensate_flicker = compensate_flicker
        self.background_f = background.astype(np.float32)
        self.threshold = float(threshold)
        self.settings = settings or DetectorSettings()
        h, w = background.shape[:2]
        self.size = (w, h)
        if roi is None:
            roi = (0, 0, w, h)
        u0, v0, rw, rh = (int(round(x)) for x in roi)
        self.roi = (max(u0, 0), max(v0, 0), min(u0 + rw, w), min(v0 + rh, h))
        self.expected_radius_px = expected_radius_px
        #: radii [px] of bodies passed over because they were not of the given size
        #: (``expected_radius_px``): a radius off by 2 is a diameter or a wrong scale
        self.off_size_radii: list[float] = []
        self._radii: list[float] = []
        self._gain = 1.0  # brightness of the current frame relative to the background
        #: sensor noise [grey levels], from the threshold (5 sigma + 10, see
        #: :func:`~fieldkit.tracking.video.background.noise_threshold`)
        self.noise_sd = max((self.threshold - 10.0) / 5.0, 1.0)
        self.body_colour = (
            None if body_colour is None else np.asarray(body_colour, np.float32)
        )
        self.status = "no_candidate"
        self._refused: list[tuple[float, str]] = []
        self._ambiguous = False

    # ---------------------------------------------------------------- candidates
    def _candidates(
        self,
        frame: np.ndarray,
        window: tuple[int, int, int, int],
        *,
        threshold: float | None = None,
        velocity: tuple[float, float] | None = None,
        close_px: int = 0,
    ) -> list[Candidate]:
        """Bodies in ``window``; refused blobs go to ``self._refused`` with a reason.

        Shadows (:func:`shadow_mask`) are left out of the body mask first; when no
        body remains the whole difference is searched again and a blob that is
        mostly shadow over a background texture it preserves is refused as
        ``"shadow"``. Each blob grows by hysteresis into its neighbours above half the
        threshold, so the dim side of a low-contrast body is part of its silhouette;
        ``close_px`` > 0 closes gaps that wide (a body on a background of nearly its
        own colour in places).
        """
        u0, v0, u1, v1 = window
        part = frame[v0:v1, u0:u1]
        bg = scaled(self.background[v0:v1, u0:u1], self._gain)
        diff = colour_difference(part, bg)
        thr = self.threshold if threshold is None else float(threshold)
        high = cv2.morphologyEx(
            (diff > thr).astype(np.uint8) * 255, cv2.MORPH_OPEN, _OPEN_KERNEL
        )
        low_level = max(0.5 * thr, 3.0 * self.noise_sd)
        shadow = None
        if self.settings.suppress_shadows:
            shadow = np.zeros(diff.shape, bool)
            where = np.nonzero(diff > low_level)  # only where it matters: fast
            shadow[where] = shadow_mask(part[where], bg[where], noise=self.noise_sd)
            if self.body_colour is not None:  # the body's own colour is never shadow
                near = np.abs(part.astype(np.float32) - self.body_colour).max(axis=2)
                shadow &= near > 3.0 * self.noise_sd + 10.0
            body = high.copy()
            body[shadow] = 0
            body = cv2.morphologyEx(body, cv2.MORPH_OPEN, _OPEN_KERNEL)
            grown = _hysteresis(diff, body, low_level, exclude=shadow)
            if close_px:
                grown = _closed(self._colour_grow(part, grown, close_px // 2), close_px)
            found = self._shapes(part, bg, grown, window, velocity, None)
            if found or not (shadow & (high > 0)).any():
                return found
            self._refused.clear()
        grown = _hysteresis(diff, high, low_level)
        if close_px:
            grown = _closed(self._colour_grow(part, grown, close_px // 2), close_px)
        return self._shapes(part, bg, grown, window, velocity, shadow)

    def _colour_grow(self, part, seeds: np.ndarray, reach: int) -> np.ndarray:
        """``seeds`` plus the pixels within ``reach`` of them that have the body's
        colour (given, else the median of the seed pixels) within the noise: where
        the background matches the body, the difference misses part of it."""
        if not seeds.any():
            return seeds
        colour = self.body_colour
        if colour is None:
            colour = np.median(part[seeds > 0].reshape(-1, 3), axis=0)
        kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * reach + 1,) * 2)
        near = cv2.dilate(seeds, kernel) > 0
        like = np.abs(part.astype(np.float32) - colour).max(axis=2)
        like = like < 3.0 * self.noise_sd + 4.0
        return np.where(near & like, 255, seeds).astype(np.uint8)

    def _shapes(self, part, bg, mask, window, velocity, shadow) -> list[Candidate]:
        """Shape test of every blob of ``mask`` (see :meth:`_candidates`)."""
        u0, v0, u1, v1 = window
        w, h = self.size
        contours = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[-2]
        s = self.settings
        out = []
        for contour in contours:
            area = cv2.contourArea(contour)
            if len(contour) < 12 or area < 0.5 * np.pi * s.min_radius_px**2:
                if area >= 0.25 * np.pi * s.min_radius_px**2:
                    self._refused.append((area, "too_small"))
                continue  # sensor noise, compression specks
            pts = contour.reshape(-1, 2).astype(np.float64)
            u, v = pts[:, 0] + u0, pts[:, 1] + v0
            inner = (u > 0.5) & (u < w - 1.5) & (v > 0.5) & (v < h - 1.5)
            cut = (~inner) | (pts[:, 0] < 0.5) | (pts[:, 0] > u1 - u0 - 1.5)
            cut |= (pts[:, 1] < 0.5) | (pts[:, 1] > v1 - v0 - 1.5)
            if (cut & inner).any() or inner.sum() < 10:
                continue  # cut by the search window, not the frame: search wider
            partial = not bool(inner.all())  # touches the frame border
            if shadow is not None and _is_shadow(part, bg, contour, self):
                self._refused.append((area, "shadow"))
                continue
            cand, reason = self._round(u, v, inner, area, partial)
            if cand is not None:
                cand.core_r = _core_radius(
                    part, bg, contour, self._inside(u0, v0) if partial else None
                )
            streak = None
            if not partial:
                streak = self._streak(contour, u0, v0, area, velocity)
                if cand is None and streak is not None:
                    cand, reason, streak = streak, "", None
                elif streak is not None and streak.r * 1.15 < cand.r:
                    # a short streak also passes for a larger circle: offer both,
                    # the expected radius chooses
                    streak.twin = True
                else:
                    streak = None
            if cand is None:
                self._refused.append((area, reason))
                continue
            if not (
                self.roi[0] <= cand.u < self.roi[2]
                and self.roi[1] <= cand.v < self.roi[3]
            ):
                self._refused.append((area, "outside_roi"))
                continue
            if self.body_colour is not None:
                fill = np.zeros(mask.shape, np.uint8)
                cv2.drawContours(fill, [contour], -1, 255, -1)
                cand.colour = np.array(cv2.mean(part, mask=fill)[:3], np.float32)
            out.append(cand)
            if streak is not None:
                streak.colour = cand.colour
                out.append(streak)
        return out

    def _inside(self, u0: int, v0: int):
        """Tells which points ``(u, v)`` of a window at ``(u0, v0)`` lie off the
        frame border (the test of :meth:`_shapes`)."""
        w, h = self.size

        def inside(u, v):
            u, v = u + u0, v + v0
            return (u > 0.5) & (u < w - 1.5) & (v > 0.5) & (v < h - 1.5)

        return inside

    def _round(self, u, v, inner, area, partial):
        """Circle fit and shape test of one blob: (Candidate, "") or (None, reason)."""
        s = self.settings
        uc, vc, r, rms = fit_circle(u[inner], v[inner])
        if rms > 0.5:  # outliers (low-contrast patch, a strand): trim and refit
            keep = inner.copy()
            for _ in range(3):
                dev = np.abs(np.hypot(u - uc, v - vc) - r)
                keep = inner & (dev < max(1.0, 2.0 * rms))
                if keep.sum() < 0.6 * inner.sum():
                    break
                uc, vc, r, rms = fit_circle(u[keep], v[keep])
            if keep.sum() < 0.6 * inner.sum():
                return None, "not_round"
            inner = keep
        # boundary pixels sit ~0.5 px inside the true rim
        r_rim = r + 0.5
        if r_rim < s.min_radius_px:
            return None, "too_small"
        if r_rim > s.max_radius_px:
            return None, "too_large"
        if rms > s.max_fit_residual * r_rim:
            return None, "not_round"
        angles = np.arctan2(v[inner] - vc, u[inner] - uc)
        bins = ((angles + np.pi) / (2 * np.pi) * 36).astype(int) % 36
        visible = np.count_nonzero(np.bincount(bins, minlength=36)) / 36.0
        if visible < s.min_visible_fraction:
            return None, "partial_arc"
        if not partial and not 0.7 <= area / (np.pi * r * r) <= 1.3:
            return None, "not_round"
        return Candidate(uc, vc, r_rim, rms, partial, visible, area=area), ""

    def _streak(self, contour, u0, v0, area, velocity) -> Candidate | None:
        """A motion-blurred body: a stadium (a disc swept along a line) or None.

        The blob must be convex, as wide as a body, longer than wide by at least
        0.6 radius, fill its stadium and, when the velocity is predicted, lie along
        it within 25 degrees. Its centroid is the mid-exposure centre.
        """
        s = self.settings
        hull = cv2.convexHull(contour)
        if area < 0.9 * cv2.contourArea(hull):
            return None
        m = cv2.moments(contour)
        if m["m00"] <= 0:
            return None
        cu, cv_ = m["m10"] / m["m00"], m["m01"] / m["m00"]
        cov = np.array([[m["mu20"], m["mu11"]], [m["mu11"], m["mu02"]]])
        _, vecs = np.linalg.eigh(cov)
        major = vecs[:, 1]
        pts = contour.reshape(-1, 2).astype(np.float64) - (cu, cv_)
        along, across = pts @ major, pts @ vecs[:, 0]
        half_width = 0.5 * float(np.ptp(across))  # boundary pixel centres
        length = float(np.ptp(along))
        sweep = length - 2.0 * half_width
        radius = half_width + 0.5
        if sweep < 0.6 * radius or not (s.min_radius_px <= radius <= s.max_radius_px):
            return None
        stadium = np.pi * half_width**2 + 2.0 * half_width * sweep
        if not 0.8 <= area / stadium <= 1.2:
            return None
        # rounded ends (a bar or a box has corners): the rim is one half-width
        # from the swept segment
        ends = np.abs(along) > 0.5 * sweep
        gap = np.hypot(np.abs(along[ends]) - 0.5 * sweep, across[ends]) - half_width
        if np.sqrt(np.mean(gap * gap)) > 0.12 * half_width + 0.3:
            return None
        if velocity is not None and np.hypot(*velocity) > 0.5:
            cos = abs(major @ np.asarray(velocity)) / np.hypot(*velocity)
            if cos < np.cos(np.radians(25.0)):
                return None
        return Candidate(
            cu + u0,
            cv_ + v0,
            radius,
            0.0,
            False,
            1.0,
            area=area,
            blurred=True,
            streak_px=sweep,
        )

    def _choose(self, candidates: list[Candidate], prediction) -> Candidate | None:
        expected = self.expected_radius_px
        if expected is None and len(self._radii) >= 5:
            expected = float(np.median(self._radii[-25:]))
        costs = []
        for cand in candidates:
            cost = 0.0
            if expected is not None:
                rel = abs(cand.r / expected - 1.0)
                soft = rel <= 2.0 * self.settings.radius_tolerance
                if soft and np.isfinite(cand.core_r):
                    # a soft rim (a halo of a few pixels): the core may be the body
                    rel = min(rel, abs(cand.core_r / expected - 1.0))
                if cand.blurred and cand.r < expected:  # a dim streak looks narrower
                    rel *= 0.5
                if rel > self.settings.radius_tolerance:
                    if self.expected_radius_px is not None:
                        self.off_size_radii.append(float(cand.r))
                    continue
                cost += rel
            if self.body_colour is not None and cand.colour is not None:
                cost += float(np.abs(cand.colour - self.body_colour).max()) / 50.0
            if prediction is not None:
                cost += np.hypot(cand.u - prediction[0], cand.v - prediction[1]) / max(
                    cand.r, 1.0
                )
            else:
                cost -= 1e-6 * cand.r  # the largest plausible body, nothing known
            costs.append((cost, cand))
        if not costs:
            return None
        costs.sort(key=lambda item: item[0])
        # several bodies and nothing (a prediction, a size, a colour) to tell them apart
        rivals = [c for c in costs if not c[1].twin]
        self._ambiguous = (
            prediction is None
            and len(rivals) > 1
            and rivals[1][0] - rivals[0][0] < 0.25
        )
        return costs[0][1]

    # ---------------------------------------------------------------- refinement
    def _coverage(self, frame: np.ndarray, uc: float, vc: float, r: float):
        """Unmixed body coverage ``alpha`` of the pixels around (uc, vc).

        Returns ``(uu, vv, alpha, usable, colour)`` or None when the patch is too
        small; ``usable`` marks pixels whose background differs enough from the body
        colour for ``alpha`` to be trusted.
        """
        w, h = self.size
        half = int(np.ceil(r + 3))
        iu, iv = int(round(uc)), int(round(vc))
        u0, u1 = max(iu - half, 0), min(iu + half + 1, w)
        v0, v1 = max(iv - half, 0), min(iv + half + 1, h)
        if u1 - u0 < 4 or v1 - v0 < 4:
            return None
        patch = frame[v0:v1, u0:u1].astype(np.float32)
        bg = self.background_f[v0:v1, u0:u1] * self._gain
        shape = patch.shape[:2]
        uu = np.broadcast_to(np.arange(u0, u1, dtype=np.float64)[None, :], shape)
        vv = np.broadcast_to(np.arange(v0, v1, dtype=np.float64)[:, None], shape)
        dist = np.hypot(uu - uc, vv - vc)
        ring = (dist > 0.8 * r) & (dist < 0.92 * r)
        if ring.sum() < 8:
            return None
        ring_pixels = patch[ring]
        colour = ring_pixels.mean(axis=0)  # trimmed mean: drop marker/rim outliers
        near = np.abs(ring_pixels - colour).max(axis=1) < 40.0
        if near.sum() >= 8:
            colour = ring_pixels[near].mean(axis=0)
        contrast = colour[None, None, :] - bg
        c2 = np.sum(contrast * contrast, axis=2)
        alpha = np.sum((patch - bg) * contrast, axis=2) / np.maximum(c2, 1.0)
        usable = c2 >= (2.0 * self.threshold) ** 2
        if self.settings.suppress_shadows:  # a shadow beside the body is background
            usable &= ~shadow_mask(patch, bg, noise=self.noise_sd)
        return uu, vv, np.clip(alpha, 0.0, 1.0), usable, colour

    def _refine(self, frame: np.ndarray, uc: float, vc: float, r: float):
        """Coverage-weighted centroid of a whole disc: (uc, vc, r, body colour)."""
        cov = self._coverage(frame, uc, vc, r)
        if cov is None:
            return uc, vc, r, (np.nan, np.nan, np.nan)
        uu, vv, alpha, usable, colour = cov
        dist = np.hypot(uu - uc, vv - vc)
        # where body and background look alike, trust the fitted shape instead
        alpha = np.where(usable, alpha, (dist <= r).astype(np.float64))
        alpha[dist < 0.85 * r] = 1.0  # interior, marker included
        alpha[dist > r + 2.5] = 0.0
        total = float(alpha.sum())
        body = tuple(float(c) for c in colour)
        if total <= 0:
            return uc, vc, r, body
        u_new = float((alpha * uu).sum() / total)
        v_new = float((alpha * vv).sum() / total)
        return u_new, v_new, float(np.sqrt(total / np.pi)), body

    def _refine_partial(self, frame: np.ndarray, uc: float, vc: float, r: float):
        """Centre of a disc of known radius cut by the frame border.

        Gauss-Newton fit of the rim coverage ``clip(r + 0.5 - d, 0, 1)`` to the
        unmixed coverage of the visible pixels near the rim.
        """
        cov = self._coverage(frame, uc, vc, r)
        if cov is None:
            return uc, vc
        uu, vv, alpha, usable, _ = cov
        for _ in range(6):
            dist = np.maximum(np.hypot(uu - uc, vv - vc), 1e-6)
            model = np.clip(r + 0.5 - dist, 0.0, 1.0)
            band = usable & (np.abs(dist - r) < 2.5)
            edge = band & (model > 0.0) & (model < 1.0)
            if edge.sum() < 6:
                break
            resid = (alpha - model)[band]
            ju = np.where(edge, (uu - uc) / dist, 0.0)[band]
            jv = np.where(edge, (vv - vc) / dist, 0.0)[band]
            step, *_ = np.linalg.lstsq(np.column_stack([ju, jv]), resid, rcond=None)
            step = np.clip(step, -1.0, 1.0)
            uc, vc = uc + float(step[0]), vc + float(step[1])
            if np.hypot(*step) < 1e-3:
                break
        return uc, vc

    # ---------------------------------------------------------------- public
    def _search(self, frame, prediction, velocity, threshold=None, close_px=0):
        """Candidates near the prediction, else in the whole region of interest."""
        w, h = self.size
        self._refused = []
        candidates = []
        if prediction is not None:
            pu, pv, reach = prediction
            window = (
                max(int(pu - reach), self.roi[0] - 0, 0),
                max(int(pv - reach), 0),
                min(int(pu + reach) + 1, w),
                min(int(pv + reach) + 1, h),
            )
            if window[2] - window[0] > 8 and window[3] - window[1] > 8:
                candidates = self._candidates(
                    frame,
                    window,
                    threshold=threshold,
                    velocity=velocity,
                    close_px=close_px,
                )
                if candidates:
                    return candidates, prediction
        u0, v0, u1, v1 = self.roi
        # search the ROI plus a margin so bodies centred near its edge are whole
        margin = (
            int(self.settings.max_radius_px)
            if self.expected_radius_px is None
            else int(2 * self.expected_radius_px)
        )
        window = (
            max(u0 - margin, 0),
            max(v0 - margin, 0),
            min(u1 + margin, w),
            min(v1 + margin, h),
        )
        self._refused = []
        found = self._candidates(
            frame, window, threshold=threshold, velocity=velocity, close_px=close_px
        )
        return found, None

    def detect(
        self,
        frame: np.ndarray,
        prediction: tuple[float, float, float] | None = None,
        velocity: tuple[float, float] | None = None,
    ) -> Detection | None:
        """Find the ball; ``prediction`` = (u, v, search radius) narrows the search.

        ``velocity`` (du, dv) [px/frame], when predicted, tells a motion streak
        along it. Sets :attr:`status` (why nothing was found, or how it was).
        """
        if self.compensate_flicker:
            self._gain = brightness_gain(frame, self.background)
        self._ambiguous = False
        given = prediction
        candidates, prediction = self._search(frame, given, velocity)
        best = self._choose(candidates, prediction)
        low_contrast = False
        if best is None and not candidates and self.settings.low_contrast:
            refused = self._refused
            holes = {r for _, r in refused} & {"not_round", "too_small"}
            expected = self.expected_radius_px or (
                float(np.median(self._radii[-25:])) if self._radii else 10.0
            )
            close = 2 * int(max(2.0, 0.25 * expected)) + 1
            passes = []
            if holes:  # a body in parts: parts of the background match its colour
                passes.append((None, close))
            if not refused and 5.0 * self.noise_sd < 0.8 * self.threshold:
                passes.append((5.0 * self.noise_sd, close))  # nothing differs enough
            for threshold, close_px in passes:
                candidates, prediction = self._search(
                    frame, given, velocity, threshold=threshold, close_px=close_px
                )
                best = self._choose(candidates, prediction)
                if best is not None:
                    low_contrast = True
                    break
            if best is None and not candidates:
                self._refused = refused
        if best is None:
            self.status = self._refusal(candidates)
            return None
        uc, vc, r = best.u, best.v, best.r
        colour = (np.nan, np.nan, np.nan)
        sd = 0.05
        if best.blurred:
            sd = 0.5 + 0.1 * best.streak_px
            status = "blurred"
        elif not best.partial:
            uc, vc, r, colour = self._refine(frame, uc, vc, r)
            uc, vc, r, colour = self._refine(frame, uc, vc, r)
            self._radii.append(r)
            status = "ok"
        else:
            status = "partial"
            sd = max(best.rms, 0.1)
            known = self.expected_radius_px
            if known is None and len(self._radii) >= 5:
                known = float(np.median(self._radii[-25:]))
            if known is not None:
                uc, vc = self._refine_partial(frame, uc, vc, known)
                r = known
        if low_contrast:
            status = "low_contrast"
        self.status = status
        return Detection(
            float(uc),
            float(vc),
            float(r),
            best.partial,
            float(best.visible),
            float(best.rms),
            colour,
            blurred=best.blurred,
            position_sd_px=float(sd),
            status=status,
            ambiguous=self._ambiguous,
        )

    def _refusal(self, candidates: list[Candidate]) -> str:
        """Why no candidate was accepted (a key of :data:`REFUSAL_REASONS`)."""
        if candidates:
            return "off_size"
        if not self._refused:
            return "no_candidate"
        return max(self._refused, key=lambda item: item[0])[1]
