"""Frame vs background: colour difference and overall brightness (lamp flicker).

Small image operations shared by the detector and the background model.
"""

from __future__ import annotations

import cv2
import numpy as np


def colour_difference(frame: np.ndarray, background: np.ndarray) -> np.ndarray:
    """Largest per-channel absolute difference (uint8, one channel)."""
    diff = cv2.absdiff(frame, background)
    if diff.ndim == 2:
        return diff
    b, g, r = cv2.split(diff)
    return cv2.max(cv2.max(b, g), r)


def brightness_gain(frame: np.ndarray, background: np.ndarray, step: int = 20) -> float:
    """Overall brightness of ``frame`` relative to ``background`` (lighting flicker).

    Median ratio of the two on a sparse grid of pixels (every ``step``-th row and
    column, background brighter than 30 grey levels); a small moving body does not
    move the median.

    Examples
    --------
    >>> bg = np.full((200, 200, 3), 100, np.uint8)
    >>> brightness_gain((bg * 1.1).astype(np.uint8), bg)
    1.1
    """
    grid = (slice(step // 2, None, step), slice(step // 2, None, step))
    b = background[grid].astype(np.float32)
    f = frame[grid].astype(np.float32)
    if b.ndim == 3:
        b, f = b.mean(axis=2), f.mean(axis=2)
    ok = b > 30.0
    if ok.sum() < 10:
        return 1.0
    return round(float(np.median(f[ok] / b[ok])), 4)


def scaled(image: np.ndarray, gain: float) -> np.ndarray:
    """``image`` times ``gain`` (saturating uint8); unchanged when the gain is ~1."""
    return image if abs(gain - 1.0) < 0.004 else cv2.convertScaleAbs(image, alpha=gain)


def shadow_mask(
    frame: np.ndarray,
    background: np.ndarray,
    *,
    darkening: tuple[float, float] = (0.4, 0.95),
    chroma_tolerance: float = 0.1,
    noise: float = 3.0,
) -> np.ndarray:
    """Pixels that look like the background in shadow (bool, one channel).

    ``frame`` and ``background`` are BGR images (or BGR pixel lists, shape (n, 3)).

    The test of Prati, Cucchiara et al. (IEEE PAMI 25, 2003), as in OpenCV's MOG2
    shadow label: a cast shadow dims the scene by a factor within ``darkening`` and
    keeps its chromaticity, so every channel is dimmed by the same factor. A pixel is
    shadow when its brightness ratio to the background lies in ``darkening`` and its
    channel ratios differ from one another by less than ``chroma_tolerance`` (relative
    to their mean) plus what ``noise`` [grey levels] allows on a dark background.

    Examples
    --------
    >>> bg = np.full((1, 3, 3), (60, 120, 180), np.uint8)
    >>> f = bg.copy()
    >>> f[0, 0] = (36, 72, 108)      # dimmed to 60 %: shadow
    >>> f[0, 1] = (40, 40, 40)       # grey body: another chromaticity
    >>> shadow_mask(f, bg)[0].tolist()
    [True, False, False]
    """
    f = frame.astype(np.float32) + 0.5
    b = background.astype(np.float32) + 0.5
    b_sum = b.sum(axis=-1)
    brightness = f.sum(axis=-1) / b_sum
    ratios = f / b
    spread = ratios.max(axis=-1) - ratios.min(axis=-1)
    allowed = chroma_tolerance * brightness + 2.0 * noise / b.min(axis=-1)
    return (
        (brightness >= darkening[0])
        & (brightness <= darkening[1])
        & (spread <= allowed)
        & (b_sum > 90.0)  # too dark a scene to tell a shadow
    )
