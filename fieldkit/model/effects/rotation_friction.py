"""The rough rotating body at impact: slip turned into rolling (eqs. 4.20-4.22, App. C).

Spin ``omega`` is a state carried unchanged through flight. At an impact with
tangential velocity ``vit`` and spin ``omega_i`` the contact point slips at
``v_s = vit + r omega_i``; the tangential impulse (per unit mass) that stops the slip
is ``J = v_s / (1 + r^2/k^2)``, limited by Coulomb friction to
``|J| <= mu (1 + e_n) |vin|``. With coupling ``c`` in [0, 1]::

    vft     = e_t vit - c J
    omega_f = (1 - c) (-vft / r) + c (omega_i - (r/k^2) J)

``c = 0`` is the base model's spin (rolling after each impact, ``omega = -vft/r``,
eq. 7.5, as RocFall/CRSP: spin is reported, it does not act); ``c = 1`` with
``e_t = 1`` is the thesis's rough rotating body (worked example 4A). A rock spinning
forward faster than it rolls (``omega < -vit/r``, negative = clockwise for travel to
+x) has ``J < 0``: the ground throws it forward, flattening the trajectory (§4.6.4).
"""

from __future__ import annotations

from numba import njit

from fieldkit.model.effects.spec import RSTONE_FOLDED, EffectSpec, Export, Parameter

SPEC = EffectSpec(
    name="rotation_friction",
    stage="impact",
    summary="spin carried through flight; friction at the contact turns slip into "
    "rolling and spin into translation",
    physics="J = (vit + r w)/(1 + r^2/k^2), |J| <= mu (1+e_n)|vin|; "
    "vft = e_t vit - c J; w_f = (1-c)(-vft/r) + c (w - r J/k^2)",
    parameters=(
        Parameter(
            "friction", 0.5, 0.0, 2.0, "-", "contact friction coefficient mu", None
        ),
        Parameter(
            "coupling",
            1.0,
            0.0,
            1.0,
            "-",
            "weight c of the rigid-body impulse (0 = base model rolling spin)",
            0.0,
        ),
    ),
    reference="thesis eqs. 4.20-4.22, section 4.6.4, appendix C",
    reads=("vit_mps", "vin_mps", "omega_i_radps", "radius_m", "gyration_m"),
    writes=("vft_mps", "omega_f_radps"),
    changes_rebound=True,
    exports={
        "CRSP": Export(
            False,
            "CRSP computes the rotation itself (w = v_T / r and the shape's moment of "
            "inertia, thesis §7.3.7); fieldkit's contact friction and coupling have "
            "no CRSP input",
        ),
        "RocFall": Export(
            True,
            "'consider rotational velocity' (on/off only: RocFall's own rotation, its "
            "friction and coupling are not written)",
        ),
        "RAMMS": Export(
            False,
            "RAMMS computes rotation from the rigid rock's contact (its own friction "
            "law, mu_min to mu_max); no lumped coupling parameter",
        ),
        "Rockyfor3D": Export(
            False,
            "Rockyfor3D computes Rt from the obstacle heights; the tangential rebound "
            "this coupling realises is in the realised e_t that rg70/rg20/rg10 are "
            "inverted from",
        ),
        "r.stone": RSTONE_FOLDED,
    },
)


@njit(cache=True)
def impact(v_it, v_in, e_t, e_n, omega_i, radius_m, gyration_m, mu, coupling):
    """``(vft, omega_f)`` after an impact (see the module docstring)."""
    vft = e_t * v_it
    if coupling == 0.0:
        return vft, -vft / radius_m
    ratio = radius_m * radius_m / (gyration_m * gyration_m)
    j = (v_it + radius_m * omega_i) / (1.0 + ratio)
    limit = mu * (1.0 + e_n) * abs(v_in)
    if j > limit:
        j = limit
    elif j < -limit:
        j = -limit
    vft = vft - coupling * j
    omega_rigid = omega_i - radius_m * j / (gyration_m * gyration_m)
    return vft, (1.0 - coupling) * (-vft / radius_m) + coupling * omega_rigid
