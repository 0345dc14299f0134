"""PNG figures of a track analysis: the track, speed and spin, flight residuals, nets.

:func:`write_track_figures` writes into a folder:

* ``track.png`` — the tracked centres coloured by flight with the fitted parabolas and
  the impacts, over a video frame (pixels) when one is given and the track carries
  image coordinates, else in the section plane x-z (metres, equal axes);
* ``speed_spin.png`` — speed (measured by local differentiation, and from the flight
  fits) and spin against time, contacts shaded;
* ``residuals.png`` — distance of each sample from its fitted flight [mm], with the
  estimated position noise;
* ``net_contact_<i>.png`` — for each extended contact, speed and share of impulse
  absorbed against time from contact start (thesis Figs. 8.14 and 8.15).
"""

from __future__ import annotations

import functools
import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fieldkit.outputs import OutputSet
from fieldkit.tracking.flights.pipeline import TrackAnalysis
from fieldkit.viz.figure_files import new_figure, save_png
from fieldkit.viz.image_projection import project, world_to_image

_CONTACT_SHADE = dict(color="0.85", zorder=0)

#: The figures every track gets (net contacts add ``net_contact_<i>.png``).
TRACK_FIGURE_NAMES: tuple[str, ...] = ("track.png", "speed_spin.png", "residuals.png")


def write_track_figures(
    directory: str | os.PathLike[str],
    analysis: TrackAnalysis,
    background_frame: np.ndarray | None = None,
    *,
    outputs: OutputSet | None = None,
) -> list[Path]:
    """Write the PNG figures of a track analysis into ``directory``.

    Parameters
    ----------
    directory
        Output folder (created if needed).
    analysis
        From :func:`fieldkit.tracking.flights.pipeline.analyse_track`.
    background_frame
        A BGR video frame to draw the track over (needs ``u_px``/``v_px`` columns in
        the track).
    outputs
        Add the figures to this :class:`~fieldkit.outputs.OutputSet` (written when
        it commits) instead of writing them at once.

    Returns
    -------
    list of Path
        The files written: :data:`TRACK_FIGURE_NAMES`, then
        ``net_contact_<i>.png`` for each extended contact.
    """
    out = Path(directory)
    drawings = [
        (TRACK_FIGURE_NAMES[0], lambda: _track_figure(analysis, background_frame)),
        (TRACK_FIGURE_NAMES[1], lambda: _speed_spin_figure(analysis)),
        (TRACK_FIGURE_NAMES[2], lambda: _residual_figure(analysis)),
    ]
    drawings += [
        (f"net_contact_{c.index}.png", functools.partial(_net_figure, c))
        for c in analysis.contacts
    ]
    into = OutputSet() if outputs is None else outputs
    paths = [save_png(draw(), out / name, outputs=into) for name, draw in drawings]
    if outputs is None:
        into.commit()
    return paths


def _flight_colour(i: int):
    import matplotlib

    return matplotlib.colormaps["tab10"](i % 10)


def _track_figure(a: TrackAnalysis, background) -> Figure:
    f = a.track.frame
    h = world_to_image(f) if background is not None else None
    fig, ax = new_figure(8.0, 5.5)
    if h is not None:
        ax.imshow(
            background[..., ::-1] if background.ndim == 3 else background, cmap="gray"
        )
        u, v = f["u_px"].to_numpy(float), f["v_px"].to_numpy(float)
        ax.set_xlabel("u [px]")
        ax.set_ylabel("v [px]")
        ax.set_title("track over a video frame")
    else:
        u, v = f["x_m"].to_numpy(float), f["z_m"].to_numpy(float)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("z [m]")
        ax.set_title("track in the section plane")
    label = f["flight"].to_numpy(int)
    off = label < 0
    ax.plot(u[off], v[off], ".", color="0.5", ms=2, label="contact / unassigned")
    for fl in a.flights:
        ax.plot(u[fl.rows], v[fl.rows], ".", ms=2, color=_flight_colour(fl.index))
        t = np.linspace(fl.t_start_s, fl.t_end_s, 100)
        x, z = fl.position(t)
        pts = project(h, x, z) if h is not None else np.column_stack([x, z])
        ax.plot(
            pts[:, 0],
            pts[:, 1],
            "-",
            lw=1,
            color=_flight_colour(fl.index),
            label=f"flight {fl.index}: g = {fl.g_mps2:.2f} ± {fl.g_se_mps2:.2f}",
        )
    imp = a.impacts.frame
    if len(imp):
        sx = -1.0 if any("mirrored" in w for w in a.warnings) else 1.0
        x, z = sx * imp["x_m"].to_numpy(float), imp["z_m"].to_numpy(float)
        pts = project(h, x, z) if h is not None else np.column_stack([x, z])
        ax.plot(pts[:, 0], pts[:, 1], "x", color="crimson", ms=8, label="impacts")
        for (px, py), p, en, et in zip(
            pts, imp["point"], imp["e_n"], imp["e_t"], strict=True
        ):
            ax.annotate(
                f"{p}: e_n {en:.2f}, e_t {et:.2f}",
                (px, py),
                fontsize=7,
                xytext=(4, -10),
                textcoords="offset points",
            )
    ax.legend(fontsize=7, loc="best")
    return fig


