"""Residuals of an impact fit against the impact's features (angle, speed)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fieldkit.fit.fit_result import FitResult
from fieldkit.outputs import OutputSet
from fieldkit.viz.figure_files import save_png

_STYLE = {
    "vfn": ("C0", "normal rebound velocity v_fN"),
    "vft": ("C1", "tangential rebound velocity v_fT"),
    "omega_f": ("C2", "rebound spin, as surface speed r ω_f"),
}


def residual_label(weighting: str) -> str:
    """The y axis of the residuals: weighted (no unit) or in m/s (unit weights)."""
    if weighting.startswith("unit weights"):
        return "residual: observed − predicted (m/s)"
    return "residual / its standard uncertainty"


def residual_figure(result: FitResult, theta_i_deg: np.ndarray, vi_mps: np.ndarray):
    """Weighted residuals vs impact angle (left) and impact speed (right)."""
    fig = Figure(figsize=(10, 4.8), layout="constrained")
    axes = fig.subplots(1, 2)
    rows = result.residual_row
    for ax, feature, label in (
        (axes[0], theta_i_deg, "impact angle to the ground θ_i (degrees)"),
        (axes[1], vi_mps, "impact speed v_i (m/s)"),
    ):
        for kind, (colour, name) in _STYLE.items():
            sel = result.residual_kind == kind
            if sel.any():
                ax.scatter(
                    feature[rows[sel]], result.residuals[sel], s=8, c=colour,
                    alpha=0.6, label=name,
                )  # fmt: skip
        ax.axhline(0.0, color="k", lw=0.8, label="prediction = observation")
        ax.set_xlabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel(residual_label(result.weighting))
    axes[0].legend(
        loc="best", fontsize=8, title="observed − predicted, one dot per impact",
        title_fontsize=8,
    )  # fmt: skip
    fig.suptitle(
        f"impact fit residuals (reduced χ² {result.redchi:.3g}): what the fitted "
        "model misses at each impact"
    )
    return fig


def write_residual_figure(
    path: str | os.PathLike[str],
    result: FitResult,
    theta_i_deg: np.ndarray,
    vi_mps: np.ndarray,
    *,
    outputs: OutputSet | None = None,
) -> Path:
    """Write :func:`residual_figure` as PNG (through ``outputs`` when given)."""
    return save_png(residual_figure(result, theta_i_deg, vi_mps), path, outputs=outputs)
