"""The three-point solve: two impacts and a tree strike fix a trajectory (§3.3.2).

At Tornado Mountain the thesis found the launch angle of 21 flights from "three points
on the parabolic path": the launch impact, a scar on a tree (its height above the ground
and its distance from the launch) and the arrival impact. A drag-free path through the
launch point ``(x1, z1)`` is (eq. 3.4)

    z(x) = z1 + tan(alpha) (x - x1) - g (x - x1)^2 / (2 V0^2 cos^2 alpha),

with two unknowns, ``V0`` and ``alpha``; the tree strike ``(xt, zt)`` and the arrival
``(x2, z2)`` give two linear equations in ``b = tan(alpha)`` and
``c = g / (2 V0^2 cos^2 alpha)``. With ``s_t`` and ``s_2`` the slopes of the straight
lines from the launch to the tree strike and to the arrival,

    c = (s_t - s_2) / (x2 - xt),    b = s_t + c (xt - x1),

and ``c > 0`` (a path that curves downward, as gravity requires) exactly when the tree
strike lies above the chord from launch to arrival: its height above the chord is
``h = c (xt - x1)(x2 - xt)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.errors import PhysicsError
from fieldkit.physics._validate import (
    as_output,
    check_gravity,
    first_values,
    raise_at_first,
    where_first,
)
from fieldkit.physics.constants import G
from fieldkit.physics.flight import Flight, _flight

__all__ = ["solve_three_point", "tree_height_above_chord"]


def tree_height_above_chord(
    x1_m: ArrayLike,
    z1_m: ArrayLike,
    x2_m: ArrayLike,
    z2_m: ArrayLike,
    xt_m: ArrayLike,
    zt_m: ArrayLike,
) -> np.ndarray:
    """Vertical height of the tree strike above the chord between the two impacts [m].

    A downward-curving (ballistic) path passes through the three points only if this is
    positive. Never raises.

    Examples
    --------
    >>> float(tree_height_above_chord(0.0, 0.0, 10.0, -5.0, 4.0, 1.0))
    3.0
    """
    x1, z1, x2, z2, xt, zt = (
        np.asarray(a, float) for a in (x1_m, z1_m, x2_m, z2_m, xt_m, zt_m)
    )
    chord_z = z1 + (z2 - z1) * (xt - x1) / (x2 - x1)
    out = zt - chord_z
    return as_output(out)


def solve_three_point(
    x1_m: ArrayLike,
    z1_m: ArrayLike,
    x2_m: ArrayLike,
    z2_m: ArrayLike,
    xt_m: ArrayLike,
    zt_m: ArrayLike,
    g: float = G,
) -> Flight:
    """The unique ballistic flight through launch, tree strike and arrival (§3.3.2).

    Solves eq. 3.4 through the three points exactly (see the module docstring), then
    builds the whole :class:`~fieldkit.physics.flight.Flight` (eqs. 3.1-3.12).

    Parameters
    ----------
    x1_m, z1_m
        Launch impact in the section plane [m].
    x2_m, z2_m
        Arrival impact [m].
    xt_m, zt_m
        Tree strike: horizontal position and elevation of the scar (ground elevation
        at the tree plus strike height) [m].
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    Flight
        With ``v0_mps`` and ``alpha_deg`` of the launch; ``theta0_deg`` is the launch
        angle to the chord (eq. 3.6) — use ``alpha_deg + psi`` for another ground dip.

    Raises
    ------
    PhysicsError
        The points are not ordered ``x1 < xt < x2``, or the tree strike lies on or
        below the chord between the impacts (no downward-opening parabola passes
        through the three points; the message gives its height above the chord).

    Examples
    --------
    A strike 3 m above the chord, 4 m along a 10 m flight that drops 5 m:

    >>> f = solve_three_point(0.0, 0.0, 10.0, -5.0, 4.0, 1.0)
    >>> round(float(f.v0_mps), 3), round(float(f.alpha_deg), 3)
    (7.83, 36.87)
    >>> round(float(f.z_at(4.0)), 9)
    1.0
    """
    check_gravity(g)
    x1, z1, x2, z2, xt, zt = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (x1_m, z1_m, x2_m, z2_m, xt_m, zt_m))
    )
    raise_at_first(
        x2 <= x1,
        lambda a, b: (
            f"the arrival impact (x = {b:.2f} m) is not beyond the launch "
            f"impact (x = {a:.2f} m): impacts must be ordered along the direction of "
            "travel"
        ),
        x1,
        x2,
        error=PhysicsError,
    )
    raise_at_first(
        (xt <= x1) | (xt >= x2),
        lambda t, a, b: (
            f"the tree strike (x = {t:.2f} m) is not between the launch "
            f"(x = {a:.2f} m) and the arrival (x = {b:.2f} m) impacts"
        ),
        xt,
        x1,
        x2,
        error=PhysicsError,
    )
    ut = xt - x1
    u2 = x2 - x1
    slope_tree = (zt - z1) / ut
    slope_arrival = (z2 - z1) / u2
    height = ut * (slope_tree - slope_arrival)  # tree strike above the chord
    flat = np.asarray(height <= 0)
    if flat.any():
        (h,) = first_values(flat, height)
        side = "on" if h == 0 else f"{-h:.2f} m below"
        raise PhysicsError(
            f"the tree strike is {side} the straight line between the two impacts "
            f"(height above that chord {h:.2f} m): no downward-curving ballistic path "
            "passes through the three points",
            where=where_first(flat),
        )
    curvature = (slope_tree - slope_arrival) / (x2 - xt)  # c = g / (2 vx^2)
    tan_alpha = slope_tree + curvature * ut
    vx = np.sqrt(g / (2.0 * curvature))
    v0 = vx * np.hypot(1.0, tan_alpha)
    alpha_deg = np.degrees(np.arctan(tan_alpha))
    return _flight(v0, alpha_deg, u2, z2 - z1, g)
