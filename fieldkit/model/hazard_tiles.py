"""A 3-D hazard map in tiles: the release cells cut into square tiles, each tile's
rocks run as independent units through the Dask engine, the rasters merged.

The run's random numbers are drawn here, once, in the one fixed order of
:func:`~fieldkit.model.simulate3d.draw_rocks3d` (release point, start, mass, and
each rock's own key); every rock's path then depends only on its start and key.
So a tiled run gives every rock exactly what :func:`~fieldkit.model.simulate3d.
simulate3d` gives it with the same seed -- the same deposits, states, rasters and
analysis-line numbers -- whatever the tiles, the unit size or the number of
workers.

Units: the rocks of one tile of ``tile_cells`` x ``tile_cells`` release cells, in
chunks of at most ``unit_rocks`` rocks. A unit returns only what the outputs need
(per-rock deposits and states, its rasters, its first crossings of the analysis
lines, and the paths of the first rocks a recording shows), never its sampled
paths: a worker holds one unit's paths at a time, at most about
``unit_rocks`` x (samples per rock) x 56 bytes.

Merging: ``passing_count`` and deposit counts add up, ``max_ke_j`` and
``max_height_m`` take the larger value (NaN where no rock came), the deposit
density is the summed count over (all rocks x cell area) -- the formulas of
:func:`~fieldkit.model.results3d.rasters`, so the maps are the same numbers.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from fieldkit.model.results3d import cells_of, deposit_counts, line_crossings, rasters
from fieldkit.model.simulate3d import Result3D, check_model3d, draw_rocks3d, simulate3d

#: Release cells per tile side.
TILE_CELLS = 32
#: Most rocks per unit.
UNIT_ROCKS = 5_000
#: Per-rock start fields of :func:`draw_rocks3d`.
START_FIELDS = ("index", "keys", "x", "y", "z", "vx", "vy", "vz", "w", "m", "r", "kg")


@dataclass(frozen=True)
class TileUnit:
    """One unit: some rocks of one tile (picklable; the model is shared)."""

    index: int
    tile: tuple[int, int]
    rocks: np.ndarray
    drawn: dict
    lines: tuple
    paths_below: int


def run_tile(model, unit: TileUnit) -> dict:
    """Run one unit (module docstring) and return what the outputs need."""
    res = simulate3d(model, int(unit.rocks.size), None, drawn=unit.drawn)
    grids = rasters(res, model.terrain)
    crossings = []
    for xy in unit.lines:
        c = line_crossings(res, xy)
        c["rock"] = unit.rocks[c["rock"]]
        crossings.append(c)
    kept = np.flatnonzero(unit.rocks < unit.paths_below)
    paths = [(int(unit.rocks[i]), res.rock_path(int(i))) for i in kept]
    return {
        "state": res.state,
        "deposit_xyz": res.deposit_xyz,
        "impacts_per_rock": res.impacts_per_rock,
        "strikes": res.tree_strikes_per_rock,
        "passing_count": grids["passing_count"],
        "max_ke_j": grids["max_ke_j"],
        "max_height_m": grids["max_height_m"],
        "deposits": deposit_counts(res, model.terrain),
        "crossings": crossings,
        "paths": [(r, {k: np.array(v) for k, v in p.items()}) for r, p in paths],
        "impacts": int(res.impacts),
        "wall_s": float(res.wall_s),
        "path_bytes": int(sum(np.asarray(v).nbytes for v in res.path.values())),
        "sample_m": float(res.sample_m),
        "notes": list(res.notes),
    }


def tile_units(
    model,
    drawn: dict,
    *,
    lines: Sequence[np.ndarray] = (),
    paths: int = 0,
    tile_cells: int = TILE_CELLS,
    unit_rocks: int = UNIT_ROCKS,
) -> list[TileUnit]:
    """The units of a run (module docstring), tiles in (row, column) order."""
    rel = np.asarray(model.releases, float)
    row, col, _ = cells_of(model.terrain, rel[:, 0], rel[:, 1])
    tile_of_release = np.column_stack([row // tile_cells, col // tile_cells])
    tiles = tile_of_release[drawn["index"]]
    order = np.lexsort((np.arange(len(tiles)), tiles[:, 1], tiles[:, 0]))
    units: list[TileUnit] = []
    start = 0
    while start < order.size:
        tile = tuple(int(v) for v in tiles[order[start]])
        end = start
        while end < order.size and tuple(tiles[order[end]]) == tile:
            end += 1
        for a in range(start, end, unit_rocks):
            rocks = np.sort(order[a:min(end, a + unit_rocks)])
            units.append(TileUnit(
                len(units), tile, rocks,
                {k: np.ascontiguousarray(drawn[k][rocks]) for k in START_FIELDS},
                tuple(np.asarray(xy, float) for xy in lines), paths,
            ))  # fmt: skip
        start = end
    return units


@dataclass
class TiledRun:
    """A tiled run: the result (paths only for the first rocks asked for), the
    merged rasters, each analysis line's merged first crossings, the units."""

    result: Result3D
    rasters: dict[str, np.ndarray]
    crossings: list[dict]
    units: int
    tiles: int
    largest_unit_path_bytes: int


