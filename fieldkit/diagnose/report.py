"""The diagnosis as a Markdown report a person reads (text only; no I/O).

Sections follow the loop of the issue: the baseline and where it fails, which
effect is missing (ranked, with the gain's standard error), each step with the
held-out error before and after and the fitted parameters, what stays
unexplained, and how the numbers were made. Every quantity is named in words with
its unit through :mod:`fieldkit.diagnose.labels` (the figures use the same words);
the JSON names (``cv_rmse_mps``, ``theta_i_deg``) appear only where a reader needs
them to find a value in the ``--json`` file. Figures are referenced by the file
names :func:`figure_names` gives; the caller writes them.
"""

from __future__ import annotations

import math

from fieldkit.diagnose import labels, residual_tests
from fieldkit.diagnose.diagnosis import Candidate, Dependence, Diagnosis
from fieldkit.model.effects import registry


def figure_names(diagnosis: Diagnosis) -> list[str]:
    """PNG names the report links: the baseline, then one per accepted step."""
    return ["baseline.png"] + [
        f"step_{i + 1}_{s.added}.png" for i, s in enumerate(diagnosis.steps)
    ]


def _fmt(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}" if math.isfinite(x) else "not finite"


def _row(*cells: object) -> str:
    """One Markdown table row; a ``|`` inside a cell is escaped."""
    return "| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |"


def _p(p: float) -> str:
    """A p-value: two significant digits (``< 1e-300`` for an underflow to 0)."""
    if not math.isfinite(p):
        return "not computed"
    return f"{p:.2g}" if p > 0 else "< 1e-300"


def _params_inline(params: dict, sds: dict) -> str:
    if not params:
        return "none"
    return ", ".join(labels.parameter_text(k, v, sds.get(k)) for k, v in params.items())


def _params_table(params: dict, sds: dict) -> list[str]:
    if not params:
        return ["Fitted parameters: none."]
    rows = ["| parameter | value ± standard error |", "|---|---|"]
    for k, v in params.items():
        words, unit = labels.parameter(k)
        rows.append(_row(words, labels.value_text(k, v, sds.get(k))))
    return rows


def rankings(diagnosis: Diagnosis) -> list[list[Candidate]]:
    """The candidates ranked in every round: the first (``candidates``), one per
    later step, and the last round that accepted nothing (when there was one)."""
    ranked = diagnosis.arrays.get("rankings")
    if ranked is not None:
        return list(ranked)
    return [diagnosis.candidates] if diagnosis.candidates else []


def _candidate_rows(candidates: list[Candidate], unit: str) -> list[str]:
    rows = [
        f"| rank | effect | held-out RMS error ({unit}) | gain | standard error "
        "of the gain | passes the rule | fitted parameters |",
        "|---|---|---|---|---|---|---|",
    ]
    for i, c in enumerate(candidates, 1):
        se = (
            f"{c.improvement_se:.1%}"
            if math.isfinite(c.improvement_se)
            else "undetermined (fewer than 3 groups)"
        )
        rows.append(
            _row(
                i,
                f"`{c.effect}`: {labels.effect(c.effect)}",
                _fmt(c.cv_rmse),
                f"{c.improvement:+.1%}",
                se,
                "yes" if c.meaningful else "no",
                _params_inline(c.params, c.params_sd),
            )
        )
    return rows


def _worst_line(w: dict, unit: str) -> str:
    if "flight" in w:  # flights: the label already names the flight and its rows
        return f"* {w['flight']}: RMS position residual {_fmt(w['baseline_rmse_m'])} m"
    return (
        f"* row {w['row']} (path {w['path_id']}, point {w['point']}, "
        f"{w['material']}): {labels.component(w['component'])} residual "
        f"{w['residual_mps']:+.3g} {unit} ({w['z']:.1f} standard deviations of "
        "its measurement)"
    )


