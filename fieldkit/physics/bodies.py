"""Rock bodies: mass, contact radius and radius of gyration (thesis Table 4-1).

A :class:`Body` is what the impact equations need: mass ``m`` [kg], contact radius ``r``
[m] (distance from the centre of mass to the contact point, thesis Fig. 4.6) and radius
of gyration ``k`` [m] about the rotation axis, so that ``I = m k^2`` (eq. 4.18).

:data:`SHAPES` is the registry of Table 4-1 (cube, sphere, cylinder, ellipsoid) and
:func:`shape_body` turns a shape and its measured dimensions into a :class:`Body`.
:func:`resolve_body` is the one place every command turns what the user gave (mass,
radius, gyration, or a shape with its dimensions) into a :class:`ResolvedBody`, with
the rules below.

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
block      ``(L1, L2, L3)``      a natural block's measured principal lengths, any
                                 order (e.g. the Tschamut 2014 shape metadata): the
                                 solid ellipsoid of those axes rolling about the
                                 SHORTEST one (:func:`principal_gyration_m` says why),
                                 k = sqrt((L1^2 + L2^2)/20) with L1 >= L2 >= L3,
                                 r_contact = (L1 + L2)/4, volume pi L1 L2 L3 / 6
========== ===================== ==================================================

Contact radius range per shape (:attr:`Shape.contact_radius_range`): a given
``radius_m`` may replace the shape's contact radius only within the smallest and
largest distance from the centre to the surface in the plane of rotation of Table 4-1,
since the impact equations are planar:

========== ==================================== ========================================
shape      range [m]                            why
========== ==================================== ========================================
cube       L/2 to L/sqrt(2)                     face-normal axis: the section is a
                                                square (face centre to corner); about a
                                                diagonal the hexagonal section lies
                                                within the same bounds
sphere     r to r                               every contact point is r away
cylinder   min(r, L/2) to sqrt(r^2 + (L/2)^2)   the L x 2r rectangle through the axis
ellipsoid  min(a, b) to max(a, b)               the a-b ellipse (rotation about c)
block      L2/2 to L1/2                         the L1-L2 ellipse (rotation about L3)
========== ==================================== ========================================

Example: Tornado Mountain boulder A, ``shape_body("ellipsoid", (1.6, 1.3, 1.3))`` gives
a = 0.8, b = c = 0.65, k = 0.46 m, volume 1.42 m^3, m = 3752 kg at 26 kN/m^3 and a
contact radius of 0.725 m (thesis 6B, 6C; Table 2-6 quotes r = 0.8 = a instead - pass
``radius_m`` to override).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

from fieldkit.errors import ArgumentError
from fieldkit.physics.constants import G

#: Default rock unit weight [kN/m^3] used by the thesis (Table 2-6).
UNIT_WEIGHT_KN_M3 = 26.0


def _require_positive(name: str, value: float) -> float:
    """Return ``value`` as float, or raise ArgumentError naming ``name``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ArgumentError(
            f"{name} must be a number (got {value!r})", source=name
        ) from None
    if not math.isfinite(number) or number <= 0.0:
        raise ArgumentError(f"{name} must be > 0 (got {number:g})", source=name)
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
        the plane of rotation [m]; a contact radius outside it is impossible (see the
        module docstring).
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


#: Solid bodies whose principal lengths give a radius of gyration
#: (:func:`principal_gyration_m`).
GYRATION_MODELS = ("ellipsoid", "cuboid")