def _shade_contacts(ax, a: TrackAnalysis) -> None:
    for i in range(len(a.flights) - 1):
        t0, t1 = a.flights[i].t_end_s, a.flights[i + 1].t_start_s
        ax.axvspan(t0, t1, **_CONTACT_SHADE)


def _speed_spin_figure(a: TrackAnalysis) -> Figure:
    import matplotlib.pyplot as plt

    f = a.track.frame
    t = f["t_s"].to_numpy(float)
    measured = np.hypot(*a.measured_velocity)
    ok = np.isfinite(measured)
    fig, (ax1, ax2) = plt.subplots(
        2, 1, figsize=(8, 6), sharex=True, layout="constrained"
    )
    if ok.any():
        ax1.plot(t[ok], measured[ok], ".", ms=2, color="0.5", label="measured")
    for fl in a.flights:
        tt = np.linspace(fl.t_start_s, fl.t_end_s, 50)
        ax1.plot(
            tt,
            fl.speed(tt),
            color=_flight_colour(fl.index),
            label=f"flight {fl.index} fit",
        )
    ax1.set_ylabel("speed [m/s]")
    ax1.legend(fontsize=7)
    omega = f["omega_radps"].to_numpy(float)
    if np.isfinite(omega).any():
        ax2.plot(t, omega, ".", ms=2, color="0.3", label="omega (track)")
    else:
        ax2.text(
            0.5, 0.5, "no spin marker followed", transform=ax2.transAxes, ha="center"
        )
    imp = a.impacts.frame
    if len(imp):
        ax2.plot(imp["t_s"], imp["omega_i_radps"], "v", color="crimson", label="before")
        ax2.plot(imp["t_s"], imp["omega_f_radps"], "^", color="green", label="after")
        ax2.legend(fontsize=7)
    ax2.set_ylabel("spin omega [rad/s]")
    ax2.set_xlabel("t [s]")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
        _shade_contacts(ax, a)
    return fig


def _residual_figure(a: TrackAnalysis) -> Figure:
    f = a.track.frame
    fig, ax = new_figure(8.0, 4.0)
    for fl in a.flights:
        ax.plot(
            f["t_s"].to_numpy(float)[fl.rows],
            1e3 * fl.residual_m,
            ".",
            ms=2,
            color=_flight_colour(fl.index),
            label=f"flight {fl.index}: RMS {1e3 * fl.rms_m:.2f} mm",
        )
    noise = a.track.meta.get("noise_m", np.nan)
    if np.isfinite(noise):
        ax.axhline(
            1e3 * noise * np.sqrt(2),
            color="k",
            ls="--",
            lw=0.8,
            label="noise estimate (2-D RMS)",
        )
    _shade_contacts(ax, a)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("distance from fitted flight [mm]")
    ax.legend(fontsize=7)
    return fig


def _net_figure(c) -> Figure:
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(
        2, 1, figsize=(7, 6), sharex=True, layout="constrained"
    )
    t_ms = 1e3 * (c.t_s - c.t_start_s)
    ax1.plot(t_ms, c.speed_mps, "o-", ms=3)
    ax1.axhline(c.v_min_mps, color="0.6", ls=":", lw=0.8)
    ax1.set_ylabel("speed V [m/s]")
    ax1.set_title(
        f"net contact {c.index}: {1e3 * c.duration_s:.1f} ms, V_i {c.vi_mps:.2f} -> "
        f"V_min {c.v_min_mps:.2f} -> V_f {c.vf_mps:.2f} m/s, "
        f"E_e = {100 * c.efficiency:.0f} % (eq. 8.1)",
        fontsize=9,
    )
    ax2.plot(t_ms, 100 * c.impulse_absorbed_fraction, "o-", ms=3, color="darkred")
    ax2.set_ylabel("impulse absorbed [% of m V_i]")
    ax2.set_xlabel("time from contact start [ms]")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    return fig
