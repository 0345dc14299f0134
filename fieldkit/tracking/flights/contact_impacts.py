"""Impacts from fitted flights: velocities at the contact, surface angle, spin, table.

For each contact between two fitted flights
(:mod:`fieldkit.tracking.flights.segmentation`):

* **Contact time.** A short contact (fewer than ``EXTENDED_CONTACT_SAMPLES`` measured
  samples off both parabolas, or paths that cross within one frame interval
  whatever the samples between show: :func:`sub_frame`) is treated as
  instantaneous: the impact instant is where
  the two fixed-g parabolas come closest (both share ``g``, so their separation is
  linear in time and the instant has a closed form), searched near the gap. An
  extended contact (a net, a rolling phase) starts and ends where the deviation from
  the adjacent parabola sets in
  (:func:`fieldkit.tracking.flights.net_contacts.contact_onset`: an onset power law
  fitted to the deviations, not the first sample beyond noise).
* **Velocities.** Impact velocity from the flight before, restitution velocity from the
  flight after, both evaluated at the contact time(s) (fixed-g fits).
* **Surface angle** ``slope_deg`` (psi, docs/architecture.md §2), always on the side
  facing the incoming body so that ``vin < 0``: from the known ground (one angle, or
  per contact from a profile or a DEM: :mod:`fieldkit.tracking.flights.ground`), or
  estimated from the contact
  points, the spin balance or the contact's chord; left NaN (e_n, e_t NaN, with a
  warning) when the data cannot identify it (a net without spin). Details and measured
  accuracy in :mod:`fieldkit.tracking.flights.contact_surface`.
* **Spin** before and after: slope of a straight line through the unwrapped marker
  angle over the whole adjacent flight (spin is constant in free flight), else the
  median of the track's ``omega_radps`` there, else NaN.
* **Uncertainty.** ``e_n_sd``, ``e_t_sd``, ``vi_sd_mps`` and the other ``*_sd``
  columns: the fits' covariance propagated to first order
  (:mod:`fieldkit.tracking.flights.impact_uncertainty`).

Travel toward -x: the table is built in the mirrored frame (``x -> -x``,
``vx -> -vx``, ``omega -> -omega``) so that x increases along travel as the
ImpactTable contract requires; a warning says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from fieldkit.impact_table import ImpactTable
from fieldkit.physics.constants import G
from fieldkit.track import Track
from fieldkit.tracking.flights.ballistic_fit import FlightFit
from fieldkit.tracking.flights.contact_physics import join_duration
from fieldkit.tracking.flights.contact_surface import surface_angles
from fieldkit.tracking.flights.ground import Ground
from fieldkit.tracking.flights.impact_uncertainty import contact_sds
from fieldkit.tracking.flights.net_contacts import contact_onset
from fieldkit.tracking.flights.segmentation import EXTENDED_CONTACT_SAMPLES, ContactSpan

#: Frames beyond the gap searched for the closest approach of the two parabolas (the
#: samples next to a soft impact fit either parabola within the noise).
SEARCH_FRAMES = 4


@dataclass
class ContactEvent:
    """One contact between flights ``before`` and ``after`` in the track's own frame."""

    before: int
    after: int
    extended: bool
    t_impact_s: float
    t_restitution_s: float
    x_m: float
    z_m: float
    x_end_m: float
    z_end_m: float
    vi_mps: tuple[float, float]
    vf_mps: tuple[float, float]
    omega_i_radps: float
    omega_f_radps: float
    rows: np.ndarray
    sag_rms_m: float = float("nan")

    @property
    def duration_s(self) -> float:
        return self.t_restitution_s - self.t_impact_s


def contact_instant(
    before: FlightFit, after: FlightFit, span: ContactSpan, dt: float
) -> float:
    """Time where the two fitted parabolas are closest, near the gap [s].

    Both fits share the fixed ``g``, so ``p_after(t) - p_before(t)`` is linear in t and
    the closest approach is ``t* = -d0.dv / |dv|^2``, clipped to the gap widened by
    ``SEARCH_FRAMES`` frame intervals on each side.
    """
    lo = span.t_last_before_s - SEARCH_FRAMES * dt
    hi = span.t_first_after_s + SEARCH_FRAMES * dt
    t0 = 0.5 * (lo + hi)
    xa, za = before.position(t0)
    xb, zb = after.position(t0)
    va, vb = before.velocity(t0), after.velocity(t0)
    d0 = np.array([xb - xa, zb - za], float)
    dv = np.array([vb[0] - va[0], vb[1] - va[1]], float)
    if dv @ dv < 1e-18:
        return t0
    return float(np.clip(t0 - (d0 @ dv) / (dv @ dv), lo, hi))


