"""Velocities along the normal impulse during one impact: the [p_N - v] diagram.

Thesis Figs. 4.4, 4.5 and C.3 plot, against the normal impulse ``p_N`` (eq. 4.3), the
normal velocity (rising linearly through zero at maximum compression ``p_c``), the
tangential velocity of the centre of mass and the slip velocity of the contact point
(falling until slip stops, eqs. C.15, C.24). :func:`impulse_history` samples those
lines for one impact, with the breakpoints (``p_c``, slip stop, ``p_f``) included
exactly so a plot or a numerical integral sees the corners.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.physics._validate import reject
from fieldkit.physics.contact_phases import contact_phases


@dataclass(frozen=True)
class ImpulseHistory:
    """Sampled [p_N - v] lines of one impact.

    Attributes
    ----------
    p
        Normal impulse, 0 ... p_f [N s] (per unit mass, m/s, without a mass).
    v_n_mps
        Normal velocity of the contact point (= of the centre for a collinear impact).
    v_t_mps
        Tangential velocity of the centre of mass.
    v_slip_mps
        Slip velocity of the contact point ``v_T + r omega`` (eq. 4.15).
    omega_radps
        Spin.
    p_t
        Tangential (friction) impulse, same units as ``p``.
    p_c, p_f, p_slip_stop
        Maximum compression, separation, and where slip stops (NaN if it does not).
    """

    p: np.ndarray
    v_n_mps: np.ndarray
    v_t_mps: np.ndarray
    v_slip_mps: np.ndarray
    omega_radps: np.ndarray
    p_t: np.ndarray
    p_c: float
    p_f: float
    p_slip_stop: float


def impulse_history(
    v_it_mps: float,
    v_in_mps: float,
    omega_i_radps: float,
    *,
    radius_m: float,
    gyration_m: float,
    e_n: float,
    friction: float = np.inf,
    offset_m: float = 0.0,
    mass_kg: float | None = None,
    points: int = 201,
) -> ImpulseHistory:
    """The [p_N - v] lines of one impact (eqs. 4.3, C.15, C.24, C.25).

    Arguments as :func:`fieldkit.physics.impact_mechanics.rough_body_impact` (scalars:
    one impact). ``points`` evenly spaced impulses from 0 to ``p_f`` are returned, plus
    the breakpoints ``p_c`` and the slip stop.

    Examples
    --------
    >>> h = impulse_history(19.9, -9.3, -15.0, radius_m=0.75, gyration_m=0.47,
    ...                     e_n=0.71, friction=0.5, mass_kg=1000.0)
    >>> round(h.p_c), round(h.p_f), round(h.p_slip_stop)
    (9300, 15903, 4878)
    >>> float(h.v_n_mps[0]), round(float(h.v_n_mps[-1]), 3), float(h.v_slip_mps[-1])
    (-9.3, 6.603, 0.0)
    """
    reject(np.asarray(points) < 2, "points", "be >= 2", points)
    scalars = (v_it_mps, v_in_mps, omega_i_radps, radius_m, gyration_m, e_n, friction)
    if any(np.ndim(x) for x in (*scalars, offset_m)):
        raise ArgumentError("impulse_history takes one impact (scalar arguments)")
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
    mass = 1.0 if mass_kg is None else float(mass_kg)
    reject(~(np.asarray(mass) > 0), "mass_kg", "be > 0", mass)
    q_f = float(ph.q_f)
    q_s = float(ph.q_slip_stop)
    marks = [float(ph.q_c)] + ([q_s] if np.isfinite(q_s) else [])
    q = np.unique(np.concatenate([np.linspace(0.0, q_f, points), marks]))
    v_t, v_n, omega = ph.body_velocities(q)
    slip, normal = ph.contact_velocities(q)
    p_t = ph.tangential_impulse(q)
    if q_s == 0.0 and ph.slip_i != 0.0:
        # infinite friction removes the slip at p = 0: a vertical step from the
        # state at impact to the state after the step
        q = np.concatenate([[0.0], q])
        v_t = np.concatenate([[ph.v_it], v_t])
        omega = np.concatenate([[ph.omega_i], omega])
        slip = np.concatenate([[ph.slip_i], slip])
        normal = np.concatenate([[ph.normal_i], normal])
        p_t = np.concatenate([[0.0], p_t])
    return ImpulseHistory(
        p=mass * q,
        v_n_mps=normal,
        v_t_mps=v_t,
        v_slip_mps=slip,
        omega_radps=omega,
        p_t=mass * p_t,
        p_c=mass * float(ph.q_c),
        p_f=mass * q_f,
        p_slip_stop=mass * q_s if np.isfinite(q_s) else float("nan"),
    )
