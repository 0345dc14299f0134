"""Hostile inputs of an independent audit (third set): model files, profiles given as
vertex lists, exports on an extruded grid, RocFall folders read by import-model.

Each bad input is one line naming the file (or flag) and the field or line, exit 1,
nothing written, inputs left as they were.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
ASPHALT = REPO / "surveys" / "asphalt" / "model_rocfall_table_7_1.json"


def _model() -> dict:
    """The asphalt Table 7-1 model without its provenance (the audit's model.json)."""
    data = json.loads(ASPHALT.read_text(encoding="utf-8"))
    data.pop("provenance", None)
    return data


@pytest.fixture()
def model_json(tmp_path) -> Path:
    path = tmp_path / "model.json"
    path.write_text(json.dumps(_model(), indent=1), encoding="utf-8")
    return path


def _nothing_new(folder: Path, before: set[str]) -> None:
    assert {p.name for p in folder.iterdir()} == before


# ------------------------------------------------------- export: grid size --


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--cellsize", "5", "--rows", "1000000000"],
         ["--rows", "25,000,000", "50,000,000"]),
        (["--cellsize", "1e-6"],
         ["--cellsize", "170,000,000 columns", "50,000,000", "1.7e-05 m"]),
        (["--cellsize", "5e-324"], ["--cellsize", "inf columns", "50,000,000"]),
        (["--cellsize", "5", "--rows", "10000000"],
         ["--cellsize", "340,000,000 cells", "at least 34 m"]),
    ],
)  # fmt: skip
def test_extruded_grid_is_bounded_before_it_is_allocated(
    cli, fails, tmp_path, model_json, extra, words
):
    before = {p.name for p in tmp_path.iterdir()}
    r = cli("export", model_json, "--to", "rockyfor3d", "--extrude", *extra,
            "-o", tmp_path / "o")  # fmt: skip
    fails(r, *words)
    _nothing_new(tmp_path, before)


def test_extruded_grid_at_the_limit_of_rows_is_written(cli, tmp_path, model_json):
    # 170 m of profile at 85 m: two columns; 2 x 1000 cells is far inside the limit
    r = cli("export", model_json, "--to", "ramms", "--extrude", "--cellsize", "85",
            "--rows", "1000", "-o", tmp_path / "o")  # fmt: skip
    assert r.exit_code == 0, r.output
    assert "wrote" in r.output


def test_export_help_states_the_grid_bounds(cli):
    r = cli("export", "--help")
    text = " ".join(r.output.replace("│", " ").split())
    assert "2 or more" in text and "50,000,000 cells" in text


# ------------------------------------------------------ model file: counts --


@pytest.mark.parametrize("value", [500.5, 1.5])
def test_max_impacts_must_be_a_whole_number(cli, fails, tmp_path, value):
    data = _model()
    data["core"] = {"max_impacts": value}
    path = tmp_path / "model.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    r = cli("simulate", path, "--rocks", "5", "--seed", "1")
    fails(r, "model.json", "core.max_impacts", f"must be a whole number (got {value})")


def test_max_impacts_written_as_a_float_is_still_a_whole_number(cli, tmp_path):
    data = _model()
    data["core"] = {"max_impacts": 500.0}
    path = tmp_path / "model.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    r = cli("simulate", path, "--rocks", "5", "--seed", "1")
    assert r.exit_code == 0, r.output


# ------------------------------------------- model file: a key given twice --


@pytest.mark.parametrize(
    ("old", "new", "path"),
    [
        ('"e_n": 0.75', '"e_n": 0.75, "e_n": 4.5', "materials.rock.e_n"),
        ('"mass_kg"', '"mass_kg": 1, "mass_kg"', "body.mass_kg"),
        ('"seeder"', '"seeder": {}, "seeder"', "seeder"),
    ],
)
def test_a_key_given_twice_is_refused_naming_its_path(
    cli, fails, digest, tmp_path, old, new, path
):
    text = json.dumps(_model())
    assert old in text
    model = tmp_path / "model.json"
    model.write_text(text.replace(old, new, 1), encoding="utf-8")
    before = digest(model)
    simulate = ["simulate", model, "--rocks", "5", "--seed", "1"]
    export = ["export", model, "--to", "rocfall", "-o", tmp_path / "o"]
    for args in (simulate, export):
        fails(cli(*args), "model.json", f"{path} given twice")
    assert digest(model) == before
    assert not (tmp_path / "o").exists()


