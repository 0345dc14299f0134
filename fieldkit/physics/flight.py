"""Ballistic flight of a rock between impacts (thesis ch. 3, eqs. 3.1-3.12).

Drag-free flight in the section plane: ``a_x = 0``, ``a_z = -g``. Positions are
relative to the launch point, ``x`` along travel, ``z`` up (docs/architecture.md §2).
The launch angle ``alpha`` is measured above the horizontal in the direction of travel;
the restitution angle ``theta0`` is measured from the ground of dip ``psi`` (positive
when the ground descends toward +x), related by ``alpha = theta0 - psi`` (eq. 3.6).

All functions are pure and broadcast their arguments like numpy. NaN inputs propagate
(missing data); only definite violations raise. Scalars come back as numpy scalars.
Errors raised from array inputs name the first offending element in ``where``.
The flight heights of eqs. 3.9-3.12 live in :mod:`fieldkit.physics.flight_heights` and
are re-exported here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.errors import ArgumentError, PhysicsError
from fieldkit.physics._validate import (
    as_output,
    check_forward_angle,
    check_gravity,
    check_into_slope,
    check_nonnegative,
    check_positive,
    first_values,
    raise_at_first,
    where_first,
)
from fieldkit.physics.constants import G
from fieldkit.physics.flight_heights import (
    max_normal_height,
    max_vertical_height,
    vertical_height_above_slope,
)

__all__ = [
    "Flight",
    "FlightSamples",
    "ballistic_reachable",
    "flight_between",
    "flight_samples",
    "launch_angle",
    "launch_speed",
    "max_normal_height",
    "max_vertical_height",
    "next_impact_on_slope",
    "restitution_angle",
    "trajectory_position",
    "trajectory_velocity",
    "vertical_height_above_slope",
]


# ------------------------------------------------------------------ eqs. 3.1 - 3.6
def trajectory_position(
    v0_mps: ArrayLike, alpha_deg: ArrayLike, t_s: ArrayLike, g: float = G
) -> tuple[np.ndarray, np.ndarray]:
    """Position of the rock ``t`` seconds after launch (eqs. 3.1, 3.2).

    ``x = V0 cos(alpha) t``, ``z = V0 sin(alpha) t - g t^2 / 2``, relative to launch.

    Parameters
    ----------
    v0_mps
        Launch speed V0 [m/s], >= 0.
    alpha_deg
        Launch angle above the horizontal in the direction of travel [deg]. Any angle
        is accepted (the thesis notes that -30° and 330° are the same direction).
    t_s
        Time since launch [s].
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    x_m, z_m
        Horizontal and vertical position relative to the launch point [m].

    Raises
    ------
    ArgumentError
        Negative launch speed or non-positive ``g``.

    Examples
    --------
    Worked example 3A with the thesis's rounded components (V0x = 16.4, V0z = 11.5):

    >>> v0, alpha = np.hypot(16.4, 11.5), np.degrees(np.arctan2(11.5, 16.4))
    >>> x, z = trajectory_position(v0, alpha, [2.0, 4.0])
    >>> np.round(z, 2).tolist(), round(float(x[1]), 1)
    ([3.38, -32.48], 65.6)
    """
    check_gravity(g)
    v0 = np.asarray(v0_mps, float)
    check_nonnegative(v0, "v0_mps", "m/s")
    alpha = np.radians(np.asarray(alpha_deg, float))
    t = np.asarray(t_s, float)
    x = v0 * np.cos(alpha) * t
    z = v0 * np.sin(alpha) * t - 0.5 * g * t**2
    return as_output(x), as_output(z)


def trajectory_velocity(
    v0_mps: ArrayLike, alpha_deg: ArrayLike, t_s: ArrayLike, g: float = G
) -> tuple[np.ndarray, np.ndarray]:
    """Velocity of the rock ``t`` seconds after launch (eqs. 3.1, 3.3).

    ``Vx = V0 cos(alpha)`` (constant), ``Vz = V0 sin(alpha) - g t``.

    Parameters
    ----------
    v0_mps
        Launch speed V0 [m/s], >= 0.
    alpha_deg
        Launch angle above the horizontal in the direction of travel [deg].
    t_s
        Time since launch [s].
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    vx_mps, vz_mps
        Horizontal and vertical velocity [m/s] (``vz < 0`` descending).

    Examples
    --------
    >>> vx, vz = trajectory_velocity(20.0, 90.0, 1.0, g=10.0)
    >>> round(float(vx), 9), float(vz)
    (0.0, 10.0)
    """
    check_gravity(g)
    v0 = np.asarray(v0_mps, float)
    check_nonnegative(v0, "v0_mps", "m/s")
    alpha = np.radians(np.asarray(alpha_deg, float))
    t = np.asarray(t_s, float)
    vx = v0 * np.cos(alpha) * np.ones_like(t)
    vz = v0 * np.sin(alpha) - g * t
    return as_output(vx), as_output(vz)


class FlightSamples(NamedTuple):
    """A flight sampled in time (:func:`flight_samples`); section-frame values."""

    t_s: np.ndarray
    x_m: np.ndarray
    z_m: np.ndarray
    vx_mps: np.ndarray
    vz_mps: np.ndarray

    @property
    def speed_mps(self) -> np.ndarray:
        """Speed at each sample [m/s]."""
        return np.hypot(self.vx_mps, self.vz_mps)


def flight_samples(
    x0_m: ArrayLike,
    z0_m: ArrayLike,
    vx_mps: ArrayLike,
    vz_mps: ArrayLike,
    duration_s: ArrayLike,
    n_samples: int = 51,
    g: float = G,
) -> FlightSamples:
    """Positions and velocities along a flight from its launch state (eqs. 3.1-3.3).

    ``n_samples`` instants equally spaced from launch (``t = 0``) to ``duration_s``:
    ``x = x0 + vx t``, ``z = z0 + vz t - g t^2 / 2``, velocity ``(vx, vz - g t)``.
    Unlike :func:`trajectory_position` the launch is given by its section-frame
    position and velocity components (an ImpactTable's ``x_m``, ``z_m``,
    ``vf_x_mps``, ``vf_z_mps`` and ``flight_time_s``), and positions are absolute.

    Parameters
    ----------
    x0_m, z0_m
        Launch point [m].
    vx_mps, vz_mps
        Launch velocity [m/s] (``vz > 0`` rising).
    duration_s
        Flight time [s], >= 0 (NaN gives NaN samples).
    n_samples
        Number of instants, >= 2.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    FlightSamples
        ``t_s``, ``x_m``, ``z_m``, ``vx_mps``, ``vz_mps`` (and ``speed_mps``); the
        arguments broadcast together, the samples run along a new last axis.

    Examples
    --------
    >>> s = flight_samples(0.0, 10.0, 3.0, 4.0, 1.0, n_samples=3, g=10.0)
    >>> s.x_m.tolist(), s.z_m.tolist(), s.vz_mps.tolist()
    ([0.0, 1.5, 3.0], [10.0, 10.75, 9.0], [4.0, -1.0, -6.0])
    >>> s.speed_mps.tolist()
    [5.0, 3.1622776601683795, 6.708203932499369]
    """
    check_gravity(g)
    if int(n_samples) < 2:
        raise ArgumentError(
            f"n_samples must be at least 2, got {n_samples}", source="n_samples"
        )
    duration = np.asarray(duration_s, float)
    check_nonnegative(duration, "duration_s", "s")
    t = np.linspace(0.0, duration, int(n_samples), axis=-1)
    x0, z0, vx, vz = (
        np.asarray(a, float)[..., np.newaxis] for a in (x0_m, z0_m, vx_mps, vz_mps)
    )
    return FlightSamples(
        t_s=t,
        x_m=x0 + vx * t,
        z_m=z0 + vz * t - 0.5 * g * t**2,
        vx_mps=vx * np.ones_like(t),
        vz_mps=vz - g * t,
    )


def launch_angle(theta0_deg: ArrayLike, slope_deg: ArrayLike) -> np.ndarray:
    """Launch angle above the horizontal from the angle to the ground (eq. 3.6).

    ``alpha = theta0 - psi`` with ``psi`` the ground dip, positive descending toward +x.

    Examples
    --------
    Worked example 3B: theta0 = 20° on a 40° slope leaves 20° below the horizontal.

    >>> float(launch_angle(20.0, 40.0))
    -20.0
    """
    return as_output(np.asarray(theta0_deg, float) - np.asarray(slope_deg, float))


def restitution_angle(alpha_deg: ArrayLike, slope_deg: ArrayLike) -> np.ndarray:
    """Angle of the launch velocity to the ground, ``theta0 = alpha + psi`` (eq. 3.6).

    Examples
    --------
    >>> float(restitution_angle(-15.0, 30.0))
    15.0
    """
    return as_output(np.asarray(alpha_deg, float) + np.asarray(slope_deg, float))


def ballistic_reachable(
    dx_m: ArrayLike, dz_m: ArrayLike, alpha_deg: ArrayLike
) -> np.ndarray:
    """Whether a ballistic path launched at ``alpha`` reaches ``(dx, dz)`` (eq. 3.5).

    True when ``dx > 0``, ``|alpha| < 90°`` and ``dx tan(alpha) - dz > 0``, i.e. the
    target lies below the launch direction. Never raises; NaN gives False.

    Examples
    --------
    >>> ballistic_reachable(10.0, [-3.0, 3.0], 12.0).tolist()
    [True, False]
    """
    dx = np.asarray(dx_m, float)
    dz = np.asarray(dz_m, float)
    alpha = np.asarray(alpha_deg, float)
    with np.errstate(invalid="ignore"):
        ok = (dx > 0) & (np.abs(alpha) < 90) & (dx * np.tan(np.radians(alpha)) - dz > 0)
    return as_output(ok)


def launch_speed(
    dx_m: ArrayLike, dz_m: ArrayLike, alpha_deg: ArrayLike, g: float = G
) -> np.ndarray:
    """Launch speed that carries the rock to a point ``(dx, dz)`` from launch (eq. 3.5).

    ``V0 = dx / (cos(alpha) * sqrt(2 (dx tan(alpha) - dz) / g))``

    Parameters
    ----------
    dx_m, dz_m
        Horizontal (along travel, > 0) and vertical offset of the arrival point from
        the launch point [m].
    alpha_deg
        Launch angle above the horizontal [deg], between -90° and 90°.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    v0_mps
        Launch speed [m/s].

    Raises
    ------
    PhysicsError
        No ballistic path with that launch angle reaches the point: ``dx <= 0`` or
        ``dx tan(alpha) - dz <= 0`` (the point lies on or above the launch direction).
    ArgumentError
        Launch angle outside (-90°, 90°), or non-positive ``g``.

    Examples
    --------
    Section 3.3.1: reaching (14, -8) on a 30° slope with theta0 = 15° and 45°.

    >>> np.round(launch_speed(14.0, -8.0, [15.0 - 30.0, 45.0 - 30.0]), 2).tolist()
    [15.57, 9.36]
    """
    check_gravity(g)
    dx = np.asarray(dx_m, float)
    dz = np.asarray(dz_m, float)
    alpha_d = np.asarray(alpha_deg, float)
    check_forward_angle(alpha_d)
    alpha = np.radians(alpha_d)
    raise_at_first(
        dx <= 0,
        lambda x: (
            f"no ballistic path reaches a point {x:.1f} m along the section: "
            "the arrival must lie beyond the launch (dx > 0)"
        ),
        dx,
        error=PhysicsError,
    )
    drop = dx * np.tan(alpha) - dz  # height of the launch line above the target
    unreachable = np.asarray(drop <= 0)
    if unreachable.any():
        a, x, z = first_values(unreachable, alpha_d, dx, dz)
        if z > 0:
            rise = f"{z:.1f} m higher"
        elif z < 0:
            rise = f"{-z:.1f} m lower"
        else:
            rise = "at the same height"
        raise PhysicsError(
            f"no ballistic path launched at {a:.1f}° reaches a point {rise} at "
            f"{x:.1f} m (it lies on or above the launch direction)",
            where=where_first(unreachable),
        )
    return as_output(dx / (np.cos(alpha) * np.sqrt(2.0 * drop / g)))


# ------------------------------------------------------------------- whole flights
@dataclass(frozen=True)
class Flight:
    """The ballistic flight from a launch point to an arrival point.

    Positions are relative to the launch point; every field is a float or a numpy
    array (all broadcast to one shape). Build one with :func:`flight_between`,
    :func:`next_impact_on_slope` or
    :func:`fieldkit.physics.three_point.solve_three_point`.

    Attributes
    ----------
    v0_mps, alpha_deg
        Launch speed [m/s] and launch angle above the horizontal [deg].
    dx_m, dz_m
        Offset of the arrival point from the launch point [m] (``dz < 0`` downhill).
    time_s
        Flight time [s].
    launch_vx_mps, launch_vz_mps, arrival_vx_mps, arrival_vz_mps
        Velocity components at launch and at arrival [m/s].
    hmax_vertical_m, x_hmax_m
        Greatest vertical height of the path above the straight chord between the two
        points, and its horizontal distance from launch [m] (eqs. 3.9-3.11 with the
        chord as the slope; for a parabola it is always mid-way, ``dx / 2``).
    hmax_normal_m
        Greatest height of the path measured normal to the chord [m] (eq. 3.12).
    g_mps2
        Gravitational acceleration used [m/s^2].
    """

    v0_mps: np.ndarray
    alpha_deg: np.ndarray
    dx_m: np.ndarray
    dz_m: np.ndarray
    time_s: np.ndarray
    launch_vx_mps: np.ndarray
    launch_vz_mps: np.ndarray
    arrival_vx_mps: np.ndarray
    arrival_vz_mps: np.ndarray
    hmax_vertical_m: np.ndarray
    x_hmax_m: np.ndarray
    hmax_normal_m: np.ndarray
    g_mps2: float = G

    @property
    def arrival_speed_mps(self) -> np.ndarray:
        """Speed at arrival [m/s]; ``V_i^2 = V0^2 - 2 g dz`` (energy conservation)."""
        return as_output(np.hypot(self.arrival_vx_mps, self.arrival_vz_mps))

    @property
    def chord_length_m(self) -> np.ndarray:
        """Straight-line distance between launch and arrival [m] (thesis L, ex. 3B)."""
        return as_output(np.hypot(self.dx_m, self.dz_m))

    @property
    def chord_slope_deg(self) -> np.ndarray:
        """Dip psi of the chord [deg], positive descending toward +x."""
        return as_output(np.degrees(np.arctan2(-np.asarray(self.dz_m), self.dx_m)))

    @property
    def theta0_deg(self) -> np.ndarray:
        """Launch angle to the chord, ``theta0 = alpha + psi_chord`` [deg] (eq. 3.6)."""
        return as_output(np.asarray(self.alpha_deg) + self.chord_slope_deg)

    @property
    def arrival_angle_deg(self) -> np.ndarray:
        """Angle of the arrival velocity below the horizontal [deg] (53° in ex. 3B)."""
        return as_output(
            np.degrees(
                np.arctan2(-np.asarray(self.arrival_vz_mps), self.arrival_vx_mps)
            )
        )

    @property
    def arrival_angle_to_chord_deg(self) -> np.ndarray:
        """Angle of the arrival velocity to the chord [deg] (theta_i on that ground)."""
        return as_output(np.asarray(self.arrival_angle_deg) - self.chord_slope_deg)

    def position_at_time(self, t_s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Position relative to launch, ``t`` s after launch [m] (eqs. 3.1, 3.2)."""
        return trajectory_position(self.v0_mps, self.alpha_deg, t_s, g=self.g_mps2)

    def z_at(self, x_m: ArrayLike) -> np.ndarray:
        """Height of the path relative to launch at distance ``x`` (eq. 3.4)."""
        x = np.asarray(x_m, float)
        vx = np.asarray(self.launch_vx_mps)
        return as_output(
            x * self.launch_vz_mps / vx - 0.5 * self.g_mps2 * (x / vx) ** 2
        )

    def height_above_chord_at(self, x_m: ArrayLike) -> np.ndarray:
        """Vertical height of the path above the chord at horizontal ``x`` [m]."""
        x = np.asarray(x_m, float)
        return as_output(self.z_at(x) - x * np.asarray(self.dz_m) / self.dx_m)

    def path(self, n_points: int = 51) -> tuple[np.ndarray, np.ndarray]:
        """``n_points`` positions equally spaced in time from launch to arrival.

        Returns ``(x_m, z_m)`` relative to launch, samples along a new last axis.
        """
        fraction = np.linspace(0.0, 1.0, int(n_points))
        t = np.asarray(self.time_s, float)[..., np.newaxis] * fraction
        v0 = np.asarray(self.v0_mps, float)[..., np.newaxis]
        alpha = np.asarray(self.alpha_deg, float)[..., np.newaxis]
        return trajectory_position(v0, alpha, t, g=self.g_mps2)


