"""Theoretical impact energy loss beside the measured one (thesis sections 6.1-6.3).

For every impact of an :class:`~fieldkit.impact_table.ImpactTable` where the data allow,
:func:`add_theory_columns` adds

``dke_theory_j``
    The energy that impact mechanics says the contact takes out of the rock [J]
    (negative = loss): the work of the contact impulse, i.e. the areas under the
    [p_N - v] lines (eq. 6.1), normal part ``-1/2 m v_iN^2 (1 - e_N^2)`` (eqs. 6.2,
    6.3, 6.5) plus friction ``-mu * integral |v_T| dp_N`` (eq. 6.9, stopped when the
    slip stops, eq. C.26). It uses the table's *measured* ``e_n`` (so the normal
    rebound is reproduced exactly), the measured ``vin_mps``, the initial slip
    velocity ``v_iT + r omega_i`` (eq. 4.15) and a friction coefficient ``mu``. The
    body is the thesis's collinear rough sphere (App. C.3): contact radius
    ``r = radius_m``, ``r_T = 0`` (so ``beta1 = 1 + r^2/k^2``, ``beta2 = 0``,
    ``beta3 = 1``), ``k = gyration_m``. In rigid-body mechanics this work equals the
    change of the rock's translational *plus* rotational kinetic energy. It is what
    the thesis's worked example 6B computes (eq. 6.7 corrected; see
    :mod:`fieldkit.physics.energy`).

``theory_loss_fraction``
    ``dke_theory_j / dke_j``: how much of the measured translational kinetic-energy
    change the theory explains. Section 6.3 finds about 0.19 (0.29 with the rotational
    change added) at Tornado Mountain #A26 and says the other case studies are similar;
    plastic deformation, fragmentation and roughness the theory does not model take
    the rest. A negative value means the rock *gained* measured kinetic energy at an
    impact where the theory predicts a loss (e.g. spin converted into translation, a
    shallow impact with ``e_n > 1``, or survey error).

The friction term depends on the initial slip ``v_iT + r omega_i``, which field surveys
do not measure: with the spin estimated as ``omega = -v/r`` (eq. 3.17, as ``fieldkit
reduce`` does) the contact is close to rolling and friction takes little; ignoring the
spin (6B) maximises it. On Tornado Mountain boulder A (thesis Table 2-4 reduced by
``fieldkit reduce``, mu = 0.68) the median fraction over the impacts that lost energy
is about 0.01 with the estimated spin and 0.46 with ``ignore_spin=True``; the thesis's
0.19 (6B, eccentric ellipsoid, slip throughout) lies between. Read the fraction as a
bracket, not a measurement.

Both are NaN where the data do not allow them:

* ``mass_kg``, ``radius_m`` or ``gyration_m`` missing;
* ``omega_i_radps`` missing (pass ``ignore_spin=True`` to take the slip velocity as the
  centre-of-mass ``v_iT``, as worked example 6B does);
* ``e_n`` missing or negative, or ``vin_mps >= 0`` (not an impact into the ground);
* ``theory_loss_fraction`` also where ``dke_j`` is 0 or missing.
"""

from __future__ import annotations

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.impact_table import ImpactTable
from fieldkit.physics.energy import friction_energy, normal_energy_change
from fieldkit.physics.impact_mechanics import (
    compression_impulse,
    final_impulse,
    inertial_coefficients,
)

__all__ = ["DEFAULT_FRICTION", "add_theory_columns"]

#: Contact friction coefficient mu: Masuya et al. (2001) block-on-gravel pull tests
#: (thesis section 5.3: concrete 0.59, gravel 0.68, soil 0.90), the value worked
#: example 6B uses for the colluvium at Tornado Mountain.
DEFAULT_FRICTION = 0.68


def add_theory_columns(
    table: ImpactTable, *, friction: float = DEFAULT_FRICTION, ignore_spin: bool = False
) -> ImpactTable:
    """Return a copy of ``table`` with ``dke_theory_j`` and ``theory_loss_fraction``.

    Parameters
    ----------
    table
        Impacts; derived columns are recomputed from the primary ones first
        (:meth:`ImpactTable.derive`).
    friction
        Coulomb friction coefficient mu at the contact [-], ``>= 0``. Default 0.68
        (see :data:`DEFAULT_FRICTION`).
    ignore_spin
        Use ``v_iT`` instead of ``v_iT + r omega_i`` as the initial slip velocity (the
        thesis's worked example 6B), so rows without a spin get a value too.

    Returns
    -------
    ImpactTable
        The derived table plus the two extension columns (see the module docstring for
        what they mean and when they are NaN).

    Raises
    ------
    ArgumentError
        If ``friction`` is negative or not a number.

    Examples
    --------
    >>> import pandas as pd
    >>> t = ImpactTable(pd.DataFrame({"path_id": ["A"], "point": ["1"], "x_m": [0.0],
    ...     "z_m": [0.0], "slope_deg": [0.0], "vi_x_mps": [10.0], "vi_z_mps": [-4.0],
    ...     "vf_x_mps": [5.0], "vf_z_mps": [2.0], "mass_kg": [1000.0],
    ...     "radius_m": [0.5], "gyration_m": [0.3], "omega_i_radps": [-20.0]}))
    >>> out = add_theory_columns(t).frame
    >>> round(float(out.loc[0, "dke_theory_j"])), round(float(out.loc[0, "dke_j"]))
    (-6000, -43500)
    """
    mu = _friction(friction)
    derived = table.derive()
    frame = derived.frame.copy()
    col = derived.column
    mass, radius, gyration = col("mass_kg"), col("radius_m"), col("gyration_m")
    v_in, v_it, e_n = col("vin_mps"), col("vit_mps"), col("e_n")
    omega = np.zeros(len(frame)) if ignore_spin else col("omega_i_radps")

    usable = (
        np.isfinite(mass)
        & (mass > 0)
        & np.isfinite(radius)
        & (radius > 0)
        & np.isfinite(gyration)
        & (gyration > 0)
        & np.isfinite(v_in)
        & (v_in < 0)
        & np.isfinite(v_it)
        & np.isfinite(e_n)
        & (e_n >= 0)
        & np.isfinite(omega)
    )
    theory = np.full(len(frame), np.nan)
    if usable.any():
        m, r, k = mass[usable], radius[usable], gyration[usable]
        vn, e = v_in[usable], e_n[usable]
        slip = v_it[usable] + r * omega[usable]  # eq. 4.15
        beta1, _, _ = inertial_coefficients(k, 0.0, r)  # eq. C.11, r_N = r, r_T = 0
        p_f = final_impulse(compression_impulse(vn, m), e)  # eqs. 4.4, 4.12, C.18
        theory[usable] = normal_energy_change(m, vn, e) + friction_energy(
            m, slip, p_f, mu, beta1
        )
    measured = col("dke_j")
    with np.errstate(divide="ignore", invalid="ignore"):
        fraction = np.where(measured != 0, theory / measured, np.nan)
    frame["dke_theory_j"] = theory
    frame["theory_loss_fraction"] = fraction
    return ImpactTable(frame, source=table.source)


def _friction(friction: float) -> float:
    try:
        mu = float(friction)
    except (TypeError, ValueError):
        raise ArgumentError(
            f"friction must be a number, got {friction!r}", source="friction"
        ) from None
    if not np.isfinite(mu) or mu < 0:
        raise ArgumentError(
            f"friction must be a finite number >= 0, got {mu:g}", source="friction"
        )
    return mu
