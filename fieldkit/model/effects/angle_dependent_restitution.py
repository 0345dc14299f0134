"""Normal restitution falling with the impact angle: ``e_n = a theta_i^(-b)`` (eq. 5.4).

fieldkit applies it as a scaling of the material's ``e_n`` so that the material SD
still applies and ``b = 0`` is exactly the base model::

    e_n(theta_i) = e_n,draw * (theta_i / theta_ref)^(-b)

The literal eq. 5.4 is the same law with ``e_n,material = a theta_ref^(-b)``: give
``a > 0`` and ``e_n = a theta_i^(-b) * (e_n,draw / e_n,mean)`` is used instead (thesis
best fit a = 19.5, b = 1.03: 0.71 at 25 deg, 0.35 at 50 deg). ``a = 0`` (the default)
selects the material-scaled form. ``theta_i`` is the acute angle between the impact
velocity and the ground, in degrees, clipped to [1, 90] deg so grazing impacts stay
finite.
"""

from __future__ import annotations

import math

from numba import njit

from fieldkit.model.effects.spec import RSTONE_FOLDED, EffectSpec, Export, Parameter

SPEC = EffectSpec(
    name="angle_dependent_restitution",
    stage="impact",
    summary="normal restitution falls with the impact angle (shallow impacts bounce)",
    physics="e_n = e_n,material * (theta_i/theta_ref)^(-b); with a > 0: "
    "e_n = a * theta_i^(-b) (eq. 5.4)",
    parameters=(
        Parameter("b", 1.03, 0.0, 3.0, "-", "exponent of eq. 5.4 (thesis 1.03)", 0.0),
        Parameter(
            "theta_ref_deg",
            30.0,
            1.0,
            90.0,
            "deg",
            "impact angle at which e_n equals the material e_n",
            None,
            held="trades exactly with the material e_n (e_n theta_ref^b is one number)",
        ),
        Parameter(
            "a",
            0.0,
            0.0,
            100.0,
            "-",
            "literal eq. 5.4 coefficient (thesis 19.5); 0 = scale the material e_n",
            0.0,
            held="a = 0 or a > 0 selects the form of eq. 5.4; with a > 0 it trades "
            "exactly with the material e_n",
        ),
    ),
    reference="thesis eq. 5.4, section 5.2.3",
    reads=("theta_i_deg", "e_n"),
    writes=("e_n",),
    changes_rebound=True,
    exports={
        "CRSP": Export(
            False,
            "CRSP's Rn depends on the impact velocity (eq. 7.1), not on the impact "
            "angle (eq. 5.4): Rn, Rt are fitted in range to the rebounds it realises",
        ),
        "RocFall": Export(
            False,
            "RocFall's lumped-mass Rn is scaled by velocity or by mass only; no "
            "impact-angle law for Rn was found in its documentation: Rn, Rt are "
            "fitted in range to the rebounds the law realises",
        ),
        "RAMMS": Export(
            False,
            "RAMMS has no restitution coefficient: the rebound at any angle comes from"
            " the rigid rock's shape, rotation and the slip-dependent ground friction",
        ),
        "Rockyfor3D": Export(
            False,
            "Rockyfor3D draws Rn within the soil type's range whatever the impact "
            "angle; the realised e_n it produces is compared with the class (mismatch "
            "below), the soil type itself follows the ground description",
        ),
        "r.stone": RSTONE_FOLDED,
    },
)

THETA_MIN_DEG = 1.0


@njit(cache=True)
def normal_restitution(e_n_draw, e_n_mean, theta_i_deg, b, theta_ref_deg, a):
    """Angle-dependent ``e_n`` from the material draw (see the module docstring)."""
    theta = min(max(theta_i_deg, THETA_MIN_DEG), 90.0)
    if b == 0.0 and a == 0.0:
        return e_n_draw
    if a > 0.0:
        ratio = e_n_draw / e_n_mean if e_n_mean > 0.0 else 1.0
        return a * math.pow(theta, -b) * ratio
    return e_n_draw * math.pow(theta / theta_ref_deg, -b)