def principal_gyration_m(lengths_m: Sequence[float], model: str = "ellipsoid") -> float:
    """Radius of gyration k [m] of a block from its three principal lengths, about
    the axis it rolls on: its shortest principal axis.

    With ``L1 >= L2 >= L3`` the full lengths of the block along its principal axes,
    about the axis along ``L3``:

    * solid ellipsoid with axes ``L1, L2, L3`` (semi-axes ``a = L1/2``, ``b = L2/2``):
      ``I = m (a^2 + b^2) / 5``, so ``k = sqrt((L1^2 + L2^2) / 20)`` (thesis Table
      4-1, "ellipsoid"; any table of moments of inertia, e.g. Goldstein, *Classical
      Mechanics*, 3rd ed., §5.3);
    * solid cuboid ``L1 x L2 x L3``: ``I = m (L1^2 + L2^2) / 12``, so
      ``k = sqrt((L1^2 + L2^2) / 12)`` (Table 4-1's cube, ``k = L/sqrt(6)``, is its
      equal-sided case).

    **Which axis.** The shortest principal axis carries the largest moment of
    inertia. A tumbling block loses energy while its angular momentum is kept
    between contacts, so its rotation drifts to the axis of largest inertia (the
    major-axis rule: Landau & Lifshitz, *Mechanics*, §37; a lumped model carries one
    k, and this is the one a rolling block ends up with): a plate rolls on its edge
    like a wheel, not end over end. The Tschamut "Plate" (0.46 x 0.30 x 0.20 m)
    rolls about its 0.20 m axis.

    **Which solid.** The ellipsoid is the default: a natural block's measured
    (bounding) lengths enclose less rock than their box. For the three Tschamut 2014
    blocks (``tests/data/tschamut2014/block_metadata.csv``, weighed 69, 79, 40 kg)
    the ellipsoids of their lengths give densities of 3008, 2579 and 2768 kg/m^3
    (rock), their boxes 1575, 1350 and 1449 kg/m^3 (lighter than any rock). Use
    ``model="cuboid"`` for sawn or cast blocks (concrete cubes, EOTA-like bricks).

    Parameters
    ----------
    lengths_m
        The three principal lengths [m] (full lengths, not semi-axes), any order.
    model
        ``"ellipsoid"`` (default) or ``"cuboid"`` (:data:`GYRATION_MODELS`).

    Returns
    -------
    float
        k [m] about the shortest principal axis; ``I = m k^2``.

    Raises
    ------
    ArgumentError
        ``source="dimensions_m"`` for other than three positive lengths,
        ``source="model"`` for an unknown model.

    Examples
    --------
    The sphere limit (all lengths 2r) gives the solid sphere, k = r sqrt(2/5); a
    cube of side L as a cuboid gives Table 4-1's L/sqrt(6):

    >>> round(principal_gyration_m((2.0, 2.0, 2.0)) / math.sqrt(0.4), 12)
    1.0
    >>> round(principal_gyration_m((0.6, 0.6, 0.6), "cuboid") * math.sqrt(6), 12)
    0.6
    >>> round(principal_gyration_m((0.46, 0.30, 0.20)), 4)  # Tschamut "Plate"
    0.1228
    """
    if model not in GYRATION_MODELS:
        raise ArgumentError(
            f"model must be one of {', '.join(GYRATION_MODELS)} (got {model!r})",
            source="model",
        )
    values = tuple(lengths_m) if not isinstance(lengths_m, int | float) else ()
    if len(values) != 3:
        raise ArgumentError(
            f"dimensions_m must be the block's 3 principal lengths (got {len(values)})",
            source="dimensions_m",
        )
    first, second, _ = sorted(
        (_require_positive("dimensions_m", v) for v in values), reverse=True
    )
    divisor = 20.0 if model == "ellipsoid" else 12.0
    return math.sqrt((first**2 + second**2) / divisor)


def _rolling_semi_axes(dims: Sequence[float]) -> tuple[float, float]:
    """The two longer semi-axes (the plane the block rolls in) [m]."""
    first, second, _ = sorted(dims, reverse=True)
    return first / 2.0, second / 2.0


