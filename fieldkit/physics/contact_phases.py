"""The [p_N - v] lines of one impact: the general rough-body solution (App. C).

During an impact the velocities are piecewise-linear functions of the normal impulse
``p_N`` (eq. 4.3, C.15): Coulomb slip (``dp_T = -mu dp_N``, C.12-C.14) until the slip
velocity vanishes (C.24-C.26), then rolling if friction can hold it (4.14b; always for
a collinear impact), otherwise slip the other way (eccentric impacts with
``mu beta1 < |beta2|``). Maximum compression ``p_c`` is where the contact normal
velocity vanishes (C.16), separation ``p_f = (1 + e_N) p_c`` (C.17, Poisson).

:func:`contact_phases` solves these lines; :mod:`fieldkit.physics.impact_mechanics`
(final state, :func:`~fieldkit.physics.impact_mechanics.rough_body_impact`) and
:mod:`fieldkit.physics.impulse_history` (sampled lines for the diagram) use them.
Signs and axes as in :mod:`fieldkit.physics.impact_mechanics`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics._validate import number_array, reject


def inertial_coefficients(
    gyration_m: ArrayLike, r_t_m: ArrayLike, r_n_m: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Inertial coefficients beta1, beta2, beta3 for plane impact (eq. C.11).

    ``beta1 = 1 + r_N^2/k^2``, ``beta2 = r_N r_T / k^2``, ``beta3 = 1 + r_T^2/k^2``
    (slope of infinite mass). They give the relative velocity of the contact point:
    ``m dv_T = beta1 dp_T - beta2 dp_N`` and ``m dv_N = -beta2 dp_T + beta3 dp_N``
    (C.6a, b).

    Parameters
    ----------
    gyration_m
        Radius of gyration k [m].
    r_t_m
        Tangential distance r_T from the contact point to the centre of mass [m]
        (0 for a collinear impact, e.g. a sphere).
    r_n_m
        Normal distance r_N from the contact point to the centre of mass [m] (the
        contact radius r of a sphere).

    Examples
    --------
    Worked example 6B (boulder A, k = 0.46, r_T = 0.8, r_N = 0.65): 3.00, 2.46, 4.02.

    >>> [round(float(b), 2) for b in inertial_coefficients(0.46, 0.8, 0.65)]
    [3.0, 2.46, 4.02]
    """
    k2 = np.asarray(gyration_m, float) ** 2
    r_t = np.asarray(r_t_m, float)
    r_n = np.asarray(r_n_m, float)
    return 1.0 + r_n**2 / k2, r_n * r_t / k2, 1.0 + r_t**2 / k2


