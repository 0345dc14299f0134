"""Loss of rock volume (and mass) along a fall path (thesis section 6.5).

Two empirical laws:

* with horizontal distance from the source, ``Omega / Omega_0 = 1 / (1 + x lambda)``
  (eq. 6.15, Nicolla et al. 2009: lambda = 0.0035-0.01 /m at Mt. Pellegrino,
  limestone; 0.008-0.02 /m at Camaldoli Hill, tuff; about 0.03 /m back-figured at
  Tornado Mountain);
* with the number of impacts, ``Omega_n / Omega_0 = n^(-0.8)`` (eq. 6.16, Tornado
  Mountain), defined for ``n >= 1`` (the first impact keeps the source volume).

Mass scales with volume at constant density, so the same ratios apply to mass; the
moment of inertia ``I = m k^2`` falls with the mass and with ``k^2`` (for a body that
keeps its shape ``k`` scales with ``Omega^(1/3)``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics._validate import (
    as_output,
    check_nonnegative,
    nonnegative_array,
    positive_array,
    reject,
)

__all__ = [
    "IMPACT_EXPONENT",
    "REDUCTION_COEFFICIENTS_PER_M",
    "initial_volume_from_impacts",
    "reduction_coefficient",
    "volume_ratio_with_distance",
    "volume_ratio_with_impacts",
]

#: Exponent of eq. 6.16 (Tornado Mountain).
IMPACT_EXPONENT = 0.8

#: Ranges of the reduction coefficient lambda [1/m] of eq. 6.15 quoted in section 6.5.
REDUCTION_COEFFICIENTS_PER_M: dict[str, tuple[float, float]] = {
    "mt_pellegrino_limestone": (0.0035, 0.01),
    "camaldoli_hill_tuff": (0.008, 0.02),
    "tornado_mountain_limestone": (0.03, 0.03),
}


def volume_ratio_with_distance(
    x_m: ArrayLike, reduction_per_m: ArrayLike
) -> np.ndarray:
    """Remaining volume fraction ``Omega/Omega_0 = 1/(1 + x lambda)`` [-] (eq. 6.15).

    Parameters
    ----------
    x_m
        Horizontal distance from the source [m], ``>= 0``.
    reduction_per_m
        Reduction coefficient lambda [1/m], ``>= 0`` (0 = no mass loss).

    Examples
    --------
    Ehime cube (section 6.5): 0.22 m^3 at the source, lambda = 0.02, 57 m of travel
    leaves about 0.1 m^3:

    >>> round(0.22 * float(volume_ratio_with_distance(57.0, 0.02)), 3)
    0.103
    """
    x = nonnegative_array(x_m, "x_m")
    lam = nonnegative_array(reduction_per_m, "reduction_per_m")
    return as_output(1.0 / (1.0 + x * lam))


def reduction_coefficient(x_m: ArrayLike, volume_ratio: ArrayLike) -> np.ndarray:
    """Lambda that leaves ``volume_ratio`` after ``x_m`` [1/m] (eq. 6.15 inverted).

    Examples
    --------
    Tornado Mountain (section 6.5): 1.42 of 30 m^3 left after 610 m -> lambda 0.03:

    >>> round(float(reduction_coefficient(610.0, 1.42 / 30.0)), 3)
    0.033
    """
    x = positive_array(x_m, "x_m")
    ratio = np.asarray(volume_ratio, float)
    reject((ratio <= 0) | (ratio > 1), "volume_ratio", "be in (0, 1]", ratio)
    return as_output((1.0 / ratio - 1.0) / x)


def volume_ratio_with_impacts(
    impact_number: ArrayLike, exponent: float = IMPACT_EXPONENT
) -> np.ndarray:
    """Remaining volume fraction after ``n`` impacts ``n^(-0.8)`` [-] (eq. 6.16).

    Parameters
    ----------
    impact_number
        Impact count n, ``>= 1`` (``n = 1`` gives 1: the source volume).
    exponent
        0.8 in the thesis (Tornado Mountain); ``0`` switches mass loss off.

    Examples
    --------
    >>> round(float(volume_ratio_with_impacts(46)), 4)
    0.0468
    """
    n = np.asarray(impact_number, float)
    reject(n < 1, "impact_number", "be >= 1 (eq. 6.16 starts at the first impact)", n)
    check_nonnegative(np.asarray(exponent, float), "exponent", "")
    return as_output(n ** (-float(exponent)))


def initial_volume_from_impacts(
    final_volume_m3: ArrayLike,
    impact_number: ArrayLike,
    exponent: float = IMPACT_EXPONENT,
) -> np.ndarray:
    """Source volume ``Omega_0 = Omega_n n^0.8`` from the volume after n impacts [m^3].

    Examples
    --------
    Tornado Mountain boulder A: 1.42 m^3 after 46 impacts -> about 30 m^3 at the source
    (section 6.5):

    >>> round(float(initial_volume_from_impacts(1.42, 46)), 1)
    30.4
    """
    final = nonnegative_array(final_volume_m3, "final_volume_m3")
    return as_output(final / volume_ratio_with_impacts(impact_number, exponent))
