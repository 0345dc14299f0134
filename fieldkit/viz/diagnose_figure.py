"""Residual-versus-feature panels of a diagnosis: before and after, side by side.

One row per feature the residuals were tested against (continuous features as
scatter with a binned median; categories as strips), one column per model: the
baseline alone, or the model before a step and after it. A feature whose
residuals the tests flagged is marked in its axis label.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fieldkit.outputs import OutputSet
from fieldkit.viz.figure_files import save_png

#: Most feature rows in one figure (the most significant first).
MAX_FEATURES = 6
_COLOURS = ("C0", "C1", "C2")


def _order(features: dict, flagged: set[str]) -> list[str]:
    names = list(features)
    return sorted(names, key=lambda n: (n not in flagged, names.index(n)))[
        :MAX_FEATURES
    ]


def _panel(ax, values, residual, components, unit) -> None:
    cats = values.dtype == object
    if cats:
        labels = sorted(set(values) - {""})
        pos = {c: i for i, c in enumerate(labels)}
        x = np.array([pos.get(v, np.nan) for v in values], float)
        ax.set_xticks(range(len(labels)), labels)
    else:
        x = values
    for j, name in enumerate(components):
        r = residual[:, j]
        ok = np.isfinite(r) & np.isfinite(x)
        if not ok.any():
            continue
        jitter = (np.linspace(-0.15, 0.15, ok.sum()) + 0.1 * (j - 1)) if cats else 0
        ax.scatter(x[ok] + jitter, r[ok], s=6, alpha=0.45, c=_COLOURS[j % 3],
                   label=name)  # fmt: skip
        if not cats and ok.sum() >= 20:
            edges = np.quantile(x[ok], np.linspace(0, 1, 9))
            mid, med = [], []
            for lo, hi in zip(edges[:-1], edges[1:], strict=True):
                sel = ok & (x >= lo) & (x <= hi)
                if sel.sum() >= 3:
                    mid.append(np.median(x[sel]))
                    med.append(np.median(r[sel]))
            ax.plot(mid, med, c=_COLOURS[j % 3], lw=2)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_ylabel(f"residual ({unit})")
    ax.grid(True, alpha=0.3)


def residual_figure(
    features: dict[str, np.ndarray],
    columns: list[tuple[str, np.ndarray, set[str]]],
    *,
    components: tuple[str, ...],
    unit: str,
    title: str,
) -> Figure:
    """Rows of features, one column per ``(label, residual (n, k), flagged)``.

    ``flagged`` names the features the column's residuals were found to depend on
    (marked ``[depends]``); rows share their y axis so the fall is seen at scale.
    """
    names = _order(features, set().union(*(c[2] for c in columns)))
    rows = max(1, len(names))
    fig = Figure(figsize=(5.2 * len(columns), 2.6 * rows), layout="constrained")
    axes = np.atleast_2d(fig.subplots(rows, len(columns), squeeze=False, sharey="row"))
    for c, (label, residual, flagged) in enumerate(columns):
        for r, name in enumerate(names):
            ax = axes[r, c]
            _panel(ax, features[name], residual, components, unit)
            mark = "  [depends]" if name in flagged else ""
            ax.set_xlabel(f"{name}{mark}")
            if r == 0:
                ax.set_title(label)
        axes[0, c].legend(loc="best", fontsize=8)
    fig.suptitle(title)
    return fig


def write_residual_figure(
    path: str | os.PathLike[str],
    features: dict[str, np.ndarray],
    columns: list[tuple[str, np.ndarray, set[str]]],
    *,
    components: tuple[str, ...],
    unit: str,
    title: str,
    outputs: OutputSet | None = None,
) -> Path:
    """Write :func:`residual_figure` as PNG (through ``outputs`` when given)."""
    fig = residual_figure(
        features, columns, components=components, unit=unit, title=title,
    )  # fmt: skip
    return save_png(fig, path, outputs=outputs)
