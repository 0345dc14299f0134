"""Height of a ballistic flight above a straight slope (thesis eqs. 3.9-3.12).

The slope through the launch point is ``z = kappa x`` with gradient
``kappa = -tan(psi)`` (eq. 3.7), ``psi`` positive when the ground descends toward +x.
The launch angle ``alpha`` is above the horizontal; ``theta0 = alpha + psi`` (eq. 3.6).
:func:`fieldkit.physics.flight.flight_between` applies these with the chord between two
impacts as the slope. Pure, vectorised; scalars come back as numpy scalars.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics._validate import (
    as_output,
    check_forward_angle,
    check_gravity,
    check_into_slope,
    check_nonnegative,
    check_positive,
)
from fieldkit.physics.constants import G

__all__ = ["max_normal_height", "max_vertical_height", "vertical_height_above_slope"]


def _launch_parabola(
    v0_mps: ArrayLike, alpha_deg: ArrayLike, g: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Checked launch angle [deg] and the parabola coefficients of eq. 3.9.

    Returns ``alpha_deg``, ``a = -g / (2 V0^2 cos^2 alpha)`` and ``b = tan(alpha)``.
    """
    check_gravity(g)
    v0 = np.asarray(v0_mps, float)
    check_positive(v0, "v0_mps", "m/s")
    alpha_d = np.asarray(alpha_deg, float)
    check_forward_angle(alpha_d)
    alpha = np.radians(alpha_d)
    return alpha_d, -g / (2.0 * (v0 * np.cos(alpha)) ** 2), np.tan(alpha)


def vertical_height_above_slope(
    x_m: ArrayLike,
    v0_mps: ArrayLike,
    alpha_deg: ArrayLike,
    slope_deg: ArrayLike,
    g: float = G,
) -> np.ndarray:
    """Vertical height of the rock above a straight slope through the launch (eq. 3.9).

    ``h = a x^2 + (b - kappa) x`` with ``a = -g / (2 V0^2 cos^2 alpha)``,
    ``b = tan(alpha)`` and slope gradient ``kappa = -tan(psi)`` (eq. 3.7).

    Parameters
    ----------
    x_m
        Horizontal distance from the launch point [m].
    v0_mps, alpha_deg
        Launch speed [m/s] (> 0) and angle above the horizontal [deg].
    slope_deg
        Dip psi of the slope [deg], positive descending toward +x.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    h_m
        Height of the trajectory above the slope, measured vertically [m].

    Examples
    --------
    >>> round(float(vertical_height_above_slope(5.0, 10.0, 0.0, 45.0, g=10.0)), 9)
    3.75
    """
    _, a, b = _launch_parabola(v0_mps, alpha_deg, g)
    x = np.asarray(x_m, float)
    kappa = -np.tan(np.radians(np.asarray(slope_deg, float)))
    return as_output(a * x**2 + (b - kappa) * x)


def max_vertical_height(
    v0_mps: ArrayLike, alpha_deg: ArrayLike, slope_deg: ArrayLike, g: float = G
) -> tuple[np.ndarray, np.ndarray]:
    """Greatest vertical height above the slope, and where it occurs (eqs. 3.10, 3.11).

    ``x_hmax = -(b - kappa) / (2 a)`` and ``hmax = -(b - kappa)^2 / (4 a)`` with ``a``,
    ``b``, ``kappa`` as in :func:`vertical_height_above_slope`; equivalently
    ``hmax = (V0 sin theta0)^2 / (2 g cos^2 psi)``.

    Parameters
    ----------
    v0_mps, alpha_deg
        Launch speed [m/s] (> 0) and angle above the horizontal [deg].
    slope_deg
        Dip psi of the slope [deg], positive descending toward +x.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    x_hmax_m, hmax_m
        Horizontal distance from launch of the highest point above the slope, and that
        vertical height [m].

    Raises
    ------
    PhysicsError
        The rock is launched into or along the slope (``theta0 = alpha + psi <= 0``).

    Examples
    --------
    Worked example 3B, unrounded (the thesis prints 14.0 m and 3.39 m from a rounded
    parabola):

    >>> x, h = max_vertical_height(18.0, -20.0, 40.0)
    >>> round(float(x), 2), round(float(h), 2)
    (13.86, 3.29)
    """
    alpha_d, a, b = _launch_parabola(v0_mps, alpha_deg, g)
    psi_d = np.asarray(slope_deg, float)
    check_into_slope(alpha_d + psi_d, psi_d)
    rise = b + np.tan(np.radians(psi_d))  # b - kappa
    return as_output(-rise / (2.0 * a)), as_output(-(rise**2) / (4.0 * a))


def max_normal_height(
    v0_mps: ArrayLike, theta0_deg: ArrayLike, slope_deg: ArrayLike, g: float = G
) -> np.ndarray:
    """Greatest height above the slope measured normal to it (eq. 3.12).

    ``h' = (V0 sin theta0)^2 / (2 g cos psi)``, i.e. the vertical maximum of eq. 3.11
    times ``cos psi``.

    Parameters
    ----------
    v0_mps
        Launch speed [m/s], >= 0.
    theta0_deg
        Angle of the launch velocity to the slope [deg] (eq. 3.6).
    slope_deg
        Dip psi of the slope [deg], between -90° and 90°.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    h_normal_m
        Maximum trajectory height normal to the slope [m].

    Examples
    --------
    Worked example 3B (thesis: 2.52 m):

    >>> round(float(max_normal_height(18.0, 20.0, 40.0)), 2)
    2.52
    """
    check_gravity(g)
    v0 = np.asarray(v0_mps, float)
    check_nonnegative(v0, "v0_mps", "m/s")
    theta0 = np.asarray(theta0_deg, float)
    psi = np.asarray(slope_deg, float)
    check_into_slope(theta0, psi)
    return as_output(
        (v0 * np.sin(np.radians(theta0))) ** 2 / (2.0 * g * np.cos(np.radians(psi)))
    )
