"""Normal restitution falling with impact speed (thesis eq. 7.1, RocFall/CRSP).

``vfn = e_n |vin| / (1 + (vin/K)^2)``: half the constant-``e_n`` rebound at
``|vin| = K``, unchanged for slow impacts. ``K = inf`` is the base model.
"""

from __future__ import annotations

from numba import njit

from fieldkit.model.effects.spec import RSTONE_FOLDED, EffectSpec, Export, Parameter

SPEC = EffectSpec(
    name="velocity_scaled_restitution",
    stage="impact",
    summary="fast impacts rebound less (soil crushing), RocFall's e_n scaling",
    physics="vfn = e_n |vin| / (1 + (vin/K)^2)",
    parameters=(
        Parameter(
            "k_mps",
            9.144,
            0.1,
            float("inf"),
            "m/s",
            "velocity scale K (RocFall default 9.144 m/s = 30 ft/s)",
            float("inf"),
        ),
    ),
    reference="thesis eq. 7.1",
    reads=("vin_mps",),
    writes=("vfn_mps",),
    changes_rebound=True,
    exports={
        "CRSP": Export(
            True,
            "CRSP's own scaling of Rn (K = 30 ft/s); another K, or no scaling, is "
            "fitted in range under CRSP's law",
        ),
        "RocFall": Export(
            True,
            "'scale Rn by velocity' at RocFall's K = 9.144 m/s; another K or an Rn "
            "above 1 is fitted in range under that law",
        ),
        "RAMMS": Export(
            False,
            "RAMMS has no restitution coefficient to scale; its impacts are plastic "
            "(epsilon = 0) whatever the speed",
        ),
        "Rockyfor3D": Export(
            False,
            "Rockyfor3D draws Rn within the soil type's range; the realised e_n the "
            "scaling produces is compared with the class (mismatch below), the soil "
            "type itself follows the ground description",
        ),
        "r.stone": RSTONE_FOLDED,
    },
)


@njit(cache=True)
def normal_speed_factor(v_in_mps, k_mps):
    """Factor ``1 / (1 + (vin/K)^2)`` on the rebound normal speed (eq. 7.1)."""
    q = v_in_mps / k_mps
    return 1.0 / (1.0 + q * q)
