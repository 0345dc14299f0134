"""Volume (and mass) lost along the path (thesis §6.5, eqs. 6.15 and 6.16).

At each impact the volume ratio is::

    Omega / Omega_0 = 1 / (1 + x lambda) * n^(-p)

with ``x`` the horizontal distance from the release point [m] (eq. 6.15,
``rate_per_m`` = lambda: 0.0035-0.03 /m in §6.5) and ``n`` the impact number
(eq. 6.16, ``impact_exponent`` = p: 0.8 at Tornado Mountain; default 0 = off). Mass
scales with the ratio; radius and radius of gyration with its cube root (the shape is
kept). ``rate_per_m = 0`` and ``impact_exponent = 0`` are the base model.
"""

from __future__ import annotations

import math

from numba import njit

from fieldkit.model.effects.spec import EffectSpec, Export, Parameter

SPEC = EffectSpec(
    name="mass_loss",
    stage="impact",
    summary="the block loses volume with distance and impacts",
    physics="Omega/Omega0 = n^(-p) / (1 + x lambda)",
    parameters=(
        Parameter(
            "rate_per_m", 0.01, 0.0, 1.0, "1/m", "lambda of eq. 6.15 (0.0035-0.03)", 0.0
        ),
        Parameter(
            "impact_exponent", 0.0, 0.0, 2.0, "-", "p of eq. 6.16 (thesis 0.8)", 0.0
        ),
    ),
    reference="thesis eqs. 6.15, 6.16, section 6.5",
    reads=("x_m",),
    writes=("mass_kg", "radius_m", "gyration_m"),
    not_from_impacts="changes mass and size along the path, not the rebound "
    "velocities an impact table measures",
    exports={
        "CRSP": Export(
            False,
            "CRSP's rock keeps its mass (no breakage)",
        ),
        "RocFall": Export(
            False,
            "RocFall's lumped-mass rock keeps its mass (no breakage or abrasion)",
        ),
        "RAMMS": Export(
            False,
            "RAMMS's rock keeps its shape and mass during a run",
        ),
        "Rockyfor3D": Export(
            False,
            "Rockyfor3D's block keeps its volume during a run (its volume variation is"
            " a setting of the run, §2.5, not fragmentation)",
        ),
        "r.stone": Export(
            False,
            "r.stone's block is a point whose mass never enters its kinematics: no "
            "fragmentation or mass loss",
        ),
    },
)


@njit(cache=True)
def volume_ratio(distance_m, impact_number, rate_per_m, impact_exponent):
    """``Omega / Omega_0`` after ``impact_number`` impacts and ``distance_m`` (>= 0)."""
    ratio = 1.0 / (1.0 + abs(distance_m) * rate_per_m)
    if impact_exponent != 0.0 and impact_number > 1:
        ratio *= math.pow(impact_number, -impact_exponent)
    return ratio
