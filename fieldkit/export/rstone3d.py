"""r.stone on a 3-D model's own DEM: its input rasters, one source cell per run.

:mod:`fieldkit.export.rstone` writes r.stone's inputs for a 2-D model on a site (a
DEM given beside the model, or the section extruded). A 3-D model
(:class:`~fieldkit.model.model3d.Model3D`) carries its own DEM and materials, so
here the rasters are the model's: the DEM (north-up, as r.stone reads it), and
``nrest``, ``trest``, ``friction`` from each cell's material (``material_index``),
with :mod:`fieldkit.export.rstone`'s conversions:

* ``nrest = 100 e_n``, ``trest = 100 e_t`` in whole percent
  (:func:`~fieldkit.export.rstone.percent`), ``friction = tan(friction_deg)``;
  a coefficient above 1 or a friction angle above 45 deg is refused, as there;
* the spread ranges ``range = 50 SD`` (:func:`~fieldkit.export.rstone.stoch_range`;
  the friction SD in tan units, :func:`~fieldkit.export.rstone.friction_sd_tan`),
  the largest over the materials present (r.stone takes one per run);
* ``start_vel``: the seeder's speed at the ground after its drop ``height_m``,
  ``sqrt(vx² + vy² + vz² + 2 g h)`` (r.stone starts a stone on its cell's ground,
  launched horizontally towards the steepest of the 8 neighbours); r.stone's
  default 1 m/s when that is 0 (it needs a speed > 0); ``stop_vel`` the core
  ``stop_speed_mps``;
* the DEM raised by whole metres when it reaches 0 m
  (:func:`~fieldkit.export.rstone.dem_offset_m`: r.stone takes z <= 0 as no
  ground); nodata cells stay nodata (no ground: a stone reaching one stops);
* the cell must be a whole number of metres (r.stone stores it as a C ``short``):
  a model whose cell is not is refused (resampling would change the ground the
  comparison is about).

What r.stone cannot take is said (:attr:`Rstone3DInputs.notes`): roughness (the
slope-roughness effect's random tilt of the normal: r.stone's ground is the DEM's
triangles), each active effect as its own export metadata for r.stone says
(:meth:`~fieldkit.model.effects.spec.EffectSpec.export`), the block's mass and
size, the lateral
spread of the launch (``ang_stoch_range`` written 0: fieldkit's seeder here has
no launch direction), and r.stone's random numbers, seeded with the constant 1
(``random2.c`` ``Init_RNG``): the same files give the same run.

Runs (:func:`run_rstone_batch`): one GRASS session in a fresh XY project imports
the DEM and the three material rasters once, then for each named source file
runs r.stone (its own source cell, N stones) and writes its ``counter`` grid
(trajectories through each cell) as ESRI ASCII. r.stone writes no deposits: what
can be compared is what the counter holds (:mod:`fieldkit.fit.footprint`).
"""

from __future__ import annotations

import math
import shlex
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fieldkit.errors import ArgumentError, FieldkitError
from fieldkit.export.ascii_grid import ascii_grid_text
from fieldkit.export.lumped import not_a_law
from fieldkit.export.rstone import (
    DEFAULT_ANGLE_RANGE,
    DEFAULT_START_VEL_MPS,
    EDGE_CELLS,
    G_MPS2,
    MAX_ELEVATION_M,
    PROGRAM,
    _check,
    dem_offset_m,
    friction_sd_tan,
    material_grids,
    percent,
    rstone_arguments,
    stoch_range,
)
from fieldkit.io.dem import DemGrid, read_dem
from fieldkit.model.effects import registry
from fieldkit.model.model3d import Model3D

#: The input rasters written once per model (the sources are written per run).
MATERIAL_GRIDS = ("nrest", "trest", "friction")

#: What fieldkit's r.stone runs say about its random numbers.
RNG_NOTE = (
    "r.stone seeds its random numbers with the constant 1 (random2.c Init_RNG): "
    "each run's N stones are one fixed sample, the same every time"
)

