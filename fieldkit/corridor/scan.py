"""A corridor scan: design energies, bounce heights and passing fractions every few
metres along a road, railway or barrier line.

Two ways, one table (:mod:`fieldkit.corridor.table`):

* **2-D** (a profile model): at every station a DEM section across the alignment
  (:mod:`fieldkit.corridor.sections`), ``rocks`` rocks released at its upslope end,
  each rock counted at its first crossing of the alignment. A station is one unit
  of work with its own seed (``SeedSequence(seed).spawn``: child ``i`` is station
  ``i``'s).
* **3-D** (a terrain model): ``rocks`` rocks from the model's releases in units of
  :data:`UNIT_ROCKS_3D` rocks, each unit with its own seed (child ``i`` of
  ``SeedSequence(seed)``); each rock is counted at its first crossing of the
  alignment, at the station whose stretch holds the crossing (midway to its
  neighbours). The passing fraction of a station is then its crossing rocks over
  all the rocks released.

Units run through :class:`fieldkit.parallel.engine.Engine`: in this process, on a
local Dask cluster or on a remote one. Each unit's numbers depend only on the seed
and the unit's index, so the table is identical whatever the number of workers.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from fieldkit.corridor.sections import (
    SectionSetup,
    StationSection,
    check_base_model,
    start_height_m,
    station_section,
)
from fieldkit.corridor.stations import (
    Stations,
    chainage_of,
    check_on_dem,
    stations_along,
)
from fieldkit.corridor.table import corridor_frame, station_numbers
from fieldkit.errors import ArgumentError
from fieldkit.io.dem import DemGrid, same_origin_and_cell
from fieldkit.parallel.engine import Engine

#: Rocks per unit of a 3-D scan (fixed: the seeds, hence the results, depend on it).
UNIT_ROCKS_3D = 2_000
#: A job of at most this many rocks in all runs in this process by default.
TINY_ROCKS = 20_000
#: Most rocks per station (2-D) or in all (3-D).
MAX_ROCKS = 10_000_000
#: Trajectories kept per station (2-D) or in all (3-D) for the rerun scene.
SCENE_PATHS = 5


@dataclass(frozen=True)
class SectionUnit:
    """One station of a 2-D scan (picklable)."""

    index: int
    model: object
    alignment_x_m: float
    rocks: int
    seed: np.random.SeedSequence
    trajectories: int = SCENE_PATHS


def run_section(unit: SectionUnit) -> dict:
    """Simulate one station's section: its table numbers, its first trajectories
    (section x, z), the impacts and the kernel time."""
    from fieldkit.model.simulate import simulate

    result = simulate(
        unit.model,
        unit.rocks,
        np.random.default_rng(unit.seed),
        analysis_x_m=[unit.alignment_x_m],
        trajectories=unit.trajectories,
    )
    a = result.analysis[0]
    crossed = np.asarray(a.crossed, bool)
    numbers = station_numbers(unit.rocks, a.total_j[crossed], a.height_m[crossed])
    return {
        "numbers": numbers,
        "paths": [np.asarray(p, float) for p in result.trajectories],
        "impacts": int(result.impacts),
        "wall_s": float(result.wall_s),
    }


@dataclass(frozen=True)
class RockUnit:
    """One unit of rocks of a 3-D scan (picklable; the model is shared)."""

    index: int
    rocks: int
    seed: np.random.SeedSequence
    alignment_xy: np.ndarray
    trajectories: int = 0


def run_rocks3d(model, unit: RockUnit) -> dict:
    """Simulate one unit of a 3-D scan: each crossing rock's first crossing of the
    alignment (x, y, energy = translational + rotational [J], bounce height [m]),
    the first ``trajectories`` paths, the impacts, the sampled paths' bytes."""
    from fieldkit.model.results3d import line_crossings
    from fieldkit.model.simulate3d import simulate3d

    result = simulate3d(model, unit.rocks, np.random.default_rng(unit.seed))
    crossing = line_crossings(result, unit.alignment_xy)
    offsets = np.asarray(result.path_offsets, np.int64)
    paths = [
        np.column_stack(
            [
                np.asarray(result.path[k][offsets[r] : offsets[r + 1]], float)
                for k in ("x_m", "y_m", "z_m")
            ]
        )  # fmt: skip
        for r in range(min(unit.trajectories, unit.rocks))
    ]
    return {
        "x_m": crossing["x_m"],
        "y_m": crossing["y_m"],
        "energy_j": crossing["ke_j"] + crossing["re_j"],
        "height_m": crossing["height_m"],
        "paths": paths,
        "impacts": int(result.impacts),
        "wall_s": float(result.wall_s),
        "path_bytes": int(sum(np.asarray(v).nbytes for v in result.path.values())),
        "notes": list(result.notes),
    }