def test_a_model_file_with_a_bom_and_crlf_is_read(cli, tmp_path):
    model = tmp_path / "model.json"
    text = json.dumps(_model(), indent=1).replace("\n", "\r\n")
    model.write_bytes(text.encode("utf-8-sig"))
    r = cli("export", model, "--to", "rocfall", "-o", tmp_path / "o")
    assert r.exit_code == 0, r.output
    assert (tmp_path / "o" / "materials.txt").is_file()


# ------------------------------------------------ import-model: RocFall files --


@pytest.fixture()
def rf(cli, tmp_path, model_json) -> Path:
    """The audit's rf/: ``fieldkit export model.json --to rocfall -o rf``."""
    r = cli("export", model_json, "--to", "rocfall", "-o", tmp_path / "rf")
    assert r.exit_code == 0, r.output
    return tmp_path / "rf"


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text, (path.name, old)
    path.write_text(text.replace(old, new, 1), encoding="utf-8")


def test_rocfall_files_with_a_bom_and_crlf_are_read(cli, tmp_path, rf):
    plain = tmp_path / "plain.json"
    assert cli("import-model", rf, "-o", plain).exit_code == 0
    for name in ("materials.txt", "rock_type.txt", "project_settings.txt", "slope.csv"):
        path = rf / name
        text = path.read_text(encoding="utf-8").replace("\n", "\r\n")
        path.write_bytes(text.encode("utf-8-sig"))
    bom = tmp_path / "bom.json"
    r = cli("import-model", rf, "-o", bom)
    assert r.exit_code == 0, r.output
    a, b = (json.loads(p.read_text()) for p in (plain, bom))
    for key in ("profile", "materials", "body", "seeder", "effects", "core"):
        assert a[key] == b[key], key


# ------------------------------- profiles as vertex lists: a profile CSV's bounds --


@pytest.mark.parametrize(
    ("key", "values", "words"),
    [
        ("z_m", [637, 637, 581, 511, 501, 1e12],
         ["profile.z_m[5]", "1e+12 m is not an elevation", "11,000 m"]),
        ("x_m", [-1e6, 0, 32.33, 113, 115.49, 160],
         ["profile.x_m[0]", "-1e+06 m is not a chainage", "100,000 m"]),
        ("x_m", [-10, -9.9995, 32.33, 113, 115.49, 160],
         ["profile.x_m[1]", "0.0005 m apart", "at least 1 mm"]),
    ],
)  # fmt: skip
def test_model_file_vertex_lists_get_the_profile_bounds(
    cli, fails, tmp_path, key, values, words
):
    data = _model()
    data["profile"][key] = values
    model = tmp_path / "model.json"
    model.write_text(json.dumps(data), encoding="utf-8")
    fails(cli("simulate", model, "--rocks", "5", "--seed", "1"), "model.json", *words)
    fails(cli("export", model, "--to", "rocfall", "-o", tmp_path / "o"), *words)
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ("-10,637,2\n0,637,2\n", "-1000000,637,2\n0,637,2\n",
         ["line 2: x", "-1e+06 m is not a chainage"]),
        ("160,501,", "160,1e12,", ["line 7: y", "1e+12 m is not an elevation"]),
        ("\n0,637,2\n", "\n0,637,2\n0.0005,637,2\n",
         ["line 4: x", "0.0005 m apart", "at least 1 mm"]),
    ],
)  # fmt: skip
def test_rocfall_slope_gets_the_profile_bounds(
    cli, fails, digest, tmp_path, rf, old, new, words
):
    slope = rf / "slope.csv"
    _edit(slope, old, new)
    before = digest(slope)
    out = tmp_path / "m.json"
    fails(cli("import-model", rf, "-o", out), "rf/slope.csv", *words)
    assert not out.exists() and digest(slope) == before


