"""Drawing world-space curves (metres, z up) onto video frames (pixels).

A tracked video carries, for every detected sample, both the image position
(``u_px``, ``v_px``) and the world position (``x_m``, ``z_m``). The plane-to-image
mapping of a calibrated camera is a homography, so it can be recovered from the track
itself (direct linear transform, least squares) and used to draw fitted flights over a
frame without knowing how the track was calibrated.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def world_to_image(frame: pd.DataFrame) -> np.ndarray | None:
    """Homography ``(x, z) -> (u, v)`` fitted to a track's samples, or None.

    Needs columns ``x_m, z_m, u_px, v_px`` with at least 4 samples not on a line.

    Examples
    --------
    >>> f = pd.DataFrame({"x_m": [0, 1, 0, 1.0], "z_m": [0, 0, 1, 1.0]})
    >>> f["u_px"], f["v_px"] = 100 + 50 * f.x_m, 400 - 50 * f.z_m
    >>> project(world_to_image(f), [0.5], [0.5]).round(6).tolist()
    [[125.0, 375.0]]
    """
    if not {"u_px", "v_px", "x_m", "z_m"} <= set(frame.columns):
        return None
    d = frame[["x_m", "z_m", "u_px", "v_px"]].dropna().to_numpy(float)
    if len(d) < 4 or np.ptp(d[:, 0]) == 0 or np.ptp(d[:, 1]) == 0:
        return None
    x, z, u, v = d.T
    one, zero = np.ones_like(x), np.zeros_like(x)
    a = np.vstack(
        [
            np.column_stack([x, z, one, zero, zero, zero, -u * x, -u * z]),
            np.column_stack([zero, zero, zero, x, z, one, -v * x, -v * z]),
        ]
    )
    coef, *_ = np.linalg.lstsq(a, np.concatenate([u, v]), rcond=None)
    return np.append(coef, 1.0).reshape(3, 3)


def project(homography: np.ndarray, x_m, z_m) -> np.ndarray:
    """Image points ``(n, 2)`` [px] of world points ``(x, z)`` [m]."""
    x = np.atleast_1d(np.asarray(x_m, float))
    z = np.atleast_1d(np.asarray(z_m, float))
    p = homography @ np.vstack([x, z, np.ones_like(x)])
    return (p[:2] / p[2]).T
