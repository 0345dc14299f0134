"""The simulator against references: an independent one, and its own interpreted twin.

The independent reference below shares no code with fieldkit: it marches each flight
in time steps of 1 ms, finds the first sign change of the height above the polyline
and refines it with Brent's method, then applies e_n and e_t in the axes of the
segment hit. Done-when criterion of issue 9: a single rock without randomness
reproduces it to 1 cm and 0.5 % over its first impacts.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from model_builders import ALL_EFFECTS, build
from scipy.optimize import brentq

from fieldkit.model import model_from_dict, simulate
from fieldkit.model.reference import simulate_one_rock, simulate_reference

G = 9.81
X = [0.0, 12.0, 25.0, 33.0, 50.0, 80.0]
Z = [60.0, 50.0, 36.0, 35.0, 20.0, 14.0]
MATERIALS = {"a": (0.6, 0.85), "b": (0.45, 0.8)}
SEGMENT_MATERIAL = ["a", "a", "b", "b", "a"]


def independent_impacts(x0, z0, vx, vz, impacts):
    """First ``impacts`` impacts by time marching + Brent (no fieldkit code)."""

    def height(t, x0, z0, vx, vz):
        x = x0 + vx * t
        return z0 + vz * t - 0.5 * G * t * t - np.interp(x, X, Z)

    out = []
    for _ in range(impacts):
        dt = 1e-3
        t = dt
        while height(t, x0, z0, vx, vz) > 0:
            t += dt
        tc = brentq(height, t - dt, t, args=(x0, z0, vx, vz), xtol=1e-14)
        x = x0 + vx * tc
        z = z0 + vz * tc - 0.5 * G * tc * tc
        vzi = vz - G * tc
        j = min(np.searchsorted(X, x) - 1, len(X) - 2)
        psi = -math.atan2(Z[j + 1] - Z[j], X[j + 1] - X[j])
        vt = vx * math.cos(psi) - vzi * math.sin(psi)
        vn = vx * math.sin(psi) + vzi * math.cos(psi)
        e_n, e_t = MATERIALS[SEGMENT_MATERIAL[j]]
        vfn, vft = -e_n * vn, e_t * vt
        vfx = vft * math.cos(psi) + vfn * math.sin(psi)
        vfz = -vft * math.sin(psi) + vfn * math.cos(psi)
        out.append((x, z, vx, vzi, vfx, vfz))
        x0, z0, vx, vz = x, z, vfx, vfz
    return np.array(out)


def test_single_rock_matches_an_independent_reference():
    model = model_from_dict(
        {
            "profile": {"x_m": X, "z_m": Z, "material": SEGMENT_MATERIAL},
            "materials": {
                k: {"e_n": v[0], "e_t": v[1], "friction_deg": 30}
                for k, v in MATERIALS.items()
            },
            "body": {"mass_kg": 100, "radius_m": 0.2},
            "seeder": {"x_m": 0.5, "z_m": 62.0, "vx_mps": 3.0, "vz_mps": 1.0},
        }
    )
    res = simulate(model, 1, np.random.default_rng(0), record_impacts=True)
    f = res.impact_table.frame
    n = 6
    assert len(f) >= n
    ref = independent_impacts(0.5, 62.0, 3.0, 1.0, n)
    got = f[["x_m", "z_m", "vi_x_mps", "vi_z_mps", "vf_x_mps", "vf_z_mps"]]
    got = got.to_numpy()[:n]
    assert np.max(np.hypot(got[:, 0] - ref[:, 0], got[:, 1] - ref[:, 1])) < 0.01
    vi_ref = np.hypot(ref[:, 2], ref[:, 3])
    vf_ref = np.hypot(ref[:, 4], ref[:, 5])
    np.testing.assert_allclose(np.hypot(got[:, 2], got[:, 3]), vi_ref, rtol=0.005)
    np.testing.assert_allclose(np.hypot(got[:, 4], got[:, 5]), vf_ref, rtol=0.005)
    np.testing.assert_allclose(got[:, 2:], ref[:, 2:], rtol=0.005, atol=0.01)


@pytest.mark.parametrize("effects", [{}, ALL_EFFECTS], ids=["base", "all_effects"])
def test_kernel_and_interpreted_reference_agree_rock_by_rock(effects):
    model = build(effects, sd=True)
    res = simulate(model, 6, np.random.default_rng(21), record_impacts=True)
    ref = simulate_reference(model, 6, np.random.default_rng(21))
    frame = res.impact_table.frame
    assert res.impacts > 15
    for i, one in enumerate(ref):
        rows = frame[frame["path_id"] == str(i)]
        assert len(rows) == len(one.impacts) == res.impacts_per_rock[i]
        for col in ("t_s", "x_m", "z_m", "vf_x_mps", "vf_z_mps", "omega_f_radps",
                    "mass_kg", "slope_deg"):  # fmt: skip
            np.testing.assert_allclose(
                rows[col].to_numpy(), one.column(col), rtol=1e-12, atol=1e-12
            )
        assert one.state == res.state[i]
        assert one.runout_x_m == pytest.approx(res.runout_x_m[i], rel=1e-12)


def test_monte_carlo_first_impacts_match_the_one_rock_reference():
    """With only vx random, each rock's first impact is the one-rock answer for its
    vx; the Monte Carlo mean and SD of the first-impact x match the reference rock's
    sensitivity (linear in vx on a flat floor)."""
    data = {
        "profile": {"x_m": [0, 500], "z_m": [0, 0], "material": "m"},
        "materials": {"m": {"e_n": 0.4, "e_t": 0.8, "friction_deg": 30}},
        "body": {"mass_kg": 10, "radius_m": 0.1},
        "seeder": {"x_m": 0, "z_m": 10, "vx_mps": 5.0, "vx_sd_mps": 0.5},
    }
    model = model_from_dict(data)
    res = simulate(model, 4000, np.random.default_rng(3), record_impacts=True)
    f = res.impact_table.frame
    first = f[f["point"] == "1"]["x_m"].to_numpy()
    one = simulate_one_rock(model, 0, x_m=0.0, z_m=10.0, vx_mps=5.0)
    t1 = math.sqrt(2 * 10 / G)
    assert one.column("x_m")[0] == pytest.approx(5.0 * t1, rel=1e-12)
    se = 0.5 * t1 / math.sqrt(first.size)
    assert abs(first.mean() - one.column("x_m")[0]) < 4 * se
    assert first.std() == pytest.approx(0.5 * t1, rel=0.05)
