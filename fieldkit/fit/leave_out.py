"""Leave-out refits: how a calibration moves without its suspect data (issue 20).

Given a fit's inputs and its result, each *variant* refits the same free
parameters with one group of suspect observations (:mod:`fieldkit.fit.suspect`)
excluded -- ``flagged out`` (impacts the reduction flags energy_gained or
e_t_above_1) and ``assumed θ0 out`` (flights on an assumed launch angle) -- the
other group treated as in the fit. A refit is a search only: no bootstrap, no
slices; it starts from the calibrated values, with the same seed (common random
numbers) and, for a path fit, each kind scaled by its CRPS at the fit's own start
(the objective of the fit with fewer data, not a new one). A path fit's refit
costs about one search each (:func:`path_leave_outs`); an impact fit's a least
squares each (:func:`impact_leave_outs`).

Each :class:`LeaveOut` gives what was dropped (counts by kind and by flag), the
refitted values, the shift of each from the full fit in its unit and in the full
fit's standard errors, and the refitted :class:`~fieldkit.model.model_file.Model`
(:func:`leave_out_models`: named models for a design-quantity comparison).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from fieldkit.errors import InputFileError
from fieldkit.fit.impact_fit import (
    MIN_IMPACTS_PER_MATERIAL,
    free_parameters,
    impact_problem,
    solve_reweighted,
    too_few,
)
from fieldkit.fit.path_fit import (
    PathFitResult,
    PathObjective,
    Step,
    _minimise,
    _no_step,
)
from fieldkit.fit.path_runs import PathRun
from fieldkit.fit.suspect import EXCLUDE, GROUPS, SuspectPolicy
from fieldkit.impact_table import SUSPECT_FLAGS, ImpactTable
from fieldkit.model.model_file import Model

#: Variant of each group -> its name.
VARIANTS: dict[str, str] = {
    "flagged": "flagged out",
    "assumed_theta0": "assumed θ0 out",
}


@dataclass
class LeaveOut:
    """One leave-out refit (module docstring).

    ``values`` is NaN-free when refitted; ``model`` None (and ``reason`` set) when
    the variant was not refitted (nothing to leave out, already excluded, too few
    data). ``held`` names parameters the variant has no data for (a material
    without impacts left): they keep the full fit's value.
    """

    group: str
    name: str
    names: list[str]
    full: np.ndarray
    full_se: np.ndarray
    dropped: dict[str, int]
    dropped_by_flag: dict[str, int] = field(default_factory=dict)
    values: np.ndarray | None = None
    model: Model | None = None
    reason: str | None = None
    held: list[str] = field(default_factory=list)
    note: str | None = None  # why some parameters are held
    objective_full: float | None = None  # the variant's objective at the full fit
    objective_refit: float | None = None  # ... and at its own optimum
    evaluations: int = 0

    @property
    def shift(self) -> np.ndarray:
        """Refitted minus full-fit value of each parameter (NaN: not refitted; 0
        where it is rounding, below 1e-9 of the value)."""
        if self.values is None:
            return np.full(len(self.names), np.nan)
        d = self.values - self.full
        return np.where(np.abs(d) < 1e-9 * np.maximum(1.0, np.abs(self.full)), 0.0, d)

    @property
    def shift_se(self) -> np.ndarray:
        """:attr:`shift` in the full fit's standard errors (NaN without one)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            out = self.shift / self.full_se
        return np.where(np.isfinite(out), out, np.nan)

    def to_dict(self) -> dict:
        """JSON-ready (no model; NaN as None)."""
        return {
            "variant": self.name,
            "group": self.group,
            "dropped": dict(self.dropped),
            "dropped_by_flag": dict(self.dropped_by_flag),
            "refitted": self.values is not None,
            "reason": self.reason,
            "held": list(self.held),
            "note": self.note,
            "objective_full": self.objective_full,
            "objective_refit": self.objective_refit,
            "evaluations": self.evaluations,
            "parameters": [
                {
                    "name": n,
                    "full": _num(f),
                    "full_stderr": _num(se),
                    "refitted": None if self.values is None else _num(v),
                    "shift": _num(d),
                    "shift_in_stderr": _num(z),
                }
                for n, f, se, v, d, z in zip(
                    self.names,
                    self.full,
                    self.full_se,
                    self.full if self.values is None else self.values,
                    self.shift,
                    self.shift_se,
                    strict=True,
                )
            ],
        }


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def variant_policies(policy: SuspectPolicy) -> list[tuple[str, SuspectPolicy]]:
    """``(group, policy with that group excluded)`` for each group of
    :data:`fieldkit.fit.suspect.GROUPS`."""
    return [(g, replace(policy, **{g: EXCLUDE})) for g in GROUPS]


