"""Restitution laws: eq. 5.4 (angle), eq. 7.1 (velocity scaling), constant."""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.errors import ArgumentError
from fieldkit.physics.restitution import (
    ANGLE_LAW_A,
    ANGLE_LAW_B,
    VELOCITY_SCALE_MPS,
    angle_dependent_restitution,
    constant_restitution,
    velocity_scaled_restitution,
)


def test_equation_5_4_thesis_values():
    # Thesis §5.2.3 / worked example 4A: theta_i = 25 deg -> e_N = 0.71;
    # theta_i = 50 deg -> 0.35 (docs/thesis-notes.md).
    assert (ANGLE_LAW_A, ANGLE_LAW_B) == (19.5, 1.03)
    e = angle_dependent_restitution([25.0, 50.0])
    assert e == pytest.approx([0.71, 0.35], abs=0.005)


def test_equation_5_4_shape():
    # Fig. 5.5: e_N > 1 for shallow impacts (below ~18 deg), ~0.3 at 60 deg,
    # and falling monotonically with the impact angle.
    theta = np.linspace(5, 90, 50)
    e = angle_dependent_restitution(theta)
    assert np.all(np.diff(e) < 0)
    assert angle_dependent_restitution(15.0) > 1.0
    assert angle_dependent_restitution(60.0) == pytest.approx(0.3, abs=0.02)
    # power law: log-linear with slope -b
    slope = np.polyfit(np.log(theta), np.log(e), 1)[0]
    assert slope == pytest.approx(-1.03, abs=1e-9)


def test_equation_7_1_scaling_factor():
    # Thesis §7.3.4: the factor 1/(1 + (v_iN/K)^2) is 0.5 at |v_iN| = K = 9.14 m/s
    # (30 ft/s) and tends to 1 for slow impacts.
    assert VELOCITY_SCALE_MPS == pytest.approx(30 * 0.3048)
    assert velocity_scaled_restitution(-VELOCITY_SCALE_MPS, 1.0) == pytest.approx(0.5)
    assert velocity_scaled_restitution(-0.01, 0.6) == pytest.approx(0.6, rel=1e-5)
    # restitution normal velocity v_fN = e_N |v_iN| / (1 + (v_iN/K)^2)
    v_in = -12.0
    v_fn = velocity_scaled_restitution(v_in, 0.5, 20.0) * abs(v_in)
    assert v_fn == pytest.approx(0.5 * 12.0 / (1 + (12.0 / 20.0) ** 2))


def test_law_functions():
    theta = np.array([20.0, 40.0])
    v_in = np.array([-3.0, -12.0])
    assert constant_restitution(0.4) == pytest.approx(0.4)
    assert angle_dependent_restitution(theta) == pytest.approx(
        ANGLE_LAW_A * theta ** (-ANGLE_LAW_B)
    )
    assert velocity_scaled_restitution(v_in, 0.8, 10.0) == pytest.approx(
        0.8 / (1 + (v_in / 10.0) ** 2)
    )


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: angle_dependent_restitution(0.0), r"theta_i_deg must be in \(0, 90\]"),
        (lambda: angle_dependent_restitution(95.0), r"theta_i_deg .* \(got 95\)"),
        (lambda: angle_dependent_restitution(-5.0), r"theta_i_deg"),
        (lambda: angle_dependent_restitution(np.nan), r"theta_i_deg must be finite"),
        (lambda: angle_dependent_restitution(25.0, a=-1.0), r"a must be > 0"),
        (lambda: angle_dependent_restitution(25.0, b=-0.5), r"b must be >= 0"),
        (lambda: constant_restitution(-0.1), r"e_n must be >= 0 \(got -0.1\)"),
        (
            lambda: velocity_scaled_restitution(-3.0, 0.5, 0.0),
            r"velocity_scale_mps must be > 0",
        ),
        (lambda: velocity_scaled_restitution(-3.0, -0.5), r"e_n must be >= 0"),
    ],
)
def test_bad_input_names_the_argument(call, message):
    with pytest.raises(ArgumentError, match=message):
        call()