def _flight(
    v0: np.ndarray, alpha_deg: np.ndarray, dx: np.ndarray, dz: np.ndarray, g: float
) -> Flight:
    """Assemble a :class:`Flight` from a launch speed, angle and arrival offset."""
    v0, alpha_deg, dx, dz = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (v0, alpha_deg, dx, dz))
    )
    alpha = np.radians(alpha_deg)
    vx = v0 * np.cos(alpha)
    vz = v0 * np.sin(alpha)
    time = dx / vx
    chord_slope = np.degrees(np.arctan2(-dz, dx))
    x_hmax, hmax = max_vertical_height(v0, alpha_deg, chord_slope, g=g)
    return Flight(
        v0_mps=as_output(v0),
        alpha_deg=as_output(alpha_deg),
        dx_m=as_output(dx),
        dz_m=as_output(dz),
        time_s=as_output(time),
        launch_vx_mps=as_output(vx),
        launch_vz_mps=as_output(vz),
        arrival_vx_mps=as_output(vx.copy()),
        arrival_vz_mps=as_output(vz - g * time),
        hmax_vertical_m=hmax,
        x_hmax_m=x_hmax,
        hmax_normal_m=as_output(hmax * dx / np.hypot(dx, dz)),
        g_mps2=g,
    )


def flight_between(
    dx_m: ArrayLike, dz_m: ArrayLike, alpha_deg: ArrayLike, g: float = G
) -> Flight:
    """The flight launched at ``alpha`` that lands at ``(dx, dz)`` from launch.

    Launch speed from eq. 3.5, velocities and time from eqs. 3.1-3.4, heights from
    eqs. 3.9-3.12 with the chord between the two points as the slope.

    Parameters
    ----------
    dx_m, dz_m
        Offset of the arrival point from the launch point [m], ``dx > 0``.
    alpha_deg
        Launch angle above the horizontal [deg], between -90° and 90°.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    Flight

    Raises
    ------
    PhysicsError
        No ballistic path with that launch angle reaches the point (see
        :func:`launch_speed`).

    Examples
    --------
    >>> f = flight_between(14.0, -8.0, -15.0)
    >>> [round(float(v), 3) for v in (f.v0_mps, f.time_s, f.x_hmax_m)]
    [15.573, 0.931, 7.0]
    """
    v0 = launch_speed(dx_m, dz_m, alpha_deg, g=g)
    return _flight(v0, alpha_deg, dx_m, dz_m, g)


