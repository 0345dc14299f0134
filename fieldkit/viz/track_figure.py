"""PNG figures of a track analysis: the track, speed and spin, flight residuals, nets.

:func:`write_track_figures` writes into a folder:

* ``track.png`` — the tracked centres coloured by flight with the fitted parabolas, the
  impacts with their impact and restitution velocity arrows (and the arrows' scale),
  the ground at each impact (the surface of dip ``slope_deg`` one radius below the
  centre), impacts with quality flags ringed, over a video frame (pixels) when one is
  given and the track carries image coordinates, else in the section plane x-z
  (metres, equal axes);
* ``speed_spin.png`` — speed (measured by local differentiation, and from the flight
  fits) and spin against time, contacts shaded;
* ``residuals.png`` — distance of each sample from its fitted flight [mm], with the
  estimated position noise;
* ``net_contact_<i>.png`` — for each extended contact, speed, and the impulse the net
  has applied (a vector, gravity removed) beside the speed deficit the thesis calls
  impulse absorbed, both per impact momentum, against time from contact start
  (thesis Figs. 8.14 and 8.15).

Every axis names its unit; legends sit outside the axes.
"""

from __future__ import annotations

import functools
import os
import textwrap
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fieldkit.outputs import OutputSet
from fieldkit.tracking.flights.net_contacts import NetContact
from fieldkit.tracking.flights.pipeline import TrackAnalysis, noise_floor
from fieldkit.viz.figure_files import new_figure, save_png
from fieldkit.viz.image_projection import project, world_to_image
from fieldkit.viz.marks import mark_flagged, outside_legend, qa_column, velocity_key

_CONTACT_SHADE = dict(color="0.85", zorder=0)
GROUND_COLOUR = "#6b4f2a"
VI_COLOUR, VF_COLOUR = "crimson", "#1f4e9c"
#: The longest velocity arrow spans this share of the track's horizontal extent.
ARROW_SHARE = 0.12

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
        (TRACK_FIGURE_NAMES[0], lambda: plot_track(analysis, background_frame)),
        (TRACK_FIGURE_NAMES[1], lambda: plot_speed_spin(analysis)),
        (TRACK_FIGURE_NAMES[2], lambda: plot_residuals(analysis)),
    ]
    drawings += [
        (f"net_contact_{c.index}.png", functools.partial(plot_net_contact, c))
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


def plot_track(a: TrackAnalysis, background: np.ndarray | None = None) -> Figure:
    """``track.png`` (see the module docstring): over ``background`` (a BGR frame) in
    pixels when the track has image coordinates, else in the section plane."""
    f = a.track.frame
    h = world_to_image(f) if background is not None else None
    fig, ax = new_figure(8.0, 5.5)
    if h is not None:
        ax.imshow(
            background[..., ::-1] if background.ndim == 3 else background, cmap="gray"
        )
        u, v = f["u_px"].to_numpy(float), f["v_px"].to_numpy(float)
        ax.set_xlabel("u, image column [px]")
        ax.set_ylabel("v, image row [px]")
        ax.set_title("track over a video frame")
    else:
        u, v = f["x_m"].to_numpy(float), f["z_m"].to_numpy(float)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x, horizontal distance [m]")
        ax.set_ylabel("z, height [m]")
        ax.set_title("track in the section plane")
    label = f["flight"].to_numpy(int)
    off = label < 0
    ax.plot(
        u[off],
        v[off],
        ".",
        color="0.5",
        ms=2,
        label="in contact or outside the flights",
    )
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
            label=f"flight {fl.index}: g = {fl.g_text().replace('+/-', '±')} m/s²",
        )
    imp = a.impacts.frame
    arrows = None
    if len(imp):
        sx = -1.0 if any("mirrored" in w for w in a.warnings) else 1.0
        span_m = float(np.nanmax(f["x_m"]) - np.nanmin(f["x_m"]))
        x, z = sx * imp["x_m"].to_numpy(float), imp["z_m"].to_numpy(float)
        pts = _plot_points(h, x, z)
        net = a.net_rows
        _draw_ground(ax, imp, sx, h, span_m=span_m, net=net)
        for rows, marker, label in (
            (~net, "x", "impacts"),
            (net, "D", "net contact (start)"),
        ):
            if rows.any():
                ax.plot(
                    pts[rows, 0],
                    pts[rows, 1],
                    marker,
                    color="crimson",
                    ms=8 if marker == "x" else 6,
                    mfc="none",
                    label=label,
                )
        _label_impacts(ax, imp, sx, h)
        mark_flagged(ax, pts[:, 0], pts[:, 1], qa_column(imp))
        _, x_leave, z_leave = leaving_points(a)
        leave = np.column_stack([sx * x_leave, z_leave])
        arrows = _draw_velocities(ax, imp, sx, h, span_m=span_m, leave=leave)
    outside_legend(ax, fontsize=7)
    if arrows is not None:  # after the limits are set: the key goes where nothing is
        quiver, largest, tips = arrows
        drawn = np.vstack([np.column_stack([u, v]), pts, tips])
        velocity_key(ax, quiver, largest, drawn[:, 0], drawn[:, 1])
    return fig


