"""Run a 3-D model for many rocks: draws, chunks, the compiled kernel, sampled paths.

:func:`simulate3d` draws every rock's release point and start with the caller's
Generator (fixed order, vectorised: release index, height, vx, vy, vz, spin, mass,
then one 64-bit key per rock), then runs :func:`fieldkit.model.kernel3d.run_rocks`
in chunks of :data:`CHUNK_ROCKS`. Each chunk runs twice: once to count every rock's
path samples and impacts, once to write them into arrays of exactly that size
(flat, with offsets). Inside the kernel every random number is a function of
(key, impact number, slot), so a seed reproduces a run exactly whatever the thread
count or chunk size.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.model import kernel3d
from fieldkit.model.effects import registry
from fieldkit.model.kernel import MATERIAL_COLUMNS
from fieldkit.model.model3d import WHY_HIT_PROBABILITY_1, Model3D
from fieldkit.model.model_file import CORE_DEFAULTS
from fieldkit.model.terrain import Terrain

#: Rocks per kernel call.
CHUNK_ROCKS = 20_000
#: Largest run accepted.
MAX_ROCKS = 10_000_000
#: Memory the sampled paths may take (7 float64 per sample).
PATH_MEMORY_LIMIT_BYTES = 4 * 2**30
_BYTES_PER_SAMPLE = 7 * 8


@dataclass
class Result3D:
    """Everything one 3-D simulation produced (the 3-D result contract).

    ``state`` uses the 2-D codes (:data:`fieldkit.model.results.STATE_NAMES`):
    stopped, exited (:data:`fieldkit.model.kernel3d.EXITED`: left the DEM or reached
    nodata) and capped. ``path`` holds every rock's samples in flat arrays, rock
    ``i``'s from ``path_offsets[i]`` to ``path_offsets[i + 1]``: fields ``x_m, y_m,
    z_m, speed_mps, ke_j, re_j, height_m`` (centre height above the ground,
    vertical), a sample at least every ``sample_m`` travelled, at every impact and
    at the final position (and just before and after every tree strike, at the
    same point). ``tree_strikes_per_rock``: the trees each rock struck
    (``tree_impacts``; zeros without). ``impact_rows`` (with
    ``record_impacts``): one array per :data:`fieldkit.model.kernel3d.IMPACT_COLUMNS`
    (``rock`` and ``material_index`` as int64), rocks in order and each rock's
    impacts in order; None when impacts were not recorded or were handed to
    ``on_impact_rows`` chunk by chunk.
    """

    rocks: int
    seed: int | None
    wall_s: float
    impacts: int
    release_index: np.ndarray
    deposit_xyz: np.ndarray
    state: np.ndarray
    impacts_per_rock: np.ndarray
    path_offsets: np.ndarray
    path: dict[str, np.ndarray]
    sample_m: float
    impact_rows: dict[str, np.ndarray] | None = None
    notes: list[str] = field(default_factory=list)
    tree_strikes_per_rock: np.ndarray | None = None

    def rock_path(self, i: int) -> dict[str, np.ndarray]:
        """The samples of rock ``i`` (views into :attr:`path`)."""
        a, b = self.path_offsets[i], self.path_offsets[i + 1]
        return {name: values[a:b] for name, values in self.path.items()}


def _material_table(materials: dict) -> np.ndarray:
    def get(m, name):
        return float(m[name] if isinstance(m, dict) else getattr(m, name))

    cols = MATERIAL_COLUMNS  # the 2-D kernel's material table, column for column
    return np.array(
        [[get(m, c) if (not isinstance(m, dict) or c in m) else 0.0 for c in cols]
         for m in materials.values()],
        float,
    )  # fmt: skip


def check_model3d(model: Model3D) -> None:
    """Refuse what the 3-D kernel cannot run, in one line naming the argument.

    Raises
    ------
    ArgumentError
        An effect not yet in 3-D (:data:`fieldkit.model.kernel3d.NOT_IN_3D`) is on;
        ``tree_impacts`` is on without ``trees`` or with a ``hit_probability``
        other than 1 (:func:`tree_hit_probability`);
        ``material_index`` is not the DEM's shape or, on a cell with data, is not
        an index into ``materials`` (a nodata cell's is not read);
        ``releases`` is not (n, 3) finite, has a point off the DEM's surface, or
        its weights are not >= 0 with a positive sum.
    """
    off = [name for name in kernel3d.NOT_IN_3D if name in model.effects]
    if off:
        raise ArgumentError(
            f"effects {', '.join(off)} are not yet in the 3-D simulator; "
            "switch them off for a 3-D model",
            source="model",
        )
    if "tree_impacts" in model.effects:
        if model.trees is None:
            raise ArgumentError("tree_impacts is on but the model has no trees",
                                source="trees")  # fmt: skip
        tree_hit_probability(model.effects["tree_impacts"], source="model")
    mi = np.asarray(model.material_index)
    if mi.shape != model.terrain.shape:
        raise ArgumentError(
            f"material_index has shape {mi.shape}, the DEM {model.terrain.shape}",
            source="material_index",
        )
    # a nodata cell has no material (-1 from the model file); the kernel reads a
    # cell's material only at an impact, which is on data (its four centres are)
    used = mi[np.isfinite(model.terrain.z)]
    if used.size and (used.min() < 0 or used.max() >= len(model.materials)):
        raise ArgumentError(
            f"material_index holds {int(used.min())}..{int(used.max())} on cells "
            f"with data; {len(model.materials)} materials",
            source="material_index",
        )
    rel = np.asarray(model.releases, float)
    if rel.ndim != 2 or rel.shape[1] != 3 or rel.shape[0] < 1:
        raise ArgumentError(
            f"releases must be (n, 3) x, y, z (got shape {rel.shape})",
            source="releases",
        )
    if not np.isfinite(rel).all():
        raise ArgumentError("releases hold a non-finite coordinate", source="releases")
    ground = model.terrain.heights(rel[:, 0], rel[:, 1])
    off = np.flatnonzero(~np.isfinite(ground))
    if off.size:
        i = int(off[0])
        raise ArgumentError(
            f"release point {i + 1} (x {rel[i, 0]:.10g}, y {rel[i, 1]:.10g}) is off "
            "the DEM's surface (outside its cell centres or beside nodata)",
            source="releases",
        )
    wts = np.asarray(model.release_weights, float)
    if wts.shape != (rel.shape[0],) or not (wts >= 0).all() or not wts.sum() > 0:
        raise ArgumentError(
            "release_weights must be one weight >= 0 per release point, not all 0",
            source="release_weights",
        )


#: Why a 3-D model's ``tree_impacts.hit_probability`` must be 1.
def tree_hit_probability(params: dict, *, source: str = "model") -> None:
    """Refuse a 3-D ``tree_impacts.hit_probability`` other than 1.

    In 2-D ``hit_probability`` is the chance that a trunk standing at a chainage
    lies in the rock's lane, which a section cannot know. A 3-D model places
    every stem, so whether the rock passes within ``d/2 + r`` of it below its top
    is geometry, and a strike is certain when it does: a probability below 1 would
    thin a mapped stand at random a second time (the map already says where the
    stems are), and a fit could use it as a free knob with no field meaning. A
    stand known only as a density is given as stems drawn from it.

    Raises
    ------
    ArgumentError
        ``hit_probability`` is not 1, naming ``source``.
    """
    p = float(params.get("hit_probability", 1.0))
    if p != 1.0:
        raise ArgumentError(
            f"tree_impacts.hit_probability is {p:g}; {WHY_HIT_PROBABILITY_1}",
            source=source,
        )


def draw_rocks3d(model: Model3D, rocks: int, rng: np.random.Generator) -> dict:
    """Release index, start state and key of every rock, in the one fixed order."""
    wts = np.asarray(model.release_weights, float)
    rel = np.asarray(model.releases, float)
    index = rng.choice(rel.shape[0], size=rocks, p=wts / wts.sum())
    s = model.seeder
    z = rng.standard_normal((6, rocks))
    height = np.abs(s.height_m + s.height_sd_m * z[0])
    mass = np.maximum(
        model.body.mass_kg + s.mass_sd_kg * z[5], 0.01 * model.body.mass_kg
    )
    cube = (mass / model.body.mass_kg) ** (1.0 / 3.0)
    keys = rng.integers(0, 2**63, size=rocks, dtype=np.uint64)
    x = rel[index, 0].copy()
    y = rel[index, 1].copy()
    ground = model.terrain.heights(x, y)  # the surface itself, not the given z
    return {
        "index": index,
        "keys": keys,
        "x": x,
        "y": y,
        "z": ground + height,
        "vx": s.vx_mps + s.vx_sd_mps * z[1],
        "vy": s.vy_mps + s.vy_sd_mps * z[2],
        "vz": s.vz_mps + s.vz_sd_mps * z[3],
        "w": s.omega_radps + s.omega_sd_radps * z[4],
        "m": mass,
        "r": model.body.radius_m * cube,
        "kg": model.body.gyration_m * cube,
    }


def _tiny_model() -> Model3D:
    """A one-patch model exercising every kernel signature (the warm-up)."""
    from fieldkit.model.materials import Material
    from fieldkit.model.model_file import Body

    terrain = Terrain(0.0, 0.0, 1.0, np.array([[1.0, 0.0], [1.0, 0.0]]))
    return Model3D(
        terrain=terrain,
        materials={"m": Material("m", 0.3, 0.8, 30.0)},
        material_index=np.zeros((2, 2), np.int64),
        effects={},
        body=Body(100.0, 0.2, 0.126),
        releases=np.array([[0.6, 1.0, 0.9]]),
        release_weights=np.ones(1),
    )


def warm_kernel3d() -> float:
    """Compile the 3-D kernel (or load it from numba's cache); returns the seconds.

    Examples
    --------
    >>> warm_kernel3d() >= 0.0
    True
    """
    tic = time.perf_counter()
    simulate3d(_tiny_model(), 1, np.random.default_rng(0), record_impacts=True)
    return time.perf_counter() - tic


def _impact_rows(rec: np.ndarray) -> dict[str, np.ndarray]:
    """Kernel impact rows as named arrays (``rock``, ``material_index`` int64)."""
    rows = dict(zip(kernel3d.IMPACT_COLUMNS, rec.T.copy(), strict=True))
    rows["rock"] = rows["rock"].astype(np.int64)
    rows["material_index"] = rows["material_index"].astype(np.int64)
    return rows


def simulate3d(
    model: Model3D,
    rocks: int,
    rng: np.random.Generator,
    *,
    sample_m: float | None = None,
    record_impacts: bool = False,
    chunk_rocks: int = CHUNK_ROCKS,
    keep_paths: bool = True,
    on_impact_rows: Callable[[dict[str, np.ndarray]], None] | None = None,
    drawn: dict | None = None,
) -> Result3D:
    """Simulate ``rocks`` rocks of ``model`` with the random numbers of ``rng``.

    Parameters
    ----------
    model
        The 3-D model (checked by :func:`check_model3d`).
    rocks
        Number of rocks, 1 to :data:`MAX_ROCKS`.
    rng
        The run's random numbers (all draws, including each rock's key).
    sample_m
        Longest distance travelled between two path samples [m]; None = half a DEM
        cell (stated in :attr:`Result3D.notes`).
    record_impacts
        Keep every impact's row (:data:`fieldkit.model.kernel3d.IMPACT_COLUMNS`).
    chunk_rocks
        Rocks per kernel call (results do not depend on it).
    keep_paths
        False: no path samples (``path`` arrays empty, ``path_offsets`` zeros) and,
        without ``record_impacts``, one kernel pass instead of two -- for fits and
        benchmarks that need only deposits. Deposits, states and impacts are the
        same either way.
    on_impact_rows
        With ``record_impacts``: called with each chunk's impact rows (as
        :attr:`Result3D.impact_rows`, consecutive rocks in order) as soon as the
        chunk has run, instead of keeping them (``impact_rows`` is then None):
        memory bounded by one chunk's impacts.
    drawn
        The rocks' starts already drawn (:func:`draw_rocks3d`, or a subset of its
        arrays, ``rocks`` long): run them instead of drawing (``rng`` unused). Each
        rock's numbers depend only on its start and key, so a run split into
        subsets gives each rock what the whole run gives it
        (:mod:`fieldkit.model.hazard_tiles`).

    Returns
    -------
    Result3D
    """
    if not (isinstance(rocks, int | np.integer) and 1 <= rocks <= MAX_ROCKS):
        raise ArgumentError(
            f"rocks must be an integer from 1 to {MAX_ROCKS:,} (got {rocks})",
            source="rocks",
        )
    if not (isinstance(chunk_rocks, int | np.integer) and chunk_rocks >= 1):
        raise ArgumentError(
            f"chunk_rocks must be >= 1 (got {chunk_rocks})", source="chunk_rocks"
        )
    check_model3d(model)
    terrain = model.terrain
    notes = []
    if sample_m is None:
        sample_m = 0.5 * terrain.cell_m
        notes.append(f"paths sampled every {sample_m:g} m (half a DEM cell)")
    if not (np.isfinite(sample_m) and sample_m > 0):
        raise ArgumentError(
            f"sample_m must be a finite distance > 0 m (got {sample_m})",
            source="sample_m",
        )
    core = {k: v[0] for k, v in CORE_DEFAULTS.items()} | dict(model.core)
    # The kernel runs with the origin at the DEM's lower-left corner: in a
    # national grid (x ~ 2.8e6 m, LV95) a position is rounded to 4.7e-10 m, 1e-8
    # of a 5 cm cell, enough to turn one contact into a chain of false ones.
    ox, oy = float(terrain.x0_m), float(terrain.y0_m)
    local = Terrain(0.0, 0.0, terrain.cell_m, terrain.z)
    grid = local.grid()
    ground = kernel3d.Ground(
        grid.z,
        grid.xc0,
        grid.yc0,
        grid.cell,
        np.ascontiguousarray(model.material_index, np.int64),
    )
    settings = kernel3d.Settings(
        float(core["slide_vn_mps"]),
        float(core["stop_speed_mps"]),
        int(core["max_impacts"]),
        float(sample_m),
        float(min(kernel3d.SLIDE_STEP_CELLS * terrain.cell_m, 0.5 * sample_m)),
    )
    mat = _material_table(model.materials)
    flags, par = registry.kernel_arrays(model.effects)
    stems = kernel3d.no_stems(local)
    if "tree_impacts" in model.effects:
        tr = model.trees
        stems = kernel3d.stems_of(np.asarray(tr.x_m, float) - ox,
                                  np.asarray(tr.y_m, float) - oy, tr.diameter_m,
                                  tr.height_m, local)  # fmt: skip
        off = len(tr.x_m) - stems.x.size
        notes.append(
            f"tree_impacts: {stems.x.size} stems on the DEM, each struck where a "
            "rock's centre passes within d/2 + r of it below its top "
            "(hit_probability 1: 3-D strikes are geometric)"
            + (f"; {off} stem(s) off the DEM's surface never reached" if off else "")
        )
    if drawn is not None and len(drawn["keys"]) != rocks:
        raise ArgumentError(
            f"drawn holds {len(drawn['keys'])} rocks, not `rocks` {rocks}",
            source="drawn",
        )
    d = draw_rocks3d(model, rocks, rng) if drawn is None else drawn
    impacts = np.zeros(rocks, np.int64)
    states = np.zeros(rocks, np.int64)
    deposit = np.zeros((rocks, 3))
    samples = np.zeros(rocks, np.int64)
    strikes = np.zeros(rocks, np.int64)
    no_rec = np.zeros((0, kernel3d.N_IMPACT))
    path_parts: list[kernel3d.Path] = []
    rec_parts: list[np.ndarray] = []
    wall = 0.0
    for a in range(0, rocks, chunk_rocks):
        b = min(rocks, a + chunk_rocks)
        sel = slice(a, b)
        starts = [d[k][sel] for k in ("keys", "x", "y", "z", "vx", "vy", "vz", "w")]
        starts[1], starts[2] = starts[1] - ox, starts[2] - oy  # the kernel's frame
        body = [d[k][sel] for k in ("m", "r", "kg")]

        def run(
            path, poff, pon, rec, roff, ron, a=a, sel=sel, starts=starts, body=body
        ):
            kernel3d.run_rocks(
                *starts, *body, ground, mat, flags, par, settings, stems,
                path, poff, pon, rec, roff, ron, a,
                impacts[sel], states[sel], deposit[sel], samples[sel], strikes[sel],
            )  # fmt: skip

        zeros = np.zeros(b - a, np.int64)
        tic = time.perf_counter()
        run(kernel3d.empty_path(), zeros, False, no_rec, zeros, False)
        if not (keep_paths or record_impacts):
            wall += time.perf_counter() - tic
            continue
        counts = samples[sel].copy() if keep_paths else zeros
        total = int(counts.sum()) + sum(p.x_m.size for p in path_parts)
        if total * _BYTES_PER_SAMPLE > PATH_MEMORY_LIMIT_BYTES:
            raise ArgumentError(
                f"the sampled paths of the first {b:,} rocks already hold {total:,} "
                f"samples ({total * _BYTES_PER_SAMPLE / 2**30:.1f} GiB, limit "
                f"{PATH_MEMORY_LIMIT_BYTES / 2**30:.0f} GiB): run fewer rocks or a "
                f"larger sample_m (now {sample_m:g} m)",
                source="rocks",
            )
        poff = np.cumsum(counts) - counts
        path = kernel3d.Path(
            *(np.empty(int(counts.sum())) for _ in kernel3d.PATH_FIELDS)
        )
        if record_impacts:
            nimp = impacts[sel]
            roff = np.cumsum(nimp) - nimp
            rec = np.empty((int(nimp.sum()), kernel3d.N_IMPACT))
        else:
            roff, rec = zeros, no_rec
        run(path, poff, keep_paths, rec, roff, record_impacts)
        wall += time.perf_counter() - tic
        path.x_m[:] += ox  # back to the DEM's coordinates
        path.y_m[:] += oy
        rec[:, kernel3d.R_X] += ox
        rec[:, kernel3d.R_Y] += oy
        path_parts.append(path)
        if record_impacts and on_impact_rows is not None:
            on_impact_rows(_impact_rows(rec))
        elif record_impacts:
            rec_parts.append(rec)
    deposit[:, 0] += ox
    deposit[:, 1] += oy
    offsets = np.zeros(rocks + 1, np.int64)
    if keep_paths:
        np.cumsum(samples, out=offsets[1:])
    path_arrays = {
        name: np.concatenate([getattr(p, name) for p in path_parts] + [np.zeros(0)])
        for name in kernel3d.PATH_FIELDS
    }
    rows = None
    if record_impacts and on_impact_rows is None:
        rows = _impact_rows(np.concatenate(rec_parts) if rec_parts else no_rec)
    return Result3D(
        rocks=rocks,
        seed=None,
        wall_s=wall,
        impacts=int(impacts.sum()),
        release_index=d["index"].astype(np.int64),
        deposit_xyz=deposit,
        state=states,
        impacts_per_rock=impacts,
        path_offsets=offsets,
        path=path_arrays,
        sample_m=float(sample_m),
        impact_rows=rows,
        notes=notes,
        tree_strikes_per_rock=strikes,
    )
