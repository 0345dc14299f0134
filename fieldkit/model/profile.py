"""The slope profile: a polyline in the section plane with a material per segment.

``x`` is the horizontal distance along the fall line (strictly increasing), ``z`` the
elevation; segment ``j`` joins vertices ``j`` and ``j+1`` and is made of
``material[j]``. The segment dip ``psi`` is positive where the ground descends toward
+x (docs/architecture.md §2).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.errors import InputFileError
from fieldkit.io.profile_csv import check_profile_vertices


@dataclass(frozen=True)
class Profile:
    """A validated slope polyline (build it with :meth:`from_arrays`)."""

    x_m: np.ndarray
    z_m: np.ndarray
    material: tuple[str, ...]
    source: str = ""

    @classmethod
    def from_arrays(
        cls,
        x_m: ArrayLike,
        z_m: ArrayLike,
        material: object,
        *,
        source: str = "",
        where: Callable[[str, int], str] | None = None,
    ) -> Profile:
        """Validate and build; errors name ``source`` and the field (``profile.x_m``).

        Every profile is built here, so every profile gets the bounds of
        :func:`fieldkit.io.profile_csv.check_profile_vertices` (chainage within
        100 km, elevation within 11 km, vertices at least 1 mm apart).
        ``where(axis, i)`` names vertex ``i`` in those errors (default
        ``profile.x_m[i]``, ``profile.z_m[i]``: a model file's vertex lists).

        Examples
        --------
        >>> p = Profile.from_arrays([0, 10, 20], [10, 0, -5], ["rock", "talus"])
        >>> p.segment_at([5.0, 15.0]).tolist()
        [0, 1]
        """

        def numbers(values: object, name: str) -> np.ndarray:
            try:
                array = np.asarray(values, dtype=float)
            except (TypeError, ValueError, OverflowError):
                raise InputFileError(
                    "must be a list of numbers", source=source, where=f"profile.{name}"
                ) from None
            if array.ndim != 1:
                raise InputFileError(
                    "must be a list of numbers", source=source, where=f"profile.{name}"
                )
            bad = np.flatnonzero(~np.isfinite(array))
            if bad.size:
                raise InputFileError(
                    f"not a finite number at index {bad[0]}",
                    source=source,
                    where=f"profile.{name}",
                )
            return array

        x = numbers(x_m, "x_m")
        z = numbers(z_m, "z_m")
        if x.size < 2:
            raise InputFileError(
                f"needs at least two vertices (got {x.size})",
                source=source,
                where="profile.x_m",
            )
        if z.size != x.size:
            raise InputFileError(
                f"has {z.size} values, profile.x_m has {x.size}",
                source=source,
                where="profile.z_m",
            )
        step = np.flatnonzero(np.diff(x) <= 0)
        if step.size:
            i = int(step[0])
            raise InputFileError(
                f"must be strictly increasing (x[{i + 1}] = {x[i + 1]:g} after "
                f"x[{i}] = {x[i]:g})",
                source=source,
                where="profile.x_m",
            )
        check_profile_vertices(
            x,
            z,
            source=source,
            where=where or (lambda axis, i: f"profile.{axis}_m[{i}]"),
        )
        if isinstance(material, str):
            material = [material] * (x.size - 1)
        if not isinstance(material, list | tuple) or not all(
            isinstance(m, str) for m in material
        ):
            raise InputFileError(
                "must be a list of material names (one per segment) or one name",
                source=source,
                where="profile.material",
            )
        if len(material) != x.size - 1:
            raise InputFileError(
                f"needs one name per segment: {x.size - 1} (got {len(material)})",
                source=source,
                where="profile.material",
            )
        x.flags.writeable = False
        z.flags.writeable = False
        return cls(x_m=x, z_m=z, material=tuple(material), source=source)

    @property
    def segments(self) -> int:
        """Number of segments."""
        return self.x_m.size - 1

    @property
    def slope(self) -> np.ndarray:
        """dz/dx of each segment."""
        return np.diff(self.z_m) / np.diff(self.x_m)

    @property
    def dip_deg(self) -> np.ndarray:
        """Dip psi of each segment [deg], positive descending toward +x."""
        return -np.degrees(np.arctan(self.slope))

    def segment_at(self, x_m: ArrayLike) -> np.ndarray:
        """Index of the segment under ``x_m`` (clipped to the profile's segments)."""
        j = np.searchsorted(self.x_m, np.asarray(x_m, float), side="right") - 1
        return np.clip(j, 0, self.segments - 1)

    def ground_z(self, x_m: ArrayLike) -> np.ndarray:
        """Ground elevation at ``x_m`` [m] (linear along each segment)."""
        return np.interp(np.asarray(x_m, float), self.x_m, self.z_m)