#: Thesis Table 4-1: volume, radius of gyration and default contact radius per shape,
#: and ``block``: a natural block of three measured principal lengths.
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
    "block": Shape(
        name="block",
        dimension_names=(
            "L1",
            "L2",
            "L3 principal lengths, any order",
        ),
        volume=lambda d: math.pi / 6.0 * math.prod(d),
        gyration=lambda d: principal_gyration_m(d, "ellipsoid"),
        contact_radius=lambda d: sum(_rolling_semi_axes(d)) / 2.0,
        contact_radius_range=lambda d: (
            min(_rolling_semi_axes(d)),
            max(_rolling_semi_axes(d)),
        ),
        rotation_axis="its shortest principal axis (principal_gyration_m)",
    ),
}

#: Shapes for which k <= r must hold whatever the dimensions (all mass within r).
_COMPACT = (None, "sphere", "cube")


def shape_spec(name: str) -> Shape:
    """The :data:`SHAPES` entry for ``name``, ignoring case and surrounding spaces.

    Raises
    ------
    ArgumentError
        ``source="shape"``, listing the known shapes.

    Examples
    --------
    >>> shape_spec(" Ellipsoid ").name
    'ellipsoid'
    """
    key = str(name).strip().lower()
    if key not in SHAPES:
        raise ArgumentError(
            f"shape must be one of {', '.join(SHAPES)} (got {name!r})", source="shape"
        )
    return SHAPES[key]


def _check_gyration_within_radius(
    gyration_m: float, radius_m: float, shape: str | None, name: str = "gyration_m"
) -> None:
    """``k <= r`` for a body without a shape, a sphere or a cube (see :class:`Body`).

    ``name`` is the argument k came from (``"inertia_kgm2"`` when k = sqrt(I/m)).
    """
    if shape in _COMPACT and gyration_m > radius_m * (1 + 1e-9):
        what = "a body" if shape is None else f"a {shape}"
        subject = "gyration_m" if name == "gyration_m" else f"{name} gives k that"
        raise ArgumentError(
            f"{subject} must be <= radius_m for {what} "
            f"(got k = {gyration_m:g} m > r = {radius_m:g} m; "
            "a solid sphere has k = 0.63 r, a thin hoop k = r)",
            source=name,
        )


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
                f"shape must be one of {', '.join(SHAPES)} (got {self.shape!r})",
                source="shape",
            )
        _check_gyration_within_radius(self.gyration_m, self.radius_m, self.shape)

    @property
    def inertia_kgm2(self) -> float:
        """Moment of inertia ``I = m k^2`` [kg m^2] (eq. 4.18)."""
        return self.mass_kg * self.gyration_m**2


#: Separators between dimensions: ``1.6,1.3,1.3``, ``1.6x1.3x1.3``, ``1.6 X 1.3 X 1.3``.
_DIMENSION_SEPARATOR = re.compile(r"\s*[,;xX×]\s*|\s+")


def parse_dimensions(text: str) -> tuple[float, ...]:
    """``"1.6,1.3,1.3"`` or ``"1.6 x 1.3 x 1.3"`` -> ``(1.6, 1.3, 1.3)`` [m].

    Commas, ``x`` or ``X`` (spaces around them allowed) or spaces separate the values.

    Raises
    ------
    ArgumentError
        ``source="dimensions_m"`` when a value is not a number (``"1.6,,1.3"``).

    Examples
    --------
    >>> parse_dimensions("1.6, 1.3,1.3"), parse_dimensions("1.6 X 1.3x1.3")
    ((1.6, 1.3, 1.3), (1.6, 1.3, 1.3))
    """
    try:
        return tuple(float(cell) for cell in _DIMENSION_SEPARATOR.split(text.strip()))
    except ValueError:
        raise ArgumentError(
            "dimensions_m must be numbers separated by commas or x, e.g. 1.6,1.3,1.3 "
            f"or 1.6x1.3x1.3 (got {text!r})",
            source="dimensions_m",
        ) from None


