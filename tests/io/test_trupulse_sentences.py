"""TruPulse $PLTIT sentences: checksums, units, formats.

Known-good sentences are the examples printed in Laser Technology's TruPulse 200 User's
Manual, 6th edition, Section 8 (pp. 30-32), found with the search tool; their XOR
checksums were verified independently. The same manual's missing-line example (p. 32)
prints checksums that do not match its characters (*68, *5D, *74; the characters give
*63, *5B, *79), which is why a lenient mode exists.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fieldkit.errors import InputFileError
from fieldkit.io.trupulse import format_trupulse_hv, nmea_checksum, parse_trupulse

MANUAL_GOOD = [
    # sentence, HD, unit, INC, SD
    ("$PLTIT,HV,11.80,M,0.00,D,3.70,D,11.80,M*63", 11.80, "M", 3.70, 11.80),
    ("$PLTIT,HV,7.01,M,0.00,D,3.00,D,7.01,M*64", 7.01, "M", 3.00, 7.01),
    ("$PLTIT,HV,16.00,F,0.00,D,-1.20,D,16.00,F*49", 16.00, "F", -1.20, 16.00),
]
MANUAL_BAD_CHECKSUM = [
    ("$PLTIT,HV,6.00,Y,0.00,D,7.20,D,6.10,Y*68", "63"),
    ("$PLTIT,HV,5.90,Y,0.00,D,11.60,D,6.00,Y*5D", "5B"),
    ("$PLTIT,ML,8.10,Y,0.00,D,3.20,D,8.10,Y*74", "79"),
]
METRES = {"M": 1.0, "F": 0.3048, "Y": 0.9144}


def xor_checksum(body: str) -> int:
    """Independent XOR loop (not the module's reduce)."""
    value = 0
    for byte in body.encode("ascii"):
        value ^= byte
    return value


@pytest.mark.parametrize(("sentence", "hd", "unit", "inc", "sd"), MANUAL_GOOD)
def test_manual_examples_parse(sentence, hd, unit, inc, sd):
    shot = parse_trupulse(sentence)
    assert shot.kind == "HV"
    assert shot.checksum_ok
    assert shot.units == unit
    assert shot.horizontal_distance_m == pytest.approx(hd * METRES[unit], abs=1e-12)
    assert shot.slope_distance_m == pytest.approx(sd * METRES[unit], abs=1e-12)
    assert shot.inclination_deg == inc
    assert shot.azimuth_deg == 0.0  # TruPulse 200: no compass


@pytest.mark.parametrize(("sentence", "hd", "unit", "inc", "sd"), MANUAL_GOOD)
def test_checksum_matches_independent_xor(sentence, hd, unit, inc, sd):
    body, _, given_checksum = sentence[1:].partition("*")
    assert int(given_checksum, 16) == xor_checksum(body)
    assert nmea_checksum(body) == given_checksum


def test_height_and_inclination_only_messages():
    assert parse_trupulse("$PLTIT,HT,15.70,F*0E").height_m == pytest.approx(
        15.70 * 0.3048
    )
    assert parse_trupulse("$PLTIT,HT,5.50,M*36").height_m == 5.50
    shot = parse_trupulse("$PLTIT,HV,,,0.00,D,29.10,D,,*5D")
    assert math.isnan(shot.horizontal_distance_m)
    assert math.isnan(shot.slope_distance_m)
    assert shot.inclination_deg == 29.10


@pytest.mark.parametrize(("sentence", "computed"), MANUAL_BAD_CHECKSUM)
def test_manual_missing_line_example_has_bad_checksums(sentence, computed):
    body = sentence[1:].partition("*")[0]
    assert f"{xor_checksum(body):02X}" == computed
    with pytest.raises(InputFileError, match=f"bad TruPulse checksum.*\\*{computed}"):
        parse_trupulse(sentence)
    shot = parse_trupulse(sentence, lenient=True)
    assert not shot.checksum_ok
    assert shot.horizontal_distance_m == pytest.approx(
        float(body.split(",")[2]) * 0.9144
    )


def test_corrupted_sentence_rejected_and_lenient_accepts():
    good = "$PLTIT,HV,11.80,M,0.00,D,3.70,D,11.80,M*63"
    corrupted = good.replace("11.80,M,0.00", "11.86,M,0.00")  # one digit changed
    with pytest.raises(InputFileError, match="bad TruPulse checksum"):
        parse_trupulse(corrupted)
    assert parse_trupulse(corrupted, lenient=True).horizontal_distance_m == 11.86
    with pytest.raises(InputFileError, match="no \\*checksum"):
        parse_trupulse(good.split("*")[0])
    assert parse_trupulse(good.split("*")[0], lenient=True).checksum_ok is False
    assert parse_trupulse("$PLTIT,HV,,,0.00,D,29.10,D,,*5d\r\n").checksum_ok  # hex case


@pytest.mark.parametrize(
    ("sentence", "message"),
    [
        ("$GPGGA,123519,4807.038,N*47", "not a TruPulse"),
        ("$PLTIT,XX,1*00", "not HV, HT or ML"),
        ("$PLTIT,HV,11.80,M,0.00,D,3.70,D*", "needs 8 values"),
        ("$PLTIT,HV,1x.80,M,0.00,D,3.70,D,11.80,M*", "'1x.80' is not a number"),
        ("$PLTIT,HV,11.80,K,0.00,D,3.70,D,11.80,M*", "unit 'K'"),
    ],
)
def test_malformed_sentences(sentence, message):
    body = sentence[1:].partition("*")[0]
    fixed = f"{sentence.split('*')[0]}*{nmea_checksum(body)}"
    with pytest.raises(InputFileError, match=message):
        parse_trupulse(fixed)


def test_format_reproduces_manual_sentences():
    for sentence, hd, unit, inc, sd in MANUAL_GOOD:
        scale = METRES[unit]
        assert format_trupulse_hv(hd * scale, 0.0, inc, sd * scale, units=unit) == (
            sentence
        )


@settings(max_examples=60, deadline=None)
@given(
    hd=st.floats(0.5, 900.0),
    azimuth=st.floats(0.0, 359.99),
    inclination=st.floats(-80.0, 80.0),
    unit=st.sampled_from(["M", "F", "Y"]),
)
def test_format_then_parse_round_trip(hd, azimuth, inclination, unit):
    sd = hd / math.cos(math.radians(inclination))
    shot = parse_trupulse(format_trupulse_hv(hd, azimuth, inclination, sd, units=unit))
    half_step = 0.005 * METRES[unit] + 1e-9  # two decimals in the instrument's unit
    assert shot.checksum_ok
    assert abs(shot.horizontal_distance_m - hd) <= half_step
    assert abs(shot.slope_distance_m - sd) <= half_step
    assert abs(shot.inclination_deg - inclination) <= 0.005 + 1e-9
    assert min(
        abs(shot.azimuth_deg - azimuth), 360 - abs(shot.azimuth_deg - azimuth)
    ) <= (0.005 + 1e-9)


def test_format_rejects_unknown_units():
    from fieldkit.errors import ArgumentError

    with pytest.raises(ArgumentError, match="units must be M, F or Y"):
        format_trupulse_hv(10.0, 0.0, 0.0, 10.0, units="KM")
