"""Model files through the command line: the files a model reads are inputs of every
command that reads it, and a bad model file is one line naming the file and field."""

from __future__ import annotations

import json

import pytest

PROFILE_CSV = "x_m,z_m,material\n0,100,rock\n12,80,talus\n40,62,talus\n90,54,\n"
MODEL = {
    "profile": {"csv": "profile.csv"},
    "materials": {
        "rock": {"e_n": 0.6, "e_t": 0.9, "friction_deg": 30},
        "talus": {"e_n": 0.5, "e_t": 0.85, "friction_deg": 35},
    },
    "body": {"mass_kg": 500, "radius_m": 0.36, "gyration_m": 0.295},
    "seeder": {"x_m": 0.5, "z_m": 101.0, "vx_mps": 4.0, "vz_mps": 1.0},
}


@pytest.fixture()
def csv_model(tmp_path):
    """A model whose profile is ``profile.csv`` beside it."""
    (tmp_path / "profile.csv").write_text(PROFILE_CSV)
    path = tmp_path / "model.json"
    path.write_text(json.dumps(MODEL))
    return path


def _commands(tmp_path, model, target):
    table = tmp_path / "table.csv"
    table.write_text("not read: the model's files are checked first\n")
    return {
        "simulate --summary": ["simulate", model, "--rocks", "3", "--seed", "1",
                               "--summary", target],
        "synth -o": ["synth", model, "--seed", "1", "-o", target],
        "fit -o": ["fit", table, "--model", model, "-o", target],
        "diagnose -o": ["diagnose", table, "--model", model, "--seed", "1",
                        "-o", target],
    }  # fmt: skip


@pytest.mark.parametrize(
    "command", ["simulate --summary", "synth -o", "fit -o", "diagnose -o"]
)
def test_no_command_replaces_the_profile_csv_its_model_reads(
    cli, fails, digest, tmp_path, csv_model, command
):
    profile = tmp_path / "profile.csv"
    before = digest(profile)
    args = _commands(tmp_path, csv_model, profile)[command]
    fails(cli(*args), "profile.csv", "input")
    assert digest(profile) == before


def test_no_command_replaces_the_dem_its_model_reads(cli, fails, digest, tmp_path):
    dem = tmp_path / "terrain.asc"
    rows = "\n".join(
        " ".join(str(100 - 2 * c - r) for c in range(20)) for r in range(5)
    )
    dem.write_text(f"ncols 20\nnrows 5\nxllcorner 0\nyllcorner 0\ncellsize 5\n"
                   f"NODATA_value -9999\n{rows}\n")  # fmt: skip
    data = dict(MODEL, profile={"dem": "terrain.asc", "line": [[5, 12], [95, 12]],
                                "materials": "0-:rock"})  # fmt: skip
    model = tmp_path / "model.json"
    model.write_text(json.dumps(data))
    before = digest(dem)
    for args in _commands(tmp_path, model, dem).values():
        fails(cli(*args), "terrain.asc", "input")
    assert digest(dem) == before


def test_export_force_does_not_replace_the_profile_it_exports(
    cli, fails, digest, tmp_path
):
    # the model's profile CSV sits in the export folder under a name RocFall uses
    out = tmp_path / "out"
    out.mkdir()
    (out / "slope.csv").write_text(PROFILE_CSV)
    model = tmp_path / "model.json"
    model.write_text(json.dumps(dict(MODEL, profile={"csv": "out/slope.csv"})))
    before = digest(out / "slope.csv")
    fails(cli("export", model, "--to", "rocfall", "-o", out, "--force"),
          "slope.csv", "input")  # fmt: skip
    assert digest(out / "slope.csv") == before
    assert sorted(p.name for p in out.iterdir()) == ["slope.csv"]


def _bad(tmp_path, change=None, text=None, name="bad.json"):
    path = tmp_path / name
    if text is not None:
        path.write_bytes(text)
    else:
        data = json.loads(json.dumps(MODEL))
        data["profile"] = {"x_m": [0, 12, 40, 90], "z_m": [100, 80, 62, 54],
                           "material": ["rock", "talus", "talus"]}  # fmt: skip
        change(data)
        path.write_text(json.dumps(data))
    return path


