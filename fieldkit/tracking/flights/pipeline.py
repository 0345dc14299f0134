"""Track -> flights -> impacts and net contacts: the analysis behind `fieldkit track`.

:func:`analyse_track` runs the whole chain on any :class:`Track` (from video, OSP
Tracker or Kinovea):

1. :func:`fieldkit.tracking.flights.segmentation.find_flights` splits the track into
   ballistic flights (contacts found from the data);
2. :func:`fieldkit.tracking.flights.ballistic_fit.fit_flight` fits each flight with g
   free (its g and standard error are checked against 9.81) and with g fixed;
3. :mod:`fieldkit.tracking.flights.contact_impacts` evaluates the fits at each contact
   and builds the ImpactTable (the ground given -- one angle, a profile, a DEM:
   :mod:`fieldkit.tracking.flights.ground` -- or its angle estimated);
4. :mod:`fieldkit.tracking.flights.contact_physics` judges every join: one with no
   impulse, at an apex, gaining energy or in mid-air above the floor the other
   impacts touch is refused with its reason (:attr:`TrackAnalysis.refusals`), and
   the flights on either side become one when one free flight explains them;
5. :mod:`fieldkit.tracking.flights.net_contacts` describes every extended contact (net).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pandas as pd

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.impact_table import ImpactTable
from fieldkit.physics.constants import G
from fieldkit.track import Track
from fieldkit.tracking.flights.ballistic_fit import (
    GRAVITY_WARNING_SIGMAS,
    FlightFit,
    fit_flight,
)
from fieldkit.tracking.flights.contact_impacts import (
    ContactEvent,
    build_impact_table,
    find_contact_events,
)
from fieldkit.tracking.flights.contact_physics import (
    Refusal,
    judge_join,
    off_the_floor,
    velocity_se,
)
from fieldkit.tracking.flights.free_flight import classify_join, explained_by_drift
from fieldkit.tracking.flights.ground import ConstantGround, Ground, in_track_frame
from fieldkit.tracking.flights.impact_uncertainty import contact_time_sd
from fieldkit.tracking.flights.net_contacts import (
    NetContact,
    analyse_net_contact,
    local_velocity,
)
from fieldkit.tracking.flights.segmentation import ContactSpan, find_flights

#: Fewest samples a track needs to be analysed.
MIN_TRACK_SAMPLES = 10
#: Fewest samples left in a flight trimmed at a soft contact.
MIN_FLIGHT_SAMPLES = 8
#: Fewest usable samples for the measured velocities of a track.
MIN_VELOCITY_SAMPLES = 5
#: Largest slow detection drift, as a share of the body radius, that may explain two
#: flights as one free flight (a drifting centre must not split a flight).
DRIFT_LIMIT_FRACTION = 0.25


@dataclass
class TrackAnalysis:
    """Everything found in one track.

    Attributes
    ----------
    track
        The input track with two more columns: ``flight`` (flight index, -1 for samples
        in contact or unassigned) and ``residual_m`` (distance from the fitted flight,
        NaN outside flights).
    flights
        The fitted flights in time order.
    impacts
        One row per contact between consecutive flights (empty table when none):
        instantaneous impacts and extended contacts alike, the latter with
        ``contact_duration_s > 0`` and, on an overhanging net, ``slope_deg`` beyond
        +/-90 deg (docs/architecture.md §2). :attr:`net_rows` tells them apart.
    contacts
        The extended contacts (nets, rolling phases) with their time series; each
        is also a row of ``impacts``.
    warnings
        One-line warnings for the user (gravity off, surface angle assumed, ...).
    refusals
        Every event between flights that is not reported as a contact, with its
        frames and a one-line reason (:class:`~.contact_physics.Refusal`).
    bridged
        One line per impact with two or more frames between its flights (frames
        lost to blur, samples off both flights): the frames bridged and the
        uncertainty of the impact time, which grows with them.
    measured_velocity
        Velocity of every track sample by local differentiation (not from the fits).
    """

    track: Track
    flights: list[FlightFit]
    impacts: ImpactTable
    contacts: list[NetContact]
    warnings: list[str]
    refusals: list[Refusal] = dataclasses.field(default_factory=list)
    bridged: list[str] = dataclasses.field(default_factory=list)

    @property
    def net_rows(self) -> np.ndarray:
        """True for the rows of ``impacts`` that are extended contacts (a net, a
        rolling phase: ``contact_duration_s > 0``), False for instantaneous impacts.

        An extended contact is one event: it is counted and described as a net
        contact, not as an impact on a ground line as well.
        """
        f = self.impacts.frame
        if "contact_duration_s" not in f.columns:
            return np.zeros(len(f), bool)
        duration = pd.to_numeric(f["contact_duration_s"], errors="coerce")
        return duration.fillna(0.0).to_numpy(float) > 0.0

    @property
    def n_impacts(self) -> int:
        """Instantaneous impacts (rows of ``impacts`` that are not net contacts)."""
        return int((~self.net_rows).sum())

    def counts_text(self) -> str:
        """``2 flights, 0 impacts, 1 net contact``: each event counted once."""

        def n(count: int, noun: str) -> str:
            return f"{count} {noun}{'' if count == 1 else 's'}"

        return (
            f"{n(len(self.flights), 'flight')}, {n(self.n_impacts, 'impact')}, "
            f"{n(len(self.contacts), 'net contact')}"
        )

    def net_rows_text(self) -> list[str]:
        """One line per net contact row of ``impacts``: the surface it found (the
        net's line, overhanging when beyond +/-90 deg) and e_n, e_t on it."""
        f = self.impacts.frame
        lines = []
        for i in np.flatnonzero(self.net_rows):
            row = f.iloc[i]
            psi = float(row["slope_deg"])
            side = (
                "overhanging: N faces the body"
                if np.isfinite(psi) and abs(psi) > 90
                else "N faces the body"
            )
            lines.append(
                f"impact table point {row['point']} (the net contact at t "
                f"{float(row['t_s']):.4f} s): surface slope_deg {psi:.1f} deg (the "
                f"net's line, {side}); "
                f"e_n {float(row['e_n']):.3f}, e_t {float(row['e_t']):.3f}"
            )
        return lines

    @cached_property
    def measured_velocity(self) -> tuple[np.ndarray, np.ndarray]:
        """Velocity ``(vx, vz)`` [m/s] of every track sample, from the samples alone.

        Local quadratic differentiation of the tracked centre
        (:func:`fieldkit.tracking.flights.net_contacts.local_velocity`, as in the net
        contacts) over the samples with finite ``t_s``, ``x_m`` and ``z_m``; NaN for
        the others, and everywhere when fewer than :data:`MIN_VELOCITY_SAMPLES` are
        usable. Aligned with the rows of ``track``; computed on first use.
        """
        f = self.track.frame
        t = f["t_s"].to_numpy(float)
        x, z = f["x_m"].to_numpy(float), f["z_m"].to_numpy(float)
        ok = np.isfinite(t) & np.isfinite(x) & np.isfinite(z)
        vx, vz = np.full(len(f), np.nan), np.full(len(f), np.nan)
        if ok.sum() >= MIN_VELOCITY_SAMPLES:
            vx[ok] = local_velocity(t[ok], x[ok])
            vz[ok] = local_velocity(t[ok], z[ok])
        return vx, vz


def analyse_track(
    track: Track,
    *,
    radius_m: float,
    surface_angle_deg: float | None = None,
    mass_kg: float | None = None,
    gyration_m: float | None = None,
    path_id: str = "video",
    ground: Ground | None = None,
    calibration_rel_sd: float = 0.0,
) -> TrackAnalysis:
    """Find flights, impacts and net contacts in a track.

    Parameters
    ----------
    track
        Positions in metres, times in seconds, x horizontal, z up.
    radius_m
        Body radius [m] (contact geometry, spin-based surface angle).
    surface_angle_deg
        Dip of the impact surface psi [deg], positive descending toward travel; when
        None it is estimated (see :mod:`fieldkit.tracking.flights.contact_impacts`).
        The same as ``ground=ConstantGround(surface_angle_deg)``.
    mass_kg, gyration_m
        Body mass [kg] and radius of gyration [m] for energies (optional).
    path_id
        Identifier written to the ImpactTable.
    ground
        The known ground (:mod:`fieldkit.tracking.flights.ground`) in the track's
        calibrated frame (turned by
        :func:`~fieldkit.tracking.flights.ground.in_track_frame` when the track is
        stored mirrored): a dip per contact from a surveyed profile or a DEM;
        excludes ``surface_angle_deg``.
    calibration_rel_sd
        Relative standard uncertainty of g from the stated length scale and
        capture rate [-] (``ballistic_fit.calibration_rel_sd``): widens each
        flight's check of g against 9.81 (``FlightFit.g_check_se_mps2``), not the
        comparison of one clip's flights, which share the calibration. 0: the
        scale and rate taken as exact.

    Returns
    -------
    TrackAnalysis

    Examples
    --------
    >>> from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball
    >>> truth = bouncing_ball(duration_s=0.5, e_n=0.6, e_t=0.8)
    >>> a = analyse_track(truth.track, radius_m=0.0375, surface_angle_deg=10.0)
    >>> len(a.flights), round(float(a.impacts.frame["e_n"].iloc[0]), 3)
    (2, 0.6)
    """
    if not np.isfinite(radius_m) or radius_m <= 0:
        raise ArgumentError(
            f"radius_m must be > 0 (got {radius_m:g})", source="radius_m"
        )
    if surface_angle_deg is not None:
        if ground is not None:
            raise ArgumentError(
                "surface_angle_deg and `ground` both give the surface; give one",
                source="surface_angle_deg",
            )
        ground = ConstantGround(surface_angle_deg)
    ground = in_track_frame(ground, track.meta)
    if mass_kg is not None and not mass_kg > 0:
        raise ArgumentError(f"mass_kg must be > 0 (got {mass_kg:g})", source="mass_kg")
    if gyration_m is not None and not gyration_m > 0:
        raise ArgumentError(
            f"gyration_m must be > 0 (got {gyration_m:g})", source="gyration_m"
        )
    if not (np.isfinite(calibration_rel_sd) and calibration_rel_sd >= 0):
        raise ArgumentError(
            f"calibration_rel_sd must be >= 0 (got {calibration_rel_sd:g})",
            source="calibration_rel_sd",
        )
    frame = track.frame.sort_values("t_s", kind="stable").reset_index(drop=True)
    track = Track(
        frame.copy(), source=track.source, fps=track.fps, meta=dict(track.meta)
    )
    track.meta["calibration_rel_sd"] = float(calibration_rel_sd)
    n_valid = int(np.isfinite(track.t + track.x + track.z).sum())
    if n_valid < MIN_TRACK_SAMPLES:
        raise InputFileError(
            f"track has {n_valid} usable samples; "
            f"at least {MIN_TRACK_SAMPLES} are needed",
            source=track.source or None,
        )

    seg = find_flights(
        track.t, track.x, track.z, noise_floor_m=noise_floor(track),
        drift_limit_m=DRIFT_LIMIT_FRACTION * radius_m,
    )  # fmt: skip
    rows_of = list(seg.flights)
    flights = _fit_all(track, rows_of)
    events = find_contact_events(track, flights, seg.contacts, seg.frame_interval_s)
    # samples a soft contact still acted on (before its fitted onset) leave the flights
    changed = False
    for ev in events:
        if not ev.extended:
            continue
        before, after = rows_of[ev.before], rows_of[ev.after]
        keep_b = before[track.t[before] <= ev.t_impact_s]
        keep_a = after[track.t[after] >= ev.t_restitution_s]
        if MIN_FLIGHT_SAMPLES <= len(keep_b) < len(before):
            rows_of[ev.before], changed = keep_b, True
        if MIN_FLIGHT_SAMPLES <= len(keep_a) < len(after):
            rows_of[ev.after], changed = keep_a, True
    if changed:
        flights = _fit_all(track, rows_of)
        events = find_contact_events(track, flights, seg.contacts, seg.frame_interval_s)
    refusals = [
        Refusal(
            float(track.t[a]), float(track.t[b]), (_frame(track, a), _frame(track, b)),
            "drift",
            f"one free flight explains the samples through a slow detection drift of "
            f"{1e3 * drift:.2f} mm (at most {DRIFT_LIMIT_FRACTION:g} radius)",
            merged=True,
        )
        for a, b, drift in seg.drift_joins
    ]  # fmt: skip
    misfit_flights = {m.flight for m in seg.misfits}
    rows_of, flights, events, judged, misfit_flights = judge_contacts(
        track, rows_of, flights, events, seg.frame_interval_s,
        sigma_m=seg.noise_m, radius_m=radius_m, gyration_m=gyration_m,
        off_floor=ground is None, misfit_flights=misfit_flights,
        g_reference_mps2=free_flight_gravity(seg.g_common_mps2),
    )  # fmt: skip
    refusals.extend(judged)

    warnings: list[str] = []
    if not flights:
        warnings.append("no ballistic flight found in the track")
    misfit = {}
    for m in seg.misfits:  # flights renumbered by joins the physics refused
        at = [f.index for f in flights if f.t_start_s <= m.t_start_s <= f.t_end_s]
        if at and at[0] in misfit_flights:
            misfit[at[0]] = m
    for f in flights:
        if f.index in misfit:  # its g is off because drag bends it, not the scale
            warnings.append(misfit[f.index].message())
            continue
        message = f.gravity_warning()
        if message:
            warnings.append(message)

    label = np.full(len(track), -1, dtype=int)
    residual = np.full(len(track), np.nan)
    for f in flights:
        label[f.rows] = f.index
        residual[f.rows] = f.residual_m
    track.frame["flight"] = label
    track.frame["residual_m"] = residual
    # the track file's provenance: which flights only a dragged flight explains
    model = np.full(len(track), "", dtype=object)
    for f in flights:
        model[f.rows] = "air_drag" if f.index in misfit else "ballistic"
    track.frame["flight_model"] = model
    # the track file carries the body, so a diagnosis of it needs no radius again
    track.frame["body_radius_m"] = radius_m
    if mass_kg is not None:
        track.frame["body_mass_kg"] = mass_kg
    track.meta["misfits"] = [m.message() for m in seg.misfits]
    track.meta.update(
        noise_m=seg.noise_m,
        g_common_mps2=seg.g_common_mps2,
        frame_interval_s=seg.frame_interval_s,
    )

    table, table_warnings = build_impact_table(
        events,
        flights,
        radius_m=radius_m,
        ground=ground,
        mass_kg=mass_kg,
        gyration_m=gyration_m,
        path_id=path_id,
    )
    warnings.extend(table_warnings)
    if table is None:
        table = empty_impact_table()

    contacts = []
    for ev in events:
        if not ev.extended:
            continue
        contacts.append(
            analyse_net_contact(
                track,
                ev.rows,
                flights[ev.before],
                flights[ev.after],
                index=len(contacts),
                mass_kg=mass_kg,
                gyration_m=gyration_m,
                omega_i_radps=ev.omega_i_radps,
                omega_f_radps=ev.omega_f_radps,
                t_start_s=ev.t_impact_s,
                t_end_s=ev.t_restitution_s,
            )
        )
    for line in warnings:  # the table's own refusals (surface, e_n < 0)
        if " refused as an impact: " in line:
            t_text = line.split("t = ", 1)[1].split(" s", 1)[0]
            t_ref = float(t_text)
            refusals.append(
                Refusal(t_ref, t_ref, _frames_at(track, t_ref), "surface",
                        line.split(" refused as an impact: ", 1)[1])
            )  # fmt: skip
    refusals.extend(edge_refusals(track, flights, seg.noise_m, radius_m))
    refusals.sort(key=lambda r: r.t_start_s)
    bridged = bridged_impacts(track, flights, events, seg.frame_interval_s)
    return TrackAnalysis(track, flights, table, contacts, warnings, refusals, bridged)


def bridged_impacts(
    track: Track, flights: list[FlightFit], events: list[ContactEvent], dt: float
) -> list[str]:
    """A line per instantaneous impact with two or more frames between its flights:
    how many, how many had no detection, and the impact time with its uncertainty
    (:func:`~.impact_uncertainty.contact_time_sd`)."""
    lines = []
    if not (np.isfinite(dt) and dt > 0):
        return lines
    for ev in events:
        if ev.extended:
            continue
        fa, fb = flights[ev.before], flights[ev.after]
        between = int(round((fb.t_start_s - fa.t_end_s) / dt)) - 1
        if between < 2:
            continue
        missing = between - len(ev.rows)
        sd = contact_time_sd(fa, fb, ev.t_impact_s)
        lines.append(
            f"impact at t = {ev.t_impact_s:.4f} +/- {sd:.2g} s "
            f"({sd / dt:.2f} frame): {between} frames between its flights "
            f"({missing} without a detection, {len(ev.rows)} off both flights) "
            "bridged by extrapolating both flights to where they meet"
        )
    return lines


def _frame(track: Track, position: int) -> int:
    """The frame number of a sample: the track's ``frame`` column, else its position."""
    if "frame" in track.frame.columns:
        value = track.frame["frame"].iloc[position]
        if np.isfinite(value):
            return int(value)
    return int(position)


def _frames_at(track: Track, t_s: float) -> tuple[int, int]:
    """Frames of the samples on either side of the instant ``t_s``."""
    k = int(np.searchsorted(track.t, t_s))
    lo, hi = max(k - 1, 0), min(k, len(track) - 1)
    return _frame(track, lo), _frame(track, hi)


def contact_spans(track: Track, rows_of: list[np.ndarray]) -> list[ContactSpan]:
    """The spans between consecutive flights (rows: the usable samples between)."""
    usable = np.isfinite(track.t + track.x + track.z)
    spans = []
    for k in range(len(rows_of) - 1):
        a, b = rows_of[k], rows_of[k + 1]
        inside = np.arange(a[-1] + 1, b[0])
        spans.append(
            ContactSpan(
                before=k, after=k + 1, rows=inside[usable[inside]],
                t_last_before_s=float(track.t[a[-1]]),
                t_first_after_s=float(track.t[b[0]]),
            )
        )  # fmt: skip
    return spans


def _one_flight_through(
    track: Track, rows_of: list[np.ndarray], ev: ContactEvent, sigma_m: float,
    radius_m: float,
) -> tuple[str, str] | None:  # fmt: skip
    """``("free_flight", reason)`` when one flight with a slow detection drift
    explains the flights on either side of ``ev`` and the samples between."""
    rows = np.concatenate([rows_of[ev.before], ev.rows, rows_of[ev.after]])
    rows = np.sort(rows[np.isfinite(track.t[rows] + track.x[rows] + track.z[rows])])
    drift = explained_by_drift(
        track.t[rows], track.x[rows], track.z[rows], g_mps2=G, sigma_m=sigma_m,
        drift_limit_m=DRIFT_LIMIT_FRACTION * radius_m,
    )  # fmt: skip
    if drift is None:
        return None
    return (
        "free_flight",
        f"one free flight explains all {rows.size} samples across it, through a slow "
        f"detection drift of {1e3 * drift:.2f} mm (at most "
        f"{DRIFT_LIMIT_FRACTION:g} radius); nothing struck the body",
    )


def free_flight_gravity(g_common_mps2: float) -> float:
    """The g a free flight of the track must fit [m/s^2]: 9.81, or the track's own
    g when that is more than 20 % off (a wrong capture rate or scale, warned)."""
    if np.isfinite(g_common_mps2) and abs(g_common_mps2 / G - 1.0) >= 0.2:
        return float(g_common_mps2)
    return G


def not_free_beside(
    ev: ContactEvent, flights: list[FlightFit], misfits: set[int], g_mps2: float
) -> str | None:
    """Why an extended contact's flights are not free flights, or None."""
    if not ev.extended:
        return None
    for k in (ev.before, ev.after):
        f = flights[k]
        if k in misfits or not (np.isfinite(f.g_se_mps2) and f.g_se_mps2 > 0):
            continue
        sigmas = (f.g_mps2 - g_mps2) / f.g_se_mps2
        if abs(sigmas) > GRAVITY_WARNING_SIGMAS:
            return (
                f"flight {k} beside it (t = {f.t_start_s:.4f}-{f.t_end_s:.4f} s) is "
                f"not a free flight in this frame (g = {f.g_text()} m/s^2, "
                f"{sigmas:+.1f} standard errors from {g_mps2:.4g}: a scale that "
                "varies with depth, lens distortion, a moving camera, a contact "
                "inside it?), so the samples between cannot be told from a contact; "
                "the clip is not reduced here"
            )
    return None


#: An extended contact is refused when the body was not detected in more than this
#: share of the frames between its flights (occluded by a net, a hoop, a person).
MAX_UNSEEN_FRACTION = 0.5
#: ... or when its samples move faster than this many times the speed energy allows.
MAX_SPEED_RATIO = 2.0


def unmeasured_inside(
    track: Track, rows_of: list[np.ndarray], ev: ContactEvent, sigma_m: float
) -> str | None:
    """Why an extended contact's path is not measured, or None.

    Between the last sample of the flight before and the first of the flight
    after (frames from the track's ``frame`` column):

    - the body was not detected in more than :data:`MAX_UNSEEN_FRACTION` of the
      frames (at least two): a net, a hoop or a person hid it;
    - or two consecutive samples lie farther apart than a body could travel:
      faster than :data:`MAX_SPEED_RATIO` times the speed its entry or exit speed
      and the fall across the samples allow (``v^2 = v_in^2 + 2 g drop``), plus
      the detection noise. Those are not one body's positions (a wrong detection),
      so the contact cannot be reduced.
    """
    if not ev.extended:
        return None
    a, b = int(rows_of[ev.before][-1]), int(rows_of[ev.after][0])
    first, last = _frame(track, a), _frame(track, b)
    where = f"contact at frames {first}-{last} not reduced: "
    if "frame" in track.frame.columns:
        between = last - first - 1
        unseen = between - (b - a - 1)  # the track's samples between them
        if unseen >= 2 and unseen > MAX_UNSEEN_FRACTION * between:
            return (
                f"{where}body not detected in {unseen} of the {between} frames "
                "between its flights"
            )
    rows = np.concatenate([[a], np.sort(ev.rows), [b]]).astype(int)
    t, x, z = track.t[rows], track.x[rows], track.z[rows]
    ok = np.isfinite(t + x + z)
    t, x, z, rows = t[ok], x[ok], z[ok], rows[ok]
    if rows.size < 3:
        return None
    dt = np.diff(t)
    step = np.hypot(np.diff(x), np.diff(z))
    v_in = max(float(np.hypot(*ev.vi_mps)), float(np.hypot(*ev.vf_mps)))
    drop = float(np.ptp(z))
    v_max = MAX_SPEED_RATIO * np.sqrt(v_in**2 + 2.0 * G * drop)
    limit = v_max * dt + 3.0 * np.sqrt(2.0) * sigma_m
    k = int(np.argmax(step - limit))
    if step[k] <= limit[k]:
        return None
    return (
        f"{where}the body moves {step[k]:.2f} m between frames "
        f"{_frame(track, int(rows[k]))} and {_frame(track, int(rows[k + 1]))} "
        f"({step[k] / dt[k]:.1f} m/s; at most {v_max:.1f} m/s from its speed and "
        "fall): the detections between its flights are not one body's path"
    )


def edge_refusals(
    track: Track, flights: list[FlightFit], sigma_m: float, radius_m: float
) -> list[Refusal]:
    """The track's ends that hold a contact no flight pair can reduce.

    Samples before the first flight (after the last) that are too few for a flight
    of their own and leave that flight's parabola, extrapolated to them, by more
    than five noise standard deviations plus :data:`DRIFT_LIMIT_FRACTION` radius,
    met something: a contact between them and the flight, with no flight on the
    other side to measure it. Each such end is one ``unreduced`` refusal.
    """
    if not flights:
        return []
    usable = np.flatnonzero(np.isfinite(track.t + track.x + track.z))
    tolerance = 5.0 * sigma_m + DRIFT_LIMIT_FRACTION * radius_m
    out = []
    ends = (
        (usable[usable < flights[0].rows[0]], flights[0], "before the first"),
        (usable[usable > flights[-1].rows[-1]], flights[-1], "after the last"),
    )
    for rows, fit, where in ends:
        if not 2 <= rows.size < MIN_FLIGHT_SAMPLES:
            continue
        x, z = fit.position(track.t[rows])
        off = float(np.max(np.hypot(track.x[rows] - x, track.z[rows] - z)))
        if off <= tolerance:
            continue
        if rows[0] < fit.rows[0]:
            a, b = int(rows[0]), int(fit.rows[0])
        else:
            a, b = int(fit.rows[-1]), int(rows[-1])
        frames = (_frame(track, a), _frame(track, b))
        out.append(
            Refusal(
                float(track.t[a]), float(track.t[b]), frames, "unreduced",
                f"contact at frames {frames[0]}-{frames[1]} not reduced: "
                f"{rows.size} samples {where} flight (fewer than "
                f"{MIN_FLIGHT_SAMPLES} for a flight) leave its parabola by "
                f"{1e3 * off:.0f} mm; no flight on their side measures the contact",
            )
        )  # fmt: skip
    return out


def judge_contacts(
    track: Track,
    rows_of: list[np.ndarray],
    flights: list[FlightFit],
    events: list[ContactEvent],
    frame_interval_s: float,
    *,
    sigma_m: float,
    radius_m: float,
    gyration_m: float | None,
    off_floor: bool,
    misfit_flights: set[int],
    g_reference_mps2: float = G,
):
    """Refuse the events that are not contacts; join the flights one flight explains.

    Each event is judged by :func:`~.contact_physics.judge_join` (an impulse, no
    energy gained, not an apex) and, with ``off_floor``, the instantaneous ones by
    :func:`~.contact_physics.off_the_floor`. The first refused event's flights
    become one when :func:`~.free_flight.classify_join` (slow drift allowed) does not
    choose two flights; otherwise they stay apart with no contact between them.
    An extended contact whose flights are not free flights (their fitted g off
    ``g_reference_mps2`` by more than
    :data:`~.ballistic_fit.GRAVITY_WARNING_SIGMAS` standard errors, drag
    misfits aside) is refused too: its start and end come from those flights, and
    the samples between cannot be told from a flight the frame bends (an
    uncorrected lens, a moving camera). Repeated until every event left is a
    contact.

    Returns
    -------
    rows_of, flights, events, refusals, misfit_flights
        The flights (rows and fits), the contact events kept, the refusals and the
        indices of the flights only a dragged flight explains, renumbered.
    """
    k_gyr = gyration_m if gyration_m is not None else np.sqrt(0.4) * radius_m
    refusals: list[Refusal] = []
    apart: set[tuple[int, int]] = set()  # joins refused, flights kept apart
    rows_of = list(rows_of)
    while True:
        kept = [
            ev for ev in events
            if (int(rows_of[ev.before][-1]), int(rows_of[ev.after][0])) not in apart
        ]  # fmt: skip
        verdicts = {}
        for ev in kept:
            fa, fb = flights[ev.before], flights[ev.after]
            verdict = judge_join(
                ev.vi_mps, ev.vf_mps, velocity_se(fa), velocity_se(fb),
                omega_i=ev.omega_i_radps, omega_f=ev.omega_f_radps, gyration_m=k_gyr,
                rise_m=ev.z_end_m - ev.z_m, instantaneous=not ev.extended,
            )  # fmt: skip
            if verdict is None:
                verdict = _one_flight_through(track, rows_of, ev, sigma_m, radius_m)
            if verdict is not None:
                verdicts[id(ev)] = verdict
        if not verdicts:
            for ev in kept:
                why = unmeasured_inside(track, rows_of, ev, sigma_m)
                if why is None:
                    why = not_free_beside(ev, flights, misfit_flights, g_reference_mps2)
                if why is not None:
                    verdicts[id(ev)] = ("unreduced", why)
                    break
        if off_floor and not verdicts:
            short = [ev for ev in kept if not ev.extended]
            high = off_the_floor(
                np.array([ev.x_m for ev in short]),
                np.array([ev.z_m for ev in short]),
                radius_m,
            )
            verdicts = {id(short[i]): ("mid_air", why) for i, why in high.items()}
        if not verdicts:
            return rows_of, flights, kept, refusals, misfit_flights
        ev = next(e for e in kept if id(e) in verdicts)
        kind, reason = verdicts[id(ev)]
        a, b = rows_of[ev.before], rows_of[ev.after]
        both = np.concatenate([a, b])
        limit = DRIFT_LIMIT_FRACTION * radius_m
        test = classify_join(
            (track.t[a], track.x[a], track.z[a]), (track.t[b], track.x[b], track.z[b]),
            g_mps2=G, sigma_m=sigma_m, drift_limit_m=limit,
        )  # fmt: skip
        merge = kind == "free_flight" or test.model != "contact"
        if not merge:
            drift = explained_by_drift(
                track.t[both], track.x[both], track.z[both], g_mps2=G,
                sigma_m=sigma_m, drift_limit_m=limit,
            )  # fmt: skip
            merge = drift is not None
        refusals.append(
            Refusal(
                float(track.t[a[-1]]), float(track.t[b[0]]),
                (_frame(track, int(a[-1])), _frame(track, int(b[0]))),
                kind, reason, merged=merge,
            )
        )  # fmt: skip
        if not merge:
            apart.add((int(a[-1]), int(b[0])))
            events = kept
            continue
        rows_of[ev.before] = both
        del rows_of[ev.after]
        misfit_flights = {i if i <= ev.before else i - 1 for i in misfit_flights}
        if test.model == "air_drag":
            misfit_flights.add(ev.before)
        flights = _fit_all(track, rows_of)
        events = find_contact_events(
            track, flights, contact_spans(track, rows_of), frame_interval_s
        )


def _fit_all(track: Track, rows_of: list[np.ndarray]) -> list[FlightFit]:
    slow = noise_floor(track)  # detection error that varies slowly along a flight
    stated = float(track.meta.get("calibration_rel_sd", 0.0))
    return [
        dataclasses.replace(
            fit_flight(
                track.t[r], track.x[r], track.z[r], index=i, rows=r, systematic_m=slow
            ),
            g_calibration_rel_sd=stated,
        )
        for i, r in enumerate(rows_of)
    ]


def noise_floor(track: Track) -> float:
    """Smallest position noise to assume [m]: 0.05 px when the pixel scale is known.

    Sub-pixel detectors reach a few hundredths of a pixel at best, and their errors
    are correlated over several frames; the scale comes from the track's
    ``radius_m / radius_px`` columns (video tracks) or ``meta["metres_per_pixel"]``.
    """
    f = track.frame
    scale = track.meta.get("metres_per_pixel")
    if scale is None and {"radius_m", "radius_px"} <= set(f.columns):
        ratio = (f["radius_m"] / f["radius_px"]).to_numpy(float)
        ratio = ratio[np.isfinite(ratio) & (ratio > 0)]
        scale = float(np.median(ratio)) if len(ratio) else None
    return 0.05 * float(scale) if scale else 0.0


def empty_impact_table() -> ImpactTable:
    """An ImpactTable with the contract columns and no rows."""
    import pandas as pd

    from fieldkit.impact_table import REQUIRED_COLUMNS

    return ImpactTable(pd.DataFrame({c: [] for c in REQUIRED_COLUMNS}))
