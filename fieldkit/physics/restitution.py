"""Normal coefficient of restitution laws (thesis eqs. 4.6, 5.4, 7.1).

Three laws, each a small pure function plus a frozen dataclass with the same
call signature ``law(theta_i_deg, v_in_mps) -> e_n`` so a forward model can hold any of
them:

* :class:`ConstantRestitution` - a fixed ``e_N`` per material (RocFall/CRSP base model);
* :class:`AngleDependentRestitution` - ``e_N = a theta_i^(-b)`` (eq. 5.4, thesis best
  fit a = 19.5, b = 1.03 with theta_i in degrees);
* :class:`VelocityScaledRestitution` - ``v_fN = e_N |v_iN| / (1 + (v_iN/K)^2)``
  (eq. 7.1, RocFall/CRSP; K = 9.144 m/s = 30 ft/s, the thesis's "9.14 m/s").

``e_N > 1`` is legal (shallow impacts, thesis §5.2.1); laws never cap it.
:data:`RESTITUTION_LAWS` maps names to the classes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.errors import ArgumentError

#: Thesis eq. 5.4 best fit to the field data (Fig. 5.5): e_N = 19.5 theta_i^-1.03.
ANGLE_LAW_A = 19.5
ANGLE_LAW_B = 1.03
#: Eq. 7.1 default K [m/s] (RocFall 4.0 / CRSP: 30 ft/s).
VELOCITY_SCALE_MPS = 9.144


def _finite(name: str, value: ArrayLike) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    bad = ~np.isfinite(array)
    if np.any(bad):
        raise ArgumentError(f"{name} must be finite (got {array[bad].flat[0]:g})")
    return array


def _require(name: str, bad: np.ndarray, requirement: str, value: np.ndarray) -> None:
    bad = np.atleast_1d(bad)
    if np.any(bad):
        values = np.broadcast_to(np.atleast_1d(np.asarray(value, float)), bad.shape)
        first = values[bad]
        raise ArgumentError(f"{name} must be {requirement} (got {first.flat[0]:g})")


def angle_dependent_restitution(
    theta_i_deg: ArrayLike, a: float = ANGLE_LAW_A, b: float = ANGLE_LAW_B
) -> np.ndarray:
    """``e_N = a theta_i^(-b)`` with theta_i in degrees (thesis eq. 5.4).

    Parameters
    ----------
    theta_i_deg
        Impact angle to the ground [deg], in (0, 90].
    a, b
        Law coefficients (thesis best fit 19.5 and 1.03; a > 0, b >= 0).

    Examples
    --------
    Thesis §5.2.3 / worked example 4A: theta_i = 25 deg -> 0.71; 50 deg -> 0.35.

    >>> [round(float(e), 2) for e in angle_dependent_restitution([25.0, 50.0])]
    [0.71, 0.35]
    """
    theta = _finite("theta_i_deg", theta_i_deg)
    _require("theta_i_deg", ~((theta > 0) & (theta <= 90)), "in (0, 90] deg", theta)
    _require("a", ~(np.asarray(a, float) > 0), "> 0", np.asarray(a, float))
    _require("b", ~(np.asarray(b, float) >= 0), ">= 0", np.asarray(b, float))
    return a * theta ** (-b)


def velocity_scaled_restitution(
    v_in_mps: ArrayLike, e_n: ArrayLike, velocity_scale_mps: float = VELOCITY_SCALE_MPS
) -> np.ndarray:
    """Effective ``e_N = e_N0 / (1 + (v_iN/K)^2)`` (thesis eq. 7.1, RocFall/CRSP).

    Eq. 7.1 scales the restitution normal velocity,
    ``v_fN = e_N0 |v_iN| / (1 + (v_iN/K)^2)``; this returns ``v_fN / |v_iN|``. The
    factor is 0.5 at ``|v_iN| = K`` and tends to 1 for slow impacts.

    Examples
    --------
    >>> round(float(velocity_scaled_restitution(-9.144, 0.8)), 3)
    0.4
    """
    v_in = _finite("v_in_mps", v_in_mps)
    e0 = _finite("e_n", e_n)
    _require("e_n", ~(e0 >= 0), ">= 0", e0)
    scale = np.asarray(velocity_scale_mps, float)
    _require("velocity_scale_mps", ~(scale > 0), "> 0", scale)
    return e0 / (1.0 + (v_in / scale) ** 2)


@dataclass(frozen=True)
class ConstantRestitution:
    """A constant normal coefficient of restitution ``e_N`` (eq. 4.6).

    Examples
    --------
    >>> float(ConstantRestitution(0.35)(40.0, -8.0))
    0.35
    """

    e_n: float

    name = "constant"

    def __post_init__(self) -> None:
        _require("e_n", ~(np.asarray(self.e_n, float) >= 0), ">= 0", self.e_n)

    def __call__(self, theta_i_deg: ArrayLike, v_in_mps: ArrayLike) -> np.ndarray:
        shape = np.broadcast_shapes(np.shape(theta_i_deg), np.shape(v_in_mps))
        return np.full(shape, float(self.e_n))[()]


@dataclass(frozen=True)
class AngleDependentRestitution:
    """``e_N = a theta_i^(-b)`` (eq. 5.4); the impact speed is not used.

    Examples
    --------
    >>> round(float(AngleDependentRestitution()(25.0, -9.3)), 3)
    0.708
    """

    a: float = ANGLE_LAW_A
    b: float = ANGLE_LAW_B

    name = "angle_dependent_restitution"

    def __post_init__(self) -> None:
        _require("a", ~(np.asarray(self.a, float) > 0), "> 0", self.a)
        _require("b", ~(np.asarray(self.b, float) >= 0), ">= 0", self.b)

    def __call__(self, theta_i_deg: ArrayLike, v_in_mps: ArrayLike) -> np.ndarray:
        e = angle_dependent_restitution(theta_i_deg, self.a, self.b)
        return np.broadcast_to(e, np.broadcast_shapes(e.shape, np.shape(v_in_mps)))[()]


@dataclass(frozen=True)
class VelocityScaledRestitution:
    """``e_N / (1 + (v_iN/K)^2)`` (eq. 7.1); the impact angle is not used.

    Examples
    --------
    >>> round(float(VelocityScaledRestitution(0.8)(30.0, -9.144)), 3)
    0.4
    """

    e_n: float
    velocity_scale_mps: float = VELOCITY_SCALE_MPS

    name = "velocity_scaled_restitution"

    def __post_init__(self) -> None:
        _require("e_n", ~(np.asarray(self.e_n, float) >= 0), ">= 0", self.e_n)
        scale = self.velocity_scale_mps
        _require("velocity_scale_mps", ~(np.asarray(scale, float) > 0), "> 0", scale)

    def __call__(self, theta_i_deg: ArrayLike, v_in_mps: ArrayLike) -> np.ndarray:
        e = velocity_scaled_restitution(v_in_mps, self.e_n, self.velocity_scale_mps)
        shape = np.broadcast_shapes(e.shape, np.shape(theta_i_deg))
        return np.broadcast_to(e, shape)[()]


#: Restitution laws by name (``fieldkit impact`` and model files).
RESTITUTION_LAWS = {
    "constant": ConstantRestitution,
    "angle": AngleDependentRestitution,
    "velocity": VelocityScaledRestitution,
}