def _dimensions(
    shape: Shape, dimensions_m: Sequence[float] | float | str
) -> tuple[float, ...]:
    if isinstance(dimensions_m, str):
        values: tuple = parse_dimensions(dimensions_m)
    elif isinstance(dimensions_m, int | float):
        values = (dimensions_m,)
    else:
        values = tuple(dimensions_m)
    expected = len(shape.dimension_names)
    if len(values) != expected:
        names = ", ".join(shape.dimension_names)
        raise ArgumentError(
            f"dimensions_m for a {shape.name} must be {expected} value(s): {names} "
            f"(got {len(values)})",
            source="dimensions_m",
        )
    return tuple(_require_positive("dimensions_m", v) for v in values)


def _format_dimensions(dims: Sequence[float], separator: str = ",") -> str:
    return separator.join(f"{d:g}" for d in dims)


def shape_body(
    shape: str,
    dimensions_m: Sequence[float] | float | str,
    unit_weight_kn_m3: float = UNIT_WEIGHT_KN_M3,
    g: float = G,
    *,
    radius_m: float | None = None,
) -> Body:
    """A :class:`Body` from a Table 4-1 shape and its dimensions.

    Parameters
    ----------
    shape
        ``"cube"``, ``"sphere"``, ``"cylinder"`` or ``"ellipsoid"`` (any case).
    dimensions_m
        Table 4-1 symbols [m]: cube ``(L,)``; sphere ``(r,)`` (radius); cylinder
        ``(L, r)`` (length, radius); ellipsoid ``(2a, 2b, 2c)`` (axis LENGTHS, rotation
        about c). See the module docstring. Text such as ``"1.6x1.3x1.3"`` is parsed
        by :func:`parse_dimensions`.
    unit_weight_kn_m3
        Rock unit weight gamma [kN/m^3]; mass = volume * gamma * 1000 / g.
    g
        Gravitational acceleration [m/s^2].
    radius_m
        Contact radius override [m] (e.g. Table 2-6 uses r = a = 0.8 m for boulder A);
        must lie within the shape's contact radius range (module docstring). Default:
        the shape's contact radius.

    Returns
    -------
    Body
        With ``volume_m3`` and ``shape`` filled in.

    Raises
    ------
    ArgumentError
        Naming the argument at fault: an unknown ``shape``, wrong or non-positive
        ``dimensions_m``, ``unit_weight_kn_m3 <= 0``, or ``radius_m`` outside the
        shape's range.

    Examples
    --------
    Tornado Mountain boulder A (thesis Table 4-1 example, worked examples 6B/6C):

    >>> body = shape_body("ellipsoid", (1.6, 1.3, 1.3))
    >>> round(body.gyration_m, 2), round(body.volume_m3, 2), round(body.mass_kg)
    (0.46, 1.42, 3752)
    >>> round(body.radius_m, 3), round(body.inertia_kgm2)
    (0.725, 797)
    """
    spec = shape_spec(shape)
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
                f"radius_m must be between {low:g} and {high:g} m for `shape` "
                f"{spec.name} with `dimensions_m` {_format_dimensions(dims)} "
                f"(got {radius:g})",
                source="radius_m",
            )
    return Body(
        mass_kg=mass,
        radius_m=radius,
        gyration_m=spec.gyration(dims),
        volume_m3=volume,
        shape=spec.name,
    )