#: How r.stone's counter is marked, and what that does to a footprint read from it.
COUNTER_NOTE = (
    "r.stone marks its counter at path points at least 5 m apart, the last one "
    "always (stone.c Filter with OUTPUT_TAB 5 m, MarkPath): the stop's cell is "
    "marked, but a trajectory can skip a cell on the way, so a footprint read from "
    "it is sparser than fieldkit's passing_count (paths cut every quarter cell)"
)


@dataclass(frozen=True)
class Rstone3DInputs:
    """r.stone's inputs for a 3-D model (module docstring).

    Attributes
    ----------
    grid
        The DEM as written (north-up, row 0 north; elevations raised by
        ``offset_m``; NaN = no ground).
    files
        ``dem.asc``, ``nrest.asc``, ``trest.asc``, ``friction.asc`` (ESRI ASCII).
    options
        r.stone's options: ``ang_stoch_range``, ``vrest_stoch_range``,
        ``hrest_stoch_range``, ``frict_stoch_range`` (whole numbers),
        ``start_vel``, ``stop_vel`` [m/s].
    offset_m
        Whole metres added to every elevation.
    notes
        What was approximated or left out, one line each.
    """

    grid: DemGrid
    files: dict[str, str]
    options: dict[str, float]
    offset_m: float
    notes: tuple[str, ...]


def _start_speed_mps(model: Model3D) -> float:
    s = model.seeder
    return math.sqrt(
        s.vx_mps**2 + s.vy_mps**2 + s.vz_mps**2 + 2.0 * G_MPS2 * max(s.height_m, 0.0)
    )


def rstone_inputs3d(model: Model3D) -> Rstone3DInputs:
    """r.stone's DEM, material rasters and options for ``model`` on its own DEM.

    Raises
    ------
    ArgumentError
        A cell that is not a whole number of metres >= 1, a restitution above 1,
        a friction angle above 45 deg (names the material), or a DEM whose relief
        exceeds what r.stone takes as ground.

    Examples
    --------
    >>> from fieldkit.model.materials import Material
    >>> from fieldkit.model.model3d import Model3D, Seeder3D
    >>> from fieldkit.model.model_blocks import Body
    >>> from fieldkit.model.terrain import Terrain
    >>> z = np.tile(np.arange(4.0)[::-1] * 5.0, (3, 1))   # falls to the east
    >>> m = Model3D(Terrain(0.0, 0.0, 5.0, z),
    ...     {"rock": Material.from_dict("rock", {"e_n": 0.3, "e_t": 0.8,
    ...      "friction_deg": 30, "e_n_sd": 0.04})}, np.zeros((3, 4), int), {},
    ...     Body(100.0, 0.2, 0.13), np.array([[2.5, 7.5, 15.0]]),
    ...     np.ones(1), Seeder3D(height_m=0.5), core={"stop_speed_mps": 0.05})
    >>> i = rstone_inputs3d(m)
    >>> i.offset_m, i.grid.values[0].tolist()      # 0 m raised to 1 m, row 0 north
    (1.0, [16.0, 11.0, 6.0, 1.0])
    >>> {k: i.options[k] for k in ("vrest_stoch_range", "start_vel", "stop_vel")}
    {'vrest_stoch_range': 2, 'start_vel': 3.132, 'stop_vel': 0.05}
    >>> i.files["nrest.asc"].splitlines()[-1]
    '30 30 30 30'
    """
    t = model.terrain
    cell = float(t.cell_m)
    if not (cell >= 1 and cell == math.floor(cell)):
        raise ArgumentError(
            f"the DEM's cells are {cell:g} m: r.stone needs a whole number of metres "
            f">= 1 (it stores the cell size as a C short, so {cell:g} m would run as "
            f"{max(0, math.floor(cell)):g} m); resample the model's DEM",
            source="model",
        )
    names = list(model.materials)
    index = np.asarray(model.material_index)[::-1]
    z = np.asarray(t.z, float)[::-1]
    ground = np.isfinite(z)
    present = [n for i, n in enumerate(names) if (index[ground] == i).any()]
    _check(model, present)
    offset = dem_offset_m(z[ground])
    dem = np.where(ground, z + offset, np.nan)
    if np.nanmax(dem) > MAX_ELEVATION_M:
        raise ArgumentError(
            f"the DEM reaches {np.nanmax(dem):.6g} m after a shift of {offset:g} m: "
            f"r.stone takes elevations in (0, {MAX_ELEVATION_M:g}] m as ground",
            source="model",
        )
    grid = DemGrid.from_corner(
        dem,
        x_left_m=float(t.x0_m),
        y_top_m=float(t.y0_m + t.shape[0] * cell),
        cellsize_m=cell,
        crs=model.crs,
    )

    def per_material(value) -> np.ndarray:
        out = np.full(z.shape, np.nan)
        for i, name in enumerate(names):
            if name in present:
                out[ground & (index == i)] = value(model.materials[name])
        return out

    files = {
        "dem.asc": ascii_grid_text(dem, grid, decimals=3),
        **material_grids(per_material, grid),
    }
    materials = [model.materials[n] for n in present]
    speed = _start_speed_mps(model)
    options: dict[str, float] = {
        "ang_stoch_range": DEFAULT_ANGLE_RANGE,
        "vrest_stoch_range": max(stoch_range(m.e_n_sd) for m in materials),
        "hrest_stoch_range": max(stoch_range(m.e_t_sd) for m in materials),
        "frict_stoch_range": max(
            stoch_range(friction_sd_tan(m.friction_deg, m.friction_deg_sd))
            for m in materials
        ),
        "start_vel": round(speed, 3) if speed > 0 else DEFAULT_START_VEL_MPS,
        "stop_vel": float(model.core["stop_speed_mps"]),
    }
    return Rstone3DInputs(
        grid, files, options, offset, tuple(_notes(model, present, offset, options))
    )


