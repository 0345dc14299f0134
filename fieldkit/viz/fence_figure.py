"""Figures for protection structures (thesis chapter 8).

* :func:`plot_time_force` -- Figs. 8.6-8.8: for a given rock impulse ``m v_i``, the
  impulse absorbed against time (Fig. 8.7, eqs. 8.5-8.7) and the force against time
  up to the end of the contact (Figs. 8.6 and 8.8, eqs. 8.2-8.4) for each structure,
  with the contact time and peak force marked.
* :func:`plot_fence_energy` -- worked example 8B: kinetic and rotational energy of the
  rock before and after the fence, and the energy the net absorbs (eq. 8.1).
* :func:`plot_fence` -- both side by side; :func:`write_fence_figure` saves it as PNG.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from fieldkit.outputs import OutputSet
from fieldkit.physics.fences import FenceEnergySplit
from fieldkit.physics.structure_forces import (
    THESIS_STRUCTURES,
    StructureLaw,
    contact_time,
    force_at,
    impulse_absorbed,
)
from fieldkit.viz.figure_files import save_png
from fieldkit.viz.marks import outside_legend

#: One colour per thesis structure; other labels cycle through the default colours.
COLOURS = {"rigid": "#d62728", "flexible": "#1f77b4", "stiff": "#2ca02c"}


_SUPERSCRIPTS = str.maketrans("0123456789.-", "⁰¹²³⁴⁵⁶⁷⁸⁹·⁻")


def force_law_text(law: StructureLaw) -> str:
    """The force law ``F = c t^n`` as written for a reader (F in N, t in s).

    Examples
    --------
    >>> from fieldkit.physics.structure_forces import StructureLaw
    >>> [force_law_text(StructureLaw("x", c, n)) for c, n in
    ...  ((1e6, 1.0), (40000.0, 2.0), (30000.0, 0.6), (2.5e-3, 1.5))]
    ['F = 1,000,000 t', 'F = 40,000 t²', 'F = 30,000 t⁰·⁶', 'F = 0.0025 t¹·⁵']
    """
    c, n = float(law.coefficient), float(law.exponent)
    coefficient = f"{c:,.0f}" if c >= 1 and c == round(c) else f"{c:.3g}"
    power = "" if n == 1 else f"{n:g}".translate(_SUPERSCRIPTS)
    return f"F = {coefficient} t{power}"


def _draw_time_force(
    ax_impulse: Axes, ax_force: Axes, impulse_ns: float, laws: Iterable[StructureLaw]
) -> None:
    laws = list(laws)
    t_ends = [float(contact_time(law, impulse_ns)) for law in laws]
    t_max = 1.15 * max(t_ends)
    t = np.linspace(0.0, t_max, 400)
    for i, (law, t_end) in enumerate(zip(laws, t_ends, strict=True)):
        colour = COLOURS.get(law.name, f"C{i}")
        inside = t <= t_end
        t_in = np.append(t[inside], t_end)
        peak = float(force_at(law, t_end))
        ax_impulse.plot(t, impulse_absorbed(law, t) / 1e3, color=colour, lw=0.8, ls=":")
        ax_impulse.plot(
            t_in,
            impulse_absorbed(law, t_in) / 1e3,
            color=colour,
            lw=2,
            label=f"{law.name}: t = {t_end:.2f} s",
        )
        ax_impulse.plot([t_end], [impulse_ns / 1e3], "o", color=colour)
        ax_force.plot(
            t_in,
            force_at(law, t_in) / 1e3,
            color=colour,
            lw=2,
            label=f"{law.name}: {force_law_text(law)}",
        )
        ax_force.plot([t_end, t_end], [0.0, peak / 1e3], color=colour, lw=0.8, ls="--")
        ax_force.annotate(
            f"{peak / 1e3:.1f} kN",
            (t_end, peak / 1e3),
            textcoords="offset points",
            xytext=(4, 4),
            color=colour,
        )
    ax_impulse.axhline(impulse_ns / 1e3, color="0.3", lw=0.8)
    ax_impulse.text(
        0.02 * t_max,
        impulse_ns / 1e3,
        f"rock impulse m v = {impulse_ns / 1e3:.2f} kN s",
        va="bottom",
        fontsize=8,
    )
    ax_impulse.set(
        xlim=(0, t_max),
        ylim=(0, 1.6 * impulse_ns / 1e3),
        xlabel="time of contact t [s]",
        ylabel="impulse absorbed p [kN s]",
        title="time - impulse (Fig. 8.7, eqs. 8.5-8.7)",
    )
    peaks = [float(force_at(law, te)) for law, te in zip(laws, t_ends, strict=True)]
    peak_max = max(peaks)
    ax_force.set(
        xlim=(0, t_max),
        ylim=(0, 1.15 * peak_max / 1e3),
        xlabel="time of contact t [s]",
        ylabel="force in the structure F [kN]",
        title="time - force (Figs. 8.6, 8.8, eqs. 8.2-8.4)",
    )
    outside_legend(ax_impulse)
    outside_legend(ax_force, title="force law: F in N, t in s", title_fontsize=8)
    for ax in (ax_impulse, ax_force):
        ax.grid(True, alpha=0.3)


def _draw_energy(ax: Axes, split: FenceEnergySplit) -> None:
    ke = np.array([float(split.kinetic_in_j), float(split.kinetic_out_j)]) / 1e3
    re = np.array([float(split.rotational_in_j), float(split.rotational_out_j)]) / 1e3
    totals = np.array([float(split.total_in_j), float(split.total_out_j)]) / 1e3
    x = np.array([0.0, 1.0])
    ax.bar(x, ke, 0.6, color="#fdae6b", label="kinetic ½ m v²")
    ax.bar(x, re, 0.6, bottom=ke, color="#a1d99b", label="rotational ½ I ω²")
    absorbed = float(split.absorbed_j) / 1e3
    ax.bar(
        [1.0],
        [absorbed],
        0.6,
        bottom=[totals[1]],
        color="#e0e0e0",
        hatch="///",
        edgecolor="#9e9e9e",
        label="absorbed by the fence",
    )
    for xi, total in zip(x, totals, strict=True):
        ax.text(xi, total, f"{total:.1f} kJ", ha="center", va="bottom", fontsize=8)
    ax.text(
        1.0,
        totals[1] + absorbed / 2,
        f"{absorbed:.1f} kJ\n({float(split.absorbed_fraction):.0%})",
        ha="center",
        va="center",
        fontsize=8,
    )
    ax.set_xticks(x, ["impact (i)", "restitution (f)"])
    ax.set(
        ylabel="energy of the rock [kJ]",
        title=f"energy split, efficiency E_f/E_i = {float(split.efficiency):.0%} "
        "(eq. 8.1)",
    )
    ax.set_ylim(0, 1.25 * float(split.total_in_j) / 1e3)
    ax.grid(True, axis="y", alpha=0.3)
    outside_legend(ax)


def plot_time_force(
    impulse_ns: float, laws: Iterable[StructureLaw] = THESIS_STRUCTURES.values()
) -> Figure:
    """Time-impulse and time-force curves of protection structures (Figs. 8.6-8.8)."""
    fig = Figure(figsize=(11.0, 4.5), layout="constrained")
    ax_impulse, ax_force = fig.subplots(1, 2)
    _draw_time_force(ax_impulse, ax_force, impulse_ns, laws)
    return fig


def plot_fence_energy(split: FenceEnergySplit) -> Figure:
    """Energy of the rock before and after an oblique fence impact (example 8B)."""
    fig = Figure(figsize=(5.0, 4.5), layout="constrained")
    _draw_energy(fig.add_subplot(), split)
    return fig


def plot_fence(
    impulse_ns: float,
    laws: Iterable[StructureLaw] = THESIS_STRUCTURES.values(),
    split: FenceEnergySplit | None = None,
) -> Figure:
    """Energy split (if given) beside the time-impulse and time-force comparison."""
    panels = 3 if split is not None else 2
    fig = Figure(figsize=(5.5 * panels, 4.8), layout="constrained")
    axes = fig.subplots(1, panels)
    if split is not None:
        _draw_energy(axes[0], split)
    _draw_time_force(axes[-2], axes[-1], impulse_ns, laws)
    return fig


def write_fence_figure(
    path: str | os.PathLike[str],
    impulse_ns: float,
    laws: Iterable[StructureLaw] = THESIS_STRUCTURES.values(),
    split: FenceEnergySplit | None = None,
    *,
    outputs: OutputSet | None = None,
) -> Path:
    """Save :func:`plot_fence` as a PNG (into ``outputs`` if given)."""
    return save_png(plot_fence(impulse_ns, laws, split), path, outputs=outputs)