@dataclass
class CorridorScan:
    """What a scan gives (module docstring).

    Attributes
    ----------
    stations
        The stations.
    frame
        The corridor table, one row per station.
    dimension
        2 or 3.
    rocks
        Rocks per station (2-D) or in all (3-D).
    seed
        The run's seed.
    units
        Units of work run.
    impacts
        Impacts simulated in all.
    wall_s
        Wall time of the units, from the first sent to the last back [s].
    notes
        What the scan assumed (stated on the command line and in the summary).
    engine
        Where the units ran (:meth:`Engine.describe`).
    paths
        A few trajectories in plan and height, ``(n, 3)`` [m] each, for the scene.
    sections
        The 2-D sections (None in 3-D).
    """

    stations: Stations
    frame: pd.DataFrame
    dimension: int
    rocks: int
    seed: int
    units: int
    impacts: int
    wall_s: float
    notes: list[str] = field(default_factory=list)
    engine: dict = field(default_factory=dict)
    paths: list = field(default_factory=list)
    sections: list | None = None

    def summary(self) -> dict:
        """The JSON summary: settings, notes, engine, totals (the table is the CSV)."""
        f = self.frame
        worst = (
            f["energy_p99_kj"].idxmax() if f["energy_p99_kj"].notna().any() else None
        )
        return {
            "dimension": self.dimension,
            "stations": len(self.stations),
            "alignment_length_m": self.stations.length_m,
            "rocks": self.rocks,
            "rocks_are": "per station" if self.dimension == 2 else "in all",
            "seed": self.seed,
            "units": self.units,
            "impacts": self.impacts,
            "wall_s": self.wall_s,
            "largest_p99_energy": None if worst is None else {
                "station": int(f.loc[worst, "station"]),
                "chainage_m": float(f.loc[worst, "chainage_m"]),
                "energy_p99_kj": float(f.loc[worst, "energy_p99_kj"]),
                "energy_p99_se_kj": float(f.loc[worst, "energy_p99_se_kj"]),
            },
            "notes": list(self.notes),
            "engine": self.engine,
        }  # fmt: skip


def check_rocks(rocks: int) -> None:
    if not (isinstance(rocks, int | np.integer) and 1 <= rocks <= MAX_ROCKS):
        raise ArgumentError(
            f"rocks must be an integer from 1 to {MAX_ROCKS:,} (got {rocks})",
            source="rocks",
        )


def _seeds(seed: int, n: int) -> list[np.random.SeedSequence]:
    return np.random.SeedSequence(seed).spawn(n)


