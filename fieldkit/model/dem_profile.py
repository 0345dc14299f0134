"""A slope section cut from a DEM: along a polyline, or the line of steepest descent.

The section is what the 2-D simulator runs on (:class:`fieldkit.model.profile.Profile`
takes ``chainage_m``, ``z_m`` and ``material``): chainage is the *horizontal* distance
along the plan line [m], z the bilinear DEM elevation (:meth:`DemGrid.elevation`), and
each segment between two vertices has one material, assigned from chainage ranges.

Two ways to choose the plan line:

* :func:`profile_along_polyline` -- through given plan vertices, each leg sampled at
  equal steps no longer than ``spacing_m`` (vertices kept exactly). A line leaving
  the grid, or crossing nodata, is an error naming the DEM file and the point.
* :func:`steepest_descent_line` -- the path a particle follows straight down the
  slope from a release point: the curve tangent to ``-grad z``.

Steepest descent: the numerical method
--------------------------------------
Fixed-step normalised gradient descent on the bilinear surface, with step halving:

1. at the current point p, the gradient g of the bilinear surface of the cell holding
   p (exact for that surface, :meth:`DemGrid.sample`); stop if ``|g|`` is below
   ``flat_slope`` (a flat area);
2. a midpoint (second-order Runge-Kutta) step of length h along ``-g/|g|``: the
   direction is taken at ``p + (h/2) d0``, which follows a curving fall line with an
   error O(h^3) per step instead of O(h^2);
3. the step is kept only if z decreases; otherwise h is halved (down to
   ``step_m / 64``) -- in a valley whose two sides meet at a crease a full step would
   cross the thalweg and climb the far side. When no step down is found the point is
   a local minimum (a pit, or a thalweg too flat to resolve), and the line stops;
4. a step leaving the cell-centre rectangle of the grid is cut at the edge (bisection
   to 1e-6 of the step) and the line stops there ("reached the grid edge"); likewise
   a step into cells of nodata stops the line at the last point with data;
5. the line also stops after ``max_length_m`` of plan length.

``step_m`` may be at most half the cell size, so every cell the line crosses gets at
least two gradient evaluations, and at least :data:`MIN_STEP_CELLS` of it: the
bilinear surface is smooth inside a cell, so a shorter step resolves nothing more, it
only multiplies the vertices (a step of 1e-9 m never ends). No section has more than
:data:`MAX_SECTION_VERTICES` vertices: a polyline or a ``max_length_m`` that would
need more is refused before any work; the default length (the grid's width plus
height) is not, and a line reaching the limit stops there ("vertex limit"). z
decreases strictly along the line by construction.
On a tilted plane the line is the straight fall line; on a cone or a bowl it is radial
(tests/model/test_dem_profile.py checks both).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.dem import INSIDE, NODATA, OUTSIDE, DemGrid
from fieldkit.model.materials import MATERIAL_NAME, check_material_name

#: Material of every segment when no chainage ranges are given.
DEFAULT_MATERIAL = "ground"

#: Default ``flat_slope``: a gradient below 0.1 per cent (0.06 deg) is flat.
FLAT_SLOPE = 1e-3

#: Step halvings before a point counts as a local minimum (h down to step_m / 64).
_HALVINGS = 6

#: Shortest steepest-descent step, as a fraction of the cell size: the bilinear
#: surface is smooth inside a cell, so shorter steps add vertices, not accuracy.
MIN_STEP_CELLS = 0.01

#: Most vertices in a section: 20 km at 1 m, ten times the longest rockfall slope.
#: Steepest descent takes about 1 ms a vertex (a loaded 2-core machine: 100,000
#: vertices took 110 s), so the limit also bounds a run to about 20 s.
MAX_SECTION_VERTICES = 20_000

#: How a steepest-descent line may end (:attr:`Section.ending`).
ENDINGS = (
    "local minimum", "flat area", "grid edge", "nodata", "maximum length",
    "vertex limit",
)  # fmt: skip


@dataclass(frozen=True)
class Section:
    """A vertical section through a DEM.

    Attributes
    ----------
    chainage_m
        ``(n,)`` horizontal distance along the plan line from its start [m],
        strictly increasing.
    z_m
        ``(n,)`` ground elevation [m].
    plan_x_m, plan_y_m
        ``(n,)`` plan coordinates of the vertices, in the DEM's grid [m].
    material
        ``(n-1,)`` material of each segment.
    ending
        How the line ended: ``"end of polyline"``, or one of :data:`ENDINGS` for a
        steepest-descent line.
    source
        The DEM file.
    """

    chainage_m: np.ndarray
    z_m: np.ndarray
    plan_x_m: np.ndarray
    plan_y_m: np.ndarray
    material: tuple[str, ...]
    ending: str = "end of polyline"
    source: str = ""

    @property
    def length_m(self) -> float:
        """Horizontal length [m]."""
        return float(self.chainage_m[-1])

    @property
    def drop_m(self) -> float:
        """Elevation of the start less that of the end [m]."""
        return float(self.z_m[0] - self.z_m[-1])

    def with_materials(self, ranges: str | Sequence[MaterialRange]) -> Section:
        """The section with vertices added at the range boundaries and the materials
        of :func:`assign_materials` (so a material changes exactly where a range says).

        Examples
        --------
        >>> s = Section(np.array([0.0, 10.0]), np.array([5.0, 0.0]), np.zeros(2),
        ...             np.array([0.0, 10.0]), ("ground",))
        >>> t = s.with_materials("0-4:rock,4-:talus")
        >>> t.chainage_m.tolist(), t.z_m.tolist(), t.material
        ([0.0, 4.0, 10.0], [5.0, 3.0, 0.0], ('rock', 'talus'))
        """
        parsed = parse_material_ranges(ranges)
        c = self.chainage_m
        cuts = [r.start_m for r in parsed] + [
            r.end_m for r in parsed if r.end_m is not None
        ]
        new = np.array([b for b in cuts if c[0] < b < c[-1] and not np.isclose(c, b,
                        rtol=0, atol=1e-9).any()])  # fmt: skip
        chainage = np.union1d(c, new)
        section = replace(
            self,
            chainage_m=chainage,
            z_m=np.interp(chainage, c, self.z_m),
            plan_x_m=np.interp(chainage, c, self.plan_x_m),
            plan_y_m=np.interp(chainage, c, self.plan_y_m),
        )
        return replace(section, material=assign_materials(chainage, parsed))


@dataclass(frozen=True)
class MaterialRange:
    """One chainage range ``start_m``-``end_m`` [m] (``end_m`` None: to the end)."""

    start_m: float
    end_m: float | None
    material: str


_RANGE = re.compile(
    r"^\s*(?P<start>[^-:]+?)\s*-\s*(?P<end>[^:]*?)\s*:\s*(?P<name>.+?)\s*$"
)


def parse_material_ranges(ranges: str | Sequence[MaterialRange]) -> list[MaterialRange]:
    """Ranges from text ``"0-40:rock,40-:talus"`` (metres of chainage), checked.

    The ranges, sorted by start, must begin at chainage 0 and meet end to start: a
    gap or an overlap is an error naming both ranges. Only the last may be open
    (``40-``); a closed last range leaves the section beyond it without a material,
    which :func:`assign_materials` refuses if the section is longer.

    Examples
    --------
    >>> [(r.start_m, r.end_m, r.material) for r in
    ...  parse_material_ranges("40-:talus, 0-40:rock")]
    [(0.0, 40.0, 'rock'), (40.0, None, 'talus')]
    >>> parse_material_ranges("0-40:rock,50-:talus")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.ArgumentError: ranges: no material between chainage 40 and 50 m...
    """
    if isinstance(ranges, str):
        items = []
        for part in ranges.split(","):
            match = _RANGE.match(part)
            if not part.strip() or match is None:
                raise ArgumentError(
                    f"'{part.strip()}' is not START-END:MATERIAL (e.g. 0-40:rock, "
                    "or 40-:talus for the rest of the section)",
                    source="ranges",
                )
            start = _range_number(match["start"], part)
            end = None if not match["end"] else _range_number(match["end"], part)
            if not MATERIAL_NAME.fullmatch(match["name"]):
                raise ArgumentError(
                    f"material name '{match['name']}' in '{part.strip()}': use "
                    "1-64 letters, digits, _ . - (starting with a letter or _)",
                    source="ranges",
                )
            items.append(MaterialRange(start, end, match["name"]))
    else:
        items = list(ranges)
    if not items:
        raise ArgumentError("no chainage ranges given", source="ranges")
    items.sort(key=lambda r: r.start_m)

    def text(r: MaterialRange) -> str:
        end = "" if r.end_m is None else f"{r.end_m:g}"
        return f"{r.start_m:g}-{end}:{r.material}"

    if items[0].start_m != 0:
        raise ArgumentError(
            f"the first range {text(items[0])} must start at chainage 0",
            source="ranges",
        )
    for i, r in enumerate(items):
        if r.end_m is not None and not r.end_m > r.start_m:
            raise ArgumentError(
                f"range {text(r)} ends before it starts", source="ranges"
            )
        if i + 1 < len(items):
            nxt = items[i + 1]
            if r.end_m is None or r.end_m > nxt.start_m:
                raise ArgumentError(
                    f"ranges {text(r)} and {text(nxt)} overlap", source="ranges"
                )
            if r.end_m < nxt.start_m:
                raise ArgumentError(
                    f"no material between chainage {r.end_m:g} and {nxt.start_m:g} m "
                    f"(ranges {text(r)} and {text(nxt)})",
                    source="ranges",
                )
    return items


def _range_number(text: str, part: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise ArgumentError(
            f"'{text}' in '{part.strip()}' is not a chainage >= 0 (m)", source="ranges"
        )
    return value


def assign_materials(
    chainage_m: np.ndarray, ranges: str | Sequence[MaterialRange]
) -> tuple[str, ...]:
    """The material of each segment: the range holding the segment's midpoint.

    Parameters
    ----------
    chainage_m
        ``(n,)`` vertex chainages [m], increasing.
    ranges
        ``"0-40:rock,40-:talus"`` or :class:`MaterialRange` items
        (:func:`parse_material_ranges`).

    Returns
    -------
    tuple of str
        ``(n-1,)`` material names. A segment straddling a boundary takes the
        material at its midpoint: use :meth:`Section.with_materials` to cut
        segments at the boundaries first.

    Raises
    ------
    ArgumentError
        Gaps, overlaps, malformed text, or a section running past the last closed
        range.

    Examples
    --------
    >>> assign_materials(np.array([0.0, 30.0, 50.0, 80.0]), "0-40:rock,40-:talus")
    ('rock', 'talus', 'talus')
    """
    parsed = parse_material_ranges(ranges)
    c = np.asarray(chainage_m, dtype=float)
    last = parsed[-1]
    if last.end_m is not None and c[-1] > last.end_m + 1e-9:
        raise ArgumentError(
            f"no material beyond chainage {last.end_m:g} m (the section is "
            f"{c[-1]:.1f} m long): end the last range open, e.g. "
            f"{last.start_m:g}-:{last.material}",
            source="ranges",
        )
    starts = np.array([r.start_m for r in parsed])
    middle = 0.5 * (c[:-1] + c[1:])
    index = np.searchsorted(starts, middle, side="right") - 1
    return tuple(parsed[i].material for i in index)


def section_from_vertices(
    x_m: np.ndarray,
    z_m: np.ndarray,
    material: Sequence[str] | None = None,
    *,
    plan_x_m: np.ndarray | None = None,
    plan_y_m: np.ndarray | None = None,
    source: str = "",
) -> Section:
    """A :class:`Section` from section vertices (a profile CSV).

    ``plan_x_m``/``plan_y_m`` None: NaN (no plan line); ``material`` None: every segment
    :data:`DEFAULT_MATERIAL`; :attr:`Section.ending` ``"end of the CSV"``.

    Examples
    --------
    >>> section_from_vertices(np.array([0.0, 5.0]), np.array([3.0, 1.0])).material
    ('ground',)
    """
    x = np.asarray(x_m, dtype=float)
    nan = np.full(x.shape, np.nan)
    names = (DEFAULT_MATERIAL,) * (len(x) - 1) if material is None else tuple(material)
    for name in dict.fromkeys(names):  # one rule for material names (materials.py)
        check_material_name(name, source=source, where="material")
    return Section(
        chainage_m=x,
        z_m=np.asarray(z_m, dtype=float),
        plan_x_m=nan if plan_x_m is None else np.asarray(plan_x_m, dtype=float),
        plan_y_m=nan.copy() if plan_y_m is None else np.asarray(plan_y_m, dtype=float),
        material=names,
        ending="end of the CSV",
        source=source,
    )


def _number(value: object, name: str) -> float:
    """``value`` as a float; an :class:`ArgumentError` naming ``name`` for anything
    but a real number (text, a list, an object, true/false)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
        raise ArgumentError(
            f"{name} must be a number (got {_shown(value)})", source=name
        )
    return float(value)


