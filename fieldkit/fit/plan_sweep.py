"""3-D path calibration over seeds and splits, each fit an independent unit of work
run through the Dask engine (:mod:`fieldkit.parallel.engine`).

A unit is one :func:`~fieldkit.fit.plan_fit.fit_plan` -- a calibration set, a seed,
the search settings -- followed, when the unit has held-out runs, by the
calibrated model's held-out ensembles on the hold-out stream
(:data:`~fieldkit.fit.plan_fit.HOLDOUT_STREAM`, apart from every fit's). A unit's
numbers depend only on its own runs, seed and settings, so a sweep gives the same
fits and scores in this process or on any number of workers; the base model is
sent to each worker once. A worker returns the fitted values (the calibrated
model is rebuilt here from them, exactly as the fit builds it) and the held-out
deposits, not the model.

Examples
--------
A repeated k-fold on a cluster (``engine`` an :class:`~fieldkit.parallel.engine.
Engine`; ``folds`` from :func:`fieldkit.fit.plan_scores.repeated_kfold`)::

    units = [PlanFitUnit(f"fold {f.fold} of repeat {f.repeat}",
                         tuple(runs[i] for i in f.calibration),
                         tuple(runs[i] for i in f.holdout), FREE, seed=1)
             for f in folds]
    for unit, fit in zip(units, plan_fit_sweep(base, units, engine)): ...
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from fieldkit.fit import plan_fit


@dataclass(frozen=True)
class PlanFitUnit:
    """One fit of a sweep (module docstring); the search settings are
    :func:`~fieldkit.fit.plan_fit.fit_plan`'s."""

    label: str
    calibration: tuple
    holdout: tuple
    free: tuple[str, ...]
    seed: int
    rocks: int = 100
    max_evaluations: int | None = None
    screen: int = 0
    distance_weight: float = 0.0
    holdout_rocks: int = 200


@dataclass
class SweptFit:
    """What a unit gives: the fit's names, start and fitted values, objectives,
    report lines; the held-out ensembles (one ``(rocks, 2)`` array of deposits in
    plan per held-out run) and the share of their rocks that left the DEM."""

    label: str
    names: list[str]
    values: np.ndarray
    objective: float
    evaluations: int
    lines: list[str]
    holdout_xy: list | None
    holdout_exited_share: float | None
    seconds: float

    def model(self, base):
        """The calibrated model (as :func:`~fieldkit.fit.plan_fit.fit_plan` builds
        it from the fitted values)."""
        return plan_fit.with_parameters3d(
            base, dict(zip(self.names, self.values, strict=True))
        )


def run_plan_fit(base, unit: PlanFitUnit) -> SweptFit:
    """Fit one unit and forecast its held-out runs."""
    import time

    tic = time.perf_counter()
    fit = plan_fit.fit_plan(
        list(unit.calibration),
        base,
        list(unit.free),
        rocks=unit.rocks,
        seed=unit.seed,
        max_evaluations=unit.max_evaluations,
        screen=unit.screen,
        distance_weight=unit.distance_weight,
    )
    xy = share = None
    if unit.holdout:
        ens = plan_fit.plan_ensembles(
            fit.model, list(unit.holdout), unit.holdout_rocks, unit.seed,
            stream=plan_fit.HOLDOUT_STREAM,
        )  # fmt: skip
        xy, share = ens.deposits_xy, float(ens.exited_share)
    return SweptFit(
        label=unit.label,
        names=list(fit.names),
        values=np.asarray(fit.values, float),
        objective=float(fit.objective),
        evaluations=int(fit.evaluations),
        lines=fit.lines(),
        holdout_xy=xy,
        holdout_exited_share=share,
        seconds=time.perf_counter() - tic,
    )


def plan_fit_sweep(
    base,
    units: Sequence[PlanFitUnit],
    engine,
    progress: Callable[[int, int], None] | None = None,
) -> list[SweptFit]:
    """Every unit's fit through ``engine``, in the order of ``units``."""
    return engine.map(
        run_plan_fit,
        list(units),
        names=[u.label for u in units],
        progress=progress,
        shared=base,
        tiny=len(units) < 2,
    )