def _dropped_by_flag(variant: list, full: list) -> dict[str, int]:
    """Per flag, the values the variant excludes beyond the full fit (both lists
    of :class:`~fieldkit.fit.suspect.SuspectCount`)."""

    def total(counts: list, flag: str) -> int:
        return sum(c.excluded_by_flag.get(flag, 0) for c in counts)

    return {f: total(variant, f) - total(full, f) for f in SUSPECT_FLAGS}


def impact_leave_outs(
    table: ImpactTable,
    model: Model,
    result,
    calibrated: Model,
    policy: SuspectPolicy | None = None,
) -> list[LeaveOut]:
    """Refit an impact fit (:func:`fieldkit.fit.impact_fit.fit_impacts` of
    ``table`` and ``model`` with ``policy``, giving ``result`` and
    ``calibrated``) without each group of suspect impacts.

    A variant needs only more data than parameters (its refit is a comparison,
    not a calibration with standard errors); parameters of a material with fewer
    than :data:`~fieldkit.fit.impact_fit.MIN_IMPACTS_PER_MATERIAL` impacts left
    are held at the full fit's values.

    Parameters
    ----------
    table, model
        The table and the base model the fit was given.
    result, calibrated
        What :func:`~fieldkit.fit.impact_fit.fit_impacts` returned.
    policy
        The fit's suspect-data policy (default: keep everything).

    Returns
    -------
    list of LeaveOut
        ``flagged out`` then ``assumed θ0 out``; one that could not be refitted
        has ``model`` None and its ``reason``.
    """
    policy = policy or SuspectPolicy()
    full = np.asarray(result.values, float)
    full_se = np.asarray(result.stderr, float)
    out = []
    for group, variant in variant_policies(policy):
        name = VARIANTS[group]
        try:
            problem = impact_problem(table, model, variant)
        except InputFileError as exc:  # nothing left to fit: said, not fatal
            leave = LeaveOut(group, name, list(result.names), full, full_se, {}, {})
            leave.reason = exc.message
            out.append(leave)
            continue
        c = problem.suspect
        already = result.suspect.excluded if result.suspect is not None else 0
        dropped = {"impacts": c.excluded - already}
        base = [result.suspect] if result.suspect is not None else []
        leave = LeaveOut(
            group, name, list(result.names), full, full_se, dropped,
            _dropped_by_flag([c], base),
        )  # fmt: skip
        if policy.treatment(group).exclude:
            leave.reason = "already excluded in the fit"
        elif getattr(c, group) == 0:
            leave.reason = f"no impact {GROUPS[group]}"
        if leave.reason:
            out.append(leave)
            continue
        # a material with fewer impacts left than a fit takes keeps its values:
        # one impact gives its e_n, e_t exactly, with nothing to tell its scatter
        used = problem.inputs.material_index[problem.use.any(axis=1)]
        left = {
            m: int(np.sum(used == problem.inputs.material_names.index(m)))
            for m in problem.materials
        }
        enough = [m for m, k in left.items() if k >= MIN_IMPACTS_PER_MATERIAL]
        free, _ = free_parameters(model, enough)
        names = [n for n in result.names if n in free]
        leave.held = [n for n in result.names if n not in free]
        few = {m: k for m, k in left.items() if k < MIN_IMPACTS_PER_MATERIAL}
        if few:
            leave.note = "held at the full fit: " + ", ".join(
                f"{m} ({k} impact{'s' * (k != 1)} left)" for m, k in few.items()
            )
        why = too_few(problem, names)
        if why:
            leave.reason = why
            out.append(leave)
            continue
        start = np.array([full[result.names.index(n)] for n in names])
        bounds = problem.bounds(model, names)
        start = np.clip(start, bounds[:, 0], bounds[:, 1])
        _, fit = solve_reweighted(problem, model, names, start)
        values = full.copy()
        for n, v in zip(names, fit.x, strict=True):
            values[result.names.index(n)] = float(v)
        leave.values = values
        leave.model = calibrated.with_parameters(
            dict(zip(result.names, map(float, values), strict=True))
        )
        leave.model = replace(leave.model, provenance=dict(calibrated.provenance))
        leave.evaluations = int(getattr(fit, "nfev", 0))
        out.append(leave)
    return out


