"""The [p_N - v] diagram of one impact (thesis Figs. 4.4, 4.5, 5.2, C.3).

Normal impulse on the horizontal axis; on the vertical axis the normal velocity (rising
through zero at maximum compression ``p_c``), the tangential velocity of the centre of
mass and the slip velocity of the contact point (falling until slip stops). The areas
under the normal-velocity line are the work of compression (loss) and restitution
(recovery), as in Fig. 4.4.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fieldkit.outputs import OutputSet
from fieldkit.physics.impulse_history import ImpulseHistory
from fieldkit.viz.figure_files import new_figure, save_png
from fieldkit.viz.marks import outside_legend

NORMAL_COLOUR = "#1f77b4"
TANGENTIAL_COLOUR = "#d62728"
SLIP_COLOUR = "#ff7f0e"


def _impulse_scale(history: ImpulseHistory) -> tuple[float, str]:
    """Scale factor and unit label so the impulse axis reads well."""
    p_f = float(history.p_f)
    if p_f >= 1e4:
        return 1e-3, "kN s"
    return 1.0, "N s"


def draw_pnv(ax, history: ImpulseHistory, *, impulse_unit: str | None = None) -> None:
    """Draw the [p_N - v] lines of ``history`` on a matplotlib axes.

    Parameters
    ----------
    ax
        Matplotlib axes.
    history
        From :func:`fieldkit.physics.impulse_history.impulse_history`.
    impulse_unit
        Axis label for the impulse (default "N s" or "kN s", chosen from ``p_f``;
        use "N s/kg" for a history computed without a mass).
    """
    scale, unit = _impulse_scale(history)
    if impulse_unit is not None:
        scale, unit = 1.0, impulse_unit
    p = history.p * scale
    p_c, p_f = history.p_c * scale, history.p_f * scale
    v_n = history.v_n_mps

    compression = p <= p_c
    ax.fill_between(
        p[compression], v_n[compression], 0.0, color=NORMAL_COLOUR, alpha=0.12,
        label="compression work (lost)",
    )  # fmt: skip
    ax.fill_between(
        p[~compression | (p == p_c)], v_n[~compression | (p == p_c)], 0.0,
        color=NORMAL_COLOUR, alpha=0.28, label="restitution work (recovered)",
    )  # fmt: skip
    v_t, v_s, omega = history.v_t_mps, history.v_slip_mps, history.omega_radps

    def change(values: np.ndarray) -> str:
        return f"{values[0]:.2f} $\\to$ {values[-1]:.2f}"

    ax.plot(p, v_n, color=NORMAL_COLOUR, lw=2,
            label=f"normal velocity $v_N$: {change(v_n)} m/s")  # fmt: skip
    ax.plot(p, v_t, color=TANGENTIAL_COLOUR, lw=2,
            label=f"tangential velocity $v_T$: {change(v_t)} m/s")  # fmt: skip
    ax.plot(p, v_s, color=SLIP_COLOUR, lw=2, ls="--",
            label=rf"slip $v_s = v_T + r\omega$: {change(v_s)} m/s")  # fmt: skip
    ax.plot([], [], " ", label=rf"spin $\omega$: {change(omega)} rad/s")
    ax.axhline(0.0, color="black", lw=0.8)

    top = max(np.max(history.v_t_mps), np.max(v_n), np.max(history.v_slip_mps))
    bottom = min(np.min(v_n), np.min(history.v_slip_mps), np.min(history.v_t_mps), 0.0)
    span = top - bottom
    for value, name in ((p_c, "$p_c$"), (p_f, "$p_f$")):
        ax.axvline(value, color="grey", lw=1, ls=":")
        ax.annotate(name, (value, bottom - 0.06 * span), ha="center", va="top")
    if np.isfinite(history.p_slip_stop):
        p_s = history.p_slip_stop * scale
        after = np.searchsorted(p, p_s, side="right") - 1  # after an instant step
        v_t_s = float(v_t[max(after, 0)])
        ax.plot([p_s], [0.0], "o", color=SLIP_COLOUR, ms=7, zorder=5,
                label=f"slip stops, $p_s$ = {p_s:.3g} {unit}")  # fmt: skip
        ax.plot([p_s], [v_t_s], "o", mfc="white", color=TANGENTIAL_COLOUR, ms=6,
                label=f"tangential velocity as slip stops: {v_t_s:.2f} m/s",
                )  # fmt: skip

    ax.set_ylim(bottom - 0.14 * span, top + 0.1 * span)
    ax.set_xlim(min(0.0, p[0]) - 0.02 * p_f, p_f * 1.02)
    ax.set_xlabel(f"normal impulse $p_N$ [{unit}]")
    ax.set_ylabel("velocity [m/s]")
    outside_legend(ax)


def pnv_figure(
    history: ImpulseHistory,
    *,
    title: str | None = None,
    impulse_unit: str | None = None,
) -> Figure:
    """A figure with the [p_N - v] diagram of one impact (Figs. 4.4, 4.5).

    Examples
    --------
    >>> from fieldkit.physics.impulse_history import impulse_history
    >>> h = impulse_history(19.9, -9.3, -15.0, radius_m=0.75, gyration_m=0.47,
    ...                     e_n=0.71, friction=0.5, mass_kg=1000.0)
    >>> fig = pnv_figure(h, title="worked example 4A")
    >>> len(fig.axes)
    1
    """
    fig, ax = new_figure(10.0, 5.0)
    draw_pnv(ax, history, impulse_unit=impulse_unit)
    ax.set_title(title or "[$p_N$ - v] diagram of the impact")
    return fig


def save_pnv_figure(
    history: ImpulseHistory,
    path: str | os.PathLike[str],
    *,
    title: str | None = None,
    impulse_unit: str | None = None,
    outputs: OutputSet | None = None,
) -> Path:
    """Draw :func:`pnv_figure` and write it as PNG (into ``outputs`` if given)."""
    fig = pnv_figure(history, title=title, impulse_unit=impulse_unit)
    return save_png(fig, path, outputs=outputs)