def _notes(model: Model3D, present: list[str], offset: float,
           options: dict[str, float]) -> list[str]:  # fmt: skip
    out = [
        "written: "
        + "; ".join(
            f"{n}: nrest {percent(m.e_n)} %, trest {percent(m.e_t)} %, friction "
            f"tan {math.tan(math.radians(m.friction_deg)):.3f}"
            for n, m in ((n, model.materials[n]) for n in present)
        )
        + f"; ranges vrest {options['vrest_stoch_range']}, hrest "
        f"{options['hrest_stoch_range']}, frict {options['frict_stoch_range']} "
        "(Gaussian SD 2 range / 100), ang_stoch_range "
        f"{options['ang_stoch_range']} (r.stone's default is 10; the model's seeder "
        "has no launch direction)",
        f"start_vel {options['start_vel']:g} m/s: the seeder's speed after its "
        f"{model.seeder.height_m:g} m drop (r.stone starts each stone at its source "
        "cell's centre on the ground, horizontally towards the steepest neighbour); "
        f"stop_vel {options['stop_vel']:g} m/s",
        RNG_NOTE,
        COUNTER_NOTE,
        f"body not written ({model.body.mass_kg:g} kg, radius "
        f"{model.body.radius_m:g} m; each run's own block likewise): r.stone's block "
        "is a point whose mass never enters its kinematics",
    ]
    rough = [n for n in present if model.materials[n].roughness_deg_sd > 0
             or model.materials[n].roughness_m > 0]  # fmt: skip
    if rough:
        out.append(
            "roughness not written: "
            + ", ".join(
                f"{n} {model.materials[n].roughness_deg_sd:.3g} deg SD of the normal"
                for n in rough
            )
            + " (r.stone's ground is the DEM's triangles); e_n, e_t are written as "
            "calibrated with it, not refitted to a law without it"
        )
    for name in model.effects:  # how r.stone takes each: the effect's own metadata
        export = registry.effect(name).export(PROGRAM)
        why = not_a_law(name, PROGRAM) or (
            export.how if export else "r.stone's export of it is not declared"
        )
        out.append(f"effect {name}: {why}")
    if offset:
        out.append(f"DEM raised by {offset:g} m (r.stone takes z <= 0 as no ground)")
    return out


