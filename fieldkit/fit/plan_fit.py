"""Calibrate a 3-D model on release/deposit observations, scored in plan (issue 21).

Each observed run (:class:`PlanRun`: its release point, its block's mass and
radius, its observed deposit) is simulated on the DEM from its own release with
``rocks`` rocks; the objective is the mean over runs of the **fair energy score**
of the simulated deposits in plan against the observed deposit
(:func:`fieldkit.fit.plan_scores.energy_score`), optionally plus ``distance_weight``
times the mean fair CRPS of the release-to-deposit distance,

.. math:: S(\\theta) = \\frac1N \\sum_r \\mathrm{ES}_{fair}(F_{r,\\theta}, y_r)
          + w \\frac1N \\sum_r \\mathrm{CRPS}_{fair}(D_{r,\\theta}, d_r).

**Rocks that leave the DEM** (state exited: off the grid or onto nodata) are
scored *at their exit point* -- the last position on the DEM, which the kernel
returns as their deposit. A rock that leaves the DEM downslope has run at least
that far, so the exit point understates its runout; on Tschamut's DEM the
observed deposits lie well inside the grid and exits are rare. The share of
exited rocks is reported (:attr:`PlanFitResult.exited_share`), so a fit driven
to the grid's edge is visible. Rocks stopped by the impact cap lie where they
were when it was reached.

**Common random numbers**: run ``r`` (its position in the list of runs) is
simulated with ``default_rng([seed, r])`` whatever the parameters, so the
objective is a deterministic function of the parameters for a seed. **Held-out
scoring** uses ``default_rng([seed, HOLDOUT_STREAM, r])``
(:func:`plan_ensembles` with ``stream=HOLDOUT_STREAM``): streams independent of
every calibration stream, so a held-out score does not reuse the rocks the fit
tuned the parameters on.

**Search**: the path fit's (:mod:`fieldkit.fit.path_fit`): Nelder-Mead in the
unit cube of the parameters' practical bounds
(:func:`fieldkit.fit.path_fit.parameter_bounds`), from the base model's values
and, with ``screen``, also from the best point of a scrambled Sobol screen,
then restarted once from the best optimum with a small simplex.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields, replace

import numpy as np
from scipy.stats import qmc

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.fit.path_fit import _minimise, parameter_bounds
from fieldkit.fit.path_runs import one_kernel_thread
from fieldkit.fit.plan_scores import energy_score, fair_crps
from fieldkit.model.effects import registry
from fieldkit.model.materials import MATERIAL_FIELDS
from fieldkit.model.model3d import Model3D
from fieldkit.model.simulate3d import simulate3d

#: Stream tag of held-out simulations: ``default_rng([seed, HOLDOUT_STREAM, r])``
#: (calibration uses ``[seed, r]``; a key of another length is another stream).
HOLDOUT_STREAM = 104_729
#: Stream tag of the Sobol screen's scrambling.
SCREEN_STREAM = 3
#: Columns a release file and a deposit file must hold.
RELEASE_COLUMNS = ("trajectory_id", "x_m", "y_m", "mass_kg", "radius_m")
DEPOSIT_COLUMNS = ("trajectory_id", "x_m", "y_m")


@dataclass(frozen=True)
class PlanRun:
    """One observed run: release point, block, observed deposit (all in metres,
    kilograms; plan coordinates of the DEM); ``group`` the block's id where the
    release file gives ``block_id`` (to stratify folds by)."""

    run_id: str
    release_xy: np.ndarray
    deposit_xy: np.ndarray
    mass_kg: float
    radius_m: float
    group: str = ""


def _read_rows(path: str, needed: Sequence[str]) -> list[dict[str, str]]:
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        raise InputFileError(f"cannot read: {exc.strerror}", source=path) from None
    if not rows:
        raise InputFileError("no data rows", source=path)
    missing = [c for c in needed if c not in rows[0]]
    if missing:
        raise InputFileError(
            f"missing column(s) {', '.join(missing)}", source=path, where="row 1"
        )
    return rows


def _number(row: dict, name: str, path: str, line: int) -> float:
    try:
        value = float(row[name])
    except (TypeError, ValueError):
        value = math.nan
    if not math.isfinite(value):
        raise InputFileError(
            f"{name}: not a finite number ({row[name]!r})",
            source=path,
            where=f"row {line}",
        )
    return value


def read_plan_runs(release_csv: str, deposit_csv: str) -> list[PlanRun]:
    """The runs of a release file and a deposit file, joined on ``trajectory_id``
    (in the release file's order).

    Raises
    ------
    InputFileError
        A missing column, a value that is not a finite number, a mass or radius
        <= 0, a release without a deposit, or a trajectory_id twice in a file.
    """
    rel = _read_rows(str(release_csv), RELEASE_COLUMNS)
    dep = _read_rows(str(deposit_csv), DEPOSIT_COLUMNS)
    deposits: dict[str, np.ndarray] = {}
    for line, row in enumerate(dep, start=2):
        tid = row["trajectory_id"]
        if tid in deposits:
            raise InputFileError(
                f"trajectory_id {tid} appears twice",
                source=str(deposit_csv),
                where=f"row {line}",
            )
        deposits[tid] = np.array(
            [_number(row, c, str(deposit_csv), line) for c in ("x_m", "y_m")]
        )
    runs, seen = [], set()
    for line, row in enumerate(rel, start=2):
        tid = row["trajectory_id"]
        if tid in seen:
            raise InputFileError(
                f"trajectory_id {tid} appears twice",
                source=str(release_csv),
                where=f"row {line}",
            )
        seen.add(tid)
        if tid not in deposits:
            raise InputFileError(
                f"trajectory_id {tid} has no deposit in {deposit_csv}",
                source=str(release_csv),
                where=f"row {line}",
            )
        v = {c: _number(row, c, str(release_csv), line) for c in RELEASE_COLUMNS[1:]}
        for c in ("mass_kg", "radius_m"):
            if not v[c] > 0:
                raise InputFileError(
                    f"{c}: must be > 0 (got {v[c]:g})",
                    source=str(release_csv),
                    where=f"row {line}",
                )
        runs.append(
            PlanRun(
                tid,
                np.array([v["x_m"], v["y_m"]]),
                deposits[tid],
                v["mass_kg"],
                v["radius_m"],
                str(row.get("block_id", "")),
            )
        )
    return runs


def parameters3d(model: Model3D) -> dict[str, float]:
    """Flat namespaced view of a 3-D model's fittable numbers, as 2-D's
    :meth:`fieldkit.model.model_file.Model.parameters`: ``materials.<m>.<field>``,
    ``<effect>.<param>`` (active effects), ``core.<setting>``."""
    out: dict[str, float] = {}
    for name, material in model.materials.items():
        for f in fields(material):
            if f.name != "name":
                out[f"materials.{name}.{f.name}"] = float(getattr(material, f.name))
    for name, values in model.effects.items():
        for key, value in values.items():
            out[f"{name}.{key}"] = float(value)
    for key, value in model.core.items():
        out[f"core.{key}"] = float(value)
    return out


def with_parameters3d(model: Model3D, values: dict[str, float]) -> Model3D:
    """A new :class:`Model3D` with some :func:`parameters3d` replaced, each checked
    against its field's bounds (:data:`fieldkit.model.materials.MATERIAL_FIELDS`,
    the effect's parameter bounds).

    Raises
    ------
    ArgumentError
        An unknown name or a value outside its bounds (names ``values`` and the
        parameter).
    """
    known = parameters3d(model)
    materials = dict(model.materials)
    effects = {k: dict(v) for k, v in model.effects.items()}
    core = dict(model.core)
    for key, value in values.items():
        if key not in known:
            raise ArgumentError(
                f"{key}: unknown parameter (known: {', '.join(known)})", source="values"
            )
        value = float(value)
        parts = key.split(".")
        if parts[0] == "materials":
            lo, hi = MATERIAL_FIELDS[parts[2]][:2]
            if not lo <= value <= hi:
                raise ArgumentError(
                    f"{key}: must be in [{lo:g}, {hi:g}] (got {value:g})",
                    source="values",
                )
            materials[parts[1]] = replace(materials[parts[1]], **{parts[2]: value})
        elif parts[0] == "core":
            core[parts[1]] = value
        else:
            effects[parts[0]] = registry.validate(
                parts[0], effects[parts[0]] | {parts[1]: value}, source="values"
            )
    return replace(model, materials=materials, effects=effects, core=core)


def run_model(model: Model3D, run: PlanRun) -> Model3D:
    """``model`` released from ``run``'s release point with ``run``'s block (its
    mass and radius; the radius of gyration scaled with the radius).

    Raises
    ------
    ArgumentError
        The release is off the DEM's surface (names the run).
    """
    r0 = model.body.radius_m
    body = replace(
        model.body,
        mass_kg=run.mass_kg,
        radius_m=run.radius_m,
        gyration_m=model.body.gyration_m * run.radius_m / r0,
    )
    x, y = run.release_xy
    z = model.terrain.height(float(x), float(y))
    if not math.isfinite(z):
        raise ArgumentError(
            f"run {run.run_id}: release (x {x:g}, y {y:g}) is off the DEM's surface "
            "(outside its cell centres or beside nodata)",
            source="runs",
        )
    return replace(
        model, body=body, releases=np.array([[x, y, z]]), release_weights=np.ones(1)
    )


@dataclass(frozen=True)
class PlanEnsembles:
    """Simulated deposits in plan, run by run, and how many rocks left the DEM."""

    deposits_xy: list[np.ndarray]
    exited: int
    rocks: int

    @property
    def exited_share(self) -> float:
        return self.exited / self.rocks if self.rocks else math.nan


def plan_ensembles(
    model: Model3D,
    runs: Sequence[PlanRun],
    rocks: int,
    seed: int,
    *,
    stream: int | None = None,
) -> PlanEnsembles:
    """Deposits (rocks, 2) of every run: run ``r`` with ``default_rng([seed, r])``
    (calibration), or ``default_rng([seed, stream, r])`` (e.g.
    :data:`HOLDOUT_STREAM`). Exited rocks lie at their exit point (module
    docstring)."""
    from fieldkit.model.kernel3d import EXITED

    out, exited = [], 0
    with one_kernel_thread():
        for r, run in enumerate(runs):
            key = [seed, r] if stream is None else [seed, stream, r]
            res = simulate3d(
                run_model(model, run),
                rocks,
                np.random.default_rng(key),
                keep_paths=False,
            )
            out.append(res.deposit_xyz[:, :2].copy())
            exited += int(np.sum(res.state == EXITED))
    return PlanEnsembles(out, exited, rocks * len(runs))


def plan_objective_terms(
    ensembles: Sequence[np.ndarray], runs: Sequence[PlanRun]
) -> tuple[np.ndarray, np.ndarray]:
    """Per-run fair energy score [m] and fair distance CRPS [m]."""
    es = np.array(
        [
            energy_score(e, r.deposit_xy, fair=True)
            for e, r in zip(ensembles, runs, strict=True)
        ]
    )
    crps = np.array(
        [
            fair_crps(
                np.hypot(*(e - r.release_xy).T),
                float(np.hypot(*(r.deposit_xy - r.release_xy))),
            )
            for e, r in zip(ensembles, runs, strict=True)
        ]
    )
    return es, crps


@dataclass
class PlanFitResult:
    """A 3-D plan fit: start and optimum, their objectives, the calibrated model."""

    names: list[str]
    start: np.ndarray
    values: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    objective_start: float
    objective: float
    evaluations: int
    model: Model3D
    exited_share: float
    distance_weight: float
    notes: list[str] = field(default_factory=list)

    def value(self, name: str) -> float:
        return float(self.values[self.names.index(name)])

    def lines(self) -> list[str]:
        """Report lines: every parameter start -> optimum, the objective."""
        out = [
            "objective (mean fair energy score in plan"
            + (
                f" + {self.distance_weight:g} x distance CRPS"
                if self.distance_weight
                else ""
            )
            + f"): start {self.objective_start:.3f} m -> optimum {self.objective:.3f}"
            f" m after {self.evaluations} evaluations"
        ]
        for n, s, v, lo, hi in zip(
            self.names, self.start, self.values, self.lower, self.upper, strict=True
        ):
            bound = (
                " (at a search bound)" if np.isclose(v, lo) or np.isclose(v, hi) else ""
            )
            out.append(f"  {n}: {s:.4g} -> {v:.4g} [{lo:g}, {hi:g}]{bound}")
        out.append(
            f"  rocks that left the DEM (or a tracked extent) at the optimum: "
            f"{100 * self.exited_share:.1f} % (scored at their exit point)"
        )
        return out + [f"  note: {n}" for n in self.notes]


def fit_plan(
    runs: Sequence[PlanRun],
    base_model: Model3D,
    free: Sequence[str],
    *,
    rocks: int = 100,
    seed: int = 0,
    max_evaluations: int | None = None,
    screen: int = 0,
    bounds: dict[str, tuple[float, float]] | None = None,
    start: dict[str, float] | None = None,
    distance_weight: float = 0.0,
    progress: Callable[[str], None] | None = None,
) -> PlanFitResult:
    """Fit the ``free`` parameters of a 3-D model to observed deposits in plan.

    Parameters
    ----------
    runs
        Observed runs (:func:`read_plan_runs`), each simulated from its own release
        with its own block.
    base_model
        The model the parameters start from (its values, unless ``start``).
    free
        Namespaced parameters (:func:`parameters3d`).
    rocks, seed
        Rocks per run and evaluation; seed of the common random numbers.
    max_evaluations
        Objective evaluations of the search (default ``max(100, 40 p)``).
    screen
        Points of a scrambled Sobol screen of the bounds before the search.
    bounds, start
        Search bounds overriding :func:`fieldkit.fit.path_fit.parameter_bounds`;
        start values overriding the base model's (clipped into the bounds).
    distance_weight
        Weight of the mean distance fair CRPS added to the objective (0: the
        energy score alone).
    progress
        Called with one line per stage.

    Returns
    -------
    PlanFitResult
    """
    say = progress or (lambda line: None)
    if not runs:
        raise ArgumentError("no runs to fit", source="runs")
    if not (isinstance(rocks, int | np.integer) and 2 <= rocks <= 20_000):
        raise ArgumentError(
            f"rocks must be 2..20,000 (got {rocks}): the fair "
            "energy score needs two members",
            source="rocks",
        )
    if not (math.isfinite(distance_weight) and distance_weight >= 0):
        raise ArgumentError(
            f"distance_weight must be >= 0 (got {distance_weight})",
            source="distance_weight",
        )
    names = list(free)
    if not names:
        raise ArgumentError("no free parameters", source="free")
    known = parameters3d(base_model)
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ArgumentError(
            f"{', '.join(unknown)}: not parameters of the model "
            f"(known: {', '.join(known)})",
            source="free",
        )
    box = [(bounds or {}).get(n) or parameter_bounds(n) for n in names]
    lower = np.array([b[0] for b in box], float)
    upper = np.array([b[1] for b in box], float)
    span = upper - lower
    x0 = np.array([(start or {}).get(n, known[n]) for n in names], float)
    x0 = np.clip(x0, lower, upper)
    p = len(names)
    evaluations = 0
    last_exited = [math.nan]

    def to_x(u):
        return lower + span * np.clip(u, 0.0, 1.0)

    def objective_at(x) -> float:
        nonlocal evaluations
        evaluations += 1
        model = with_parameters3d(base_model, dict(zip(names, x, strict=True)))
        ens = plan_ensembles(model, runs, rocks, seed)
        last_exited[0] = ens.exited_share
        es, crps = plan_objective_terms(ens.deposits_xy, runs)
        value = float(np.mean(es))
        if distance_weight:
            value += distance_weight * float(np.mean(crps))
        return value

    def f(u):
        return objective_at(to_x(u))

    u0 = (x0 - lower) / span
    f0 = f(u0)
    say(
        f"fit {p} parameters to {len(runs)} runs ({rocks} rocks each): start {f0:.3f} m"
    )
    budget = max_evaluations or max(100, 40 * p)
    starts = [u0]
    if screen > 0:
        sobol = qmc.Sobol(
            p, scramble=True, seed=np.random.default_rng([seed, SCREEN_STREAM])
        )
        points = sobol.random(screen)
        values = np.array([f(u) for u in points])
        best = int(np.argmin(values))
        say(f"screened {screen} points: best {values[best]:.3f} m (start {f0:.3f} m)")
        if values[best] < f0:
            starts.append(points[best])
    first = int(budget * 0.7) // len(starts)
    u1, f1, _ = min((_minimise(f, u, 0.15, first) for u in starts), key=lambda r: r[1])
    u2, f2, _ = _minimise(f, u1, 0.05, max(budget - first * len(starts), p + 2))
    u_best, f_best = (u2, f2) if f2 <= f1 else (u1, f1)
    x_best = to_x(u_best)
    f_check = objective_at(x_best)  # also sets the exited share at the optimum
    say(f"optimum {f_best:.3f} m after {evaluations} evaluations")
    model = with_parameters3d(base_model, dict(zip(names, x_best, strict=True)))
    notes = []
    if not math.isclose(f_check, f_best, rel_tol=1e-9, abs_tol=1e-9):
        notes.append(f"the optimum re-evaluates to {f_check:.3f} m")  # never expected
    return PlanFitResult(
        names=names,
        start=x0,
        values=x_best,
        lower=lower,
        upper=upper,
        objective_start=f0,
        objective=f_best,
        evaluations=evaluations,
        model=model,
        exited_share=last_exited[0],
        distance_weight=float(distance_weight),
        notes=notes,
    )