def _set(where, value):
    def change(data):
        *parents, last = where.split(".")
        node = data
        for key in parents:
            node = node.setdefault(key, {})
        node[last] = value

    return change


TRACEBACK_CASES = [
    ("not UTF-8", b'{"profile": "\xff\xfe"}', "not a UTF-8 text file"),
    ("deeply nested", b"[" * 100_000 + b"]" * 100_000, "nested 100000 levels"),
    ("a folder", None, "cannot read"),
]


@pytest.mark.parametrize("text, words", [c[1:] for c in TRACEBACK_CASES],
                         ids=[c[0] for c in TRACEBACK_CASES])  # fmt: skip
def test_unreadable_model_files_are_one_line(cli, fails, tmp_path, text, words):
    if text is None:
        bad = tmp_path / "bad.json"
        bad.mkdir()
    else:
        bad = _bad(tmp_path, text=text)
    fails(cli("export", bad, "--to", "json", "-o", tmp_path / "x"), "bad.json", words)
    assert not (tmp_path / "x").exists()


TYPE_CASES = [
    ("profile", {"csv": 5}, "profile.csv: must be text"),
    ("profile", {"csv": "p.csv", "units": ["ft"]}, "profile.units: must be text"),
    ("profile", [1, 2], "profile: must be an object"),
    ("materials", None, "materials: must be an object"),
    ("body.mass_kg", "heavy", "body.mass_kg: must be a number"),
    ("body.mass_kg", [500], "body.mass_kg: must be a number"),
    ("seeder.vx_mps", {"a": 1}, "seeder.vx_mps: must be a number"),
    ("materials.rock.e_n", None, "materials.rock.e_n: must be a number"),
    ("materials.rock", [0.5], "materials.rock: must be an object"),
    ("effects.air_drag", 3, "effects.air_drag: must be an object"),
    ("effects.air_drag.cd", "x", "effects.air_drag.cd: must be a number"),
    ("core.max_impacts", True, "core.max_impacts: must be a number"),
    ("trees", {"x_m": "abc", "diameter_m": [1], "height_m": [1]},
     "trees.x_m: must be a list of numbers"),
    ("profile.z_m", [100, "a", 62, 54], "profile.z_m: must be a list of numbers"),
    ("profile.x_m", [0, 12, 40, 10**400], "profile.x_m: must be a list of numbers"),
    ("body.mass_kg", None, "body.mass_kg: must be a number (got None)"),
    ("body.radius_m", 10**400, "body.radius_m: must be a finite number"),
]  # fmt: skip


@pytest.mark.parametrize("where, value, words", TYPE_CASES,
                         ids=[f"{c[0]}={c[1]!r}" for c in TYPE_CASES])  # fmt: skip
def test_wrong_json_types_are_one_line_naming_the_field(
    cli, fails, tmp_path, where, value, words
):
    bad = _bad(tmp_path, _set(where, value))
    fails(cli("export", bad, "--to", "json", "-o", tmp_path / "x"), "bad.json", words)
    assert not (tmp_path / "x").exists()


DEM_TYPE_CASES = [
    ({"step_m": "abc"}, "profile.step_m: must be a number"),
    ({"line": 5}, "profile.line: must be [[x, y], ...]"),
    ({"line": [[1, "a"], [2, 3]]}, "profile.line[0]: must be a number"),
    ({"from": "here", "line": None}, "profile.from: must be [x, y]"),
    ({"max_length_m": [1]}, "profile.max_length_m: must be a number"),
    ({"dem": 7}, "profile.dem: must be text"),
    ({"materials": 3}, "profile.materials: must be text"),
    ({"materials": "0-:=cmd"}, "profile.materials: material name '=cmd'"),
]


@pytest.mark.parametrize("entry, words", DEM_TYPE_CASES,
                         ids=[str(c[0]) for c in DEM_TYPE_CASES])  # fmt: skip
