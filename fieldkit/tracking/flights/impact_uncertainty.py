"""Standard uncertainties of video impacts, from the flight fits' residuals.

The ``<column>_sd`` columns of a track's ImpactTable (docs/architecture.md §3;
:data:`fieldkit.impact_table.SD_COLUMNS`: ``e_n_sd``, ``e_t_sd``, ``vi_sd_mps``, ...)
are a first-order (linearised) propagation of the fixed-g fits' parameter covariance:

* each flight's ``(x0, vx)`` and ``(z0, vz)`` at its reference time have covariance
  ``sigma^2 (A'A)^-1`` (:attr:`FlightFit.covariance`), ``sigma`` estimated from the
  fit's own residuals; x and z, and different flights, are independent;
* the velocities at the contact are functions of those eight parameters of the two
  flights -- through the contact instant too, for an instantaneous contact: the two
  parabolas' closest approach ``t* = t0 - d0.dv / |dv|^2``
  (:func:`fieldkit.tracking.flights.contact_impacts.contact_instant`) moves with them,
  and a later ``t*`` makes both ``vz`` smaller by ``g dt*``;
* then ``vin``, ``vit``, ``vfn``, ``vft``, ``theta_i``, ``e_n = -vfn / vin`` and
  ``e_t = vft / vit`` (eqs. 4.6, 4.7, :func:`fieldkit.impact_table.restitution`).

The Jacobian of that chain is taken by central differences (each parameter stepped
by a thousandth of its own standard error, where the chain is linear to far better
than the noise), and ``sd = sqrt(diag(J C J'))``.

What is held fixed: the surface angle ``slope_deg`` at its value (exact when given;
an estimated angle's own error is not included, so the sd is then a lower bound), the
start and end times of an extended contact (found from the deviation onset), and a
closest approach that lies on the edge of its search window.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from fieldkit.impact_table import SD_COLUMNS, restitution
from fieldkit.tracking.flights.ballistic_fit import FlightFit

#: Fraction of a parameter's standard error used as the finite-difference step.
STEP_FRACTION = 1e-3


def _joint_parameters(before: FlightFit, after: FlightFit):
    """The two flights' parameters end to end (8) and their block-diagonal
    covariance (the flights are fitted to different samples)."""
    theta_a, cov_a = _parameters(before)
    theta_b, cov_b = _parameters(after)
    cov = np.zeros((8, 8))
    cov[:4, :4], cov[4:, 4:] = cov_a, cov_b
    return np.concatenate([theta_a, theta_b]), cov


def _parameters(fit: FlightFit) -> tuple[np.ndarray, np.ndarray]:
    """``(x0, vx, z0, vz)`` at ``t_ref_s`` and their 4 x 4 covariance."""
    theta = np.array([fit.x0_m, fit.vx_mps, fit.z0_m, fit.vz_mps], float)
    cov = np.zeros((4, 4))
    cov[:2, :2] = fit.covariance
    cov[2:, 2:] = fit.covariance
    return theta, cov


def _closest_approach(
    theta: np.ndarray, before: FlightFit, after: FlightFit, t0: float
) -> float:
    """Time of the closest approach of the two parabolas with parameters ``theta``
    (``(x0, vx, z0, vz)`` of ``before`` then of ``after``), unclipped [s]."""
    xa, vxa, za, vza, xb, vxb, zb, vzb = theta
    ta, tb = t0 - before.t_ref_s, t0 - after.t_ref_s
    ga, gb = before.g_fixed_mps2, after.g_fixed_mps2
    d0 = np.array(
        [
            (xb + vxb * tb) - (xa + vxa * ta),
            (zb + vzb * tb - 0.5 * gb * tb**2) - (za + vza * ta - 0.5 * ga * ta**2),
        ]
    )
    dv = np.array([vxb - vxa, (vzb - gb * tb) - (vza - ga * ta)])
    if dv @ dv < 1e-18:
        return t0
    return float(t0 - (d0 @ dv) / (dv @ dv))


def _velocities(
    theta: np.ndarray,
    before: FlightFit,
    after: FlightFit,
    times: tuple[float, float],
    instant: bool,
) -> tuple[float, float, float, float]:
    """``vi_x, vi_z, vf_x, vf_z`` in the track's frame for parameters ``theta``.

    With ``instant`` the contact time is the closest approach of the two parabolas
    for these parameters; otherwise ``times`` (impact, restitution) are kept.
    """
    _, vxa, _, vza, _, vxb, _, vzb = theta
    ti, tf = times
    if instant:
        ti = tf = _closest_approach(theta, before, after, ti)
    return (
        vxa,
        vza - before.g_fixed_mps2 * (ti - before.t_ref_s),
        vxb,
        vzb - after.g_fixed_mps2 * (tf - after.t_ref_s),
    )


def contact_sd(
    before: FlightFit,
    after: FlightFit,
    times: tuple[float, float],
    slope_deg: float,
    *,
    instant: bool,
    direction: float = 1.0,
) -> dict[str, float]:
    """Standard uncertainty of each value of :data:`SD_COLUMNS` at one contact.

    Parameters
    ----------
    before, after
        The fitted flights into and out of the contact.
    times
        Impact and restitution times of the contact [s] (equal for an instantaneous
        one).
    slope_deg
        Surface dip psi at the contact [deg] (held fixed).
    instant
        The contact time is the closest approach of the two parabolas and moves with
        them (False, or a contact time clipped to its search window: ``times`` are
        held fixed).
    direction
        -1 when the table is in the mirrored frame (travel toward -x): ``vx`` changes
        sign before the N/T decomposition.

    Returns
    -------
    dict
        ``{sd column: value}``; NaN where the value itself is undefined or a fit has
        no covariance (too few samples).

    Examples
    --------
    Two flights with known covariance meeting on level ground at t = 0: ``vz`` before
    -4 m/s, after +2 m/s, ``vx`` 3 m/s, times held. ``e_n = -vfn / vin`` = 0.5, and
    with sd 0.1 m/s on each ``vz``, ``e_n_sd = 0.1 sqrt(1 + 0.5^2) / 4``.

    >>> def flight(vz):
    ...     return FlightFit(0, np.arange(4), -0.1, 0.1, 0.0, 0.0, 0.0, 3.0, vz,
    ...                      0.1, 0.1, 9.81, 0.0, 9.81, 0.0, 0.0, np.empty(0),
    ...                      covariance=np.diag([0.0, 0.01]))
    >>> sd = contact_sd(flight(-4.0), flight(2.0), (0.0, 0.0), 0.0, instant=False)
    >>> round(sd["e_n_sd"], 6), round(float(0.1 * np.sqrt(1.25) / 4), 6)
    (0.027951, 0.027951)
    """
    theta, cov = _joint_parameters(before, after)
    names = list(SD_COLUMNS)
    nan = dict.fromkeys(SD_COLUMNS.values(), float("nan"))
    if not np.all(np.isfinite(cov)):
        return nan
    psi = np.array([slope_deg], float)
    if instant and abs(_closest_approach(theta, before, after, times[0]) - times[0]) > (
        1e-6
    ):
        instant = False  # clipped to the search window: the time does not move

    def values(p: np.ndarray) -> np.ndarray:
        vix, viz, vfx, vfz = _velocities(p, before, after, times, instant)
        v = (direction * vix, viz, direction * vfx, vfz)
        out = restitution(*(np.array([c], float) for c in v), psi)
        return np.array([float(out[name][0]) for name in names])

    centre = values(theta)
    jacobian = np.zeros((len(names), 8))
    for k in range(8):
        se = float(np.sqrt(cov[k, k]))
        if se == 0.0:
            continue
        step = np.zeros(8)
        step[k] = STEP_FRACTION * se
        jacobian[:, k] = (values(theta + step) - values(theta - step)) / (2 * step[k])
    variance = np.einsum("ik,kl,il->i", jacobian, cov, jacobian)
    sd = np.sqrt(np.maximum(variance, 0.0))
    sd = np.where(np.isfinite(centre), sd, np.nan)
    return {
        SD_COLUMNS[name]: float(value) for name, value in zip(names, sd, strict=True)
    }


def contact_sds(
    pairs: Sequence[tuple[FlightFit, FlightFit, tuple[float, float], bool]],
    slope_deg: np.ndarray,
    direction: float = 1.0,
) -> dict[str, np.ndarray]:
    """:func:`contact_sd` of every contact, as columns (one value per contact).

    ``pairs`` holds ``(before, after, (t_impact, t_restitution), instant)`` per
    contact, in the table's order; ``slope_deg`` the dip at each (table frame).
    """
    rows = [
        contact_sd(a, b, times, float(psi), instant=instant, direction=direction)
        for (a, b, times, instant), psi in zip(pairs, slope_deg, strict=True)
    ]
    return {
        column: np.array([row[column] for row in rows], float)
        for column in SD_COLUMNS.values()
    }


def contact_time_sd(before: FlightFit, after: FlightFit, t_s: float) -> float:
    """Standard uncertainty [s] of an instantaneous contact's time: the closest
    approach of the two parabolas, moved by the fits' parameter errors (first-order
    propagation as in :func:`contact_sd`). It grows with the time the flights are
    extrapolated over, so with the frames missing around the contact.

    Examples
    --------
    Level flights ``vz`` -4 and +2 m/s meeting at t = 0, position sd 1 mm each
    in z (velocity exact): the meeting moves by ``dz / (vz_after - vz_before)``,
    ``sd = sqrt(2) 1e-3 / 6``.

    >>> def flight(vz):
    ...     return FlightFit(0, np.arange(4), -0.1, 0.1, 0.0, 0.0, 0.0, 3.0, vz,
    ...                      0.0, 0.0, 9.81, 0.0, 9.81, 0.0, 0.0, np.empty(0),
    ...                      covariance=np.diag([1e-6, 0.0]))
    >>> sd = contact_time_sd(flight(-4.0), flight(2.0), 0.0)
    >>> round(sd * 1e6, 3), round(float(np.sqrt(2) * 1e-3 / 6 * 1e6), 3)
    (235.702, 235.702)
    """
    theta, cov = _joint_parameters(before, after)
    if not np.all(np.isfinite(cov)):
        return float("nan")
    jacobian = np.zeros(8)
    for k in range(8):
        se = float(np.sqrt(cov[k, k]))
        if se == 0.0:
            continue
        step = np.zeros(8)
        step[k] = STEP_FRACTION * se
        plus = _closest_approach(theta + step, before, after, t_s)
        minus = _closest_approach(theta - step, before, after, t_s)
        jacobian[k] = (plus - minus) / (2 * step[k])
    return float(np.sqrt(max(float(jacobian @ cov @ jacobian), 0.0)))