def sub_frame(
    track: Track, before: FlightFit, after: FlightFit, span: ContactSpan, dt: float
) -> bool:
    """True when the samples off both flights are an impact seen through blurred or
    mis-detected frames, not an extended contact.

    Two conditions: the two flights' paths cross within one frame interval of each
    other in time, inside the span (where the paths cross,
    :func:`~.contact_physics.join_duration`, the incoming flight passes the
    crossing at ``t1`` and the outgoing one at ``t2``); and the samples of the span
    lie on the impact's path -- the flight before until the crossing, the flight
    after from it -- within the distance the body travels in one frame (what blur
    or a mis-detection can shift a centre by; median over the span) plus three
    times the flights' residual RMS. A net holds the body back from both flights by
    decimetres: its samples are off that path, although a contact force along one
    normal leaves crossing paths with ``t1 = t2``.
    """
    if not np.isfinite(dt) or dt <= 0 or len(span.rows) == 0:
        return False
    guess = contact_instant(before, after, span, dt)
    t1, t2, miss = join_duration(before, after, guess)
    if not (np.isfinite(t1) and np.isfinite(t2)):
        return False
    lo, hi = span.t_last_before_s - dt, span.t_first_after_s + dt
    rms = 3.0 * max(before.rms_m, after.rms_m)
    if not (lo <= t1 <= hi and lo <= t2 <= hi and abs(t2 - t1) < dt and miss <= rms):
        return False
    t = track.t[span.rows]
    crossing = 0.5 * (t1 + t2)
    xa, za = before.position(t)
    xb, zb = after.position(t)
    px, pz = np.where(t < crossing, xa, xb), np.where(t < crossing, za, zb)
    off = np.hypot(track.x[span.rows] - px, track.z[span.rows] - pz)
    off = off[np.isfinite(off)]
    travel = dt * max(float(before.speed(t1)), float(after.speed(t2)))
    return bool(len(off) and np.median(off) <= travel + rms)


def flight_spin(track: Track, rows: np.ndarray) -> float:
    """Spin over a flight [rad/s]: line fit to the marker angle, else median omega."""
    t = track.t[rows]
    angle = track.frame["angle_rad"].to_numpy(float)[rows]
    ok = np.isfinite(angle) & np.isfinite(t)
    if ok.sum() >= 3 and np.ptp(t[ok]) > 0:
        return float(np.polyfit(t[ok], angle[ok], 1)[0])
    omega = track.frame["omega_radps"].to_numpy(float)[rows]
    omega = omega[np.isfinite(omega)]
    return float(np.median(omega)) if len(omega) else float("nan")


def find_contact_events(
    track: Track,
    flights: list[FlightFit],
    spans: list[ContactSpan],
    frame_interval_s: float,
) -> list[ContactEvent]:
    """Impact and restitution state at every contact between consecutive flights."""
    events = []
    spins = [flight_spin(track, f.rows) for f in flights]
    for span in spans:
        fa, fb = flights[span.before], flights[span.after]
        extended = len(span.rows) >= EXTENDED_CONTACT_SAMPLES
        if extended and sub_frame(track, fa, fb, span, frame_interval_s):
            extended = False  # the flights meet within a frame: an impact
        if extended:
            ti = contact_onset(track, fa, span.rows, forward=True)
            tf = contact_onset(track, fb, span.rows, forward=False)
            if not ti < tf:
                ti, tf = span.t_last_before_s, span.t_first_after_s
        else:
            ti = tf = contact_instant(fa, fb, span, frame_interval_s)
        xa, za = fa.position(ti)
        xb, zb = fb.position(tf)
        if extended:
            x_i, z_i, x_f, z_f = float(xa), float(za), float(xb), float(zb)
        else:
            x_i = x_f = 0.5 * float(xa + xb)
            z_i = z_f = 0.5 * float(za + zb)
        vi = tuple(float(v) for v in fa.velocity(ti))
        vf = tuple(float(v) for v in fb.velocity(tf))
        sag = float("nan")
        if extended:
            sag = chord_sag(track, span.rows, (x_i, z_i), (x_f, z_f), (ti, tf))
        events.append(
            ContactEvent(
                span.before,
                span.after,
                extended,
                float(ti),
                float(tf),
                x_i,
                z_i,
                x_f,
                z_f,
                vi,
                vf,
                spins[span.before],
                spins[span.after],
                span.rows,
                sag,
            )
        )
    return events