@dataclass(frozen=True)
class ContactPhases:
    """The piecewise-linear [p_N - v] lines of one impact, per unit mass (App. C).

    ``q`` is the normal impulse per unit mass ``p_N / m`` [m/s]. Phase 1 slips in
    direction ``direction`` (sign of the initial slip velocity) with
    ``dp_T/dp_N = ratio_1``; at ``q_slip_stop`` (``inf`` if it never stops) the contact
    either rolls (``ratio_2 = beta2/beta1``, always for collinear impacts) or slips the
    other way (eccentric impacts with ``mu beta1 < |beta2|``). Use
    :func:`contact_phases` to build it.
    """

    v_it: np.ndarray
    v_in: np.ndarray
    omega_i: np.ndarray
    r_t: np.ndarray
    r_n: np.ndarray
    k2: np.ndarray
    slip_i: np.ndarray
    normal_i: np.ndarray
    direction: np.ndarray
    ratio_1: np.ndarray
    slope_t_1: np.ndarray
    slope_n_1: np.ndarray
    q_slip_stop: np.ndarray
    p_t_slip_stop: np.ndarray
    normal_slip_stop: np.ndarray
    rolls: np.ndarray
    ratio_2: np.ndarray
    slope_t_2: np.ndarray
    slope_n_2: np.ndarray
    q_c: np.ndarray
    q_f: np.ndarray

    def tangential_impulse(self, q: ArrayLike) -> np.ndarray:
        """Tangential impulse per unit mass ``p_T/m`` at normal impulse ``q`` [m/s]."""
        q = np.asarray(q, float)
        with np.errstate(invalid="ignore", over="ignore"):
            early = self.ratio_1 * q
            late = self.p_t_slip_stop + self.ratio_2 * (q - self.q_slip_stop)
        return np.where(q < self.q_slip_stop, early, late)

    def contact_velocities(self, q: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Slip (tangential) and normal velocity of the contact point at ``q`` [m/s]."""
        q = np.asarray(q, float)
        with np.errstate(invalid="ignore", over="ignore"):
            early = q < self.q_slip_stop
            v_t = np.where(
                early,
                self.slip_i + self.slope_t_1 * q,
                self.slope_t_2 * (q - self.q_slip_stop),
            )
            v_n = np.where(
                early,
                self.normal_i + self.slope_n_1 * q,
                self.normal_slip_stop + self.slope_n_2 * (q - self.q_slip_stop),
            )
        return v_t, v_n

    def body_velocities(
        self, q: ArrayLike
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Centre-of-mass velocities ``V_T, V_N`` [m/s] and spin [rad/s] at ``q``."""
        q = np.asarray(q, float)
        p_t = self.tangential_impulse(q)
        omega = self.omega_i + (self.r_n * p_t - self.r_t * q) / self.k2
        return self.v_it + p_t, self.v_in + q, omega

    def normal_work(self, q: ArrayLike) -> np.ndarray:
        """``int_0^q v_N dp_N`` per unit mass [J/kg] (area under the v_N line)."""
        q = np.asarray(q, float)
        with np.errstate(invalid="ignore", over="ignore"):
            q1 = np.minimum(q, self.q_slip_stop)
            v1 = self.normal_i + self.slope_n_1 * q1
            part1 = np.where(q1 > 0, 0.5 * (self.normal_i + v1) * q1, 0.0)
            q2 = np.maximum(q - self.q_slip_stop, 0.0)
            part2 = np.where(
                q2 > 0,
                self.normal_slip_stop * q2 + 0.5 * self.slope_n_2 * q2**2,
                0.0,
            )
        return part1 + part2

    def friction_work(self, q: ArrayLike) -> np.ndarray:
        """``int_0^q v_T dp_T`` per unit mass [J/kg] (always <= 0: friction)."""
        q = np.asarray(q, float)
        v_t, _ = self.contact_velocities(q)
        p_t = self.tangential_impulse(q)
        with np.errstate(invalid="ignore", over="ignore"):
            finished = q >= self.q_slip_stop
            first = np.where(
                finished,
                0.5 * self.slip_i * self.p_t_slip_stop,
                0.5 * (self.slip_i + v_t) * p_t,
            )
            second = np.where(
                finished & ~self.rolls, 0.5 * v_t * (p_t - self.p_t_slip_stop), 0.0
            )
        return first + second


def contact_phases(
    v_it_mps: ArrayLike,
    v_in_mps: ArrayLike,
    omega_i_radps: ArrayLike,
    *,
    radius_m: ArrayLike,
    gyration_m: ArrayLike,
    e_n: ArrayLike,
    friction: ArrayLike = np.inf,
    offset_m: ArrayLike = 0.0,
) -> ContactPhases:
    """Solve the [p_N - v] lines of a rough rotating body impact (eqs. C.12-C.18).

    Arguments as :func:`fieldkit.physics.impact_mechanics.rough_body_impact`.
    Raises :class:`ArgumentError` naming the argument for out-of-range input.
    """
    v_it = number_array(v_it_mps, "v_it_mps")
    v_in = number_array(v_in_mps, "v_in_mps")
    omega_i = number_array(omega_i_radps, "omega_i_radps")
    r_n = number_array(radius_m, "radius_m")
    k = number_array(gyration_m, "gyration_m")
    e = number_array(e_n, "e_n")
    mu = number_array(friction, "friction")
    r_t = number_array(offset_m, "offset_m")
    reject(~np.isfinite(v_it), "v_it_mps", "be finite", v_it)
    reject(~np.isfinite(v_in), "v_in_mps", "be finite", v_in)
    reject(~np.isfinite(omega_i), "omega_i_radps", "be finite", omega_i)
    reject(~(r_n > 0) | ~np.isfinite(r_n), "radius_m", "be > 0", r_n)
    reject(~(k > 0) | ~np.isfinite(k), "gyration_m", "be > 0", k)
    reject(~(e >= 0) | ~np.isfinite(e), "e_n", "be >= 0", e)
    reject(~(mu >= 0), "friction", "be >= 0 (inf = slip always stops)", mu)
    reject(~np.isfinite(r_t), "offset_m", "be finite", r_t)
    reject(
        np.isinf(mu) & (r_t != 0),
        "friction",
        "be finite for an eccentric impact (offset_m != 0)",
        mu,
    )
    reject(~(v_in < 0), "v_in_mps", "be < 0 (moving into the ground)", v_in)

    v_it, v_in, omega_i, r_n, k, e, mu, r_t = np.broadcast_arrays(
        v_it, v_in, omega_i, r_n, k, e, mu, r_t
    )
    k2 = k**2
    beta1, beta2, beta3 = inertial_coefficients(k, r_t, r_n)
    slip_i = v_it + omega_i * r_n  # eq. 4.15 / C.21 (contact tangential velocity)
    normal_i = v_in - omega_i * r_t  # contact normal velocity (= v_in when collinear)
    reject(
        ~(normal_i < 0),
        "v_in_mps",
        "be such that the contact point moves into the ground (v_in - omega_i r_T < 0)",
        v_in,
    )
    s = np.sign(slip_i)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        # phase 1: slip in direction s, dp_T = -s mu dp_N (C.12-C.14)
        ratio_1 = -s * mu
        slope_t_1 = beta1 * ratio_1 - beta2
        slope_n_1 = beta3 - beta2 * ratio_1
        retard = mu * beta1 + s * beta2  # > 0: friction brings the slip to a stop
        q_s = np.where(retard > 0, np.abs(slip_i) / retard, np.inf)  # C.26
        q_s = np.where(s == 0, 0.0, q_s)  # rolling at impact; mu = inf gives 0 too
        p_t_s = (beta2 * q_s - slip_i) / beta1  # from v_T(q_s) = 0 (C.6a integrated)
        normal_s = normal_i - beta2 * p_t_s + beta3 * q_s  # C.6b integrated
        # phase 2: roll if friction can hold it (4.14b), else slip the other way
        rolls = mu * beta1 >= np.abs(beta2)
        s_2 = np.where(s != 0, -s, -np.sign(beta2))
        ratio_2 = np.where(rolls, beta2 / beta1, -s_2 * mu)
        slope_t_2 = np.where(rolls, 0.0, beta1 * ratio_2 - beta2)
        slope_n_2 = beta3 - beta2 * ratio_2
        # maximum compression: contact normal velocity = 0 (C.16, piecewise)
        q_c1 = np.where(slope_n_1 > 0, -normal_i / slope_n_1, np.inf)
        q_c2 = q_s - normal_s / slope_n_2
        q_c = np.where(q_c1 < q_s, q_c1, q_c2)
    q_f = (1.0 + e) * q_c  # C.17 (Poisson)
    q_s = np.where(q_s < q_f, q_s, np.inf)  # slip that would stop after separation
    return ContactPhases(
        v_it=v_it,
        v_in=v_in,
        omega_i=omega_i,
        r_t=r_t,
        r_n=r_n,
        k2=k2,
        slip_i=slip_i,
        normal_i=normal_i,
        direction=s,
        ratio_1=ratio_1,
        slope_t_1=slope_t_1,
        slope_n_1=slope_n_1,
        q_slip_stop=q_s,
        p_t_slip_stop=p_t_s,
        normal_slip_stop=normal_s,
        rolls=rolls,
        ratio_2=ratio_2,
        slope_t_2=slope_t_2,
        slope_n_2=slope_n_2,
        q_c=q_c,
        q_f=q_f,
    )
