"""The falling body for a reduction: mass, contact radius and radius of gyration.

Either given directly (``--mass``, ``--radius``, ``--gyration``; any may be missing,
and the columns that need it stay NaN) or from a thesis Table 4-1 shape with its
dimensions and unit weight (``--shape ellipsoid --dimensions 1.6,1.3,1.3
--unit-weight 26``), computed by :func:`fieldkit.physics.bodies.shape_body`.

Dimensions follow that module (Table 4-1's own symbols): cube ``L`` (side length),
sphere ``r`` (RADIUS), cylinder ``L,r`` (length, radius), ellipsoid ``2a,2b,2c`` (the
three full AXIS LENGTHS, rotation about c). ``--radius`` may override the shape's
contact radius (Tornado boulder A: the ellipsoid gives r = (a + b)/2 = 0.725 m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fieldkit.errors import ArgumentError, FieldkitError
from fieldkit.physics.bodies import SHAPES, UNIT_WEIGHT_KN_M3, Body, shape_body

NAN = float("nan")


@dataclass(frozen=True)
class BodyProperties:
    """Body properties used for every row of a path (NaN where not given).

    Attributes
    ----------
    mass_kg, radius_m, gyration_m
        Mass m [kg], contact radius r [m] and radius of gyration k [m] (I = m k^2).
    description
        One line saying where the values came from, for the printed summary.
    """

    mass_kg: float = NAN
    radius_m: float = NAN
    gyration_m: float = NAN
    description: str = "no body given"


def parse_dimensions(text: str | None) -> tuple[float, ...] | None:
    """``"1.6,1.3,1.3"`` -> ``(1.6, 1.3, 1.3)`` [m]; raises naming ``--dimensions``.

    Examples
    --------
    >>> parse_dimensions("1.6, 1.3,1.3")
    (1.6, 1.3, 1.3)
    """
    if text is None:
        return None
    values = []
    for cell in text.replace(";", ",").split(","):
        try:
            value = float(cell)
        except ValueError:
            raise ArgumentError(
                f"{cell.strip()!r} is not a number (give lengths in metres, e.g. "
                "1.6,1.3,1.3)",
                source="--dimensions",
            ) from None
        values.append(value)
    return tuple(values)


def _check(value: float | None, option: str) -> float:
    if value is None:
        return NAN
    if not math.isfinite(value) or value <= 0:
        raise ArgumentError(f"must be a positive number (got {value:g})", source=option)
    return float(value)


def resolve_body(
    *,
    mass_kg: float | None = None,
    radius_m: float | None = None,
    gyration_m: float | None = None,
    shape: str | None = None,
    dimensions_m: tuple[float, ...] | None = None,
    unit_weight_kn_m3: float | None = None,
) -> BodyProperties:
    """Resolve the body options into :class:`BodyProperties`.

    Parameters
    ----------
    mass_kg, radius_m, gyration_m
        Given directly [kg, m, m]. With ``shape``, only ``radius_m`` may be given
        (it overrides the shape's contact radius).
    shape
        ``cube``, ``sphere``, ``cylinder`` or ``ellipsoid`` (thesis Table 4-1).
    dimensions_m
        The shape's dimensions [m] (see the module docstring).
    unit_weight_kn_m3
        Rock unit weight [kN/m^3]; default 26 (thesis Table 2-6).

    Raises
    ------
    ArgumentError
        Naming the option: non-positive values, a shape with ``--mass`` or
        ``--gyration``, a shape without dimensions, dimensions without a shape, or
        ``k > r`` for a body given directly.

    Examples
    --------
    >>> b = resolve_body(shape="ellipsoid", dimensions_m=(1.6, 1.3, 1.3))
    >>> round(b.mass_kg), round(b.radius_m, 3), round(b.gyration_m, 2)
    (3752, 0.725, 0.46)
    >>> resolve_body(mass_kg=3750.0).radius_m
    nan
    """
    if shape is None:
        if dimensions_m is not None:
            raise ArgumentError("dimensions need --shape", source="--dimensions")
        if unit_weight_kn_m3 is not None:
            raise ArgumentError("a unit weight needs --shape", source="--unit-weight")
        m = _check(mass_kg, "--mass")
        r = _check(radius_m, "--radius")
        k = _check(gyration_m, "--gyration")
        if math.isfinite(r) and math.isfinite(k) and math.isfinite(m):
            try:
                Body(mass_kg=m, radius_m=r, gyration_m=k)
            except FieldkitError as exc:
                raise ArgumentError(exc.message, source="--gyration") from None
        given = [
            f"{name} {value:g} {unit}"
            for name, value, unit in (("m", m, "kg"), ("r", r, "m"), ("k", k, "m"))
            if math.isfinite(value)
        ]
        text = ", ".join(given) if given else "no body given"
        return BodyProperties(m, r, k, text)

    name = shape.strip().lower()
    if name not in SHAPES:
        raise ArgumentError(
            f"unknown shape {shape!r}; use one of {', '.join(SHAPES)}", source="--shape"
        )
    for value, option in ((mass_kg, "--mass"), (gyration_m, "--gyration")):
        if value is not None:
            raise ArgumentError(
                f"give either {option} or --shape with --dimensions, not both",
                source=option,
            )
    if dimensions_m is None:
        names = ", ".join(SHAPES[name].dimension_names)
        raise ArgumentError(
            f"--shape {name} needs --dimensions ({names} in metres)", source="--shape"
        )
    gamma = (
        UNIT_WEIGHT_KN_M3
        if unit_weight_kn_m3 is None
        else _check(unit_weight_kn_m3, "--unit-weight")
    )
    r_override = None if radius_m is None else _check(radius_m, "--radius")
    try:
        body = shape_body(name, dimensions_m, gamma, radius_m=r_override)
    except FieldkitError as exc:
        option = (
            "--radius" if "radius_m" in exc.message and r_override else "--dimensions"
        )
        raise ArgumentError(exc.message, source=option) from None
    dims = " x ".join(f"{d:g}" for d in dimensions_m)
    text = (
        f"{name} {dims} m at {gamma:g} kN/m3: m {body.mass_kg:.0f} kg, "
        f"r {body.radius_m:.3f} m, k {body.gyration_m:.3f} m"
    )
    return BodyProperties(body.mass_kg, body.radius_m, body.gyration_m, text)
