"""A 2-D model per station: the DEM section across the alignment there.

At every station the section runs in plan along the station's normal, from
``upslope_m`` on the higher side of the alignment (the release zone's side) through
the station to ``beyond_m`` on the other side. Which side is higher is read from
the DEM: the mean ground at 1, 2 and 4 cells to either side (a side off the DEM
counts as lower). A section that would leave the DEM (or meet nodata) is cut at its
last point on the data, and the table states the length used; fewer than two DEM
cells upslope is an error naming the station.

The section's x runs downslope from 0 at its upslope end; the alignment is the
analysis line at ``x = upslope length``. The model's materials, body, effects and
core carry over unchanged; its profile is replaced by the section (one material,
the model's only one, or the chainage ranges given), and its seeder moves to the
top: rocks start at the section's upslope end (or along its first
``release_band_m``) at the model seeder's height above the ground, with its
velocities (vx along the section, downslope), spin and spreads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fieldkit.corridor.stations import Stations
from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.dem import INSIDE, DemGrid
from fieldkit.model.dem_profile import profile_along_polyline
from fieldkit.model.model_file import Model, model_from_dict, model_to_dict

#: Fewest DEM cells of slope upslope of a station.
MIN_UPSLOPE_CELLS = 2.0


@dataclass(frozen=True)
class SectionSetup:
    """How the sections are cut and the rocks started (module docstring).

    Attributes
    ----------
    upslope_m, beyond_m
        Plan length of the section above and below the alignment [m].
    release_band_m
        Rocks start along the first this-many metres of the section (0: at its
        upslope end).
    material_ranges
        Chainage ranges (from the section's upslope end) -> material, as
        ``fieldkit profile --materials``; None: the model's only material.
    step_m
        Longest step between section vertices [m]; None: half a DEM cell.
    """

    upslope_m: float = 150.0
    beyond_m: float = 20.0
    release_band_m: float = 0.0
    material_ranges: str | None = None
    step_m: float | None = None

    def check(self) -> SectionSetup:
        for name in ("upslope_m", "beyond_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and 0 < value <= 1e5):
                raise ArgumentError(
                    f"{name} must be a length > 0 and <= 100 km (got {value:g})",
                    source=name,
                )
        if not (math.isfinite(self.release_band_m)
                and 0 <= self.release_band_m < self.upslope_m):  # fmt: skip
            raise ArgumentError(
                f"release_band_m must be >= 0 and < `upslope_m` {self.upslope_m:g} "
                f"(got {self.release_band_m:g})",
                source="release_band_m",
            )
        if self.step_m is not None and not (math.isfinite(self.step_m)
                                            and self.step_m > 0):  # fmt: skip
            raise ArgumentError(
                f"step_m must be > 0 (got {self.step_m:g})", source="step_m"
            )
        return self


def start_height_m(model: Model) -> float:
    """The model seeder's start height above the ground [m]: its ``height_m`` (a
    release line) or ``z_m`` less the ground at its ``x_m``."""
    sd = model.seeder
    if sd.height_m is not None:
        return float(sd.height_m)
    return float(sd.z_m - model.profile.ground_z(sd.x_m))


def check_base_model(model: Model, setup: SectionSetup) -> None:
    """Refuse a 2-D model a corridor cannot use: trees placed on its own profile,
    or several materials without ``material_ranges``."""
    if model.trees is not None or "tree_impacts" in model.effects:
        raise InputFileError(
            "has trees placed along its own profile; a corridor scan cuts new "
            "sections and cannot place them (remove `trees` and tree_impacts, or "
            "run the 3-D model)",
            source=model.source or "model",
        )
    used = set(model.profile.material)
    if setup.material_ranges is None and len(used) != 1:
        raise ArgumentError(
            f"the model's profile has {len(used)} materials "
            f"({', '.join(sorted(used))});"
            " give `material_ranges` to place them on every section",
            source="material_ranges",
        )


def _reach(grid: DemGrid, x0: float, y0: float, dx: float, dy: float,
           length: float) -> float:  # fmt: skip
    """How far along (dx, dy) from (x0, y0) the DEM has data, up to ``length``."""
    step = 0.25 * grid.cellsize_m
    s = np.arange(0.0, length + step, step)
    s[-1] = min(s[-1], length)
    _, _, _, status = grid.sample(x0 + s * dx, y0 + s * dy)
    bad = np.flatnonzero(status != INSIDE)
    return float(length if bad.size == 0 else s[max(int(bad[0]) - 1, 0)])


def upslope_sign(grid: DemGrid, x: float, y: float, nx: float, ny: float) -> float:
    """+1 when the DEM is higher to the left of the alignment (the normal's side),
    -1 when to the right (module docstring)."""
    d = grid.cellsize_m * np.array([1.0, 2.0, 4.0])
    means = []
    for sign in (1.0, -1.0):
        z, _, _, status = grid.sample(x + sign * d * nx, y + sign * d * ny)
        ok = status == INSIDE
        means.append(float(np.mean(z[ok])) if ok.any() else -math.inf)
    return 1.0 if means[0] >= means[1] else -1.0


@dataclass(frozen=True)
class StationSection:
    """The 2-D model of one station and where the alignment lies on it."""

    model: Model
    alignment_x_m: float
    side: str
    beyond_m: float


def station_section(
    grid: DemGrid, stations: Stations, i: int, base: Model, setup: SectionSetup
) -> StationSection:
    """The section and 2-D model of station ``i`` (module docstring).

    Raises
    ------
    InputFileError
        Less than :data:`MIN_UPSLOPE_CELLS` cells of DEM upslope of the station.
    """
    x, y = stations.xy_m[i]
    nx, ny = stations.normal_xy[i]
    sign = upslope_sign(grid, x, y, nx, ny)
    ux, uy = sign * nx, sign * ny
    up = _reach(grid, x, y, ux, uy, setup.upslope_m)
    down = _reach(grid, x, y, -ux, -uy, setup.beyond_m)
    where = f"station {i} (chainage {stations.chainage_m[i]:.1f} m)"
    if up < MIN_UPSLOPE_CELLS * grid.cellsize_m:
        raise InputFileError(
            f"only {up:.1f} m of DEM upslope of the alignment (at least "
            f"{MIN_UPSLOPE_CELLS * grid.cellsize_m:g} m, two cells, needed)",
            source=grid.source,
            where=where,
        )
    vertices = [(x + up * ux, y + up * uy), (x, y)]
    if down > 0:
        vertices.append((x - down * ux, y - down * uy))
    step = setup.step_m if setup.step_m is not None else 0.5 * grid.cellsize_m
    section = profile_along_polyline(grid, vertices, step)
    if setup.material_ranges is not None:
        section = section.with_materials(setup.material_ranges)
        material = list(section.material)
    else:
        material = [base.profile.material[0]] * (len(section.chainage_m) - 1)
    data = model_to_dict(base)
    data.pop("analysis_points", None)
    data["profile"] = {
        "x_m": section.chainage_m.tolist(),
        "z_m": section.z_m.tolist(),
        "material": material,
    }
    sd = dict(data["seeder"])
    for key in ("x_m", "z_m", "x_max_m", "height_m", "x_sd_m"):
        sd.pop(key, None)
    height = start_height_m(base)
    sd["x_m"] = 0.0
    if setup.release_band_m > 0:
        sd["x_max_m"] = min(setup.release_band_m, up)
        sd["height_m"] = height
    else:
        sd["z_m"] = float(section.z_m[0]) + height
    data["seeder"] = sd
    model = model_from_dict(data, source=f"{base.source or 'model'} on {where}")
    return StationSection(
        model=model,
        alignment_x_m=float(up),
        side="left" if sign > 0 else "right",
        beyond_m=float(down),
    )
