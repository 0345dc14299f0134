"""Walk-through: why an impact loses energy, and what a fence absorbs (thesis ch. 4, 8).

1. Worked example 4A: a 1.5 m sphere hits colluvium at 22 m/s, 25 deg, spinning at
   -15 rad/s. The rough-rotating-body equations (4.20-4.24) give the rebound; e_N comes
   from the field relation e_N = 19.5 theta_i^-1.03 (eq. 5.4).
2. The same impact without spin: the rock leaves slower and steeper.
3. Worked example 8B: a 520 kg rock hits an attenuator fence; energy split and
   efficiency (eq. 8.1).

Run:  python examples/impact_and_fence.py
"""

from __future__ import annotations

import numpy as np

from fieldkit.physics.bodies import shape_body
from fieldkit.physics.fences import fence_energy_split
from fieldkit.physics.impact_mechanics import rough_body_impact
from fieldkit.physics.local_axes import to_local
from fieldkit.physics.restitution import angle_dependent_restitution


def main() -> None:
    sphere = shape_body("sphere", (0.75,))  # radius 0.75 m, 26 kN/m3
    speed, theta_i = 22.0, 25.0
    v_it, v_in = (
        speed * np.cos(np.radians(theta_i)),
        -speed * np.sin(np.radians(theta_i)),
    )
    e_n = angle_dependent_restitution(theta_i)
    print(
        f"sphere: m {sphere.mass_kg:.0f} kg, k {sphere.gyration_m:.3f} m; e_N {e_n:.3f}"
    )
    for spin in (-15.0, 0.0):
        r = rough_body_impact(
            v_it,
            v_in,
            spin,
            radius_m=sphere.radius_m,
            gyration_m=sphere.gyration_m,
            e_n=e_n,
            mass_kg=sphere.mass_kg,
        )
        vft, vfn, wf = float(r.v_ft_mps), float(r.v_fn_mps), float(r.omega_f_radps)
        thf, de_kj = float(r.theta_f_deg), float(r.energy_change_j) / 1e3
        print(
            f"omega_i {spin:6.1f}: v_fT {vft:5.2f}  v_fN {vfn:4.2f}  omega_f {wf:6.2f}"
            f"  theta_f {thf:5.2f} deg  energy change {de_kj:7.1f} kJ"
        )
    print("thesis 4A: v_fT 17.5, v_fN 6.6, omega_f -23.3, theta_f 20.7 (spin -15)")

    split = fence_energy_split(520.0, 0.35, 22.0, 18.0, 11.5, -11.6)
    e_in, absorbed = float(split.total_in_j) / 1e3, float(split.absorbed_j) / 1e3
    share, efficiency = float(split.absorbed_fraction), float(split.efficiency)
    print(
        f"fence 8B: in {e_in:.1f} kJ, absorbed {absorbed:.1f} kJ ({100 * share:.0f} %),"
        f" efficiency {100 * efficiency:.0f} % (thesis: 97.4 kJ, 72 %)"
    )
    # The local-axes helper is what every impact computation shares.
    vt, vn = to_local(10.0, -5.0, 30.0)
    print(f"(10, -5) m/s on a 30 deg slope: v_T {float(vt):.2f}, v_N {float(vn):.2f}")


if __name__ == "__main__":
    main()
