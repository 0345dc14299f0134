"""Impact of a rough, rotating body on the slope in local N/T axes (ch. 4, App. C).

Axes (docs/architecture.md §2, thesis Fig. 4.6): T along the ground down-slope, N out of
the ground; the impact normal velocity is negative, ``omega`` is negative clockwise (the
usual spin for travel down-slope). Impulses are the thesis's: ``p`` is the normal
impulse, the independent variable of the [p_N - v] diagram (eq. 4.3).

The body is given by its contact radius ``r`` (= ``r_N``, the height of the centre of
mass above the contact point), its radius of gyration ``k`` and, for an eccentric
impact, the tangential offset ``r_T`` of the centre of mass from the contact point
(positive when the centre lies down-slope of the contact). ``r_T = 0`` is the thesis's
collinear impact of a sphere (App. C.3), for which eqs. 4.20-4.22 hold whenever slip
stops before separation.

The general solution (:func:`rough_body_impact`, solved piecewise in
:mod:`fieldkit.physics.contact_phases`) follows App. C: Coulomb friction
``dp_T = -mu dp_N`` while the contact slips (C.12-C.15), rolling (no slip) once the slip
velocity vanishes if friction can hold it, otherwise slip reverses (eccentric impacts
only); the end of compression ``p_c`` is where the contact normal velocity vanishes
(C.16) and the impact ends at ``p_f = (1 + e_N) p_c`` (C.17, Poisson's hypothesis).
Everything is mass-independent; impulses are reported per unit mass unless
``mass_kg`` is given.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics._validate import number_array, reject
from fieldkit.physics.contact_phases import contact_phases, inertial_coefficients

__all__ = [
    "ImpactResult",
    "compression_impulse",
    "final_impulse",
    "final_speed_and_angle",
    "inertial_coefficients",
    "minimum_friction_to_stop_slip",
    "rolling_final_velocities",
    "rough_body_impact",
    "slip_stop_impulse_ratio",
    "slip_velocity",
]


def slip_velocity(
    v_t_mps: ArrayLike, omega_radps: ArrayLike, radius_m: ArrayLike
) -> np.ndarray:
    """Slip velocity of the contact point ``v_s = v_T + r omega`` [m/s] (eq. 4.15).

    Zero means rolling without slip (``omega = -v_T / r``).

    Examples
    --------
    Worked example 4A at impact: 19.9 m/s and -15 rad/s on a 0.75 m radius sphere.

    >>> round(float(slip_velocity(19.9, -15.0, 0.75)), 2)
    8.65
    """
    return np.asarray(v_t_mps, float) + np.asarray(radius_m, float) * np.asarray(
        omega_radps, float
    )


def compression_impulse(
    v_in_mps: ArrayLike,
    mass_kg: ArrayLike,
    beta2: ArrayLike = 0.0,
    beta3: ArrayLike = 1.0,
    friction: ArrayLike = 0.0,
) -> np.ndarray:
    """Normal impulse at maximum compression for constant slip [N s] (eqs. 4.4, C.16).

    ``p_c = -m v_iN / (beta3 + mu beta2)``; with the defaults (collinear impact)
    ``p_c = -m v_iN`` (eq. 4.4).

    Examples
    --------
    Worked example 6B: 3750 kg, v_iN = -4.4 m/s, mu = 0.68 -> 2898 kg m/s.

    >>> round(float(compression_impulse(-4.4, 3750, 2.46, 4.02, 0.68)))
    2898
    """
    return (
        -np.asarray(mass_kg, float)
        * np.asarray(v_in_mps, float)
        / (np.asarray(beta3, float) + np.asarray(friction, float) * np.asarray(beta2))
    )


def final_impulse(p_c: ArrayLike, e_n: ArrayLike) -> np.ndarray:
    """Normal impulse at separation ``p_f = (1 + e_N) p_c`` (eqs. 4.12, C.17, C.18).

    Examples
    --------
    >>> round(float(final_impulse(2898.0, 1.30)))
    6665
    """
    return (1.0 + np.asarray(e_n, float)) * np.asarray(p_c, float)


def slip_stop_impulse_ratio(
    v_it_mps: ArrayLike,
    v_in_mps: ArrayLike,
    omega_i_radps: ArrayLike,
    *,
    radius_m: ArrayLike,
    gyration_m: ArrayLike,
    friction: ArrayLike,
) -> np.ndarray:
    """Impulse ratio ``p_s / p_c`` at which slip stops, collinear impact (eq. C.26).

    ``p_s/p_c = -(v_iT + r omega_i) / (v_iN mu (1 + r^2/k^2))``. Slip stops before
    separation when this is below ``1 + e_N``. Written for ``v_iT + r omega_i >= 0``
    (down-slope slip), as in the thesis; :func:`rough_body_impact` handles both signs.

    Examples
    --------
    >>> round(float(slip_stop_impulse_ratio(19.9, -9.3, -15.0, radius_m=0.75,
    ...                                     gyration_m=0.4743, friction=0.5)), 3)
    0.531
    """
    r = np.asarray(radius_m, float)
    k = np.asarray(gyration_m, float)
    v_s = slip_velocity(v_it_mps, omega_i_radps, r)
    mu = np.asarray(friction, float)
    return -v_s / (np.asarray(v_in_mps, float) * mu * (1 + r**2 / k**2))


def rolling_final_velocities(
    v_it_mps: ArrayLike,
    v_in_mps: ArrayLike,
    omega_i_radps: ArrayLike,
    *,
    radius_m: ArrayLike,
    gyration_m: ArrayLike,
    e_n: ArrayLike,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Final velocities when slip stops during the impact (eqs. 4.20-4.22, C.27-C.29).

    ``v_fT = v_iT - (v_iT + r omega_i) / (1 + r^2/k^2)``, ``v_fN = -e_N v_iN``,
    ``omega_f = omega_i - (r/k^2) (v_iT + r omega_i) / (1 + r^2/k^2)``.
    Independent of the friction coefficient, provided it is large enough for slip to
    stop before separation (see :func:`minimum_friction_to_stop_slip`).

    Returns
    -------
    v_ft_mps, v_fn_mps, omega_f_radps

    Examples
    --------
    Worked example 4A (v_i = 22 m/s at 25 deg, omega_i = -15 rad/s, 1.5 m sphere,
    e_N = 0.708 from eq. 5.4): thesis v_fT 17.5, v_fN 6.6, omega_f -23.3.

    >>> v_ft, v_fn, w_f = rolling_final_velocities(19.939, -9.298, -15.0,
    ...     radius_m=0.75, gyration_m=0.75 * 0.4 ** 0.5, e_n=0.708)
    >>> round(float(v_ft), 1), round(float(v_fn), 1), round(float(w_f), 1)
    (17.5, 6.6, -23.3)
    """
    r = np.asarray(radius_m, float)
    k2 = np.asarray(gyration_m, float) ** 2
    v_it = np.asarray(v_it_mps, float)
    change = slip_velocity(v_it, omega_i_radps, r) / (1.0 + r**2 / k2)
    v_ft = v_it - change
    v_fn = -np.asarray(e_n, float) * np.asarray(v_in_mps, float)
    omega_f = np.asarray(omega_i_radps, float) - r / k2 * change
    return v_ft, v_fn, omega_f


