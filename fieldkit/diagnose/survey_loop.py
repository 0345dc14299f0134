"""The reduction in the loop: a diagnosis's null and power on surveyed paths.

A reduced survey is not a table of measured impacts: every flight without a tree
strike was solved with an *assumed* launch angle, slopes are chords between
scars, and every point carries GNSS error that an impact's arrival and rebound
share. Those steps alone can make a speed or an angle law look real (issue 18: on
boulder A's geometry, 16 % of effect-free surveyed paths got a recommendation). So
the gain a candidate shows on a surveyed table is compared with the gains the
*same survey and reduction* produce when no effect is present:

1. The observed table is read back into what its reduction assumed
   (:func:`loop_paths`): each path's points (its own profile), materials, body,
   assumed theta0, position error (``x_sd_m``, ``z_sd_m``) and how many of its
   flights a tree strike fixed.
2. A **null campaign** simulates one rock per observed path on that path's own
   profile (the surveyed points joined by straight segments, each segment of the
   material of the scar it ends at) under the *fitted baseline* (constant e_n,
   e_t per material, their scatter from the table: :func:`material_scatter`),
   surveys it with the same error and trees
   (:mod:`fieldkit.campaign.virtual`), reduces it with the same options
   (:func:`fieldkit.reduce.pipeline.reduce_path`) and diagnoses it. The best
   candidate's held-out gain of each null campaign is kept.
3. A candidate is recommended only when its gain exceeds the ``quantile`` of the
   null gains as well as the usual rule. With ``B`` null campaigns the threshold
   is the ``ceil(q (B + 1))``-th smallest null gain, so the decision is a Monte
   Carlo test at level ``1 - q`` (Besag & Diggle 1977): with B = 19 and q = 0.95,
   the largest of 19.
4. **Power**: campaigns simulated with each candidate switched on at the size the
   observed table fitted it, diagnosed under the same threshold: the share in
   which that candidate is recommended is the power this geometry gives it.

The null is a parametric bootstrap: it is as good as the fitted baseline and the
survey model (scar threshold, spacing, trees) are. The report states both and
compares the null campaigns' baseline error with the observed one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from fieldkit.campaign.design import CampaignDesign
from fieldkit.campaign.virtual import virtual_campaign
from fieldkit.errors import ArgumentError, FieldkitError
from fieldkit.impact_table import ImpactTable
from fieldkit.model.model_file import Model, model_from_dict
from fieldkit.physics.bodies import resolve_body
from fieldkit.reduce.pipeline import ReduceOptions, reduce_path
from fieldkit.reduce.uncertainty import (
    DEFAULT_ELEVATION_SIGMA_M,
    DEFAULT_POSITION_SIGMA_M,
    DEFAULT_STRIKE_HEIGHT_SIGMA_M,
    PositionError,
)

#: Null campaigns by default (a Monte Carlo test at 5 % needs 19; 99 gives a
#: threshold that moves little from seed to seed).
DEFAULT_NULL = 99
#: Campaigns per candidate for its power.
DEFAULT_POWER = 40
#: The null quantile a recommended gain must exceed.
DEFAULT_QUANTILE = 0.95
#: Most null or power campaigns one diagnosis may ask for (each takes seconds).
MAX_CAMPAIGNS = 10_000
#: Power below which the report says the data cannot tell the laws apart.
LOW_POWER = 0.5
#: Most scars of one simulated rock in a null path: then the next rock starts again
#: from the observed scar there at the observed speed (:func:`loop_table`).
PIECE_SCARS = 10
#: Least scatter of e_n, e_t given to the simulated rocks (an impact is never
#: exactly repeatable).
MIN_SCATTER = 0.02


@dataclass(frozen=True)
class LoopPath:
    """What the reduction of one surveyed path assumed, read back from its table."""

    path_id: str
    x_m: np.ndarray
    z_m: np.ndarray
    material: tuple[str, ...]
    theta0_deg: float
    mass_kg: float
    radius_m: float
    gyration_m: float
    position_sigma_m: float
    elevation_sigma_m: float
    strike_height_sigma_m: float
    tree_share: float
    mean_flight_m: float
    launch_vx_mps: np.ndarray
    launch_vz_mps: np.ndarray
    #: Impacts a campaign standing in for this path surveys (None: as many as the
    #: path has; a benchmark asks for more or fewer on the same geometry).
    target_scars: int | None = None

    @property
    def scars(self) -> int:
        """Surveyed impacts a stand-in campaign makes (the source not counted)."""
        return len(self.x_m) - 1 if self.target_scars is None else self.target_scars


def _first(frame: pd.DataFrame, column: str, default: float) -> float:
    if column not in frame:
        return default
    values = frame[column].to_numpy(float)
    values = values[np.isfinite(values)]
    return float(values[0]) if values.size else default


def loop_paths(table: ImpactTable) -> tuple[list[LoopPath], list[str]]:
    """Each path of a reduced survey as its reduction saw it, and notes on what had
    to be assumed (a default position error where the table has no ``x_sd_m``)."""
    notes: list[str] = []
    frame = table.frame
    out = []
    for path_id, rows in frame.groupby(frame["path_id"].astype(str), sort=False):
        rows = rows.reset_index(drop=True)
        src = rows["theta0_source"].astype("string").fillna("")
        assumed = rows["theta0_deg"].to_numpy(float)[src.eq("assumed").to_numpy()]
        assumed = assumed[np.isfinite(assumed)]
        theta0 = float(np.median(assumed)) if assumed.size else 32.6
        if not assumed.size:
            notes.append(
                f"{path_id}: no flight used an assumed launch angle; the loop reduces "
                "its simulated paths with theta0 32.6 deg where no tree fixes a flight"
            )
        if "x_sd_m" not in rows:
            notes.append(
                f"{path_id}: the table does not record its position error (x_sd_m, "
                f"z_sd_m); the loop surveys with the reduction's default "
                f"{DEFAULT_POSITION_SIGMA_M:g} m in plan and height"
            )
        trees = (
            rows["tree_strike"] if "tree_strike" in rows else pd.Series([], "boolean")
        )
        known = trees.dropna()
        share = float(known.astype(bool).mean()) if len(known) else 0.0
        x = rows["x_m"].to_numpy(float)
        z = rows["z_m"].to_numpy(float)
        keep = np.concatenate([[True], np.diff(x) > 0.05])
        keep &= np.isfinite(x) & np.isfinite(z)
        if not keep.all():
            notes.append(
                f"{path_id}: {int((~keep).sum())} point(s) not downslope of the one "
                "before left out of the loop's profile"
            )
        vx = rows["vf_x_mps"].to_numpy(float)
        vz = rows["vf_z_mps"].to_numpy(float)
        material = rows["material"].astype("string").fillna("unknown").to_numpy(str)
        out.append(
            LoopPath(
                path_id=str(path_id),
                x_m=x[keep],
                z_m=z[keep],
                material=tuple(material[keep]),
                theta0_deg=theta0,
                mass_kg=_first(rows, "mass_kg", math.nan),
                radius_m=_first(rows, "radius_m", math.nan),
                gyration_m=_first(rows, "gyration_m", math.nan),
                position_sigma_m=_first(rows, "x_sd_m", DEFAULT_POSITION_SIGMA_M),
                elevation_sigma_m=_first(rows, "z_sd_m", DEFAULT_ELEVATION_SIGMA_M),
                strike_height_sigma_m=_first(
                    rows, "strike_height_sd_m", DEFAULT_STRIKE_HEIGHT_SIGMA_M
                ),
                tree_share=share,
                mean_flight_m=float(np.mean(np.diff(x[keep])))
                if keep.sum() > 1
                else 1.0,
                launch_vx_mps=vx[keep],
                launch_vz_mps=vz[keep],
            )
        )
    return out, notes


def material_scatter(table: ImpactTable) -> dict[str, tuple[float, float]]:
    """Per material, the SD of e_n and e_t beyond the survey error (method of
    moments: ``var(e) - mean(e_sd^2)``, floored at :data:`MIN_SCATTER`); the
    median absolute deviation is used for the spread so a few wild rows (an e_n of
    4 on a grazing impact) do not set it."""
    frame = table.derive().frame
    out = {}
    for name, rows in frame.groupby(frame["material"].astype(str), sort=True):
        values = []
        for col in ("e_n", "e_t"):
            e = rows[col].to_numpy(float)
            e = e[np.isfinite(e)]
            if e.size < 3:
                values.append(MIN_SCATTER)
                continue
            spread = 1.4826 * float(np.median(np.abs(e - np.median(e))))
            sd_col = f"{col}_sd"
            noise = 0.0
            if sd_col in rows:
                sd = rows[sd_col].to_numpy(float)
                sd = sd[np.isfinite(sd)]
                noise = float(np.median(sd)) if sd.size else 0.0
            values.append(max(MIN_SCATTER, math.sqrt(max(spread**2 - noise**2, 0.0))))
        out[str(name)] = (values[0], values[1])
    return out


def path_model(
    path: LoopPath,
    materials: dict[str, dict[str, float]],
    effects: dict[str, dict[str, float]],
    start: int = 0,
) -> Model:
    """The model a null or power campaign simulates on ``path``'s own profile, its
    rocks leaving point ``start`` with the velocity the reduction gave the observed
    rock there (+-0.5 m/s).

    On an even slope a lumped-mass rock keeps the speed scale it arrives with (its
    flights lengthen with the square of the speed, and so does the height it
    gains), so where a simulated rock starts and how fast sets how long its flights
    are; starting it from the observed rock's own scars at its own speed keeps the
    simulated flights like the surveyed ones."""
    seg_material = list(path.material[1:])
    used = {
        m: materials.get(m, materials[next(iter(materials))]) for m in set(seg_material)
    }
    x0 = float(path.x_m[start])
    vx = path.launch_vx_mps[start]
    vz = path.launch_vz_mps[start]
    if not (np.isfinite(vx) and np.isfinite(vz) and vx > 0):
        vx, vz = 1.0, 0.0  # an unsolved flight: a slow start
    return model_from_dict(
        {
            "profile": {
                "x_m": [float(v) for v in path.x_m],
                "z_m": [float(v) for v in path.z_m],
                "material": seg_material,
            },
            "materials": used,
            "effects": effects,
            "body": {
                "mass_kg": path.mass_kg,
                "radius_m": path.radius_m,
                "gyration_m": path.gyration_m,
            },
            "seeder": {
                "x_m": x0 + 1e-3,
                "z_m": float(path.z_m[start]) + 0.01,
                "vx_mps": float(vx),
                "vz_mps": float(vz),
                "vx_sd_mps": 0.5,
                "vz_sd_mps": 0.5,
            },
        },
        source=f"the loop's model of {path.path_id}",
    )


def path_design(path: LoopPath) -> CampaignDesign:
    """The survey of ``path`` as the loop repeats it: its own position error, trees
    as often as its flights had them, at most as many scars as it has."""
    spacing = 0.0
    if path.tree_share > 0:
        share = min(path.tree_share, 0.95)
        spacing = -path.mean_flight_m / math.log(1.0 - share)
    return CampaignDesign(
        position_sigma_m=path.position_sigma_m,
        elevation_sigma_m=path.elevation_sigma_m,
        strike_height_sigma_m=path.strike_height_sigma_m,
        tree_spacing_m=spacing,
        theta0_deg=path.theta0_deg,
        max_scars=path.scars,
    )


def loop_table(
    paths: list[LoopPath],
    materials: dict[str, dict[str, float]],
    effects: dict[str, dict[str, float]],
    rng: np.random.Generator,
) -> tuple[ImpactTable, int, int]:
    """One virtual campaign through the reduction, standing in for the observed
    table: on each observed path's profile, rocks are simulated and surveyed until
    they have left as many impacts as the path has. Each rock starts at an observed
    scar with the rebound velocity the reduction gave the observed rock there
    (:func:`path_model`), the first at the first scar, each next one at the
    observed scar past the last one's end, and is surveyed for at most
    :data:`PIECE_SCARS` scars, so the speed is brought back to the observed one
    every few flights (a lumped-mass rock keeps whatever speed scale it has); the
    flight from its start is reduced as a release and left out
    (:func:`_without_release`); each rock is reduced on its own with the path's
    options and its rows take the path's id, so the diagnosis holds them out in
    blocks as it holds out the observed path. Returns the table, the rocks
    surveyed and the rocks whose reduction failed (left out).

    A lumped-mass rock of the fitted baseline often flies farther between impacts
    than the surveyed rock did, so one observed path is usually pieced together
    from several simulated rocks: what is matched is the number of impacts and the
    survey and reduction, not the length of each rock's run.
    """
    frames = []
    rocks = failed = 0
    for path in paths:
        design = path_design(path)
        body = resolve_body(
            mass_kg=path.mass_kg, radius_m=path.radius_m, gyration_m=path.gyration_m
        )
        options = ReduceOptions(
            path_id=path.path_id,
            theta0_deg=path.theta0_deg,
            body=body,
            position_error=PositionError(
                position_sigma_m=path.position_sigma_m,
                elevation_sigma_m=path.elevation_sigma_m,
                strike_height_sigma_m=path.strike_height_sigma_m,
            ),
        )
        have = 0
        tries = 0
        start = 1 if len(path.x_m) > 3 else 0
        while have < path.scars:
            tries += 1
            if tries > 10 * path.scars:
                raise FieldkitError(
                    f"{path.path_id}: {tries} simulated rocks of the fitted baseline "
                    f"left only {have} of its {path.scars} scars",
                    source="null campaign",
                )
            left = path.scars - have
            rock_design = replace(
                design, max_scars=max(2, min(left + 1, PIECE_SCARS)), min_scars=2
            )
            model = path_model(path, materials, effects, start)
            rocks += 1
            try:
                made = virtual_campaign(model, rock_design, 1, rng, source="null")
            except FieldkitError:
                # no rock from this scar left two scars before the profile's end
                # (near the foot of a path): start again higher up
                failed += 1
                start = int(rng.integers(1, max(2, len(path.x_m) - 2)))
                start = max(start, 1) if len(path.x_m) > 3 else 0
                continue
            virtual = made.paths[0]
            # the next rock starts at the observed scar past this one's last
            end = float(virtual.truth["x_true_m"].iloc[-1])
            start = int(np.searchsorted(path.x_m, end, side="right"))
            if start >= len(path.x_m) - 2:
                # past the path's end: go on from a scar drawn at random (not the
                # release again: the path has one source and one cliff)
                start = int(rng.integers(1, max(2, len(path.x_m) - 2)))
            start = max(start, 1) if len(path.x_m) > 3 else 0
            try:
                reduced = reduce_path(virtual.survey, options).table.frame
            except FieldkitError:
                failed += 1
                continue
            reduced = _without_release(reduced)
            reduced["path_id"] = path.path_id
            reduced["point"] = f"rock{rocks}." + reduced["point"].astype(str)
            frames.append(reduced)
            have += len(virtual.survey.points) - 2
    table = ImpactTable(pd.concat(frames, ignore_index=True), source="null campaign")
    return table, rocks, failed


def _without_release(frame: pd.DataFrame) -> pd.DataFrame:
    """A rock started mid-path: its first flight was reduced as a release (the
    least-speed launch), which the observed path has only at its source; so the
    release row goes and the first scar keeps only its rebound (no arriving
    flight, not an impact), as the observed path's first scar after a release
    would not be repeated."""
    out = frame.iloc[1:].copy()
    first = out.index[0]
    for column in ("vi_x_mps", "vi_z_mps", "omega_i_radps"):
        if column in out:
            out.loc[first, column] = np.nan
    return ImpactTable(out.reset_index(drop=True)).derive().frame


@dataclass(frozen=True)
class LoopTask:
    """One campaign to simulate and diagnose (picklable for the worker pool)."""

    kind: str  # "null" or the candidate whose power is measured
    paths: list[LoopPath]
    materials: dict[str, dict[str, float]]
    effects: dict[str, dict[str, float]]
    candidates: list[str]
    folds: int
    gain_floor: float
    seed: np.random.SeedSequence


def run_task(task: LoopTask) -> dict:
    """Simulate, survey, reduce and screen one campaign (the diagnosis's first
    step, :func:`~fieldkit.diagnose.impacts.screen_impacts`): its best gain, each
    candidate's gain and what the rule recommends (``failed`` says why when the
    campaign could not be made)."""
    from fieldkit.diagnose.impacts import screen_impacts

    rng = np.random.default_rng(task.seed)
    try:
        table, rocks, failed = loop_table(task.paths, task.materials, task.effects, rng)
        screen = screen_impacts(
            table,
            None,
            rng=rng,
            folds=task.folds,
            candidates=task.candidates,
            gain_floor=task.gain_floor,
        )
    except FieldkitError as exc:
        return {"kind": task.kind, "failed": str(exc)}
    return {
        "kind": task.kind,
        "failed": None,
        "best_gain": screen.best_gain,
        "gains": screen.gains,
        "recommended": screen.recommended,
        "baseline_cv_rmse": screen.baseline_cv_rmse,
        "impacts": len(table),
        "rocks": rocks,
        "rocks_failed": failed,
    }


def run_tasks(
    tasks: list[LoopTask],
    workers=None,
    progress: Callable[[int], None] | None = None,
) -> list[dict]:
    """Every task, in order, through the Dask engine (:mod:`fieldkit.parallel.
    engine`): ``workers`` an :class:`~fieldkit.parallel.engine.Engine`, or a count
    of local worker processes (None: one per core, fewer than 4 tasks in this
    process; 1: this process). Each task carries its own seed, so the results do
    not depend on where it ran."""
    from fieldkit.parallel.engine import Engine

    if not isinstance(workers, Engine):
        with Engine(engine_spec_of(workers)) as engine:
            return run_tasks(tasks, engine, progress)
    last = 0

    def advance(done: int, total: int) -> None:
        nonlocal last
        if progress:
            progress(done - last)
        last = done

    return workers.map(run_task, tasks, label="campaign", progress=advance,
                       tiny=len(tasks) < 4)  # fmt: skip


def engine_spec_of(workers: int | None):
    """The engine of a worker count (:func:`run_tasks`)."""
    from fieldkit.parallel.engine import EngineSpec

    return EngineSpec(workers=0 if workers == 1 else workers)


def check_loop_options(
    null: int | None, power: int, quantile: float, workers: int | None
) -> None:
    """Refuse null/power sizes, a quantile or a worker count that cannot work."""
    for name, value in (("null", null), ("power", power)):
        if value is not None and not 0 <= value <= MAX_CAMPAIGNS:
            raise ArgumentError(
                f"must be from 0 to {MAX_CAMPAIGNS:,} campaigns (got {value})",
                source=name,
            )
    if not (math.isfinite(quantile) and 0.5 <= quantile < 1.0):
        raise ArgumentError(
            f"must be at least 0.5 and below 1 (got {quantile:g})",
            source="null_quantile",
        )
    if null and null < math.ceil(1.0 / (1.0 - quantile)) - 1:
        need = math.ceil(1.0 / (1.0 - quantile)) - 1
        raise ArgumentError(
            f"{null} null campaigns cannot show a gain beyond their {quantile:g} "
            f"quantile: give at least {need}",
            source="null",
        )
    if workers is not None and not 1 <= workers <= 256:
        raise ArgumentError(f"must be from 1 to 256 (got {workers})", source="workers")


def null_threshold(gains: np.ndarray, quantile: float) -> float:
    """The Monte Carlo test's critical gain: the ``ceil(q (B + 1))``-th smallest of
    ``B`` null gains (+inf when B is too small for the level).

    Examples
    --------
    >>> null_threshold(np.arange(19.0), 0.95)
    18.0
    >>> null_threshold(np.arange(99.0), 0.95)
    94.0
    """
    g = np.sort(np.asarray(gains, float))
    k = int(math.ceil(quantile * (g.size + 1)))
    return float(g[k - 1]) if 1 <= k <= g.size else math.inf


@dataclass
class LoopResult:
    """The null and the power of one surveyed table's diagnosis."""

    threshold: float
    quantile: float
    null_gains: np.ndarray
    null_baseline_cv_rmse: np.ndarray
    null_failed: int
    power: dict[str, dict]
    notes: list[str]
    first_failure: str | None = None

    def null_json(self, observed_gain: float) -> dict:
        """The JSON's ``null`` (ARCHITECTURE §7: size, quantile, gains)."""
        return null_record(
            "campaigns",
            "campaigns simulated under the fitted baseline on each path's own "
            "profile, surveyed and reduced with the table's own options, diagnosed; "
            "the statistic is the best candidate's held-out gain",
            self.null_gains,
            self.quantile,
            self.threshold,
            observed_gain,
            failed=self.null_failed,
            baseline_cv_rmse=self.null_baseline_cv_rmse,
        )


