"""Fall velocity from fall height, slope angle and effective friction (eqs. 3.13-3.16).

A block sliding down a slope of dip ``psi`` with an effective friction coefficient
``mu'`` (surface material and roughness lumped together, Japan Road Association 2000)
reaches, after a vertical fall ``H``,

    V = sqrt(2 g H (1 - mu' / tan psi))                                  (3.13)

Written as a fraction of the free-fall velocity, ``eta = V / sqrt(2 g H)`` (3.14),
``eta = sqrt(1 - mu' / tan psi)`` (3.15) and, for back-analysis of a measured
velocity, ``mu' = tan(psi) (1 - eta^2)`` (3.16). Table 3-1 gives design values of
``mu'`` by slope category (:data:`EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY`).

Pure, vectorised; scalars come back as numpy scalars. Errors from array inputs name
the first offending element in ``where``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.errors import ArgumentError, PhysicsError
from fieldkit.physics._validate import (
    as_output,
    check_gravity,
    check_nonnegative,
    check_positive,
    raise_at_first,
)
from fieldkit.physics.constants import G

__all__ = [
    "EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY",
    "back_analyse_friction",
    "design_friction",
    "fall_velocity",
    "friction_from_velocity_ratio",
    "velocity_ratio",
    "velocity_ratio_from_friction",
]

#: Table 3-1 (thesis, after Japan Road Association 2000): effective friction
#: coefficient ``mu'`` by slope category. ``design_mu`` is the design value (it tends to
#: give upper-bound velocities); ``field_range`` the range found in field tests
#: (category D is printed as "~0.31", kept here as (0.31, 0.31)).
EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY: dict[str, dict] = {
    "A": {
        "description": "Smooth, strong rock surfaces and uniform slope profile; "
        "no tree cover.",
        "design_mu": 0.05,
        "field_range": (0.0, 0.1),
    },
    "B": {
        "description": "Smooth to rough, weak rock surfaces with medium to high "
        "roughness slope profile; no tree cover.",
        "design_mu": 0.15,
        "field_range": (0.11, 0.2),
    },
    "C": {
        "description": "Smooth to rough, weak rock, soil, sand or talus with low to "
        "medium roughness slope profile; no tree cover.",
        "design_mu": 0.25,
        "field_range": (0.21, 0.3),
    },
    "D": {
        "description": "Talus with angular boulders exposed at surface, medium to "
        "high roughness slope profile; no tree cover or few trees.",
        "design_mu": 0.35,
        "field_range": (0.31, 0.31),
    },
}


def design_friction(category: str) -> float:
    """Design ``mu'`` of a Table 3-1 slope category ("A" to "D").

    Raises
    ------
    ArgumentError
        Unknown category; the message lists the known ones.

    Examples
    --------
    >>> design_friction("d")
    0.35
    """
    key = str(category).strip().upper()
    if key not in EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY:
        known = ", ".join(EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY)
        raise ArgumentError(
            f"unknown slope category {category!r} (Table 3-1 has {known})",
            source="category",
        )
    return EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY[key]["design_mu"]


def _check_slope(psi_deg: np.ndarray) -> None:
    raise_at_first(
        (psi_deg <= 0) | (psi_deg > 90),
        lambda p: f"slope angle must be above 0° and at most 90° (got {p:.1f}°)",
        psi_deg,
        source="slope_deg",
    )


def velocity_ratio_from_friction(
    friction_coefficient: ArrayLike, slope_deg: ArrayLike
) -> np.ndarray:
    """Slope parameter ``eta = sqrt(1 - mu' / tan psi)`` (eq. 3.15).

    Parameters
    ----------
    friction_coefficient
        Effective friction coefficient mu' [-], >= 0.
    slope_deg
        Slope angle psi [deg], 0 < psi <= 90.

    Returns
    -------
    eta
        Fall velocity as a fraction of the free-fall velocity [-].

    Raises
    ------
    PhysicsError
        ``mu' > tan psi``: friction holds the block, it does not accelerate.

    Examples
    --------
    >>> round(float(velocity_ratio_from_friction(0.25, 45.0)), 4)
    0.866
    """
    mu = np.asarray(friction_coefficient, float)
    check_nonnegative(mu, "friction_coefficient", "")
    psi = np.asarray(slope_deg, float)
    _check_slope(psi)
    tan_psi = np.tan(np.radians(psi))
    raise_at_first(
        mu > tan_psi * (1.0 + 1e-12),  # tolerate rounding of tan(psi)
        lambda m, p: (
            f"effective friction mu' = {m:.2f} exceeds tan({p:.1f}°) = "
            f"{np.tan(np.radians(p)):.2f}: a block on this slope does not accelerate"
        ),
        mu,
        psi,
        error=PhysicsError,
    )
    return as_output(np.sqrt(np.maximum(1.0 - mu / tan_psi, 0.0)))


def fall_velocity(
    height_m: ArrayLike,
    slope_deg: ArrayLike,
    friction_coefficient: ArrayLike,
    g: float = G,
) -> np.ndarray:
    """Velocity after a vertical fall ``H`` down a slope with friction (eq. 3.13).

    ``V = sqrt(2 g H (1 - mu' / tan psi))``

    Parameters
    ----------
    height_m
        Vertical fall height H [m], >= 0.
    slope_deg
        Slope angle psi [deg], 0 < psi <= 90 (90° is free fall).
    friction_coefficient
        Effective friction coefficient mu' [-] (Table 3-1), 0 <= mu' <= tan psi.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    velocity_mps
        Fall velocity [m/s].

    Raises
    ------
    PhysicsError
        ``mu' > tan psi`` (the block would not move).
    ArgumentError
        Negative height or friction, slope angle outside (0°, 90°].

    Examples
    --------
    The 26 m Ehime rock slope at 44° with the Table 3-1 category B value:

    >>> round(float(fall_velocity(26.0, 44.0, design_friction("B"))), 2)
    20.76
    """
    check_gravity(g)
    height = np.asarray(height_m, float)
    check_nonnegative(height, "height_m", "m")
    eta = velocity_ratio_from_friction(friction_coefficient, slope_deg)
    return as_output(eta * np.sqrt(2.0 * g * height))


def velocity_ratio(
    velocity_mps: ArrayLike, height_m: ArrayLike, g: float = G
) -> np.ndarray:
    """Measured velocity as a fraction of the free-fall velocity (eq. 3.14).

    ``eta = V / sqrt(2 g H)``

    Parameters
    ----------
    velocity_mps
        Measured fall velocity V [m/s], >= 0.
    height_m
        Vertical fall height H [m], > 0.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    eta
        [-]; a value above 1 (faster than free fall) is returned as is.

    Examples
    --------
    Tornado Mountain, V = 12.5 m/s after H = 250 m (the thesis prints 0.39; the
    correct value is 0.18, see docs/thesis-notes.md errata):

    >>> round(float(velocity_ratio(12.5, 250.0)), 3)
    0.178
    """
    check_gravity(g)
    velocity = np.asarray(velocity_mps, float)
    check_nonnegative(velocity, "velocity_mps", "m/s")
    height = np.asarray(height_m, float)
    check_positive(height, "height_m", "m")
    return as_output(velocity / np.sqrt(2.0 * g * height))


def friction_from_velocity_ratio(eta: ArrayLike, slope_deg: ArrayLike) -> np.ndarray:
    """Effective friction coefficient from the slope parameter (eq. 3.16).

    ``mu' = tan(psi) (1 - eta^2)``

    Parameters
    ----------
    eta
        Velocity ratio V / sqrt(2 g H) [-], 0 <= eta <= 1.
    slope_deg
        Slope angle psi [deg], 0 < psi <= 90.

    Returns
    -------
    friction_coefficient
        Effective friction coefficient mu' [-].

    Raises
    ------
    PhysicsError
        ``eta > 1``: faster than free fall, which no friction explains.

    Examples
    --------
    Worked example 3C, Ehime rock (eta = 0.9 at 44°) and talus (0.7 at 35°):

    >>> np.round(friction_from_velocity_ratio([0.9, 0.7], [44.0, 35.0]), 2).tolist()
    [0.18, 0.36]
    """
    eta = np.asarray(eta, float)
    check_nonnegative(eta, "eta", "")
    raise_at_first(
        eta > 1,
        lambda e: (
            f"velocity ratio eta = {e:.2f} exceeds 1: the rock would be faster "
            "than in free fall from that height, which no friction coefficient explains"
        ),
        eta,
        error=PhysicsError,
    )
    psi = np.asarray(slope_deg, float)
    _check_slope(psi)
    return as_output(np.tan(np.radians(psi)) * (1.0 - eta**2))


def back_analyse_friction(
    velocity_mps: ArrayLike, height_m: ArrayLike, slope_deg: ArrayLike, g: float = G
) -> np.ndarray:
    """Effective friction ``mu'`` from a measured velocity (eqs. 3.14 and 3.16).

    The back-analysis of worked example 3C.

    Parameters
    ----------
    velocity_mps
        Measured velocity [m/s].
    height_m
        Vertical fall height above the measurement [m], > 0.
    slope_deg
        Slope angle [deg], 0 < psi <= 90.
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    friction_coefficient
        Effective friction coefficient mu' [-].

    Raises
    ------
    PhysicsError
        The velocity exceeds the free-fall velocity ``sqrt(2 g H)``.

    Examples
    --------
    Tornado Mountain colluvium, 12.5 m/s after 250 m on 22° (the thesis prints 0.34,
    from its mis-computed eta = 0.39; eq. 3.16 with eta = 0.18 gives 0.39):

    >>> round(float(back_analyse_friction(12.5, 250.0, 22.0)), 2)
    0.39
    """
    eta = velocity_ratio(velocity_mps, height_m, g=g)
    raise_at_first(
        eta > 1,
        lambda v, h: (
            f"{v:.1f} m/s exceeds the free-fall velocity "
            f"{np.sqrt(2 * g * h):.1f} m/s from {h:.1f} m: no friction coefficient "
            "explains it"
        ),
        np.asarray(velocity_mps, float),
        height_m,
        error=PhysicsError,
    )
    return friction_from_velocity_ratio(eta, slope_deg)
