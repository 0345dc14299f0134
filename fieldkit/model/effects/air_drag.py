"""Quadratic air drag in flight: ``a = -k |v| v``, ``k = rho C_d pi r^2 / (2 m)``.

Without drag the flight is the exact parabola. With drag the flight is integrated in
substeps; within each the acceleration is held at its value at the predicted mid-step
velocity (second order), so each substep is a parabola and first contact inside it is
still found exactly. A substep lasts at most the core setting ``drag_dt_s`` and at
most as long as drag takes to change the speed by :data:`STEP_SPEED_CHANGE` (0.2 %):
``dt = min(drag_dt_s, 0.002 / (k |v|))``, so weak drag (big blocks) costs few
substeps and strong drag (small, fast blocks) gets short ones. ``cd = 0`` is the base
model (the exact parabola is used, bit for bit). Drag matters for video tracks of
small, fast blocks; for metre-size blocks it changes flights by millimetres.
"""

from __future__ import annotations

import math

from numba import njit

from fieldkit.model.effects.spec import EffectSpec, Export, Parameter

SPEC = EffectSpec(
    name="air_drag",
    stage="flight",
    summary="quadratic air drag shortens flights",
    physics="a = g - k |v| v, k = rho C_d pi r^2 / (2 m)",
    parameters=(
        Parameter("cd", 0.5, 0.0, 3.0, "-", "drag coefficient of a rough block", 0.0),
        Parameter(
            "air_density_kg_m3",
            1.225,
            0.0,
            2.0,
            "kg/m^3",
            "air density (sea level)",
            None,
        ),
    ),
    reference="none in the thesis (standard quadratic drag)",
    reads=("vi_x_mps", "vi_z_mps", "radius_m", "mass_kg"),
    writes=("vi_x_mps", "vi_z_mps"),
    not_from_impacts="acts in flight; diagnose a video track (flight "
    "residuals) instead",
    exports={
        "CRSP": Export(
            False,
            "CRSP is a lumped-mass model without air drag (thesis §7.2)",
        ),
        "RocFall": Export(
            False,
            "RocFall's lumped mass ignores air resistance",
        ),
        "RAMMS": Export(
            False,
            "RAMMS's flight has no drag input",
        ),
        "Rockyfor3D": Export(
            False,
            "Rockyfor3D's flight is a parabola; it has no drag input",
        ),
        "r.stone": Export(
            False,
            "r.stone's flight is a drag-free parabola (Parab, points.c)",
        ),
    },
)


@njit(cache=True)
def drag_factor(cd, air_density_kg_m3, radius_m, mass_kg):
    """``k = rho C_d pi r^2 / (2 m)`` [1/m]."""
    return air_density_kg_m3 * cd * math.pi * radius_m * radius_m / (2.0 * mass_kg)


#: Largest relative speed change by drag within one substep.
STEP_SPEED_CHANGE = 0.002


@njit(cache=True)
def substep_s(vx, vz, k, max_dt_s):
    """Substep length: ``min(max_dt_s, STEP_SPEED_CHANGE / (k |v|))`` [s]."""
    rate = k * math.sqrt(vx * vx + vz * vz)
    if rate * max_dt_s <= STEP_SPEED_CHANGE:
        return max_dt_s
    return STEP_SPEED_CHANGE / rate


@njit(cache=True)
def substep_acceleration(vx, vz, k, g, dt):
    """Constant ``(ax, az)`` for a substep of ``dt``: drag at the mid-step velocity."""
    speed = math.sqrt(vx * vx + vz * vz)
    ax0 = -k * speed * vx
    az0 = -g - k * speed * vz
    mx = vx + 0.5 * dt * ax0
    mz = vz + 0.5 * dt * az0
    speed = math.sqrt(mx * mx + mz * mz)
    return -k * speed * mx, -g - k * speed * mz