def null_record(
    kind: str,
    method: str,
    gains: np.ndarray,
    quantile: float,
    threshold: float,
    observed_gain: float,
    *,
    failed: int = 0,
    baseline_cv_rmse: np.ndarray | None = None,
) -> dict:
    """A diagnosis's ``null`` (docs/architecture.md §4), for null campaigns and
    null tables alike: the Monte Carlo p of ``observed_gain`` among ``gains``."""
    g = np.asarray(gains, float)
    exceed = int(np.sum(g >= observed_gain)) if math.isfinite(observed_gain) else 0
    return {
        "kind": kind,
        "method": method,
        "size": int(g.size),
        "failed": int(failed),
        "quantile": quantile,
        "threshold": _num(threshold),
        "observed_gain": _num(observed_gain),
        "p_value": (1 + exceed) / (g.size + 1) if g.size else None,
        "gains": [_num(v) for v in g],
        "baseline_cv_rmse_mps": [
            _num(v) for v in (baseline_cv_rmse if baseline_cv_rmse is not None else [])
        ],
    }


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def baseline_world(
    table: ImpactTable, params: dict[str, float], model: Model | None
) -> tuple[dict[str, dict[str, float]], dict[str, dict[str, float]]]:
    """``(materials, effects)`` of the fitted baseline, as a model file has them:
    the fitted e_n, e_t per material with the table's own scatter
    (:func:`material_scatter`), friction from ``model`` (else 30 deg), and the
    effects of ``model`` with their fitted parameters."""
    scatter = material_scatter(table)
    materials: dict[str, dict[str, float]] = {}
    effects: dict[str, dict[str, float]] = {}
    for name, value in params.items():
        head, _, rest = name.partition(".")
        if head == "materials":
            material, _, key = rest.partition(".")
            materials.setdefault(material, {})[key] = float(value)
        else:
            effects.setdefault(head, {})[rest] = float(value)
    for name, values in materials.items():
        sd_n, sd_t = scatter.get(name, (MIN_SCATTER, MIN_SCATTER))
        friction = 30.0
        if model is not None and name in model.materials:
            friction = float(model.materials[name].friction_deg)
        values.setdefault("e_n", 0.5)
        values.setdefault("e_t", 0.8)
        values["friction_deg"] = friction
        values["e_n_sd"] = min(sd_n, 2.5)
        values["e_t_sd"] = min(sd_t, 1.0)
    if model is not None:
        for name, values in model.effects.items():
            effects[name] = {**values, **effects.get(name, {})}
    return materials, effects


