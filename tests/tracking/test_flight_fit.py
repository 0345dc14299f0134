"""Ballistic flight fits: exact parabolas, noise, and the wrong-capture-rate warning."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fieldkit.physics.constants import G
from fieldkit.tracking.flights.ballistic_fit import fit_flight


def parabola(t, x0, z0, vx, vz, g=G):
    return x0 + vx * t, z0 + vz * t - 0.5 * g * t**2


@settings(max_examples=25, deadline=None)
@given(
    x0=st.floats(-5, 5),
    z0=st.floats(-5, 5),
    vx=st.floats(-20, 20),
    vz=st.floats(-20, 20),
    n=st.integers(5, 400),
)
def test_exact_parabola_is_recovered(x0, z0, vx, vz, n):
    t = np.arange(n) / 1205.0 + 0.37
    x, z = parabola(t - 0.37, x0, z0, vx, vz)
    fit = fit_flight(t, x, z)
    assert fit.g_mps2 == pytest.approx(
        G, rel=1e-5, abs=1e-4 * (1 + 1 / (n / 1205) ** 2)
    )
    px, pz = fit.position(t)
    assert np.max(np.hypot(px - x, pz - z)) < 1e-9
    vxf, vzf = fit.velocity(0.37)
    assert float(vxf) == pytest.approx(vx, abs=1e-7)
    assert float(vzf) == pytest.approx(vz, abs=1e-7)


def test_noisy_flight_gravity_within_its_standard_error():
    rng = np.random.default_rng(7)
    t = np.arange(240) / 1205.0  # 0.2 s
    x, z = parabola(t, 0.0, 1.0, 2.5, 1.2)
    hits = 0
    for _ in range(40):
        f = fit_flight(
            t, x + rng.normal(0, 5e-4, t.size), z + rng.normal(0, 5e-4, t.size)
        )
        hits += abs(f.g_mps2 - G) <= 2.0 * f.g_se_mps2
        # velocity error: reported SE is honest to a factor ~3
        assert abs(f.vx_mps - 2.5) < 4 * f.vx_se_mps
        assert f.gravity_warning() is None
    # ~95 % of 2-sigma intervals should cover the truth
    assert hits >= 34
    # analytic SE of the quadratic coefficient for n uniform samples over T:
    # g = -2 c, var(c) = sigma^2 / (n T^4 / 180)
    duration = t[-1] - t[0]
    expected = 2 * 5e-4 * np.sqrt(180.0 / (t.size * duration**4))
    assert f.g_se_mps2 == pytest.approx(expected, rel=0.25)


def test_wrong_capture_rate_scales_gravity_and_warns():
    t_true = np.arange(300) / 1205.0
    x, z = parabola(t_true, 0.0, 1.0, 2.0, 0.5)
    fps_given = 1100.0
    t_given = np.arange(300) / fps_given
    f = fit_flight(t_given, x, z)
    assert f.g_mps2 == pytest.approx(G * (fps_given / 1205.0) ** 2, rel=1e-9)
    message = f.gravity_warning()
    assert message is not None and "-16.7 %" in message and "`fps`" in message
    # the factor the warning suggests restores the true rate: fps_given times it is
    # 1205 (dividing instead would give 1004). Printed with 4 significant digits
    # (1.095 for 1.09545...), so the product is right to 5e-4.
    printed = float(re.search(r"times (\S+) would fit", message).group(1))
    assert fps_given * printed == pytest.approx(1205.0, rel=5e-4)
    assert fps_given * np.sqrt(G / f.g_mps2) == pytest.approx(1205.0, rel=1e-9)


def test_too_few_samples():
    with pytest.raises(ValueError):
        fit_flight([0.0, 0.1, 0.2], [0, 1, 2], [0, 1, 2])
