"""The 3-D kernel against independent references: closed forms on planes, the
symmetry of a V-valley, the 2-D kernel on the same profile, and reproducibility."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from fieldkit.errors import ArgumentError
from fieldkit.model import model_from_dict, simulate
from fieldkit.model.kernel3d import SLIDE_STEP_CELLS
from fieldkit.model.materials import Material
from fieldkit.model.model3d import Model3D, Seeder3D
from fieldkit.model.model_file import Body
from fieldkit.model.results import EXITED_DOWNSLOPE, STOPPED
from fieldkit.model.simulate3d import simulate3d
from fieldkit.model.terrain import Terrain

G = 9.81
BODY = Body(mass_kg=100.0, radius_m=0.2, gyration_m=0.126)


def grid_of(fn, nx, ny, cell=1.0, x0=0.0, y0=0.0):
    """A terrain whose cell centres take ``fn(x, y)``."""
    xc = x0 + (np.arange(nx) + 0.5) * cell
    yc = y0 + (np.arange(ny) + 0.5) * cell
    xx, yy = np.meshgrid(xc, yc)
    return Terrain(x0, y0, cell, fn(xx, yy))


def model_on(terrain, releases, *, seeder=None, effects=None, core=None, **material):
    mat = {"e_n": 0.3, "e_t": 0.8, "friction_deg": 20.0} | material
    release = np.array([[x, y, terrain.height(x, y)] for x, y in releases], dtype=float)
    return Model3D(
        terrain=terrain,
        materials={"m": Material("m", **mat)},
        material_index=np.zeros(terrain.shape, np.int64),
        effects=effects or {},
        body=BODY,
        releases=release,
        release_weights=np.ones(len(releases)),
        seeder=seeder or Seeder3D(),
        core=core or {},
    )


def plane(beta_deg, azimuth_deg, z0=300.0):
    """A plane dipping ``beta`` towards the azimuth (from +x towards +y)."""
    tb = math.tan(math.radians(beta_deg))
    ca, sa = math.cos(math.radians(azimuth_deg)), math.sin(math.radians(azimuth_deg))
    return lambda x, y: z0 - tb * (x * ca + y * sa)


def test_terrain_is_bilinear_between_centres_and_off_outside():
    t = Terrain(10.0, 20.0, 2.0, np.array([[0.0, 2.0], [4.0, 10.0]]))
    # centres at x 11, 13 and y 21, 23; a point a quarter in from (11, 21)
    u, v = 0.25, 0.5
    expected = 0 * (1 - u) * (1 - v) + 2 * u * (1 - v) + 4 * (1 - u) * v + 10 * u * v
    assert t.height(11.5, 22.0) == pytest.approx(expected, rel=1e-14)
    assert math.isnan(t.height(10.9, 22.0))  # west of the first centre
    nx, ny, nz = t.normal(11.5, 22.0)
    gx = ((2 - 0) * (1 - v) + (10 - 4) * v) / 2.0
    gy = ((4 - 0) * (1 - u) + (10 - 2) * u) / 2.0
    norm = math.sqrt(gx * gx + gy * gy + 1)
    assert (nx, ny, nz) == pytest.approx((-gx / norm, -gy / norm, 1 / norm), rel=1e-14)
    with_hole = Terrain(0.0, 0.0, 1.0, np.array([[0.0, np.nan], [0.0, 0.0]]))
    assert math.isnan(with_hole.height(1.0, 1.0))


@pytest.mark.parametrize("azimuth_deg", [0.0, 30.0, 135.0])
def test_a_rock_slides_down_an_inclined_plane_as_eq_7_3_says(azimuth_deg):
    beta, phi = 30.0, 20.0
    t = grid_of(plane(beta, azimuth_deg), 160, 160)
    ca, sa = math.cos(math.radians(azimuth_deg)), math.sin(math.radians(azimuth_deg))
    x0, y0 = 80.0 - 40.0 * ca, 80.0 - 40.0 * sa
    model = model_on(t, [(x0, y0)], friction_deg=phi)
    res = simulate3d(model, 1, np.random.default_rng(0), sample_m=0.5)
    assert res.impacts == 0
    assert res.state[0] == EXITED_DOWNSLOPE  # slides off the DEM
    p = res.rock_path(0)
    along = (p["x_m"] - x0) * ca + (p["y_m"] - y0) * sa  # plan distance down-dip
    across = -(p["x_m"] - x0) * sa + (p["y_m"] - y0) * ca
    b = math.radians(beta)
    a = G * (math.sin(b) - math.tan(math.radians(phi)) * math.cos(b))
    s = along / math.cos(b)  # distance travelled along the slope
    # the fall line, and v^2 = 2 a s at every sample (a closed form in s; with
    # s = a t^2 / 2 it is the position at t)
    np.testing.assert_allclose(across, 0.0, atol=1e-8)  # edge nudges 1e-9 cell
    np.testing.assert_allclose(p["speed_mps"] ** 2, 2 * a * s, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(
        p["z_m"], t.heights(p["x_m"], p["y_m"]), rtol=0, atol=1e-9
    )
    # passing the line 30 m down-dip (plan): speed there from the samples around it
    line = 30.0
    k = np.searchsorted(along, line)
    f = (line - along[k - 1]) / (along[k] - along[k - 1])
    v2 = (1 - f) * p["speed_mps"][k - 1] ** 2 + f * p["speed_mps"][k] ** 2
    assert v2 == pytest.approx(2 * a * line / math.cos(b), rel=1e-8)
    # sampled at least every sample_m travelled
    step = np.sqrt(
        np.diff(p["x_m"]) ** 2 + np.diff(p["y_m"]) ** 2 + np.diff(p["z_m"]) ** 2
    )
    assert step.max() <= 0.5 + 1e-9


def test_a_rock_on_a_plane_steeper_friction_does_not_move():
    t = grid_of(plane(25.0, 60.0), 40, 40)
    model = model_on(t, [(20.0, 20.0)], friction_deg=30.0)
    res = simulate3d(model, 3, np.random.default_rng(1))
    assert (res.state == STOPPED).all()
    assert res.impacts == 0
    np.testing.assert_array_equal(res.deposit_xyz[:, :2], [[20.0, 20.0]] * 3)


def test_a_thrown_rock_lands_where_the_parabola_meets_the_plane():
    beta, az = 35.0, 20.0
    t = grid_of(plane(beta, az), 120, 120)
    x0, y0, hgt = 20.0, 30.0, 3.0
    vx, vy, vz = 4.0, -1.5, 2.0
    seeder = Seeder3D(height_m=hgt, vx_mps=vx, vy_mps=vy, vz_mps=vz)
    model = model_on(t, [(x0, y0)], seeder=seeder)
    res = simulate3d(model, 1, np.random.default_rng(0), record_impacts=True)
    rows = res.impact_rows
    # closed form: z0 + vz t - g t^2/2 = plane(x0 + vx t, y0 + vy t)
    tb = math.tan(math.radians(beta))
    ca, sa = math.cos(math.radians(az)), math.sin(math.radians(az))
    z0 = t.height(x0, y0) + hgt
    slope_rate = -tb * (vx * ca + vy * sa)  # dz_plane/dt along the plan path
    qa, qb, qc = -G / 2, vz - slope_rate, z0 - t.height(x0, y0)
    tl = (-qb - math.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    first = (x0 + vx * tl, y0 + vy * tl, z0 + vz * tl - G * tl * tl / 2)
    got = (rows["x_m"][0], rows["y_m"][0], rows["z_m"][0])
    assert got == pytest.approx(first, abs=1e-9)  # exact contact (1 mm bound: 1e-3)
    # impact speeds in the plane's axes
    n = np.array([tb * ca, tb * sa, 1.0]) / math.sqrt(1 + tb * tb)
    v_in = np.array([vx, vy, vz - G * tl])
    assert rows["vin_mps"][0] == pytest.approx(v_in @ n, rel=1e-9)
    vt = v_in - (v_in @ n) * n
    assert rows["vit_mps"][0] == pytest.approx(np.linalg.norm(vt), rel=1e-9)
    assert rows["vfn_mps"][0] == pytest.approx(-0.3 * (v_in @ n), rel=1e-9)
    assert rows["vft_mps"][0] == pytest.approx(0.8 * np.linalg.norm(vt), rel=1e-9)


def v_valley(nx=60, ny=41, cell=1.0, flank_deg=30.0, axis_deg=0.0):
    """A V-valley along x, axis on the centre row ny // 2, falling ``axis_deg``."""
    yc = (ny // 2 + 0.5) * cell
    tf = math.tan(math.radians(flank_deg))
    ta = math.tan(math.radians(axis_deg))
    return grid_of(lambda x, y: 100.0 + tf * np.abs(y - yc) - ta * x, nx, ny, cell), yc


def test_a_rock_released_on_a_flank_ends_on_the_valley_axis():
    t, yc = v_valley()
    model = model_on(t, [(30.0, yc + 8.0)], friction_deg=15.0)
    res = simulate3d(model, 1, np.random.default_rng(0))
    assert res.state[0] == STOPPED
    assert abs(res.deposit_xyz[0, 1] - yc) < 0.5  # within half a cell of the axis
    assert res.deposit_xyz[0, 0] == pytest.approx(30.0, abs=1e-9)  # no x motion


def test_a_rock_slides_down_a_v_valley_axis_as_eq_7_3_says_along_it():
    axis, phi = 30.0, 20.0
    t, yc = v_valley(nx=120, ny=21, flank_deg=40.0, axis_deg=axis)
    model = model_on(t, [(10.0, yc)], friction_deg=phi)
    res = simulate3d(model, 1, np.random.default_rng(0), sample_m=1.0)
    assert res.impacts == 0 and res.state[0] == EXITED_DOWNSLOPE
    p = res.rock_path(0)
    np.testing.assert_allclose(p["y_m"], yc, atol=1e-12)  # in the axis all along
    b = math.radians(axis)
    a = G * (math.sin(b) - math.tan(math.radians(phi)) * math.cos(b))
    s = (p["x_m"] - 10.0) / math.cos(b)
    assert s[-1] > 100.0
    np.testing.assert_allclose(p["speed_mps"] ** 2, 2 * a * s, rtol=1e-8, atol=1e-8)


def test_v_valley_rocks_released_on_the_axis_spread_symmetrically_and_lose_energy():
    t, yc = v_valley(nx=200, ny=61, flank_deg=35.0, axis_deg=20.0)
    seeder = Seeder3D(
        height_m=2.0, vx_mps=3.0, vy_sd_mps=2.0, vz_sd_mps=1.0, height_sd_m=0.5
    )
    model = model_on(
        t,
        [(10.0, yc)],
        seeder=seeder,
        e_n=0.45,
        e_n_sd=0.15,
        e_t=0.85,  # no SD: a drawn e_t > 1 gains energy in 2-D too (legal)
        friction_deg=30.0,  # < the flanks (35), > the axis (20): rests in the axis
        roughness_m=0.1,
        roughness_deg_sd=5.0,
        effects={"slope_roughness": {"scale": 1.0}},
    )
    res = simulate3d(model, 600, np.random.default_rng(7), record_impacts=True)
    # every rock comes to rest in the valley's axis (the notch), most exactly, all
    # within one slide step (where a step from rest meets rising ground)
    stopped = res.state == STOPPED
    assert stopped.mean() > 0.9
    off = np.abs(res.deposit_xyz[stopped, 1] - yc)
    assert np.median(off) < 1e-6
    assert off.max() <= SLIDE_STEP_CELLS * t.cell_m
    # on the way the bounces spread to both flanks alike
    rows = res.impact_rows
    lateral = rows["y_m"] - yc
    se = lateral.std(ddof=1) / math.sqrt(lateral.size)  # impacts of a rock: +-
    assert lateral.std() > 0.5  # the test has spread to see
    assert abs(lateral.mean()) < 3 * se
    # paths: a sample at least every sample_m (half a cell here) travelled
    p = res.path
    gap = np.hypot(np.hypot(np.diff(p["x_m"]), np.diff(p["y_m"])), np.diff(p["z_m"]))
    inside = np.ones(gap.size, bool)
    inside[res.path_offsets[1:-1] - 1] = False  # from one rock's end to the next
    assert res.sample_m == 0.5
    assert gap[inside].max() <= 0.5 * (1 + 1e-9)
    per_rock = np.bincount(rows["rock"], weights=lateral, minlength=600)
    se_rock = per_rock.std(ddof=1) / math.sqrt(per_rock.size)  # rocks independent
    assert abs(per_rock.mean()) < 3 * se_rock
    before = rows["vin_mps"] ** 2 + rows["vit_mps"] ** 2
    after = rows["vfn_mps"] ** 2 + rows["vft_mps"] ** 2
    assert rows["vin_mps"].size > 1000
    assert (after <= before * (1 + 1e-12)).all()  # passive impacts
    assert (rows["vin_mps"] < 0).all()  # every impact moves into its (tilted) surface


def test_a_plane_dipping_along_x_reproduces_the_2d_runout_distribution():
    # a 35 deg slope of 60 m onto a level floor, both at the DEM's centres
    cell = 1.0
    nx = 150
    xc = (np.arange(nx) + 0.5) * cell
    slope = math.tan(math.radians(35.0))
    zx = np.where(xc < 60.5, (60.5 - xc) * slope, 0.0)  # the break at a centre
    t = Terrain(0.0, 0.0, cell, np.tile(zx, (5, 1)))
    material = {
        "e_n": 0.35,
        "e_n_sd": 0.1,
        "e_t": 0.8,
        "e_t_sd": 0.1,
        "friction_deg": 32.0,
    }
    x0, hgt, vx0 = 2.5, 1.5, 2.0
    rocks = 3000
    m3 = model_on(
        t,
        [(x0, 2.5)],
        seeder=Seeder3D(height_m=hgt, vx_mps=vx0, vx_sd_mps=0.5),
        **material,
    )
    r3 = simulate3d(m3, rocks, np.random.default_rng(11))
    ground0 = float(np.interp(x0, xc, zx))
    m2 = model_from_dict(
        {
            # the same surface by its three vertices (collinear intermediate
            # vertices make the 2-D kernel launch on rounding-level dip changes)
            "profile": {"x_m": [0.5, 60.5, 149.5], "z_m": [60 * slope, 0.0, 0.0],
                        "material": "m"},
            "materials": {"m": material},
            "body": {"mass_kg": 100.0, "radius_m": 0.2, "gyration_m": 0.126},
            "seeder": {"x_m": x0, "z_m": ground0 + hgt, "vx_mps": vx0,
                       "vx_sd_mps": 0.5},
        }
    )  # fmt: skip
    r2 = simulate(m2, rocks, np.random.default_rng(12))
    assert (r3.state == STOPPED).all() and (r2.state == STOPPED).all()
    np.testing.assert_allclose(r3.deposit_xyz[:, 1], 2.5, atol=1e-9)  # stays in plane
    x3, x2 = r3.deposit_xyz[:, 0], r2.runout_x_m
    for q in (0.1, 0.5, 0.9):
        # MC error of a quantile: sqrt(q (1-q) / n) / density, density from the
        # pooled sample's spacing around the quantile
        pooled = np.concatenate([x3, x2])
        lo, hi = np.quantile(pooled, [q - 0.05, q + 0.05])
        density = 0.1 / (hi - lo)
        se = math.sqrt(q * (1 - q) / rocks) / density
        diff = np.quantile(x3, q) - np.quantile(x2, q)
        assert abs(diff) < 3 * math.sqrt(2) * se, (q, diff, se)
    se_mean = math.sqrt(x3.var() / rocks + x2.var() / rocks)
    assert abs(x3.mean() - x2.mean()) < 3 * se_mean


@pytest.mark.parametrize("vx0", [1.0, 3.0])
def test_one_rock_on_a_plane_dipping_along_x_follows_the_2d_kernel_exactly(vx0):
    # no random draws: the same rock in both kernels, impact by impact
    slope = math.tan(math.radians(35.0))
    xc = np.arange(150) + 0.5
    zx = np.where(xc < 60.5, (60.5 - xc) * slope, 0.0)
    t = Terrain(0.0, 0.0, 1.0, np.tile(zx, (5, 1)))
    material = {"e_n": 0.35, "e_t": 0.8, "friction_deg": 32.0}
    m3 = model_on(t, [(2.5, 2.5)], seeder=Seeder3D(height_m=1.5, vx_mps=vx0),
                  **material)  # fmt: skip
    r3 = simulate3d(m3, 1, np.random.default_rng(0), record_impacts=True)
    m2 = model_from_dict(
        {
            "profile": {"x_m": [0.5, 60.5, 149.5], "z_m": [60 * slope, 0.0, 0.0],
                        "material": "m"},
            "materials": {"m": material},
            "body": {"mass_kg": 100.0, "radius_m": 0.2, "gyration_m": 0.126},
            "seeder": {"x_m": 2.5, "z_m": 58 * slope + 1.5, "vx_mps": vx0},
        }
    )  # fmt: skip
    r2 = simulate(m2, 1, np.random.default_rng(0), record_impacts=True)
    frame = r2.impact_table.frame
    assert r3.impacts == r2.impacts >= 2
    np.testing.assert_allclose(r3.impact_rows["x_m"], frame["x_m"], rtol=1e-12)
    np.testing.assert_allclose(r3.impact_rows["z_m"], frame["z_m"], rtol=1e-12)
    assert r3.state[0] == r2.state[0] == STOPPED
    # the slide (stepped in 3-D, exact in 2-D) ends at the same place
    assert r3.deposit_xyz[0, 0] == pytest.approx(r2.runout_x_m[0], abs=1e-8)


def test_same_seed_same_result_whatever_threads_and_chunks():
    t, yc = v_valley(nx=80, ny=31, flank_deg=30.0, axis_deg=25.0)
    seeder = Seeder3D(height_m=1.0, vx_mps=2.0, vy_sd_mps=1.0, vz_sd_mps=0.5)
    model = model_on(
        t,
        [(5.0, yc), (5.0, yc + 4.0)],
        seeder=seeder,
        e_n_sd=0.1,
        friction_deg_sd=3.0,
        roughness_m=0.1,
        effects={"slope_roughness": {"scale": 1.0}},
    )
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = simulate3d(model, 200, np.random.default_rng(3), record_impacts=True)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = simulate3d(
            model, 200, np.random.default_rng(3), record_impacts=True, chunk_rocks=37
        )
    finally:
        numba.set_num_threads(threads)
    bare = simulate3d(model, 200, np.random.default_rng(3), keep_paths=False)
    np.testing.assert_array_equal(bare.deposit_xyz, one.deposit_xyz)
    assert bare.path["x_m"].size == 0 and not bare.path_offsets.any()
    np.testing.assert_array_equal(one.deposit_xyz, two.deposit_xyz)
    np.testing.assert_array_equal(one.state, two.state)
    np.testing.assert_array_equal(one.path_offsets, two.path_offsets)
    for name in one.path:
        np.testing.assert_array_equal(one.path[name], two.path[name])
    for name in one.impact_rows:
        np.testing.assert_array_equal(one.impact_rows[name], two.impact_rows[name])
    assert one.impacts > 200


def test_the_impact_effects_act_in_3d_and_impacts_stay_passive():
    t, yc = v_valley(nx=120, ny=41, flank_deg=30.0, axis_deg=30.0)
    effects = {
        "angle_dependent_restitution": {"b": 0.8},
        "velocity_scaled_restitution": {"k_mps": 12.0},
        "rotation_friction": {"friction": 0.6, "coupling": 0.7},
        "slope_roughness": {"scale": 1.0},
        "affine_rebound": {"b_n_mps": 0.3, "b_t_mps": -0.2},
    }
    seeder = Seeder3D(height_m=2.0, vx_mps=4.0, vy_sd_mps=1.0)
    common = {"seeder": seeder, "e_n": 0.4, "e_n_sd": 0.1, "roughness_m": 0.05}
    on = model_on(t, [(5.0, yc)], effects=effects, **common)
    off = model_on(t, [(5.0, yc)], **common)
    r_on = simulate3d(on, 200, np.random.default_rng(5), record_impacts=True)
    r_off = simulate3d(off, 200, np.random.default_rng(5), record_impacts=True)
    rows = r_on.impact_rows
    assert not np.allclose(r_on.deposit_xyz, r_off.deposit_xyz)
    # with rotation coupling the spin is carried energy: v^2 + k^2 w^2 never grows
    k2 = BODY.gyration_m**2
    before = (
        rows["vin_mps"] ** 2 + rows["vit_mps"] ** 2 + k2 * rows["omega_i_radps"] ** 2
    )
    after = (
        rows["vfn_mps"] ** 2 + rows["vft_mps"] ** 2 + k2 * rows["omega_f_radps"] ** 2
    )
    assert rows["vin_mps"].size > 200
    assert (after <= before * (1 + 1e-12) + 1e-12).all()


def test_mass_loss_follows_eqs_6_15_16_with_the_plan_distance():
    t = grid_of(plane(35.0, 45.0), 80, 80)
    seeder = Seeder3D(height_m=3.0, vx_mps=3.0, vy_mps=3.0)
    effects = {"mass_loss": {"rate_per_m": 0.02, "impact_exponent": 0.5}}
    model = model_on(t, [(10.0, 10.0)], seeder=seeder, e_n=0.5, effects=effects)
    res = simulate3d(model, 1, np.random.default_rng(0), record_impacts=True)
    rows = res.impact_rows
    assert rows["x_m"].size >= 3
    p = res.rock_path(0)
    # the sample just after impact i (its rebound) carries the reduced mass
    moving = p["speed_mps"] > 0
    mass = 2 * p["ke_j"][moving] / p["speed_mps"][moving] ** 2
    for i in range(rows["x_m"].size):
        dist = math.hypot(rows["x_m"][i] - 10.0, rows["y_m"][i] - 10.0)
        ratio = (i + 1.0) ** -0.5 / (1 + 0.02 * dist) if i else 1 / (1 + 0.02 * dist)
        assert np.isclose(mass, BODY.mass_kg * ratio, rtol=1e-9).any(), i


@pytest.mark.parametrize("effect", ["air_drag"])
def test_an_effect_not_yet_in_3d_is_refused(effect):
    t = grid_of(plane(30.0, 0.0), 10, 10)
    model = model_on(t, [(5.0, 5.0)], effects={effect: {}})
    with pytest.raises(ArgumentError, match=f"{effect} are not yet in the 3-D"):
        simulate3d(model, 1, np.random.default_rng(0))


def test_on_rough_ground_no_path_goes_below_the_surface():
    rng = np.random.default_rng(4)
    xc = np.arange(60) + 0.5
    z = 60.0 - 0.8 * xc[None, :] + rng.normal(0.0, 0.4, (30, 60))
    z[20:23, 40:43] = np.nan  # a nodata hole
    t = Terrain(0.0, 0.0, 1.0, z)
    seeder = Seeder3D(height_m=1.0, vx_mps=3.0, vx_sd_mps=1.0, vy_sd_mps=2.0)
    model = model_on(
        t,
        [(3.0, 15.0), (5.0, 21.5)],
        seeder=seeder,
        e_n=0.5,
        e_n_sd=0.15,
        roughness_m=0.2,
        effects={"slope_roughness": {"scale": 1.0}},
    )
    res = simulate3d(model, 300, np.random.default_rng(9), record_impacts=True)
    h = res.path["height_m"]
    assert res.impacts > 1000
    assert np.nanmin(h) > -1e-9  # never inside the ground
    assert np.isfinite(res.deposit_xyz).all()
    stopped = res.state == STOPPED
    ground = t.heights(res.deposit_xyz[stopped, 0], res.deposit_xyz[stopped, 1])
    np.testing.assert_allclose(res.deposit_xyz[stopped, 2], ground, atol=1e-9)
    assert set(np.unique(res.state)) <= {STOPPED, EXITED_DOWNSLOPE}
    d = res.deposit_xyz[res.state == EXITED_DOWNSLOPE]
    at_hole = (d[:, 0] > 38) & (d[:, 0] < 44) & (d[:, 1] > 19) & (d[:, 1] < 24)
    assert at_hole.any()  # some rocks end at the nodata hole, as "exited"


def test_a_rock_at_rest_on_a_ridge_centre_starts_down_the_crest_not_one_side():
    # a crest along y (the centre column x = 10.5), falling towards -y
    t = grid_of(lambda x, y: 50.0 + 0.6 * y - 0.3 * np.abs(x - 10.5), 21, 40)
    model = model_on(t, [(10.5, 30.5)], friction_deg=10.0)  # a cell centre
    res = simulate3d(model, 1, np.random.default_rng(0), sample_m=0.2)
    p = res.rock_path(0)
    assert p["y_m"][1] < 30.5  # it moved, down the crest (the patches' mean slope)
    assert p["x_m"][1] == 10.5  # not down the north-east patch's fall line
    # and, balanced on the crest, it runs down it to the DEM's edge
    assert res.state[0] == EXITED_DOWNSLOPE
    np.testing.assert_array_equal(p["x_m"], 10.5)


def test_bad_runs_are_refused_in_one_line_naming_the_argument(monkeypatch):
    import fieldkit.model.simulate3d as sim3

    t = grid_of(plane(30.0, 0.0), 20, 10)
    model = model_on(t, [(5.0, 5.0)])
    bad_index = Model3D(**{**model.__dict__, "material_index": np.zeros((3, 3))})
    with pytest.raises(ArgumentError, match="material_index has shape"):
        simulate3d(bad_index, 1, np.random.default_rng(0))
    with pytest.raises(ArgumentError, match="sample_m must be"):
        simulate3d(model, 1, np.random.default_rng(0), sample_m=0.0)
    outside = Model3D(**{**model.__dict__, "releases": np.array([[0.2, 5.0, 0.0]])})
    with pytest.raises(ArgumentError, match="release point 1 .* is off the DEM"):
        simulate3d(outside, 1, np.random.default_rng(0))
    monkeypatch.setattr(sim3, "PATH_MEMORY_LIMIT_BYTES", 56 * 100)
    with pytest.raises(ArgumentError, match="run fewer rocks or a larger sample_m"):
        simulate3d(model, 5, np.random.default_rng(0), sample_m=0.1)
