"""Rock bodies: mass, contact radius and radius of gyration (thesis Table 4-1).

A :class:`Body` is what the impact equations need: mass ``m`` [kg], contact radius ``r``
[m] (distance from the centre of mass to the contact point, thesis Fig. 4.6) and radius
of gyration ``k`` [m] about the rotation axis, so that ``I = m k^2`` (eq. 4.18).

:data:`SHAPES` is the registry of Table 4-1 (cube, sphere, cylinder, ellipsoid) and
:func:`shape_body` turns a shape and its measured dimensions into a :class:`Body`.

Dimensions per shape (Table 4-1's own symbols, all in metres):

========== ===================== ==================================================
shape      ``dimensions_m``      notes
========== ===================== ==================================================
cube       ``(L,)``              side length; k = L/sqrt(6), r = L/2 (Table 2-6)
sphere     ``(r,)``              radius (not diameter); k = r sqrt(2/5), r = r
cylinder   ``(L, r)``            length and radius; tumbling about the axis through
                                 mid-height, k = sqrt((3 r^2 + L^2)/12),
                                 r_contact = (r + L/2)/2 (mean of the two half-extents)
ellipsoid  ``(2a, 2b, 2c)``      the three AXIS LENGTHS (Table 4-1 "axes 2a, 2b, 2c";
                                 Table 2-6 "axes lengths 1.6, 1.3, 1.3 m"); rotation
                                 about axis c, k = sqrt((a^2 + b^2)/5),
                                 r_contact = (a + b)/2 (worked example 6B)
========== ===================== ==================================================

Example: Tornado Mountain boulder A, ``shape_body("ellipsoid", (1.6, 1.3, 1.3))`` gives
a = 0.8, b = c = 0.65, k = 0.46 m, volume 1.42 m^3, m = 3752 kg at 26 kN/m^3 and a
contact radius of 0.725 m (thesis 6B, 6C; Table 2-6 quotes r = 0.8 = a instead - pass
``radius_m`` to override).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from fieldkit.errors import ArgumentError
from fieldkit.physics.constants import G

#: Default rock unit weight [kN/m^3] used by the thesis (Table 2-6).
UNIT_WEIGHT_KN_M3 = 26.0


def _require_positive(name: str, value: float) -> float:
    """Return ``value`` as float, or raise ArgumentError naming ``name``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ArgumentError(f"{name} must be a number (got {value!r})") from None
    if not math.isfinite(number) or number <= 0.0:
        raise ArgumentError(f"{name} must be > 0 (got {number:g})")
    return number


@dataclass(frozen=True)
class Shape:
    """One row of thesis Table 4-1.

    Attributes
    ----------
    name
        Registry key (``"cube"``, ``"sphere"``, ``"cylinder"``, ``"ellipsoid"``).
    dimension_names
        What ``dimensions_m`` means, in order (Table 4-1 symbols).
    volume
        ``dimensions -> volume`` [m^3].
    gyration
        ``dimensions -> k`` [m] about the rotation axis of Table 4-1.
    contact_radius
        ``dimensions -> default contact radius r`` [m].
    contact_radius_range
        ``dimensions -> (smallest, largest)`` distance from the centre to the surface in
        the plane of rotation [m]; a contact radius outside it is impossible.
    rotation_axis
        Which axis the body tumbles about (Table 4-1).
    """

    name: str
    dimension_names: tuple[str, ...]
    volume: Callable[[Sequence[float]], float]
    gyration: Callable[[Sequence[float]], float]
    contact_radius: Callable[[Sequence[float]], float]
    contact_radius_range: Callable[[Sequence[float]], tuple[float, float]]
    rotation_axis: str


def _semi(dims: Sequence[float]) -> tuple[float, float, float]:
    return dims[0] / 2.0, dims[1] / 2.0, dims[2] / 2.0


