"""RocFall export and import: round trip, distribution convention, refusals.

Reference numbers are hand computations: 3 SD bounds (3 x 0.04 = 0.12, 3 x 1.5 =
4.5), the truncated-normal mean of N(1, 0.04) on [0.88, 1] from tabulated phi(0) =
0.398942, phi(3) = 0.004432, Phi(-3) = 0.001350, the velocity above which a scaled
Rn of 1.2 falls below 1 (9.144 sqrt(0.2)), arctan((1 - Rt)/Rt) for Rt = 0.59.
"""

from __future__ import annotations

import math
from dataclasses import fields

import numpy as np
import pytest

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.export.rocfall import (
    Distribution,
    clipped_mean,
    distribution,
    export_rocfall,
    truncated_mean,
)
from fieldkit.export.rocfall_import import Text, model_from_rocfall, read_rocfall
from fieldkit.model.model_file import model_from_dict, model_to_dict, read_model

TABLE_7_1 = "surveys/tornado_mountain/model_rocfall_table_7_1.json"


@pytest.fixture()
def table_7_1(repo):
    """Table 7-1's model as a dict (profile, two materials, roughness on)."""
    return model_to_dict(read_model(repo / TABLE_7_1))


def _scaled(data, k_mps=None):
    data = dict(data, effects=dict(data["effects"]))
    data["effects"]["velocity_scaled_restitution"] = (
        {} if k_mps is None else {"k_mps": k_mps}
    )
    return model_from_dict(data)


def _reimport(export, **kwargs):
    files = export.files
    return model_from_rocfall(
        Text(files["materials.txt"], "materials.txt"),
        Text(files["slope.csv"], "slope.csv"),
        Text(files["rock_type.txt"], "rock_type.txt"),
        settings=Text(files["project_settings.txt"], "project_settings.txt"),
        **kwargs,
    )


def _block_line(text, material, key):
    """The value after ``key:`` in the block of ``material`` of materials.txt."""
    block = text.split(f": {material}\n", 1)[1].split("\n\n", 1)[0]
    for line in block.splitlines():
        if line.split(":", 1)[0].split(" (")[0] == key:
            return line.split(":", 1)[1].strip()
    raise AssertionError(f"{key} not in {material}")


def test_round_trip_table_7_1_with_velocity_scaling(table_7_1, tmp_path):
    model = _scaled(table_7_1, k_mps=7.5)
    export = export_rocfall(model)
    for name, text in export.files.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    back, notes = read_rocfall(
        tmp_path / "materials.txt",
        tmp_path / "slope.csv",
        rock_type=tmp_path / "rock_type.txt",
        settings=tmp_path / "project_settings.txt",
        radius_m=model.body.radius_m,
    )
    assert list(back.materials) == ["rock", "colluvium"]
    for name, material in model.materials.items():
        for f in fields(material):
            assert getattr(back.materials[name], f.name) == getattr(material, f.name)
    assert back.effects["velocity_scaled_restitution"] == {"k_mps": 7.5}
    assert back.effects["slope_roughness"] == {"scale": 1.0}
    assert set(back.effects) == {"velocity_scaled_restitution", "slope_roughness"}
    assert np.array_equal(back.profile.x_m, model.profile.x_m)
    assert np.array_equal(back.profile.z_m, model.profile.z_m)
    assert back.profile.material == model.profile.material
    assert back.body.mass_kg == 3750.0
    assert back.body.radius_m == 0.725
    for f in fields(model.seeder):
        assert getattr(back.seeder, f.name) == getattr(model.seeder, f.name)
    assert back.core["stop_speed_mps"] == model.core["stop_speed_mps"]
    assert any("gyration" in n for n in notes)


def test_import_defaults_are_stated(table_7_1):
    back, notes = _reimport(export_rocfall(_scaled(table_7_1)))
    # a sphere of 2650 kg/m^3 and 3750 kg: r = (3 * 3750 / (4 pi 2650))^(1/3)
    assert back.body.radius_m == pytest.approx(0.69646, abs=1e-5)
    assert any("2650 kg/m^3" in n for n in notes)
    assert any("slide_vn_mps = 0.5" in n for n in notes)
    assert back.provenance["import_notes"] == notes


