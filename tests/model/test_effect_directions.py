"""Each effect moves results the way its physics says, by the amount it says."""

from __future__ import annotations

import math

import numpy as np
import pytest
from model_builders import build
from scipy.integrate import solve_ivp

from fieldkit.model import model_from_dict, simulate
from fieldkit.model.reference import simulate_one_rock

G = 9.81


def incline(effects, e_n=0.45, e_t=0.85, radius_m=0.3, mass_kg=300.0, **material):
    return model_from_dict(
        {
            "profile": {"x_m": [0, 300], "z_m": [200, 200 - 300 * math.tan(0.6)],
                        "material": "m"},
            "materials": {"m": {"e_n": e_n, "e_t": e_t, "friction_deg": 30,
                                **material}},
            "body": {"mass_kg": mass_kg, "radius_m": radius_m, "gyration_m": 0.2},
            "seeder": {"x_m": 1, "z_m": 202},
            "effects": effects,
        }
    )  # fmt: skip


def test_negative_spin_flattens_the_rebound_by_the_rough_body_impulse():
    model = incline({"rotation_friction": {"friction": 0.5, "coupling": 1.0}})
    still = simulate_one_rock(model, 0, x_m=1.0, z_m=202.0, vx_mps=4.0)
    spun = simulate_one_rock(model, 0, x_m=1.0, z_m=202.0, vx_mps=4.0, omega_radps=-60)
    # same first impact, flatter rebound (section 4.6.4)
    assert spun.column("x_m")[0] == still.column("x_m")[0]

    def rebound_angle(one):
        vx, vz = one.column("vf_x_mps")[0], one.column("vf_z_mps")[0]
        return math.degrees(math.atan2(vz, vx)) + math.degrees(0.6)  # to the ground

    assert rebound_angle(spun) < rebound_angle(still) - 5
    assert spun.column("x_m")[1] - spun.column("x_m")[0] > 0  # still flies on
    # the impulse by hand: eqs. 4.20-4.22 with r = 0.3, k = 0.2, mu = 0.5
    vx, vz = 4.0, spun.column("vi_z_mps")[0]
    c, s = math.cos(0.6), math.sin(0.6)
    vit, vin = vx * c - vz * s, vx * s + vz * c
    j = (vit + 0.3 * -60) / (1 + 0.3**2 / 0.2**2)
    j = max(j, -0.5 * (1 + 0.45) * abs(vin))
    vft = 0.85 * vit - j
    got_vft = spun.column("vf_x_mps")[0] * c - spun.column("vf_z_mps")[0] * s
    assert got_vft == pytest.approx(vft, rel=1e-12)
    omega = -60 - 0.3 * j / 0.2**2
    assert spun.column("omega_f_radps")[0] == pytest.approx(omega, rel=1e-12)


def test_roughness_raises_bounce_heights():
    heights = []
    for effects in ({}, {"slope_roughness": {"scale": 1.0}}):
        model = incline(effects, roughness_m=0.15, e_n=0.35)
        res = simulate(model, 3000, np.random.default_rng(4), analysis_x_m=[60, 90])
        h = np.concatenate([p.height_m[p.crossed] for p in res.analysis])
        heights.append((h.mean(), h.std() / math.sqrt(h.size)))
    (smooth, se0), (rough, se1) = heights
    assert rough > smooth + 4 * math.hypot(se0, se1)


def test_rough_steep_faces_give_dips_the_impact_table_accepts():
    # issue 17: a 70 deg face with a roughness SD of ~60 deg drew local dips past
    # 180 deg, which the ImpactTable (ARCHITECTURE §2: (-180, 180]) refused mid-run
    model = model_from_dict(
        {
            "profile": {"x_m": [0, 10, 60], "z_m": [60, 32.5, 0],
                        "material": ["face", "soil"]},
            "materials": {
                "face": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30,
                         "roughness_m": 0.5, "roughness_deg_sd": 30.0},
                "soil": {"e_n": 0.3, "e_t": 0.7, "friction_deg": 35},
            },
            "body": {"mass_kg": 100.0, "radius_m": 0.3, "gyration_m": 0.19},
            "seeder": {"x_m": 0.5, "z_m": 60, "vx_mps": 1.0},
            "effects": {"slope_roughness": {"scale": 1.0}},
        }
    )  # fmt: skip
    res = simulate(model, 2000, np.random.default_rng(7), record_impacts=True)
    dip = res.impact_table.frame["slope_deg"].to_numpy(float)
    assert dip.size > 2000 and np.all((dip > -180.0) & (dip <= 180.0))
    assert np.any(np.abs(dip) > 90.0)  # local overhangs drawn, and kept as such


