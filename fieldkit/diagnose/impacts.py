"""Diagnose an ImpactTable: where the model fails and which effect is missing.

The loop (issue 10, docs/architecture.md §4):

1. **Baseline** — constant ``e_n``, ``e_t`` per material (or the given model,
   its effects' parameters refitted) — scored by its held-out error: k-fold
   cross-validation over independent groups (paths, or blocks of consecutive
   impacts when there are too few paths, :mod:`~fieldkit.diagnose.groups`).
2. **Where it fails** — per-impact and per-material held-out residuals, the worst
   impacts named, and a test of whether the residuals depend on each feature
   (:mod:`~fieldkit.diagnose.residual_tests`).
3. **Which effect is missing** — each candidate the data can inform
   (:mod:`~fieldkit.diagnose.candidates`) is added in turn, refitted on the
   training folds and scored on the held-out ones; ranked by held-out error, each
   with its gain ``1 - cv/cv_ref`` and the jackknife SE of that gain
   (:mod:`~fieldkit.diagnose.scoring`). A candidate is *meaningful* when its gain
   exceeds ``z`` standard errors. When another meaningful candidate's gain is
   within ``z`` paired standard errors of the best one's, the two cannot be told
   apart: both are reported as confounded, with the measurement that would
   separate them, and neither is added.
4. **Stepwise** — the best meaningful candidate is accepted, the rest ranked again
   against the new model, until none is meaningful (or a confounded pair stops it).
5. **What stays unexplained** — the dependence tests on the final model's held-out
   residuals; any dependence left is reported as outside the candidates' reach.

Residuals are in m/s: ``vfn``, ``vft`` and spins as the surface speed
``r omega_f``; weights ``1/sd^2`` from the same uncertainties the fit uses
(:func:`fieldkit.fit.impact_fit.impact_problem`), normalised, so the metric is a
weighted RMSE in m/s (plain RMSE with unit weights).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fieldkit.diagnose import candidates as cands
from fieldkit.diagnose import residual_tests
from fieldkit.diagnose.diagnosis import Candidate, Diagnosis, ModelScore, Step
from fieldkit.diagnose.groups import DEFAULT_FOLDS, Groups, make_groups
from fieldkit.diagnose.scoring import (
    CONFOUND_Z,
    DEFAULT_Z,
    MIN_GAIN,
    HeldOut,
    held_out,
    improvement,
    meaningful,
    recommendation_rule,
    weighted_rmse,
)
from fieldkit.errors import InputFileError
from fieldkit.fit.impact_fit import (
    ImpactProblem,
    fit_result,
    free_parameters,
    impact_problem,
    too_few,
)
from fieldkit.fit.synthetic import with_effects
from fieldkit.impact_table import ImpactTable, path_point_kinds
from fieldkit.model.model_file import Model, model_from_dict

METRIC = "cv_rmse_mps"
#: Fewest groups (paths or blocks) a diagnosis needs (jackknife SE, 3 folds).
MIN_GROUPS = 3
#: Worst impacts named in the report.
N_WORST = 5
#: Most rows that are not impacts named one by one in :func:`impact_count`.
N_NAMED_ROWS = 5


def not_impacts(table: ImpactTable) -> list[tuple[int, str]]:
    """The rows of ``table`` that are not impacts: ``(row, what)``, row 1-based.

    These are the rows every fit leaves out
    (:func:`~fieldkit.fit.impact_fit.no_flight_rows`): a reduced path's release
    point (no arriving flight), stop point (no leaving flight) and the two ends of a
    flight the reduction could not solve (``flight_unsolved``).
    """
    return path_point_kinds(table.frame)


def impact_count(table: ImpactTable) -> str:
    """How many impacts of ``table`` a diagnosis uses, in words, with the rows left
    out named (the number the summary, the report and the JSON's ``n_rows`` give).

    Examples
    --------
    >>> import pandas as pd
    >>> frame = pd.DataFrame({
    ...     "path_id": ["A"] * 3, "point": ["1", "2", "3"], "x_m": [0.0, 5, 10],
    ...     "z_m": [9.0, 5, 0], "slope_deg": [-40.0] * 3,
    ...     "vi_x_mps": [None, 1.0, 2.0], "vi_z_mps": [None, -1, -2],
    ...     "vf_x_mps": [1.0, 2.0, None], "vf_z_mps": [1, 1, None]})
    >>> impact_count(ImpactTable(frame))
    '1 impact (of 3 rows; not impacts: row 1, a release point; row 3, a stop point)'
    """
    left = not_impacts(table)
    n = len(table) - len(left)
    head = f"{n} impact" + ("" if n == 1 else "s")
    if not left:
        return head
    named = [f"row {row}, {what}" for row, what in left[:N_NAMED_ROWS]]
    if len(left) > N_NAMED_ROWS:
        named.append(f"{len(left) - N_NAMED_ROWS} more")
    return f"{head} (of {len(table)} rows; not impacts: {'; '.join(named)})"


@dataclass
class Scored:
    """A model variant with its held-out residuals and full-data fit."""

    model: Model
    effects: list[str]
    held: HeldOut
    residual: np.ndarray  # (n, 3) held-out residuals [m/s]
    params: dict[str, float]
    params_sd: dict[str, float]
    fit_rmse: float

    @property
    def cv_rmse(self) -> float:
        """Weighted held-out RMSE [m/s]."""
        return self.held.rmse

    def score(self) -> ModelScore:
        """As a :class:`ModelScore`."""
        return ModelScore(
            list(self.effects), self.cv_rmse, self.params, self.params_sd, self.fit_rmse
        )


def base_model(table: ImpactTable) -> Model:
    """Constant ``e_n``, ``e_t`` per material of ``table`` (the base model).

    Starting values are each material's median measured ``e_n``, ``e_t`` (clipped
    to [0.05, 1.5]); the profile, seeder and friction angle are placeholders an
    impact-level diagnosis never reads.
    """
    with warnings.catch_warnings():  # empty columns are reported by the checks
        warnings.simplefilter("ignore", RuntimeWarning)
        return _base_model(table)


def _base_model(table: ImpactTable) -> Model:
    frame = table.derive().frame
    materials = {}
    for name, rows in frame.groupby(frame["material"].astype("string"), sort=True):
        e_n = float(np.nanmedian(rows["e_n"])) if rows["e_n"].notna().any() else 0.5
        e_t = float(np.nanmedian(rows["e_t"])) if rows["e_t"].notna().any() else 0.8
        materials[str(name)] = {
            "e_n": float(np.clip(e_n, 0.05, 1.5)),
            "e_t": float(np.clip(e_t, 0.05, 1.5)),
            "friction_deg": 30.0,
        }
    first = next(iter(materials)) if materials else "rock"
    radius = float(np.nanmedian(table.column("radius_m"))) if len(frame) else 0.5
    return model_from_dict(
        {
            "profile": {"x_m": [0.0, 1.0], "z_m": [1.0, 0.0], "material": first},
            "materials": materials
            or {"rock": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30.0}},
            "body": {"mass_kg": 1.0, "radius_m": radius if radius > 0 else 0.5},
            "seeder": {"x_m": 0.0, "z_m": 2.0},
        },
        source="base model (constant e_n, e_t per material)",
    )


class _Scorer:
    """Cross-validated scoring of model variants on one problem."""

    def __init__(self, problem: ImpactProblem, groups: Groups) -> None:
        self.problem = problem
        self.groups = groups
        scale = np.ones_like(problem.observed)
        scale[:, 2] = problem.inputs.radius_m
        self.scale = scale  # omega -> surface speed r omega
        sd = problem.sd * scale
        w = np.where(problem.use, 1.0 / sd**2, np.nan)
        self.weight = w / np.nanmean(w)

    def held_out(self, model: Model) -> HeldOut:
        """Only the cross-validated score of ``model`` (no full-data fit)."""
        residual = self._cv_residual(model)
        return held_out(residual, self.weight, self.groups.group, self.groups.n_groups)

    def _cv_residual(self, model: Model) -> np.ndarray:
        p = self.problem
        names, _ = free_parameters(model, p.materials)
        residual = np.full_like(p.observed, np.nan)
        labels = p.table.frame["material"].astype("string").to_numpy(str)
        for k in range(self.groups.n_folds):
            test = self.groups.fold == k
            seen = set(labels[~test & p.use.any(axis=1)])
            # A material absent from the training folds keeps its starting values.
            free = [
                n
                for n in names
                if not n.startswith("materials.") or n.split(".")[1] in seen
            ]
            fit = p.solve(model, free, ~test)
            pred = p.predict(model, free, fit.x)
            residual[test] = (p.observed[test] - pred[test]) * self.scale[test]
        residual[~p.use] = np.nan
        return residual

    def score(self, model: Model, effects: list[str]) -> Scored:
        """Cross-validated residuals and the full-data fit of ``model``."""
        p = self.problem
        names, _ = free_parameters(model, p.materials)
        residual = self._cv_residual(model)
        start, _ = p.start(model, names)
        full = p.solve(model, names, start=start)
        result = fit_result(p, names, start, full, [])
        pred = p.predict(model, names, full.x)
        r_all = np.where(p.use, (p.observed - pred) * self.scale, np.nan)
        fit_rmse = weighted_rmse(r_all, self.weight)
        held = held_out(residual, self.weight, self.groups.group, self.groups.n_groups)
        return Scored(
            model=model.with_parameters(
                dict(zip(names, map(float, full.x), strict=True))
            ),
            effects=effects,
            held=held,
            residual=residual,
            params=dict(zip(names, map(float, full.x), strict=True)),
            params_sd=dict(zip(names, map(float, result.stderr), strict=True)),
            fit_rmse=fit_rmse,
        )


def _check(problem: ImpactProblem, groups: Groups, model: Model, extra: list[str]):
    table = problem.table
    if groups.n_groups < MIN_GROUPS:
        raise InputFileError(
            f"too few impacts to diagnose: {len(table)} impact(s) make "
            f"{groups.n_groups} independent group(s); need at least {MIN_GROUPS} "
            "(paths, or blocks of consecutive impacts) for held-out scores",
            source=table.source,
        )
    widest = with_effects(model, {e: {} for e in extra})
    names, _ = free_parameters(widest, problem.materials)
    for k in range(groups.n_folds):
        why = too_few(problem, names, groups.fold != k)
        if why:
            raise InputFileError(
                f"{why} in every training fold (fold {k + 1} of {groups.n_folds} "
                "falls short)",
                source=table.source,
            )


def _prepare(
    table: ImpactTable,
    model: Model,
    rng: np.random.Generator,
    folds: int,
    candidates: list[str] | None,
):
    """The problem, path ids, fold groups, candidate pool and skipped candidates
    of a diagnosis (and of its first-step screen), every check passed."""
    problem = impact_problem(table, model)
    path_id = (
        problem.table.frame["path_id"].astype("string").fillna("").to_numpy(str)
        if "path_id" in problem.table.frame
        else np.array(["path"] * len(problem.table))
    )
    groups = make_groups(path_id, rng, folds=folds)
    pool, skipped = cands.impact_candidates(problem, model)
    if candidates is not None:
        for name in pool:
            if name not in candidates:
                skipped[name] = "left out by the caller"
        pool = [c for c in pool if c in candidates]
    _check(problem, groups, model, pool)
    return problem, path_id, groups, pool, skipped


def diagnose_impacts(
    table: ImpactTable,
    model: Model | None = None,
    *,
    rng: np.random.Generator,
    folds: int = DEFAULT_FOLDS,
    z: float = DEFAULT_Z,
    z_confound: float = CONFOUND_Z,
    candidates: list[str] | None = None,
    progress: Callable[[str], None] | None = None,
    gain_floor: float = MIN_GAIN,
) -> Diagnosis:
    """Diagnose ``table`` against ``model`` (None: constant e_n, e_t per material).

    ``z`` is the recommendation rule (gain > z SE and > ``MIN_GAIN``);
    ``z_confound`` the rule of the conditional gains that decide
    confounding (see :func:`_alike`).
    ``gain_floor`` is the least held-out gain a candidate must show (the rule's
    1 %, or a null's threshold when larger: :mod:`fieldkit.diagnose.survey_loop`).
    ``rng`` deals the groups to folds (a seed reproduces the diagnosis exactly);
    ``candidates`` restricts the candidate effects (default: every one the table
    can inform); ``progress`` is called with a short message before each model is
    scored, the first time once every check of the table has passed. See the
    module docstring for the method.

    Raises
    ------
    InputFileError
        Missing columns (named), non-finite values (rows named), materials not in
        the model, too few impacts or groups (how many are needed).
    """
    notes: list[str] = []
    if model is None:
        model = base_model(table)
        notes.append(
            "baseline: constant e_n, e_t per material (no --model given), fitted"
        )
    problem, path_id, groups, pool, skipped = _prepare(
        table, model, rng, folds, candidates
    )
    notes += problem.notes
    notes.append(f"weights: {problem.weighting}")
    scorer = _Scorer(problem, groups)
    say = progress or (lambda _msg: None)
    say("baseline")
    baseline = scorer.score(model, list(model.effects))
    current = baseline
    steps: list[Step] = []
    first: list[Candidate] | None = None
    confounded: list[list[str]] = []
    advice: list[str] = []
    remaining = list(pool)
    rankings: list[list[Candidate]] = []  # every round, the last one included
    accepted: list[Scored] = []
    stopped = "no candidate effect the data can inform" if not pool else ""
    while remaining:
        scored = {}
        for name in remaining:
            say(f"step {len(steps) + 1}: {name}")
            variant = with_effects(current.model, {name: {}})
            scored[name] = scorer.score(variant, [*current.effects, name])
        ranked = _rank(current, scored, z, max(MIN_GAIN, gain_floor))
        rankings.append(ranked)
        if first is None:
            first = ranked
        best = ranked[0]
        if not best.meaningful:
            stopped = (
                "no remaining candidate passes the rule (best: "
                f"{best.effect}, gain {best.improvement:+.1%} ± "
                f"{best.improvement_se:.1%})"
            )
            break
        alike = _alike(scorer, scored, ranked, z_confound)
        if alike:
            for other in alike:
                confounded.append([best.effect, other])
                advice.append(cands.separating_measurement(best.effect, other, problem))
            stopped = (
                f"{best.effect} cannot be told apart from {', '.join(alike)} "
                "(neither adds a meaningful held-out gain to the other): neither "
                "is added"
            )
            break
        after = scored[best.effect]
        steps.append(Step(best.effect, current.cv_rmse, after.cv_rmse, ranked))
        current = after
        accepted.append(after)
        remaining.remove(best.effect)
    else:
        if pool:
            stopped = "every candidate was added"
    features = residual_tests.impact_features(
        problem.table.frame, cands.measured_spin(problem)
    )
    sd = np.sqrt(1.0 / scorer.weight)
    stage_tests = [
        residual_tests.dependence_tests(r / sd, features)
        for r in [baseline.residual] + [s.residual for s in accepted]
    ]
    before_tests, after_tests = stage_tests[0], stage_tests[-1]
    if groups.unit == "block":
        notes.append(
            "held out: blocks of one path, not independent rocks. An impact's "
            "arrival and rebound come from the same surveyed points, so survey error "
            "is shared across blocks and between vin and vfn; on error-only "
            "simulations of the thesis surveys the rule found an effect in 1 of 20 "
            "tables (Tornado Mountain; 0 of 20 on the others, "
            "docs/real-data-diagnosis.md)"
        )
    if len(set(path_id)) < len(path_id) / 2:
        notes.append(
            "dependence tests treat impacts as independent; impacts of one rock "
            "share its shape and survey errors, so on few paths they are liberal"
        )
    return Diagnosis(
        metric=METRIC,
        baseline=baseline.score(),
        candidates=first or [],
        recommended=steps[0].added if steps else None,
        steps=steps,
        confounded=confounded,
        after=current.score(),
        rule=(
            f"a candidate is recommended when {recommendation_rule(z)} (jackknife "
            "over the held-out groups); the best and a runner-up that passes the "
            "rule too are confounded (neither is added) when neither lowers the "
            f"other's held-out error by more than {MIN_GAIN * 100:g} % and by more "
            f"than {z_confound:g} standard error(s) of that gain"
        ),
        groups=groups.description,
        stopped=stopped,
        skipped=skipped,
        advice=advice,
        dependence_before=before_tests,
        dependence_after=after_tests,
        unexplained=residual_tests.describe(after_tests),
        worst=_worst(problem, baseline.residual, scorer.weight),
        per_material=_per_material(problem, baseline, current, scorer.weight),
        notes=notes,
        n_data=int(problem.use.sum()),
        n_rows=len(problem.table),
        size=impact_count(table),
        arrays={
            "features": features,
            "baseline": baseline.residual,
            "after": current.residual,
            "steps": [s.residual for s in accepted],
            "weight": scorer.weight,
            "path_id": path_id,
            "after_model": current.model,
            "dependence": stage_tests,
            "rankings": rankings,
        },
    )


def _rank(
    current: Scored, scored: dict[str, Scored], z: float, floor: float = MIN_GAIN
) -> list[Candidate]:
    out = []
    for name, s in scored.items():
        gain, se = improvement(current.held, s.held)
        added = {k: v for k, v in s.params.items() if k.startswith(name + ".")}
        added_sd = {k: v for k, v in s.params_sd.items() if k.startswith(name + ".")}
        out.append(
            Candidate(
                name,
                s.cv_rmse,
                gain,
                se,
                meaningful(gain, se, z=z, min_gain=floor),
                added,
                added_sd,
            )
        )
    return sorted(out, key=lambda c: c.cv_rmse)


def _alike(
    scorer: _Scorer,
    scored: dict[str, Scored],
    ranked: list[Candidate],
    z: float,
) -> list[str]:
    """Meaningful runners-up that explain the same thing as the best candidate.

    For the best ``A`` and each meaningful runner-up ``B`` the model with both is
    scored: when neither adds a meaningful held-out gain to the other (``B`` given
    ``A`` and ``A`` given ``B``), the data cannot tell them apart. When ``B`` adds
    to ``A`` both are real (``B`` is ranked again at the next step); when only
    ``A`` adds to ``B``, ``A`` is the better explanation.
    """
    best = ranked[0].effect
    out = []
    for other in ranked[1:]:
        if not other.meaningful:
            continue
        both = with_effects(scored[best].model, {other.effect: {}})
        held = scorer.held_out(both)
        if meaningful(*improvement(scored[best].held, held), z=z):
            continue
        if meaningful(*improvement(scored[other.effect].held, held), z=z):
            continue
        out.append(other.effect)
    return out


def _worst(problem: ImpactProblem, residual: np.ndarray, weight: np.ndarray) -> list:
    frame = problem.table.frame
    z = np.abs(residual) * np.sqrt(weight)
    zmax = np.nanmax(np.where(np.isfinite(z), z, -1.0), axis=1)
    order = np.argsort(-zmax, kind="stable")[:N_WORST]
    out = []
    for i in order:
        j = int(np.nanargmax(np.where(np.isfinite(z[i]), z[i], -1.0)))
        out.append(
            {
                "row": int(problem.rows[i]) + 1,
                "path_id": str(frame["path_id"].iloc[i]) if "path_id" in frame else "",
                "point": str(frame["point"].iloc[i]) if "point" in frame else "",
                "material": str(frame["material"].iloc[i]),
                "component": residual_tests.COMPONENTS[j],
                "residual_mps": float(residual[i, j]),
                "z": float(z[i, j]),
            }
        )
    return out


def _per_material(
    problem: ImpactProblem, baseline: Scored, after: Scored, weight: np.ndarray
) -> dict:
    labels = problem.table.frame["material"].astype("string").to_numpy(str)
    out = {}
    for m in problem.materials:
        rows = labels == m
        entry = {"impacts": float(rows.sum())}
        for label, s in (("baseline", baseline), ("after", after)):
            entry[f"{label}_cv_rmse_mps"] = weighted_rmse(
                s.residual[rows], weight[rows]
            )
            entry[f"{label}_bias_vfn_mps"] = float(np.nanmean(s.residual[rows, 0]))
            entry[f"{label}_bias_vft_mps"] = float(np.nanmean(s.residual[rows, 1]))
        out[m] = entry
    return out


@dataclass
class Screen:
    """The first step of a diagnosis only: each candidate's held-out gain over the
    baseline and what the rule would recommend (what a null or power campaign
    needs; :mod:`fieldkit.diagnose.survey_loop`)."""

    gains: dict[str, float]
    ses: dict[str, float]
    baseline_cv_rmse: float
    recommended: str | None

    @property
    def best_gain(self) -> float:
        """The largest gain (-inf with no candidate)."""
        return max(self.gains.values(), default=-float("inf"))


def screen_impacts(
    table: ImpactTable,
    model: Model | None = None,
    *,
    rng: np.random.Generator,
    folds: int = DEFAULT_FOLDS,
    z: float = DEFAULT_Z,
    candidates: list[str] | None = None,
    gain_floor: float = MIN_GAIN,
) -> Screen:
    """:func:`diagnose_impacts`'s first step, held-out scores only: the same
    baseline, folds (for the same ``rng``), candidates and rule, without the full-data
    fits, the confounding check, the later steps or the residual tests. The
    recommendation is the best candidate when it passes the rule (a confounded pair
    is not looked for, so it is at most as strict as the full diagnosis)."""
    if model is None:
        model = base_model(table)
    problem, _, groups, pool, _ = _prepare(table, model, rng, folds, candidates)
    scorer = _Scorer(problem, groups)
    base = scorer.held_out(model)
    gains, ses = {}, {}
    for name in pool:
        gains[name], ses[name] = improvement(
            base, scorer.held_out(with_effects(model, {name: {}}))
        )
    floor = max(MIN_GAIN, gain_floor)
    best = max(gains, key=gains.get, default=None)
    passed = best is not None and meaningful(
        gains[best], ses[best], z=z, min_gain=floor
    )
    return Screen(gains, ses, base.rmse, best if passed else None)
