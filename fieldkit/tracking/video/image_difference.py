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