def test_smaller_blocks_feel_rougher_ground():
    from fieldkit.model.effects.slope_roughness import dip_sd_rad

    assert dip_sd_rad(0.1, 0.0, 0.1, 1.0) == pytest.approx(math.pi / 4)
    assert dip_sd_rad(0.1, 0.0, 1.0, 1.0) < dip_sd_rad(0.1, 0.0, 0.2, 1.0)
    assert dip_sd_rad(0.1, 3.0, 1.0, 2.0) == pytest.approx(
        2 * math.hypot(math.atan(0.1), math.radians(3.0))
    )


def flat_throw(effects, mass_kg=1.3, radius_m=0.05):
    return model_from_dict(
        {
            "profile": {"x_m": [0, 400], "z_m": [0, 0], "material": "m"},
            "materials": {"m": {"e_n": 0.3, "e_t": 0.8, "friction_deg": 30}},
            "body": {"mass_kg": mass_kg, "radius_m": radius_m},
            "seeder": {"x_m": 0, "z_m": 20},
            "effects": effects,
        }
    )


def test_drag_shortens_flights_and_matches_a_fine_ode_solution():
    cd, rho, m, r = 0.8, 1.225, 1.3, 0.05
    k = rho * cd * math.pi * r * r / (2 * m)
    start = dict(x_m=0.0, z_m=20.0, vx_mps=25.0, vz_mps=8.0)
    free = simulate_one_rock(flat_throw({}), 0, **start)
    dragged = simulate_one_rock(flat_throw({"air_drag": {"cd": cd}}), 0, **start)

    def rhs(t, y):
        v = math.hypot(y[2], y[3])
        return [y[2], y[3], -k * v * y[2], -G - k * v * y[3]]

    def ground(t, y):
        return y[1]

    ground.terminal, ground.direction = True, -1
    sol = solve_ivp(rhs, (0, 20), [0, 20, 25, 8], method="RK45", events=ground,
                    rtol=1e-11, atol=1e-12)  # fmt: skip
    x_ref = sol.y_events[0][0][0]
    x_free = 25 * (8 + math.sqrt(64 + 2 * G * 20)) / G
    assert free.column("x_m")[0] == pytest.approx(x_free, rel=1e-12)
    assert dragged.column("x_m")[0] < x_free - 1.0  # drag shortens the flight
    assert abs(dragged.column("x_m")[0] - x_ref) < 0.01
    assert dragged.column("t_s")[0] == pytest.approx(sol.t_events[0][0], abs=1e-3)


def test_angle_and_velocity_laws_scale_e_n_as_documented():
    model = build({"angle_dependent_restitution": {"b": 1.03}})
    f = simulate(model, 50, np.random.default_rng(2), record_impacts=True)
    f = f.impact_table.frame
    fly = f["vfn_mps"] > 0.5
    mat_e_n = f["material"].map({"rock": 0.55, "talus": 0.45, "soil": 0.3})
    theta = f["theta_i_deg"].clip(1, 90)
    want = mat_e_n * (theta / 30.0) ** -1.03
    np.testing.assert_allclose(f["e_n"][fly], want[fly], rtol=1e-9)
    assert (f["e_n"][fly & (theta < 30)] > mat_e_n[fly & (theta < 30)]).all()

    model = build({"velocity_scaled_restitution": {"k_mps": 9.144}})
    f = simulate(model, 50, np.random.default_rng(2), record_impacts=True)
    f = f.impact_table.frame
    fly = f["vfn_mps"] > 0.5
    mat_e_n = f["material"].map({"rock": 0.55, "talus": 0.45, "soil": 0.3})
    want = mat_e_n / (1 + (f["vin_mps"] / 9.144) ** 2)
    np.testing.assert_allclose(f["e_n"][fly], want[fly], rtol=1e-9)


