"""Residual-versus-feature panels of a diagnosis: before and after, side by side.

One row per feature the residuals were tested against (continuous features as
scatter with a binned median; categories as strips), one column per model: the
baseline alone, or the model before a step and after it. Axes, legend and titles
use the words of :mod:`fieldkit.diagnose.labels` (the report's words); a feature
the residuals were found to depend on says so in a box inside its panel, with the
residual and the Holm-adjusted p-value of the test. A legend under the panels explains
every mark: one colour per residual, its binned median, the zero line.
"""

from __future__ import annotations

import os
import textwrap
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from fieldkit.diagnose import labels
from fieldkit.diagnose.diagnosis import Dependence, Diagnosis
from fieldkit.diagnose.report import baseline_label, figure_names
from fieldkit.outputs import OutputSet
from fieldkit.viz.figure_files import save_png

#: Most feature rows in one figure (the most significant first).
MAX_FEATURES = 6
#: Quantile bins of the binned median drawn over a continuous feature.
MEDIAN_BINS = 8
_COLOURS = ("C0", "C1", "C2")
#: Head room added above a panel's points for its note (fraction of the y range).
NOTE_ROOM = 0.22


def _depends(tests: list[Dependence]) -> dict[str, str]:
    """Feature -> the note inside its panel when residuals depend on it."""
    notes: dict[str, list[str]] = {}
    alpha = {d.alpha for d in tests}
    for d in sorted(tests, key=lambda d: d.p_value):
        if d.significant:
            notes.setdefault(d.feature, []).append(
                f"{labels.symbol(d.component)} (Holm p = {d.p_holm:.1g})"
            )
    level = f" (Holm p ≤ {alpha.pop():g})" if len(alpha) == 1 else ""
    return {
        f: f"residuals depend on this feature{level}: " + ", ".join(n)
        for f, n in notes.items()
    }


def _wrap(text: str, chars: int) -> str:
    """``text`` in lines of at most ``chars``, broken before its last parenthesis
    when that is enough (a unit or a scale stays whole on its own line)."""
    if len(text) <= chars:
        return text
    head, _, tail = text.rpartition(" (")
    if head and len(head) <= chars and len(tail) < chars:
        return f"{head}\n({tail}"
    return textwrap.fill(text, chars)


def _note(ax, text: str) -> None:
    """``text`` inside the top left corner of ``ax``, boxed: it belongs to this
    panel (under the axis it read as the heading of the panel below)."""
    ax.text(
        0.01, 0.97, text, transform=ax.transAxes, ha="left", va="top", fontsize=8,
        bbox={"boxstyle": "round,pad=0.25", "fc": "white", "ec": "0.5", "alpha": 0.9},
        zorder=5,
    )  # fmt: skip


def _order(features: dict, flagged: set[str]) -> list[str]:
    names = list(features)
    return sorted(names, key=lambda n: (n not in flagged, names.index(n)))[
        :MAX_FEATURES
    ]


def _category_axis(ax, values: np.ndarray, residual: np.ndarray):
    """Place a categorical feature on the x axis: one strip per category, each
    ticked with its name and how many points it holds (``rock (n = 2)``), the axis
    wide enough for every strip. Returns ``(x, jitter)``: each point's category
    position and, per residual column, its offset within the strip."""
    names = sorted(set(values) - {""})
    pos = {c: i for i, c in enumerate(names)}
    x = np.array([pos.get(v, np.nan) for v in values], float)
    drawn = np.isfinite(residual).any(axis=1)
    counts = [int((drawn & (values == c)).sum()) for c in names]
    ax.set_xticks(range(len(names)), [f"{c}\n(n = {n})" for c, n in
                                      zip(names, counts, strict=True)])  # fmt: skip
    ax.set_xlim(-0.5, len(names) - 0.5)
    jitter = np.zeros(residual.shape)
    for j in range(residual.shape[1]):
        for c in names:
            sel = np.flatnonzero((values == c) & np.isfinite(residual[:, j]))
            spread = np.linspace(-0.15, 0.15, sel.size) if sel.size > 1 else 0.0
            jitter[sel, j] = spread + 0.1 * (j - 1)
    return x, jitter


def _panel(ax, values, residual, components) -> None:
    cats = values.dtype == object
    if cats:
        x, jitter = _category_axis(ax, values, residual)
    else:
        x, jitter = values, np.zeros(residual.shape)
    for j, _ in enumerate(components):
        r = residual[:, j]
        ok = np.isfinite(r) & np.isfinite(x)
        if not ok.any():
            continue
        ax.scatter(x[ok] + jitter[ok, j], r[ok], s=6, alpha=0.45, c=_COLOURS[j % 3])
        if not cats and ok.sum() >= 20:
            edges = np.quantile(x[ok], np.linspace(0, 1, MEDIAN_BINS + 1))
            mid, med = [], []
            for lo, hi in zip(edges[:-1], edges[1:], strict=True):
                sel = ok & (x >= lo) & (x <= hi)
                if sel.sum() >= 3:
                    mid.append(np.median(x[sel]))
                    med.append(np.median(r[sel]))
            ax.plot(mid, med, c=_COLOURS[j % 3], lw=2)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.grid(True, alpha=0.3)