# ---------------- import-model: a value is reported where it came from --


@pytest.mark.parametrize(
    ("name", "old", "new", "words"),
    [
        ("rock_type.txt", "initial horizontal velocity (m/s): 2, 1,",
         "initial horizontal velocity (m/s): 2, 1e5,",
         ["line 9: initial horizontal velocity (seeder.vx_mps)",
          "must be <= 100 m/s (got 100000)"]),
        ("rock_type.txt", "initial vertical velocity (m/s): 2, 0, 0.3,",
         "initial vertical velocity (m/s): 2, 0, 300,",
         ["line 10: initial vertical velocity (seeder.vz_sd_mps)",
          "must be <= 100 m/s (got 300)"]),
        ("rock_type.txt", "mass (kg): 1, 500,", "mass (kg): 1, 1e308,",
         ["line 8: mass (body.mass_kg)", "must be <= 1e+09 kg (got 1e+308)"]),
        ("rock_type.txt", "seeder y (m): 637.36", "seeder y (m): 1e6",
         ["line 14: seeder y (seeder.z_m)", "more than 1000 m above the ground"]),
    ],
)  # fmt: skip
def test_import_model_names_the_rocfall_file_and_line_of_a_value(
    cli, fails, tmp_path, rf, name, old, new, words
):
    _edit(rf / name, old, new)
    out = tmp_path / "m.json"
    r = cli("import-model", rf, "-o", out)
    fails(r, f"rf/{name}", *words)
    assert "materials.txt" not in r.stderr
    assert not out.exists()


# ------------- the other JSON input (a track's homography): one parser, same rule --


@pytest.fixture(scope="module")
def throw_clip(tmp_path_factory):
    """A ball thrown across a 320x240 scene (as in test_cli_track_messages.py)."""
    import importlib.util
    import sys

    import numpy as np

    name = "fieldkit_video_render_for_audit_models"
    spec = importlib.util.spec_from_file_location(name, REPO / "video" / "render.py")
    render = importlib.util.module_from_spec(spec)
    sys.modules[name] = render
    spec.loader.exec_module(render)
    path = tmp_path_factory.mktemp("clip") / "throw.avi"
    camera = render.Camera(width=320, height=240, origin_u_px=20.0, origin_v_px=220.0)
    rng = np.random.default_rng(4)
    scene = render.BounceScene(plate_point_m=(0.0, -1.0))
    bg = np.clip(render.background(camera, rng, scene) + 0.5, 0, 255).astype(np.uint8)
    t = np.arange(80) / 1205.0
    poses = np.column_stack(
        [0.05 + 2.5 * t, 0.25 + 1.0 * t - 0.5 * 9.81 * t**2, 0.2 - 40.0 * t]
    )
    render.write_clip(path, camera, render.Ball(), bg, poses, rng)
    return path


def test_homography_json_with_a_key_given_twice_is_refused(
    cli, fails, tmp_path, throw_clip
):
    corners = [(20, 220, 0.0, 0.0), (300, 220, 0.56, 0.0), (300, 20, 0.56, 0.4),
               (20, 20, 0.0, 0.4)]  # fmt: skip
    points = [{"u_px": u, "v_px": v, "x_m": x, "z_m": z} for u, v, x, z in corners]
    text = json.dumps({"points": points}).replace(
        '"x_m": 0.56', '"x_m": 0.5, "x_m": 0.56', 1
    )
    h = tmp_path / "h.json"
    h.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    r = cli(
        "track", throw_clip, "--fps", "1205", "--homography", h, "-o", out / "t.csv"
    )
    fails(r, f"{h}: points[1].x_m given twice")
    assert not out.exists()
