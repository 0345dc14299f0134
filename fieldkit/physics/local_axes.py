"""Section frame (x, z) <-> local impact axes (T, N) at a slope of dip psi.

T runs along the ground down-slope (direction of travel); N is the outward normal.
With psi positive when the ground descends toward +x (docs/architecture.md §2):

    T = ( cos psi, -sin psi),   N = ( sin psi, cos psi)

so an impact has ``v_N < 0`` and a rebound ``v_N > 0``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike


def to_local(
    vx: ArrayLike, vz: ArrayLike, slope_deg: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """Resolve a section-frame velocity into tangential and normal components.

    Parameters
    ----------
    vx, vz
        Horizontal (along travel) and vertical velocity [m/s].
    slope_deg
        Ground dip psi [deg], positive descending toward +x.

    Returns
    -------
    v_t, v_n
        Components along T (down-slope) and N (outward normal) [m/s].

    Examples
    --------
    >>> [float(v) for v in to_local(0.0, -10.0, 0.0)]
    [0.0, -10.0]
    """
    psi = np.radians(np.asarray(slope_deg, dtype=float))
    vx = np.asarray(vx, dtype=float)
    vz = np.asarray(vz, dtype=float)
    v_t = vx * np.cos(psi) - vz * np.sin(psi)
    v_n = vx * np.sin(psi) + vz * np.cos(psi)
    return v_t, v_n


def to_section(
    v_t: ArrayLike, v_n: ArrayLike, slope_deg: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`to_local`: local (T, N) components back to (vx, vz) [m/s]."""
    psi = np.radians(np.asarray(slope_deg, dtype=float))
    v_t = np.asarray(v_t, dtype=float)
    v_n = np.asarray(v_n, dtype=float)
    vx = v_t * np.cos(psi) + v_n * np.sin(psi)
    vz = -v_t * np.sin(psi) + v_n * np.cos(psi)
    return vx, vz


def angle_to_ground_deg(v_t: ArrayLike, v_n: ArrayLike) -> np.ndarray:
    """Angle between a velocity and the ground [deg], always in [0, 180].

    For an impact (``v_n < 0``) this is ``theta_i = atan(-v_n/v_t)``; for a rebound
    (``v_n > 0``) ``theta_f = atan(v_n/v_t)`` (docs/architecture.md §2). Angles above 90
    deg mean motion up-slope (``v_t < 0``).
    """
    return np.degrees(
        np.arctan2(np.abs(np.asarray(v_n, float)), np.asarray(v_t, float))
    )
