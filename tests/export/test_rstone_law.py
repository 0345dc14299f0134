"""r.stone's law ported along a section (fieldkit.export.rstone_law): analytic cases.

Every case builds the law by hand (no spread: ranges 0) on a small section whose
vertices are cell centres, and checks a number that follows from r.stone's
rules in points.c (G = 9.805 m/s², stone.h).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fieldkit.export.rstone_law import G_MPS2, RstoneLaw
from fieldkit.model.results import EXITED_DOWNSLOPE, STOPPED


def _law(x, z, *, nrest=100, trest=100, friction=0.5, start=2.0, stop=0.0,
         ranges=(0, 0, 0), release=None) -> RstoneLaw:  # fmt: skip
    x = np.asarray(x, float)
    n = x.size
    return RstoneLaw(
        x_m=x,
        z_m=np.asarray(z, float),
        nrest_pct=np.full(n, nrest),
        trest_pct=np.full(n, trest),
        friction_tan=np.full(n, friction),
        vrest_stoch_range=ranges[0],
        hrest_stoch_range=ranges[1],
        frict_stoch_range=ranges[2],
        start_vel_mps=start,
        stop_vel_mps=stop,
        release_x_m=float(x[0] if release is None else release),
        mass_kg=1000.0,
    )


def _run(law, at=(), rocks=1, seed=0):
    return law.simulate(rocks, np.random.default_rng(seed), at)


def test_rolling_stop_on_flat_ground_from_speed_v():
    # A 1 m step: the launch at 2 m/s lands on the flat at x = 2 sqrt(2 / g), 1.35
    # m from the release and at 4.86 m/s: r.stone rolls (short AND slow), keeping
    # the velocity in the plane (2 m/s), and brakes by g sin(beta): the rock stops
    # after v² / (2 g sin(beta)), exactly (points.c Roll, 'stop between two steps').
    law = _law([0.0, 0.2, 300.0], [1.0, 0.0, 0.0], friction=0.5, start=2.0)
    result = _run(law)
    landing = 2.0 * math.sqrt(2.0 / G_MPS2)
    brake = G_MPS2 * math.sin(math.atan(0.5))
    assert result.state[0] == STOPPED and result.impacts_per_rock[0] == 0
    expected = landing + 2.0**2 / (2 * brake)
    assert result.runout_x_m[0] == pytest.approx(expected, abs=1e-9)


def test_energy_is_conserved_with_nrest_and_trest_100_and_no_stop():
    # Elastic bounces (both factors 1, no spread), no stop speed, fast enough never
    # to roll: the speed at every crossing is that of a free fall from the start.
    x = np.arange(0.0, 201.0, 5.0)
    z = 150.0 - 0.6 * x + 3.0 * np.sin(x / 7.0)
    law = _law(x, z, start=10.0)
    at = [23.0, 61.0, 97.5, 144.0, 188.0]
    result = _run(law, at, rocks=3)
    assert (result.state == EXITED_DOWNSLOPE).all()
    assert result.impacts_per_rock.min() >= 3
    for point in result.analysis:
        assert point.crossed.all()
        ground = np.interp(point.x_m, x, z)
        energy = point.speed_mps**2 / 2 + G_MPS2 * (ground + point.height_m)
        np.testing.assert_allclose(energy, 10.0**2 / 2 + G_MPS2 * z[0], rtol=1e-9)
        np.testing.assert_allclose(point.total_j, 1000.0 * point.speed_mps**2 / 2)


def test_the_roll_switch_needs_a_short_and_a_slow_bounce():
    # Short (1.35 m) and slow (4.86 m/s): rolls, no bounce.
    short_slow = _run(_law([0.0, 0.2, 300.0], [1.0, 0.0, 0.0], start=2.0))
    assert short_slow.impacts_per_rock[0] == 0
    # Short (0.55 m) but fast (5.5 m/s: a 1.5 m drop at 1 m/s): bounces.
    short_fast = _run(_law([0.0, 0.1, 300.0], [1.5, 0.0, 0.0], start=1.0,
                           nrest=10, trest=10, stop=1.0))  # fmt: skip
    drop = math.sqrt(2 * 1.5 / G_MPS2)
    assert math.hypot(drop, 1.5) < 3 and math.hypot(1.0, G_MPS2 * drop) > 5
    assert short_fast.impacts_per_rock[0] >= 1
    # Slow but long: a frictionless roll over a convex break flies again and lands
    # at about 3.1 m/s, 11.4 m from the last bounce point (the release: no bounce
    # yet): bounces.
    x = [0.0, 0.2, 10.0, 300.0]
    z = [1.0, 0.0, 0.0, -58.0]
    slow_long = _run(_law(x, z, start=2.0, friction=0.0, nrest=10, trest=10,
                          stop=1.0))  # fmt: skip
    assert slow_long.impacts_per_rock[0] >= 1


def test_a_launch_off_a_cliff_lands_where_the_parabola_says():
    # 20 m cliff, 5 m/s horizontal launch: lands at 5 sqrt(2 h / g); nrest 0 there
    # is r.stone's water (Bounce): the rock stops where it landed.
    law = _law([0.0, 0.5, 300.0], [20.0, 0.0, 0.0], nrest=0, start=5.0)
    result = _run(law, at=[5.0])
    assert result.state[0] == STOPPED
    assert result.runout_x_m[0] == pytest.approx(5.0 * math.sqrt(40.0 / G_MPS2))
    point = result.analysis[0]
    assert point.height_m[0] == pytest.approx(20.0 - G_MPS2 / 2)  # t = 1 s
    assert point.speed_mps[0] == pytest.approx(math.hypot(5.0, G_MPS2))


def test_the_seed_reproduces_a_run_exactly():
    x = np.arange(0.0, 301.0, 5.0)
    z = np.where(x < 150, 200 - 0.9 * x, 65.0)
    law = _law(x, z, nrest=30, trest=70, friction=0.7, start=3.0, stop=0.5,
               ranges=(5, 5, 5))  # fmt: skip
    a = _run(law, at=[100.0, 200.0], rocks=200, seed=11)
    b = _run(law, at=[100.0, 200.0], rocks=200, seed=11)
    c = _run(law, at=[100.0, 200.0], rocks=200, seed=12)
    np.testing.assert_array_equal(a.runout_x_m, b.runout_x_m)
    np.testing.assert_array_equal(a.state, b.state)
    for p, q in zip(a.analysis, b.analysis, strict=True):
        np.testing.assert_array_equal(p.speed_mps, q.speed_mps)
        np.testing.assert_array_equal(p.height_m, q.height_m)
    assert not np.array_equal(a.runout_x_m, c.runout_x_m)
    assert (a.state == STOPPED).all()
    assert np.ptp(a.runout_x_m) > 0  # the draws spread the runouts


def test_the_export_readme_states_the_ported_law(cli, repo, tmp_path):
    out = tmp_path / "rstone"
    r = cli("export", repo / "surveys/tornado_mountain/model_path_calibrated.json",
            "--to", "rstone", "--extrude", "-o", out)  # fmt: skip
    assert r.exit_code == 0, r.stderr
    readme = (out / "README.md").read_text()
    assert "2-D port of r.stone's own kernel" in readme
    assert "shorter than 3 m and slower than 5 m/s (both)" in readme
    assert "slide_vn_mps" not in readme.split("## Translation error")[1].split("##")[0]
    assert f"wrote {out / 'README.md'}" in r.stderr + r.stdout


def test_a_dem_export_emulates_from_the_release_cell(cli, repo, tmp_path):
    # Tschamut's seeder lies at chainage 0, the section's first point: the
    # emulation's cell centres start there (r.stone starts a rock at its release
    # cell's centre), so its rocks start, run and leave the section's lower end
    # as the calibrated model's do (none left at the upper end at once).
    out = tmp_path / "rstone"
    r = cli("export", repo / "examples/tschamut/model_base.json", "--to", "rstone",
            "-o", out, "--dem", repo / "tests/data/tschamut2014/terrain.asc",
            "--release", "30.602,235.28")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    readme = (out / "README.md").read_text()
    assert "| runout p50 | 150 ± 0 m | 150 ± 0 m |" in readme
    assert "72.4 % (calibrated), 96.5 % (emulated)" in readme
