"""Normal coefficient of restitution laws (thesis eqs. 4.6, 5.4, 7.1).

Three pure functions, each returning ``e_N``:

* :func:`constant_restitution` - a fixed ``e_N`` per material (RocFall/CRSP base
  model, eq. 4.6);
* :func:`angle_dependent_restitution` - ``e_N = a theta_i^(-b)`` (eq. 5.4, thesis best
  fit a = 19.5, b = 1.03 with theta_i in degrees);
* :func:`velocity_scaled_restitution` - ``v_fN = e_N |v_iN| / (1 + (v_iN/K)^2)``
  (eq. 7.1, RocFall/CRSP; K = 9.144 m/s = 30 ft/s, the thesis's "9.14 m/s").

The last two carry the effect names of docs/architecture.md §5. ``e_N > 1`` is legal
(shallow impacts, thesis §5.2.1); laws never cap it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics._validate import reject

#: Thesis eq. 5.4 best fit to the field data (Fig. 5.5): e_N = 19.5 theta_i^-1.03.
ANGLE_LAW_A = 19.5
ANGLE_LAW_B = 1.03
#: Eq. 7.1 default K [m/s] (RocFall 4.0 / CRSP: 30 ft/s).
VELOCITY_SCALE_MPS = 9.144


def _finite(name: str, value: ArrayLike) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    reject(~np.isfinite(array), name, "be finite", array)
    return array


def constant_restitution(e_n: ArrayLike) -> np.ndarray:
    """A constant normal coefficient of restitution ``e_N`` (eq. 4.6), ``>= 0``.

    The base model of RocFall and CRSP: one ``e_N`` per slope material, whatever the
    impact angle and speed.

    Examples
    --------
    >>> float(constant_restitution(0.35))
    0.35
    """
    e = np.asarray(e_n, float)
    reject(~(e >= 0), "e_n", "be >= 0", e)
    return e[()]


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
    reject(~(np.asarray(a, float) > 0), "a", "be > 0", np.asarray(a, float))
    reject(~(np.asarray(b, float) >= 0), "b", "be >= 0", np.asarray(b, float))
    theta = _finite("theta_i_deg", theta_i_deg)
    reject(~((theta > 0) & (theta <= 90)), "theta_i_deg", "be in (0, 90] deg", theta)
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
    reject(~(e0 >= 0), "e_n", "be >= 0", e0)
    scale = np.asarray(velocity_scale_mps, float)
    reject(~(scale > 0), "velocity_scale_mps", "be > 0", scale)
    return e0 / (1.0 + (v_in / scale) ** 2)
