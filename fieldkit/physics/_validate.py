"""Input checks shared by the physics modules: the one way physics validates input.

Private to :mod:`fieldkit.physics`. Every check raises a one-line
:class:`~fieldkit.errors.ArgumentError` (or :class:`~fieldkit.errors.PhysicsError`)
through :func:`raise_at_first`: ``source`` names the argument, ``where`` the first
offending element of an array (``"element 3"``), and the message reads
``"<name> must <requirement> (got <value>)"``. The range checks let NaN pass, so
missing data propagates as NaN; :func:`number_array` is for arguments that must be
numbers.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.errors import ArgumentError, FieldkitError, PhysicsError


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


def raise_at_first(
    bad: ArrayLike,
    message: Callable[..., str],
    *values: ArrayLike,
    error: type[FieldkitError] = ArgumentError,
    source: str | None = None,
) -> None:
    """Raise ``error`` at the first True of ``bad``, if any, naming that element.

    ``message`` is called with the values of ``values`` at that element.
    """
    bad = np.asarray(bad)
    if bad.any():
        raise error(
            message(*first_values(bad, *values)), source=source, where=where_first(bad)
        )


def as_output(value: ArrayLike) -> np.ndarray:
    """Return 0-d arrays as numpy scalars, arrays unchanged."""
    value = np.asarray(value)
    return value[()] if value.ndim == 0 else value


def reject(
    bad: ArrayLike,
    name: str,
    requirement: str,
    value: ArrayLike,
    *,
    unit: str = "",
    error: type[FieldkitError] = ArgumentError,
) -> None:
    """Raise ``"<name> must <requirement> (got <value> <unit>)"`` at the first bad one.

    Examples
    --------
    >>> reject(np.array([1.0, -2.0]) < 0, "e_n", "be >= 0", [1.0, -2.0])
    Traceback (most recent call last):
    ...
    fieldkit.errors.ArgumentError: e_n: element 1: e_n must be >= 0 (got -2)
    """
    suffix = f" {unit}" if unit else ""
    raise_at_first(
        bad,
        lambda v: f"{name} must {requirement} (got {v:g}{suffix})",
        value,
        error=error,
        source=name,
    )


def number_array(value: ArrayLike, name: str) -> np.ndarray:
    """``value`` as a float array; ArgumentError naming ``name`` unless all are numbers
    (NaN included)."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ArgumentError(
            f"{name} must be a number (got {value!r})", source=name
        ) from None
    reject(np.isnan(array), name, "be a number", array)
    return array


def check_gravity(g: float) -> None:
    """ArgumentError unless ``g > 0`` (NaN fails)."""
    g = np.asarray(g, float)
    raise_at_first(
        ~(g > 0), lambda v: f"gravity g must be positive (got {v:g})", g, source="g"
    )


def check_nonnegative(value: np.ndarray, name: str, unit: str) -> None:
    """ArgumentError naming ``name`` if any element is negative."""
    reject(value < 0, name, "not be negative", value, unit=unit)


def check_positive(value: np.ndarray, name: str, unit: str) -> None:
    """ArgumentError naming ``name`` if any element is zero or negative."""
    reject(value <= 0, name, "be positive", value, unit=unit)


def nonnegative_array(value: ArrayLike, name: str, unit: str = "") -> np.ndarray:
    """``value`` as a float array; ArgumentError naming ``name`` if any is negative."""
    array = np.asarray(value, float)
    check_nonnegative(array, name, unit)
    return array


def positive_array(value: ArrayLike, name: str, unit: str = "") -> np.ndarray:
    """``value`` as a float array; ArgumentError naming ``name`` unless all are > 0."""
    array = np.asarray(value, float)
    check_positive(array, name, unit)
    return array


def check_forward_angle(alpha_deg: np.ndarray) -> None:
    """ArgumentError unless -90° < alpha < 90° (travel toward +x)."""
    raise_at_first(
        np.abs(alpha_deg) >= 90,
        lambda a: (
            "launch angle must be between -90° and 90° (travel toward +x) "
            f"(got {a:.1f}°)"
        ),
        alpha_deg,
        source="alpha_deg",
    )


def check_into_slope(theta0_deg: np.ndarray, psi_deg: np.ndarray) -> None:
    """ArgumentError for |psi| >= 90°; PhysicsError for a launch into the slope."""
    raise_at_first(
        np.abs(psi_deg) >= 90,
        lambda p: f"slope dip must be between -90° and 90° (got {p:.1f}°)",
        psi_deg,
        source="slope_deg",
    )
    raise_at_first(
        theta0_deg <= 0,
        lambda t: (
            f"a rock launched at {t:.1f}° to the slope goes into the ground: "
            "the restitution angle theta0 must be above 0°"
        ),
        theta0_deg,
        error=PhysicsError,
    )