@dataclass(frozen=True)
class ResolvedBody:
    """The body a command works with: each value, where it came from, and notes.

    Made by :func:`resolve_body`; any value may be unknown (None), and a command
    states which it needs with :meth:`require`.

    Attributes
    ----------
    mass_kg, radius_m, gyration_m
        Mass m [kg], contact radius r [m], radius of gyration k [m]; None if unknown.
    mass_source, radius_source, gyration_source
        Where each known value came from: ``"given"`` (an argument), ``"shape"``
        (thesis Table 4-1), ``"inertia"`` (k = sqrt(I/m)) or ``"measured"`` (e.g. from
        a video); None when the value is unknown.
    volume_m3, shape, dimensions_m, unit_weight_kn_m3
        The shape's volume [m^3], name, dimensions [m] and unit weight [kN/m^3], or
        None without a shape.
    notes
        One-line statements the output must carry (a given value overriding the
        shape's, a measured value); arguments named in backticks.
    """

    mass_kg: float | None = None
    radius_m: float | None = None
    gyration_m: float | None = None
    mass_source: str | None = None
    radius_source: str | None = None
    gyration_source: str | None = None
    volume_m3: float | None = None
    shape: str | None = None
    dimensions_m: tuple[float, ...] | None = None
    unit_weight_kn_m3: float | None = None
    notes: tuple[str, ...] = ()

    @property
    def inertia_kgm2(self) -> float | None:
        """``I = m k^2`` [kg m^2] (eq. 4.18), or None when m or k is unknown."""
        if self.mass_kg is None or self.gyration_m is None:
            return None
        return self.mass_kg * self.gyration_m**2

    @property
    def description(self) -> str:
        """One line: the shape (if any) and the known values.

        Examples
        --------
        >>> resolve_body(mass_kg=3750, radius_m=0.725).description
        'm 3750 kg, r 0.725 m'
        """
        values = [
            f"{symbol} {value:.4g} {unit}"
            for symbol, value, unit in (
                ("m", self.mass_kg, "kg"),
                ("r", self.radius_m, "m"),
                ("k", self.gyration_m, "m"),
            )
            if value is not None
        ]
        text = ", ".join(values) if values else "no body given"
        if self.shape is None or self.dimensions_m is None:
            return text
        dims = _format_dimensions(self.dimensions_m, " x ")
        return f"{self.shape} {dims} m at {self.unit_weight_kn_m3:g} kN/m3: {text}"

    def missing(self, *names: str) -> tuple[str, ...]:
        """Which of ``names`` (``"mass_kg"``, ``"radius_m"``, ``"gyration_m"``) are
        unknown."""
        return tuple(name for name in names if getattr(self, name) is None)

    def require(self, *names: str, source: str | None = None) -> ResolvedBody:
        """Return self, or raise one error listing every unknown value of ``names``.

        Parameters
        ----------
        *names
            The values the caller needs: ``"mass_kg"``, ``"radius_m"``,
            ``"gyration_m"``.
        source
            What needs them (e.g. the calling command), for the error.

        Raises
        ------
        ArgumentError
            ``"body needs `radius_m` and `gyration_m` (or `shape`)"``.

        Examples
        --------
        >>> try:
        ...     resolve_body(mass_kg=3750).require("radius_m", "gyration_m")
        ... except ArgumentError as exc:
        ...     print(exc)
        body needs `radius_m` and `gyration_m` (or `shape`)
        """
        missing = [f"`{name}`" for name in self.missing(*names)]
        if not missing:
            return self
        listed = missing[-1]
        if len(missing) > 1:
            listed = f"{', '.join(missing[:-1])} and {listed}"
        raise ArgumentError(f"body needs {listed} (or `shape`)", source=source)

    def with_measured_radius(self, radius_m: float) -> ResolvedBody:
        """This body with an unknown contact radius set from a measurement.

        A NaN or non-positive measurement leaves the radius unknown; a given radius
        is kept. The note says the measured value is used.

        Raises
        ------
        ArgumentError
            When the measured radius is smaller than a given gyration (``k <= r``).

        Examples
        --------
        >>> body = resolve_body().with_measured_radius(0.0375)
        >>> body.radius_m, body.radius_source, body.notes
        (0.0375, 'measured', ('`radius_m` not given; using the measured 0.0375 m',))
        """
        if self.radius_m is not None or not (math.isfinite(radius_m) and radius_m > 0):
            return self
        radius = float(radius_m)
        if self.gyration_m is not None:
            _check_gyration_within_radius(self.gyration_m, radius, self.shape)
        note = f"`radius_m` not given; using the measured {radius:.4g} m"
        return replace(
            self,
            radius_m=radius,
            radius_source="measured",
            notes=(*self.notes, note),
        )