def path_leave_outs(
    runs: Sequence[PathRun],
    result: PathFitResult,
    *,
    kinds: Sequence[str] | None = None,
    max_evaluations: int | None = None,
    step: Step | None = None,
) -> list[LeaveOut]:
    """Refit a path fit (``result`` of :func:`fieldkit.fit.path_fit.fit_paths` on
    ``runs``) without each group of suspect observed values: a Nelder-Mead search
    from the calibrated values in the fit's bounds, ``result.rocks`` rocks and
    ``result.seed`` (common random numbers), each kind scaled by its CRPS at the
    fit's start; ``max_evaluations`` as the fit's main search (default ``max(150,
    60 p)``). Values and kinds as ``result`` scored them (``kinds``: the fit's,
    default ``result.kinds``).

    Parameters
    ----------
    runs
        The runs the fit was given.
    result
        The fit's result (its policy, counts, bounds, start, rocks and seed).
    kinds
        The kinds the fit scored, if it was given them.
    max_evaluations
        Objective evaluations of each refit's search.
    step
        ``step(description, total)`` context manager around each refit.

    Returns
    -------
    list of LeaveOut
        ``flagged out`` then ``assumed θ0 out``, with the variant's objective at
        the full fit's values and at its own optimum.
    """
    stage = step or _no_step
    names = list(result.names)
    p = len(names)
    lower, upper = np.asarray(result.lower, float), np.asarray(result.upper, float)
    span = upper - lower
    full = np.asarray(result.values, float)
    full_se = np.asarray(result.stderr, float)
    budget = max_evaluations or max(150, 60 * p)
    out = []
    for group, variant in variant_policies(result.suspect_policy):
        name = VARIANTS[group]
        objective = PathObjective(
            runs, names, result.rocks, result.seed, kinds or result.kinds,
            suspect=variant,
        )
        dropped = {
            k: c.excluded - (result.suspect[k].excluded if k in result.suspect else 0)
            for k, c in objective.suspect.items()
        }
        by_flag = _dropped_by_flag(
            list(objective.suspect.values()), list(result.suspect.values())
        )
        leave = LeaveOut(group, name, names, full, full_se, dropped, by_flag)
        if result.suspect_policy.treatment(group).exclude:
            leave.reason = "already excluded in the fit"
        elif sum(dropped.values()) == 0:
            leave.reason = f"no observed value {GROUPS[group]}"
        if leave.reason:
            out.append(leave)
            continue
        objective.set_scales(np.asarray(result.start, float))

        def f(u, objective=objective):
            return objective(lower + span * np.clip(u, 0.0, 1.0))

        u0 = (full - lower) / span
        with stage(f"leave-out refit, {name}: one search", None):
            f0 = f(u0)
            first = int(budget * 0.7)
            u1, f1, _ = _minimise(f, u0, 0.15, first)
            u2, f2, _ = _minimise(f, u1, 0.05, max(budget - first, p + 2))
        u_best, f_best = (u2, f2) if f2 <= f1 else (u1, f1)
        if f0 <= f_best:  # the search found nothing better than where it began
            u_best, f_best = u0, f0
        values = lower + span * np.clip(u_best, 0.0, 1.0)
        leave.values = values
        leave.model = result.model.with_parameters(
            dict(zip(names, map(float, values), strict=True))
        )
        leave.objective_full, leave.objective_refit = float(f0), float(f_best)
        leave.evaluations = objective.evaluations
        out.append(leave)
    return out


def leave_out_models(leave_outs: Sequence[LeaveOut]) -> dict[str, Model]:
    """The refitted models by variant name (``"flagged out"``, ...), for a
    design-quantity comparison beside the start and calibrated models."""
    return {lo.name: lo.model for lo in leave_outs if lo.model is not None}


def leave_out_lines(leave_outs: Sequence[LeaveOut]) -> list[str]:
    """A short table: per parameter the full fit's value and each variant's
    refitted value with its shift (in units and the full fit's standard errors),
    then what each variant dropped, or why it was not refitted."""
    if not leave_outs:
        return []
    names = leave_outs[0].names
    width = max(len(n) for n in names)
    head = f"  {'':<{width}}  {'full fit':>10}" + "".join(
        f"  {lo.name:>30}" for lo in leave_outs
    )
    lines = [head]
    for j, n in enumerate(names):
        row = f"  {n:<{width}}  {leave_outs[0].full[j]:>10.4g}"
        for lo in leave_outs:
            if lo.values is None:
                cell = "not refitted"
            elif n in lo.held:
                cell = f"{lo.values[j]:.4g} (held)"
            else:
                d, z = lo.shift[j], lo.shift_se[j] + 0.0  # no -0.0
                se = f", {z:+.1f} SE" if math.isfinite(z) else ""
                cell = f"{lo.values[j]:.4g} ({d:+.3g}{se})"
            row += f"  {cell:>30}"
        lines.append(row)
    for lo in leave_outs:
        total = sum(lo.dropped.values())
        parts = ", ".join(f"{k} {v}" for k, v in lo.dropped.items() if v)
        flags = ", ".join(f"{k} {v}" for k, v in lo.dropped_by_flag.items() if v)
        several = len(lo.dropped) > 1 and parts
        text = f"  {lo.name}: dropped {total}" + (f" ({parts})" if several else "")
        if flags:
            text += f"; by flag: {flags}"
        if lo.note:
            text += f"; {lo.note}"
        if lo.reason:
            text += f"; not refitted: {lo.reason}"
        elif lo.objective_full is not None:
            text += (
                f"; objective on the remaining data {lo.objective_full:.4g} at the "
                f"full fit -> {lo.objective_refit:.4g} refitted "
                f"({lo.evaluations} evaluations)"
            )
        lines.append(text)
    return lines
