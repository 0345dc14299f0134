"""The core against closed-form answers: flights, bounces, slides, energy."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fieldkit.model import model_from_dict, simulate
from fieldkit.model.reference import simulate_one_rock
from fieldkit.model.results import EXITED_DOWNSLOPE, STOPPED

G = 9.81


def flat_model(e_n=0.5, e_t=0.9, friction_deg=30.0, **core):
    return model_from_dict(
        {
            "profile": {"x_m": [0, 1000], "z_m": [0, 0], "material": "m"},
            "materials": {"m": {"e_n": e_n, "e_t": e_t, "friction_deg": friction_deg}},
            "body": {"mass_kg": 10, "radius_m": 0.1},
            "seeder": {"x_m": 0, "z_m": 5},
            "core": core,
        }
    )


def test_bounces_on_a_floor_follow_the_closed_form_then_slide_and_stop():
    h, vx, e_n, e_t = 5.0, 2.0, 0.5, 0.9
    one = simulate_one_rock(flat_model(e_n, e_t), 0, x_m=0.0, z_m=h, vx_mps=vx)
    t = math.sqrt(2 * h / G)
    x, vz, u = vx * t, G * t, vx
    expected = []  # (t, x, vi_z, vf_z)
    while True:
        expected.append((t, x, -vz, e_n * vz))
        u *= e_t
        vz *= e_n
        if vz < 0.5:  # slide_vn_mps default
            break
        t += 2 * vz / G
        x += u * 2 * vz / G
    assert len(one.impacts) == len(expected) == 5
    np.testing.assert_allclose(one.column("t_s"), [e[0] for e in expected], rtol=1e-12)
    np.testing.assert_allclose(one.column("x_m"), [e[1] for e in expected], rtol=1e-12)
    np.testing.assert_allclose(
        one.column("vi_z_mps"), [e[2] for e in expected], rtol=1e-12
    )
    np.testing.assert_allclose(
        one.column("vf_z_mps"), [e[3] for e in expected], rtol=1e-12
    )
    # then slides from the last impact with u and stops after u^2 / (2 g tan phi)
    assert one.state == STOPPED
    stop = expected[-1][1] + u**2 / (2 * G * math.tan(math.radians(30)))
    assert one.runout_x_m == pytest.approx(stop, rel=1e-12)


def test_slide_on_an_incline_stops_where_eq_7_3_says():
    psi, phi, e_t = 20.0, 30.0, 0.8
    s = math.tan(math.radians(psi))
    model = model_from_dict(
        {
            "profile": {"x_m": [0, 200], "z_m": [100, 100 - 200 * s], "material": "m"},
            "materials": {"m": {"e_n": 0.0, "e_t": e_t, "friction_deg": phi}},
            "body": {"mass_kg": 10, "radius_m": 0.1},
            "seeder": {"x_m": 10, "z_m": 100},
        }
    )
    one = simulate_one_rock(model, 0, x_m=10.0, z_m=100.0, vx_mps=6.0)
    assert len(one.impacts) == 1
    x1 = one.column("x_m")[0]
    # independent first contact: 100 - g t^2/2 = 100 - s (10 + 6 t)
    t1 = (6 * s + math.sqrt((6 * s) ** 2 + 2 * G * 10 * s)) / G
    assert x1 == pytest.approx(10 + 6 * t1, rel=1e-12)
    p = math.radians(psi)
    v_t = 6.0 * math.cos(p) + G * t1 * math.sin(p)  # tangential (down-slope)
    a = G * (math.sin(p) - math.cos(p) * math.tan(math.radians(phi)))
    dist = (e_t * v_t) ** 2 / (-2 * a)
    assert one.state == STOPPED
    assert one.runout_x_m == pytest.approx(x1 + dist * math.cos(p), rel=1e-12)


def test_perfectly_elastic_rock_keeps_its_energy_head():
    model = model_from_dict(
        {
            "profile": {
                "x_m": [0, 15, 30, 42, 60, 90],
                "z_m": [60, 48, 30, 27, 12, 0],
                "material": "m",
            },
            "materials": {"m": {"e_n": 1.0, "e_t": 1.0, "friction_deg": 30}},
            "body": {"mass_kg": 10, "radius_m": 0.1},
            "seeder": {"x_m": 1, "z_m": 62, "vx_mps": 2.0},
            "core": {"slide_vn_mps": 0.0},
        }
    )
    one = simulate_one_rock(model, 0, x_m=1.0, z_m=62.0, vx_mps=2.0)
    head0 = 62 + 2.0**2 / (2 * G)
    z = one.column("z_m")
    vi2 = one.column("vi_x_mps") ** 2 + one.column("vi_z_mps") ** 2
    vf2 = one.column("vf_x_mps") ** 2 + one.column("vf_z_mps") ** 2
    assert len(z) >= 3
    np.testing.assert_allclose(z + vi2 / (2 * G), head0, rtol=1e-11)
    np.testing.assert_allclose(z + vf2 / (2 * G), head0, rtol=1e-11)
    assert one.state == EXITED_DOWNSLOPE


def test_vertical_drop_and_rocks_leaving_either_end():
    one = simulate_one_rock(flat_model(e_n=0.0), 0, x_m=3.0, z_m=2.0)
    assert one.column("x_m")[0] == 3.0
    assert one.column("vi_z_mps")[0] == pytest.approx(-math.sqrt(2 * G * 2.0))
    assert one.state == STOPPED and one.runout_x_m == 3.0
    model = flat_model(e_n=0.9, e_t=1.0)
    right = simulate_one_rock(model, 0, x_m=990.0, z_m=5.0, vx_mps=20.0)
    left = simulate_one_rock(model, 0, x_m=10.0, z_m=5.0, vx_mps=-20.0)
    assert (right.state, right.runout_x_m) == (1, 1000.0)
    assert (left.state, left.runout_x_m) == (2, 0.0)


def test_analysis_point_on_a_free_fall_matches_the_parabola():
    model = model_from_dict(
        {
            "profile": {"x_m": [0, 100], "z_m": [50, 0], "material": "m"},
            "materials": {"m": {"e_n": 0.3, "e_t": 0.8, "friction_deg": 30}},
            "body": {"mass_kg": 10, "radius_m": 0.1, "gyration_m": 0.05},
            "seeder": {"x_m": 0, "z_m": 60, "vx_mps": 5.0},
        }
    )
    res = simulate(model, 3, np.random.default_rng(0), analysis_x_m=[4.0])
    point = res.analysis[0]
    t = 4.0 / 5.0
    speed = math.hypot(5.0, G * t)
    assert point.crossed.all()
    np.testing.assert_allclose(point.speed_mps, speed, rtol=1e-12)
    np.testing.assert_allclose(point.ke_j, 0.5 * 10 * speed**2, rtol=1e-12)
    np.testing.assert_allclose(point.re_j, 0.0)
    np.testing.assert_allclose(point.height_m, 60 - G * t**2 / 2 - 48.0, rtol=1e-12)