def resolve_body(
    *,
    mass_kg: float | None = None,
    radius_m: float | None = None,
    gyration_m: float | None = None,
    inertia_kgm2: float | None = None,
    shape: str | None = None,
    dimensions_m: Sequence[float] | float | str | None = None,
    unit_weight_kn_m3: float | None = None,
    g: float = G,
) -> ResolvedBody:
    """Turn what the user gave about the rock into one :class:`ResolvedBody`.

    Every command resolves its body here, so the same rules hold everywhere:

    * every given value must be > 0;
    * ``shape`` (any case) with ``dimensions_m`` gives mass, r and k by thesis
      Table 4-1; ``gyration_m`` or ``inertia_kgm2`` with a shape is an error (the
      shape gives k); a shape needs its dimensions, and ``dimensions_m`` or
      ``unit_weight_kn_m3`` without a shape is an error;
    * a given (weighed) ``mass_kg`` overrides the shape's volume x unit weight, and
      a note says so;
    * a given ``radius_m`` overrides the shape's contact radius only within the
      shape's range (module docstring; an error names both otherwise), with a note;
    * ``0 < k <= r`` whenever both are known, except for the elongated shapes
      (cylinder, ellipsoid), whose contact radius is bounded by their dimensions
      instead (see :class:`Body`);
    * ``inertia_kgm2`` gives k = sqrt(I/m) and needs ``mass_kg``; it excludes
      ``gyration_m``.

    Values nobody gave stay None; the caller states what it needs with
    :meth:`ResolvedBody.require`.

    Parameters
    ----------
    mass_kg, radius_m, gyration_m
        Mass [kg], contact radius [m] and radius of gyration [m].
    inertia_kgm2
        Moment of inertia I [kg m^2], instead of ``gyration_m``.
    shape
        ``cube``, ``sphere``, ``cylinder`` or ``ellipsoid`` (thesis Table 4-1).
    dimensions_m
        The shape's dimensions [m] (module docstring), as numbers or as text
        (``"1.6,1.3,1.3"``, ``"1.6x1.3x1.3"``).
    unit_weight_kn_m3
        Rock unit weight [kN/m^3] for a shape; default 26 (thesis Table 2-6).
    g
        Gravitational acceleration [m/s^2].

    Returns
    -------
    ResolvedBody

    Raises
    ------
    ArgumentError
        With ``source`` the argument at fault (``"mass_kg"``, ``"shape"``, ...).

    Examples
    --------
    >>> b = resolve_body(shape="Ellipsoid", dimensions_m="1.6x1.3x1.3")
    >>> round(b.mass_kg), round(b.radius_m, 3), round(b.gyration_m, 2), b.mass_source
    (3752, 0.725, 0.46, 'shape')
    >>> weighed = resolve_body(shape="ellipsoid", dimensions_m=(1.6, 1.3, 1.3),
    ...                        mass_kg=3750)
    >>> weighed.mass_kg, weighed.mass_source, len(weighed.notes)
    (3750.0, 'given', 1)
    >>> resolve_body(mass_kg=3750.0).radius_m is None
    True
    """
    given = {
        name: _require_positive(name, value)
        for name, value in (
            ("mass_kg", mass_kg),
            ("radius_m", radius_m),
            ("gyration_m", gyration_m),
            ("inertia_kgm2", inertia_kgm2),
            ("unit_weight_kn_m3", unit_weight_kn_m3),
        )
        if value is not None
    }
    if "gyration_m" in given and "inertia_kgm2" in given:
        raise ArgumentError(
            "inertia_kgm2 and `gyration_m` both give k; give one of them",
            source="inertia_kgm2",
        )
    if shape is None:
        return _direct_body(given, dimensions_m)
    spec = shape_spec(shape)
    for name in ("gyration_m", "inertia_kgm2"):
        if name in given:
            raise ArgumentError(
                f"{name} is computed from `shape` and `dimensions_m` (thesis Table "
                "4-1); give one or the other",
                source=name,
            )
    if dimensions_m is None:
        names = ", ".join(spec.dimension_names)
        raise ArgumentError(
            f"shape {spec.name} needs `dimensions_m` ({names}, in metres)",
            source="shape",
        )
    dims = _dimensions(spec, dimensions_m)
    gamma = given.get("unit_weight_kn_m3", UNIT_WEIGHT_KN_M3)
    body = shape_body(spec.name, dims, gamma, g, radius_m=given.get("radius_m"))
    notes = []
    if "mass_kg" in given:
        notes.append(
            f"`mass_kg` {given['mass_kg']:g} kg overrides the {body.mass_kg:.4g} kg "
            f"of the {spec.name} ({body.volume_m3:.3g} m3 at {gamma:g} kN/m3)"
        )
    if "radius_m" in given:
        low, high = spec.contact_radius_range(dims)
        notes.append(
            f"`radius_m` {body.radius_m:g} m overrides the {spec.name}'s contact "
            f"radius {spec.contact_radius(dims):.4g} m (range {low:.4g}-{high:.4g} m)"
        )
    return ResolvedBody(
        mass_kg=given.get("mass_kg", body.mass_kg),
        radius_m=body.radius_m,
        gyration_m=body.gyration_m,
        mass_source="given" if "mass_kg" in given else "shape",
        radius_source="given" if "radius_m" in given else "shape",
        gyration_source="shape",
        volume_m3=body.volume_m3,
        shape=spec.name,
        dimensions_m=dims,
        unit_weight_kn_m3=gamma,
        notes=tuple(notes),
    )