def calibrate(
    table: ImpactTable,
    first: object,
    *,
    model: Model | None,
    candidates: list[str],
    folds: int,
    seed: int,
    null_size: int = DEFAULT_NULL,
    power_size: int = DEFAULT_POWER,
    quantile: float = DEFAULT_QUANTILE,
    workers: int | None = None,
    progress: Callable[[int], None] | None = None,
) -> LoopResult:
    """The null threshold and each candidate's power for ``table``.

    ``first`` is the plain diagnosis of ``table`` (its baseline's fitted
    parameters and the candidates' fitted sizes are what the campaigns simulate).
    Null and power campaigns draw from streams spawned from ``seed`` apart from
    the diagnosis's own fold deal. ``workers``: as :func:`run_tasks` (one engine
    for every campaign of the call).
    """
    from fieldkit.parallel.engine import Engine

    if not isinstance(workers, Engine):
        with Engine(engine_spec_of(workers)) as engine:
            return calibrate(
                table, first, model=model, candidates=candidates, folds=folds,
                seed=seed, null_size=null_size, power_size=power_size,
                quantile=quantile, workers=engine, progress=progress,
            )  # fmt: skip
    paths, notes = loop_paths(table)
    materials, effects = baseline_world(table, first.baseline.params, model)
    root = np.random.SeedSequence([int(seed), 18])
    null_seeds = root.spawn(null_size)
    null_tasks = [
        LoopTask("null", paths, materials, effects, candidates, folds, 0.0, s)
        for s in null_seeds
    ]
    results = run_tasks(null_tasks, workers, progress)
    # a campaign that could not be made is replaced (fresh streams, at most two
    # rounds), so the test has the size asked for whenever the geometry allows it
    for _ in range(2):
        missing = sum(r["failed"] is not None for r in results)
        ok_count = len(results) - missing
        if not missing or ok_count >= null_size:
            break
        extra = [
            LoopTask("null", paths, materials, effects, candidates, folds, 0.0, s)
            for s in root.spawn(null_size - ok_count)
        ]
        results += run_tasks(extra, workers, None)
    ok = [r for r in results if r["failed"] is None]
    failed = [r for r in results if r["failed"] is not None]
    gains = np.array([r["best_gain"] for r in ok], float)
    threshold = null_threshold(gains, quantile) if gains.size else math.inf
    base_cv = np.array([r["baseline_cv_rmse"] for r in ok], float)
    power: dict[str, dict] = {}
    power_tasks = []
    sizes: dict[str, dict[str, float]] = {}
    for cand in first.candidates:
        values = {k.split(".", 1)[1]: v for k, v in cand.params.items()}
        sizes[cand.effect] = values
        world = {**effects, cand.effect: {**effects.get(cand.effect, {}), **values}}
        power_seeds = root.spawn(power_size)
        power_tasks += [
            LoopTask(
                cand.effect, paths, materials, world, candidates, folds, threshold, s
            )  # fmt: skip
            for s in power_seeds
        ]
    if power_tasks and math.isfinite(threshold):
        for r in run_tasks(power_tasks, workers, progress):
            entry = power.setdefault(
                r["kind"],
                {"params": sizes[r["kind"]], "campaigns": 0, "found": 0, "failed": 0},
            )
            if r["failed"] is not None:
                entry["failed"] += 1
                continue
            entry["campaigns"] += 1
            entry["found"] += int(r["recommended"] == r["kind"])
        for entry in power.values():
            n = entry["campaigns"]
            entry["rate"] = entry["found"] / n if n else None
            entry["rate_se"] = (
                math.sqrt(entry["rate"] * (1 - entry["rate"]) / n) if n else None
            )
    if failed:
        notes.append(
            f"{len(failed)} of {len(results)} null campaigns could not be simulated "
            f"or reduced (first: {failed[0]['failed']}) and were replaced by new "
            f"ones; the null is the {len(ok)} made"
        )
    return LoopResult(
        threshold=threshold,
        quantile=quantile,
        null_gains=gains,
        null_baseline_cv_rmse=base_cv,
        null_failed=len(failed),
        power=power,
        notes=notes,
        first_failure=failed[0]["failed"] if failed else None,
    )