def source_cell(inputs: Rstone3DInputs, x_m: float, y_m: float) -> tuple[int, int]:
    """``(row, col)`` (row 0 north) of the cell holding ``(x_m, y_m)``, where
    r.stone starts a run's stones (at its centre).

    Raises
    ------
    ArgumentError
        The point is off the grid, on no ground, or within :data:`EDGE_CELLS` of
        the grid's edge (r.stone never starts a stone whose first triangle needs a
        cell beyond the edge), or its cell or one of the 8 around it is no ground
        (r.stone picks the launch direction from the 8 neighbours' elevations).

    Examples
    --------
    >>> g = DemGrid.from_corner(np.ones((4, 4)), x_left_m=0, y_top_m=20,
    ...                         cellsize_m=5)
    >>> i = Rstone3DInputs(g, {}, {}, 0.0, ())
    >>> source_cell(i, 7.0, 12.0)
    (1, 1)
    """
    g = inputs.grid
    cell = g.cellsize_m
    left, top = g.x_left_m, g.y_top_m
    col = math.floor((x_m - left) / cell)
    row = math.floor((top - y_m) / cell)
    rows, cols = g.shape
    e = EDGE_CELLS
    where = f"point (x {x_m:g}, y {y_m:g})"
    if not (e <= row < rows - e and e <= col < cols - e):
        raise ArgumentError(
            f"{where}: its cell (row {row}, col {col}) is not at least {e} cell "
            f"inside the {rows} x {cols} grid: r.stone cannot start stones there",
            source="release",
        )
    block = g.values[row - 1 : row + 2, col - 1 : col + 2]
    if not np.isfinite(block).all():
        raise ArgumentError(
            f"{where}: its cell or one of its 8 neighbours is no ground (nodata): "
            "r.stone launches towards the steepest of the 8 and its first triangle "
            "needs the east and north ones",
            source="release",
        )
    return row, col


def sources_text(inputs: Rstone3DInputs, cells: list[tuple[int, int]],
                 stones: int) -> str:  # fmt: skip
    """The ``sources`` grid: ``stones`` in each of ``cells``, 0 elsewhere on
    ground (ESRI ASCII, whole numbers).

    Raises
    ------
    ArgumentError
        ``stones`` not a whole number >= 1.
    """
    if isinstance(stones, bool) or not isinstance(stones, int) or stones < 1:
        raise ArgumentError(
            f"stones must be a whole number >= 1 (got {stones})", source="stones"
        )
    g = inputs.grid
    values = np.where(np.isfinite(g.values), 0.0, np.nan)
    for row, col in cells:
        values[row, col] = stones
    return ascii_grid_text(values, g, integer=True)


def batch_script(options: dict[str, float], names: list[str]) -> str:
    """Bash for a GRASS session (:func:`run_rstone_batch`): import the DEM and
    the material rasters once, then for each name run r.stone on
    ``sources_<name>.asc`` and write ``counter_<name>.asc`` (nodata -1)."""
    args = rstone_arguments(options, int(options["ang_stoch_range"]))
    runs = " ".join(shlex.quote(n) for n in names)
    return f"""#!/usr/bin/env bash
# r.stone once per source file beside this script (written by fieldkit).
set -euo pipefail
cd "$(dirname "$0")"
for name in dem {" ".join(MATERIAL_GRIDS)}; do
    r.in.gdal -o --overwrite --quiet input="$name.asc" output="$name"
done
g.region raster=dem
for run in {runs}; do
    r.in.gdal -o --overwrite --quiet input="sources_$run.asc" output=sources
    r.stone --overwrite --quiet dem=dem sources=sources nrest=nrest trest=trest \\
        friction=friction {args} counter=counter
    r.out.gdal -c -m --overwrite --quiet input=counter output="counter_$run.asc" \\
        format=AAIGrid type=Int32 nodata=-1
done
"""


