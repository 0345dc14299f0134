"""RocFall export and import: round trip, distribution convention, refusals.

Reference numbers are hand computations: 3 SD bounds (3 x 0.04 = 0.12, 3 x 1.5 =
4.5), the truncated-normal mean of N(1, 0.04) on [0.88, 1] from tabulated phi(0) =
0.398942, phi(3) = 0.004432, Phi(-3) = 0.001350, the velocity above which a scaled
Rn of 1.2 falls below 1 (9.144 sqrt(0.2)), arctan((1 - Rt)/Rt) for Rt = 0.59.
"""

from __future__ import annotations

import json
import math
from dataclasses import fields

import numpy as np
import pytest

from fieldkit.errors import InputFileError
from fieldkit.export.lumped import WrittenOutOfRange
from fieldkit.export.rocfall import (
    Distribution,
    check_written,
    clipped_mean,
    distribution,
    export_rocfall,
    rocfall_model,
    truncated_mean,
)
from fieldkit.export.rocfall_import import Text, model_from_rocfall, read_rocfall
from fieldkit.export.translation import realised_impacts
from fieldkit.model.model_file import model_from_dict, model_to_dict, read_model

TABLE_7_1 = "surveys/tornado_mountain/model_rocfall_table_7_1.json"
PATH_START = "surveys/tornado_mountain/model_path_start.json"


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
    # RocFall's own K: the law is RocFall's and every value is written as calibrated
    # (another K is fitted in range: test_a_law_rocfall_cannot_take_round_trips_...)
    model = _scaled(table_7_1, k_mps=9.144)
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
    assert back.effects["velocity_scaled_restitution"] == {"k_mps": 9.144}
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
    # colluvium rn 1.0 +- 0.04: max cut at 1, with velocity scaling too (RocFall
    # documents Rn in [0, 1]; before issue 19 the scaled max was 1.12)
    assert _block_line(plain, "colluvium", "rn") == "2, 1, 0.04, 0.12, 0"
    assert _block_line(scaled, "colluvium", "rn") == "2, 1, 0.04, 0.12, 0"
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


def _tuples(text, key):
    """Every ``key`` tuple of materials.txt as (mean, min, max)."""
    out = []
    for line in text.splitlines():
        if line.startswith(f"{key}:"):
            kind, mean, sd, rel_min, rel_max = map(float, line[3:].split(","))
            out.append((mean, mean - rel_min, mean + rel_max))
    return out


def test_rt_above_one_is_fitted_in_range(table_7_1):
    # before issue 19: refused; now the in-range value under RocFall's law
    table_7_1["materials"]["rock"]["e_t"] = 1.05
    export = export_rocfall(model_from_dict(table_7_1))
    rt = [t for t in _tuples(export.files["materials.txt"], "rt")]
    assert all(0.0 <= v <= 1.0 for t in rt for v in t), rt
    assert any(
        "materials.rock.e_t = 1.05 is outside RocFall's Rt" in m
        for m in export.mismatches
    )


def test_check_written_refuses_a_value_out_of_range(table_7_1):
    table_7_1["materials"]["colluvium"]["e_n"] = 1.2
    with pytest.raises(WrittenOutOfRange, match=r"material colluvium: Rn .* = 1.2"):
        check_written(model_from_dict(table_7_1))


def _calibrated(repo, tmp_path, **changes):
    """Tornado's path-calibrated model as the README reports it (colluvium e_n
    1.186 with eq. 7.1 at K = 13.24 m/s, bench e_n 0.83), written to a file."""
    data = json.loads((repo / PATH_START).read_text())
    data["materials"]["colluvium"]["e_n"] = 1.18581256337219
    data["materials"]["bench"]["e_n"] = 0.83
    data["effects"]["velocity_scaled_restitution"] = {"k_mps": 13.2440621510482}
    for key, value in changes.items():
        data[key] = value
    path = tmp_path / "calibrated.json"
    path.write_text(json.dumps(data))
    return path


