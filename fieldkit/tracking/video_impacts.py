"""Impacts from fitted flights: velocities at the contact, surface angle, spin, table.

For each contact between two fitted flights (:mod:`fieldkit.tracking.contacts`):

* **Contact time.** A short contact (fewer than ``EXTENDED_CONTACT_SAMPLES`` measured
  samples off both parabolas) is treated as instantaneous: the impact instant is where
  the two fixed-g parabolas come closest (both share ``g``, so their separation is
  linear in time and the instant has a closed form), searched near the gap. An
  extended contact (a net, a rolling phase) starts and ends where the deviation from
  the adjacent parabola sets in (:func:`fieldkit.tracking.net_contact.contact_onset`:
  an onset power law fitted to the deviations, not the first sample beyond noise).
* **Velocities.** Impact velocity from the flight before, restitution velocity from the
  flight after, both evaluated at the contact time(s) (fixed-g fits).
* **Surface angle** ``slope_deg`` (psi, positive descending in the direction of
  travel, ARCHITECTURE §2): the given ``surface_angle_deg`` if any; otherwise

  - two or more impacts: the least-squares line through the centres at the impact
    instants (the centres lie one radius off a plane surface, so the line is parallel
    to it);
  - a single impact: from the angular-momentum balance of a rigid body about the
    contact point. The friction impulse that changes the tangential velocity also
    changes the spin: ``dv_T = k^2 d_omega / r``. With the measured velocity change
    and spin change this fixes the direction of T (the root with an outward normal
    impulse). It needs spin before and after (a marker), the radius and the radius of
    gyration (a solid sphere, ``k = sqrt(2/5) r``, when not given);
  - a single impact without spin: 0° (horizontal) is assumed, with a warning;
  - an extended contact: the chord from the centre at contact start to the centre at
    contact end (the body follows the surface while in contact).
* **Spin** before and after: slope of a straight line through the unwrapped marker
  angle over the whole adjacent flight (spin is constant in free flight), else the
  median of the track's ``omega_radps`` there, else NaN.

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
from fieldkit.tracking.contacts import EXTENDED_CONTACT_SAMPLES, ContactSpan
from fieldkit.tracking.flight_fit import FlightFit
from fieldkit.tracking.net_contact import contact_onset
from fieldkit.tracking.track import Track

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
            )
        )
    return events


def travel_direction(flights: list[FlightFit]) -> float:
    """+1 when the body travels toward +x overall, -1 toward -x."""
    total = sum(f.vx_mps * f.n_samples for f in flights)
    return -1.0 if total < 0 else 1.0


def surface_angle_from_points(x_m: np.ndarray, z_m: np.ndarray) -> tuple[float, float]:
    """Dip psi [deg] of the least-squares line through contact centres, and its SE.

    Examples
    --------
    >>> x = np.array([0.0, 1.0, 2.0])
    >>> round(surface_angle_from_points(x, -np.tan(np.radians(10.0)) * x)[0], 6)
    10.0
    """
    x = np.asarray(x_m, float)
    z = np.asarray(z_m, float)
    coef, cov = (
        np.polyfit(x, z, 1, cov=True) if len(x) > 3 else (np.polyfit(x, z, 1), None)
    )
    slope = coef[0]
    psi = -np.degrees(np.arctan(slope))
    se = float("nan")
    if cov is not None:
        se = float(np.degrees(np.sqrt(max(cov[0, 0], 0.0)) / (1.0 + slope**2)))
    return float(psi), se


def surface_angle_from_spin(
    vi: tuple[float, float],
    vf: tuple[float, float],
    omega_i: float,
    omega_f: float,
    radius_m: float,
    gyration_m: float,
) -> float:
    """Dip psi [deg] of the surface at one impact from the angular-momentum balance.

    About the contact point the friction impulse ``P_T`` changes both the tangential
    velocity and the spin of a rigid body: ``m dv_T = P_T`` and
    ``m k^2 d_omega = r P_T``
    (thesis ch. 4; sign convention of ARCHITECTURE §2), so ``dv . T = k^2 d_omega / r``
    with ``T = (cos psi, -sin psi)``. Of the two roots the one whose normal impulse
    ``dv . N`` is outward (positive) is returned.

    Examples
    --------
    >>> psi = surface_angle_from_spin((1.0, -3.0), (1.0, 2.0), 0.0, 0.0, 0.04, 0.025)
    >>> round(psi, 6)
    0.0
    """
    dvx, dvz = vf[0] - vi[0], vf[1] - vi[1]
    big = np.hypot(dvx, dvz)
    c = gyration_m**2 * (omega_f - omega_i) / radius_m
    if big <= 0 or not np.isfinite(c):
        return float("nan")
    phi = np.arctan2(dvz, dvx)
    psi = np.arccos(np.clip(c / big, -1.0, 1.0)) - phi
    psi = (psi + np.pi / 2) % np.pi - np.pi / 2  # into [-90, 90)
    return float(np.degrees(psi))


def build_impact_table(
    events: list[ContactEvent],
    flights: list[FlightFit],
    *,
    radius_m: float,
    surface_angle_deg: float | None = None,
    mass_kg: float | None = None,
    gyration_m: float | None = None,
    path_id: str = "video",
) -> tuple[ImpactTable | None, list[str]]:
    """The ImpactTable of the contact events, and warnings.

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
            )
        )
    f = pd.DataFrame(rows)
    slope = np.full(len(f), np.nan)
    source = np.full(len(f), "video", dtype=object)
    if surface_angle_deg is not None:
        slope[:] = surface_angle_deg
        source[:] = "given"
    else:
        short = ~f["extended"].to_numpy(bool)
        if short.sum() >= 2:
            psi, se = surface_angle_from_points(
                f.loc[short, "x_m"], f.loc[short, "z_m"]
            )
            slope[short] = psi
            note = f" +/- {se:.2f}" if np.isfinite(se) else ""
            warnings.append(
                f"surface angle estimated from {int(short.sum())} contact points: "
                f"{psi:.2f}{note} deg (give --surface-angle to override)"
            )
        elif short.sum() == 1:
            i = int(np.flatnonzero(short)[0])
            r = f.iloc[i]
            psi = surface_angle_from_spin(
                (r.vi_x_mps, r.vi_z_mps),
                (r.vf_x_mps, r.vf_z_mps),
                r.omega_i_radps,
                r.omega_f_radps,
                radius_m,
                k,
            )
            if np.isfinite(psi):
                slope[i] = psi
                warnings.append(
                    f"surface angle {psi:.2f} deg estimated from the single impact's "
                    "velocity and spin change (angular-momentum balance, "
                    f"k = {k:.4g} m); give --surface-angle if the surface is known"
                )
            else:
                slope[i] = 0.0
                source[i] = "assumed"
                warnings.append(
                    "no surface angle from a single impact without spin: "
                    "0 deg assumed; give --surface-angle"
                )
        for i in np.flatnonzero(~short):
            r = f.iloc[i]
            slope[i] = -np.degrees(np.arctan2(r.z_end_m - r.z_m, r.x_end_m - r.x_m))
    f["slope_deg"] = slope
    f["slope_source"] = source
    f.insert(0, "path_id", path_id)
    f.insert(1, "point", [str(i + 1) for i in range(len(f))])
    f["radius_m"] = radius_m
    f["gyration_m"] = gyration_m if gyration_m is not None else np.nan
    f["mass_kg"] = mass_kg if mass_kg is not None else np.nan
    has_spin = np.isfinite(f["omega_i_radps"]) & np.isfinite(f["omega_f_radps"])
    f["omega_source"] = np.where(has_spin, "measured", "none")
    _flight_geometry(f)
    f = f.drop(columns=["x_end_m", "z_end_m", "extended"])
    table = ImpactTable(f, source=path_id).derive()
    table.frame["theta0_deg"] = table.frame["theta_f_deg"]
    table.frame["theta0_source"] = pd.array(["video"] * len(f), dtype="string")
    return table, warnings


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
