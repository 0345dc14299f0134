"""A straight-line rebound: the diagnosis's flexible alternative, not a thesis law.

``vfn = -e_n vin + b_n`` and ``vft = e_t vit + b_t sign(vit)``: the base model's
rebound plus an intercept on each component (m/s). It bends neither with the impact
angle (eq. 5.4) nor with the impact speed (eq. 7.1); it lets a diagnosis ask
whether the rebound departs from constant ``e_n``, ``e_t`` in some way the two named
laws do not describe (on a surveyed path with an assumed launch angle the rebound
normal speed can look flat against the impact speed, which eq. 7.1 would otherwise
be the only candidate to absorb). ``b_n = b_t = 0`` is the base model.

An intercept never turns a rebound round: ``vfn`` stays >= 0 and ``vft`` keeps the
direction it had without the intercept (0 where the intercept would reverse it).
"""

from __future__ import annotations

from numba import njit

from fieldkit.model.effects.spec import EffectSpec, Parameter

SPEC = EffectSpec(
    name="affine_rebound",
    stage="impact",
    summary="rebound velocities a straight line in the impact velocities "
    "(intercepts b_n, b_t): a statistical alternative to the named laws",
    physics="vfn = -e_n vin + b_n, vft = e_t vit + b_t sign(vit)",
    parameters=(
        Parameter(
            "b_n_mps",
            0.5,
            -20.0,
            20.0,
            "m/s",
            "intercept of the rebound normal speed",
            0.0,
        ),
        Parameter(
            "b_t_mps",
            0.0,
            -20.0,
            20.0,
            "m/s",
            "intercept of the rebound tangential speed, along the impact's "
            "tangential direction",
            0.0,
        ),
    ),
    reference="none: an empirical straight line, not a thesis law — the "
    "diagnosis's flexible alternative",
    reads=("vin_mps", "vit_mps"),
    writes=("vfn_mps", "vft_mps"),
    kind="alternative",
    changes_rebound=True,
)


@njit(cache=True)
def rebound(vfn, vft, vit, b_n_mps, b_t_mps):
    """``(vfn, vft)`` with the intercepts added (never turning the rebound round)."""
    vfn = max(vfn + b_n_mps, 0.0)
    if vit > 0.0:
        shifted = vft + b_t_mps
    elif vit < 0.0:
        shifted = vft - b_t_mps
    else:
        shifted = vft
    if shifted * vft < 0.0:
        shifted = 0.0
    return vfn, shifted
