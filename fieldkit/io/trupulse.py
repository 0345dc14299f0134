"""Laser Technology TruPulse serial sentences (Criterion 400 / NMEA-style ``$PLTIT``).

Formats (TruPulse 200 User's Manual, 6th ed., Section 8 "Serial Data Interface"; the
360 uses the same messages with a real azimuth)::

    $PLTIT,HV,<HD>,<u>,<AZ>,D,<INC>,D,<SD>,<u>*<cs>    horizontal vector
    $PLTIT,HT,<HT>,<u>*<cs>                             height
    $PLTIT,ML,<HD>,<u>,<AZ>,D,<INC>,D,<SD>,<u>*<cs>    missing line (shot 1 → shot 2)

``u`` is F (feet), Y (yards) or M (metres); values carry two decimals; inclination may
be negative; an "inclination only" shot leaves HD and SD empty. The checksum is the XOR
of every character between ``$`` and ``*``, in two hex digits. The TruPulse 200 has no
compass and always sends azimuth 0.00; the 360's azimuth is magnetic unless the user set
a declination in the instrument, and the sentence does not say which (the field book
does: :mod:`fieldkit.io.fieldbook`, ``azimuth_reference``).

Checksums are verified strictly by default. ``lenient=True`` accepts a wrong or missing
checksum and records it in :attr:`TruPulseShot.checksum_ok` (the manual's own
missing-line example sentences carry wrong checksums).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import reduce

from fieldkit.errors import ArgumentError, InputFileError

#: Metres per instrument length unit.
TRUPULSE_UNITS: dict[str, float] = {"M": 1.0, "F": 0.3048, "Y": 0.9144}


@dataclass(frozen=True)
class TruPulseShot:
    """One decoded TruPulse message, lengths in metres, angles in degrees.

    ``horizontal_distance_m``, ``slope_distance_m``, ``azimuth_deg`` and
    ``inclination_deg`` are NaN when the message does not carry them (HT messages,
    inclination-only shots); ``height_m`` is NaN except for HT messages.
    """

    kind: str
    horizontal_distance_m: float
    azimuth_deg: float
    inclination_deg: float
    slope_distance_m: float
    height_m: float = math.nan
    units: str = "M"
    checksum_ok: bool = True
    sentence: str = ""


def nmea_checksum(body: str) -> str:
    """XOR of the characters of ``body`` (the text between ``$`` and ``*``), as 2 hex.

    Examples
    --------
    >>> nmea_checksum("PLTIT,HV,11.80,M,0.00,D,3.70,D,11.80,M")
    '63'
    """
    return f"{reduce(lambda acc, ch: acc ^ ord(ch), body, 0):02X}"


def _number(text: str, what: str, sentence: str) -> float:
    if text.strip() == "":
        return math.nan
    try:
        value = float(text)
    except ValueError:
        raise InputFileError(
            f"TruPulse {what} '{text}' is not a number in '{sentence}'"
        ) from None
    if not math.isfinite(value):
        raise InputFileError(f"TruPulse {what} '{text}' is not finite in '{sentence}'")
    return value


def _length(value_text: str, unit_text: str, what: str, sentence: str) -> float:
    value = _number(value_text, what, sentence)
    if math.isnan(value):
        return value
    unit = unit_text.strip().upper()
    if unit not in TRUPULSE_UNITS:
        raise InputFileError(
            f"TruPulse {what} unit '{unit_text}' is not F, Y or M in '{sentence}'"
        )
    if value < 0:
        raise InputFileError(
            f"TruPulse {what} {value_text} is negative in '{sentence}'"
        )
    return value * TRUPULSE_UNITS[unit]


def _angle(value_text: str, unit_text: str, what: str, sentence: str) -> float:
    value = _number(value_text, what, sentence)
    if not math.isnan(value) and unit_text.strip().upper() != "D":
        raise InputFileError(
            f"TruPulse {what} unit '{unit_text}' is not D (degrees) in '{sentence}'"
        )
    return value


def parse_trupulse(sentence: str, *, lenient: bool = False) -> TruPulseShot:
    """Decode a ``$PLTIT`` HV, HT or ML sentence.

    Parameters
    ----------
    sentence
        One line as the instrument sends it (surrounding whitespace ignored).
    lenient
        Accept a wrong or missing checksum (``checksum_ok`` tells which).

    Raises
    ------
    InputFileError
        Not a ``$PLTIT`` sentence, unknown message type, wrong field count, text in a
        number, unknown unit, bad checksum (unless lenient). The message quotes the
        sentence; callers add the file and row.

    Examples
    --------
    The manual's high-quality-target example (TruPulse 200, 6th ed., p. 30):

    >>> shot = parse_trupulse("$PLTIT,HV,11.80,M,0.00,D,3.70,D,11.80,M*63")
    >>> shot.kind, shot.horizontal_distance_m, shot.inclination_deg
    ('HV', 11.8, 3.7)
    >>> round(parse_trupulse("$PLTIT,HT,15.70,F*0E").height_m, 5)
    4.78536
    """
    text = sentence.strip()
    if not text.startswith("$PLTIT,"):
        raise InputFileError(f"not a TruPulse $PLTIT sentence: '{text}'")
    if "*" in text:
        body, _, given = text[1:].partition("*")
        given = given.strip().upper()
    else:
        body, given = text[1:], ""
    computed = nmea_checksum(body)
    checksum_ok = given == computed
    if not checksum_ok and not lenient:
        if given:
            raise InputFileError(
                f"bad TruPulse checksum: sentence says *{given}, the characters give "
                f"*{computed} in '{text}'"
            )
        raise InputFileError(f"TruPulse sentence has no *checksum: '{text}'")
    fields = body.split(",")
    if fields and fields[-1] == "" and len(fields) in (5, 11):
        fields = fields[:-1]  # the manual's format line shows a comma before '*'
    kind = fields[1].strip().upper() if len(fields) > 1 else ""
    if kind in ("HV", "ML"):
        if len(fields) != 10:
            raise InputFileError(
                f"TruPulse {kind} sentence needs 8 values, has {len(fields) - 2}: "
                f"'{text}'"
            )
        hd = _length(fields[2], fields[3], "horizontal distance", text)
        az = _angle(fields[4], fields[5], "azimuth", text)
        inc = _angle(fields[6], fields[7], "inclination", text)
        sd = _length(fields[8], fields[9], "slope distance", text)
        if not math.isnan(az) and not 0.0 <= az <= 360.0:
            raise InputFileError(
                f"TruPulse azimuth {az:g} is outside 0-360 in '{text}'"
            )
        if not math.isnan(inc) and not -90.0 <= inc <= 90.0:
            raise InputFileError(
                f"TruPulse inclination {inc:g} is outside ±90 in '{text}'"
            )
        units = (fields[3] or fields[9] or "M").strip().upper()
        return TruPulseShot(kind, hd, az, inc, sd, math.nan, units, checksum_ok, text)
    if kind == "HT":
        if len(fields) != 4:
            raise InputFileError(
                f"TruPulse HT sentence needs 2 values, has {len(fields) - 2}: '{text}'"
            )
        height = _number(fields[2], "height", text)
        unit = fields[3].strip().upper()
        if unit not in TRUPULSE_UNITS:
            raise InputFileError(
                f"TruPulse height unit '{fields[3]}' is not F, Y or M in '{text}'"
            )
        nan = math.nan
        return TruPulseShot(
            "HT",
            nan,
            nan,
            nan,
            nan,
            height * TRUPULSE_UNITS[unit],
            unit,
            checksum_ok,
            text,
        )
    raise InputFileError(
        f"TruPulse message type '{kind}' is not HV, HT or ML in '{text}'"
    )


def format_trupulse_hv(
    horizontal_distance_m: float,
    azimuth_deg: float,
    inclination_deg: float,
    slope_distance_m: float,
    *,
    units: str = "M",
) -> str:
    """The ``$PLTIT,HV`` sentence a TruPulse would send for a shot, with its checksum.

    Lengths are given in metres and written in ``units`` (M, F or Y) with two decimals,
    like the instrument; azimuth and inclination with two decimals. A NaN distance
    leaves its field empty (inclination-only shot).

    Examples
    --------
    >>> format_trupulse_hv(11.8, 0.0, 3.7, 11.8)
    '$PLTIT,HV,11.80,M,0.00,D,3.70,D,11.80,M*63'
    >>> format_trupulse_hv(16.0 * 0.3048, 0.0, -1.2, 16.0 * 0.3048, units="F")
    '$PLTIT,HV,16.00,F,0.00,D,-1.20,D,16.00,F*49'
    """
    unit = units.strip().upper()
    if unit not in TRUPULSE_UNITS:
        raise ArgumentError(f"units must be M, F or Y, not '{units}'", source="units")
    scale = TRUPULSE_UNITS[unit]

    def length(value: float) -> tuple[str, str]:
        if value is None or math.isnan(value):
            return "", ""
        return f"{value / scale:.2f}", unit

    azimuth = round(float(azimuth_deg) % 360.0, 2) % 360.0
    inclination = round(float(inclination_deg), 2) + 0.0  # no "-0.00"
    hd, hd_unit = length(horizontal_distance_m)
    sd, sd_unit = length(slope_distance_m)
    body = f"PLTIT,HV,{hd},{hd_unit},{azimuth:.2f},D,{inclination:.2f},D,{sd},{sd_unit}"
    return f"${body}*{nmea_checksum(body)}"
