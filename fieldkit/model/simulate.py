"""Run a model for many rocks: draws, chunks, the compiled kernel, streamed impacts.

:func:`simulate` draws every rock's start from the seeder and one 64-bit key per rock
with the caller's Generator (fixed order, vectorised), then runs
:func:`fieldkit.model.kernel.run_rocks` in chunks. Inside the kernel each random
number is a function of (key, impact number, slot)
(:mod:`fieldkit.model.random_streams`), so a seed reproduces a run exactly whatever
the thread count or chunk size.

Recording impacts (``record_impacts=True``) runs each chunk twice: once to count each
rock's impacts, once to write them into an array of exactly that size, which is
turned into an :class:`~fieldkit.impact_table.ImpactTable` and handed to
``on_impact_chunk`` (or kept, when no callback is given). Memory is bounded by one
chunk's impacts; without recording it does not depend on the number of impacts.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

import fieldkit.model.kernel as kernel
from fieldkit.errors import ArgumentError
from fieldkit.impact_table import ImpactTable
from fieldkit.model.effects import registry
from fieldkit.model.model_file import Model
from fieldkit.model.results import AnalysisPoint, SimulationResult
from fieldkit.model.seeder import Starts, draw_starts

#: Rocks per kernel call when impacts are not recorded (progress granularity).
CHUNK_ROCKS = 100_000
#: Trace points kept per sampled trajectory.
TRACE_POINTS = 20_000
#: Largest run accepted (beyond these a run exhausts memory or never ends).
MAX_ROCKS = 10_000_000
MAX_ANALYSIS_POINTS = 100
MAX_ENVELOPE_BINS = 100_000
MAX_TRAJECTORIES = 1_000
#: Memory the per-rock arrays may take: starts, outcomes, analysis points, envelope.
MEMORY_LIMIT_BYTES = 4 * 2**30
#: Bytes per rock besides analysis points and envelope (12 float64/int64 arrays).
_BYTES_PER_ROCK = 12 * 8
#: Envelope bins along the profile when no bin width is given.
DEFAULT_ENVELOPE_BINS = 200


def default_envelope_dx_m(x_extent_m: float) -> float:
    """The envelope bin width used when none is given: the profile's x extent over
    :data:`DEFAULT_ENVELOPE_BINS`, rounded up to 1, 2 or 5 x 10^k m.

    Examples
    --------
    >>> default_envelope_dx_m(700.0), default_envelope_dx_m(110.0)
    (5.0, 1.0)
    """
    raw = max(float(x_extent_m), 1e-9) / DEFAULT_ENVELOPE_BINS
    power = 10.0 ** math.floor(math.log10(raw))
    for step in (1.0, 2.0, 5.0, 10.0):
        if step * power >= raw * (1 - 1e-12):
            return step * power
    return 10.0 * power  # pragma: no cover -- the loop always returns


def check_run(
    rocks: int,
    x_range_m: tuple[float, float],
    analysis_x_m: Sequence[float] = (),
    envelope_dx_m: float | None = None,
    trajectories: int = 0,
) -> None:
    """Refuse a run that is meaningless or would exhaust memory, naming the argument.

    Raises
    ------
    ArgumentError
        ``rocks`` < 1 or > :data:`MAX_ROCKS`; an analysis x not finite or outside
        the profile's ``x_range_m``; more than :data:`MAX_ANALYSIS_POINTS` of them;
        ``envelope_dx_m`` not finite and > 0 or making more than
        :data:`MAX_ENVELOPE_BINS` bins; ``trajectories`` outside [0,
        :data:`MAX_TRAJECTORIES`]; per-rock arrays above :data:`MEMORY_LIMIT_BYTES`.

    Examples
    --------
    >>> check_run(1000, (0.0, 700.0), [610.0], 5.0, 20)
    >>> try:
    ...     check_run(1000, (0.0, 700.0), [900.0])
    ... except ArgumentError as exc:
    ...     print(exc.message)
    900 m lies outside the profile (x from 0 to 700 m)
    """
    if not (isinstance(rocks, int | np.integer) and 1 <= rocks <= MAX_ROCKS):
        raise ArgumentError(
            f"rocks must be an integer from 1 to {MAX_ROCKS:,} (got {rocks})",
            source="rocks",
        )
    x0, x1 = x_range_m
    for xa in analysis_x_m:
        if not math.isfinite(xa):
            raise ArgumentError(
                f"{xa} is not a finite x (the profile spans x {x0:g} to {x1:g} m)",
                source="analysis_x_m",
            )
        if not x0 <= xa <= x1:
            raise ArgumentError(
                f"{xa:g} m lies outside the profile (x from {x0:g} to {x1:g} m)",
                source="analysis_x_m",
            )
    if len(analysis_x_m) > MAX_ANALYSIS_POINTS:
        raise ArgumentError(
            f"{len(analysis_x_m)} analysis points; at most {MAX_ANALYSIS_POINTS}",
            source="analysis_x_m",
        )
    bins = 0
    if envelope_dx_m is not None:
        if not (math.isfinite(envelope_dx_m) and envelope_dx_m > 0):
            raise ArgumentError(
                f"envelope_dx_m must be a finite width > 0 m (got {envelope_dx_m})",
                source="envelope_dx_m",
            )
        bins = max(1, math.ceil((x1 - x0) / envelope_dx_m))
        if bins > MAX_ENVELOPE_BINS:
            raise ArgumentError(
                f"envelope_dx_m {envelope_dx_m:g} m makes {bins:,} bins over the "
                f"{x1 - x0:g} m profile; at most {MAX_ENVELOPE_BINS:,} (a width of "
                f"at least {(x1 - x0) / MAX_ENVELOPE_BINS:.3g} m)",
                source="envelope_dx_m",
            )
    if not (
        isinstance(trajectories, int | np.integer)
        and 0 <= trajectories <= MAX_TRAJECTORIES
    ):
        raise ArgumentError(
            f"trajectories must be from 0 to {MAX_TRAJECTORIES:,} (got {trajectories})",
            source="trajectories",
        )
    per_rock = _BYTES_PER_ROCK + len(analysis_x_m) * kernel.N_ANALYSIS * 8 + bins * 4
    need = rocks * per_rock
    if need > MEMORY_LIMIT_BYTES:
        raise ArgumentError(
            f"{rocks:,} rocks with {len(analysis_x_m)} analysis points and {bins:,} "
            f"envelope bins need {need / 2**30:.1f} GiB for per-rock results; the "
            f"limit is {MEMORY_LIMIT_BYTES / 2**30:.0f} GiB: at most "
            f"{MEMORY_LIMIT_BYTES // per_rock:,} rocks here",
            source="rocks",
        )


@dataclass(frozen=True)
class KernelInputs:
    """The model as the kernel reads it (shared by simulate and reference).

    ``model`` is the :class:`fieldkit.model.kernel.KernelModel` bundle (profile,
    material table, trees, effects, core); ``material_names`` the material table's
    rows in order.
    """

    model: kernel.KernelModel
    material_names: tuple[str, ...]


#: A one-segment model that exercises every argument type of the kernel.
_TINY_MODEL = {
    "profile": {"x_m": [0.0, 10.0], "z_m": [5.0, 0.0], "material": "rock"},
    "materials": {"rock": {"e_n": 0.3, "e_t": 0.8, "friction_deg": 30.0}},
    "body": {"mass_kg": 100.0, "radius_m": 0.2},
    "seeder": {"x_m": 0.5, "z_m": 6.0},
}


def warm_kernel() -> float:
    """Compile the kernel (or load it from numba's cache); returns the seconds.

    Runs one rock of a one-segment model with an analysis point, an envelope,
    recorded impacts and a trajectory: every kernel signature a simulation uses.
    """
    from fieldkit.model.model_file import model_from_dict

    tic = time.perf_counter()
    simulate(
        model_from_dict(_TINY_MODEL),
        1,
        np.random.default_rng(0),
        analysis_x_m=[5.0],
        trajectories=1,
        record_impacts=True,
        envelope_dx_m=1.0,
        compile_first=False,
    )
    return time.perf_counter() - tic


def kernel_inputs(model: Model) -> KernelInputs:
    """Flatten ``model`` into :class:`KernelInputs` (the one place the kernel's
    bundles are built from a model)."""
    prof = model.profile
    px = np.ascontiguousarray(prof.x_m, float)
    pz = np.ascontiguousarray(prof.z_m, float)
    sl = np.diff(pz) / np.diff(px)
    psi = -np.arctan(sl)
    names = tuple(model.materials)
    materials = np.array(
        [
            [getattr(m, column) for column in kernel.MATERIAL_COLUMNS]
            for m in model.materials.values()
        ],
        float,
    )
    flags, par = registry.kernel_arrays(model.effects)
    trees = model.trees
    empty = np.zeros(0)

    def tree_column(name: str) -> np.ndarray:
        if trees is None:
            return empty
        return np.ascontiguousarray(getattr(trees, name), float)

    bundle = kernel.KernelModel(
        profile=kernel.Profile(
            x_m=px,
            z_m=pz,
            slope=sl,
            cos_psi=np.cos(psi),
            sin_psi=np.sin(psi),
            psi_deg=np.degrees(psi),
            material=np.array([names.index(name) for name in prof.material], np.int64),
        ),
        materials=materials,
        trees=kernel.Trees(*(tree_column(name) for name in kernel.Trees._fields)),
        effects=kernel.Effects(flags=flags, par=par),
        core=kernel.Core(*(float(model.core[k]) for k in kernel.Core._fields)),
    )
    return KernelInputs(model=bundle, material_names=names)


def kernel_rocks(
    starts: Starts, keys: np.ndarray, radius: np.ndarray, gyration: np.ndarray
) -> kernel.Rocks:
    """The rocks' starts as the kernel's :class:`~fieldkit.model.kernel.Rocks`."""
    return kernel.Rocks(
        key=keys,
        x_m=starts.x_m,
        z_m=starts.z_m,
        vx_mps=starts.vx_mps,
        vz_mps=starts.vz_mps,
        omega_radps=starts.omega_radps,
        mass_kg=starts.mass_kg,
        radius_m=radius,
        gyration_m=gyration,
    )


def draw_rocks(
    model: Model, rocks: int, rng: np.random.Generator
) -> tuple[Starts, np.ndarray]:
    """Start states and per-rock keys, drawn in the one fixed order of a run."""
    starts = draw_starts(model.seeder, model.profile, model.body.mass_kg, rocks, rng)
    keys = rng.integers(0, 2**63, size=rocks, dtype=np.uint64)
    return starts, keys


def body_of(model: Model, mass_kg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Radius and gyration of rocks of ``mass_kg`` (shape kept: ∝ mass^(1/3))."""
    cube = (np.asarray(mass_kg, float) / model.body.mass_kg) ** (1.0 / 3.0)
    return model.body.radius_m * cube, model.body.gyration_m * cube


def impact_columns(
    rec: np.ndarray, impacts: np.ndarray, first_rock: int
) -> dict[str, np.ndarray]:
    """Kernel impact rows of consecutive rocks as named arrays
    (:data:`kernel.RECORD_COLUMNS` plus ``rock``, the rock's index in the run)."""
    cols = dict(zip(kernel.RECORD_COLUMNS, rec.T, strict=True))
    cols["rock"] = np.repeat(np.arange(first_rock, first_rock + impacts.size), impacts)
    return cols


def impact_frame(
    rec: np.ndarray, impacts: np.ndarray, first_rock: int, names: tuple[str, ...]
) -> ImpactTable:
    """ImpactTable (derived) from kernel impact rows of consecutive rocks."""
    cols = impact_columns(rec, impacts, first_rock)
    rock = cols["rock"]
    starts = np.repeat(np.cumsum(impacts) - impacts, impacts)
    number = np.arange(rec.shape[0]) - starts + 1
    frame = pd.DataFrame(
        {
            "path_id": rock.astype(str),
            "point": number.astype(str),
            "t_s": cols["t_s"],
            "x_m": cols["x_m"],
            "z_m": cols["z_m"],
            "slope_deg": cols["slope_deg"],
            "material": np.asarray(names, dtype=object)[
                cols["material_index"].astype(np.int64)
            ],
            "mass_kg": cols["mass_kg"],
            "radius_m": cols["radius_m"],
            "gyration_m": cols["gyration_m"],
            "vi_x_mps": cols["vi_x_mps"],
            "vi_z_mps": cols["vi_z_mps"],
            "vf_x_mps": cols["vf_x_mps"],
            "vf_z_mps": cols["vf_z_mps"],
            "omega_i_radps": cols["omega_i_radps"],
            "omega_f_radps": cols["omega_f_radps"],
            "tree_strike": cols["tree_strike"] > 0.5,
        }
    )
    return ImpactTable(frame, source="simulation").derive()


def simulate(
    model: Model,
    rocks: int,
    rng: np.random.Generator,
    *,
    analysis_x_m: Sequence[float] = (),
    trajectories: int = 0,
    record_impacts: bool = False,
    impact_chunk_rocks: int = 20000,
    on_impact_chunk: Callable[[ImpactTable], None] | None = None,
    progress: Callable[[int, int], None] | None = None,
    envelope_dx_m: float | None = None,
    on_impact_columns: Callable[[dict[str, np.ndarray]], None] | None = None,
    compile_first: bool = True,
    on_compile: Callable[[], None] | None = None,
) -> SimulationResult:
    """Simulate ``rocks`` rocks of ``model`` with the random numbers of ``rng``.

    Parameters
    ----------
    analysis_x_m
        x of vertical analysis lines (speeds, energies, heights of crossing rocks).
    trajectories
        Sample (x, z) paths of the first this-many rocks.
    record_impacts, impact_chunk_rocks, on_impact_chunk
        Build the ImpactTable of simulated impacts, ``impact_chunk_rocks`` rocks at a
        time, handing each chunk to ``on_impact_chunk`` (else kept in the result).
    progress
        Called with (rocks done, rocks) after each chunk.
    envelope_dx_m
        Bin width of the bounce-height envelope; None = no envelope.
    on_impact_columns
        With ``record_impacts``: receives each chunk's impacts as the kernel's named
        arrays (:func:`impact_columns`) instead of an ImpactTable -- for callers that
        need a few columns of many simulations (a path fit), without the table's
        derived columns.
    compile_first, on_compile
        Before the clock starts, load the compiled kernel or, when it is not
        cached (:func:`fieldkit.model.kernel.kernel_ready`), call
        ``on_compile`` (to say so) and compile it on a one-rock model: the
        result's ``compile_s`` is the compile time (0 when loaded from the cache)
        and ``wall_s`` is simulation time only.
        ``compile_first=False`` (used by the warm-up itself) skips the check.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 50], "z_m": [30, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 31}})
    >>> simulate(m, 2, np.random.default_rng(0)).state.tolist()
    [1, 1]
    """
    check_run(
        rocks,
        (float(model.profile.x_m[0]), float(model.profile.x_m[-1])),
        [float(x) for x in np.asarray(analysis_x_m, float).reshape(-1)],
        envelope_dx_m,
        trajectories,
    )
    if impact_chunk_rocks < 1:
        raise ArgumentError(
            f"impact_chunk_rocks must be >= 1 (got {impact_chunk_rocks})",
            source="impact_chunk_rocks",
        )
    compile_s = 0.0
    if compile_first and not kernel.kernel_loaded():
        # compile (or load from the cache) before the clock starts
        compiles = not kernel.kernel_ready()
        if compiles and on_compile is not None:
            on_compile()
        seconds = warm_kernel()
        compile_s = seconds if compiles else 0.0
    inputs = kernel_inputs(model)
    starts, keys = draw_rocks(model, rocks, rng)
    radius, gyration = body_of(model, starts.mass_kg)
    ana_x = np.asarray(analysis_x_m, float).reshape(-1)
    ana = np.full((rocks, ana_x.size, kernel.N_ANALYSIS), np.nan)
    x0, x1 = inputs.model.profile.x_m[0], inputs.model.profile.x_m[-1]
    if envelope_dx_m is not None:
        bins = max(1, math.ceil((x1 - x0) / envelope_dx_m))
        edges = x0 + envelope_dx_m * np.arange(bins + 1)
        env = np.full((rocks, bins), np.nan, np.float32)
        envdx = float(envelope_dx_m)
    else:
        edges = np.zeros(0)
        env = np.zeros((rocks, 0), np.float32)
        envdx = 1.0
    impacts = np.zeros(rocks, np.int64)
    states = np.zeros(rocks, np.int64)
    runout = np.zeros(rocks, float)
    chunk = impact_chunk_rocks if record_impacts else CHUNK_ROCKS
    tables: list[ImpactTable] = []
    wall = 0.0
    no_rec = np.zeros((0, kernel.N_RECORD))
    all_rocks = kernel_rocks(starts, keys, radius, gyration)
    for a in range(0, rocks, chunk):
        b = min(rocks, a + chunk)
        sel = slice(a, b)

        def run(rec, offsets, on, sel=sel):
            kernel.run_rocks(
                kernel.Rocks(*(field[sel] for field in all_rocks)),
                inputs.model,
                kernel.Probes(ana_x, ana[sel], float(x0), envdx, env[sel]),
                kernel.Records(rec, offsets, on),
                kernel.Outcomes(impacts[sel], states[sel], runout[sel]),
            )

        tic = time.perf_counter()
        run(no_rec, np.zeros(b - a, np.int64), False)
        wall += time.perf_counter() - tic
        if record_impacts:
            counts = impacts[sel]
            offsets = np.cumsum(counts) - counts
            rec = np.empty((int(counts.sum()), kernel.N_RECORD))
            tic = time.perf_counter()
            run(rec, offsets, True)
            wall += time.perf_counter() - tic
            if on_impact_columns is not None:
                on_impact_columns(impact_columns(rec, counts, a))
            elif on_impact_chunk is not None:
                on_impact_chunk(impact_frame(rec, counts, a, inputs.material_names))
            else:
                tables.append(impact_frame(rec, counts, a, inputs.material_names))
        if progress is not None:
            progress(b, rocks)
    analysis = [
        AnalysisPoint(
            x_m=float(xa),
            crossed=ana[:, i, kernel.A_CROSSED] == 1.0,
            speed_mps=ana[:, i, kernel.A_SPEED],
            ke_j=ana[:, i, kernel.A_KE],
            re_j=ana[:, i, kernel.A_RE],
            total_j=ana[:, i, kernel.A_TOTAL],
            height_m=ana[:, i, kernel.A_HEIGHT],
        )
        for i, xa in enumerate(ana_x)
    ]
    paths = []
    for i in range(min(trajectories, rocks)):
        trace = np.zeros((TRACE_POINTS, 2))
        scratch_ana = np.full((0, kernel.N_ANALYSIS), np.nan)
        *_, count = kernel.run_rock(
            kernel.Rock(*(field[i] for field in all_rocks)),
            inputs.model,
            kernel.Probe(
                np.zeros(0), scratch_ana, float(x0), 1.0, np.zeros(0, np.float32)
            ),
            kernel.Record(no_rec, 0, False),
            trace,
        )
        paths.append(trace[:count].copy())
    table = None
    if record_impacts and on_impact_chunk is None and on_impact_columns is None:
        table = ImpactTable(
            pd.concat([t.frame for t in tables], ignore_index=True), source="simulation"
        )
    return SimulationResult(
        model=model,
        rocks=rocks,
        seed=None,
        wall_s=wall,
        impacts=int(impacts.sum()),
        runout_x_m=runout,
        state=states,
        impacts_per_rock=impacts,
        analysis=analysis,
        envelope_x_m=edges,
        envelope_height_m=env,
        trajectories=paths,
        impact_table=table,
        compile_s=compile_s,
    )