#: Thesis Table 4-1: volume, radius of gyration and default contact radius per shape.
SHAPES: dict[str, Shape] = {
    "cube": Shape(
        name="cube",
        dimension_names=("L side length",),
        volume=lambda d: d[0] ** 3,
        gyration=lambda d: d[0] / math.sqrt(6.0),
        contact_radius=lambda d: d[0] / 2.0,
        contact_radius_range=lambda d: (d[0] / 2.0, d[0] / math.sqrt(2.0)),
        rotation_axis="normal to a face (or along a diagonal)",
    ),
    "sphere": Shape(
        name="sphere",
        dimension_names=("r radius",),
        volume=lambda d: 4.0 / 3.0 * math.pi * d[0] ** 3,
        gyration=lambda d: d[0] * math.sqrt(2.0 / 5.0),
        contact_radius=lambda d: d[0],
        contact_radius_range=lambda d: (d[0], d[0]),
        rotation_axis="any diameter",
    ),
    "cylinder": Shape(
        name="cylinder",
        dimension_names=("L length", "r radius"),
        volume=lambda d: math.pi * d[1] ** 2 * d[0],
        gyration=lambda d: math.sqrt((3.0 * d[1] ** 2 + d[0] ** 2) / 12.0),
        contact_radius=lambda d: (d[1] + d[0] / 2.0) / 2.0,
        contact_radius_range=lambda d: (
            min(d[1], d[0] / 2.0),
            math.hypot(d[1], d[0] / 2.0),
        ),
        rotation_axis="transverse, through mid-height (tumbling)",
    ),
    "ellipsoid": Shape(
        name="ellipsoid",
        dimension_names=("2a axis length", "2b axis length", "2c axis length"),
        volume=lambda d: 4.0 / 3.0 * math.pi * math.prod(_semi(d)),
        gyration=lambda d: math.sqrt((_semi(d)[0] ** 2 + _semi(d)[1] ** 2) / 5.0),
        contact_radius=lambda d: (_semi(d)[0] + _semi(d)[1]) / 2.0,
        contact_radius_range=lambda d: (
            min(_semi(d)[:2]),
            max(_semi(d)[:2]),
        ),
        rotation_axis="axis c (the third dimension)",
    ),
}

#: Shapes for which k <= r must hold whatever the dimensions (all mass within r).
_COMPACT = (None, "sphere", "cube")


@dataclass(frozen=True)
class Body:
    """A rock as the impact equations see it.

    Parameters
    ----------
    mass_kg
        Mass m [kg], > 0.
    radius_m
        Contact radius r [m], > 0: centre of mass to contact point (thesis Fig. 4.6).
    gyration_m
        Radius of gyration k [m], > 0, with ``I = m k^2``. For a body without a shape,
        or a sphere or cube, ``k <= r`` is required (every mass point lies within r of
        the centre; a thin hoop is the limit k = r). Elongated shapes (cylinder,
        ellipsoid) landing on a flat side can have k > r; :func:`shape_body` checks
        their contact radius against the dimensions instead.
    volume_m3
        Volume [m^3] if known, > 0.
    shape
        A key of :data:`SHAPES`, or None.

    Raises
    ------
    ArgumentError
        Naming the argument, e.g. ``"mass_kg must be > 0 (got -3)"``.

    Examples
    --------
    >>> body = Body(mass_kg=1000.0, radius_m=0.5, gyration_m=0.3)
    >>> round(body.inertia_kgm2, 6)
    90.0
    """

    mass_kg: float
    radius_m: float
    gyration_m: float
    volume_m3: float | None = None
    shape: str | None = None

    def __post_init__(self) -> None:
        for name in ("mass_kg", "radius_m", "gyration_m"):
            object.__setattr__(self, name, _require_positive(name, getattr(self, name)))
        if self.volume_m3 is not None:
            object.__setattr__(
                self, "volume_m3", _require_positive("volume_m3", self.volume_m3)
            )
        if self.shape is not None and self.shape not in SHAPES:
            raise ArgumentError(
                f"shape must be one of {', '.join(SHAPES)} (got {self.shape!r})"
            )
        if self.shape in _COMPACT and self.gyration_m > self.radius_m * (1 + 1e-9):
            what = "a body" if self.shape is None else f"a {self.shape}"
            raise ArgumentError(
                f"gyration_m must be <= radius_m for {what} "
                f"(got k = {self.gyration_m:g} m > r = {self.radius_m:g} m; "
                "a solid sphere has k = 0.63 r, a thin hoop k = r)"
            )

    @property
    def inertia_kgm2(self) -> float:
        """Moment of inertia ``I = m k^2`` [kg m^2] (eq. 4.18)."""
        return self.mass_kg * self.gyration_m**2

    @property
    def density_kg_m3(self) -> float | None:
        """Mass over volume [kg/m^3], or None when the volume is unknown."""
        return None if self.volume_m3 is None else self.mass_kg / self.volume_m3