def simulate3d_tiled(
    model,
    rocks: int,
    rng: np.random.Generator,
    engine,
    *,
    lines: Sequence[np.ndarray] = (),
    paths: int = 0,
    tile_cells: int = TILE_CELLS,
    unit_rocks: int = UNIT_ROCKS,
    progress: Callable[[int, int], None] | None = None,
) -> TiledRun:
    """Run ``rocks`` rocks of ``model`` in tiles through ``engine`` (a
    :class:`fieldkit.parallel.engine.Engine`; module docstring)."""
    check_model3d(model)
    drawn = draw_rocks3d(model, rocks, rng)
    units = tile_units(model, drawn, lines=lines, paths=paths,
                       tile_cells=tile_cells, unit_rocks=unit_rocks)  # fmt: skip
    out = engine.map(
        run_tile,
        units,
        names=[f"tile {u.tile} unit {u.index} ({u.rocks.size} rocks)" for u in units],
        progress=progress,
        shared=model,
    )
    state = np.zeros(rocks, np.int64)
    xyz = np.zeros((rocks, 3))
    impacts = np.zeros(rocks, np.int64)
    strikes = np.zeros(rocks, np.int64)
    shape = model.terrain.shape
    passing = np.zeros(shape, np.int64)
    deposits = np.zeros(shape, np.int64)
    maxima = {k: np.full(shape, np.nan) for k in ("max_ke_j", "max_height_m")}
    for u, o in zip(units, out, strict=True):
        state[u.rocks] = o["state"]
        xyz[u.rocks] = o["deposit_xyz"]
        impacts[u.rocks] = o["impacts_per_rock"]
        strikes[u.rocks] = o["strikes"]
        passing += o["passing_count"]
        deposits += o["deposits"]
        for k, grid in maxima.items():
            np.fmax(grid, o[k], out=grid)
    crossings = []
    for i in range(len(lines)):
        parts = [o["crossings"][i] for o in out]
        merged = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
        order = np.argsort(merged["rock"], kind="stable")
        crossings.append({k: v[order] for k, v in merged.items()})
    kept = sorted((r, p) for o in out for r, p in o["paths"])
    counts = [p["x_m"].size for _, p in kept]
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    fields = kept[0][1].keys() if kept else ("x_m", "y_m", "z_m")
    path = {k: np.concatenate([p[k] for _, p in kept] + [np.zeros(0)]) for k in fields}
    notes = list(dict.fromkeys(n for o in out for n in o["notes"]))
    result = Result3D(
        rocks=rocks,
        seed=None,
        wall_s=float(sum(o["wall_s"] for o in out)),
        impacts=int(impacts.sum()),
        release_index=drawn["index"].astype(np.int64),
        deposit_xyz=xyz,
        state=state,
        impacts_per_rock=impacts,
        path_offsets=offsets,
        path=path,
        sample_m=out[0]["sample_m"] if out else 0.0,
        notes=notes,
        tree_strikes_per_rock=strikes,
    )
    cell = model.terrain.cell_m
    grids = {
        "passing_count": passing,
        "max_ke_j": maxima["max_ke_j"],
        "max_height_m": maxima["max_height_m"],
        "deposit_density_per_m2": deposits / (max(rocks, 1) * cell**2),
    }
    return TiledRun(
        result=result,
        rasters=grids,
        crossings=crossings,
        units=len(units),
        tiles=len({u.tile for u in units}),
        largest_unit_path_bytes=max((o["path_bytes"] for o in out), default=0),
    )