def _legend(
    fig: Figure,
    components: tuple[str, ...],
    present: list[bool],
    unit: str,
    what: str,
    ncols: int,
) -> None:
    """The legend under the panels: one entry per residual drawn (a component
    without data, e.g. spin never measured, is left out), the median, zero."""
    shown = [j for j in range(len(components)) if present[j]]
    handles = [
        Line2D([], [], ls="", marker="o", ms=4, alpha=0.6, color=_COLOURS[j % 3])
        for j in shown
    ]
    texts = [
        f"{labels.component(components[j])} ({unit}), one point per {what}"
        for j in shown
    ]
    handles += [
        Line2D([], [], color="grey", lw=2),
        Line2D([], [], color="k", lw=0.8),
    ]
    texts += [
        f"binned median of each residual ({MEDIAN_BINS} quantile bins, same colour)",
        "zero residual: the model matches the measurement",
    ]
    fig.legend(handles, texts, loc="outside lower center", ncols=ncols, fontsize=8)


def residual_figure(
    features: dict[str, np.ndarray],
    columns: list[tuple[str, np.ndarray, list[Dependence]]],
    *,
    components: tuple[str, ...],
    unit: str,
    title: str,
    residual_kind: str = "held-out",
    what: str = "impact",
) -> Figure:
    """Rows of features, one column per ``(label, residual (n, k), tests)``.

    ``tests`` are the dependence tests of the column's residuals: a feature they
    found is noted in a box inside its panel. Rows share their y axis so the fall
    is seen at scale; ``what`` one point stands for (impact, sample).
    """
    title += f"\nresiduals: {residual_kind}"
    notes = [_depends(tests) for _, _, tests in columns]
    names = _order(features, set().union(*notes))
    if len(names) < len(features):
        flagged = set().union(*notes)
        hidden = "; ".join(
            labels.feature(f) + (" (the residuals depend on it too)" if f in flagged
                                 else "")
            for f in features
            if f not in names
        )  # fmt: skip
        title += (
            f"\n{len(names)} of {len(features)} features shown (those the residuals "
            f"depend on first); not shown: {hidden}; the report lists every test"
        )
    rows = max(1, len(names))
    width = max(8.0, 5.6 * len(columns))
    fig = Figure(figsize=(width, 2.8 * rows + 1.2), layout="constrained")
    axes = np.atleast_2d(fig.subplots(rows, len(columns), squeeze=False, sharey="row"))
    chars = int(11 * width / len(columns))  # characters a column's line holds
    for c, (label, residual, _) in enumerate(columns):
        for r, name in enumerate(names):
            ax = axes[r, c]
            _panel(ax, features[name], residual, components)
            note = notes[c].get(name)
            ax.set_xlabel(_wrap(labels.feature(name), chars))
            if note:
                _note(ax, note)
            if c == 0:
                ax.set_ylabel(f"residual, measured − model ({unit})")
            if r == 0:
                ax.set_title(textwrap.fill(label, chars), fontsize=10)
    for r, name in enumerate(names):
        if any(name in n for n in notes):  # room for the note above the points
            low, high = axes[r, 0].get_ylim()
            axes[r, 0].set_ylim(low, high + NOTE_ROOM * (high - low))
    present = [
        any(np.isfinite(residual[:, j]).any() for _, residual, _ in columns)
        for j in range(len(components))
    ]
    _legend(fig, components, present, unit, what, ncols=min(2, len(columns)))
    wrap = int(11 * width)
    fig.suptitle("\n".join(textwrap.fill(line, wrap) for line in title.split("\n")))
    return fig


def write_residual_figure(
    path: str | os.PathLike[str],
    features: dict[str, np.ndarray],
    columns: list[tuple[str, np.ndarray, list[Dependence]]],
    *,
    components: tuple[str, ...],
    unit: str,
    title: str,
    residual_kind: str = "held-out",
    what: str = "impact",
    outputs: OutputSet | None = None,
) -> Path:
    """Write :func:`residual_figure` as PNG (through ``outputs`` when given)."""
    fig = residual_figure(
        features, columns, components=components, unit=unit, title=title,
        residual_kind=residual_kind, what=what,
    )  # fmt: skip
    return save_png(fig, path, outputs=outputs)


def write_diagnosis_figures(
    folder: Path, diagnosis: Diagnosis, *, outputs: OutputSet | None = None
) -> list[Path]:
    """The baseline's figure and one before/after figure per accepted step, named
    as the report links them (:func:`~fieldkit.diagnose.report.figure_names`)."""
    d = diagnosis
    arrays = d.arrays
    unit = labels.unit(d.metric)
    error = labels.metric_words(d.metric)
    components = tuple(arrays.get("components", ("vfn", "vft", "omega_f")))
    kind = arrays.get(
        "residual_kind",
        "held-out (each impact predicted by the model fitted without its fold)",
    )
    what = "sample of a flight" if d.metric == "cv_rmse_m" else "impact"
    tests = arrays["dependence"]
    names = figure_names(d)
    common = dict(components=components, unit=unit, residual_kind=kind, what=what)
    written = [
        write_residual_figure(
            folder / names[0],
            arrays["features"],
            [
                (
                    f"baseline: {error} {d.baseline.cv_rmse:.4g} {unit}",
                    arrays["baseline"],
                    tests[0],
                )
            ],
            title=f"Baseline, {baseline_label(d)}: residuals against each feature",
            outputs=outputs,
            **common,
        )
    ]
    before = arrays["baseline"]
    for i, (step, after) in enumerate(zip(d.steps, arrays["steps"], strict=True)):
        effect = labels.effect(step.added)
        was = f"before: held-out RMS error {step.cv_rmse_before:.4g} {unit}"
        now = f"after adding {effect}: held-out RMS error {step.cv_rmse:.4g} {unit}"
        written.append(
            write_residual_figure(
                folder / names[i + 1],
                arrays["features"],
                [(was, before, tests[i]), (now, after, tests[i + 1])],
                title=f"Step {i + 1}: add {effect}; residuals before and after",
                outputs=outputs,
                **common,
            )
        )
        before = after
    return written
