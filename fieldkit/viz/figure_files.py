"""Saving figures: headless backend, atomic PNG files, one consistent look."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless everywhere; set before pyplot is imported

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from fieldkit.outputs import write_atomic  # noqa: E402

DPI = 150


def new_figure(width_in: float = 8.0, height_in: float = 5.0) -> tuple[Figure, object]:
    """A figure with one axes, grid on, in the house style."""
    fig, ax = plt.subplots(figsize=(width_in, height_in), layout="constrained")
    ax.grid(True, alpha=0.3)
    return fig, ax


def save_png(fig: Figure, path: str | os.PathLike[str]) -> Path:
    """Write ``fig`` to ``path`` as PNG atomically and close it."""
    try:
        return write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=DPI, format="png"))
    finally:
        plt.close(fig)
