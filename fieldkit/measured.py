"""A value measured in the field at an analysis point (speed, energy, bounce height).

The data type shared by the simulation (a measured value's percentile among the
simulated rocks), the fit's design quantities (is the calibrated model
unconservative against it?), the survey preset (``[[measured]]``) and the figures.
:func:`measured_problem` holds the one bound check every reader applies: a value
outside it is a typo or a unit slip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fieldkit.physics.constants import MAX_MASS_KG, MAX_SPEED_MPS

#: Standard gravity for the bound on a measured bounce height [m/s^2].
_G_MPS2 = 9.81

#: The measured quantities, in the order they are reported: field -> words, scale
#: to the unit printed, unit printed.
QUANTITIES: dict[str, tuple[str, float, str]] = {
    "speed_mps": ("speed", 1.0, "m/s"),
    "ke_j": ("translational KE", 1e-3, "kJ"),
    "total_j": ("total energy KE+RE", 1e-3, "kJ"),
    "height_m": ("bounce height", 1.0, "m"),
}


@dataclass(frozen=True)
class Measured:
    """A measured value at an analysis point, compared with the rocks crossing it.

    Attributes
    ----------
    x_m
        Where it was measured along the section [m].
    speed_mps, ke_j, total_j, height_m
        Any of: the speed of the centre [m/s], the translational kinetic energy
        ``1/2 m v^2`` [J], the total energy (translational + rotational) [J] and
        the bounce height of the centre above the ground [m]; None: not measured.
    source
        Where the value comes from (``"thesis §7.5.4"``); empty when not said.
    """

    x_m: float
    speed_mps: float | None = None
    ke_j: float | None = None
    height_m: float | None = None
    total_j: float | None = None
    source: str = ""

    def values(self) -> dict[str, float]:
        """The measured quantities given, in :data:`QUANTITIES` order.

        Examples
        --------
        >>> Measured(610.0, speed_mps=18.0, ke_j=600e3).values()
        {'speed_mps': 18.0, 'ke_j': 600000.0}
        """
        return {
            k: float(getattr(self, k))
            for k in QUANTITIES
            if getattr(self, k) is not None
        }


def measured_bounds() -> dict[str, tuple[float, str, str]]:
    """Largest measured speed, energies and bounce height: (limit, units, why).

    Examples
    --------
    >>> measured_bounds()["speed_mps"][:2]
    (100.0, 'm/s')
    """
    ke_max = 0.5 * MAX_MASS_KG * MAX_SPEED_MPS**2
    why_ke = (
        f"1/2 m v^2 of the largest rockfall block ({MAX_MASS_KG:g} kg) at "
        f"{MAX_SPEED_MPS:g} m/s"
    )
    return {
        "speed_mps": (
            MAX_SPEED_MPS, "m/s", "free fall from 500 m reaches 99 m/s; rockfall "
            "impacts are tens of m/s",
        ),
        "ke_j": (ke_max, "J", why_ke),
        "total_j": (2.0 * ke_max, "J", "twice " + why_ke + " (rotation at most as "
                    "much again)"),
        "height_m": (
            MAX_SPEED_MPS**2 / (2 * _G_MPS2), "m",
            f"a rock thrown up at {MAX_SPEED_MPS:g} m/s rises v^2/(2g)",
        ),
    }  # fmt: skip


def measured_problem(field: str, value: object) -> str | None:
    """What is wrong with a measured ``field`` = ``value`` (None: nothing).

    ``x_m`` must be a finite number; a quantity of :data:`QUANTITIES` a finite
    number from 0 to its :func:`measured_bounds` limit.

    Examples
    --------
    >>> measured_problem("speed_mps", 18.0) is None
    True
    >>> measured_problem("speed_mps", -5.0)[:22]
    'must be from 0 to 100 '
    >>> measured_problem("x_m", "610")
    "must be a finite number (got '610')"
    """
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    if not (ok and math.isfinite(value)):
        return f"must be a finite number (got {value!r})"
    bound = measured_bounds().get(field)
    if bound is not None:
        limit, units, why = bound
        if not 0 <= value <= limit:
            return f"must be from 0 to {limit:.4g} {units} ({why})"
    return None
