"""Is a join between two fitted flights physically a contact?

The segmentation (:mod:`fieldkit.tracking.flights.segmentation`) splits a track
wherever one free flight stops explaining the samples. On real clips a detection
error that drifts (a dark ball's centre on a changing background, blur) can split a
contact-free fall, and the "contacts" it leaves gain energy or sit at the apex. Each
join is therefore judged by the physics of a contact before it is reported:

* **an impulse.** The velocity change ``dv = v_f - v_i`` between the two fitted
  flights must exceed its standard error (the two fits' velocity errors in
  quadrature, inflated for residuals correlated frame to frame); otherwise nothing
  acted on the body there.
* **no energy gained.** A contact takes energy (a rigid or deformable surface, a
  net). The change of mechanical energy per unit mass, ``(|v_f|^2 - |v_i|^2) / 2``
  plus ``g`` times the rise over an extended contact, must not be positive by more
  than :data:`ENERGY_GAIN_SIGMAS` of its standard error (first-order propagation of
  the velocity errors). When the spin is measured on both sides the smaller of
  that and the change with the spin's energy ``k^2 (w_f^2 - w_i^2) / 2`` counts
  (spin feeds the translation in a topspin bounce).
* **not an apex.** A surface below pushes the body up: an instantaneous join where
  the body rises (or is level, within :data:`APEX_SIGMAS` errors) before and falls
  (or is level) after, with no reversal of the horizontal velocity (a wall), is
  the top of one flight.

A join that fails is a :class:`Refusal` with its frames and a one-line reason. The
pipeline joins the two flights into one when one free flight explains them
(:func:`fieldkit.tracking.flights.free_flight.classify_join`, with a slow detection
drift allowed) and otherwise keeps them apart with no contact between them.

:func:`join_duration` estimates how long a contact lasted from the two flights
alone: where their paths cross, the incoming flight passes the crossing point at
``t1`` and the outgoing one at ``t2``; an impact shorter than a frame has
``|t2 - t1| <`` one frame interval, a net holds the body for many.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fieldkit.physics.constants import G
from fieldkit.tracking.flights.ballistic_fit import FlightFit

#: Standard errors of the velocity change below which a join has no impulse.
IMPULSE_SIGMAS = 3.0
#: Standard errors by which a contact may appear to gain kinetic energy.
ENERGY_GAIN_SIGMAS = 3.0
#: Standard errors within which a vertical velocity counts as level at an apex.
APEX_SIGMAS = 3.0


@dataclass(frozen=True)
class Refusal:
    """An event between two flights that is not reported as a contact, and why.

    Attributes
    ----------
    t_start_s, t_end_s
        Time span of the event: the last sample of the flight before and the first
        of the flight after [s].
    frames
        Frame numbers of those two samples (the track's ``frame`` column, else the
        sample positions).
    kind
        ``no_impulse``, ``energy_gain``, ``apex``, ``mid_air``, ``surface`` or
        ``unreduced``.
    reason
        One line saying why, with the numbers.
    merged
        True when the two flights were joined into one flight.
    """

    t_start_s: float
    t_end_s: float
    frames: tuple[int, int]
    kind: str
    reason: str
    merged: bool = False

    def message(self) -> str:
        """``event at t = 0.0630-0.0680 s (frames 63-68) refused as a contact
        (apex): ...``."""
        what = "; the flights on either side are one flight" if self.merged else ""
        return (
            f"event at t = {self.t_start_s:.4f}-{self.t_end_s:.4f} s (frames "
            f"{self.frames[0]}-{self.frames[1]}) refused as a contact ({self.kind}): "
            f"{self.reason}{what}"
        )


def velocity_se(fit: FlightFit) -> float:
    """Standard error of one velocity component of a flight [m/s]: the fit's least
    squares value times the AR(1) factor of its residuals (errors correlated from
    frame to frame)."""
    rho = fit.residual_rho if np.isfinite(fit.residual_rho) else 0.0
    rho = min(max(rho, 0.0), 0.95)
    return float(fit.vx_se_mps) * math.sqrt((1.0 + rho) / (1.0 - rho))


def judge_join(
    vi: tuple[float, float],
    vf: tuple[float, float],
    se_i: float,
    se_f: float,
    *,
    omega_i: float = float("nan"),
    omega_f: float = float("nan"),
    gyration_m: float | None = None,
    rise_m: float = 0.0,
    instantaneous: bool = True,
) -> tuple[str, str] | None:
    """``(kind, reason)`` when the join with velocities ``vi`` -> ``vf`` is not a
    contact, else None.

    Parameters
    ----------
    vi, vf
        Velocity ``(vx, vz)`` [m/s] of the flight before and after, at the join.
    se_i, se_f
        Standard error of one velocity component of each [m/s].
    omega_i, omega_f, gyration_m
        Spin before and after [rad/s] and radius of gyration [m]: the rotational
        energy counts when all three are known.
    rise_m
        Height the centre gains from the start to the end of the contact [m] (0 for
        an impact; an extended contact's potential energy counts).
    instantaneous
        False for an extended contact (a net): it is not judged as an apex.

    Examples
    --------
    >>> judge_join((1.0, -3.0), (0.9, 2.2), 0.01, 0.01) is None
    True
    >>> judge_join((1.0, 0.01), (1.0, -0.01), 0.01, 0.01)[0]
    'no_impulse'
    >>> judge_join((1.0, -1.0), (1.0, 1.5), 0.01, 0.01)[0]
    'energy_gain'
    """
    vi_a, vf_a = np.asarray(vi, float), np.asarray(vf, float)
    dv = vf_a - vi_a
    se_dv = math.hypot(se_i, se_f)
    size = float(np.hypot(*dv))
    if not size > IMPULSE_SIGMAS * se_dv * math.sqrt(2.0):
        return (
            "no_impulse",
            f"the velocity changes by {size:.3g} m/s, within {IMPULSE_SIGMAS:g} "
            f"standard errors ({se_dv:.2g} m/s per component) of none: nothing "
            "struck the body",
        )
    # rising (or level) before, falling (or level) after, the horizontal motion not
    # reversed: the top of a flight, not a push from a surface below
    zi, zf = vi_a[1], vf_a[1]
    rising_then_falling = zi >= -APEX_SIGMAS * se_i and zf <= APEX_SIGMAS * se_f
    wall = vi_a[0] * vf_a[0] < 0 and abs(vi_a[0]) > APEX_SIGMAS * se_i
    if instantaneous and rising_then_falling and not wall:
        return (
            "apex",
            f"vertical velocity {zi:+.3f} m/s before and {zf:+.3f} m/s after "
            f"(+/- {max(se_i, se_f):.2g}): the body is at the top of its flight, "
            "no surface below pushed it",
        )
    gain = 0.5 * float(vf_a @ vf_a - vi_a @ vi_a) + G * rise_m
    var = float(vf_a @ vf_a) * se_f**2 + float(vi_a @ vi_a) * se_i**2
    spin = ""
    if gyration_m and np.isfinite(omega_i) and np.isfinite(omega_f):
        # spin can feed the translation (a topspin bounce) and a measured spin
        # may be off: refused only when the energy rises with and without it
        with_spin = gain + 0.5 * gyration_m**2 * (omega_f**2 - omega_i**2)
        if with_spin < gain:
            gain, spin = with_spin, " (with the spin's energy)"
    se_gain = math.sqrt(var)
    if gain > ENERGY_GAIN_SIGMAS * se_gain:
        before = 0.5 * float(vi_a @ vi_a)
        share = f", {100 * gain / before:+.0f} %" if before > 0 else ""
        return (
            "energy_gain",
            f"the mechanical energy per unit mass{spin} rises by {gain:.4g} +/- "
            f"{se_gain:.2g} J/kg{share}: more than {ENERGY_GAIN_SIGMAS:g} standard "
            "errors; a contact cannot give the body energy",
        )
    return None


def join_duration(
    before: FlightFit, after: FlightFit, t_guess_s: float, *, iterations: int = 30
) -> tuple[float, float, float]:
    """Where the two flights' paths cross: ``(t1, t2, miss_m)``.

    The incoming flight passes the crossing point at ``t1``, the outgoing one at
    ``t2`` (Newton on ``p_before(t1) = p_after(t2)`` from ``t_guess_s``); ``t2 - t1``
    is the contact's duration as the flights see it. ``miss_m`` is the distance left
    between the two points (0 when the paths cross; the closest approach otherwise,
    e.g. paths along one line). NaN times when the iteration fails.

    Examples
    --------
    >>> from fieldkit.tracking.flights.ballistic_fit import fit_flight
    >>> t = np.linspace(0.0, 0.1, 20)
    >>> a = fit_flight(t, 1.0 * t, 0.5 - 2.0 * t - 4.905 * t**2)
    >>> b = fit_flight(t + 0.1, 0.1 + 0.9 * t, 0.251 + 2.0 * t - 4.905 * t**2)
    >>> t1, t2, miss = join_duration(a, b, 0.1)
    >>> round(t1, 4), round(t2, 4), miss < 1e-9
    (0.1, 0.1, True)
    """
    t1 = t2 = float(t_guess_s)
    for _ in range(iterations):
        xa, za = before.position(t1)
        xb, zb = after.position(t2)
        va, vb = before.velocity(t1), after.velocity(t2)
        r = np.array([float(xa - xb), float(za - zb)])
        jac = np.array([[float(va[0]), -float(vb[0])], [float(va[1]), -float(vb[1])]])
        if abs(np.linalg.det(jac)) < 1e-12 * max(1.0, float(np.abs(jac).max()) ** 2):
            break
        step = np.linalg.solve(jac, r)
        t1, t2 = t1 - float(step[0]), t2 - float(step[1])
        if np.abs(step).max() < 1e-12:
            break
    xa, za = before.position(t1)
    xb, zb = after.position(t2)
    miss = float(np.hypot(xa - xb, za - zb))
    if not (np.isfinite(t1) and np.isfinite(t2)):
        return float("nan"), float("nan"), float("nan")
    return t1, t2, miss


#: Steepest line through the other impacts [deg] for it to count as one level floor.
LEVEL_FLOOR_DEG = 5.0


def off_the_floor(x_m: np.ndarray, z_m: np.ndarray, radius_m: float) -> dict[int, str]:
    """Impacts whose centre lies in mid-air above the floor the others touch.

    Without a surveyed ground the surface is where the impacts are: for each impact,
    a straight line through the others (at least two) is the floor when it is level
    (dip under :data:`LEVEL_FLOOR_DEG`) and the others lie on it within half a
    radius; an impact more than one radius above it is refused. On sloping or
    uneven ground nothing is refused (the surface is not known well enough).

    Parameters
    ----------
    x_m, z_m
        Centres of the instantaneous impacts [m].
    radius_m
        Body radius [m].

    Returns
    -------
    dict
        Position in ``x_m`` -> reason.

    Examples
    --------
    >>> off_the_floor(np.array([0.1, 0.5, 0.9]), np.array([0.033, 0.38, 0.034]),
    ...               0.033)[1][:24]
    'the centre is 347 mm abo'
    """
    x, z = np.asarray(x_m, float), np.asarray(z_m, float)
    out: dict[int, str] = {}
    if len(x) < 3:
        return out
    for i in range(len(x)):
        others = np.flatnonzero(np.arange(len(x)) != i)
        xo, zo = x[others], z[others]
        if np.ptp(xo) > 0:
            slope, level = np.polyfit(xo, zo, 1)
        else:
            slope, level = 0.0, float(np.mean(zo))
        if np.degrees(np.arctan(abs(slope))) > LEVEL_FLOOR_DEG:
            continue
        if np.abs(zo - (level + slope * xo)).max() > 0.5 * radius_m:
            continue
        height = z[i] - (level + slope * x[i])
        if height > radius_m:
            out[i] = (
                f"the centre is {1e3 * height:.0f} mm above the level floor the "
                f"other {len(others)} impacts touch (more than one radius, "
                f"{1e3 * radius_m:.0f} mm): the body is in mid-air"
            )
    return out
