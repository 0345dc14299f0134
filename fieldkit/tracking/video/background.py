"""The empty scene behind a moving body: a background model from sampled frames.

The per-pixel median of frames sampled across the clip removes a moving body. Two
cases a plain median gets wrong are repaired: a slow body (it covers the same pixels
in many samples; :func:`clean_background` takes the median without it, in rounds) and
a body resting for most of the clip (it *is* the median there; its "ghost" appears in
the other samples and :func:`repair_resting_body` takes the scene from them).
:func:`noise_threshold` sets the detector's threshold from the measured noise.
"""

from __future__ import annotations

import warnings

import numpy as np

from fieldkit.tracking.video.detection import BallDetector
from fieldkit.tracking.video.image_difference import (
    brightness_gain,
    colour_difference,
    scaled,
)


def median_background(frames: list[np.ndarray]) -> np.ndarray:
    """Per-pixel median (uint8 BGR) of a list of frames sampled across the clip.

    Examples
    --------
    >>> f = [np.full((2, 2, 3), v, np.uint8) for v in (10, 200, 12)]
    >>> int(median_background(f)[0, 0, 0])
    12
    """
    stack = np.stack(frames, axis=0)
    if len(frames) % 2:  # odd count: the middle order statistic, no float copy
        return np.partition(stack, len(frames) // 2, axis=0)[len(frames) // 2]
    return np.median(stack, axis=0).astype(np.uint8)


def noise_threshold(frames: list[np.ndarray], background: np.ndarray) -> float:
    """Difference threshold from the robust noise level of frames vs the background."""
    sigmas = []
    for frame in frames[: min(len(frames), 7)]:
        gain = brightness_gain(frame, background)
        d = colour_difference(frame, scaled(background, gain))[::2, ::2]
        d = d.astype(np.float32)
        sigmas.append(
            1.4826 * float(np.median(np.abs(d - np.median(d))))
            + 0.5 * float(np.median(d))
        )
    sigma = float(np.median(sigmas)) if sigmas else 3.0
    return float(np.clip(5.0 * sigma + 10.0, 15.0, 80.0))


def background_model(
    frames: list[np.ndarray],
    *,
    roi: tuple[int, int, int, int] | None = None,
    expected_radius_px: float | None = None,
    max_rounds: int = 5,
) -> tuple[np.ndarray, float]:
    """Background (uint8 BGR) and difference threshold from frames across a clip.

    The per-pixel median, then rounds of :func:`clean_background`: the body is found
    in the samples against the current background and left out of the median there,
    until no more samples show it (a slow body hides in a plain median; each round
    uncovers more of it).
    """
    first = median_background(frames)
    threshold = noise_threshold(frames, first)
    first = repair_resting_body(frames, first, threshold, roi=roi)
    background = first
    detections: list = [None] * len(frames)
    for _ in range(max_rounds):
        detector = BallDetector(
            background, threshold, roi=roi, expected_radius_px=expected_radius_px
        )
        new = 0
        for i, frame in enumerate(frames):
            if detections[i] is None:  # found ones stay found
                detections[i] = detector.detect(frame)
                new += detections[i] is not None
        if new == 0:
            break
        background = clean_background(frames, first, detections)
    return background, threshold


def clean_background(
    frames: list[np.ndarray], background: np.ndarray, detections: list
) -> np.ndarray:
    """Recompute the median where a slow body spoilt it, leaving the body out.

    ``detections[i]`` is the :class:`Detection` found in ``frames[i]`` against the
    first ``background`` (or None). Around every detection, each frame's pixels
    covered by its own body (radius 1.3 r + 2 px) are excluded and the median is
    taken over the other frames; pixels covered in every frame keep their value.
    """
    out = background.copy()
    h, w = background.shape[:2]
    discs = [
        (i, d.u_px, d.v_px, 1.3 * d.radius_px + 2.0)
        for i, d in enumerate(detections)
        if d is not None
    ]
    if not discs:
        return out
    for _, uc, vc, reach in discs:
        u0, u1 = max(int(uc - 2 * reach), 0), min(int(uc + 2 * reach) + 1, w)
        v0, v1 = max(int(vc - 2 * reach), 0), min(int(vc + 2 * reach) + 1, h)
        if u1 <= u0 or v1 <= v0:
            continue
        patch = np.stack([f[v0:v1, u0:u1] for f in frames]).astype(np.float32)
        uu = np.arange(u0, u1)[None, :]
        vv = np.arange(v0, v1)[:, None]
        for j, uj, vj, rj in discs:
            covered = (uu - uj) ** 2 + (vv - vj) ** 2 <= rj * rj
            patch[j][covered] = np.nan
        with warnings.catch_warnings():  # all-NaN columns: covered in every frame
            warnings.simplefilter("ignore", RuntimeWarning)
            median = np.nanmedian(patch, axis=0)
        known = np.isfinite(median)
        region = out[v0:v1, u0:u1]
        region[known] = np.clip(median[known] + 0.5, 0, 255).astype(np.uint8)
    return out


def _ring_colour(image: np.ndarray, uc: float, vc: float, r: float) -> np.ndarray:
    """Mean colour of the ring 0.8-0.92 r (outside a marker, inside the rim)."""
    h, w = image.shape[:2]
    u0, u1 = max(int(uc - r), 0), min(int(uc + r) + 2, w)
    v0, v1 = max(int(vc - r), 0), min(int(vc + r) + 2, h)
    uu = np.arange(u0, u1)[None, :] - uc
    vv = np.arange(v0, v1)[:, None] - vc
    d2 = uu * uu + vv * vv
    ring = (d2 > (0.8 * r) ** 2) & (d2 < (0.92 * r) ** 2)
    patch = image[v0:v1, u0:u1].astype(np.float32)
    return patch[ring].mean(axis=0) if ring.any() else np.full(3, np.nan)


def repair_resting_body(
    frames: list[np.ndarray],
    background: np.ndarray,
    threshold: float,
    *,
    roi: tuple[int, int, int, int] | None = None,
) -> np.ndarray:
    """Remove a body that rests for most of the clip from the median background.

    Such a body is part of the median, so the frames where it is elsewhere show its
    "ghost": a ball-shaped difference at the same place in several samples. A static
    candidate is a ghost when the background model there has the colour of the moving
    body (seen in the other candidates) while the frames show something else; the
    background there is then taken from the samples that show the ghost (they show the
    scene without the body). A genuinely resting body seen in a minority of samples
    keeps the median, which is already clean.
    """
    detector = BallDetector(background, threshold, roi=roi, compensate_flicker=False)
    h, w = background.shape[:2]
    found = []  # (sample, uc, vc, r)
    for i, frame in enumerate(frames):
        window = (0, 0, w, h)
        for cand in detector._candidates(frame, window):
            if not cand.partial and not cand.blurred:
                found.append((i, cand.u, cand.v, cand.r))
    clusters: list[list[tuple]] = []
    for item in found:
        for cluster in clusters:
            if np.hypot(item[1] - cluster[0][1], item[2] - cluster[0][2]) < 1.5:
                cluster.append(item)
                break
        else:
            clusters.append([item])
    moving = [c[0] for c in clusters if len(c) == 1]
    static = [c for c in clusters if len({s for s, *_ in c}) >= 2]
    if not moving or not static:
        return background
    body = np.median(
        [_ring_colour(frames[i], u, v, r) for i, u, v, r in moving], axis=0
    )
    out = background.copy()
    for cluster in static:
        _, uc, vc, r = cluster[0]
        in_model = _ring_colour(background, uc, vc, r)
        in_frames = np.mean(
            [_ring_colour(frames[i], uc, vc, r) for i, *_ in cluster], 0
        )
        if np.linalg.norm(in_model - body) >= np.linalg.norm(in_frames - body):
            continue  # the frames hold the body: a body resting in a few samples
        reach = 1.3 * r + 3.0
        u0, u1 = max(int(uc - reach), 0), min(int(uc + reach) + 2, w)
        v0, v1 = max(int(vc - reach), 0), min(int(vc + reach) + 2, h)
        patches = np.stack([frames[i][v0:v1, u0:u1] for i, *_ in cluster])
        uu = np.arange(u0, u1)[None, :] - uc
        vv = np.arange(v0, v1)[:, None] - vc
        disc = uu * uu + vv * vv <= reach * reach
        region = out[v0:v1, u0:u1]
        region[disc] = np.median(patches, axis=0).astype(np.uint8)[disc]
    return out


def flickers(frames: list[np.ndarray], background: np.ndarray) -> bool:
    """Whether the overall brightness of the frames varies by more than 0.5 %."""
    gains = [brightness_gain(f, background) for f in frames]
    return bool(gains) and (max(gains) - min(gains)) > 0.005