def test_wrongly_typed_dem_profile_fields_are_one_line(
    cli, fails, tmp_path, entry, words
):
    profile = {
        "dem": "terrain.asc",
        "line": [[5, 12], [95, 12]],
        "materials": "0-:rock",
    }
    profile.update(entry)
    profile = {k: v for k, v in profile.items() if v is not None}
    bad = _bad(tmp_path, lambda d: d.update(profile=profile))
    rows = "\n".join(" ".join(str(100 - 2 * c) for c in range(20)) for _ in range(5))
    (tmp_path / "terrain.asc").write_text(
        f"ncols 20\nnrows 5\nxllcorner 0\nyllcorner 0\ncellsize 5\n"
        f"NODATA_value -9999\n{rows}\n"
    )
    fails(cli("export", bad, "--to", "json", "-o", tmp_path / "x"), "bad.json", words)


BOUND_CASES = [
    ("body.mass_kg", "Infinity", "body.mass_kg: must be a finite number (got inf)"),
    ("body.mass_kg", 1e12, "body.mass_kg: must be <= 1e+09 kg"),
    ("body.radius_m", 0, "body.radius_m: must be > 0"),
    ("body.gyration_m", 3.0, "body.gyration_m: gyration_m must be <= radius_m"),
    ("materials.talus.e_n", 1e308, "materials.talus.e_n: must be <= 5"),
    ("materials.talus.e_t", 50, "materials.talus.e_t: must be <= 2"),
    ("materials.talus.e_n_sd", 9, "materials.talus.e_n_sd: must be <= 2.5"),
    ("materials.talus.roughness_m", 1e9, "roughness_m: must be <= 10 m"),
    ("seeder.vx_mps", -1e6, "seeder.vx_mps: must be >= -100 m/s"),
    ("seeder.omega_radps", 1e5, "seeder.omega_radps: must be <= 500 rad/s"),
    ("seeder.z_m", 1e6, "seeder.z_m: start is more than 1000 m above the ground"),
    ("seeder.z_m", "-Infinity", "seeder.z_m: must be a finite number (got -inf)"),
    ("seeder.vz_mps", "NaN", "seeder.vz_mps: must be a finite number (got nan)"),
    ("profile.z_m", "[100, 80, NaN, 54]", "profile.z_m: not a finite number at"),
    ("materials.rock.e_t", "NaN", "materials.rock.e_t: must be a finite number"),
    ("effects.velocity_scaled_restitution.k_mps", "Infinity",
     "effects.velocity_scaled_restitution.k_mps: must be a finite number (got inf)"),
    ("effects.velocity_scaled_restitution.k_mps", 10**400,
     "effects.velocity_scaled_restitution.k_mps: must be a finite number"),
    ("trees", {"x_m": [5], "diameter_m": [0.3], "height_m": [1e4]},
     "trees.height_m: must be <= 150 m"),
]  # fmt: skip


@pytest.mark.parametrize(
    "where, value, words",
    BOUND_CASES,
    ids=[f"{c[0]}={c[1]!r}"[:50] for c in BOUND_CASES],
)
def test_infinite_and_absurd_values_are_refused(
    cli, fails, tmp_path, where, value, words
):
    bad = _bad(tmp_path, _set(where, "@@"))
    # JSON's non-standard literals are written by hand, as a user's file would have them
    literal = value if isinstance(value, str) else json.dumps(value)
    bad.write_text(bad.read_text().replace('"@@"', literal))
    fails(cli("export", bad, "--to", "json", "-o", tmp_path / "x"), "bad.json", words)
    assert not (tmp_path / "x").exists()


def test_a_body_within_bounds_is_exported_unchanged(cli, tmp_path):
    good = _bad(tmp_path, _set("body.gyration_m", 0.36))  # k = r: a thin hoop
    r = cli("export", good, "--to", "json", "-o", tmp_path / "x")
    assert r.exit_code == 0, r.output
    written = json.loads((tmp_path / "x" / "model.json").read_text())
    assert written["body"] == {"mass_kg": 500, "radius_m": 0.36, "gyration_m": 0.36}


