"""Oblique rock impact on a fence: redirection and energy split (thesis section 8.2).

A fence inclined up-slope is hit obliquely; the rock is redirected instead of stopped
and the net absorbs only part of the impact energy (Fig. 8.3b). The thesis models the
redirection with the rough-body impact equations of chapter 4 (eqs. 4.20-4.24) in axes
attached to the net:

* **N** normal to the net, pointing back toward the incoming rock, so the impact normal
  velocity is negative; **T** along the net in the direction of the rock's tangential
  motion (down the net in Fig. 8.3b);
* ``theta_i`` is the angle between the incoming velocity and the net;
* spin is positive when the rotation moves the contact point along +T (the thesis's
  "clockwise, positive" in Fig. 8.3), so the slip velocity is ``v_T + r omega`` as on
  the slope, and :func:`fieldkit.physics.impact_mechanics.rough_body_impact` applies
  unchanged.

The energy split (worked example 8B) compares the rock's total energy
``1/2 m v^2 + 1/2 I omega^2`` before and after; the difference is what the fence
absorbs, and the energy efficiency (eq. 8.1) is ``E_f / E_i``.

Worked example 8A is internally inconsistent (docs/thesis-notes.md): with r = 0.43 m,
k = 0.35 m and omega_i = +18 rad/s, eq. 4.20 gives v_fT = 5.4 m/s and eq. 4.22
omega_f = -12.6 rad/s (omega_i = -18 gives 11.6 m/s), not the printed 9.9 m/s and
-11.6 rad/s; only the printed v_f = 11.5 m/s follows from the printed components.
Worked example 8B's energies are exact given its printed velocities.
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
from fieldkit.physics.energy import total_kinetic_energy
from fieldkit.physics.impact_mechanics import rough_body_impact
from fieldkit.physics.restitution import angle_dependent_restitution

__all__ = [
    "FenceEnergySplit",
    "FenceRedirection",
    "energy_efficiency",
    "fence_energy_split",
    "fence_redirection",
]


#: Relative excess of the rebound's energy over the impact's taken as rounding: a
#: rebound computed with e_N <= 1 (which cannot gain energy) reaches 1 + 1e-12.
ENERGY_ROUNDING = 1e-9

#: Why a rebound may not carry more energy than the impact, for the error messages.
_PASSIVE = (
    "a fence is passive and can only absorb energy (thesis ch. 8: the efficiency "
    "E_f/E_i of eq. 8.1 is at most 1)"
)


def _gains_energy(e_i: np.ndarray, e_f: np.ndarray) -> np.ndarray:
    """Where the rebound energy ``e_f`` exceeds the impact energy ``e_i``."""
    return np.asarray(e_f > e_i * (1.0 + ENERGY_ROUNDING))


def _restitution_words(e_n: float, *, given: bool) -> str:
    """The e_N a computed rebound used, and where it came from."""
    return f"e_n {e_n:.3g}" if given else f"e_N {e_n:.3g} (eq. 5.4; no e_n given)"


class FenceEnergySplit(NamedTuple):
    """Energies of a rock before and after hitting a fence (worked example 8B) [J].

    ``absorbed_fraction = absorbed_j / total_in_j``; ``efficiency = total_out_j /
    total_in_j`` (eq. 8.1, as a fraction: 0 when the rock is stopped).
    """

    kinetic_in_j: np.ndarray
    rotational_in_j: np.ndarray
    total_in_j: np.ndarray
    kinetic_out_j: np.ndarray
    rotational_out_j: np.ndarray
    total_out_j: np.ndarray
    absorbed_j: np.ndarray
    absorbed_fraction: np.ndarray
    efficiency: np.ndarray


class FenceRedirection(NamedTuple):
    """Velocities of a rock redirected by a fence (worked example 8A), net axes.

    Velocities [m/s], spin [rad/s], angles [deg] to the net; ``e_n`` is the normal
    coefficient of restitution used; ``slip_stops`` whether the contact reached
    rolling before leaving the net (always, with the default infinite friction).
    """

    v_it_mps: np.ndarray
    v_in_mps: np.ndarray
    v_ft_mps: np.ndarray
    v_fn_mps: np.ndarray
    omega_f_radps: np.ndarray
    speed_out_mps: np.ndarray
    angle_out_deg: np.ndarray
    e_n: np.ndarray
    slip_stops: np.ndarray


def energy_efficiency(
    impact_energy_j: ArrayLike, restitution_energy_j: ArrayLike
) -> np.ndarray:
    """Energy efficiency of a fence ``E_e = E_f / E_i`` [-] (eq. 8.1, as a fraction).

    0 when the fence stops the rock (normal impact, Fig. 8.3a); the thesis quotes
    ``39.2 / 138.8 = 28 %`` for the oblique impact of Fig. 8.3b (section 8.2.3).

    Examples
    --------
    >>> round(float(energy_efficiency(138.8, 39.2)), 2)
    0.28
    """
    e_i = positive_array(impact_energy_j, "impact_energy_j", "J")
    e_f = nonnegative_array(restitution_energy_j, "restitution_energy_j", "J")
    return as_output(e_f / e_i)


def fence_energy_split(
    mass_kg: ArrayLike,
    gyration_m: ArrayLike,
    speed_in_mps: ArrayLike,
    omega_in_radps: ArrayLike,
    speed_out_mps: ArrayLike,
    omega_out_radps: ArrayLike,
) -> FenceEnergySplit:
    """Energy absorbed by a fence from the rock's velocities before and after [J].

    ``E = 1/2 m v^2 + 1/2 I omega^2`` with ``I = m k^2`` (eqs. 6.10, 6.12), before and
    after; absorbed = ``E_i - E_f``; efficiency ``E_f / E_i`` (eq. 8.1). The mass is
    assumed constant during the impact, as in worked example 8B.

    Parameters
    ----------
    mass_kg
        Rock mass m [kg], > 0.
    gyration_m
        Radius of gyration k [m], >= 0.
    speed_in_mps, speed_out_mps
        Speed of the centre of mass before and after [m/s], >= 0.
    omega_in_radps, omega_out_radps
        Spin before and after [rad/s] (sign irrelevant for the energy).

    Raises
    ------
    ArgumentError
        Naming ``speed_out_mps`` when the rock leaves with more energy than it
        brought (beyond :data:`ENERGY_ROUNDING`): a fence cannot add energy
        (eq. 8.1, efficiency at most 1).

    Examples
    --------
    Worked example 8B: 520 kg, k = 0.35 m, 22 -> 11.5 m/s, 18 -> -11.6 rad/s; the
    net absorbs 97.4 kJ, 72 % (printed from rounded sums 136.1 - 38.7):

    >>> s = fence_energy_split(520.0, 0.35, 22.0, 18.0, 11.5, -11.6)
    >>> round(float(s.absorbed_j) / 1e3, 2), round(float(s.absorbed_fraction), 2)
    (97.49, 0.72)
    >>> fence_energy_split(520.0, 0.35, 10.0, 0.0, 30.0, 0.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.ArgumentError: speed_out_mps: the rebound (speed_out_mps 30 m/s, ...
    """
    mass = positive_array(mass_kg, "mass_kg", "kg")
    gyration = nonnegative_array(gyration_m, "gyration_m", "m")
    speed_in = nonnegative_array(speed_in_mps, "speed_in_mps", "m/s")
    speed_out = nonnegative_array(speed_out_mps, "speed_out_mps", "m/s")
    inertia = mass * gyration**2
    ke_i = 0.5 * mass * speed_in**2
    ke_f = 0.5 * mass * speed_out**2
    e_i = np.asarray(total_kinetic_energy(mass, speed_in, inertia, omega_in_radps))
    e_f = np.asarray(total_kinetic_energy(mass, speed_out, inertia, omega_out_radps))
    raise_at_first(
        _gains_energy(e_i, e_f),
        lambda v, w, ef, ei: (
            f"the rebound (speed_out_mps {v:g} m/s, spin_out_radps {w:g} rad/s) "
            f"carries E_f = {ef / 1e3:.2f} kJ, more than the impact's E_i = "
            f"{ei / 1e3:.2f} kJ: {_PASSIVE}"
        ),
        speed_out,
        np.asarray(omega_out_radps, float),
        e_f,
        e_i,
        source="speed_out_mps",
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        efficiency = np.where(e_i > 0, e_f / e_i, np.nan)
    absorbed = e_i - e_f
    return FenceEnergySplit(
        as_output(ke_i),
        as_output(e_i - ke_i),
        as_output(e_i),
        as_output(ke_f),
        as_output(e_f - ke_f),
        as_output(e_f),
        as_output(absorbed),
        as_output(1.0 - efficiency),
        as_output(efficiency),
    )


def fence_redirection(
    speed_mps: ArrayLike,
    angle_deg: ArrayLike,
    omega_radps: ArrayLike,
    *,
    radius_m: ArrayLike,
    gyration_m: ArrayLike,
    e_n: ArrayLike | None = None,
    friction: ArrayLike = np.inf,
) -> FenceRedirection:
    """Rebound of a rough rotating rock off a fence (worked example 8A; eqs. 4.20-4.24).

    ``v_iT = v cos(theta_i)``, ``v_iN = -v sin(theta_i)`` in net axes (module
    docstring); the impact is solved by
    :func:`fieldkit.physics.impact_mechanics.rough_body_impact`.

    Parameters
    ----------
    speed_mps
        Impact speed v_i [m/s], > 0.
    angle_deg
        Impact angle to the net theta_i [deg], in (0, 90] (90 = normal impact).
    omega_radps
        Spin at impact [rad/s], positive when it moves the contact point along +T.
    radius_m, gyration_m
        Contact radius r and radius of gyration k [m].
    e_n
        Normal coefficient of restitution; default ``19.5 theta_i^-1.03`` (eq. 5.4),
        as worked example 8A does.
    friction
        Coulomb friction at the net; ``inf`` (default) = slip stops, eqs. 4.20-4.22.

    Raises
    ------
    ArgumentError
        Naming ``e_n`` when the rebound carries more energy per unit mass
        (``v^2/2 + k^2 omega^2/2``) than the impact: an ``e_n`` above 1, given or
        from eq. 5.4 at a shallow ``angle_deg``, cannot hold for a passive net.

    Examples
    --------
    Worked example 8A inputs (v = 22 m/s, theta_i = 50 deg, omega = +18 rad/s,
    r = 0.43, k = 0.35, the printed e_N = 0.35 of eq. 5.4): v_fN = 5.9 m/s as printed;
    v_fT = 5.4 m/s and omega_f = -12.6 rad/s (printed 9.9 and -11.6: see the module
    docstring).

    >>> r = fence_redirection(22.0, 50.0, 18.0, radius_m=0.43, gyration_m=0.35,
    ...                       e_n=0.35)
    >>> [round(float(x), 1) for x in (r.v_fn_mps, r.v_ft_mps, r.omega_f_radps)]
    [5.9, 5.4, -12.6]
    """
    speed = positive_array(speed_mps, "speed_mps", "m/s")
    angle = np.asarray(angle_deg, float)
    reject((angle <= 0) | (angle > 90), "angle_deg", "be in (0, 90]", angle, unit="deg")
    theta = np.radians(angle)
    v_it = speed * np.cos(theta)
    v_in = -speed * np.sin(theta)
    given_e_n = e_n
    if e_n is None:
        e_n = angle_dependent_restitution(angle)
    result = rough_body_impact(
        v_it,
        v_in,
        omega_radps,
        radius_m=radius_m,
        gyration_m=gyration_m,
        e_n=e_n,
        friction=friction,
    )
    gyration = np.asarray(gyration_m, float)
    e_i = 0.5 * (speed**2 + (gyration * np.asarray(omega_radps, float)) ** 2)
    e_f = 0.5 * (result.v_f_mps**2 + (gyration * result.omega_f_radps) ** 2)
    raise_at_first(
        _gains_energy(e_i, e_f),
        lambda en, a, ef, ei: (
            _restitution_words(en, given=given_e_n is not None)
            + f" at {a:g} deg to the net sends the rock off with {ef / ei:.3g} "
            f"times the energy it brought ({ef:.4g} against {ei:.4g} J/kg): "
            f"{_PASSIVE}; give an e_n of at most 1"
        ),
        np.asarray(e_n, float),
        angle,
        e_f,
        e_i,
        source="e_n",
    )
    return FenceRedirection(
        as_output(v_it),
        as_output(v_in),
        as_output(result.v_ft_mps),
        as_output(result.v_fn_mps),
        as_output(result.omega_f_radps),
        as_output(result.v_f_mps),
        as_output(result.theta_f_deg),
        as_output(np.asarray(e_n, float)),
        as_output(result.slip_stops),
    )