def final_speed_and_angle(
    v_ft_mps: ArrayLike, v_fn_mps: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """Restitution speed and angle to the ground (eqs. 4.23, 4.24).

    ``v_f = sqrt(v_fT^2 + v_fN^2)``; ``theta_f = atan(v_fN / v_fT)`` in degrees, taken
    with ``atan2`` so a rebound up-slope (``v_fT < 0``) gives an angle above 90.

    Examples
    --------
    >>> [round(float(x), 1) for x in final_speed_and_angle(17.46, 6.60)]
    [18.7, 20.7]
    """
    v_ft = np.asarray(v_ft_mps, float)
    v_fn = np.asarray(v_fn_mps, float)
    return np.hypot(v_ft, v_fn), np.degrees(np.arctan2(v_fn, v_ft))


def minimum_friction_to_stop_slip(
    v_it_mps: ArrayLike,
    v_in_mps: ArrayLike,
    omega_i_radps: ArrayLike,
    *,
    radius_m: ArrayLike,
    gyration_m: ArrayLike,
    e_n: ArrayLike,
) -> np.ndarray:
    """Smallest mu for which slip stops before separation, collinear impact (eq. C.26).

    From ``p_s/p_c <= p_f/p_c = 1 + e_N``:
    ``mu_min = |v_iT + r omega_i| / (-(1 + e_N) v_iN (1 + r^2/k^2))``. Above it the
    thesis's eqs. 4.20-4.22 apply; below it the body slips throughout the impact.

    Examples
    --------
    >>> round(float(minimum_friction_to_stop_slip(19.939, -9.298, -15.0,
    ...     radius_m=0.75, gyration_m=0.75 * 0.4 ** 0.5, e_n=0.708)), 3)
    0.156
    """
    r = np.asarray(radius_m, float)
    k = np.asarray(gyration_m, float)
    v_s = np.abs(slip_velocity(v_it_mps, omega_i_radps, r))
    q_f = -(1.0 + np.asarray(e_n, float)) * np.asarray(v_in_mps, float)
    return v_s / (q_f * (1.0 + r**2 / k**2))


@dataclass(frozen=True)
class ImpactResult:
    """Outcome of :func:`rough_body_impact` (arrays broadcast over the inputs).

    Velocities are of the centre of mass in local axes [m/s], spin [rad/s] (thesis
    signs). Impulses ``p_c``, ``p_f``, ``p_slip_stop`` are in N s when a mass was given,
    otherwise per unit mass (N s/kg = m/s). Energies [J] are NaN without a mass.

    Attributes
    ----------
    v_ft_mps, v_fn_mps, omega_f_radps
        Final tangential and normal velocity and spin (eqs. 4.20-4.22 when slip stops).
    v_f_mps, theta_f_deg
        Final speed and angle to the ground (eqs. 4.23, 4.24).
    e_n, e_t
        ``-v_fN/v_iN`` (= the e_N used, for a collinear impact) and ``v_fT/v_iT``.
    slip_velocity_i_mps, slip_velocity_f_mps
        Contact slip velocity ``v_T + r omega`` before and after (eq. 4.15).
    p_c, p_f
        Normal impulse at maximum compression and at separation (C.16-C.18).
    slip_stops, p_slip_stop
        Whether slip stops before separation, and the normal impulse where it does
        (C.26; NaN if it does not). A body rolling at impact has ``p_slip_stop = 0``.
    ke_i_j, ke_f_j, re_i_j, re_f_j
        Kinetic and rotational energy before and after.
    energy_change_j
        ``(ke_f + re_f) - (ke_i + re_i)``; negative = loss.
    work_compression_j, work_restitution_j, work_friction_j
        Work of the contact force: normal impulse up to ``p_c`` (<= 0), normal impulse
        from ``p_c`` to ``p_f`` (>= 0), and friction (<= 0); they sum to
        ``energy_change_j`` (thesis eqs. 6.7-6.9, generalised; see docs/thesis-notes.md
        for the eq. 6.7 factor 1/2).
    """

    v_ft_mps: np.ndarray
    v_fn_mps: np.ndarray
    omega_f_radps: np.ndarray
    v_f_mps: np.ndarray
    theta_f_deg: np.ndarray
    e_n: np.ndarray
    e_t: np.ndarray
    slip_velocity_i_mps: np.ndarray
    slip_velocity_f_mps: np.ndarray
    p_c: np.ndarray
    p_f: np.ndarray
    slip_stops: np.ndarray
    p_slip_stop: np.ndarray
    ke_i_j: np.ndarray
    ke_f_j: np.ndarray
    re_i_j: np.ndarray
    re_f_j: np.ndarray
    energy_change_j: np.ndarray
    work_compression_j: np.ndarray
    work_restitution_j: np.ndarray
    work_friction_j: np.ndarray


def rough_body_impact(
    v_it_mps: ArrayLike,
    v_in_mps: ArrayLike,
    omega_i_radps: ArrayLike,
    *,
    radius_m: ArrayLike,
    gyration_m: ArrayLike,
    e_n: ArrayLike,
    friction: ArrayLike = np.inf,
    offset_m: ArrayLike = 0.0,
    mass_kg: ArrayLike | None = None,
) -> ImpactResult:
    """Impact of a rough, rotating body on the slope (thesis §4.6, App. C).

    Parameters
    ----------
    v_it_mps, v_in_mps
        Impact velocity of the centre of mass along T (down-slope) and N [m/s];
        ``v_in_mps < 0``.
    omega_i_radps
        Spin at impact [rad/s], negative clockwise (thesis Fig. 4.6).
    radius_m
        Contact radius r = r_N [m], > 0.
    gyration_m
        Radius of gyration k [m], > 0.
    e_n
        Normal coefficient of restitution (>= 0; > 1 is allowed, eq. 5.4 gives it at
        shallow impacts). Applied as ``p_f = (1 + e_N) p_c`` (C.17).
    friction
        Coulomb friction coefficient mu >= 0 at the contact. ``inf`` (default) is the
        thesis's assumption for eqs. 4.20-4.22: slip always stops before separation
        (collinear impacts only: infinite friction has no meaning when the impulse is
        eccentric). ``0`` is a smooth contact.
    offset_m
        Tangential offset r_T of the centre of mass from the contact point [m]
        (eccentric impact, C.11); 0 = collinear impact (thesis ch. 4).
    mass_kg
        Mass [kg]; optional, only scales impulses and energies.

    Returns
    -------
    ImpactResult

    Examples
    --------
    Worked example 4A: thesis v_fT 17.5, v_fN 6.6, omega_f -23.3, theta_f 20.7 deg.

    >>> import numpy as np
    >>> th = np.radians(25.0)
    >>> res = rough_body_impact(22 * np.cos(th), -22 * np.sin(th), -15.0,
    ...     radius_m=0.75, gyration_m=0.75 * np.sqrt(0.4), e_n=19.5 * 25 ** -1.03)
    >>> [round(float(x), 1) for x in (res.v_ft_mps, res.v_fn_mps, res.omega_f_radps,
    ...                               res.theta_f_deg)]
    [17.5, 6.6, -23.3, 20.7]
    """
    ph = contact_phases(
        v_it_mps,
        v_in_mps,
        omega_i_radps,
        radius_m=radius_m,
        gyration_m=gyration_m,
        e_n=e_n,
        friction=friction,
        offset_m=offset_m,
    )
    if mass_kg is None:
        mass = np.ones_like(ph.q_f)
        energy_scale = np.full_like(ph.q_f, np.nan)
    else:
        mass = number_array(mass_kg, "mass_kg")
        reject(~(mass > 0) | ~np.isfinite(mass), "mass_kg", "be > 0", mass)
        mass = np.broadcast_to(mass, ph.q_f.shape)
        energy_scale = mass
    v_ft, v_fn, omega_f = ph.body_velocities(ph.q_f)
    v_f, theta_f = final_speed_and_angle(v_ft, v_fn)
    speed2_i = ph.v_it**2 + ph.v_in**2
    ke_i = 0.5 * energy_scale * speed2_i
    ke_f = 0.5 * energy_scale * v_f**2
    re_i = 0.5 * energy_scale * ph.k2 * ph.omega_i**2
    re_f = 0.5 * energy_scale * ph.k2 * omega_f**2
    w_c = ph.normal_work(ph.q_c)
    w_f = ph.normal_work(ph.q_f)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        e_t = v_ft / ph.v_it
    slip_stops = np.isfinite(ph.q_slip_stop)

    def out(x: np.ndarray) -> np.ndarray:
        return np.asarray(x)[()]

    return ImpactResult(
        v_ft_mps=out(v_ft),
        v_fn_mps=out(v_fn),
        omega_f_radps=out(omega_f),
        v_f_mps=out(v_f),
        theta_f_deg=out(theta_f),
        e_n=out(-v_fn / ph.v_in),
        e_t=out(e_t),
        slip_velocity_i_mps=out(ph.slip_i),
        slip_velocity_f_mps=out(ph.contact_velocities(ph.q_f)[0]),
        p_c=out(mass * ph.q_c),
        p_f=out(mass * ph.q_f),
        slip_stops=out(slip_stops),
        p_slip_stop=out(np.where(slip_stops, mass * ph.q_slip_stop, np.nan)),
        ke_i_j=out(ke_i),
        ke_f_j=out(ke_f),
        re_i_j=out(re_i),
        re_f_j=out(re_f),
        energy_change_j=out(ke_f + re_f - ke_i - re_i),
        work_compression_j=out(energy_scale * w_c),
        work_restitution_j=out(energy_scale * (w_f - w_c)),
        work_friction_j=out(energy_scale * ph.friction_work(ph.q_f)),
    )