def test_distribution_tuples_by_hand(table_7_1):
    scaled = export_rocfall(_scaled(table_7_1)).files["materials.txt"]
    plain = export_rocfall(model_from_dict(table_7_1)).files["materials.txt"]
    # rn 0.75 +- 0.04: 3 sd = 0.12 each side, max 0.87 <= 1
    assert _block_line(plain, "rock", "rn") == "2, 0.75, 0.04, 0.12, 0.12"
    # friction 2.86 +- 1.5: 3 sd = 4.5 above; below cut at 0 -> relative min 2.86
    assert _block_line(plain, "rock", "friction angle") == "2, 2.86, 1.5, 2.86, 4.5"
    assert _block_line(plain, "rock", "slope roughness sd") == "35"
    # colluvium rn 1.0 +- 0.04: max cut at 1 without scaling, 1.12 with it
    assert _block_line(plain, "colluvium", "rn") == "2, 1, 0.04, 0.12, 0"
    assert _block_line(scaled, "colluvium", "rn") == "2, 1, 0.04, 0.12, 0.12"
    assert _block_line(plain, "colluvium", "friction angle") == "2, 19.29, 2, 6, 6"
    # no SD -> distribution 1 (none)
    assert distribution(3.007, 0.0).text() == "1, 3.007, 0, 0, 0"
    # Rt 0.9 +- 0.05: relative max = 1 - 0.9 = 0.1 < 0.15
    d = distribution(0.9, 0.05, lower=0.0, upper=1.0)
    assert (d.rel_min, d.minimum, d.maximum) == pytest.approx((0.15, 0.75, 1.0))


def test_truncation_mismatch_by_hand(table_7_1):
    d = Distribution(2, 1.0, 0.04, 0.12, 0.0)
    # 1 - 0.04 (0.398942 - 0.004432) / (0.5 - 0.001350) = 0.968354
    assert truncated_mean(d) == pytest.approx(0.968354, abs=2e-6)
    # max(0, N(2.86, 1.5)): 2.86 Phi(1.9067) + 1.5 phi(1.9067) = 2.7791 + 0.0972
    assert clipped_mean(2.86, 1.5) == pytest.approx(2.8763, abs=2e-4)
    export = export_rocfall(model_from_dict(table_7_1))
    text = " ".join(export.mismatches)
    assert "colluvium rn" in text and "mean 0.9684" in text


def test_rn_above_one_refused_without_velocity_scaling(table_7_1):
    table_7_1["materials"]["colluvium"]["e_n"] = 1.2
    with pytest.raises(ArgumentError) as exc:
        export_rocfall(model_from_dict(table_7_1))
    message = str(exc.value)
    assert "\n" not in message
    for part in ("colluvium", "e_n = 1.2", "[0, 1]", "velocity_scaled_restitution"):
        assert part in message


def test_rt_above_one_refused(table_7_1):
    table_7_1["materials"]["rock"]["e_t"] = 1.05
    with pytest.raises(ArgumentError, match=r"material rock: e_t = 1.05 .*\[0, 1\]"):
        export_rocfall(_scaled(table_7_1))


def test_rn_above_one_with_velocity_scaling_is_written_and_flagged(table_7_1):
    table_7_1["materials"]["colluvium"]["e_n"] = 1.2
    export = export_rocfall(_scaled(table_7_1))
    assert _block_line(export.files["materials.txt"], "colluvium", "rn") == (
        "2, 1.2, 0.04, 0.12, 0.12"
    )
    # scaled Rn < 1 above K sqrt(Rn - 1) = 9.144 * 0.447214 = 4.089 m/s
    flagged = [m for m in export.mismatches if "colluvium rn = 1.2" in m]
    assert len(flagged) == 1 and "4.09 m/s" in flagged[0]


def test_unmapped_effects_listed(table_7_1):
    table_7_1["effects"].update(
        {
            "angle_dependent_restitution": {},
            "air_drag": {},
            "mass_loss": {},
            "tree_impacts": {},
            "rotation_friction": {},
        }
    )
    table_7_1["trees"] = {"x_m": [300.0], "diameter_m": [0.3], "height_m": [20.0]}
    export = export_rocfall(model_from_dict(table_7_1))
    unmapped = " ".join(what for what, _ in export.unmapped)
    for name in ("angle_dependent_restitution", "air_drag", "mass_loss"):
        assert name in unmapped
    assert "tree_impacts" in unmapped
    assert "rotation_friction.friction = 0.5" in unmapped
    assert "consider rotational velocity: on" in export.files["project_settings.txt"]
    assert "scale rn by velocity: off" in export.files["project_settings.txt"]
    readme = export.readme("calibrated.json")
    assert "**air_drag (" in readme