def dependence_sentence(d: Dependence) -> str:
    """One dependence in words, each p-value labelled (which test; raw or
    Holm-adjusted)."""
    raw = (
        "the smaller p doubled"
        if d.p_method == residual_tests.COMBINED_P
        else d.p_method.split(": ")[-1] or "the test alone"
    )
    return (
        f"{labels.component(d.component)} residuals depend on "
        f"{labels.feature(d.feature)}: {d.statistic}; p = {_p(d.p_value)} "
        f"({raw}), Holm-adjusted p = {_p(d.p_holm)} ≤ {d.alpha:g}"
    )


def levels(alpha: float) -> str:
    """Which diagnosis tests at ``alpha`` and the level of the other kind: an
    ImpactTable's tests at :data:`~fieldkit.diagnose.residual_tests.ALPHA`, a
    track's flight tests at :data:`~fieldkit.diagnose.flights.DEPENDENCE_ALPHA`.

    Examples
    --------
    >>> levels(0.05)
    "the level of a track's flight tests; an ImpactTable's tests use 0.01"
    """
    from fieldkit.diagnose.flights import DEPENDENCE_ALPHA

    impacts, track = residual_tests.ALPHA, DEPENDENCE_ALPHA
    if alpha == track != impacts:
        return (
            "the level of a track's flight tests; an ImpactTable's tests use "
            f"{impacts:g}"
        )
    if alpha == impacts != track:
        return (
            f"the level of an ImpactTable's tests; a track's flight tests use {track:g}"
        )
    return "the level of every diagnosis"


def _dependence_section(tests: list[Dependence], features: dict) -> list[str]:
    if not tests:
        return ["No residual could be tested against a feature.", ""]
    alpha = tests[0].alpha
    hits = sorted((x for x in tests if x.significant), key=lambda x: x.p_value)
    methods = "; ".join(dict.fromkeys(x.p_method for x in tests if x.p_method))
    out = [
        f"{len(tests)} tests, each residual against each feature. *p* is a test's "
        f"own p-value ({methods or 'the test alone'}); *Holm p* is *p* adjusted by "
        f"Holm's method over all {len(tests)} tests. A residual depends on a "
        f"feature when its Holm p ≤ {alpha:g} ({levels(alpha)}). These tests "
        "describe the residuals only: no recommendation rests on them (a "
        "candidate is recommended by its held-out gain alone).",
        "",
    ]
    if hits:
        out += [
            "| residual | feature | test | p | Holm p |",
            "|---|---|---|---|---|",
        ]
        out += [
            _row(
                labels.component(x.component),
                labels.feature(x.feature),
                x.statistic,
                _p(x.p_value),
                _p(x.p_holm),
            )
            for x in hits
        ]
        out.append("")
        out.append(
            f"The other {len(tests) - len(hits)} tests show no dependence "
            f"(Holm p > {alpha:g})."
        )
    else:
        out.append(f"The residuals depend on no feature (every Holm p > {alpha:g}).")
    tested = sorted({x.feature for x in tests})
    out += [
        "",
        "Features tested: " + "; ".join(labels.feature(f) for f in tested) + ".",
    ]
    untested = [f for f in features if f not in tested]
    if untested:
        out.append(
            "Not tested (drawn in the figure all the same): "
            + "; ".join(
                f"{labels.feature(f)}: {residual_tests.why_untested(features[f])}"
                for f in untested
            )
            + "."
        )
    out.append("")
    return out


def baseline_label(d: Diagnosis) -> str:
    """What the baseline is, in words."""
    if d.metric == "cv_rmse_m":
        base = "ballistic flights (g = 9.81 m/s², no drag)"
    else:
        base = "constant e_n, e_t per material"
    return base + "".join(f" + {labels.effect(e)}" for e in d.baseline.effects)


