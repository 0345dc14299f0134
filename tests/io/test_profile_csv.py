"""Profile vertices from a CSV: units, materials per segment, strict checks."""

from __future__ import annotations

import doctest

import numpy as np
import pytest

from fieldkit.errors import InputFileError
from fieldkit.io.profile_csv import read_profile_csv


def write(tmp_path, text, name="profile.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_metres_with_materials(tmp_path):
    p = read_profile_csv(write(tmp_path, "x_m,z_m,material\n0,100,rock\n12,80,talus\n"
                                         "40,62,\n"))  # fmt: skip
    assert p.x_m.tolist() == [0.0, 12.0, 40.0] and p.z_m.tolist() == [100, 80, 62]
    assert p.material == ("rock", "talus") and p.plan_x_m is None


def test_feet_from_units_or_header(tmp_path):
    plain = write(tmp_path, "chainage;elevation\n0;328,084\n100;300\n")
    p = read_profile_csv(plain, units="ft")
    np.testing.assert_allclose(p.x_m, [0.0, 30.48])
    np.testing.assert_allclose(p.z_m, [100.0000032, 91.44])
    assert p.material is None
    with pytest.raises(InputFileError, match="has no length unit"):
        read_profile_csv(plain)
    header = write(tmp_path, "x (ft),z_m\n0,5\n10,4\n", "b.csv")
    p = read_profile_csv(header, units="m")  # the header's unit wins
    np.testing.assert_allclose(p.x_m, [0.0, 3.048])
    np.testing.assert_allclose(p.z_m, [5.0, 4.0])


def test_plan_columns_are_kept(tmp_path):
    p = read_profile_csv(write(tmp_path, "x_m,z_m,plan_x_m,plan_y_m,material\n"
                                         "0,10,5,6,rock\n3,9,8,2,\n"))  # fmt: skip
    assert p.plan_x_m.tolist() == [5.0, 8.0] and p.plan_y_m.tolist() == [6.0, 2.0]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("x_m,z_m\n0,10\n5,9\n5,8\n", "row 4: column 'x_m' must increase down the "
         "section: 5 after 5"),
        ("x_m,z_m\n0,10\n5,9\n3,8\n", "row 4: column 'x_m' must increase"),
        ("x_m,z_m\n0,10\n", "row 2: a profile needs at least 2 vertices (got 1)"),
        ("x_m,z_m\n0,10\n5,nan\n", "row 3: column 'z_m': 'nan' is not a finite number"),
        ("x_m,z_m\n0,10\n5,\n", "row 3: column 'z_m' is empty"),
        ("x_m,z_m\n0,10\nfive,9\n", "row 3: column 'x_m': 'five' is not a number"),
        ("x_m,height_m,material\n0,10,\n5,9,\n", "row 2: column 'material' is empty"),
        ("x_m,y_m\n0,10\n5,9\n", "a profile CSV needs columns x, z; missing z"),
    ],
)  # fmt: skip
def test_bad_profiles_are_one_line(tmp_path, text, message):
    path = write(tmp_path, text)
    with pytest.raises(InputFileError) as info:
        read_profile_csv(path)
    line = str(info.value)
    assert line.startswith(str(path)) and message in line and "\n" not in line, line


def test_doctests():
    import fieldkit.io.profile_csv as module

    result = doctest.testmod(module)
    assert result.attempted > 0 and result.failed == 0
