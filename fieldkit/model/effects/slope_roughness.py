"""Random local slope at each impact, rougher for small blocks (eq. 7.4, CRSP/RocFall).

The dip used for the impact axes is ``psi + delta`` with ``delta ~ N(0, sd)``::

    sd = scale * sqrt( atan(s / r)^2 + roughness_deg_sd^2 )

``s`` is the material's ``roughness_m`` (CRSP: the height of the asperities within a
block radius), ``r`` the block radius, so the same ground perturbs a small block more
(§7.3.6); ``roughness_deg_sd`` is RocFall's direct SD of the segment dip (Table 7-1).
If the perturbed surface faces away from the incoming rock (``vin >= 0``), the mirror
draw ``-delta`` is used, and if that also fails, ``delta = 0``. ``scale = 0`` is the
base model.
"""

from __future__ import annotations

import math

from numba import njit

from fieldkit.model.effects.spec import EffectSpec, Export, Parameter

SPEC = EffectSpec(
    name="slope_roughness",
    stage="impact",
    summary="random local slope at each impact; small blocks feel rougher ground",
    physics="psi' = psi + N(0, scale * hypot(atan(s/r), sd_psi))",
    parameters=(
        Parameter(
            "scale",
            1.0,
            0.0,
            5.0,
            "-",
            "multiplier on the dip SD",
            0.0,
            held="acts through the slope the table records",
        ),
    ),
    reference="thesis eq. 7.4, section 7.3.6; RocFall Table 7-1",
    reads=("slope_deg", "radius_m"),
    writes=("slope_deg",),
    not_from_impacts="a random local slope scatters rebounds without biasing "
    "them: it shows as a reduced chi-square above 1, not as a held-out gain",
    exports={
        "CRSP": Export(
            True,
            "each cell's S = r tan(dip SD)",
        ),
        "RocFall": Export(
            True,
            "each material's slope roughness (SD of the dip)",
        ),
        "RAMMS": Export(
            False,
            "RAMMS's roughness comes from the DEM and the rock's shape; no random dip "
            "input",
        ),
        "Rockyfor3D": Export(
            False,
            "Rockyfor3D's roughness inputs (rg70/rg20/rg10) carry its Rt (written from"
            " the realised e_t); fieldkit's random local dip has no input of its own "
            "-- Rockyfor3D's rebound geometry on the DEM applies",
        ),
        "r.stone": Export(
            False,
            "r.stone has no roughness input: its ground is the DEM's triangles "
            "(stone.c NewPlane)",
        ),
    },
)


@njit(cache=True)
def dip_sd_rad(roughness_m, roughness_deg_sd, radius_m, scale):
    """SD of the local dip perturbation [rad] (see the module docstring)."""
    crsp = math.atan(roughness_m / radius_m)
    rocfall = math.radians(roughness_deg_sd)
    return scale * math.sqrt(crsp * crsp + rocfall * rocfall)
