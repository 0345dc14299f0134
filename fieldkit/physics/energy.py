"""Energies of a falling rock (thesis ch. 6, appendices B and D).

Kinetic, rotational and energy-head terms (eqs. 6.10, 6.14), and the energy changes
during an impact read as areas on the [p_N - v] diagram: normal compression and
restitution (6.2, 6.3, 6.5), the oblique rotating-body energies (6.6-6.9, with the
missing factor 1/2 of eq. 6.7 restored) and the rotational energy change (6.11).

NaN inputs propagate (missing data); definite violations (negative mass, e_N < 0, an
impact velocity pointing out of the ground) raise :class:`fieldkit.errors.ArgumentError`
naming the argument. Scalars in, numpy scalars out.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics._validate import (
    as_output,
    nonnegative_array,
    positive_array,
    raise_at_first,
    reject,
)
from fieldkit.physics.constants import G
from fieldkit.physics.impact_mechanics import compression_impulse, final_impulse


def kinetic_energy(mass_kg: ArrayLike, speed_mps: ArrayLike) -> np.ndarray:
    """Translational kinetic energy ``KE = 1/2 m v^2`` [J].

    Examples
    --------
    >>> float(kinetic_energy(1000.0, 10.0))
    50000.0
    """
    return 0.5 * np.asarray(mass_kg, float) * np.asarray(speed_mps, float) ** 2


def rotational_energy(
    mass_kg: ArrayLike, gyration_m: ArrayLike, omega_radps: ArrayLike
) -> np.ndarray:
    """Rotational kinetic energy ``RE = 1/2 I w^2``, ``I = m k^2`` [J] (eq. 6.10)."""
    inertia = np.asarray(mass_kg, float) * np.asarray(gyration_m, float) ** 2
    return 0.5 * inertia * np.asarray(omega_radps, float) ** 2


def potential_energy(
    mass_kg: ArrayLike, height_m: ArrayLike, g: float = G
) -> np.ndarray:
    """Potential energy ``PE = m g h`` [J] of a height ``h`` above a datum (eq. 6.13).

    Examples
    --------
    >>> float(potential_energy(1000.0, 5.0, g=9.81))
    49050.0
    """
    return np.asarray(mass_kg, float) * g * np.asarray(height_m, float)


def energy_head(z_m: ArrayLike, speed_mps: ArrayLike, g: float = G) -> np.ndarray:
    """Energy head ``E = z + v^2 / (2 g)`` [m] (thesis eq. 6.14).

    Examples
    --------
    >>> float(energy_head(100.0, 9.81, g=9.81))
    104.905
    """
    return np.asarray(z_m, float) + np.asarray(speed_mps, float) ** 2 / (2.0 * g)


# ====================================================================================
# Energy changes during an impact (thesis ch. 6, appendices B and D)
# ====================================================================================
#
# All impact energies are the work done at the contact point by the contact impulse,
# read as areas on the [p_N - v] diagram (eq. 6.1): ``E = integral of v dp``. They are
# negative for energy taken out of the body. ``beta`` is the slope factor of the normal
# pN-v line, ``beta = beta3 + mu * beta2`` (eq. C.15b); ``beta = 1`` for a collinear
# impact (sphere, centre of mass above the contact: beta2 = 0, beta3 = 1) and for the
# non-rotating body of section 6.1.1.


def rotational_energy_change(
    inertia_kgm2: ArrayLike, omega_i_radps: ArrayLike, omega_f_radps: ArrayLike
) -> np.ndarray:
    """Rotational energy change in an impact ``-1/2 I (w_i^2 - w_f^2)`` [J] (6.11).

    Negative when the spin slows down. ``I = m k^2`` [kg m^2]; spins in [rad/s].

    Examples
    --------
    Worked example 6C (Tornado Mountain #A26), I = 797 kg m^2, -11.1 -> -8.8 rad/s:

    >>> round(float(rotational_energy_change(797.0, -11.1, -8.8)) / 1e3, 2)
    -18.24
    """
    inertia = np.asarray(inertia_kgm2, float)
    nonnegative_array(inertia, "inertia_kgm2")
    w_i = np.asarray(omega_i_radps, float)
    w_f = np.asarray(omega_f_radps, float)
    return as_output(-0.5 * inertia * (w_i**2 - w_f**2))


def total_kinetic_energy(
    mass_kg: ArrayLike,
    speed_mps: ArrayLike,
    inertia_kgm2: ArrayLike,
    omega_radps: ArrayLike,
) -> np.ndarray:
    """Translational plus rotational energy ``1/2 m v^2 + 1/2 I w^2`` [J] (6.10).

    Examples
    --------
    Worked example 8B, impact on the fence: 520 kg at 22 m/s, I = 63.7 kg m^2, 18 rad/s:

    >>> round(float(total_kinetic_energy(520.0, 22.0, 63.7, 18.0)) / 1e3, 1)
    136.2
    """
    mass = np.asarray(mass_kg, float)
    inertia = np.asarray(inertia_kgm2, float)
    nonnegative_array(mass, "mass_kg")
    nonnegative_array(inertia, "inertia_kgm2")
    speed = np.asarray(speed_mps, float)
    omega = np.asarray(omega_radps, float)
    return as_output(0.5 * mass * speed**2 + 0.5 * inertia * omega**2)


def total_energy_change(
    mass_kg: ArrayLike,
    speed_i_mps: ArrayLike,
    speed_f_mps: ArrayLike,
    inertia_kgm2: ArrayLike,
    omega_i_radps: ArrayLike,
    omega_f_radps: ArrayLike,
) -> np.ndarray:
    """Total energy change of an impact ``Delta KE + Delta RE`` [J] (section 6.3).

    ``1/2 m (v_f^2 - v_i^2) - 1/2 I (w_i^2 - w_f^2)`` (eqs. 6.10, 6.11); negative =
    loss. From measured (or modelled) velocities before and after the impact.

    Examples
    --------
    Worked example 8B (fence): -97.5 kJ, the energy the net absorbs:

    >>> round(float(total_energy_change(520.0, 22.0, 11.5, 63.7, 18.0, -11.6)) / 1e3, 2)
    -97.49
    """
    mass = np.asarray(mass_kg, float)
    nonnegative_array(mass, "mass_kg")
    translational = (
        0.5
        * mass
        * (np.asarray(speed_f_mps, float) ** 2 - np.asarray(speed_i_mps, float) ** 2)
    )
    rotation = rotational_energy_change(inertia_kgm2, omega_i_radps, omega_f_radps)
    return as_output(translational + rotation)


def compression_energy(
    mass_kg: ArrayLike, vin_mps: ArrayLike, beta: ArrayLike = 1.0
) -> np.ndarray:
    """Energy lost up to maximum compression ``E_N(p_c) = -m v_iN^2 / (2 beta)`` [J].

    Area of the compression triangle on the [p_N - v] diagram,
    ``integral_0^p_c (v_iN + beta p / m) dp`` with ``p_c = -m v_iN / beta`` (eq. 6.6).
    For ``beta = 1`` this is eq. 6.2 / B.8 / D.2: all the normal kinetic energy.

    With ``beta = beta3 + mu beta2`` it is eq. 6.7 **corrected**: the thesis prints
    ``-m v_iN^2 / beta``, dropping the factor 1/2 in the last line of its own integral
    (docs/thesis-notes.md erratum). Worked example 6B inherits the slip (-12.9 kJ
    printed; the integral is -6.4 kJ).

    Parameters
    ----------
    mass_kg
        Body mass m [kg].
    vin_mps
        Normal velocity of the contact point at impact v_iN [m/s] (negative).
    beta
        Slope factor of the normal pN-v line [-], ``beta3 + mu * beta2`` (eq. C.15b).

    Examples
    --------
    Worked example 6A: 1000 kg dropped 5 m, all 49 kJ of normal energy is absorbed:

    >>> round(float(compression_energy(1000.0, -(2 * 9.81 * 5.0) ** 0.5)) / 1e3, 2)
    -49.05
    """
    mass, vin, beta = _normal_args(mass_kg, vin_mps, beta)
    return as_output(-mass * vin**2 / (2.0 * beta))


def restitution_energy(
    mass_kg: ArrayLike, vin_mps: ArrayLike, e_n: ArrayLike, beta: ArrayLike = 1.0
) -> np.ndarray:
    """Elastic strain energy recovered in restitution ``E_N(p_f) - E_N(p_c)`` [J].

    ``beta / (2 m) (p_f - p_c)^2`` with ``p_f = p_c (1 + e_N)`` (eqs. 6.8, C.17),
    which is ``e_N^2 m v_iN^2 / (2 beta)``; for ``beta = 1`` eq. 6.3 / B.9 / D.3.

    Parameters
    ----------
    mass_kg, vin_mps, beta
        As :func:`compression_energy`.
    e_n
        Normal coefficient of restitution ``-v_fN / v_iN`` [-], ``>= 0`` (may exceed 1).

    Examples
    --------
    >>> round(float(restitution_energy(1000.0, -10.0, 0.5)))
    12500
    """
    mass, vin, beta = _normal_args(mass_kg, vin_mps, beta)
    e_n = _restitution_arg(e_n)
    return as_output(e_n**2 * mass * vin**2 / (2.0 * beta))


def normal_energy_change(
    mass_kg: ArrayLike, vin_mps: ArrayLike, e_n: ArrayLike, beta: ArrayLike = 1.0
) -> np.ndarray:
    """Net normal energy change ``-1/2 m v_iN^2 (1 - e_N^2) / beta`` [J] (eq. 6.5).

    Compression (:func:`compression_energy`) plus restitution
    (:func:`restitution_energy`), eqs. 6.4-6.5 / D.4-D.6 for ``beta = 1``.

    Examples
    --------
    Worked example 6A: 1000 kg, 5 m drop, ``e_N = 0.18`` on concrete -> -47.5 kJ:

    >>> v_in = -(2 * 9.81 * 5.0) ** 0.5
    >>> round(float(normal_energy_change(1000.0, v_in, 0.18)) / 1e3, 1)
    -47.5
    """
    mass, vin, beta = _normal_args(mass_kg, vin_mps, beta)
    e_n = _restitution_arg(e_n)
    return as_output(-0.5 * mass * vin**2 * (1.0 - e_n**2) / beta)


def sliding_friction_energy(
    mass_kg: ArrayLike,
    slip_mps: ArrayLike,
    final_impulse_ns: ArrayLike,
    friction: ArrayLike,
    beta1: ArrayLike = 1.0,
    beta2: ArrayLike = 0.0,
) -> np.ndarray:
    """Friction work when the contact slips throughout the impact [J] (eq. 6.9).

    ``E_T = -mu p_f / 2 (2 v_iT - (beta2 + mu beta1) p_f / m)``: the area under the
    tangential pN-v line (C.15a) from 0 to the final normal impulse ``p_f``, times
    ``-mu``. This is the thesis's formula as printed and is only valid while the slip
    keeps its direction up to separation (``v_T(p_f) >= 0``); use
    :func:`friction_energy` when slip may stop during the impact.

    Parameters
    ----------
    mass_kg
        Body mass m [kg].
    slip_mps
        Tangential velocity of the contact point at impact v_iT [m/s]. For a spinning
        body this is the slip velocity ``v_T + r omega`` (eq. 4.15); worked example 6B
        uses the centre-of-mass component.
    final_impulse_ns
        Normal impulse at separation p_f [N s] (eq. C.18).
    friction
        Coulomb friction coefficient mu [-].
    beta1, beta2
        Inertial coefficients (eq. C.11) [-].

    Examples
    --------
    Worked example 6B (thesis -31.3 kJ; the integral with the printed inputs is -30.8):

    >>> e = sliding_friction_energy(3750.0, 10.8, 6665.0, 0.68, 3.00, 2.46)
    >>> round(float(e) / 1e3, 1)
    -30.8
    """
    mass, slip, p_f, mu = _friction_args(mass_kg, slip_mps, final_impulse_ns, friction)
    b1, b2 = np.asarray(beta1, float), np.asarray(beta2, float)
    return as_output(-mu * p_f / 2.0 * (2.0 * slip - (b2 + mu * b1) * p_f / mass))


def friction_energy(
    mass_kg: ArrayLike,
    slip_mps: ArrayLike,
    final_impulse_ns: ArrayLike,
    friction: ArrayLike,
    beta1: ArrayLike = 1.0,
    beta2: ArrayLike = 0.0,
) -> np.ndarray:
    """Friction work at the contact, stopping when the slip stops [J] (eq. 6.9, C.26).

    ``E_T = -mu * integral_0^p* |v_T| dp`` with the slip line
    ``|v_T| = |v_iT| - (beta2 + mu beta1) p / m`` (C.15a) and ``p*`` the smaller of the
    final normal impulse ``p_f`` and the impulse at which slip stops,
    ``p_s = m |v_iT| / (beta2 + mu beta1)`` (C.26 for a sphere). After slip stops the
    contact rolls and friction does no more work. Either slip direction is handled
    (friction always opposes slip), so the result is never positive. When slip does not
    stop before separation this equals :func:`sliding_friction_energy`.

    Exact for a collinear impact (``beta2 = 0``: the normal pN-v line does not depend on
    friction); for ``beta2 != 0`` it keeps the thesis's constant-slip normal line.

    Examples
    --------
    A sphere (beta1 = 3.5) whose slip stops: the loss is the energy that brings the
    contact to rolling, ``-m v_s^2 / (2 beta1)``:

    >>> round(float(friction_energy(100.0, 7.0, 1e4, 0.7, 3.5)))
    -700
    """
    mass, slip, p_f, mu = _friction_args(mass_kg, slip_mps, final_impulse_ns, friction)
    slip = np.abs(slip)
    slope = np.asarray(beta2, float) + mu * np.asarray(beta1, float)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        p_stop = np.where(slope > 0, mass * slip / slope, np.inf)
    p_end = np.minimum(p_f, p_stop)
    return as_output(-mu * (slip * p_end - slope * p_end**2 / (2.0 * mass)))


class ImpactEnergies(NamedTuple):
    """Energy changes of one oblique impact of a rough rotating body (eqs. 6.6-6.9).

    All in [J], negative = taken out of the body; impulses in [N s].
    """

    compression_j: np.ndarray
    restitution_j: np.ndarray
    friction_j: np.ndarray
    total_j: np.ndarray
    compression_impulse_ns: np.ndarray
    final_impulse_ns: np.ndarray


def oblique_impact_energies(
    mass_kg: ArrayLike,
    vin_mps: ArrayLike,
    slip_mps: ArrayLike,
    e_n: ArrayLike,
    friction: ArrayLike,
    beta1: ArrayLike = 1.0,
    beta2: ArrayLike = 0.0,
    beta3: ArrayLike = 1.0,
    *,
    slip_stops: bool = True,
) -> ImpactEnergies:
    """Normal and tangential energy changes of an oblique impact (eqs. 6.6-6.9).

    ``beta = beta3 + mu beta2``; ``p_c = -m v_iN / beta`` (6.6, C.16);
    ``p_f = p_c (1 + e_N)`` (C.17); compression ``-m v_iN^2 / (2 beta)`` (6.7 corrected,
    see :func:`compression_energy`); restitution ``beta (p_f - p_c)^2 / (2 m)`` (6.8);
    friction work (6.9). The total is the work of the contact impulse, i.e. the change
    of the body's whole kinetic energy (translational plus rotational) predicted by
    impact mechanics; the thesis (section 6.3) calls it the translational loss and adds
    the rotational change (6.11) on top.

    Parameters
    ----------
    mass_kg
        Body mass [kg].
    vin_mps
        Normal velocity at impact v_iN [m/s] (negative).
    slip_mps
        Tangential velocity of the contact point at impact [m/s] (``v_T + r omega``).
    e_n
        Normal coefficient of restitution [-].
    friction
        Friction coefficient mu [-].
    beta1, beta2, beta3
        Inertial coefficients (eq. C.11) [-]; defaults are the non-rotating body.
    slip_stops
        True (default): friction stops working when slip stops
        (:func:`friction_energy`). False: the thesis's constant-slip formula 6.9
        (:func:`sliding_friction_energy`).

    Examples
    --------
    Worked example 6B (Tornado #A26), printed inputs:

    >>> r = oblique_impact_energies(3750.0, -4.4, 10.8, 1.30, 0.68, 3.00, 2.46, 4.02)
    >>> round(float(r.compression_impulse_ns)), round(float(r.compression_j) / 1e3, 1)
    (2898, -6.4)
    """
    mass, vin, _ = _normal_args(mass_kg, vin_mps, 1.0)
    e_n = _restitution_arg(e_n)
    mu = nonnegative_array(friction, "friction")
    b1, b2, b3 = (np.asarray(b, float) for b in (beta1, beta2, beta3))
    beta = b3 + mu * b2
    raise_at_first(
        beta <= 0,
        lambda b: f"beta3 + friction * beta2 must be positive (got {b:g})",
        beta,
        source="beta3",
    )
    p_c = compression_impulse(vin, mass, b2, b3, mu)  # eqs. 6.6, C.16
    p_f = final_impulse(p_c, e_n)  # eqs. C.17, C.18
    compression = -mass * vin**2 / (2.0 * beta)
    restitution = beta * (p_f - p_c) ** 2 / (2.0 * mass)
    tangential = friction_energy if slip_stops else sliding_friction_energy
    work = tangential(mass, slip_mps, p_f, mu, b1, b2)
    return ImpactEnergies(
        as_output(compression),
        as_output(restitution),
        as_output(np.asarray(work)),
        as_output(compression + restitution + work),
        as_output(p_c),
        as_output(p_f),
    )


# ------------------------------------------------------------------ argument checks


def _friction_args(
    mass_kg: ArrayLike,
    slip_mps: ArrayLike,
    final_impulse_ns: ArrayLike,
    friction: ArrayLike,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Checked mass, slip velocity, final normal impulse and friction (eq. 6.9)."""
    mass = positive_array(mass_kg, "mass_kg")
    slip = np.asarray(slip_mps, float)
    p_f = nonnegative_array(final_impulse_ns, "final_impulse_ns")
    return mass, slip, p_f, nonnegative_array(friction, "friction")


def _normal_args(
    mass_kg: ArrayLike, vin_mps: ArrayLike, beta: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    mass = positive_array(mass_kg, "mass_kg")
    vin = np.asarray(vin_mps, float)
    reject(vin > 0, "vin_mps", "be <= 0 (toward the ground)", vin, unit="m/s")
    return mass, vin, positive_array(beta, "beta")


def _restitution_arg(e_n: ArrayLike) -> np.ndarray:
    return nonnegative_array(e_n, "e_n")
