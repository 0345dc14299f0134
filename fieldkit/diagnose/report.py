"""The diagnosis as a Markdown report a person reads (text only; no I/O).

Sections follow the loop of the issue: the baseline and where it fails, which
effect is missing (ranked, with the gain's standard error), each step with the
held-out error before and after and the fitted parameters, what stays
unexplained, and how the numbers were made. Figures are referenced by the file
names :func:`figure_names` gives; the caller writes them.
"""

from __future__ import annotations

import math

from fieldkit.diagnose.diagnosis import Candidate, Diagnosis


def figure_names(diagnosis: Diagnosis) -> list[str]:
    """PNG names the report links: the baseline, then one per accepted step."""
    return ["baseline.png"] + [
        f"step_{i + 1}_{s.added}.png" for i, s in enumerate(diagnosis.steps)
    ]


def _fmt(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}" if math.isfinite(x) else "—"


def _params(params: dict, sds: dict) -> str:
    if not params:
        return "—"
    return ", ".join(
        f"{k} = {_fmt(v)} ± {_fmt(sds.get(k, math.nan), 2)}" for k, v in params.items()
    )


def _candidate_rows(candidates: list[Candidate], unit: str) -> list[str]:
    rows = [
        f"| rank | effect | held-out RMSE ({unit}) | gain | SE of gain | meaningful "
        "| fitted parameters |",
        "|---|---|---|---|---|---|---|",
    ]
    for i, c in enumerate(candidates, 1):
        rows.append(
            f"| {i} | `{c.effect}` | {_fmt(c.cv_rmse)} | {c.improvement:+.1%} | "
            f"{c.improvement_se:.1%} | {'yes' if c.meaningful else 'no'} | "
            f"{_params(c.params, c.params_sd)} |"
        )
    return rows


def _worst_line(w: dict, unit: str) -> str:
    if "row" not in w:  # flights: label and numbers as given
        return "* " + ", ".join(
            f"{k} {_fmt(v) if isinstance(v, float) else v}" for k, v in w.items()
        )
    return (
        f"* row {w['row']} (path {w['path_id']}, point {w['point']}, "
        f"{w['material']}): {w['component']} residual "
        f"{w['residual_mps']:+.3g} {unit} ({w['z']:.1f} sd)"
    )


def baseline_label(d: Diagnosis) -> str:
    """What the baseline is, in words."""
    if d.metric == "cv_rmse_m":
        base = "ballistic flights (g = 9.81 m/s^2)"
    else:
        base = "constant e_n, e_t per material"
    return base + "".join(f" + {e}" for e in d.baseline.effects)


def markdown(diagnosis: Diagnosis, *, title: str, inputs: list[str]) -> str:
    """The full report for ``diagnosis`` (``inputs``: the files it read)."""
    d = diagnosis
    unit = "m/s" if d.metric.endswith("_mps") else "m"
    figs = figure_names(d)
    out = [f"# Diagnosis: {title}", ""]
    out += [f"* input: `{name}`" for name in inputs]
    out += [
        f"* {d.n_rows} rows, {d.n_data} data; held out: {d.groups}",
        f"* metric: `{d.metric}` — weighted RMS of held-out residuals ({unit})",
        "",
        "## Verdict",
        "",
    ]
    if d.steps:
        added = ", ".join(f"`{s.added}`" for s in d.steps)
        fall = 1.0 - d.after.cv_rmse / d.baseline.cv_rmse
        out.append(
            f"Missing physics found: {added}. Held-out error "
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
            "No effect recommended: the baseline already explains these data as well "
            "as any candidate the data can inform (no held-out gain beyond its "
            "standard error)."
        )
    out += [f"Stopped: {d.stopped}.", ""]
    if d.unexplained:
        out.append(
            "**Residual structure no candidate explains** (physics outside "
            "fieldkit's vocabulary, or a data problem):"
        )
        out += [f"* residuals still: {u}" for u in d.unexplained]
        out.append("")
    out += [
        "## Baseline: where it fails",
        "",
        f"Model: {baseline_label(d)}; "
        f"held-out RMSE {_fmt(d.baseline.cv_rmse)} {unit} "
        f"(in-sample {_fmt(d.baseline.fit_rmse)}).",
        "",
        f"Fitted: {_params(d.baseline.params, d.baseline.params_sd)}",
        "",
    ]
    if d.per_material:
        out += [
            f"| material | impacts | baseline RMSE ({unit}) | mean vfn residual | "
            f"mean vft residual | after RMSE ({unit}) |",
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
        out += ["Worst impacts (held-out, baseline):", ""]
        out += [_worst_line(w, unit) for w in d.worst]
        out.append("")
    hits = [x for x in d.dependence_before if x.significant]
    out.append("Residuals depend on:" if hits else "Residuals depend on no feature.")
    out += [
        f"* {x.feature} ({x.component}): {x.statistic}, p = {x.p_value:.2g}"
        for x in sorted(hits, key=lambda x: x.p_value)
    ]
    tested = sorted({x.feature for x in d.dependence_before})
    out += ["", f"Features tested: {', '.join(tested) or 'none'}.", ""]
    kind = d.arrays.get("residual_kind", "held-out")
    out += [f"![baseline residuals ({kind})]({figs[0]})", ""]
    out += ["## Which effect is missing", ""]
    out += _candidate_rows(d.candidates, unit) if d.candidates else ["No candidates."]
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
            f"Held-out RMSE {_fmt(s.cv_rmse_before)} → {_fmt(s.cv_rmse)} {unit} "
            f"({1 - s.cv_rmse / s.cv_rmse_before:.1%} lower).",
            "",
            f"Fitted: {_params(s.candidates[0].params, s.candidates[0].params_sd)}",
            "",
        ]
        out += _candidate_rows(s.candidates, unit)
        out += ["", f"![before and after]({figs[i + 1]})", ""]
    out += [
        "## After",
        "",
        f"Effects: {', '.join(d.after.effects) or 'none'}; held-out RMSE "
        f"{_fmt(d.after.cv_rmse)} {unit}.",
        "",
        f"Fitted: {_params(d.after.params, d.after.params_sd)}",
        "",
        "## How the numbers were made",
        "",
        f"* rule: {d.rule}",
        f"* held out: {d.groups}",
    ]
    out += [f"* {n}" for n in d.notes]
    return "\n".join(out) + "\n"