def _dimensions(
    shape: Shape, dimensions_m: Sequence[float] | float
) -> tuple[float, ...]:
    if isinstance(dimensions_m, int | float):
        values: tuple[float, ...] = (dimensions_m,)
    else:
        values = tuple(dimensions_m)
    expected = len(shape.dimension_names)
    if len(values) != expected:
        names = ", ".join(shape.dimension_names)
        raise ArgumentError(
            f"dimensions_m for a {shape.name} must be {expected} value(s): {names} "
            f"(got {len(values)})"
        )
    return tuple(_require_positive("dimensions_m", v) for v in values)


def shape_body(
    shape: str,
    dimensions_m: Sequence[float] | float,
    unit_weight_kn_m3: float = UNIT_WEIGHT_KN_M3,
    g: float = G,
    *,
    radius_m: float | None = None,
) -> Body:
    """A :class:`Body` from a Table 4-1 shape and its dimensions.

    Parameters
    ----------
    shape
        ``"cube"``, ``"sphere"``, ``"cylinder"`` or ``"ellipsoid"``.
    dimensions_m
        Table 4-1 symbols [m]: cube ``(L,)``; sphere ``(r,)`` (radius); cylinder
        ``(L, r)`` (length, radius); ellipsoid ``(2a, 2b, 2c)`` (axis LENGTHS, rotation
        about c). See the module docstring.
    unit_weight_kn_m3
        Rock unit weight gamma [kN/m^3]; mass = volume * gamma * 1000 / g.
    g
        Gravitational acceleration [m/s^2].
    radius_m
        Contact radius override [m] (e.g. Table 2-6 uses r = a = 0.8 m for boulder A);
        must lie within the shape's smallest and largest half-extent in the plane of
        rotation. Default: the shape's contact radius (see module docstring).

    Returns
    -------
    Body
        With ``volume_m3`` and ``shape`` filled in.

    Examples
    --------
    Tornado Mountain boulder A (thesis Table 4-1 example, worked examples 6B/6C):

    >>> body = shape_body("ellipsoid", (1.6, 1.3, 1.3))
    >>> round(body.gyration_m, 2), round(body.volume_m3, 2), round(body.mass_kg)
    (0.46, 1.42, 3752)
    >>> round(body.radius_m, 3), round(body.inertia_kgm2)
    (0.725, 797)
    """
    if shape not in SHAPES:
        raise ArgumentError(f"shape must be one of {', '.join(SHAPES)} (got {shape!r})")
    spec = SHAPES[shape]
    dims = _dimensions(spec, dimensions_m)
    gamma = _require_positive("unit_weight_kn_m3", unit_weight_kn_m3)
    volume = spec.volume(dims)
    mass = volume * gamma * 1000.0 / _require_positive("g", g)
    radius = spec.contact_radius(dims)
    if radius_m is not None:
        radius = _require_positive("radius_m", radius_m)
        low, high = spec.contact_radius_range(dims)
        if not low * (1 - 1e-9) <= radius <= high * (1 + 1e-9):
            raise ArgumentError(
                f"radius_m must be between {low:g} and {high:g} m for this {shape} "
                f"(got {radius:g})"
            )
    return Body(
        mass_kg=mass,
        radius_m=radius,
        gyration_m=spec.gyration(dims),
        volume_m3=volume,
        shape=shape,
    )
