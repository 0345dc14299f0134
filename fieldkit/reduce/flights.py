"""Solve every flight of a surveyed path (thesis §7.1, eqs. 3.4-3.6).

A flight joins two successive points of the section. Its parabola needs one more fact
than the two end points; in order of preference:

``tree``
    a tree strike between the two impacts: the three-point solve fixes the parabola
    exactly (§3.3.2, :func:`fieldkit.physics.three_point.solve_three_point`);
``given``
    a restitution angle to the ground measured for that point (e.g. Ehime
    accelerometers), ``alpha = theta0 - psi`` (eq. 3.6);
``assumed``
    the ``theta0_deg`` of the reduction (thesis: the 33° mean of the tree-defined
    flights at Tornado Mountain) with ``alpha = theta0 - psi``. The flight that leaves
    the source is a rock detaching from a cliff, not a rebound, so there "assumed"
    means the least-speed launch that reaches the first impact (eq. 3.5 minimised over
    alpha: ``alpha = 45° + beta/2`` with ``beta`` the elevation angle of the chord) --
    the rock leaves with as little energy as the geometry allows.

Launch speed and velocities then follow from eq. 3.5 through the two impacts
(:func:`fieldkit.physics.flight.flight_between`). A flight the geometry does not allow
(a tree strike no downward parabola reaches; under the assumed or given theta0 the next
point lies above the launch line, common on steep ground with half a metre of GNSS
error) is kept as an *unsolved* flight with its reason (:attr:`SolvedFlight.unsolved`):
its launch and arrival velocities are unknown and the rest of the path is solved as
usual. Only a path none of whose flights can be solved raises
:class:`~fieldkit.errors.PhysicsError` (the first flight's reason, naming the file and
the point or row).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from fieldkit.errors import ArgumentError, FieldkitError, PhysicsError
from fieldkit.physics.flight import Flight, flight_between
from fieldkit.physics.three_point import solve_three_point
from fieldkit.survey import TreeStrike


@dataclass(frozen=True)
class SolvedFlight:
    """One solved flight from point ``launch`` to point ``arrival``.

    ``theta0_deg`` is the launch angle to the ground at the launch point (eq. 3.6),
    NaN when that ground slope is unknown (the source). An *unsolved* flight (no
    parabola through its end points meets its condition) has ``flight`` None, NaN
    angles, ``theta0_source`` None and ``unsolved`` the one-line reason (without the
    file name; ``unsolved_error`` is the full error, file and point or row included).
    """

    launch: str
    arrival: str
    alpha_deg: float
    theta0_deg: float
    theta0_source: str | None
    flight: Flight | None
    tree: TreeStrike | None
    unsolved: str | None = None
    unsolved_error: FieldkitError | None = None


def _unsolved(
    launch: str, arrival: str, tree: TreeStrike | None, error: FieldkitError
) -> SolvedFlight:
    where = error.where
    if where and tree is not None:
        where = f"tree {where}"  # a row of the tree file, not of the points
    reason = f"{where}: {error.message}" if where else error.message
    return SolvedFlight(
        launch, arrival, math.nan, math.nan, None, None, tree, reason, error
    )


def least_speed_launch_angle_deg(dx_m: float, dz_m: float) -> float:
    """Launch angle of the slowest ballistic path to ``(dx, dz)`` [deg].

    ``alpha = 45° + beta/2`` with ``beta = atan2(dz, dx)`` the elevation of the chord
    (minimum of eq. 3.5 over alpha); the speed is ``V0^2 = g (L + dz)``.

    Examples
    --------
    >>> least_speed_launch_angle_deg(10.0, 0.0)
    45.0
    >>> round(least_speed_launch_angle_deg(8.0, -34.0), 2)
    6.62
    """
    return 45.0 + 0.5 * math.degrees(math.atan2(dz_m, dx_m))


def solve_flights(
    points: Sequence[str],
    x_m: np.ndarray,
    z_m: np.ndarray,
    slope_deg: np.ndarray,
    *,
    theta0_deg: float | None,
    given_theta0_deg: np.ndarray | None = None,
    trees: Mapping[str, TreeStrike] | None = None,
    points_source: str | None = None,
    trees_source: str | None = None,
) -> list[SolvedFlight]:
    """Solve the ``n - 1`` flights between ``n`` successive points.

    Parameters
    ----------
    points
        Point names in order along the path (first = source, last = stopped).
    x_m, z_m
        Section coordinates [m].
    slope_deg
        Ground dip psi at each point [deg] (NaN where unknown, e.g. the source).
    theta0_deg
        Assumed restitution angle to the ground [deg] for flights with neither a tree
        nor a given angle; None means every such flight is an error.
    given_theta0_deg
        Per-point measured restitution angle [deg] (NaN where not given).
    trees
        Tree strikes by launch point name.
    points_source, trees_source
        File names for error messages.

    Returns
    -------
    list of SolvedFlight
        ``n - 1`` flights, in order. A flight no ballistic path makes (reason
        ``"point 7: flight from point 6 to point 7 ..."``) or whose tree strike no
        parabola reaches (``"tree row 4: tree strike ..."``) is unsolved
        (:attr:`SolvedFlight.unsolved`).

    Raises
    ------
    PhysicsError
        Every flight unsolved: the first one's reason, with the file (``"<points
        file>: point 7: ..."`` or ``"<tree file>: row 4: ..."``).
    PhysicsError, InputFileError
        A tree strike after the last point or after a point not on the path.
    ArgumentError
        A flight with no way to fix its parabola (no tree, no angle, no ``theta0_deg``).

    Examples
    --------
    Section 3.3.1: the second flight reaches (14, -8) from a 30° slope with
    theta0 = 15°; the first (from the source) is the least-speed launch.

    >>> import numpy as np
    >>> x, z = np.array([0.0, 10.0, 24.0]), np.array([6.0, 0.0, -8.0])
    >>> f = solve_flights(["0", "1", "2"], x, z, np.array([np.nan, 30.0, 29.7]),
    ...                   theta0_deg=15.0)
    >>> round(float(f[1].flight.v0_mps), 2), f[1].theta0_source
    (15.57, 'assumed')
    """
    trees = trees or {}
    n = len(points)
    given = np.full(n, np.nan) if given_theta0_deg is None else given_theta0_deg
    out: list[SolvedFlight] = []
    for j in range(n - 1):
        launch, arrival = str(points[j]), str(points[j + 1])
        dx, dz = float(x_m[j + 1] - x_m[j]), float(z_m[j + 1] - z_m[j])
        psi = float(slope_deg[j])
        tree = trees.get(launch)
        if tree is not None:
            try:
                flight = _tree_flight(tree, x_m, z_m, j, launch, arrival, trees_source)
            except PhysicsError as error:
                out.append(_unsolved(launch, arrival, tree, error))
                continue
            alpha = float(flight.alpha_deg)
            out.append(
                SolvedFlight(launch, arrival, alpha, alpha + psi, "tree", flight, tree)
            )
            continue
        if math.isfinite(given[j]) and math.isfinite(psi):
            theta0, source = float(given[j]), "given"
            alpha = theta0 - psi
        elif j == 0:
            alpha = least_speed_launch_angle_deg(dx, dz)
            theta0, source = alpha + psi, "assumed"
        elif theta0_deg is not None and math.isfinite(psi):
            theta0, source = float(theta0_deg), "assumed"
            alpha = theta0 - psi
        else:
            raise ArgumentError(
                f"the flight from point {launch} to point {arrival} has no tree strike "
                "and no restitution angle: give `theta0_deg` (the thesis assumes "
                "32.6°)",
                source=points_source,
                where=f"point {launch}",
            )
        try:
            flight = flight_between(dx, dz, alpha)
        except FieldkitError as exc:
            error = PhysicsError(
                f"flight from point {launch} to point {arrival} "
                f"({dx:.2f} m along, {dz:+.2f} m up) with theta0 {theta0:.1f}° "
                f"({source}) on a {psi:.1f}° slope: {exc.message}",
                source=points_source,
                where=f"point {arrival}",
            )
            out.append(_unsolved(launch, arrival, None, error))
            continue
        out.append(SolvedFlight(launch, arrival, alpha, theta0, source, flight, None))
    unused = set(trees) - {str(p) for p in points[:-1]}
    if unused:
        tree = trees[sorted(unused)[0]]
        raise PhysicsError(
            f"tree strike after point {tree.after_impact}, which starts no flight "
            "(it is the last point or not on this path)",
            source=trees_source,
            where=tree.where,
        )
    if out and all(f.unsolved for f in out):
        raise out[0].unsolved_error
    return out


def _tree_flight(
    tree: TreeStrike,
    x_m: np.ndarray,
    z_m: np.ndarray,
    j: int,
    launch: str,
    arrival: str,
    trees_source: str | None,
) -> Flight:
    x1, z1, x2, z2 = (float(v) for v in (x_m[j], z_m[j], x_m[j + 1], z_m[j + 1]))
    xt = x1 + tree.distance_m
    zt = tree.z_m
    try:
        return solve_three_point(x1, z1, x2, z2, xt, zt)
    except FieldkitError as exc:
        raise PhysicsError(
            f"tree strike {tree.height_m:.2f} m high, {tree.distance_m:.2f} m after "
            f"point {launch}: no parabola through points {launch} and {arrival} "
            f"reaches it ({exc.message})",
            source=trees_source,
            where=tree.where,
        ) from None