def _texts(materials, slope="x_m,y_m,material_id\n0,10,1\n10,0,\n"):
    return (
        Text(materials, "materials.txt"),
        Text(slope, "slope.csv"),
        Text("rock type 1: b\nmass (kg): 100\n", "rock_type.txt"),
    )


GOOD = "material 1: rock\nrn: 0.5\nrt: 0.8\nfriction angle (deg): 30\n"


def test_bad_import_missing_field_names_file_and_line(tmp_path):
    (tmp_path / "materials.txt").write_text(
        "# my rocfall materials\n\nmaterial 1: rock\nrn: 0.5\nfriction angle: 30\n"
    )
    (tmp_path / "slope.csv").write_text("0,10,1\n10,0\n")
    (tmp_path / "rock.txt").write_text("rock type 1: b\nmass (kg): 100\n")
    with pytest.raises(InputFileError) as exc:
        read_rocfall(
            tmp_path / "materials.txt",
            tmp_path / "slope.csv",
            rock_type=tmp_path / "rock.txt",
        )
    message = str(exc.value)
    assert "\n" not in message
    assert message.startswith(str(tmp_path / "materials.txt") + ": line 3: ")
    assert message.endswith("material 1 (rock): rt missing")


@pytest.mark.parametrize(
    ("materials", "slope", "where", "says"),
    [
        (
            GOOD.replace("rn: 0.5", "rn: 2, abc, 0.04, 0.1, 0.1"),
            None,
            "materials.txt: line 2",
            "rn of material 1 (rock): not a number ('abc')",
        ),
        (
            GOOD.replace("rn: 0.5", "rn: 2, 0.5, 0.04"),
            None,
            "materials.txt: line 2",
            "(got 3 values)",
        ),
        (
            GOOD.replace("rn: 0.5", "rn: 9, 0.5, 0.04, 0.1, 0.1"),
            None,
            "materials.txt: line 2",
            "distribution id must be one of",
        ),
        (
            GOOD.replace("(deg)", "(rad)"),
            None,
            "materials.txt: line 4",
            "unit must be deg (got rad)",
        ),
        (GOOD, "x,y,id\n0,10,1\nten,0,\n", "slope.csv: line 3", "x: not a number"),
        (GOOD, "0,10,2\n10,0,\n", "slope.csv: line 1", "material id 2 is not in"),
        (GOOD, "0,10,1\n10,0,1\n5,-1\n", "slope.csv: line 3", "x must increase"),
    ],
)
def test_bad_import_lines(materials, slope, where, says):
    texts = _texts(materials) if slope is None else _texts(materials, slope)
    with pytest.raises(InputFileError) as exc:
        model_from_rocfall(*texts)
    message = str(exc.value)
    assert "\n" not in message
    assert message.startswith(where + ": ") and says in message


def test_hand_written_blocks():
    materials = (
        "MATERIAL 1: talus  # typed by hand\n"
        "  Rn: 3 0.4 0 0.1 0.1\n"
        "  Rt:   0.59\n"
        "  Friction Angle (deg): 2 25 2 6 6\n"
    )
    settings = Text(
        "Analysis method: Lumped Mass\nfriction angle: calculate from Rt\n"
        "scale Rn velocity k (m/s): 12\n",
        "settings.txt",
    )
    rock = Text(
        "rock type 1: block\nmass (kg): 500\nseeder x (m): 2\nseeder y (m): 12\n"
        "initial horizontal velocity (m/s): 1.5\n",
        "rock.txt",
    )
    model, notes = model_from_rocfall(
        Text(materials, "m.txt"),
        Text("0 10 1\n20 0 1\n30 -1\n", "s.csv"),
        rock,
        settings=settings,
        radius_m=0.3,
    )
    talus = model.materials["talus"]
    # uniform on [0.3, 0.5]: sd = 0.2 / sqrt(12) = 0.057735
    assert talus.e_n == 0.4 and talus.e_n_sd == pytest.approx(0.057735, abs=1e-6)
    # friction from Rt: arctan(0.41 / 0.59) = 34.797 deg
    assert talus.friction_deg == pytest.approx(34.797, abs=1e-3)
    assert model.effects == {"velocity_scaled_restitution": {"k_mps": 12.0}}
    assert model.seeder.x_m == 2.0 and model.seeder.vx_mps == 1.5
    assert model.profile.material == ("talus", "talus")
    assert any("uniform" in n for n in notes)
    assert any("initial vertical velocity not given" in n for n in notes)
    assert math.isclose(model.body.radius_m, 0.3)
