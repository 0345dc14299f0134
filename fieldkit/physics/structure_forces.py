"""Time-force laws of rigid, flexible and stiff protection structures (section 8.3).

The thesis idealises the force a structure develops during the contact as a power law of
time, ``F = c t^x`` (eqs. 8.2-8.4):

* rigid wall ``F = n t`` (x = 1, eq. 8.2), n = 1e6 N/s for mass concrete;
* flexible fence ``F = a t^x`` with x > 1 (eq. 8.3), a = 4e4, x = 2.0;
* stiff (attenuator) fence ``F = b t^x`` with x < 1 (eq. 8.4), b = 3e4, x = 0.6.

The impulse absorbed up to time t is the area under the curve,
``p = c t^(x+1) / (x+1)`` (eqs. 8.5-8.7). The contact lasts until the rock's impulse
``m v_i`` is absorbed, ``t = ((x+1) p / c)^(1/(x+1))``, and the force then is the peak
force. For the thesis's example (520 kg at 22 m/s, p = 11,440 N s) this gives
t = 0.15, 0.95, 0.73 s and F = 151, 36.1 and 24.9 kN: the thesis prints 22.0 kN for the
stiff structure, which its own law does not give (docs/thesis-notes.md erratum), so the
stiff fence carries 16 % of the rigid wall's force and 69 % of the flexible fence's
(printed: 15 % and 61 %).

The coefficient ``c`` has units N s^-x (the thesis writes [M L T^-3] for n).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics._validate import as_output, nonnegative_array, raise_at_first

__all__ = [
    "THESIS_STRUCTURES",
    "StructureLaw",
    "contact_time",
    "force_at",
    "impulse_absorbed",
    "peak_force",
]


@dataclass(frozen=True)
class StructureLaw:
    """A time-force law ``F = coefficient * t^exponent`` (eqs. 8.2-8.4).

    Attributes
    ----------
    name
        ``"rigid"``, ``"flexible"``, ``"stiff"`` or a user label.
    coefficient
        n, a or b [N s^-exponent], > 0.
    exponent
        x [-], > 0: 1 for rigid, > 1 flexible, < 1 stiff.
    equation
        Thesis equation of the force law.
    """

    name: str
    coefficient: float
    exponent: float
    equation: str = ""

    def __post_init__(self) -> None:
        for name, value in (
            ("coefficient", self.coefficient),
            ("exponent", self.exponent),
        ):
            raise_at_first(
                ~(np.isfinite(value) & (value > 0)),
                lambda v, name=name: (
                    f"{self.name} structure {name} must be positive (got {v:g})"
                ),
                value,
                source=name,
            )


#: The three illustrative structures of section 8.3.2 (Figs. 8.6-8.8).
THESIS_STRUCTURES: dict[str, StructureLaw] = {
    "rigid": StructureLaw("rigid", 1.0e6, 1.0, "8.2"),
    "flexible": StructureLaw("flexible", 4.0e4, 2.0, "8.3"),
    "stiff": StructureLaw("stiff", 3.0e4, 0.6, "8.4"),
}


def force_at(law: StructureLaw, t_s: ArrayLike) -> np.ndarray:
    """Force in the structure ``t`` seconds into the contact [N] (eqs. 8.2-8.4).

    Examples
    --------
    >>> float(force_at(THESIS_STRUCTURES["flexible"], 0.5))
    10000.0
    """
    t = nonnegative_array(t_s, "t_s")
    return as_output(law.coefficient * t**law.exponent)


def impulse_absorbed(law: StructureLaw, t_s: ArrayLike) -> np.ndarray:
    """Impulse absorbed by the structure up to time t [N s] (eqs. 8.5-8.7).

    ``p = c t^(x+1) / (x+1)``; for the rigid wall ``p = n t^2 / 2`` (eq. 8.5).

    Examples
    --------
    >>> round(float(impulse_absorbed(THESIS_STRUCTURES["rigid"], 0.1)), 6)
    5000.0
    """
    t = nonnegative_array(t_s, "t_s")
    x = law.exponent
    return as_output(law.coefficient * t ** (x + 1.0) / (x + 1.0))


def contact_time(law: StructureLaw, impulse_ns: ArrayLike) -> np.ndarray:
    """Contact duration needed to absorb ``impulse_ns`` [s] (eqs. 8.5-8.7 inverted).

    ``t = ((x+1) p / c)^(1/(x+1))``.

    Examples
    --------
    Section 8.3.2: 520 kg at 22 m/s, rigid wall with n = 1e6 -> 0.15 s:

    >>> round(float(contact_time(THESIS_STRUCTURES["rigid"], 520 * 22.0)), 2)
    0.15
    """
    p = nonnegative_array(impulse_ns, "impulse_ns")
    x = law.exponent
    return as_output(((x + 1.0) * p / law.coefficient) ** (1.0 / (x + 1.0)))


def peak_force(law: StructureLaw, impulse_ns: ArrayLike) -> np.ndarray:
    """Force at the end of the contact that absorbs ``impulse_ns`` [N].

    Examples
    --------
    Section 8.3.2, stiff fence (b = 3e4, x = 0.6): 24.9 kN (thesis prints 22.0 kN,
    an arithmetic slip; see the module docstring):

    >>> round(float(peak_force(THESIS_STRUCTURES["stiff"], 11440.0)) / 1e3, 1)
    24.9
    """
    return as_output(np.asarray(force_at(law, contact_time(law, impulse_ns))))