def markdown(diagnosis: Diagnosis, *, title: str, inputs: list[str]) -> str:
    """The full report for ``diagnosis`` (``inputs``: the files it read)."""
    d = diagnosis
    unit = labels.unit(d.metric)
    error = labels.metric_words(d.metric)
    figs = figure_names(d)
    components = d.arrays.get("components", ("vfn", "vft", "omega_f"))
    out = [f"# Diagnosis: {title}", ""]
    out += [f"* input: `{name}`" for name in inputs]
    out += [
        f"* {d.size or f'{d.n_rows} rows'}, {d.n_data} data; held out: {d.groups}",
        f"* error measure: the {error} ({unit}), the weighted root-mean-square of "
        "the residuals (measured − model) of data held out of the fit "
        f"(`{d.metric}` in the JSON)",
        "* residuals: " + ", ".join(labels.component(c) for c in components)
        + f", all in {unit}",
        "",
        "## Verdict",
        "",
    ]  # fmt: skip
    if d.steps:
        added = ", ".join(f"`{s.added}`" for s in d.steps)
        fall = 1.0 - d.after.cv_rmse / d.baseline.cv_rmse
        out.append(
            f"Missing physics found: {added}. Held-out RMS error "
            f"{_fmt(d.baseline.cv_rmse)} → {_fmt(d.after.cv_rmse)} {unit} "
            f"({fall:.1%} lower)."
        )
    elif d.confounded:
        out.append(
            "No effect recommended: the best candidates cannot be told apart with "
            "these data (see *Confounded*)."
        )
    else:
        out.append(
            "No effect recommended: no candidate the data can inform passes the "
            "rule (see *Which effect is missing*)."
        )
    meaning = alternative_meaning(d)
    if meaning:
        out.append(meaning[0].upper() + meaning[1:] + ".")
    out += [f"Stopped: {d.stopped}.", ""]
    out += _sensitivity_section(d)
    if d.unexplained and d.confounded:
        out.append(
            "**Residual structure left**: the confounded candidates below may "
            "explain it, but the data cannot tell which, so neither was added:"
        )
    elif d.unexplained:
        out.append(
            "**Residual structure no candidate explains** (physics outside "
            "fieldkit's vocabulary, or a data problem):"
        )
        out += [
            f"* {dependence_sentence(x)}"
            for x in sorted(d.dependence_after, key=lambda x: x.p_value)
            if x.significant
        ]
        out.append("")
    out += [
        "## Baseline: where it fails",
        "",
        f"Model: {baseline_label(d)}; held-out RMS error "
        f"{_fmt(d.baseline.cv_rmse)} {unit} (in-sample "
        f"{_fmt(d.baseline.fit_rmse)} {unit}).",
        "",
    ]
    out += _params_table(d.baseline.params, d.baseline.params_sd)
    out.append("")
    if d.per_material:
        out += [
            f"| material | impacts | baseline held-out RMS error ({unit}) | mean "
            f"normal rebound velocity v_fn residual ({unit}) | mean tangential "
            f"rebound velocity v_ft residual ({unit}) | held-out RMS error after "
            f"({unit}) |",
            "|---|---|---|---|---|---|",
        ]
        for m, e in d.per_material.items():
            out.append(
                f"| {m} | {int(e['impacts'])} | {_fmt(e['baseline_cv_rmse_mps'])} | "
                f"{_fmt(e['baseline_bias_vfn_mps'], 2)} | "
                f"{_fmt(e['baseline_bias_vft_mps'], 2)} | "
                f"{_fmt(e['after_cv_rmse_mps'])} |"
            )
        out.append("")
    if d.worst:
        flights = "flight" in d.worst[0]
        out += [
            "Worst flights (baseline, each flight's own fit):"
            if flights
            else "Worst impacts (baseline, held out):",
            "",
        ]
        out += [_worst_line(w, unit) for w in d.worst]
        out.append("")
    out += ["### Do the residuals depend on a feature?", ""]
    out += _dependence_section(d.dependence_before, d.arrays.get("features", {}))
    kind = d.arrays.get("residual_kind", "held-out")
    out += [f"![baseline residuals against each feature; residuals {kind}]({figs[0]})",
            ""]  # fmt: skip
    rounds = rankings(d)
    out += [
        "## Which effect is missing",
        "",
        f"A candidate is recommended when {rule_head(d)}; the gain is 1 − "
        "(the candidate's held-out RMS error) / (the model's before it).",
        "",
    ]
    out += _candidate_rows(rounds[0], unit) if rounds else ["No candidates."]
    out.append("")
    if d.skipped:
        out += ["Not tested (the data cannot inform them):", ""]
        out += [f"* `{k}`: {v}" for k, v in d.skipped.items()]
        out.append("")
    if d.confounded:
        out += ["### Confounded", ""]
        out += [f"* {a}" for a in d.advice]
        out.append("")
    for i, s in enumerate(d.steps):
        out += [
            f"## Step {i + 1}: add `{s.added}` — the error falls",
            "",
            f"Held-out RMS error {_fmt(s.cv_rmse_before)} → {_fmt(s.cv_rmse)} {unit} "
            f"({1 - s.cv_rmse / s.cv_rmse_before:.1%} lower). Fitted: "
            f"{_params_inline(s.candidates[0].params, s.candidates[0].params_sd)}.",
            "",
        ]
        if i == 0:
            out.append("Ranked in *Which effect is missing* above.")
        else:
            out += [f"Candidates ranked against the model after step {i}:", ""]
            out += _candidate_rows(s.candidates, unit)
        out += ["", f"![residuals before and after]({figs[i + 1]})", ""]
    out += ["## After", ""]
    if d.steps and len(rounds) > len(d.steps):
        out += [
            f"Candidates ranked against the model after step {len(d.steps)} "
            "(none passes the rule):",
            "",
        ]
        out += _candidate_rows(rounds[len(d.steps)], unit)
        out.append("")
    out += [
        "Effects: "
        + (", ".join(labels.effect(e) for e in d.after.effects) or "none")
        + "; held-out RMS error "
        f"{_fmt(d.after.cv_rmse)} {unit}.",
        "",
    ]
    out += _params_table(d.after.params, d.after.params_sd)
    out += [
        "",
        "## How the numbers were made",
        "",
        f"* rule: {d.rule}",
        f"* held out: {d.groups}",
    ]
    out += [f"* {n}" for n in d.notes]
    return "\n".join(out) + "\n"


