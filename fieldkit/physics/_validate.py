"""Input checks shared by the flight, three-point and fall-velocity physics.

Private to :mod:`fieldkit.physics`. Each check raises a one-line
:class:`~fieldkit.errors.ArgumentError` or :class:`~fieldkit.errors.PhysicsError`; for
array inputs ``where`` names the first offending element (``"element 3"``). NaN never
fails a check, so missing data propagates as NaN.
"""

from __future__ import annotations

import numpy as np

from fieldkit.errors import ArgumentError, PhysicsError


def where_first(mask: np.ndarray) -> str | None:
    """Location of the first True element of ``mask`` (None for a scalar)."""
    if mask.ndim == 0:
        return None
    index = np.unravel_index(int(np.argmax(mask)), mask.shape)
    return f"element {index[0] if len(index) == 1 else tuple(int(i) for i in index)}"


def first_values(mask: np.ndarray, *arrays: np.ndarray) -> list[float]:
    """Values of ``arrays`` (broadcast to ``mask``) at the first True of ``mask``."""
    index = np.unravel_index(int(np.argmax(mask)), mask.shape) if mask.ndim else ()
    return [float(np.broadcast_to(a, mask.shape)[index]) for a in arrays]


def as_output(value: np.ndarray) -> np.ndarray:
    """Return 0-d arrays as numpy scalars, arrays unchanged."""
    return value[()] if np.ndim(value) == 0 else value


def check_gravity(g: float) -> None:
    """ArgumentError unless ``g > 0``."""
    if not np.all(np.asarray(g, float) > 0):
        raise ArgumentError(f"gravity g must be positive, got {g}", source="g")


def check_nonnegative(value: np.ndarray, name: str, unit: str) -> None:
    """ArgumentError naming ``name`` if any element is negative."""
    bad = np.asarray(value < 0)
    if bad.any():
        (v,) = first_values(bad, value)
        raise ArgumentError(
            f"{name} must not be negative, got {v:g} {unit}",
            source=name,
            where=where_first(bad),
        )


def check_positive(value: np.ndarray, name: str, unit: str) -> None:
    """ArgumentError naming ``name`` if any element is zero or negative."""
    bad = np.asarray(value <= 0)
    if bad.any():
        (v,) = first_values(bad, value)
        raise ArgumentError(
            f"{name} must be positive, got {v:g} {unit}",
            source=name,
            where=where_first(bad),
        )


def check_forward_angle(alpha_deg: np.ndarray) -> None:
    """ArgumentError unless -90° < alpha < 90° (travel toward +x)."""
    bad = np.asarray(np.abs(alpha_deg) >= 90)
    if bad.any():
        (a,) = first_values(bad, alpha_deg)
        raise ArgumentError(
            "launch angle must be between -90° and 90° (travel toward +x), "
            f"got {a:.1f}°",
            source="alpha_deg",
            where=where_first(bad),
        )


def check_into_slope(theta0_deg: np.ndarray, psi_deg: np.ndarray) -> None:
    """ArgumentError for |psi| >= 90°; PhysicsError for a launch into the slope."""
    steep = np.asarray(np.abs(psi_deg) >= 90)
    if steep.any():
        (p,) = first_values(steep, psi_deg)
        raise ArgumentError(
            f"slope dip must be between -90° and 90°, got {p:.1f}°",
            source="slope_deg",
            where=where_first(steep),
        )
    into = np.asarray(theta0_deg <= 0)
    if into.any():
        (t,) = first_values(into, theta0_deg)
        raise PhysicsError(
            f"a rock launched at {t:.1f}° to the slope goes into the ground: the "
            "restitution angle theta0 must be above 0°",
            where=where_first(into),
        )