NAME_CASES = [
    ("=cmd|' /C calc'!A0", "formula"),
    ("talus,rock", "comma"),
    ("talus\nrn: 0.99", "line break"),
    ("talus#2", "hash"),
    ("", "empty"),
    ("x" * 65, "too long"),
]


@pytest.mark.parametrize("name, why", NAME_CASES, ids=[c[1] for c in NAME_CASES])
def test_material_names_that_would_inject_are_refused(cli, fails, tmp_path, name, why):
    def rename(data):
        data["materials"][name] = data["materials"].pop("talus")
        data["profile"]["material"] = ["rock", name, name]

    bad = _bad(tmp_path, rename)
    out = tmp_path / "x"
    r = cli("export", bad, "--to", "rocfall", "-o", out)
    fails(r, "bad.json", "materials", repr(name)[:20], "not allowed")
    assert not out.exists()


def test_a_material_name_in_a_profile_csv_is_checked_too(cli, fails, tmp_path):
    (tmp_path / "profile.csv").write_text(PROFILE_CSV.replace("talus", "=1+1"))
    data = json.loads(json.dumps(MODEL))
    data["materials"]["=1+1"] = data["materials"].pop("talus")
    model = tmp_path / "model.json"
    model.write_text(json.dumps(data))
    fails(cli("export", model, "--to", "json", "-o", tmp_path / "x"),
          "profile.csv", "material", "'=1+1'", "not allowed")  # fmt: skip


def _rocfall_folder(cli, tmp_path, repo):
    folder = tmp_path / "rocfall"
    model = repo / "surveys" / "tornado_mountain" / "model_rocfall_table_7_1.json"
    r = cli("export", model, "--to", "rocfall", "-o", folder)
    assert r.exit_code == 0, r.output
    return folder


def test_import_model_refuses_a_setting_given_twice(cli, fails, tmp_path, repo):
    folder = _rocfall_folder(cli, tmp_path, repo)
    settings = folder / "project_settings.txt"
    lines = settings.read_text().splitlines()
    first = next(
        i for i, t in enumerate(lines) if t.startswith("scale rn by velocity:")
    )
    lines.append("scale rn by velocity: off")
    settings.write_text("\n".join(lines) + "\n")
    out = tmp_path / "back.json"
    fails(cli("import-model", folder, "-o", out), "project_settings.txt",
          f"line {len(lines)}", "'scale rn by velocity' given twice",
          f"first on line {first + 1}")  # fmt: skip
    assert not out.exists()


def test_import_model_refuses_an_injected_material_name(cli, fails, tmp_path, repo):
    folder = _rocfall_folder(cli, tmp_path, repo)
    materials = folder / "materials.txt"
    text = materials.read_text()
    materials.write_text(text.replace("material 1: rock", "material 1: =HYPERLINK(1)"))
    out = tmp_path / "back.json"
    fails(cli("import-model", folder, "-o", out), "materials.txt", "line",
          "'=HYPERLINK(1)'", "not allowed")  # fmt: skip
    assert not out.exists()


def test_export_then_import_keeps_every_material_value(cli, tmp_path, repo):
    folder = _rocfall_folder(cli, tmp_path, repo)
    out = tmp_path / "back.json"
    r = cli("import-model", folder, "-o", out)
    assert r.exit_code == 0, r.output
    back = json.loads(out.read_text())["materials"]
    model = repo / "surveys" / "tornado_mountain" / "model_rocfall_table_7_1.json"
    original = json.loads(model.read_text())["materials"]
    assert set(back) == set(original)
    for name, values in original.items():
        for key in ("e_n", "e_t"):
            assert back[name][key] == pytest.approx(values[key], abs=1e-12), name


def test_profile_refuses_an_injected_material_name_in_its_csv(cli, fails, tmp_path):
    vertices = tmp_path / "vertices.csv"
    vertices.write_text(PROFILE_CSV.replace("talus", "=HYPERLINK(1)", 1))
    out = tmp_path / "profile.csv"
    fails(cli("profile", vertices, "-o", out), "vertices.csv", "'=HYPERLINK(1)'",
          "not allowed")  # fmt: skip
    assert not out.exists()