def _shown(value: object) -> str:
    """``value`` as a short one-line text for a message."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 40 else text[:37] + "..."


def _check_step(value: float, name: str, grid: DemGrid | None = None) -> float:
    """A step > 0; with ``grid`` (steepest descent) between :data:`MIN_STEP_CELLS`
    of the cell size and half of it."""
    value = _number(value, name)
    if not (math.isfinite(value) and value > 0):
        raise ArgumentError(f"{name} must be > 0 (got {value:g})", source=name)
    if grid is not None and value > grid.cellsize_m / 2 + 1e-12:
        raise ArgumentError(
            f"{name} must be <= half the cell size, {grid.cellsize_m / 2:g} m "
            f"(got {value:g})",
            source=name,
        )
    if grid is not None and value < MIN_STEP_CELLS * grid.cellsize_m * (1 - 1e-9):
        raise ArgumentError(
            f"{name} must be >= {MIN_STEP_CELLS:g} of the cell size, "
            f"{MIN_STEP_CELLS * grid.cellsize_m:g} m (got {value:g}): a shorter step "
            "adds vertices, not accuracy, on the bilinear surface of a cell",
            source=name,
        )
    return value


def _check_vertex_count(count: float, name: str, step: float, over: str = "") -> None:
    """Refuse a section of more than :data:`MAX_SECTION_VERTICES` vertices
    (``over``: the length they cover, for the message)."""
    if count > MAX_SECTION_VERTICES:
        raise ArgumentError(
            f"{name} {step:g} m{over} would make about {count:.3g} section vertices, "
            f"more than the limit of {MAX_SECTION_VERTICES:,}: give a longer step or a "
            "shorter line",
            source=name,
        )


def _check_points(points, name: str, minimum: int) -> np.ndarray:
    """``points`` as ``(k, 2)`` finite plan coordinates, k >= ``minimum``."""
    wanted = "[x, y]" if minimum == 1 else "a list of [x, y] points"
    try:
        if isinstance(points, (str, bytes, dict)):
            raise TypeError
        xy = np.asarray(points, dtype=float)
        pair = xy.shape == (2,)
        pairs = xy.ndim == 2 and xy.shape[1:] == (2,)
        if not (pair if minimum == 1 else pairs):
            raise ValueError
    except (TypeError, ValueError):
        raise ArgumentError(
            f"{name} must be {wanted} in metres (got {_shown(points)})", source=name
        ) from None
    xy = xy.reshape(-1, 2)
    if len(xy) < minimum:
        raise ArgumentError(
            f"{name} needs at least {minimum} plan points (got {len(xy)})", source=name
        )
    if not np.isfinite(xy).all():
        raise ArgumentError(f"{name} must be finite numbers", source=name)
    return xy


def profile_along_polyline(
    grid: DemGrid,
    vertices_xy: Sequence[Sequence[float]] | np.ndarray,
    spacing_m: float,
) -> Section:
    """The DEM section under a plan polyline.

    Parameters
    ----------
    grid
        The DEM.
    vertices_xy
        ``(k, 2)`` plan vertices (x, y) [m] in the DEM's coordinates, k >= 2.
    spacing_m
        Longest step between section vertices [m]; each leg is cut into equal steps.

    Returns
    -------
    Section
        Every segment material :data:`DEFAULT_MATERIAL` (see
        :meth:`Section.with_materials`).

    Raises
    ------
    ArgumentError
        Fewer than two vertices, a repeated vertex, spacing <= 0.
    InputFileError
        A section point outside the grid or on nodata: names the DEM file, the leg,
        the point and its chainage.

    Examples
    --------
    >>> g = DemGrid.from_corner(np.array([[10.0, 10.0], [0.0, 0.0]]), x_left_m=0,
    ...                         y_top_m=2, cellsize_m=1)
    >>> s = profile_along_polyline(g, [(1.0, 1.5), (1.0, 0.5)], 0.5)
    >>> s.chainage_m.tolist(), s.z_m.tolist()
    ([0.0, 0.5, 1.0], [10.0, 5.0, 0.0])
    """
    xy = _check_points(vertices_xy, "vertices_xy", 2)
    step = _check_step(spacing_m, "spacing_m")
    legs = np.hypot(*np.diff(xy, axis=0).T)
    _check_vertex_count(1 + float(np.ceil(legs / step).sum()), "spacing_m", step)
    if (legs <= 0).any():
        i = int(np.flatnonzero(legs <= 0)[0])
        raise ArgumentError(
            f"vertices_xy points {i + 1} and {i + 2} are the same point "
            f"({xy[i, 0]:g}, {xy[i, 1]:g})",
            source="vertices_xy",
        )
    xs, ys, legs_of = [xy[:1, 0]], [xy[:1, 1]], [np.array([0])]
    for i, length in enumerate(legs):
        n = max(1, math.ceil(length / step - 1e-9))
        f = np.arange(1, n + 1) / n
        xs.append(xy[i, 0] + f * (xy[i + 1, 0] - xy[i, 0]))
        ys.append(xy[i, 1] + f * (xy[i + 1, 1] - xy[i, 1]))
        legs_of.append(np.full(n, i))
    x, y, leg = np.concatenate(xs), np.concatenate(ys), np.concatenate(legs_of)
    chainage = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])
    z, _, _, status = grid.sample(x, y)
    bad = np.flatnonzero(status != INSIDE)
    if bad.size:
        i = int(bad[0])
        k = int(leg[i])
        what = "leaves the grid" if status[i] == OUTSIDE else "crosses nodata"
        raise InputFileError(
            f"the line {what} at (x, y) = ({x[i]:.2f}, {y[i]:.2f}), chainage "
            f"{chainage[i]:.1f} m, on the leg from ({xy[k, 0]:g}, {xy[k, 1]:g}) to "
            f"({xy[k + 1, 0]:g}, {xy[k + 1, 1]:g}): "
            + grid.problem_at(x[i], y[i], int(status[i])),
            source=grid.source,
        )
    return Section(
        chainage_m=chainage,
        z_m=z,
        plan_x_m=x,
        plan_y_m=y,
        material=(DEFAULT_MATERIAL,) * (len(x) - 1),
        source=grid.source,
    )


def _direction(grid: DemGrid, x: float, y: float) -> tuple[float, float, float] | None:
    """Unit down-slope direction and slope magnitude at (x, y), None off the data."""
    _, gx, gy, status = grid.sample(x, y)
    if status[0] != INSIDE:
        return None
    norm = math.hypot(gx[0], gy[0])
    if norm == 0:
        return 0.0, 0.0, 0.0
    return -gx[0] / norm, -gy[0] / norm, norm


def descent_steps(
    grid: DemGrid, step_m: float, max_length_m: float | None = None
) -> tuple[float, float, int]:
    """Check a steepest descent's step and length before any work.

    Returns
    -------
    step_m, max_length_m, steps
        The step, the length (None: the grid's width plus height) and the most
        steps the line can take (below :data:`MAX_SECTION_VERTICES`).

    Raises
    ------
    ArgumentError
        A step outside :data:`MIN_STEP_CELLS` .. half the cell size; a
        ``max_length_m`` <= 0, or one needing more than :data:`MAX_SECTION_VERTICES`
        vertices at this step.
    """
    h = _check_step(step_m, "step_m", grid)
    given = max_length_m is not None
    if max_length_m is None:
        nrows, ncols = grid.shape
        max_length_m = (ncols - 1) * grid.dx_m + (nrows - 1) * grid.dy_m
    length = _number(max_length_m, "max_length_m")
    if not (math.isfinite(length) and length > 0):
        raise ArgumentError(
            f"max_length_m must be > 0 (got {length:g})", source="max_length_m"
        )
    if given:
        _check_vertex_count(
            1 + math.ceil(length / h), "step_m", h, f" over max_length_m {length:g} m"
        )
    return h, length, min(math.ceil(length / h), MAX_SECTION_VERTICES - 1)


def steepest_descent_line(
    grid: DemGrid,
    start_xy: Sequence[float],
    step_m: float,
    *,
    max_length_m: float | None = None,
    flat_slope: float = FLAT_SLOPE,
    progress: Callable[[int, int], None] | None = None,
) -> Section:
    """The line of steepest descent from a release point (method: module docstring).

    Parameters
    ----------
    grid
        The DEM.
    start_xy
        Release point (x, y) [m]; must lie on data inside the grid.
    step_m
        Plan step [m], between :data:`MIN_STEP_CELLS` of the cell size and half
        of it.
    max_length_m
        Stop after this plan length [m] (None: the grid's width plus height).
    flat_slope
        Stop where the slope (tan of the dip) is below this (default 0.001).
    progress
        Called as ``progress(steps_done, steps_at_most)`` every 100 vertices.

    Returns
    -------
    Section
        Vertices every ``step_m`` (shorter where steps were halved or at the end),
        z strictly decreasing; :attr:`Section.ending` says why it stopped.

    Raises
    ------
    ArgumentError
        A bad ``step_m``, ``max_length_m`` or ``flat_slope``.
    InputFileError
        The start is outside the grid or on nodata (names the DEM file), or the
        ground is flat at the start.

    Examples
    --------
    >>> g = DemGrid.from_corner(np.add.outer(np.zeros(5), -np.arange(5.0)),
    ...                         x_left_m=0, y_top_m=5, cellsize_m=1)  # z = -x + 0.5
    >>> s = steepest_descent_line(g, (1.0, 2.5), 0.5)
    >>> s.ending, s.length_m, s.drop_m, set(s.plan_y_m.round(9).tolist())
    ('grid edge', 3.5, 3.5, {2.5})
    """
    h, max_length_m, at_most = descent_steps(grid, step_m, max_length_m)
    if not (math.isfinite(flat_slope) and flat_slope >= 0):
        raise ArgumentError(
            f"flat_slope must be >= 0 (got {flat_slope:g})", source="flat_slope"
        )
    start = _check_points(start_xy, "start_xy", 1)[0]
    z0, _, _, status = grid.sample(start[0], start[1])
    if status[0] != INSIDE:
        raise InputFileError(
            f"the start (x, y) = ({start[0]:g}, {start[1]:g}) has no elevation: "
            + grid.problem_at(start[0], start[1], int(status[0])),
            source=grid.source,
        )
    x, y, z = [float(start[0])], [float(start[1])], [float(z0[0])]
    length, ending = 0.0, "maximum length"
    while length < max_length_m - 1e-9:
        if len(x) >= MAX_SECTION_VERTICES:  # the default length, or halved steps
            ending = "vertex limit"
            break
        if progress is not None and len(x) % 100 == 0:
            progress(min(len(x), at_most), at_most)
        here = _direction(grid, x[-1], y[-1])
        assert here is not None  # every kept point is on data
        dx0, dy0, slope = here
        if slope < flat_slope:
            ending = "flat area"
            break
        step = min(h, max_length_m - length)
        moved = None
        for _ in range(_HALVINGS + 1):
            moved = _midpoint_step(grid, x[-1], y[-1], dx0, dy0, step, z[-1])
            if moved[0] != "climbs":
                break
            step /= 2
        kind, nx, ny, nz = moved
        if kind == "climbs":
            ending = "local minimum"
            break
        if kind != "ok":  # grid edge or nodata: cut the step at the boundary
            nx, ny, nz = _last_point_on_data(grid, x[-1], y[-1], nx, ny, z[-1])
            ending = "grid edge" if kind == "outside" else "nodata"
            if nx is not None:
                length += math.hypot(nx - x[-1], ny - y[-1])
                x.append(nx), y.append(ny), z.append(nz)
            break
        length += math.hypot(nx - x[-1], ny - y[-1])
        x.append(nx), y.append(ny), z.append(nz)
    if len(x) < 2:
        raise InputFileError(
            f"the ground at the start (x, y) = ({start[0]:g}, {start[1]:g}) does not "
            f"fall ({ending}): no line of steepest descent",
            source=grid.source,
        )
    px, py = np.array(x), np.array(y)
    chainage = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(px), np.diff(py)))])
    return Section(
        chainage_m=chainage,
        z_m=np.array(z),
        plan_x_m=px,
        plan_y_m=py,
        material=(DEFAULT_MATERIAL,) * (len(px) - 1),
        ending=ending,
        source=grid.source,
    )


def _midpoint_step(grid, x, y, dx0, dy0, step, z_here):
    """One midpoint step: ``(kind, x, y, z)`` with kind ok, climbs, outside, nodata."""
    mid = _direction(grid, x + 0.5 * step * dx0, y + 0.5 * step * dy0)
    if mid is None or mid[2] == 0:
        dx, dy = dx0, dy0  # the midpoint is off the data: take the first direction
    else:
        dx, dy = mid[0], mid[1]
    nx, ny = x + step * dx, y + step * dy
    z, _, _, status = grid.sample(nx, ny)
    if status[0] == OUTSIDE:
        return "outside", nx, ny, math.nan
    if status[0] == NODATA:
        return "nodata", nx, ny, math.nan
    if not z[0] < z_here:
        return "climbs", nx, ny, float(z[0])
    return "ok", nx, ny, float(z[0])


def _last_point_on_data(grid, x0, y0, x1, y1, z0):
    """The last point with data on the segment (x0, y0)-(x1, y1), by bisection, if
    it is lower than z0; else (None, None, None)."""
    lo, hi = 0.0, 1.0
    for _ in range(40):
        t = 0.5 * (lo + hi)
        _, _, _, status = grid.sample(x0 + t * (x1 - x0), y0 + t * (y1 - y0))
        lo, hi = (t, hi) if status[0] == INSIDE else (lo, t)
    x, y = x0 + lo * (x1 - x0), y0 + lo * (y1 - y0)
    z = float(grid.sample(x, y)[0][0])
    if lo * math.hypot(x1 - x0, y1 - y0) < 1e-6 or not z < z0:
        return None, None, None
    return x, y, z
