"""Slope materials: restitution, friction and roughness of one ground (Table 7-1).

A :class:`Material` holds what RocFall and CRSP users enter per slope material: the
normal and tangential coefficients of restitution (eqs. 4.6, 4.7), the friction angle
of the sliding/rolling phase (eq. 7.3), each with an optional standard deviation
(fieldkit's default SD is 0, stated; RocFall's Table 7-1 footnote suggests 0.04 for
the coefficients), and the two roughness measures of the ``slope_roughness`` effect:
CRSP's roughness ``s`` [m] (eq. 7.4) and RocFall's SD of the segment dip [deg].

Every field has a finite bound (:data:`MATERIAL_FIELDS`), chosen so that a value
outside it is a typing or unit error rather than a ground:

* ``e_n`` in [0, 5]: ``e_n > 1`` is legal for shallow impacts (docs/architecture.md
  §2; eq. 5.4 gives e_n = 3.7 at 5 deg with the thesis' a = 19.5, b = 1.03) but a
  constant ground coefficient above 5 multiplies the normal speed five-fold at
  every impact;
* ``e_t`` in [0, 2]: measured ``e_t`` exceed 1 only where spin turns into
  translation (flagged ``e_t > 1`` in an ImpactTable, up to about 1.5); a constant
  above 2 would double the tangential speed at every impact;
* the SDs of ``e_n`` and ``e_t`` at most half their mean's range (2.5, 1): a wider
  spread is all truncation at 0;
* ``friction_deg`` in [0, 89] deg (tan 90 deg is infinite), its SD <= 45 deg;
* ``roughness_m`` <= 10 m: CRSP's roughness is the height of the ground's
  irregularities felt by a block (classes up to ~3 m); ``roughness_deg_sd`` <= 45.

A material **name** (:func:`check_material_name`) is 1 to 64 characters: letters,
digits, ``_``, ``.`` and ``-``, starting with a letter or ``_`` (``rock``,
``talus_2``, ``Geröll``). The name is written into other programs' files (RocFall's
``material 1: name`` lines, CSV columns, chainage ranges ``0-40:rock``), where a
comma, colon, ``#``, quote or line break would change their meaning and a leading
``=`` would make a spreadsheet run it.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, fields

from fieldkit.errors import InputFileError

#: Material fields: name -> (lower bound, upper bound, unit, meaning); the bounds
#: are explained in the module docstring.
MATERIAL_FIELDS: dict[str, tuple[float, float, str, str]] = {
    "e_n": (0.0, 5.0, "-", "normal coefficient of restitution (eq. 4.6)"),
    "e_t": (0.0, 2.0, "-", "tangential coefficient of restitution (eq. 4.7)"),
    "friction_deg": (0.0, 89.0, "deg", "friction angle of sliding/rolling (eq. 7.3)"),
    "e_n_sd": (0.0, 2.5, "-", "SD of e_n, drawn per impact"),
    "e_t_sd": (0.0, 1.0, "-", "SD of e_t, drawn per impact"),
    "friction_deg_sd": (
        0.0,
        45.0,
        "deg",
        "SD of the friction angle, per segment entry",
    ),
    "roughness_m": (0.0, 10.0, "m", "CRSP roughness s of eq. 7.4"),
    "roughness_deg_sd": (0.0, 45.0, "deg", "RocFall SD of the segment dip"),
}
REQUIRED = ("e_n", "e_t", "friction_deg")
#: A material name (module docstring): letters, digits, ``_ . -``, at most 64.
MATERIAL_NAME = re.compile(r"[^\W\d][\w.-]{0,63}")


def check_material_name(name: object, *, source: str, where: str) -> str:
    """``name`` if it is a valid material name, else a one-line InputFileError.

    Examples
    --------
    >>> check_material_name("talus_2", source="m.json", where="materials")
    'talus_2'
    >>> check_material_name("=cmd|x", source="m.json", where="materials")
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.InputFileError: m.json: materials: material name '=cmd|x' ...
    """
    if isinstance(name, str) and MATERIAL_NAME.fullmatch(name):
        return name
    raise InputFileError(
        f"material name {name!r} is not allowed: use 1-64 letters, digits, _ . - "
        "starting with a letter or _",
        source=source,
        where=where,
    )


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
        check_material_name(name, source=source, where="materials")
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
    whole: bool = False,
) -> float:
    """``value`` as a finite float in ``[lower, upper]``, else a one-line
    InputFileError (NaN and +-Infinity are refused whatever the bounds).

    ``whole``: the field counts something, so it must be a whole number (``500``
    or ``500.0``, not ``500.5``).

    Examples
    --------
    >>> check_number(500.0, 1, 1e6, source="m.json", where="core.max_impacts",
    ...              whole=True)
    500.0
    >>> check_number(500.5, 1, 1e6, source="m.json", where="core.max_impacts",
    ...              whole=True)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.InputFileError: m.json: ...: must be a whole number (got 500.5)
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputFileError(
            f"must be a number (got {_shown(value)})", source=source, where=where
        )
    try:
        number = float(value)
    except OverflowError:  # an integer beyond the float range
        number = math.inf if value > 0 else -math.inf
    if not math.isfinite(number):
        raise InputFileError(
            f"must be a finite number (got {number})", source=source, where=where
        )
    if whole and not number.is_integer():
        raise InputFileError(
            f"must be a whole number (got {number:.10g})", source=source, where=where
        )
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


def _shown(value: object) -> str:
    """A short ``repr`` of a wrong value for a one-line message."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
