"""The local ground at a contact: a plane fitted to the DEM over the block's footprint.

The DEM's surface is the 3-D simulator's (:class:`fieldkit.model.terrain.Terrain`:
bilinear between cell centres). At a contact the plane ``z = a + b (x - x0) + c (y -
y0)`` is fitted by least squares to that surface at the points of a square grid
over a disc of radius ``footprint_m`` about the contact's plan position (the block's
radius by default: the ground it can touch) -- the footprint and the fit of
:func:`fieldkit.io.dem.footprint_offsets` and :func:`fieldkit.io.dem.footprint_plane`,
shared with the 2-D tracks' DEM ground (:mod:`fieldkit.tracking.flights.ground`).
N is the plane's upward unit normal. Over a disc inside one DEM patch the fit gives
the bilinear surface's own gradient at the centre exactly (the twist term is
orthogonal to a plane over a symmetric disc), so on a simulated run N is the normal
the simulator used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fieldkit.io.dem import footprint_offsets, footprint_plane
from fieldkit.model.terrain import Terrain


@dataclass(frozen=True)
class LocalPlane:
    """The fitted ground plane at a plan position.

    Attributes
    ----------
    z_m
        The plane's height at the position [m].
    normal
        Upward unit normal (3-vector).
    points
        DEM points the plane was fitted to (off-surface points are left out).
    rms_m
        Root-mean-square misfit of the DEM points to the plane [m].
    """

    z_m: float
    normal: np.ndarray
    points: int
    rms_m: float

    def distance(self, xyz_m: np.ndarray, x_m: float, y_m: float) -> float:
        """Signed distance of a point above the plane, along N [m]."""
        ground = np.array([x_m, y_m, self.z_m])
        return float((np.asarray(xyz_m, float) - ground) @ self.normal)


def local_plane(
    terrain: Terrain, x_m: float, y_m: float, footprint_m: float
) -> LocalPlane | None:
    """The ground plane over a disc of radius ``footprint_m`` about ``(x_m, y_m)``.

    Returns None when fewer than half the disc's points lie on the DEM's surface.

    Examples
    --------
    >>> t = Terrain(0.0, 0.0, 1.0, np.add.outer(np.zeros(4), -0.5 * np.arange(4)))
    >>> p = local_plane(t, 1.5, 1.5, 0.2)
    >>> [round(float(v), 4) + 0.0 for v in p.normal], round(p.z_m, 6)
    ([0.4472, 0.0, 0.8944], -0.5)
    """
    dx, dy = footprint_offsets(footprint_m)
    z = terrain.heights(x_m + dx, y_m + dy)
    ok = np.isfinite(z)
    if ok.sum() < dx.size / 2:
        return None
    a, b, c, rms = footprint_plane(dx[ok], dy[ok], z[ok])
    n = np.array([-b, -c, 1.0])
    return LocalPlane(a, n / np.linalg.norm(n), int(ok.sum()), rms)