def next_impact_on_slope(
    v0_mps: ArrayLike, theta0_deg: ArrayLike, psi_deg: ArrayLike, g: float = G
) -> Flight:
    """Where a rock launched from a uniform slope lands on it again (eqs. 3.6-3.8).

    ``alpha = theta0 - psi`` (eq. 3.6); the slope through the launch point is
    ``z = kappa x`` with ``kappa = -tan(psi)`` (eq. 3.7); the impact is at
    ``x = -2 (kappa - tan alpha) / (g / (V0 cos alpha)^2)`` (eq. 3.8).

    Parameters
    ----------
    v0_mps
        Launch (restitution) speed [m/s], > 0.
    theta0_deg
        Launch angle to the slope [deg], 0 < theta0 < 90 + psi.
    psi_deg
        Slope dip [deg], positive descending toward +x, between -90° and 90°.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    Flight
        From the launch point to the next impact; the chord is the slope.

    Raises
    ------
    PhysicsError
        theta0 <= 0: the rock is launched into the slope.
    ArgumentError
        Non-positive speed, slope dip outside (-90°, 90°), or a launch angle
        ``alpha >= 90°`` (travelling backwards).

    Examples
    --------
    Worked example 3B, unrounded (the thesis's rounded parabola gives 28.2, -23.8):

    >>> f = next_impact_on_slope(18.0, 20.0, 40.0)
    >>> [round(float(v), 1) for v in (f.dx_m, f.dz_m, f.chord_length_m)]
    [27.7, -23.3, 36.2]
    """
    check_gravity(g)
    v0 = np.asarray(v0_mps, float)
    check_positive(v0, "v0_mps", "m/s")
    theta0 = np.asarray(theta0_deg, float)
    psi = np.asarray(psi_deg, float)
    check_into_slope(theta0, psi)
    alpha_d = theta0 - psi
    check_forward_angle(alpha_d)
    alpha = np.radians(alpha_d)
    tan_psi = np.tan(np.radians(psi))
    dx = 2.0 * (np.tan(alpha) + tan_psi) * (v0 * np.cos(alpha)) ** 2 / g
    return _flight(v0, alpha_d, dx, -tan_psi * dx, g)
