"""Time-force laws of protection structures (thesis section 8.3.2, eqs. 8.2-8.7)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fieldkit.errors import ArgumentError
from fieldkit.physics.structure_forces import (
    THESIS_STRUCTURES,
    StructureLaw,
    contact_time,
    force_at,
    impulse_absorbed,
    peak_force,
)

# Section 8.3.2: 520 kg at 22 m/s -> impulse 11,440 kg m/s.
IMPULSE = 520 * 22.0


def test_thesis_impulse():
    assert IMPULSE == pytest.approx(11440)


@pytest.mark.parametrize(
    ("name", "time_s", "force_kn"),
    [
        ("rigid", 0.15, 151),  # n = 1e6: t1 = 0.15 s, F = 151 kN
        ("flexible", 0.95, 36.1),  # a = 4e4, x = 2.0: t2 = 0.95 s, F = 36.1 kN
        # b = 3e4, x = 0.6: t3 = 0.73 s; F = 24.9 kN by eq. 8.4. The thesis prints
        # 22.0 kN (docs/thesis-notes.md erratum of section 8.3.2).
        ("stiff", 0.73, 24.9),
    ],
)
def test_section_8_3_2_contact_times_and_forces(name, time_s, force_kn):
    law = THESIS_STRUCTURES[name]
    assert contact_time(law, IMPULSE) == pytest.approx(time_s, abs=0.005)
    decimals = 0.5 if force_kn > 100 else 0.05
    assert peak_force(law, IMPULSE) / 1e3 == pytest.approx(force_kn, abs=decimals)


def test_stiff_force_ratios_corrected():
    # Thesis: 22.0/151 = 15 % and 22.0/36.1 = 61 %; with F = 24.9 kN: 16 % and 69 %.
    stiff = peak_force(THESIS_STRUCTURES["stiff"], IMPULSE)
    rigid = peak_force(THESIS_STRUCTURES["rigid"], IMPULSE)
    flexible = peak_force(THESIS_STRUCTURES["flexible"], IMPULSE)
    assert stiff / rigid == pytest.approx(0.16, abs=0.005)
    assert stiff / flexible == pytest.approx(0.69, abs=0.005)


@pytest.mark.parametrize("name", sorted(THESIS_STRUCTURES))
def test_impulse_is_numerical_area_under_force_curve(name):
    law = THESIS_STRUCTURES[name]
    t_end = float(contact_time(law, IMPULSE))
    t = np.linspace(0.0, t_end, 200001)
    f = force_at(law, t)
    area = float(np.sum((f[1:] + f[:-1]) * np.diff(t)) / 2)
    assert area == pytest.approx(IMPULSE, rel=1e-6)
    assert impulse_absorbed(law, t_end) == pytest.approx(IMPULSE, rel=1e-12)


@settings(max_examples=50, deadline=None)
@given(
    coefficient=st.floats(1e2, 1e7),
    exponent=st.floats(0.2, 4.0),
    impulse=st.floats(1.0, 1e6),
)
def test_contact_time_inverts_impulse(coefficient, exponent, impulse):
    law = StructureLaw("any", coefficient, exponent)
    assert impulse_absorbed(law, contact_time(law, impulse)) == pytest.approx(
        impulse, rel=1e-9
    )


def test_bad_laws_and_inputs():
    with pytest.raises(ArgumentError, match="coefficient"):
        StructureLaw("rigid", -1.0, 1.0)
    with pytest.raises(ArgumentError, match="exponent"):
        StructureLaw("stiff", 3e4, 0.0)
    with pytest.raises(ArgumentError, match="impulse_ns"):
        contact_time(THESIS_STRUCTURES["rigid"], -5.0)
    with pytest.raises(ArgumentError, match="t_s"):
        force_at(THESIS_STRUCTURES["rigid"], [0.1, -0.1])
