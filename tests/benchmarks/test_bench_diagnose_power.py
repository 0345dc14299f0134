"""The diagnose benchmark's table builder realises the effect size it is asked for."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_diagnose_power.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_diagnose_power", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def pool():
    """Impact states of 30 paths x 6 impacts (drawn directly: no simulation)."""
    rng = np.random.default_rng(3)
    n = 180
    speed = rng.uniform(8.0, 24.0, n)
    theta = np.radians(rng.uniform(3.0, 45.0, n))  # impact angle to the ground
    slope = rng.uniform(10.0, 40.0, n)
    vt, vn = speed * np.cos(theta), -speed * np.sin(theta)
    psi = np.radians(slope)
    radius = rng.uniform(0.3, 0.45, n)
    return pd.DataFrame(
        {
            "path_id": np.repeat(np.arange(30), 6).astype(str),
            "x_m": np.arange(n, dtype=float),
            "z_m": 100.0 - np.arange(n, dtype=float),
            "slope_deg": slope,
            "material": rng.choice(["rock", "talus", "soil"], n),
            "mass_kg": 500.0,
            "radius_m": radius,
            "gyration_m": 0.82 * radius,
            "vi_x_mps": vt * np.cos(psi) + vn * np.sin(psi),
            "vi_z_mps": -vt * np.sin(psi) + vn * np.cos(psi),
            "omega_i_radps": -rng.uniform(0.3, 1.2, n) * vt / radius,
        }
    )


@pytest.mark.parametrize(
    ("hidden", "narrow"),
    [
        ({"velocity_scaled_restitution": 1.0}, None),
        ({"angle_dependent_restitution": 0.5, "rotation_friction": 0.25}, None),
        ({"angle_dependent_restitution": 0.5}, 0),  # index into NARROW_CASES
    ],
)
def test_realised_effect_size_matches_target(bench, pool, hidden, narrow):
    sigma = 0.25
    table, effects, _ = bench.build_table(
        pool,
        60,
        hidden,
        sigma,
        np.random.default_rng(7),
        narrow=None if narrow is None else bench.NARROW_CASES[narrow],
    )
    assert len(table) == 60
    assert table.frame["path_id"].nunique() >= bench.MIN_PATHS
    # Recompute A independently of the builder's bookkeeping: from the clean
    # rebound rebuilt from the written table's own impact states.
    model = bench.smoke_model()
    states = table.frame
    inputs = bench.inputs_of(states, model)
    for effect, target in hidden.items():
        a = bench.effect_size(inputs, model, {effect: effects[effect]})
        assert a / sigma == pytest.approx(target, rel=0.02)
    # The noise is what was asked for: written SDs, residuals about sigma.
    clean = bench.clean_rebound(inputs, model, effects)
    resid = np.column_stack(
        [
            table.column("vfn_mps") - clean[:, 0],
            table.column("vft_mps") - clean[:, 1],
            (table.column("omega_f_radps") - clean[:, 2]) * inputs.radius_m,
        ]
    )
    assert np.allclose(table.column("vfn_sd_mps"), sigma)
    assert 0.7 * sigma < np.sqrt(np.mean(resid**2)) < 1.3 * sigma


def test_unabsorbed_is_zero_without_effect(bench, pool):
    model = bench.smoke_model()
    states = bench.sample_states(pool, 60, np.random.default_rng(1))
    inputs = bench.inputs_of(states, model)
    assert bench.effect_size(inputs, model, {}) < 1e-12


def test_narrow_tables_have_narrow_speeds(bench, pool):
    for spread, window in bench.NARROW_CASES:
        states = bench.sample_states(
            pool, 30, np.random.default_rng(2), narrow=(spread, window)
        )
        assert len(states) == 30
        speed = np.hypot(states["vi_x_mps"], states["vi_z_mps"])
        assert np.all(np.abs(speed / bench.NARROW_SPEED - 1) <= spread)
