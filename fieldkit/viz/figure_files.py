"""Saving figures: headless backend, PNG outputs, one consistent look."""

from __future__ import annotations

import io
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless everywhere; set before pyplot is imported

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from fieldkit.outputs import OutputSet, write_file  # noqa: E402

DPI = 150


def new_figure(width_in: float = 8.0, height_in: float = 5.0) -> tuple[Figure, object]:
    """A figure with one axes, grid on, in the house style.

    A plain :class:`~matplotlib.figure.Figure`, not a pyplot one: nothing keeps it
    alive after the caller drops it (no pyplot registry to leak into).
    """
    fig = Figure(figsize=(width_in, height_in), layout="constrained")
    ax = fig.add_subplot()
    ax.grid(True, alpha=0.3)
    return fig, ax


def save_png(
    fig: Figure, path: str | os.PathLike[str], *, outputs: OutputSet | None = None
) -> Path:
    """Render ``fig`` as PNG into memory, close it, and write it to ``path``.

    Into ``outputs`` (written when the set commits) or, without one, at once
    (:func:`fieldkit.outputs.write_file`).
    """
    try:
        buffer = io.BytesIO()
        fig.savefig(buffer, dpi=DPI, format="png")
    finally:
        plt.close(fig)
    data = buffer.getvalue()
    return write_file(path, lambda tmp: tmp.write_bytes(data), outputs)