def chord_sag(
    track: Track,
    rows: np.ndarray,
    start: tuple[float, float],
    end: tuple[float, float],
    times: tuple[float, float],
) -> float:
    """RMS distance [m] of the centres in contact from the chord start -> end.

    A body rolling or sliding on a rigid plane keeps its centre on the chord (within
    the noise); in a net it sags into the net by centimetres. NaN without samples.
    """
    rows = np.asarray(rows, int)
    t = track.t[rows]
    inside = (t > times[0]) & (t < times[1])
    dx, dz = end[0] - start[0], end[1] - start[1]
    length = np.hypot(dx, dz)
    if not inside.any() or length == 0:
        return float("nan")
    px = track.x[rows][inside] - start[0]
    pz = track.z[rows][inside] - start[1]
    off = (px * dz - pz * dx) / length
    off = off[np.isfinite(off)]
    return float(np.sqrt(np.mean(off**2))) if len(off) else float("nan")


def travel_direction(flights: list[FlightFit]) -> float:
    """+1 when the body travels toward +x overall, -1 toward -x."""
    total = sum(f.vx_mps * f.n_samples for f in flights)
    return -1.0 if total < 0 else 1.0


def build_impact_table(
    events: list[ContactEvent],
    flights: list[FlightFit],
    *,
    radius_m: float,
    ground: Ground | None = None,
    mass_kg: float | None = None,
    gyration_m: float | None = None,
    path_id: str = "video",
) -> tuple[ImpactTable | None, list[str]]:
    """The ImpactTable of the contact events, and warnings.

    ``ground`` (:mod:`fieldkit.tracking.flights.ground`) gives the dip at each
    contact, queried at the contact centre in the track's frame; without it the dip
    is estimated (:func:`fieldkit.tracking.flights.contact_surface.surface_angles`).
    Returns ``(None, warnings)`` when there is no contact.
    """
    warnings: list[str] = []
    if not events:
        return None, warnings
    sx = travel_direction(flights)
    if sx < 0:
        warnings.append(
            "the body travels toward -x: the impact table uses x mirrored (x -> -x, "
            "omega -> -omega) so that x increases along travel"
        )
    k = gyration_m if gyration_m is not None else np.sqrt(0.4) * radius_m
    rows = []
    for ev in events:
        rows.append(
            dict(
                x_m=sx * ev.x_m,
                z_m=ev.z_m,
                x_end_m=sx * ev.x_end_m,
                z_end_m=ev.z_end_m,
                vi_x_mps=sx * ev.vi_mps[0],
                vi_z_mps=ev.vi_mps[1],
                vf_x_mps=sx * ev.vf_mps[0],
                vf_z_mps=ev.vf_mps[1],
                omega_i_radps=sx * ev.omega_i_radps,
                omega_f_radps=sx * ev.omega_f_radps,
                t_s=ev.t_impact_s,
                contact_duration_s=ev.duration_s,
                extended=ev.extended,
                sag_rms_m=ev.sag_rms_m,
            )
        )
    f = pd.DataFrame(rows)
    known = None
    if ground is not None:
        known = ground.dip_deg(
            np.array([ev.x_m for ev in events]), np.array([ev.z_m for ev in events]), sx
        )
    slope, source, slope_warnings = surface_angles(
        f,
        radius_m=radius_m,
        gyration_m=k,
        surface_angle_deg=known,
        given_source=ground.source if ground is not None else "given",
    )
    warnings.extend(slope_warnings)
    f["slope_deg"] = slope
    f["slope_source"] = pd.array(source, dtype="string")
    f.insert(0, "path_id", path_id)
    f.insert(1, "point", [str(i + 1) for i in range(len(f))])
    f["radius_m"] = radius_m
    f["gyration_m"] = gyration_m if gyration_m is not None else np.nan
    f["mass_kg"] = mass_kg if mass_kg is not None else np.nan
    has_spin = np.isfinite(f["omega_i_radps"]) & np.isfinite(f["omega_f_radps"])
    f["omega_source"] = np.where(has_spin, "measured", "none")
    _flight_geometry(f)
    pairs = [
        (
            flights[ev.before],
            flights[ev.after],
            (ev.t_impact_s, ev.t_restitution_s),
            not ev.extended,
        )
        for ev in events
    ]
    for column, values in contact_sds(pairs, slope, sx).items():
        f[column] = values
    extended = f["extended"].to_numpy(bool)
    internal = ["x_end_m", "z_end_m", "extended", "sag_rms_m"]
    table = ImpactTable(f.drop(columns=internal), source=path_id).derive()
    gap = np.full(len(events), np.nan)
    if ground is not None and hasattr(ground, "distance_m"):  # a profile, a DEM
        gap = np.array([ground.distance_m(ev.x_m, ev.z_m) for ev in events]) - radius_m
    refused = refused_impacts(table.frame, extended, radius_m=radius_m, gap_m=gap)
    if refused:
        for i, reason in refused.items():
            row = table.frame.iloc[i]
            warnings.append(
                f"contact at t = {float(row['t_s']):.4f} s refused as an impact: "
                f"{reason}"
            )
        keep = np.setdiff1d(np.arange(len(f)), list(refused))
        if keep.size == 0:
            return None, warnings
        f = f.iloc[keep].reset_index(drop=True)
        f["point"] = [str(i + 1) for i in range(len(f))]
        _flight_geometry(f)  # the flight to the next kept impact
        table = ImpactTable(f.drop(columns=internal), source=path_id).derive()
    table.frame["theta0_deg"] = table.frame["theta_f_deg"]
    table.frame["theta0_source"] = pd.array(["video"] * len(f), dtype="string")
    return table, warnings