def alternative_meaning(d: Diagnosis) -> str:
    """What it means when the statistical alternative (an effect whose metadata
    kind is not a law, ``affine_rebound``) is the best candidate that passes the
    rule, in words; ``""`` otherwise."""
    best = d.candidates[0] if d.candidates else None
    if best is None or not best.meaningful:
        return ""
    spec = registry.BY_NAME.get(best.effect)
    if spec is None or spec.is_law:
        return ""
    return (
        f"{best.effect}, a straight line in the impact velocities, is the best "
        "candidate: the rebound departs from constant e_n, e_t, but neither named "
        "law, eq. 5.4 (e_n falling with the impact angle) nor eq. 7.1 (falling with "
        "the impact speed), is the better description; the line is a statistical "
        "alternative, not a physical law"
    )


def _sensitivity_section(d: Diagnosis) -> list[str]:
    if not d.sensitivity:
        return []
    out = [
        "## Sensitivity of the verdict",
        "",
        "The same diagnosis (fold seed and options) on variants of the table: "
        "the assumed launch angles shifted, the materials grouped.",
        "",
        "| variant | what changed | recommended | accepted | best candidate | "
        "gain ± SE | flights without a solution |",
        "|---|---|---|---|---|---|---|",
    ]
    for v in d.sensitivity:
        if v.error:
            out.append(
                f"| {v.variant} | {v.description} | not diagnosed: {v.error} "
                f"| | | | {v.unsolved_flights} |"
            )
            continue
        gain = f"{v.gain:+.1%} ± {v.gain_se:.1%}" if math.isfinite(v.gain) else "-"
        out.append(
            f"| {v.variant} | {v.description} | {v.recommended or 'nothing'} | "
            f"{', '.join(v.accepted) or 'none'} | {v.best or '-'} | {gain} | "
            f"{v.unsolved_flights} |"
        )
    out.append("")
    return out


def rule_head(d: Diagnosis) -> str:
    """The recommendation rule's first clause ("it lowers the held-out error by
    ..."), without the confounding rule."""
    head = d.rule.split(" when ", 1)[-1]
    return head.split(" (jackknife", 1)[0]