def power_words(effect: str, entry: dict) -> str:
    """ "with this survey, velocity_scaled_restitution at k_mps 6.5 would be found in
    12 % (± 5 %) of campaigns"."""
    params = ", ".join(f"{k} {v:.3g}" for k, v in entry["params"].items())
    rate = entry.get("rate")
    if rate is None:
        return f"{effect}: no power campaign could be simulated"
    return (
        f"with this survey, {effect} at {params or 'its default'} would be found in "
        f"{rate:.0%} (± {entry['rate_se']:.0%}) of {entry['campaigns']} campaigns"
    )


def diagnose_surveyed(
    table: ImpactTable,
    model: Model | None,
    *,
    seed: int,
    folds: int,
    null_size: int = DEFAULT_NULL,
    power_size: int = DEFAULT_POWER,
    quantile: float = DEFAULT_QUANTILE,
    workers: int | None = None,
    progress: Callable[[str], None] | None = None,
    loop_progress: Callable[[int, int], None] | None = None,
):
    """Diagnose a reduced survey with the reduction in the loop (module docstring).

    The plain diagnosis is run first (its fitted baseline and candidate sizes set
    the campaigns); then ``null_size`` null campaigns and ``power_size`` campaigns
    per candidate; then the diagnosis again with the null's threshold as the least
    gain a candidate must show (same seed, same folds). Returns the
    :class:`~fieldkit.diagnose.diagnosis.Diagnosis` with ``null`` and ``power``.
    """
    from fieldkit.diagnose.impacts import diagnose_impacts

    first = diagnose_impacts(
        table, model, rng=np.random.default_rng(seed), folds=folds, progress=progress
    )
    tested = [c.effect for c in first.candidates]
    if not tested:
        first.notes.append("no candidate to test: no null campaigns simulated")
        return first
    total = null_size + power_size * len(tested)
    done = 0

    def advance(k: int) -> None:
        nonlocal done
        done += k
        if loop_progress:
            loop_progress(done, total)

    loop = calibrate(
        table,
        first,
        model=model,
        candidates=tested,
        folds=folds,
        seed=seed,
        null_size=null_size,
        power_size=power_size,
        quantile=quantile,
        workers=workers,
        progress=advance,
    )
    floor = loop.threshold if math.isfinite(loop.threshold) else math.inf
    final = diagnose_impacts(
        table,
        model,
        rng=np.random.default_rng(seed),
        folds=folds,
        candidates=tested,
        gain_floor=floor,
    )
    final.notes = first.notes + loop.notes
    best = max((c.improvement for c in final.candidates), default=math.nan)
    final.null = loop.null_json(best)
    final.power = {
        name: {**entry, "words": power_words(name, entry)}
        for name, entry in loop.power.items()
    }
    g = loop.null_gains
    final.rule += (
        f"; on a surveyed table the gain must also exceed the {quantile:.0%} "
        f"quantile of the gains of {g.size} effect-free campaigns simulated under "
        "the fitted baseline and surveyed and reduced like this one "
        f"({gain_text(loop.threshold)})"
    )
    if first.recommended and not final.recommended:
        c = next(c for c in first.candidates if c.effect == first.recommended)
        exceed = int(np.sum(g >= c.improvement))
        final.stopped = (
            f"{c.effect} lowers the held-out error by {c.improvement:+.1%} ± "
            f"{c.improvement_se:.1%}, which passes the plain rule, but {exceed} of "
            f"{g.size} effect-free campaigns through the same survey and reduction "
            f"gained as much (threshold {gain_text(loop.threshold)}): no finding"
        )
    rates = [e["rate"] for e in loop.power.values() if e.get("rate") is not None]
    if final.recommended:
        verdict = (
            f"{final.recommended} is found: its gain exceeds what "
            f"{g.size} effect-free campaigns through the same survey and reduction "
            f"gained in {quantile:.0%} of cases"
        )
    elif not rates:
        verdict = (
            "no finding beyond what the survey and the reduction produce with no "
            "effect; the power was not simulated (power campaigns 0), so whether "
            "this survey could have found one is not known"
        )
    elif max(rates) < LOW_POWER:
        verdict = (
            "the data cannot tell the laws apart: with this survey no candidate at "
            f"its fitted size would be found in {LOW_POWER:.0%} of campaigns; more "
            "surveyed paths, tree strikes that fix the launch angle, or measured "
            "slopes at the scars would"
        )
    else:
        verdict = (
            "no effect found, and this survey could have found one: a candidate at "
            f"its fitted size would be found in {max(rates):.0%} of campaigns"
        )
    final.null["verdict"] = verdict
    return final


