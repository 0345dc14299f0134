"""Path-level fit: determinism of the objective, recovery of known parameters from
synthetic sites, and the report of what the runs cannot pin down."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fieldkit.errors import ArgumentError
from fieldkit.fit.path_fit import PathObjective, fit_paths, parameter_bounds
from fieldkit.fit.path_runs import PathRun
from fieldkit.fit.synthetic_paths import synthetic_site

ET = "materials.talus.e_t"
PHI = "materials.talus.friction_deg"
TRUTH = {ET: 0.7, PHI: 34.0}  # base model (the start): e_t 0.8, friction 30 deg


def test_objective_deterministic_for_a_seed_and_differs_for_another():
    site = synthetic_site(TRUTH, 4, np.random.default_rng(5))
    x = np.array([0.75, 32.0])
    a = PathObjective(site, [ET, PHI], 100, seed=3)
    b = PathObjective(site, [ET, PHI], 100, seed=3)
    c = PathObjective(site, [ET, PHI], 100, seed=4)
    assert np.array_equal(a.per_run(x), b.per_run(x))
    assert a(x) == b(x)
    assert c(x) != a(x)
    # and it moves with the parameters (friction controls the runout)
    assert a(np.array([0.75, 40.0])) > a(x) + 1.0


def test_objective_leaves_out_unobserved_runs_and_keeps_their_streams():
    site = synthetic_site(TRUTH, 3, np.random.default_rng(5))
    gap = PathRun("gap", site[0].model, math.nan)
    full = PathObjective(site, [PHI], 50, seed=1)
    holed = PathObjective([site[0], gap, *site[1:]], [PHI], 50, seed=1)
    assert len(holed.runs) == 3
    # run i keeps stream [seed, i] of its position in the list given
    assert holed.index == [0, 2, 3]
    assert np.array_equal(full.per_run([30.0])[0], holed.per_run([30.0])[0])


def test_parameter_bounds():
    assert parameter_bounds(PHI) == (5.0, 60.0)
    assert parameter_bounds("materials.talus.friction_deg_sd") == (0.0, 15.0)
    assert parameter_bounds("angle_dependent_restitution.b") == (0.0, 3.0)
    assert parameter_bounds("core.stop_speed_mps") == (0.0, 10.0)
    with pytest.raises(ArgumentError, match="each run's own"):
        parameter_bounds("body.mass_kg")
    with pytest.raises(ArgumentError, match="no finite search bounds"):
        parameter_bounds("velocity_scaled_restitution.k_mps")


def test_fit_refuses_unknown_parameter():
    site = synthetic_site(TRUTH, 2, np.random.default_rng(5))
    with pytest.raises(ArgumentError, match="unknown parameter"):
        fit_paths(site, site[0].model, ["materials.rock.e_t"], bootstrap=0)


@pytest.fixture(scope="module")
def recovered():
    """Fits of 10 and 40 synthetic runs (true e_t 0.7, friction 34 deg) from the
    base model's 0.8 and 30 deg."""
    out = {}
    for n in (10, 40):
        site = synthetic_site(TRUTH, n, np.random.default_rng(n))
        out[n] = fit_paths(site, site[0].model, [ET, PHI], rocks=200, seed=0)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("n", [10, 40])
def test_recovers_truth_within_interval(recovered, n):
    r = recovered[n]
    assert r.objective_optimum < r.objective_start
    for name, true in TRUTH.items():
        lo, hi = r.interval(name)
        assert lo <= true <= hi, (name, r.value(name), lo, hi)
        assert abs(r.value(name) - true) <= 2.0 * r.error(name)
    assert r.model.materials["talus"].friction_deg == pytest.approx(r.value(PHI))
    assert r.n_evaluations > 0 and r.wall_s > 0


@pytest.mark.slow
def test_more_runs_give_narrower_intervals(recovered):
    for name in TRUTH:
        small = np.diff(recovered[10].interval(name))[0]
        large = np.diff(recovered[40].interval(name))[0]
        assert large < small, (name, small, large)
    # 40 runs pin both down; friction is pinned at either size
    assert recovered[40].pinned == [True, True]
    assert recovered[10].pinned[1]


@pytest.mark.slow
def test_flat_parameter_is_reported_not_pinned():
    # core.drag_dt_s does nothing without air drag: the runs cannot inform it
    site = synthetic_site(TRUTH, 10, np.random.default_rng(10))
    r = fit_paths(
        site, site[0].model, [PHI, "core.drag_dt_s"], rocks=200, seed=0, bootstrap=10
    )
    assert r.pinned == [True, False]
    assert r.interval("core.drag_dt_s") == parameter_bounds("core.drag_dt_s")
    assert any("core.drag_dt_s not pinned down" in note for note in r.notes)
