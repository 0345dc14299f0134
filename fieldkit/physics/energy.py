"""Energies of a falling rock (thesis ch. 6, appendices B and D).

Basic kinetic, rotational and energy-head terms live here; the impact-energy equations of
chapter 6 extend this module.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics.constants import G


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
    """Rotational kinetic energy ``RE = 1/2 I omega^2`` with ``I = m k^2`` [J] (eq. 6.10)."""
    inertia = np.asarray(mass_kg, float) * np.asarray(gyration_m, float) ** 2
    return 0.5 * inertia * np.asarray(omega_radps, float) ** 2


def energy_head(z_m: ArrayLike, speed_mps: ArrayLike, g: float = G) -> np.ndarray:
    """Energy head ``E = z + v^2 / (2 g)`` [m] (thesis eq. 6.14).

    Examples
    --------
    >>> float(energy_head(100.0, 9.81, g=9.81))
    104.905
    """
    return np.asarray(z_m, float) + np.asarray(speed_mps, float) ** 2 / (2.0 * g)