def loop_lines(null: dict | None, power: dict | None) -> list[str]:
    """The null, the power and the verdict in words (the summary and the report)."""
    if not null:
        return []
    gains = np.array([v for v in null["gains"] if v is not None], float)
    what = (
        "null tables of the fitted baseline with the table's own errors"
        if null.get("kind") == "tables"
        else "effect-free campaigns simulated under the fitted baseline on the "
        "path's own profile, surveyed and reduced like the table"
    )
    lines = [
        f"null: {null['size']} {what}"
        + (f" ({null['failed']} could not be made, replaced)" if null["failed"] else "")
        + ": best gains median "
        + (gain_text(float(np.median(gains))) if gains.size else "n/a")
        + f", {null['quantile']:.0%} quantile "
        + gain_text(null["threshold"] or math.inf),
    ]
    observed = null.get("observed_gain")
    if observed is not None and null.get("p_value") is not None:
        lines.append(
            f"null: the observed best gain {observed:+.1%} is reached by "
            f"{int(np.sum(gains >= observed))} of them (Monte Carlo p = "
            f"{null['p_value']:.2g})"
        )
    lines += [f"power: {entry['words']}" for entry in (power or {}).values()]
    if null.get("verdict"):
        lines.append(f"verdict: {null['verdict']}")
    return lines


def gain_text(x: float) -> str:
    """A gain as a signed percentage, or 'not available' when not finite."""
    return f"{x:+.1%}" if math.isfinite(x) else "not available"