def _direct_body(
    given: dict[str, float], dimensions_m: Sequence[float] | float | str | None
) -> ResolvedBody:
    """The body from values given one by one (no shape)."""
    shapes = ", ".join(SHAPES)
    if dimensions_m is not None:
        raise ArgumentError(
            f"dimensions_m needs `shape` ({shapes})", source="dimensions_m"
        )
    if "unit_weight_kn_m3" in given:
        raise ArgumentError(
            "unit_weight_kn_m3 needs `shape` (it turns the shape's volume into a "
            f"mass; {shapes})",
            source="unit_weight_kn_m3",
        )
    mass, radius = given.get("mass_kg"), given.get("radius_m")
    gyration, gyration_source = given.get("gyration_m"), "given"
    if "inertia_kgm2" in given:
        if mass is None:
            raise ArgumentError(
                "inertia_kgm2 needs `mass_kg` (k = sqrt(I/m))", source="inertia_kgm2"
            )
        gyration, gyration_source = math.sqrt(given["inertia_kgm2"] / mass), "inertia"
    if gyration is not None and radius is not None:
        name = "inertia_kgm2" if gyration_source == "inertia" else "gyration_m"
        _check_gyration_within_radius(gyration, radius, None, name)
    return ResolvedBody(
        mass_kg=mass,
        radius_m=radius,
        gyration_m=gyration,
        mass_source=None if mass is None else "given",
        radius_source=None if radius is None else "given",
        gyration_source=None if gyration is None else gyration_source,
    )


def sphere_density_kg_m3(mass_kg: float, radius_m: float) -> float:
    """Density of a solid sphere of ``mass_kg`` and ``radius_m``: m / (4/3 pi r^3)
    (the sphere a lumped-mass or sphere-only simulator puts in a block's place).

    Examples
    --------
    >>> round(sphere_density_kg_m3(4 / 3 * math.pi * 2650, 1.0), 6)
    2650.0
    """
    return mass_kg / (4.0 / 3.0 * math.pi * radius_m**3)
