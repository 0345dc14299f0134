"""Slope materials: restitution, friction and roughness of one ground (Table 7-1).

A :class:`Material` holds what RocFall and CRSP users enter per slope material: the
normal and tangential coefficients of restitution (eqs. 4.6, 4.7), the friction angle
of the sliding/rolling phase (eq. 7.3), each with an optional standard deviation
(fieldkit's default SD is 0, stated; RocFall's Table 7-1 footnote suggests 0.04 for
the coefficients), and the two roughness measures of the ``slope_roughness`` effect:
CRSP's roughness ``s`` [m] (eq. 7.4) and RocFall's SD of the segment dip [deg].
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from fieldkit.errors import InputFileError

#: Material fields: name -> (lower bound, upper bound, unit, meaning).
MATERIAL_FIELDS: dict[str, tuple[float, float, str, str]] = {
    "e_n": (0.0, math.inf, "-", "normal coefficient of restitution (eq. 4.6)"),
    "e_t": (0.0, math.inf, "-", "tangential coefficient of restitution (eq. 4.7)"),
    "friction_deg": (0.0, 89.0, "deg", "friction angle of sliding/rolling (eq. 7.3)"),
    "e_n_sd": (0.0, math.inf, "-", "SD of e_n, drawn per impact"),
    "e_t_sd": (0.0, math.inf, "-", "SD of e_t, drawn per impact"),
    "friction_deg_sd": (
        0.0,
        45.0,
        "deg",
        "SD of the friction angle, per segment entry",
    ),
    "roughness_m": (0.0, math.inf, "m", "CRSP roughness s of eq. 7.4"),
    "roughness_deg_sd": (0.0, 45.0, "deg", "RocFall SD of the segment dip"),
}
REQUIRED = ("e_n", "e_t", "friction_deg")


@dataclass(frozen=True)
class Material:
    """One slope material (see the module docstring and :data:`MATERIAL_FIELDS`)."""

    name: str
    e_n: float
    e_t: float
    friction_deg: float
    e_n_sd: float = 0.0
    e_t_sd: float = 0.0
    friction_deg_sd: float = 0.0
    roughness_m: float = 0.0
    roughness_deg_sd: float = 0.0

    @classmethod
    def from_dict(cls, name: str, data: object, *, source: str = "") -> Material:
        """Validate a model-file entry ``materials.<name>``; one-line errors.

        Examples
        --------
        >>> Material.from_dict("rock", {"e_n": 0.5, "e_t": 0.9, "friction_deg": 30}).e_t
        0.9
        """
        where = f"materials.{name}"
        if not isinstance(data, dict):
            raise InputFileError("must be an object", source=source, where=where)
        known = {f.name for f in fields(cls)} - {"name"}
        for key in data:
            if key not in known:
                raise InputFileError(
                    f"unknown field (known: {', '.join(sorted(known))})",
                    source=source,
                    where=f"{where}.{key}",
                )
        for key in REQUIRED:
            if key not in data:
                raise InputFileError("missing", source=source, where=f"{where}.{key}")
        values = {}
        for key, value in data.items():
            lower, upper, unit, _ = MATERIAL_FIELDS[key]
            values[key] = check_number(
                value, lower, upper, source=source, where=f"{where}.{key}", unit=unit
            )
        return cls(name=name, **values)


def check_number(
    value: object,
    lower: float,
    upper: float,
    *,
    source: str,
    where: str,
    unit: str = "",
) -> float:
    """``value`` as a float in ``[lower, upper]``, else a one-line InputFileError."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputFileError(
            f"must be a number (got {value!r})", source=source, where=where
        )
    number = float(value)
    if math.isnan(number):
        raise InputFileError("must be a number (got NaN)", source=source, where=where)
    unit = "" if unit in ("", "-") else f" {unit}"
    if number < lower:
        raise InputFileError(
            f"must be >= {lower:g}{unit} (got {number:g})", source=source, where=where
        )
    if number > upper:
        raise InputFileError(
            f"must be <= {upper:g}{unit} (got {number:g})", source=source, where=where
        )
    return number