def test_literal_eq_5_4_reproduces_the_thesis_values():
    from fieldkit.model.effects.angle_dependent_restitution import normal_restitution

    # thesis: theta_i = 25 deg -> 0.71; 50 deg -> 0.35 (a = 19.5, b = 1.03)
    assert normal_restitution(0.5, 0.5, 25.0, 1.03, 30.0, 19.5) == pytest.approx(
        0.71, abs=0.005
    )
    assert normal_restitution(0.5, 0.5, 50.0, 1.03, 30.0, 19.5) == pytest.approx(
        0.35, abs=0.005
    )


def test_mass_loss_follows_eq_6_15_and_6_16():
    model = build({"mass_loss": {"rate_per_m": 0.02, "impact_exponent": 0.8}})
    res = simulate(model, 20, np.random.default_rng(8), record_impacts=True)
    f = res.impact_table.frame
    n = f["point"].astype(int)
    ratio = 1 / (1 + 0.02 * (f["x_m"] - 1.0)) * np.where(n > 1, n**-0.8, 1.0)
    np.testing.assert_allclose(f["mass_kg"], 400 * ratio, rtol=1e-12)
    np.testing.assert_allclose(f["radius_m"], 0.33 * ratio ** (1 / 3), rtol=1e-12)


def test_tree_strikes_take_energy_and_shorten_runout():
    base = simulate(build(), 500, np.random.default_rng(9))
    model = build({"tree_impacts": {"hit_probability": 1.0}})
    res = simulate(model, 500, np.random.default_rng(9))
    assert res.runout_x_m.mean() < base.runout_x_m.mean() - 1.0
    from fieldkit.model.effects.tree_impacts import speed_after_strike

    # 0.3 m trunk: E = 38.7 * 30^2.31 J
    e = 38.7 * 30**2.31
    assert speed_after_strike(30.0, 400.0, 0.3, 38.7, 2.31) == pytest.approx(
        math.sqrt(900 - 2 * e / 400)
    )
    assert speed_after_strike(20.0, 400.0, 0.3, 38.7, 2.31) == 0.0


def test_a_flight_through_a_tree_loses_the_trunk_energy():
    data = {
        "profile": {"x_m": [0, 400], "z_m": [0, 0], "material": "m"},
        "materials": {"m": {"e_n": 0.3, "e_t": 0.8, "friction_deg": 30}},
        "body": {"mass_kg": 100.0, "radius_m": 0.3},
        "seeder": {"x_m": 0, "z_m": 20},
        "trees": {"x_m": [20.0], "diameter_m": [0.1], "height_m": [30.0]},
        "effects": {"tree_impacts": {"hit_probability": 1.0}},
    }
    one = simulate_one_rock(model_from_dict(data), 0, x_m=0.0, z_m=20.0, vx_mps=25.0,
                            vz_mps=8.0)  # fmt: skip
    t = 20.0 / 25.0
    z, vz = 20 + 8 * t - G * t * t / 2, 8 - G * t
    v = math.hypot(25.0, vz)
    scale = math.sqrt(v * v - 2 * 38.7 * 10**2.31 / 100.0) / v
    vx2, vz2 = 25 * scale, vz * scale
    t2 = (vz2 + math.sqrt(vz2 * vz2 + 2 * G * z)) / G
    assert one.column("tree_strike")[0] == 1.0
    assert one.column("tree_strike")[1] == 0.0
    assert one.column("x_m")[0] == pytest.approx(20 + vx2 * t2, rel=1e-12)
    assert one.column("vi_z_mps")[0] == pytest.approx(vz2 - G * t2, rel=1e-12)
    assert one.column("t_s")[0] == pytest.approx(t + t2, rel=1e-12)