def test_calibrated_tornado_written_in_range_with_translation_error(
    cli, repo, tmp_path
):
    out = tmp_path / "rocfall"
    r = cli("export", _calibrated(repo, tmp_path), "--to", "rocfall", "-o", out)
    assert r.exit_code == 0, r.output
    for name in ("materials.txt", "README.md"):
        assert f"wrote {out / name}" in r.output
    text = (out / "materials.txt").read_text()
    # before issue 19: "rn: 2, 1.18581256337219, 0.04, 0.12, 0.12", K 13.24
    for key in ("rn", "rt"):
        for mean, low, high in _tuples(text, key):
            assert 0.0 <= low <= mean <= high <= 1.0
    assert (
        "scale rn velocity k (m/s): 9.144" in (out / "project_settings.txt").read_text()
    )
    readme = (out / "README.md").read_text()
    # colluvium: under RocFall's K the least-squares Rn is above 1: clipped, said
    assert (
        "materials.colluvium.e_n: the least-squares value under RocFall's law is 1.4"
        in readme
    )
    assert "## Translation error: calibrated model vs the target's law" in readme
    assert "| runout p50 |" in readme and "| runout p95 |" in readme
    assert "p95 total energy at" in readme and "p95 bounce height at" in readme
    # the written value carries its own spread; the calibrated one is beside it
    row = next(x for x in readme.splitlines() if "material 2 (colluvium): rn" in x)
    calibrated, target, how = row.strip("| ").split(" | ")
    assert calibrated == "materials.colluvium.e_n = 1.186; e_n_sd = 0.04"
    assert target.startswith("material 2 (colluvium): rn = (2, ")
    assert how.startswith("written ") and "spread 0." in how
    # the search always runs from the clipped least squares (Rn 1); its values
    # are written only if they also behave closer on the translation error's own
    # stream, and the README says which happened
    assert "Behaviour search over materials.rock.e_n, materials.rock.e_t" in readme
    if "The values found are written" in readme:
        assert "behaviour search from the impact-level 1)" in how
    else:
        assert "The impact-level values are written" in readme
        assert how.startswith("written 1 (")
    for section in ("## Sources of the target's rules", "## Unconfirmed"):
        assert section in readme


def test_a_law_rocfall_cannot_take_round_trips_to_the_values_written(repo, tmp_path):
    model = read_model(_calibrated(repo, tmp_path))
    export = export_rocfall(model)
    back, _ = _reimport(export, radius_m=model.body.radius_m)
    written, coefficients, reasons, _, search = rocfall_model(model)
    assert reasons and back.effects["velocity_scaled_restitution"] == {"k_mps": 9.144}
    for name, (rn, rt) in coefficients.items():
        assert back.materials[name].e_n == rn.written == written.materials[name].e_n
        assert back.materials[name].e_t == rt.written
        assert back.materials[name].e_n_sd == model.materials[name].e_n_sd


def test_fitted_rn_is_the_least_squares_value_under_rocfalls_law(repo, tmp_path):
    # the bench's Rn by hand from the calibrated model's own impacts:
    # p = sum(vfN f v) / sum((f v)^2), f = 1 / (1 + (v / 9.144)^2), v = |viN|
    model = read_model(_calibrated(repo, tmp_path))
    impacts = realised_impacts(model)
    bench = impacts[impacts["material"] == "bench"]
    v = -bench["vin_mps"].to_numpy()
    f = 1.0 / (1.0 + (v / 9.144) ** 2)
    p = float(np.sum(bench["vfn_mps"].to_numpy() * f * v) / np.sum((f * v) ** 2))
    written = rocfall_model(model)
    assert 0.0 < p < 1.0
    # the start of the behaviour search; written when the search's values are not
    bench_rn = written.coefficients["bench"][0]
    if written.search.accepted:
        assert bench_rn.impact_level == pytest.approx(p, rel=1e-12)
    else:
        assert bench_rn.written == pytest.approx(p, rel=1e-12)
    # (rock Rn, Rt, colluvium Rn, Rt, bench Rn, Rt)
    assert written.search.search.start[4] == pytest.approx(p, rel=1e-12)


def test_a_material_no_rock_touches_is_not_written_raw(cli, repo, tmp_path):
    # a segment above the seeder: no rock ever strikes "crest"
    data = {
        "profile": {
            "x_m": [0, 10, 70, 140],
            "z_m": [80, 70, 30, 10],
            "material": ["crest", "talus", "talus"],
        },
        "materials": {
            "crest": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30},
            "talus": {"e_n": 1.1, "e_t": 0.8, "friction_deg": 30},
        },
        "effects": {"velocity_scaled_restitution": {"k_mps": 13.0}},
        "body": {"mass_kg": 100, "radius_m": 0.2},
        "seeder": {"x_m": 12, "z_m": 72},
    }
    path = tmp_path / "m.json"
    path.write_text(json.dumps(data))
    out = tmp_path / "out"
    r = cli("export", path, "--to", "rocfall", "-o", out)
    assert r.exit_code == 0, r.output
    readme = " ".join((out / "README.md").read_text().split())
    assert "crest: NO SIMULATED IMPACT on it" in readme
    # crest's own law, 0.5 / (1 + (v/13)^2), at every simulated impact's normal
    # speed, fitted under RocFall's 1 / (1 + (v/9.144)^2): above 0.5, not raw 0.5
    impacts = realised_impacts(model_from_dict(data))
    assert (impacts["material"] == "talus").all()
    v = -impacts["vin_mps"].to_numpy()
    g, f = 1 / (1 + (v / 13.0) ** 2), 1 / (1 + (v / 9.144) ** 2)
    p = float(np.sum(0.5 * g * f * v * v) / np.sum((f * v) ** 2))
    rn = _block_line((out / "materials.txt").read_text(), "crest", "rn")
    assert p > 0.5 and float(rn.split(",")[1]) == pytest.approx(p, rel=1e-12)


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