def rstone_missing() -> str:
    """Why r.stone cannot run here ("" when GRASS GIS and r.stone are present)."""
    grass = shutil.which("grass")
    if grass is None:
        return "GRASS GIS is not installed (no `grass` on PATH)"
    try:
        done = subprocess.run(
            [grass, "--config", "path"], capture_output=True, text=True, timeout=60
        )
    except (OSError, subprocess.SubprocessError) as exc:
        return f"`grass --config path` failed: {exc}"
    base = done.stdout.strip()
    if done.returncode != 0 or not base:
        last = (done.stderr.strip().splitlines() or ["no output"])[-1]
        return f"`grass --config path` failed (exit {done.returncode}: {last})"
    if not (Path(base) / "bin" / "r.stone").is_file():
        return (
            f"r.stone is not built into GRASS ({base}/bin/r.stone; "
            "tools/r.stone/install.sh builds it)"
        )
    return ""


def run_rstone_batch(
    inputs: Rstone3DInputs,
    sources: dict[str, tuple[int, int]],
    stones: int,
    folder: Path | None = None,
    *,
    timeout_s: float = 600.0,
) -> dict[str, np.ndarray]:
    """Run r.stone once per named source cell, ``stones`` stones each, in one GRASS
    session; the counter grid of each run (row 0 north, as ``inputs.grid``; 0
    where no trajectory passed, NaN off the ground).

    Parameters
    ----------
    inputs
        :func:`rstone_inputs3d`'s rasters.
    sources
        Run name (letters, digits, ``_``, ``-``) -> its source cell (row, col).
    stones
        Stones started in each run.
    folder
        Where the files go (a temporary folder, removed, when None).
    timeout_s
        Longest wall time of the GRASS session.

    Raises
    ------
    ArgumentError
        A run name that is not a plain word, or ``stones`` < 1.
    FieldkitError
        GRASS GIS or r.stone missing (:func:`rstone_missing`), or r.stone failing
        (the last line of its error output).
    """
    missing = rstone_missing()
    if missing:
        raise FieldkitError(missing, source="rstone")
    for name in sources:
        if not name or not all(c.isalnum() or c in "_-" for c in name):
            raise ArgumentError(
                f"run name {name!r}: letters, digits, '_' and '-' only",
                source="sources",
            )
    if folder is None:
        with tempfile.TemporaryDirectory(prefix="fieldkit-rstone-") as tmp:
            return run_rstone_batch(inputs, sources, stones, Path(tmp),
                                    timeout_s=timeout_s)  # fmt: skip
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in inputs.files.items():
        (folder / name).write_text(text, encoding="utf-8")
    for name, cell in sources.items():
        (folder / f"sources_{name}.asc").write_text(
            sources_text(inputs, [cell], stones), encoding="utf-8"
        )
    script = folder / "run_rstone_batch.sh"
    script.write_text(batch_script(inputs.options, list(sources)), encoding="utf-8")
    db = folder / "grassdb"
    shutil.rmtree(db, ignore_errors=True)
    runs = [
        ["grass", "-c", "XY", str(db / "xy"), "-e"],
        ["grass", str(db / "xy" / "PERMANENT"), "--exec", "bash", str(script)],
    ]
    for command in runs:
        try:
            done = subprocess.run(command, capture_output=True, text=True,
                                  timeout=timeout_s)  # fmt: skip
        except (OSError, subprocess.SubprocessError) as exc:
            raise FieldkitError(
                f"{command[0]} failed: {exc}", source="rstone"
            ) from None
        if done.returncode != 0:
            last = (done.stderr.strip().splitlines() or ["(no error output)"])[-1]
            raise FieldkitError(
                f"GRASS/r.stone exited with {done.returncode}: {last}", source="rstone"
            )
    ground = np.isfinite(inputs.grid.values)
    out = {}
    for name in sources:
        counter = np.nan_to_num(read_dem(folder / f"counter_{name}.asc").values)
        out[name] = np.where(ground, counter, np.nan)
    return out
