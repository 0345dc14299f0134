"""Energy taken by trees the rock strikes in flight (thesis §6.6, Fig. 6.8).

Trees stand at given ``x`` with a trunk diameter (at chest height) and a height. A
flight passing a tree with its centre below the tree top, or a rock sliding or rolling
past it, strikes it with probability
``hit_probability`` (the chance the trunk lies in the rock's lane; for a stand of
density ``n`` per m^2 and lane width ``d + 2r`` it is about ``n (d + 2r)`` per metre).
A strike dissipates the energy the trunk can take,
``E = energy_factor * (d_cm)^energy_exponent`` [J] (Dorren & Berger 2005, Fig. 6.8:
38.7 and 2.31 for beech), capped at the kinetic energy; the speed falls accordingly,
direction kept. The next impact row is flagged ``tree_strike``.
``hit_probability = 0`` is the base model.

In 3-D (:mod:`fieldkit.model.kernel3d`) the stems are placed in plan, so whether a
rock passes within ``d/2 + r`` of one below its top is geometry: every such pass is
a strike, the same law applies there, and ``hit_probability`` must be 1.
"""

from __future__ import annotations

import math

from numba import njit

from fieldkit.model.effects.spec import EffectSpec, Export, Parameter

SPEC = EffectSpec(
    name="tree_impacts",
    stage="flight",
    summary="tree strikes in flight dissipate the energy the trunk can absorb",
    physics="E = c * dbh_cm^p (capped at KE); v' = sqrt(v^2 - 2E/m)",
    parameters=(
        Parameter(
            "hit_probability",
            0.5,
            0.0,
            1.0,
            "-",
            "chance a passing tree is struck (2-D; 1 in 3-D: strikes are geometric)",
            0.0,
        ),
        Parameter(
            "energy_factor",
            38.7,
            0.0,
            1000.0,
            "J/cm^p",
            "c of E = c dbh^p (Dorren & Berger 2005: 38.7)",
            None,
        ),
        Parameter(
            "energy_exponent", 2.31, 1.0, 3.0, "-", "p of E = c dbh^p (2.31)", None
        ),
    ),
    reference="thesis section 6.6, Fig. 6.8 (Dorren and Berger 2005)",
    reads=("x_m", "z_m", "mass_kg"),
    writes=("vi_x_mps", "vi_z_mps", "tree_strike"),
    not_from_impacts="acts in flight; reduced impact velocities come from "
    "flights assumed ballistic, so the table cannot show it",
    exports={
        "CRSP": Export(
            False,
            "no tree-impact input was found for CRSP 4.0",
        ),
        "RocFall": Export(
            False,
            "RocFall's lumped mass has no trees (barriers only); the trees are not "
            "exported",
        ),
        "RAMMS": Export(
            False,
            "forest is set in RAMMS by polygons (not written)",
        ),
        "Rockyfor3D": Export(
            False,
            "Rockyfor3D's forest inputs (tree file or nrtrees/dbh grids, §2.2) are not"
            " written: the run is without forest",
        ),
        "r.stone": Export(
            False,
            "r.stone has no forest or tree input",
        ),
    },
)


@njit(cache=True)
def speed_after_strike(speed_mps, mass_kg, diameter_m, energy_factor, energy_exponent):
    """Speed after striking a trunk of ``diameter_m`` (0 when it takes all the KE)."""
    energy_j = energy_factor * math.pow(diameter_m * 100.0, energy_exponent)
    v2 = speed_mps * speed_mps - 2.0 * energy_j / mass_kg
    return math.sqrt(v2) if v2 > 0.0 else 0.0
