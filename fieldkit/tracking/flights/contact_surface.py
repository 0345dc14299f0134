"""The surface at a contact: its dip psi, on the side facing the body.

``slope_deg`` (psi) fixes the local axes of an impact (docs/architecture.md §2,
:mod:`fieldkit.physics.local_axes`): ``N = (sin psi, cos psi)`` is the outward normal,
``T = (cos psi, -sin psi)`` its right-handed partner along the surface. A dip alone
fixes the surface *line*; psi and psi - 180 are the same line with opposite normals.
Here the normal is always the one facing the incoming body (:func:`facing_body`), so
``vin < 0`` and, for a body that leaves the surface, ``vfn > 0``. psi lies in
(-180, 180]: beyond +/-90 deg the body met the surface from below (an overhanging net,
a ceiling). N then faces down toward the body and T, the right-handed partner of N
(which keeps the slip velocity ``v_s = v_T + r omega`` of docs/architecture.md §2
valid), points *up* the surface: a body sliding down an overhang has ``vit < 0`` and
angles to the surface above 90 deg. e_n is unaffected and ``e_t = vft/vit`` does not
depend on the sign of T.

Where psi comes from (:func:`surface_angles`):

* the known ground when given: one angle, or one per contact from a surveyed profile
  or a DEM (:mod:`fieldkit.tracking.flights.ground`); its side is chosen facing the
  body, with a warning when that flips it;
* short impacts, two or more: the least-squares line through the centres at the
  impact instants (one radius off a plane surface, so parallel to it);
* a single short impact: the angular-momentum balance of a rigid sphere about its
  centre (:func:`surface_angle_from_spin`: the friction impulse that changes the
  tangential velocity also changes the spin, ``dv_T = k^2 d_omega / r``); without
  spin 0 deg is assumed, with a warning;
* an extended contact (a net, a rolling phase), :func:`extended_contact_angle`:

  - with spin measured before and after: the same balance over the whole contact,
    gravity impulse removed. On the rendered ``video/net`` clip (an overhanging
    spring-damper net with Coulomb friction) it gives psi = -105.13 deg against the
    true -105.12;
  - without spin, when the centre stays on the chord from contact start to end
    (a rigid surface: rolling, sliding): the chord;
  - without spin on a deforming surface (the centre sags off the chord into a net):
    the surface cannot be identified from the track. The chord leans into a damped
    net (the body leaves while still pressing into it by ``c |d'| / k``; -107.6 deg
    on ``video/net``, 4 to 14 deg off on synthetic captures) and the direction of the
    net impulse leans by the friction (13 deg on ``video/net``); on ``video/net``
    they give e_n = 0.743 and 0.356 against the true 0.664. psi, and so ``vin``,
    ``vfn``, e_n, e_t and the angles, are left NaN with a warning (give
    ``surface_angle_deg`` or film a marker for the spin).

A surface estimated from the data that the body does not leave (``vfn <= 0``) is
likewise left NaN with a warning.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from fieldkit.physics.constants import G
from fieldkit.physics.local_axes import to_local

#: Largest RMS distance of the contact centres from the contact's chord, as a share of
#: the radius, for the surface to count as rigid (a net sags by centimetres).
RIGID_SAG_FRACTION = 0.05


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


def wrap_angle_deg(angle_deg: float) -> float:
    """The same direction as ``angle_deg`` in (-180, 180] [deg].

    Examples
    --------
    >>> wrap_angle_deg(-105.0), wrap_angle_deg(255.0), wrap_angle_deg(-180.0)
    (-105.0, -105.0, 180.0)
    """
    wrapped = 180.0 - (180.0 - angle_deg) % 360.0
    # (-tiny) % 360 rounds to exactly 360.0, which would give -180
    return float(wrapped + 360.0 if wrapped <= -180.0 else wrapped)


def facing_body(psi_deg: float, vi: tuple[float, float]) -> float:
    """``psi`` or ``psi - 180``: the side of the surface line facing the incoming body.

    A dip fixes the surface line only up to its side: ``psi`` and ``psi - 180`` are
    the same line with opposite normals ``N = (sin psi, cos psi)``. The body strikes
    the side it comes from, so the outward normal is the one with ``vi . N < 0``
    (docs/architecture.md §2: ``vin < 0``). |psi| > 90 deg is a surface met from below
    (an overhanging net, a ceiling); ``T = (cos psi, -sin psi)`` is then the
    right-handed partner of N and points up the surface.

    Examples
    --------
    >>> facing_body(75.0, (4.0, -2.7)), facing_body(15.0, (2.0, -3.0))
    (-105.0, 15.0)
    """
    _, vin = to_local(vi[0], vi[1], psi_deg)
    return wrap_angle_deg(psi_deg + 180.0 if vin > 0 else psi_deg)


def surface_angle_from_spin(
    vi: tuple[float, float],
    vf: tuple[float, float],
    omega_i: float,
    omega_f: float,
    radius_m: float,
    gyration_m: float,
    *,
    duration_s: float = 0.0,
) -> float:
    """Dip psi [deg] of the surface at one contact from the angular-momentum balance.

    About its centre the friction impulse ``P_T`` changes both the tangential velocity
    and the spin of a rigid sphere (normal forces pass through the centre):
    ``m dv_T = P_T`` and ``m k^2 d_omega = r P_T`` (thesis ch. 4; sign convention of
    docs/architecture.md §2), so ``dv . T = k^2 d_omega / r`` with
    ``T = (cos psi, -sin psi)``. ``dv`` is the change the surface caused: for a
    contact lasting ``duration_s`` the gravity impulse is removed,
    ``dv = v_f - v_i + g duration z`` (for velocities taken from ballistic fits at the
    contact ends this does not depend on where exactly the ends are put). Of the two
    roots the one whose normal impulse ``dv . N`` is outward (positive) is returned, in
    (-180, 180]: beyond +/-90 deg the surface was met from below (an overhang, see
    :func:`facing_body`).

    Examples
    --------
    >>> psi = surface_angle_from_spin((1.0, -3.0), (1.0, 2.0), 0.0, 0.0, 0.04, 0.025)
    >>> round(psi, 6)
    0.0
    >>> psi = surface_angle_from_spin((3.0, 0.0), (-2.0, 0.0), 0.0, 0.0, 0.04, 0.025)
    >>> round(psi, 6)  # a vertical wall met from the left: N = (-1, 0)
    -90.0
    """
    dvx, dvz = vf[0] - vi[0], vf[1] - vi[1] + G * duration_s
    big = np.hypot(dvx, dvz)
    c = gyration_m**2 * (omega_f - omega_i) / radius_m
    if big <= 0 or not np.isfinite(c) or not np.isfinite(big):
        return float("nan")
    phi = np.arctan2(dvz, dvx)
    psi = np.arccos(np.clip(c / big, -1.0, 1.0)) - phi
    return wrap_angle_deg(float(np.degrees(psi)))


def surface_angles(
    f: pd.DataFrame,
    *,
    radius_m: float,
    gyration_m: float,
    surface_angle_deg: float | np.ndarray | None = None,
    given_source: str = "given",
) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Dip psi [deg] of the surface at every contact, its source, and warnings.

    ``f`` holds one row per contact (travel frame): ``x_m, z_m, x_end_m, z_end_m``,
    ``vi_*``, ``vf_*``, ``omega_i/f_radps``, ``contact_duration_s``, ``extended``.
    ``surface_angle_deg``, when known, is one dip for every contact or one per
    contact (a profile or a DEM, :mod:`fieldkit.tracking.flights.ground`), recorded
    with source ``given_source``. Every angle is then turned to the side facing the
    incoming body (:func:`facing_body`), so ``vin < 0``. An estimated surface the
    body does not leave (``vfn <= 0``) was not identified: its psi is NaN (e_n, e_t
    NaN) with a warning; a known one is kept, with a warning.
    """
    n = len(f)
    slope = np.full(n, np.nan)
    source = np.full(n, "video", dtype=object)
    warnings: list[str] = []
    extended = f["extended"].to_numpy(bool)
    given = surface_angle_deg is not None
    if given:
        slope[:] = surface_angle_deg
        source[:] = given_source
    short = ~extended
    if surface_angle_deg is None and short.sum() >= 2:
        psi, se = surface_angle_from_points(f.loc[short, "x_m"], f.loc[short, "z_m"])
        slope[short] = psi
        note = f" +/- {se:.2f}" if np.isfinite(se) else ""
        warnings.append(
            f"surface angle estimated from {int(short.sum())} contact points: "
            f"{psi:.2f}{note} deg (give `surface_angle_deg` to override)"
        )
    elif surface_angle_deg is None and short.sum() == 1:
        i = int(np.flatnonzero(short)[0])
        r = f.iloc[i]
        psi = surface_angle_from_spin(
            (r.vi_x_mps, r.vi_z_mps),
            (r.vf_x_mps, r.vf_z_mps),
            r.omega_i_radps,
            r.omega_f_radps,
            radius_m,
            gyration_m,
        )
        if np.isfinite(psi):
            slope[i] = psi
            warnings.append(
                f"surface angle {psi:.2f} deg estimated from the single impact's "
                "velocity and spin change (angular-momentum balance, "
                f"k = {gyration_m:.4g} m); give `surface_angle_deg` if the surface is "
                "known"
            )
        else:
            slope[i] = 0.0
            source[i] = "assumed"
            warnings.append(
                "no surface angle from a single impact without spin: "
                "0 deg assumed; give `surface_angle_deg`"
            )
    if surface_angle_deg is None:
        for i in np.flatnonzero(extended):
            slope[i], note = extended_contact_angle(f.iloc[i], radius_m, gyration_m)
            warnings.append(f"point {i + 1} (net contact): {note}")
            if not np.isfinite(slope[i]):
                source[i] = None
    for i in range(n):
        r = f.iloc[i]
        vi, vf = (r.vi_x_mps, r.vi_z_mps), (r.vf_x_mps, r.vf_z_mps)
        if not np.isfinite(slope[i]):
            continue
        turned = facing_body(slope[i], vi)
        if given and turned != wrap_angle_deg(slope[i]):
            warnings.append(
                f"contact {i + 1}: the body meets the given surface from below; "
                f"psi = {turned:.2f} deg (the same line, normal facing the body)"
            )
        slope[i] = turned
        _, vin = to_local(*vi, turned)
        _, vfn = to_local(*vf, turned)
        if vfn > 0 and vin < 0:
            continue
        what = (
            f"vin = {float(vin):.3f}, vfn = {float(vfn):.3f} m/s on psi = {turned:.2f}"
        )
        if given:
            warnings.append(
                f"contact {i + 1}: the body does not leave the given surface ({what})"
            )
        else:
            slope[i], source[i] = np.nan, None
            warnings.append(
                f"contact {i + 1} at t = {r.t_s:.4f} s: the contact surface cannot be "
                f"identified ({what}): e_n, e_t left NaN; give `surface_angle_deg`"
            )
    return slope, source, warnings