def scan2d(
    grid: DemGrid,
    alignment_xy: np.ndarray,
    spacing_m: float,
    model,
    rocks: int,
    seed: int,
    engine: Engine,
    *,
    setup: SectionSetup | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> CorridorScan:
    """The 2-D scan (module docstring) of a profile ``model`` on the DEM ``grid``."""
    setup = (setup or SectionSetup()).check()
    check_rocks(rocks)
    stations = stations_along(alignment_xy, spacing_m)
    check_on_dem(stations, grid)
    check_base_model(model, setup)
    sections: list[StationSection] = [
        station_section(grid, stations, i, model, setup) for i in range(len(stations))
    ]
    seeds = _seeds(seed, len(stations))
    units = [
        SectionUnit(i, s.model, s.alignment_x_m, rocks, seeds[i])
        for i, s in enumerate(sections)
    ]
    tic = time.perf_counter()
    out = engine.map(
        run_section,
        units,
        names=[
            f"station {i} (chainage {c:.1f} m)"
            for i, c in enumerate(stations.chainage_m)
        ],  # fmt: skip
        progress=progress,
        tiny=rocks * len(units) <= TINY_ROCKS,
    )
    wall = time.perf_counter() - tic
    frame = corridor_frame(
        stations,
        [o["numbers"] for o in out],
        {
            "upslope_side": [s.side for s in sections],
            "upslope_used_m": [s.alignment_x_m for s in sections],
            "beyond_used_m": [s.beyond_m for s in sections],
        },
    )
    short = [
        i for i, s in enumerate(sections) if s.alignment_x_m < setup.upslope_m - 1e-6
    ]
    notes = [
        f"2-D sections across the alignment every {spacing_m:g} m: "
        f"{setup.upslope_m:g} m upslope (the higher side, read from the DEM) and "
        f"{setup.beyond_m:g} m beyond; "
        f"{rocks:,} rocks per station, each counted at its first crossing",
        "rocks start "
        + (
            f"along the top {setup.release_band_m:g} m of each section"
            if setup.release_band_m > 0
            else "at each section's upslope end"
        )
        + f", {start_height_m(model):g} m above the ground with the model seeder's "
        "velocities (vx along the section, downslope), spin and spreads",  # fmt: skip
        "materials: "
        + (
            setup.material_ranges
            or f"{model.profile.material[0]} on every section (the model's "
            "only material)"
        ),  # fmt: skip
        "energy = translational + rotational kinetic energy at the crossing; bounce "
        "height = the centre's height above the ground there",
    ]
    if short:
        notes.append(
            f"{len(short)} section(s) cut short where the DEM ends upslope (stations "
            + ", ".join(map(str, short[:10]))
            + (" ..." if len(short) > 10 else "")
            + "): `upslope_used_m` in the table"
        )
    paths = []
    for s, o, i in zip(sections, out, range(len(out)), strict=True):
        top = stations.xy_m[i] + s.alignment_x_m * (
            1 if s.side == "left" else -1) * stations.normal_xy[i]  # fmt: skip
        down = -(1 if s.side == "left" else -1) * stations.normal_xy[i]
        for p in o["paths"]:
            xy = top + p[:, :1] * down
            paths.append(np.column_stack([xy, p[:, 1]]))
    return CorridorScan(
        stations=stations,
        frame=frame,
        dimension=2,
        rocks=rocks,
        seed=seed,
        units=len(units),
        impacts=sum(o["impacts"] for o in out),
        wall_s=wall,
        notes=notes,
        engine=engine.describe(),
        paths=paths,
        sections=sections,
    )


def check_same_dem(model, grid: DemGrid) -> None:
    """Refuse a DEM that is not the terrain model's own (a 3-D scan counts
    crossings on the model's terrain; the alignment is checked on ``grid``)."""
    from fieldkit.model.terrain_file import terrain_from_dem

    t, mine = terrain_from_dem(grid), model.terrain
    same = (
        t.shape == mine.shape
        and same_origin_and_cell((t.x0_m, t.y0_m, t.cell_m),
                                 (mine.x0_m, mine.y0_m, mine.cell_m))
        and np.allclose(t.z, mine.z, equal_nan=True)
    )  # fmt: skip
    if not same:
        raise ArgumentError(
            "is not the DEM of the terrain model (its `terrain.dem`): a 3-D scan "
            "runs on the model's own DEM",
            source=grid.source,
        )


def scan3d(
    model,
    grid: DemGrid,
    alignment_xy: np.ndarray,
    spacing_m: float,
    rocks: int,
    seed: int,
    engine: Engine,
    *,
    progress: Callable[[int, int], None] | None = None,
    unit_rocks: int = UNIT_ROCKS_3D,
) -> CorridorScan:
    """The 3-D scan (module docstring) of a terrain ``model`` whose DEM is ``grid``."""
    from fieldkit.model.simulate3d import check_model3d

    check_rocks(rocks)
    check_model3d(model)
    stations = stations_along(alignment_xy, spacing_m)
    check_same_dem(model, grid)
    check_on_dem(stations, grid)  # the model's DEM: its own check
    n_units = -(-rocks // unit_rocks)
    seeds = _seeds(seed, n_units)
    xy = stations.alignment_xy
    units = [
        RockUnit(
            i,
            min(unit_rocks, rocks - i * unit_rocks),
            seeds[i],
            xy,
            SCENE_PATHS * 4 if i == 0 else 0,
        )  # fmt: skip
        for i in range(n_units)
    ]
    tic = time.perf_counter()
    out = engine.map(
        run_rocks3d,
        units,
        label="rock unit",
        names=[
            f"rock unit {i} (rocks {i * unit_rocks}-{i * unit_rocks + u.rocks - 1})"
            for i, u in enumerate(units)
        ],  # fmt: skip
        progress=progress,
        tiny=rocks <= TINY_ROCKS,
        shared=model,
    )
    wall = time.perf_counter() - tic
    x = np.concatenate([o["x_m"] for o in out])
    y = np.concatenate([o["y_m"] for o in out])
    energy = np.concatenate([o["energy_j"] for o in out])
    height = np.concatenate([o["height_m"] for o in out])
    at = chainage_of(stations, x, y)
    which = np.clip(np.searchsorted(stations.edges_m, at, side="right") - 1, 0,
                    len(stations) - 1)  # fmt: skip
    rows = [station_numbers(rocks, energy[which == i], height[which == i])
            for i in range(len(stations))]  # fmt: skip
    frame = corridor_frame(
        stations,
        rows,
        {"stretch_from_m": stations.edges_m[:-1], "stretch_to_m": stations.edges_m[1:]},
    )
    biggest = max(o["path_bytes"] for o in out)
    notes = [
        f"3-D: {rocks:,} rocks from the model's {len(model.releases)} release points "
        f"in {n_units} unit(s) of up to {unit_rocks:,} rocks (seed per unit); each "
        "rock counted at its first crossing of the alignment, at the station whose "
        "stretch (midway to its neighbours) holds the crossing",
        f"passing fraction = a station's crossing rocks / all {rocks:,} rocks; "
        f"{int(x.size):,} rocks crossed the alignment in all",
        "energy = translational + rotational kinetic energy at the crossing; bounce "
        "height = the centre's height above the ground there",
        f"memory: a unit's sampled paths held at most {biggest / 2**20:.1f} MiB",
        *dict.fromkeys(n for o in out for n in o["notes"]),
    ]
    return CorridorScan(
        stations=stations,
        frame=frame,
        dimension=3,
        rocks=rocks,
        seed=seed,
        units=n_units,
        impacts=sum(o["impacts"] for o in out),
        wall_s=wall,
        notes=notes,
        engine=engine.describe(),
        paths=[p for o in out for p in o["paths"]],
    )