#: How far a contact's centre may lie beyond one radius from a known ground (a
#: profile, a DEM), as a share of the radius (the threshold of `fieldkit track`'s
#: warning about a ground off the track's frame).
SURFACE_TOLERANCE_FRACTION = 1.0


def refused_impacts(
    f: pd.DataFrame,
    extended: np.ndarray,
    *,
    radius_m: float,
    gap_m: np.ndarray | None = None,
) -> dict[int, str]:
    """Rows of a derived impact table that cannot be impacts, with the reason.

    Only instantaneous impacts are judged (an extended contact may overhang: a net).
    Refused are an impact on a surface turned past vertical to face the body (the
    body would have struck the ground from below), one with ``e_n < 0`` (the body
    does not leave the surface it struck), and, on a ground whose position is known
    (a profile, a DEM: ``gap_m``, the centre's distance from it less one radius),
    one whose centre lies more than ``SURFACE_TOLERANCE_FRACTION r`` beyond contact
    while another contact touches it: a contact needs the ground. (When no contact
    touches the ground it is rather off the track's frame, which `fieldkit track`
    warns about; one angle, ``--surface-angle``, fixes the dip but not where the
    ground is, so it refuses no contact by height.)
    """
    out = {}
    short = ~np.asarray(extended, bool)
    psi_all = f["slope_deg"].to_numpy(float)
    tolerance = SURFACE_TOLERANCE_FRACTION * radius_m
    gap = np.full(len(f), np.nan) if gap_m is None else np.asarray(gap_m, float)
    touching = short & np.isfinite(gap) & (np.abs(gap) <= tolerance)
    for i in range(len(f)):
        if not short[i]:
            continue
        psi, e_n = float(psi_all[i]), float(f["e_n"].iloc[i])
        if np.isfinite(psi) and abs(psi) > 90.0:
            out[i] = (
                f"the surface would face the body from below (slope_deg {psi:.1f}, "
                "past vertical): the body cannot strike the ground from underneath"
            )
        elif np.isfinite(e_n) and e_n < 0:
            out[i] = (
                f"e_n = {e_n:.3f} < 0 (the body does not leave the surface it struck)"
            )
        elif touching.any() and np.isfinite(gap[i]) and gap[i] > tolerance:
            out[i] = (
                f"the centre is {gap[i] * 1e3:.1f} mm beyond contact with the known "
                f"ground ({f['slope_source'].iloc[i]}), more than the tolerance of "
                f"{tolerance * 1e3:.1f} mm ({SURFACE_TOLERANCE_FRACTION:g} radius) "
                "while other contacts touch it: the body is in mid-air"
            )
    return out


def _flight_geometry(f: pd.DataFrame) -> None:
    """Time, length and heights of the flight leaving each impact (to the next)."""
    n = len(f)
    for col in ("flight_time_s", "flight_length_m", "hmax_vertical_m", "hmax_normal_m"):
        f[col] = np.nan
    for i in range(n - 1):
        t0 = f.loc[i, "t_s"] + f.loc[i, "contact_duration_s"]
        dt = f.loc[i + 1, "t_s"] - t0
        dx = f.loc[i + 1, "x_m"] - f.loc[i, "x_end_m"]
        dz = f.loc[i + 1, "z_m"] - f.loc[i, "z_end_m"]
        h = G * dt**2 / 8.0  # a parabola rises g T^2 / 8 above its chord (vertically)
        f.loc[
            i, ["flight_time_s", "flight_length_m", "hmax_vertical_m", "hmax_normal_m"]
        ] = (
            dt,
            abs(dx),
            h,
            h * np.cos(np.arctan2(dz, dx)),
        )
