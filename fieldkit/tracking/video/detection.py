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

    # ---------------------------------------------------------------- candidates
    def _candidates(self, frame: np.ndarray, window: tuple[int, int, int, int]):
        u0, v0, u1, v1 = window
        w, h = self.size
        diff = colour_difference(
            frame[v0:v1, u0:u1], scaled(self.background[v0:v1, u0:u1], self._gain)
        )
        _, mask = cv2.threshold(diff, self.threshold, 255, cv2.THRESH_BINARY)
        mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, _OPEN_KERNEL)
        contours = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[-2]
        s = self.settings
        out = []
        for contour in contours:
            pts = contour.reshape(-1, 2).astype(np.float64)
            if len(pts) < 12:
                continue
            area = cv2.contourArea(contour)
            if area < 0.5 * np.pi * s.min_radius_px**2:
                continue
            u, v = pts[:, 0] + u0, pts[:, 1] + v0
            inner = (u > 0.5) & (u < w - 1.5) & (v > 0.5) & (v < h - 1.5)
            cut = (~inner) | (pts[:, 0] < 0.5) | (pts[:, 0] > u1 - u0 - 1.5)
            cut |= (pts[:, 1] < 0.5) | (pts[:, 1] > v1 - v0 - 1.5)
            if (cut & inner).any() or inner.sum() < 10:
                continue  # cut by the search window, not the frame: search wider
            partial = not bool(inner.all())  # touches the frame border
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
                    continue
                inner = keep
            # boundary pixels sit ~0.5 px inside the true rim
            r_rim = r + 0.5
            if not (s.min_radius_px <= r_rim <= s.max_radius_px):
                continue
            if rms > s.max_fit_residual * r_rim:
                continue
            angles = np.arctan2(v[inner] - vc, u[inner] - uc)
            bins = ((angles + np.pi) / (2 * np.pi) * 36).astype(int) % 36
            visible = np.count_nonzero(np.bincount(bins, minlength=36)) / 36.0
            if visible < s.min_visible_fraction:
                continue
            if not partial and not 0.7 <= area / (np.pi * r * r) <= 1.3:
                continue
            if not (
                self.roi[0] <= uc < self.roi[2] and self.roi[1] <= vc < self.roi[3]
            ):
                continue
            out.append((uc, vc, r_rim, rms, partial, visible))
        return out

    def _choose(self, candidates, prediction):
        expected = self.expected_radius_px
        if expected is None and len(self._radii) >= 5:
            expected = float(np.median(self._radii[-25:]))
        best, best_cost = None, np.inf
        for cand in candidates:
            uc, vc, r = cand[:3]
            cost = 0.0
            if expected is not None:
                rel = abs(r / expected - 1.0)
                if rel > self.settings.radius_tolerance:
                    if self.expected_radius_px is not None:
                        self.off_size_radii.append(float(r))
                    continue
                cost += rel
            if prediction is not None:
                cost += np.hypot(uc - prediction[0], vc - prediction[1]) / max(r, 1.0)
            else:
                cost -= 1e-6 * r  # the largest plausible body when nothing is known
            if cost < best_cost:
                best, best_cost = cand, cost
        return best

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
    def detect(
        self, frame: np.ndarray, prediction: tuple[float, float, float] | None = None
    ) -> Detection | None:
        """Find the ball; ``prediction`` = (u, v, search radius) narrows the search."""
        w, h = self.size
        if self.compensate_flicker:
            self._gain = brightness_gain(frame, self.background)
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
                candidates = self._candidates(frame, window)
        if not candidates:
            prediction = None
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
            candidates = self._candidates(frame, window)
        best = self._choose(candidates, prediction)
        if best is None:
            return None
        uc, vc, r, rms, partial, visible = best
        colour = (np.nan, np.nan, np.nan)
        if not partial:
            uc, vc, r, colour = self._refine(frame, uc, vc, r)
            uc, vc, r, colour = self._refine(frame, uc, vc, r)
            self._radii.append(r)
        else:
            known = self.expected_radius_px
            if known is None and len(self._radii) >= 5:
                known = float(np.median(self._radii[-25:]))
            if known is not None:
                uc, vc = self._refine_partial(frame, uc, vc, known)
                r = known
        return Detection(
            float(uc), float(vc), float(r), partial, float(visible), float(rms), colour
        )
