"""tree_impacts in 3-D: geometric strikes on placed stems against hand calculations.

A strike: the rock centre enters the vertical cylinder of radius ``d/2 + r`` about a
stem, up to the tree's top (through its side, or through its top while inside the
disc); the trunk takes ``E = c d_cm^p`` (thesis §6.6, Fig. 6.8), direction kept.
The energy is computed here by hand, not with the kernel's function.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from test_kernel3d import BODY, grid_of, model_on, plane

from fieldkit.errors import ArgumentError
from fieldkit.model import kernel3d
from fieldkit.model.model3d import Seeder3D
from fieldkit.model.simulate3d import simulate3d
from fieldkit.model.terrain_file import Trees3D

G = 9.81
R_ROCK = BODY.radius_m
#: E = c d_cm^p with c = 1 J/cm^p (small enough to leave the rock moving).
FACTOR, EXPONENT = 1.0, 2.31
TREES = {"tree_impacts": {"hit_probability": 1.0, "energy_factor": FACTOR,
                          "energy_exponent": EXPONENT}}  # fmt: skip


def energy_j(d_m: float) -> float:
    return FACTOR * (100.0 * d_m) ** EXPONENT


def with_trees(model, xs, ys, ds, hs):
    trees = Trees3D(*(np.asarray(v, float) for v in (xs, ys, ds, hs)))
    return replace(model, trees=trees)


def strike_samples(path, tree_x, tree_y, reach):
    """Indices ``i`` where samples ``i`` and ``i + 1`` sit at one point within
    ``reach`` of the stem with the speed falling (just before and after a strike;
    an impact's two samples, arrival and rebound, sit on the ground elsewhere; the
    first flight sample repeats the strike's point with the speed recomputed)."""
    x, y = path["x_m"], path["y_m"]
    same = (np.diff(x) == 0) & (np.diff(y) == 0) & (np.diff(path["z_m"]) == 0)
    near = np.hypot(x[:-1] - tree_x, y[:-1] - tree_y) <= reach * (1 + 1e-9)
    drop = np.diff(path["speed_mps"]) < -1e-9 * path["speed_mps"][:-1]
    return np.flatnonzero(same & near & drop)


def flat_flight(tree_x, tree_y, d, h, *, x0=10.0, y0=20.0):
    """A rock released 10 m above flat ground at 10 m/s along +x, one tree."""
    t = grid_of(lambda x, y: 0.0 * x, 60, 40)
    model = model_on(
        t, [(x0, y0)], seeder=Seeder3D(height_m=10.0, vx_mps=10.0), effects=TREES
    )
    model = with_trees(model, [tree_x], [tree_y], [d], [h])
    return simulate3d(model, 1, np.random.default_rng(0), record_impacts=True)


def test_a_rock_sliding_down_a_plane_at_a_tree_loses_the_laws_energy():
    beta, phi, d = 30.0, 20.0, 0.3
    t = grid_of(plane(beta, 0.0), 80, 20)
    x0, y0, tree_x = 10.0, 10.0, 30.0
    model = model_on(t, [(x0, y0)], friction_deg=phi, effects=TREES)
    model = with_trees(model, [tree_x], [y0], [d], [20.0])
    res = simulate3d(model, 1, np.random.default_rng(0), sample_m=0.5)
    p = res.rock_path(0)
    reach = d / 2 + R_ROCK
    (i,) = strike_samples(p, tree_x, y0, reach)
    assert p["x_m"][i] == pytest.approx(tree_x - reach, abs=1e-9)
    assert p["y_m"][i] == pytest.approx(y0, abs=1e-9)
    # eq. 7.3 on the plane, down the fall line from rest
    along = (tree_x - reach - x0) / math.cos(math.radians(beta))
    b, f = math.radians(beta), math.radians(phi)
    acc = G * (math.sin(b) - math.cos(b) * math.tan(f))
    v_before = math.sqrt(2.0 * acc * along)
    assert p["speed_mps"][i] == pytest.approx(v_before, rel=1e-9)
    # the law at the strike (exact on the speed there; slide steps end 1e-9 cell
    # past patch edges, hence rel 1e-9 above)
    v_after = math.sqrt(p["speed_mps"][i] ** 2 - 2.0 * energy_j(d) / BODY.mass_kg)
    assert p["speed_mps"][i + 1] == pytest.approx(v_after, rel=1e-12)
    assert res.tree_strikes_per_rock.tolist() == [1]
    # after the strike the rock slides on from the stem with the speed left
    j = int(np.searchsorted(p["x_m"], tree_x + 5.0))
    s2 = (p["x_m"][j] - p["x_m"][i]) / math.cos(math.radians(beta))
    assert p["speed_mps"][j] == pytest.approx(
        math.sqrt(v_after**2 + 2.0 * acc * s2), rel=1e-9
    )


def test_a_flight_strikes_a_tree_and_flies_on_with_the_speed_left():
    d, x0, y0 = 0.3, 10.0, 20.0
    reach = d / 2 + R_ROCK
    tree_x = x0 + 5.0 + reach  # entered at t = 0.5 s
    res = flat_flight(tree_x, y0, d, 20.0)
    p = res.rock_path(0)
    (i,) = strike_samples(p, tree_x, y0, reach)
    ts = 0.5
    zs = 10.0 - 0.5 * G * ts**2
    assert (p["x_m"][i], p["y_m"][i], p["z_m"][i]) == pytest.approx(
        (x0 + 5.0, y0, zs), abs=1e-9
    )
    v2 = 10.0**2 + (G * ts) ** 2
    assert p["speed_mps"][i] == pytest.approx(math.sqrt(v2), rel=1e-12)
    v2_after = v2 - 2.0 * energy_j(d) / BODY.mass_kg
    assert p["speed_mps"][i + 1] == pytest.approx(math.sqrt(v2_after), rel=1e-12)
    # direction kept: the landing of the scaled parabola from the strike point
    scale = math.sqrt(v2_after / v2)
    vx, vz = 10.0 * scale, -G * ts * scale
    tau = (vz + math.sqrt(vz * vz + 2.0 * G * zs)) / G
    rows = res.impact_rows
    assert rows["x_m"][0] == pytest.approx(x0 + 5.0 + vx * tau, abs=1e-9)
    assert rows["y_m"][0] == pytest.approx(y0, abs=1e-9)
    assert rows["tree_strike"][0] == 1.0
    assert rows["tree_strike"][1:].sum() == 0.0
    assert res.tree_strikes_per_rock.tolist() == [1]


@pytest.mark.parametrize(("offset_m", "struck"), [(+0.01, False), (-0.01, True)])
def test_a_tree_beside_the_lane_is_struck_only_within_d_over_2_plus_r(offset_m, struck):
    d, x0, y0 = 0.3, 10.0, 20.0
    reach = d / 2 + R_ROCK
    res = flat_flight(x0 + 6.0, y0 + reach + offset_m, d, 20.0)
    assert res.tree_strikes_per_rock.tolist() == [int(struck)]
    p = res.rock_path(0)
    found = strike_samples(p, x0 + 6.0, y0 + reach + offset_m, reach)
    assert found.size == int(struck)
    if struck:
        # entered where the lane's edge meets the circle
        (i,) = found
        dx = math.sqrt(reach**2 - (reach + offset_m) ** 2)
        assert p["x_m"][i] == pytest.approx(x0 + 6.0 - dx, abs=1e-9)


@pytest.mark.parametrize(
    ("height_m", "strike_t_s"),
    [
        (5.0, None),  # shorter: the rock passes over it (8.2-8.8 m at the stem)
        (20.0, 0.5),  # taller: struck on its side on entering the disc
        (8.5, math.sqrt(1.5 / (0.5 * G))),  # struck through its top, in the disc
    ],
)
def test_trees_shorter_and_taller_than_the_flight(height_m, strike_t_s):
    d, x0, y0 = 0.3, 10.0, 20.0
    reach = d / 2 + R_ROCK
    res = flat_flight(x0 + 5.0 + reach, y0, d, height_m)
    p = res.rock_path(0)
    found = strike_samples(p, x0 + 5.0 + reach, y0, reach)
    if strike_t_s is None:
        assert res.tree_strikes_per_rock.tolist() == [0]
        assert found.size == 0
        return
    assert res.tree_strikes_per_rock.tolist() == [1]
    (i,) = found
    assert p["x_m"][i] == pytest.approx(x0 + 10.0 * strike_t_s, abs=1e-9)
    assert p["z_m"][i] == pytest.approx(10.0 - 0.5 * G * strike_t_s**2, abs=1e-9)


def test_no_trees_on_means_the_base_model_and_a_tree_far_away_changes_nothing():
    t = grid_of(plane(35.0, 20.0), 60, 60)
    seeder = Seeder3D(height_m=1.0, vx_mps=2.0, vy_sd_mps=1.0)
    base = model_on(t, [(5.0, 20.0)], seeder=seeder, e_n=0.4, e_n_sd=0.1)
    far = with_trees(replace(base, effects=TREES), [55.0], [1.0], [0.3], [20.0])
    a = simulate3d(base, 200, np.random.default_rng(3))
    b = simulate3d(far, 200, np.random.default_rng(3))
    assert np.array_equal(a.deposit_xyz, b.deposit_xyz)
    assert b.tree_strikes_per_rock.sum() == 0


def test_the_cell_index_finds_what_a_search_of_every_stem_finds():
    """stem_struck (cells near the piece only) against a loop over all stems, on
    random pieces, with stems wider than a cell among them."""
    rng = np.random.default_rng(11)
    t = grid_of(lambda x, y: 0.0 * x, 30, 20, cell=2.0)
    n = 400
    xs, ys = rng.uniform(1.0, 59.0, n), rng.uniform(1.0, 39.0, n)
    ds = np.where(rng.random(n) < 0.1, 4.5, rng.uniform(0.05, 0.6, n))
    stems = kernel3d.stems_of(xs, ys, ds, rng.uniform(2.0, 30.0, n), t)
    gr = kernel3d.Ground(*t.grid(), np.zeros(t.shape, np.int64))
    hits = 0
    for _ in range(300):
        x, y = rng.uniform(1.0, 59.0, 2) * [1.0, 39.0 / 59.0]
        ux, uy = rng.normal(0.0, 8.0, 2)
        z, bz, az, s_end, r = 3.0, rng.normal(), -0.5 * G, rng.uniform(0.1, 2.0), 0.2
        k, s = kernel3d.stem_struck(gr, stems, -1, x, y, z, ux, uy, bz, az, s_end, r)
        every = [kernel3d._stem_entry(stems, i, x, y, z, ux, uy, bz, az, s_end, r)
                 for i in range(stems.x.size)]  # fmt: skip
        best = int(np.argmin(every))
        if math.isinf(every[best]):
            assert k == -1
        else:
            assert (k, s) == (best, every[best])
            hits += 1
    assert hits > 50


def test_hit_probability_other_than_1_is_refused_in_3d():
    t = grid_of(plane(30.0, 0.0), 10, 10)
    model = model_on(t, [(5.0, 5.0)], effects={"tree_impacts": {}})
    model = with_trees(model, [6.0], [5.0], [0.3], [20.0])
    model = replace(model, effects={"tree_impacts": TREES["tree_impacts"]
                                    | {"hit_probability": 0.5}})  # fmt: skip
    with pytest.raises(ArgumentError, match="hit_probability is 0.5; in 3-D"):
        simulate3d(model, 1, np.random.default_rng(0))


def test_strikes_do_not_depend_on_chunks():
    t = grid_of(plane(35.0, 20.0), 60, 60)
    seeder = Seeder3D(height_m=1.0, vx_mps=2.0, vy_sd_mps=1.0)
    model = model_on(t, [(5.0, 20.0)], seeder=seeder, e_n=0.4, e_n_sd=0.1,
                     effects=TREES)  # fmt: skip
    rng = np.random.default_rng(8)
    model = with_trees(model, rng.uniform(5, 55, 300), rng.uniform(5, 55, 300),
                       rng.uniform(0.1, 0.5, 300), rng.uniform(5, 25, 300))  # fmt: skip
    a = simulate3d(model, 120, np.random.default_rng(3))
    b = simulate3d(model, 120, np.random.default_rng(3), chunk_rocks=7)
    assert a.tree_strikes_per_rock.sum() > 20
    assert np.array_equal(a.tree_strikes_per_rock, b.tree_strikes_per_rock)
    assert np.array_equal(a.deposit_xyz, b.deposit_xyz)
    assert np.array_equal(a.path["speed_mps"], b.path["speed_mps"])
