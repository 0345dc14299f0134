"""Coefficients of restitution as the thesis plots them (Figs. 5.7 and 5.8).

* :func:`plot_en_theta` -- [theta_i - e_N] scatter by slope material with the power law
  of eq. 5.4, ``e_N = 19.5 theta_i^-1.03`` (Fig. 5.7); impacts whose restitution angle
  theta0 a tree strike fixed (or that were measured) are filled, those on the assumed
  theta0 open. Reusable: takes plain arrays, so video tracks, simulations and fits can
  draw the same figure with their own law.

Impacts with quality flags (``qa_flags``) are ringed in red; legends sit outside the
axes.
* :func:`plot_et_impacts` -- e_T against impact number, with the mean per material in
  the legend (Fig. 5.8).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from fieldkit.impact_table import ImpactTable
from fieldkit.outputs import OutputSet
from fieldkit.physics.restitution import (
    ANGLE_LAW_A,
    ANGLE_LAW_B,
    angle_dependent_restitution,
)
from fieldkit.viz.figure_files import save_png
from fieldkit.viz.marks import mark_flagged, outside_legend, qa_column

MARKERS = {
    "rock": "s",
    "talus": "^",
    "colluvium": "o",
    "asphalt": "D",
    "concrete": "v",
    "bench": "P",
}

#: ``theta0_source`` values that fix the restitution angle (the rest were assumed).
FIXED_SOURCES = ("tree", "given", "video")


def _groups(material: Sequence[str] | None, n: int) -> tuple[np.ndarray, list[str]]:
    labels = np.array(
        ["all impacts"] * n
        if material is None
        else ["unknown" if m is None or m != m else str(m) for m in material]
    )
    return labels, list(dict.fromkeys(labels.tolist()))


def _figure() -> tuple[Figure, object]:
    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    ax = fig.add_subplot()
    ax.grid(True, alpha=0.3)
    return fig, ax


def plot_en_theta(
    theta_i_deg: ArrayLike,
    e_n: ArrayLike,
    *,
    material: Sequence[str] | None = None,
    law: tuple[float, float] | None = (ANGLE_LAW_A, ANGLE_LAW_B),
    law_label: str | None = None,
    title: str | None = None,
    theta0_source: Sequence[str] | None = None,
    qa_flags: Sequence[str | None] | None = None,
) -> Figure:
    """[theta_i - e_N] scatter with a power law ``e_N = a theta_i^-b`` (Fig. 5.7).

    Parameters
    ----------
    theta_i_deg
        Impact angle to the ground [deg].
    e_n
        Normal coefficient of restitution.
    material
        Slope material per point (one marker per material), or None.
    law
        ``(a, b)`` of the power law to draw (drawn by
        :func:`fieldkit.physics.restitution.angle_dependent_restitution`), default
        the thesis fit of eq. 5.4 ``(ANGLE_LAW_A, ANGLE_LAW_B)`` = ``(19.5, 1.03)``;
        None draws no curve.
    law_label, title
        Legend text for the curve and figure title (defaults describe eq. 5.4).
    theta0_source
        Where each impact's restitution angle came from (``theta0_source``): impacts
        fixed by a tree strike or measured (:data:`FIXED_SOURCES`) are drawn filled
        (collection gid ``theta0-fixed``), the others open (``theta0-assumed``), each
        group with a legend entry. None: all filled, no such entries.
    qa_flags
        Per point, its ``qa_flags`` (``;``-separated): points whose flags set them
        apart are ringed in red (:func:`fieldkit.viz.marks.mark_flagged`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    theta = np.asarray(theta_i_deg, float)
    en = np.asarray(e_n, float)
    ok = np.isfinite(theta) & np.isfinite(en)
    labels, names = _groups(material, len(theta))
    fixed = (
        np.ones(len(theta), bool)
        if theta0_source is None
        else np.array([str(s) in FIXED_SOURCES for s in theta0_source], bool)
    )
    fig, ax = _figure()
    for i, name in enumerate(names):
        sel = ok & (labels == name)
        colour = f"C{i}"
        label = f"{name} ({sel.sum()})"
        for group, gid, style in (
            (
                sel & fixed,
                "theta0-fixed",
                dict(facecolors=colour, edgecolors="black", linewidths=0.5),
            ),
            (
                sel & ~fixed,
                "theta0-assumed",
                dict(facecolors="none", edgecolors=colour, linewidths=1.2),
            ),
        ):
            if not group.any():
                continue
            ax.scatter(
                theta[group],
                en[group],
                marker=MARKERS.get(name, "o"),
                s=28,
                label=label,
                zorder=3,
                gid=None if theta0_source is None else gid,
                **style,
            )
            label = None
    if theta0_source is not None:
        for group, style, text in (
            (
                fixed,
                dict(facecolors="0.4", edgecolors="black"),
                "θ0 fixed by a tree strike or measured",
            ),
            (~fixed, dict(facecolors="none", edgecolors="0.4"), "θ0 assumed"),
        ):
            if (ok & group).any():
                ax.scatter(
                    [],
                    [],
                    marker="o",
                    s=28,
                    linewidths=0.8,
                    label=f"{text} ({(ok & group).sum()})",
                    **style,
                )
    mark_flagged(ax, theta, en, qa_flags)
    if law is not None:
        a, b = law
        t = np.linspace(3.0, 90.0, 300)
        ax.plot(
            t,
            angle_dependent_restitution(t, a, b),
            color="black",
            lw=1.2,
            label=law_label or f"eq. 5.4: $e_N$ = {a:g}·$\\theta_i^{{-{b:g}}}$",
        )
    top = np.nanmax(en[ok]) if ok.any() else 2.0
    ax.set_xlim(0, 90)
    ax.set_ylim(0, max(2.0, min(top * 1.1, 8.0)))
    ax.axhline(1.0, color="0.5", lw=0.8, ls=":", label="$e_N$ = 1: normal speed kept")
    ax.set_xlabel(r"impact angle $\theta_i$ [deg]")
    ax.set_ylabel(r"normal coefficient of restitution $e_N$ [-]")
    ax.set_title(title or r"[$\theta_i$ - $e_N$] relationship (thesis Fig. 5.7)")
    outside_legend(ax)
    return fig


def plot_et_impacts(
    e_t: ArrayLike,
    *,
    impact_number: ArrayLike | None = None,
    material: Sequence[str] | None = None,
    title: str | None = None,
    qa_flags: Sequence[str | None] | None = None,
) -> Figure:
    """Tangential coefficient of restitution per impact (thesis Fig. 5.8).

    Parameters
    ----------
    e_t
        Tangential coefficient of restitution per impact.
    impact_number
        Horizontal axis ("calculation #"); default 1, 2, ...
    material
        Slope material per impact; the legend gives each material's mean e_T.
    qa_flags
        Per impact, its ``qa_flags``: impacts whose flags set them apart are ringed
        in red (:func:`fieldkit.viz.marks.mark_flagged`).
    """
    et = np.asarray(e_t, float)
    number = (
        np.arange(1, len(et) + 1)
        if impact_number is None
        else np.asarray(impact_number, float)
    )
    ok = np.isfinite(et)
    labels, names = _groups(material, len(et))
    fig, ax = _figure()
    for name in names:
        sel = ok & (labels == name)
        mean = float(np.mean(et[sel])) if sel.any() else float("nan")
        ax.plot(
            number[sel],
            et[sel],
            marker=MARKERS.get(name, "o"),
            ls="-",
            lw=0.6,
            ms=5,
            mec="black",
            mew=0.5,
            label=f"{name}: {sel.sum()} impacts, mean $e_T$ = {mean:.2f}",
        )
    ax.axhline(
        1.0, color="0.5", lw=0.8, ls=":", label="$e_T$ = 1: tangential speed kept"
    )
    ax.set_ylim(0, max(1.4, float(np.nanmax(et)) * 1.1 if ok.any() else 1.4))
    ax.set_xlabel("impact number along the path (thesis: calculation #) [-]")
    ax.set_ylabel(r"tangential coefficient of restitution $e_T$ [-]")
    mark_flagged(ax, number, et, qa_flags)
    ax.set_title(title or r"$e_T$ per impact (thesis Fig. 5.8)")
    outside_legend(ax)
    return fig


def write_restitution_figures(
    table: ImpactTable,
    en_path: str | os.PathLike[str],
    et_path: str | os.PathLike[str],
    *,
    law: tuple[float, float] | None = (ANGLE_LAW_A, ANGLE_LAW_B),
    outputs: OutputSet | None = None,
) -> tuple[Path, Path]:
    """Write the Fig. 5.7 and Fig. 5.8 PNGs of an ImpactTable's impacts (into
    ``outputs`` when given, see :func:`fieldkit.viz.figure_files.save_png`)."""
    f = table.frame
    impacts = f[
        np.isfinite(f["e_n"].to_numpy(float)) | np.isfinite(f["e_t"].to_numpy(float))
    ]
    material = (
        impacts["material"].astype(object).where(impacts["material"].notna(), None)
    )
    mat = None if impacts["material"].isna().all() else material.tolist()
    name = ", ".join(table.paths())
    qa_flags = qa_column(impacts)
    en_fig = plot_en_theta(
        impacts["theta_i_deg"],
        impacts["e_n"],
        material=mat,
        law=law,
        title=f"{name}: [θi - eN] with eq. 5.4 (thesis Fig. 5.7)",
        theta0_source=impacts["theta0_source"].tolist(),
        qa_flags=qa_flags,
    )
    et_fig = plot_et_impacts(
        impacts["e_t"],
        material=mat,
        title=f"{name}: $e_T$ per impact (thesis Fig. 5.8)",
        qa_flags=qa_flags,
    )
    return (
        save_png(en_fig, en_path, outputs=outputs),
        save_png(et_fig, et_path, outputs=outputs),
    )