def extended_contact_angle(
    row: pd.Series, radius_m: float, gyration_m: float
) -> tuple[float, str]:
    """Dip psi [deg] of the surface of one extended contact (NaN if unknown), and how.

    ``row`` holds the contact's centre at start and end (``x_m, z_m, x_end_m,
    z_end_m``), velocities, spins, ``contact_duration_s`` and ``sag_rms_m`` (RMS
    distance of the centres in contact from the chord start -> end). In order: the
    angular-momentum balance over the contact when the spin before and after is
    known (:func:`surface_angle_from_spin`, gravity impulse removed); the chord when
    the centre stayed on it (``sag_rms_m <= RIGID_SAG_FRACTION r``: a rigid surface);
    otherwise NaN (see the module docstring for why neither the chord nor the impulse
    direction identifies a net).
    """
    vi, vf = (row.vi_x_mps, row.vi_z_mps), (row.vf_x_mps, row.vf_z_mps)
    chord = -np.degrees(np.arctan2(row.z_end_m - row.z_m, row.x_end_m - row.x_m))
    chord = facing_body(float(chord), vi)
    psi = surface_angle_from_spin(
        vi,
        vf,
        row.omega_i_radps,
        row.omega_f_radps,
        radius_m,
        gyration_m,
        duration_s=row.contact_duration_s,
    )
    sag = float(row.get("sag_rms_m", np.nan))
    if np.isfinite(psi):
        return psi, (
            f"surface angle {psi:.2f} deg from the velocity and spin change over the "
            f"contact (angular-momentum balance; chord of the contact {chord:.2f} deg)"
        )
    if sag <= RIGID_SAG_FRACTION * radius_m:
        return chord, (
            f"surface angle {chord:.2f} deg from the chord of the contact (the centre "
            f"stays within {sag * 1e3:.2f} mm RMS of it: a rigid surface)"
        )
    return float("nan"), (
        f"the contact surface cannot be identified without spin: the centre sags "
        f"{sag * 1e3:.1f} mm RMS off the chord ({chord:.2f} deg) into a deforming "
        "surface, whose chord and impulse direction are biased by its damping and "
        "friction; e_n, e_t left NaN (give `surface_angle_deg`, or film a marker)"
    )
