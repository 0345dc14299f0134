"""The local ground at a contact: a plane fitted to the DEM over the block's footprint.

The DEM's surface is the 3-D simulator's (:class:`fieldkit.model.terrain.Terrain`:
bilinear between cell centres). At a contact the plane ``z = a + b (x - x0) + c (y -
y0)`` is fitted by least squares to that surface at :data:`FOOTPRINT_POINTS` points
spread evenly over a disc of radius ``footprint_m`` about the contact's plan position
(the block's radius by default: the ground it can touch). N is the plane's upward unit
normal. Over a disc inside one DEM patch the fit gives the bilinear surface's own
gradient at the centre exactly (the twist term is orthogonal to a plane over a
symmetric disc), so on a simulated run N is the normal the simulator used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fieldkit.model.terrain import Terrain

#: Rings x points of the footprint disc the plane is fitted to (centre included).
FOOTPRINT_RINGS = 3
FOOTPRINT_SPOKES = 12
FOOTPRINT_POINTS = 1 + FOOTPRINT_RINGS * FOOTPRINT_SPOKES


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


def _disc(radius_m: float) -> tuple[np.ndarray, np.ndarray]:
    r = radius_m * np.arange(1, FOOTPRINT_RINGS + 1) / FOOTPRINT_RINGS
    a = 2 * np.pi * np.arange(FOOTPRINT_SPOKES) / FOOTPRINT_SPOKES
    dx = np.r_[0.0, (r[:, None] * np.cos(a)[None, :]).ravel()]
    dy = np.r_[0.0, (r[:, None] * np.sin(a)[None, :]).ravel()]
    return dx, dy


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
    dx, dy = _disc(footprint_m)
    z = terrain.heights(x_m + dx, y_m + dy)
    ok = np.isfinite(z)
    if ok.sum() < FOOTPRINT_POINTS / 2:
        return None
    a = np.c_[np.ones(ok.sum()), dx[ok], dy[ok]]
    coef, *_ = np.linalg.lstsq(a, z[ok], rcond=None)
    res = z[ok] - a @ coef
    n = np.array([-coef[1], -coef[2], 1.0])
    return LocalPlane(
        float(coef[0]),
        n / np.linalg.norm(n),
        int(ok.sum()),
        float(np.sqrt(np.mean(res * res))),
    )
