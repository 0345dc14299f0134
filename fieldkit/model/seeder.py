"""Where and how rocks start: a point with optional SDs, or a release line.

A point seeder starts every rock at ``(x_m, z_m)`` with velocity ``(vx, vz)``, spin
``omega`` and the body's mass, each perturbed by a normal draw with its SD (0 = fixed).
A release line (``x_max_m`` given) draws ``x`` uniformly in ``[x_m, x_max_m]`` and
starts the rock ``height_m`` above the ground there. All draws for all rocks come
from the run's Generator in one fixed order (x, z, vx, vz, omega, mass), vectorised.
Drawn starts below the ground are reflected above it (``z = ground + |z - ground|``)
and drawn masses below 1 % of the body's mass are raised to it (both stated here; a
seeder whose *mean* start is below the ground is refused).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fieldkit.model.profile import Profile


@dataclass(frozen=True)
class Seeder:
    """Start conditions of the rocks (see the module docstring)."""

    x_m: float
    z_m: float
    vx_mps: float = 0.0
    vz_mps: float = 0.0
    omega_radps: float = 0.0
    x_sd_m: float = 0.0
    z_sd_m: float = 0.0
    vx_sd_mps: float = 0.0
    vz_sd_mps: float = 0.0
    omega_sd_radps: float = 0.0
    mass_sd_kg: float = 0.0
    x_max_m: float | None = None
    height_m: float | None = None


@dataclass(frozen=True)
class Starts:
    """Drawn start state of every rock (arrays of length ``rocks``)."""

    x_m: np.ndarray
    z_m: np.ndarray
    vx_mps: np.ndarray
    vz_mps: np.ndarray
    omega_radps: np.ndarray
    mass_kg: np.ndarray


def draw_starts(
    seeder: Seeder,
    profile: Profile,
    mass_kg: float,
    rocks: int,
    rng: np.random.Generator,
) -> Starts:
    """Draw the start state of ``rocks`` rocks with ``rng`` (fixed order, vectorised).

    Examples
    --------
    >>> p = Profile.from_arrays([0, 10], [10, 0], ["rock"])
    >>> rng = np.random.default_rng(1)
    >>> s = draw_starts(Seeder(x_m=1.0, z_m=12.0), p, 100.0, 3, rng)
    >>> s.z_m.tolist()
    [12.0, 12.0, 12.0]
    """
    z = rng.standard_normal((6, rocks))
    if seeder.x_max_m is not None:
        x = seeder.x_m + (seeder.x_max_m - seeder.x_m) * rng.random(rocks)
    else:
        x = seeder.x_m + seeder.x_sd_m * z[0]
    x = np.clip(x, profile.x_m[0], profile.x_m[-1])
    ground = profile.ground_z(x)
    if seeder.height_m is not None:
        height = seeder.height_m + seeder.z_sd_m * z[1]
        elevation = ground + np.abs(height)
    else:
        elevation = seeder.z_m + seeder.z_sd_m * z[1]
        elevation = ground + np.abs(elevation - ground)
    mass = np.maximum(mass_kg + seeder.mass_sd_kg * z[5], 0.01 * mass_kg)
    return Starts(
        x_m=x,
        z_m=elevation,
        vx_mps=seeder.vx_mps + seeder.vx_sd_mps * z[2],
        vz_mps=seeder.vz_mps + seeder.vz_sd_mps * z[3],
        omega_radps=seeder.omega_radps + seeder.omega_sd_radps * z[4],
        mass_kg=mass,
    )