#: Gap between an impact's contact point and its label [points].
LABEL_GAP_PT = 6.0


def _label_impacts(ax, imp, sx: float, h) -> None:
    """Label each impact ``point: e_n .., e_t ..`` on the surface side of its contact
    point (one radius below the centre along -N, past the ground line), where no
    trajectory runs; on a video frame the image's own axes keep the same sense."""
    psi = np.radians(imp["slope_deg"].to_numpy(float))
    radius = np.nan_to_num(imp["radius_m"].to_numpy(float))
    x, z = sx * imp["x_m"].to_numpy(float), imp["z_m"].to_numpy(float)
    away = -np.column_stack([sx * np.sin(psi), np.cos(psi)])  # -N, track frame
    away = np.where(np.isfinite(away), away, [0.0, -1.0])  # no slope: below
    contact = np.column_stack([x, z]) + radius[:, None] * away
    anchor = _plot_points(h, contact[:, 0], contact[:, 1])
    for (ax_, ay), (dx, dy), p, en, et in zip(
        anchor, away, imp["point"], imp["e_n"], imp["e_t"], strict=True
    ):
        if not (np.isfinite(ax_) and np.isfinite(ay)):
            continue
        ax.annotate(
            f"{p}: e_n {en:.2f}, e_t {et:.2f}",
            (ax_, ay),
            fontsize=7,
            xytext=(LABEL_GAP_PT * dx, LABEL_GAP_PT * dy),
            textcoords="offset points",
            ha="left" if dx > 0.35 else "right" if dx < -0.35 else "center",
            va="bottom" if dy > 0.35 else "top" if dy < -0.35 else "center",
            bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.75),
            zorder=8,
        )


