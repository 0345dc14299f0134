"""The ground a track's contacts are on: the dip psi the contact code asks for.

The contact code (:func:`fieldkit.tracking.flights.contact_impacts.build_impact_table`)
asks a :class:`Ground` for the dip of the surface at each contact, so one slope per
track (:class:`ConstantGround`, ``fieldkit track --surface-angle``) and one slope per
contact (a surveyed section, :class:`ProfileGround`; a DEM cut by a section line,
:class:`DemSectionGround`) are the same to it. Every impact row records the dip it used
(``slope_deg``) and where it came from (``slope_source``: ``given``, ``profile``,
``dem``).

Frames. A ground is given in the calibrated frame of the track: ``x`` horizontal (for
a DEM, the plan distance along the section line from its first point), ``z`` up. A
video track whose body travels toward -x is stored mirrored (``x -> -x``,
``meta["mirrored_x"]``, :mod:`fieldkit.tracking.video.pipeline`);
:func:`in_track_frame` turns the ground to match. :meth:`Ground.dip_deg` answers in the
ImpactTable's travel frame (docs/architecture.md §2: positive when the ground descends
in the direction of travel), so for a body travelling toward -x a profile's dip changes
sign; a constant angle is already given along travel.

How the local slope is computed:

* profile: the dip of the profile segment nearest the body's centre at the contact
  (the segment the body touches: at a kink the centre lies within one radius of the
  segment it meets, and farther from the other);
* DEM: a least-squares plane ``z = a + b e + c n`` through the DEM (bilinear) sampled
  on a square grid of :data:`~fieldkit.io.dem.FOOTPRINT_SAMPLES` x
  :data:`~fieldkit.io.dem.FOOTPRINT_SAMPLES` points clipped to a disc of the footprint
  radius around the plan point below the centre
  (:func:`fieldkit.io.dem.footprint_offsets`, :func:`fieldkit.io.dem.footprint_plane`:
  the same plane ``fieldkit track3d`` fits at a 3-D contact);
  the dip is that plane's slope along the section line, ``psi = -atan(b u_e + c u_n)``
  (``u`` the line's unit plan direction). The footprint radius is stated by the
  caller (default: the body radius, at least one DEM cell, so that the fit sees more
  than the one bilinear cell).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.dem import (
    INSIDE,
    DemGrid,
    footprint_offsets,
    footprint_plane,
)


class Ground(Protocol):
    """What the contact code needs of the ground: its dip at the contacts."""

    #: ``slope_source`` of the impact rows: ``given``, ``profile`` or ``dem``.
    source: str

    @property
    def description(self) -> str:
        """One line stating how the slope at a contact is computed."""
        ...

    def dip_deg(self, x_m: np.ndarray, z_m: np.ndarray, travel: float) -> np.ndarray:
        """Dip psi [deg] at contacts centred at ``(x_m, z_m)`` (track frame), positive
        descending along travel; ``travel`` is +1 toward +x, -1 toward -x."""
        ...


@dataclass(frozen=True)
class ConstantGround:
    """One dip for every contact (``--surface-angle``), given along travel.

    Examples
    --------
    >>> ConstantGround(15.0).dip_deg(np.array([0.0, 1.0]), np.zeros(2), -1.0).tolist()
    [15.0, 15.0]
    """

    angle_deg: float
    source: str = "given"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.angle_deg) and -180.0 < self.angle_deg <= 180.0):
            raise ArgumentError(
                "surface_angle_deg must be a dip in (-180, 180] deg "
                f"(docs/architecture.md §2), got {self.angle_deg:g}",
                source="surface_angle_deg",
            )

    @property
    def description(self) -> str:
        return f"one surface angle for every contact: {self.angle_deg:g} deg (given)"

    def dip_deg(self, x_m: np.ndarray, z_m: np.ndarray, travel: float) -> np.ndarray:
        return np.full(np.shape(x_m), float(self.angle_deg))


def _nearest_segment(
    px: np.ndarray, pz: np.ndarray, x: float, z: float
) -> tuple[int, float]:
    """Index of the polyline segment nearest ``(x, z)`` and the distance to it [m]."""
    ax, az = px[:-1], pz[:-1]
    dx, dz = np.diff(px), np.diff(pz)
    length2 = dx * dx + dz * dz
    s = np.clip(((x - ax) * dx + (z - az) * dz) / length2, 0.0, 1.0)
    distance = np.hypot(ax + s * dx - x, az + s * dz - z)
    i = int(np.argmin(distance))
    return i, float(distance[i])


@dataclass(frozen=True)
class ProfileGround:
    """A surveyed section: the dip of the segment nearest each contact's centre.

    Parameters
    ----------
    x_m, z_m
        Profile vertices in the track's frame [m], x strictly increasing (as
        :func:`fieldkit.io.profile_csv.read_profile_csv` and a model file's
        ``profile`` give them).
    name
        Where the profile came from, for the description.

    Examples
    --------
    >>> g = ProfileGround(np.array([0.0, 1.0, 2.0]), np.array([0.0, -0.2, -1.2]))
    >>> [round(float(d), 3) for d in g.dip_deg(np.array([0.5, 1.6]),
    ...                                        np.array([0.0, -0.5]), 1.0)]
    [11.31, 45.0]
    """

    x_m: np.ndarray
    z_m: np.ndarray
    name: str = "profile"
    source: str = "profile"

    def __post_init__(self) -> None:
        x = np.asarray(self.x_m, float)
        z = np.asarray(self.z_m, float)
        if x.ndim != 1 or x.shape != z.shape or len(x) < 2:
            raise ArgumentError(
                "a ground profile needs matching x_m, z_m with at least 2 vertices",
                source="ground_profile",
            )
        if (
            not (np.isfinite(x).all() and np.isfinite(z).all())
            or (np.diff(x) <= 0).any()
        ):
            raise ArgumentError(
                "a ground profile needs finite vertices with x strictly increasing",
                source="ground_profile",
            )
        object.__setattr__(self, "x_m", x)
        object.__setattr__(self, "z_m", z)

    @property
    def description(self) -> str:
        return (
            f"slope at each contact: the dip of the segment of {self.name} "
            f"({len(self.x_m) - 1} segments) nearest the body's centre"
        )

    def dip_deg(self, x_m: np.ndarray, z_m: np.ndarray, travel: float) -> np.ndarray:
        segment_dip = -np.degrees(np.arctan2(np.diff(self.z_m), np.diff(self.x_m)))
        out = np.empty(np.shape(x_m))
        for k, (x, z) in enumerate(zip(np.ravel(x_m), np.ravel(z_m), strict=True)):
            i, _ = _nearest_segment(self.x_m, self.z_m, float(x), float(z))
            out.flat[k] = travel * segment_dip[i]
        return out

    def distance_m(self, x_m: float, z_m: float) -> float:
        """Distance [m] of the point ``(x_m, z_m)`` from the profile line."""
        return _nearest_segment(self.x_m, self.z_m, float(x_m), float(z_m))[1]


@dataclass(frozen=True)
class DemSectionGround:
    """A DEM cut by a straight section line: a plane fitted over the block's footprint.

    Parameters
    ----------
    grid
        The DEM (:func:`fieldkit.io.dem.read_dem`).
    start_m, end_m
        Plan points (e, n) [m] of the section line in the DEM's CRS; the track's x is
        the plan distance from ``start_m`` toward ``end_m``.
    footprint_m
        Radius [m] of the disc the plane is fitted over (module docstring).

    Examples
    --------
    A plane descending 0.25 m per metre toward +e, cut along e:

    >>> e = np.arange(0.0, 20.0, 1.0)
    >>> grid = DemGrid.from_corner(np.tile(50 - 0.25 * (e + 0.5), (20, 1)),
    ...                            x_left_m=0, y_top_m=20, cellsize_m=1)
    >>> g = DemSectionGround(grid, (2.0, 10.0), (18.0, 10.0), footprint_m=1.5)
    >>> round(float(g.dip_deg(np.array([5.0]), np.array([0.0]), 1.0)[0]), 6)
    14.036243
    """

    grid: DemGrid
    start_m: tuple[float, float]
    end_m: tuple[float, float]
    footprint_m: float
    source: str = "dem"

    def __post_init__(self) -> None:
        length = math.hypot(
            self.end_m[0] - self.start_m[0], self.end_m[1] - self.start_m[1]
        )
        if not length > 0:
            raise ArgumentError(
                "the section line's two plan points are identical",
                source="section_line",
            )
        if not (math.isfinite(self.footprint_m) and self.footprint_m > 0):
            raise ArgumentError(
                f"footprint_m must be > 0 (got {self.footprint_m:g})",
                source="footprint_m",
            )

    @property
    def direction(self) -> tuple[float, float]:
        """Unit plan direction (e, n) of the section line."""
        de, dn = self.end_m[0] - self.start_m[0], self.end_m[1] - self.start_m[1]
        length = math.hypot(de, dn)
        return de / length, dn / length

    @property
    def description(self) -> str:
        n = len(self._offsets()[0])
        return (
            "slope at each contact: a plane fitted to the DEM "
            f"{self.grid.source or ''} over a disc of radius {self.footprint_m:.3g} m "
            f"({n} bilinear samples; cell {self.grid.cellsize_m:g} m) below the "
            "centre, its dip along the section line "
            f"({self.start_m[0]:g},{self.start_m[1]:g} -> "
            f"{self.end_m[0]:g},{self.end_m[1]:g})"
        ).replace("DEM  over", "DEM over")

    def _offsets(self) -> tuple[np.ndarray, np.ndarray]:
        return footprint_offsets(self.footprint_m)

    def plane_at(self, x_m: float) -> tuple[float, float]:
        """The fitted plane below section x ``x_m`` [m]: its height there [m] and
        its slope along the section line (dz per metre of x).

        Raises
        ------
        InputFileError
            Naming the DEM, when the footprint reaches off the grid or into nodata.
        """
        ue, un = self.direction
        de, dn = self._offsets()
        e0 = self.start_m[0] + float(x_m) * ue
        n0 = self.start_m[1] + float(x_m) * un
        z, _, _, status = self.grid.sample(e0 + de, n0 + dn)
        if (status != INSIDE).any():
            raise InputFileError(
                f"the contact at section x {float(x_m):.3f} m (plan {e0:.2f}, "
                f"{n0:.2f}) has DEM cells off the grid or nodata within "
                f"{self.footprint_m:g} m",
                source=self.grid.source or None,
            )
        a, b, c, _ = footprint_plane(de, dn, z)
        return a, b * ue + c * un

    def dip_deg(self, x_m: np.ndarray, z_m: np.ndarray, travel: float) -> np.ndarray:
        out = np.empty(np.shape(x_m))
        for k, x in enumerate(np.ravel(x_m)):
            _, slope = self.plane_at(float(x))
            out.flat[k] = travel * -math.degrees(math.atan(slope))
        return out

    def distance_m(self, x_m: float, z_m: float) -> float:
        """Distance [m] of the point ``(x_m, z_m)`` from the fitted plane below it
        (the track's z must then be elevation in the DEM's datum)."""
        height, slope = self.plane_at(float(x_m))
        return abs(float(z_m) - height) / math.sqrt(1.0 + slope * slope)


@dataclass(frozen=True)
class MirroredGround:
    """``ground`` seen from a track stored with ``x -> -x`` (:func:`in_track_frame`).

    Examples
    --------
    >>> g = ProfileGround(np.array([0.0, 1.0, 2.0]), np.array([0.0, -0.2, -1.2]))
    >>> m = MirroredGround(g)  # travel toward +x in the track: up this profile
    >>> float(m.dip_deg(np.array([-1.6]), np.array([-0.5]), 1.0)[0])
    -45.0
    """

    ground: Ground

    @property
    def source(self) -> str:
        return self.ground.source

    @property
    def description(self) -> str:
        return self.ground.description

    def dip_deg(self, x_m: np.ndarray, z_m: np.ndarray, travel: float) -> np.ndarray:
        return self.ground.dip_deg(-np.asarray(x_m, float), z_m, -travel)

    def distance_m(self, x_m: float, z_m: float) -> float:
        return self.ground.distance_m(-float(x_m), z_m)  # type: ignore[attr-defined]


def in_track_frame(ground: Ground | None, meta: dict) -> Ground | None:
    """``ground`` (given in the calibrated frame) in the frame of a track with
    metadata ``meta``: mirrored when the track was stored with ``x -> -x``
    (``meta["mirrored_x"]``). A constant angle is given along travel and stays."""
    if ground is None or isinstance(ground, ConstantGround):
        return ground
    return MirroredGround(ground) if meta.get("mirrored_x") else ground