def leaving_points(a: TrackAnalysis) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where and when the body leaves each contact of ``a.impacts``: ``(t_s, x_m,
    z_m)`` per row.

    An impact row gives the contact's start (``t_s``, ``x_m``, ``z_m``); an
    instantaneous impact leaves from there. An extended contact (a net) lasts
    ``contact_duration_s``: the body leaves at its end, on the flight that follows
    (the first flight starting after the contact's start), where the restitution
    velocity and the spin after the contact belong.
    """
    imp = a.impacts.frame
    t = imp["t_s"].to_numpy(float).copy()
    x, z = imp["x_m"].to_numpy(float).copy(), imp["z_m"].to_numpy(float).copy()
    if "contact_duration_s" not in imp.columns:
        return t, x, z
    duration = np.nan_to_num(imp["contact_duration_s"].to_numpy(float))
    starts = np.array([fl.t_start_s for fl in a.flights])
    for i in np.flatnonzero(duration > 0):
        after = np.flatnonzero(starts > t[i])
        if not len(after):
            continue
        t[i] = t[i] + duration[i]
        px, pz = a.flights[after[0]].position(t[i])
        x[i], z[i] = float(px), float(pz)
    return t, x, z


def _plot_points(h, x, z) -> np.ndarray:
    """``(n, 2)`` plot coordinates of world points: pixels over a frame, else metres."""
    return project(h, x, z) if h is not None else np.column_stack([x, z])


def _draw_ground(ax, imp, sx: float, h, *, span_m: float, net=None) -> None:
    """The surface at each impact: the line of dip ``slope_deg`` through the contact
    point one radius below the centre (along -N), reaching halfway to the neighbouring
    impacts (a quarter of the track's extent for a single impact). Rows ``net``
    (extended contacts) draw the net's line instead of ground, labelled so."""
    psi = np.radians(imp["slope_deg"].to_numpy(float))
    x, z = sx * imp["x_m"].to_numpy(float), imp["z_m"].to_numpy(float)
    radius = np.nan_to_num(imp["radius_m"].to_numpy(float))
    tangent = np.column_stack([sx * np.cos(psi), -np.sin(psi)])  # T, track frame
    normal = np.column_stack([sx * np.sin(psi), np.cos(psi)])  # N, track frame
    contact = np.column_stack([x, z]) - radius[:, None] * normal
    gaps = np.abs(np.diff(x))
    reach = np.full(len(x), 0.25 * span_m)
    if len(x) > 1:
        left = np.concatenate([[np.inf], gaps])
        right = np.concatenate([gaps, [np.inf]])
        reach = 0.5 * np.minimum(left, right)
    net = np.zeros(len(x), bool) if net is None else np.asarray(net, bool)
    labels = {
        False: "ground at each impact (the surface at its fitted dip)",
        True: "net's line at the contact (its fitted dip)",
    }
    for c, t, r, ok, is_net in zip(
        contact, tangent, reach, np.isfinite(psi), net, strict=True
    ):
        if not ok:
            continue
        ends = np.array([c - r * t, c + r * t])
        line = _plot_points(h, ends[:, 0], ends[:, 1])
        ax.plot(
            line[:, 0],
            line[:, 1],
            "-" if not is_net else "--",
            color=GROUND_COLOUR,
            lw=2.0,
            label=labels.pop(bool(is_net), None),
        )


def _draw_velocities(ax, imp, sx: float, h, *, span_m: float, leave=None):
    """Impact velocity arrows ending at each impact and restitution velocity arrows
    leaving it (from ``leave``, the ``(n, 2)`` points where the body leaves each
    contact in the track frame, :func:`leaving_points`; default the impact points),
    at one scale. Returns ``(quiver, largest speed, arrow tips)`` for the key, or
    None when no velocity is finite.

    Over a video frame the arrows are the projected displacements, scaled by the
    median image scale at the impacts [px/m], so the key is exact for a camera
    square to the plane."""
    centre = np.column_stack(
        [sx * imp["x_m"].to_numpy(float), imp["z_m"].to_numpy(float)]
    )
    vi = np.column_stack(
        [sx * imp["vi_x_mps"].to_numpy(float), imp["vi_z_mps"].to_numpy(float)]
    )
    vf = np.column_stack(
        [sx * imp["vf_x_mps"].to_numpy(float), imp["vf_z_mps"].to_numpy(float)]
    )
    speeds = np.concatenate([np.hypot(*vi.T), np.hypot(*vf.T)])
    if not np.isfinite(speeds).any():
        return None
    largest = float(np.nanmax(speeds))
    tau = ARROW_SHARE * max(span_m, 1e-9) / largest  # [s]: arrow length = v tau [m]
    scale = 1.0  # plot units per metre
    if h is not None:
        step = _plot_points(h, centre[:, 0] + 1.0, centre[:, 1]) - _plot_points(
            h, centre[:, 0], centre[:, 1]
        )
        scale = float(np.nanmedian(np.hypot(*step.T)))
    leave = centre if leave is None else np.asarray(leave, float)
    starts, vectors, colours = [], [], []
    for start_m, end_m, colour in (
        (centre - vi * tau, centre, VI_COLOUR),
        (leave, leave + vf * tau, VF_COLOUR),
    ):
        ok = np.isfinite(start_m).all(axis=1) & np.isfinite(end_m).all(axis=1)
        a = _plot_points(h, start_m[ok, 0], start_m[ok, 1])
        b = _plot_points(h, end_m[ok, 0], end_m[ok, 1])
        starts.append(a)
        vectors.append((b - a) / (tau * scale))  # m/s along the plot's axes
        colours += [colour] * int(ok.sum())
    starts, vectors = np.vstack(starts), np.vstack(vectors)
    quiver = ax.quiver(
        starts[:, 0],
        starts[:, 1],
        vectors[:, 0],
        vectors[:, 1],
        color=colours,
        angles="xy",
        scale_units="xy",
        scale=1.0 / (tau * scale),
        width=0.004,
        zorder=6,
    )
    ax.plot([], [], color=VI_COLOUR, lw=2, label="impact velocity (∝ speed)")
    ax.plot([], [], color=VF_COLOUR, lw=2, label="restitution velocity (∝ speed)")
    return quiver, largest, starts + vectors * tau * scale


#: Legend entry of the shaded contact spans.
CONTACT_LABEL = "contact: between two flights"


def _shade_contacts(ax, a: TrackAnalysis, *, label: bool = True) -> None:
    """Shade the time from each flight's last sample to the next one's first (one
    legend entry, :data:`CONTACT_LABEL`, unless ``label`` is False)."""
    for i in range(len(a.flights) - 1):
        t0, t1 = a.flights[i].t_end_s, a.flights[i + 1].t_start_s
        first = label and i == 0
        ax.axvspan(t0, t1, label=CONTACT_LABEL if first else None, **_CONTACT_SHADE)


def plot_speed_spin(a: TrackAnalysis) -> Figure:
    """``speed_spin.png``: speed and spin against time, contacts shaded."""
    import matplotlib.pyplot as plt

    f = a.track.frame
    t = f["t_s"].to_numpy(float)
    measured = np.hypot(*a.measured_velocity)
    ok = np.isfinite(measured)
    fig, (ax1, ax2) = plt.subplots(
        2, 1, figsize=(8, 6), sharex=True, layout="constrained"
    )
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
        _shade_contacts(ax, a)
    if ok.any():
        ax1.plot(
            t[ok],
            measured[ok],
            ".",
            ms=2,
            color="0.5",
            label="measured (local differentiation)",
        )
    for fl in a.flights:
        tt = np.linspace(fl.t_start_s, fl.t_end_s, 50)
        ax1.plot(
            tt,
            fl.speed(tt),
            color=_flight_colour(fl.index),
            label=f"flight {fl.index} fit",
        )
    ax1.set_ylabel("speed [m/s]")
    outside_legend(ax1, fontsize=7)
    omega = f["omega_radps"].to_numpy(float)
    if np.isfinite(omega).any():
        ax2.plot(t, omega, ".", ms=2, color="0.3", label="spin from the marker (track)")
    else:
        ax2.text(
            0.5, 0.5, "no spin marker followed", transform=ax2.transAxes, ha="center"
        )
    imp = a.impacts.frame
    if len(imp):
        ax2.plot(
            imp["t_s"],
            imp["omega_i_radps"],
            "v",
            color="crimson",
            label="spin before the impact",
        )
        t_leave, _, _ = leaving_points(a)
        ax2.plot(
            t_leave,
            imp["omega_f_radps"],
            "^",
            color="green",
            label="spin after the impact (net: as it leaves)",
        )
    outside_legend(ax2, fontsize=7)
    ax2.set_ylabel("spin omega [rad/s]")
    ax2.set_xlabel("time t [s]")
    return fig


def plot_residuals(a: TrackAnalysis) -> Figure:
    """``residuals.png``: distance of each sample from its fitted flight [mm]."""
    f = a.track.frame
    fig, ax = new_figure(8.0, 4.0)
    _shade_contacts(ax, a)
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
            label=textwrap.fill(_noise_label(a.track, noise), 44),
        )
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("distance from fitted flight [mm]")
    outside_legend(ax, fontsize=7)
    return fig


def _noise_label(track, noise_m: float) -> str:
    """What the dashed noise line of ``residuals.png`` is: the position noise the
    flight finding assumed (2-D), and whether it is the scatter measured in short
    windows or the floor for detections correlated from frame to frame
    (:func:`fieldkit.tracking.flights.pipeline.noise_floor`), which can lie well
    above the residuals of a clean video."""
    mm = 1e3 * noise_m * np.sqrt(2)
    text = f"position noise assumed to find flights, 2-D ({mm:.2f} mm)"
    floor = noise_floor(track)
    if floor > 0 and abs(noise_m - floor) <= 1e-9 * floor:
        return (
            f"{text}: its floor of 0.05 px, as detection errors are correlated "
            "over frames"
        )
    return f"{text}: the scatter about local parabolas"


def plot_net_contact(c: NetContact) -> Figure:
    """``net_contact_<i>.png``: speed and impulse absorbed through a net contact."""
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
    ax2.plot(
        t_ms,
        100 * c.net_impulse_fraction,
        "o-",
        ms=3,
        color="darkred",
        label="impulse the net has applied, |m (v - v_i - g t)| "
        "(a vector, gravity removed)",
    )
    ax2.plot(
        t_ms,
        100 * c.impulse_absorbed_fraction,
        "--",
        lw=1.0,
        color="0.45",
        label="speed deficit m (V_i - V), the thesis' impulse absorbed (Fig. 8.15)",
    )
    ax2.set_ylabel("share of the impact momentum m V_i [%]")
    ax2.set_xlabel("time from contact start [ms]")
    outside_legend(ax2, below=True, ncols=1, fontsize=7)
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    return fig
