"""CRSP export: feet, cells = segments, the rock's density, refusals (hand numbers)."""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import replace

import pytest

from fieldkit.errors import ArgumentError
from fieldkit.export.crsp import check_written, export_crsp
from fieldkit.export.lumped import WrittenOutOfRange
from fieldkit.export.site import site_from_section
from fieldkit.model.model_file import model_from_dict

PATH_START = "surveys/tornado_mountain/model_path_start.json"


def rows(text: str) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(text)))


def small(**material) -> dict:
    """A one-segment model: 30.48 m = 100 ft across, 100 ft down."""
    return {
        "profile": {"x_m": [0, 30.48], "z_m": [30.48, 0], "material": "talus"},
        "materials": {
            "talus": {"e_n": 0.35, "e_t": 0.85, "friction_deg": 30, **material}
        },
        "body": {"mass_kg": 100, "radius_m": 0.2},
        "seeder": {"x_m": 1, "z_m": 31},
    }


def test_tornado_vertices_in_feet_by_hand(tornado):
    cells = rows(export_crsp(tornado).files["cells.csv"])
    # Table 2-4 point A (0, 350 m), B (8, 316 m); run-on end (700, -4 m).
    # 350 / 0.3048 = 1148.294, 8 / 0.3048 = 26.247, 316 / 0.3048 = 1036.745,
    # 700 / 0.3048 = 2296.588, -4 / 0.3048 = -13.123.
    first, last = cells[0], cells[-1]
    assert (first["begin_x_ft"], first["begin_y_ft"]) == ("0.00", "1148.29")
    assert (first["end_x_ft"], first["end_y_ft"]) == ("26.25", "1036.75")
    assert (last["end_x_ft"], last["end_y_ft"]) == ("2296.59", "-13.12")


def test_cells_are_the_profile_segments(tornado):
    cells = rows(export_crsp(tornado).files["cells.csv"])
    x, z = tornado.profile.x_m, tornado.profile.z_m
    assert len(cells) == len(x) - 1 == 50
    for j, cell in enumerate(cells):
        assert int(cell["cell"]) == j + 1
        assert float(cell["begin_x_ft"]) == pytest.approx(x[j] / 0.3048, abs=0.005)
        assert float(cell["begin_y_ft"]) == pytest.approx(z[j] / 0.3048, abs=0.005)
        assert float(cell["end_x_ft"]) == pytest.approx(x[j + 1] / 0.3048, abs=0.005)
        assert float(cell["end_y_ft"]) == pytest.approx(z[j + 1] / 0.3048, abs=0.005)
        assert cell["material"] == tornado.profile.material[j]
    # Thesis Table 7-1, site 4: rock e_N 0.75, e_T 0.59, dip SD 35 deg; colluvium
    # 1.00, 0.62, no roughness. Table 7-1 has no velocity scaling, CRSP always
    # scales Rn: the in-range Rn under CRSP's law is clipped at 1 for both (least
    # squares far above 1). Before issue 19 the cells held the constant-law Rn
    # (0.750, 1.000) and S = 0 although rock's dip SD is 35 deg; now
    # S = 0.725 tan(35 deg) = 0.50765 m = 1.6655 ft.
    surface = {c["material"]: (c["Rn"], c["S_ft"]) for c in cells}
    assert surface == {"rock": ("1.000", "1.67"), "colluvium": ("1.000", "0.00")}
    rt = {c["material"]: float(c["Rt"]) for c in cells}
    assert rt["rock"] == pytest.approx(0.59, abs=0.002)
    assert rt["colluvium"] == pytest.approx(0.62, abs=0.002)
    # Consecutive cells join: each ends where the next begins.
    for a, b in zip(cells, cells[1:], strict=False):
        assert (a["end_x_ft"], a["end_y_ft"]) == (b["begin_x_ft"], b["begin_y_ft"])


def test_tornado_boulder_density_diameter_and_shape(tornado):
    rock = {
        r["field"]: r["value"] for r in rows(export_crsp(tornado).files["rock.csv"])
    }
    # 3750 kg, r = 0.725 m: V = 4/3 pi 0.725^3 = 4.18879 * 0.381078 = 1.59626 m^3,
    # rho = 3750 / 1.59626 = 2349.2 kg/m^3; 1 pcf = 0.45359237 / 0.3048^3
    # = 16.01846 kg/m^3, so 2349.2 / 16.01846 = 146.66 pcf.
    assert float(rock["density"]) == pytest.approx(146.66, abs=0.01)
    # Diameter 1.45 m / 0.3048 = 4.757 ft; k/r = 0.46 / 0.725 = 0.634 ~ sphere 0.632.
    assert rock["diameter"] == "4.757"
    assert rock["shape"] == "sphere"
    # 3750 kg / 0.45359237 = 8267.3 lb (the thesis rounds to 8270 lb, §8.1).
    assert rock["mass (check)"] == "8267.3"


def test_cylinder_when_gyration_is_that_of_an_axis():
    data = small()
    data["body"]["gyration_m"] = 0.2 * math.sqrt(0.5)  # k/r = 0.707
    export = export_crsp(model_from_dict(data))
    assert "shape,cylinder," in export.files["rock.csv"]
    assert any("disk" in m for m in export.mismatches)


def test_start_in_feet(tornado):
    start = {r["field"]: r for r in rows(export_crsp(tornado).files["start.csv"])}
    # 350.725 m / 0.3048 = 1150.67 ft; 3.007 m/s / 0.3048 = 9.87 ft/s; 0.5 -> 1.64.
    assert start["y"]["value"] == "1150.67"
    assert start["vx"]["value"] == "9.87"
    assert start["vx"]["sd"] == "1.64"


@pytest.mark.parametrize(
    ("field", "value", "target"),
    [("e_t", 1.2, "Rt"), ("e_n", 0.0, "Rn"), ("e_n", 1.0001, "Rn")],
)
def test_coefficients_outside_crsp_are_fitted_in_range(field, value, target):
    # before issue 19: refused; now the in-range values under CRSP's law, said
    data = small(**{field: value})
    data["effects"] = {"velocity_scaled_restitution": {}}
    export = export_crsp(model_from_dict(data))
    cell = rows(export.files["cells.csv"])[0]
    assert 0.0 < float(cell["Rn"]) <= 1.0 and 0.0 < float(cell["Rt"]) <= 1.0
    said = f"materials.talus.{field} = {value:.4g} is outside CRSP's {target} range"
    assert any(said in m for m in export.mismatches), export.mismatches


def test_rn_above_one_with_velocity_scaling_is_fitted_in_range():
    # before issue 19 "1.250" was written (documented range: up to 1)
    data = small(e_n=1.25)
    data["effects"] = {"velocity_scaled_restitution": {}}
    export = export_crsp(model_from_dict(data))
    assert 0.0 < float(rows(export.files["cells.csv"])[0]["Rn"]) <= 1.0
    assert any(
        "materials.talus.e_n: the least-squares value under CRSP's law is" in m
        for m in export.mismatches
    ), export.mismatches


def test_check_written_refuses_a_value_out_of_range():
    surface = {"talus": (0.0, 0.85, 1.25)}
    with pytest.raises(WrittenOutOfRange, match=r"talus cells: Rn = 1.25 outside"):
        check_written(model_from_dict(small()), surface)


def test_calibrated_tornado_through_the_cli(cli, repo, tmp_path):
    data = json.loads((repo / PATH_START).read_text())
    data["materials"]["colluvium"]["e_n"] = 1.18581256337219
    data["materials"]["bench"]["e_n"] = 0.83
    data["effects"]["velocity_scaled_restitution"] = {"k_mps": 13.2440621510482}
    path = tmp_path / "calibrated.json"
    path.write_text(json.dumps(data))
    out = tmp_path / "crsp"
    r = cli("export", path, "--to", "crsp", "-o", out)
    assert r.exit_code == 0, r.output
    for name in ("cells.csv", "rock.csv", "start.csv", "README.md"):
        assert f"wrote {out / name}" in r.output
    cells = rows((out / "cells.csv").read_text())
    for cell in cells:  # before issue 19: colluvium Rn 1.186
        assert 0.0 < float(cell["Rn"]) <= 1.0 and 0.0 < float(cell["Rt"]) <= 1.0
    s_ft = {c["material"]: c["S_ft"] for c in cells}
    assert s_ft == {"rock": "1.67", "colluvium": "0.00", "bench": "0.00"}
    readme = (out / "README.md").read_text()
    assert "## Translation error: calibrated model vs the target's law" in readme
    assert "| runout p50 |" in readme and "p95 total energy at" in readme
    assert "materials.colluvium.e_n: the least-squares value under CRSP's law" in readme
    assert "## Sources of the target's rules" in readme
    assert "## Unconfirmed" in readme and "f(F) and SF" in readme


def test_restitution_of_one_is_accepted():
    # CRSP's own law (velocity scaling at K = 30 ft/s) with Rn = 1: as calibrated
    data = small(e_n=1.0)
    data["effects"] = {"velocity_scaled_restitution": {}}
    export = export_crsp(model_from_dict(data))
    assert rows(export.files["cells.csv"])[0]["Rn"] == "1.000"
    assert not any("cannot be written" in m for m in export.mismatches)


def test_behaviour_search_is_checked_on_an_independent_stream():
    # e_n = 1.0 without scaling: CRSP's scaled Rn at 1 behaves differently; the
    # search's Rn is written only if it also cuts the translation error's gap
    export = export_crsp(model_from_dict(small(e_n=1.0)))
    line = next(m for m in export.mismatches if m.startswith("Behaviour search"))
    assert "over materials.talus.e_n in CRSP's ranges" in line
    start, found = (
        float(x) for x in line.split("own stream ")[1].split(". ")[0].split(" and ")
    )
    rn = float(rows(export.files["cells.csv"])[0]["Rn"])
    if found <= 0.8 * start:
        assert "The values found are written" in line and rn < 1.0
    else:
        assert "The impact-level values are written" in line


def test_roughness_s_in_feet_and_its_effect():
    on = small(roughness_m=0.3048)
    on["effects"] = {"slope_roughness": {}}
    assert rows(export_crsp(model_from_dict(on)).files["cells.csv"])[0]["S_ft"] == (
        "1.00"
    )
    off = small(roughness_m=0.3048)  # slope_roughness off: the model used none
    assert rows(export_crsp(model_from_dict(off)).files["cells.csv"])[0]["S_ft"] == (
        "0.00"
    )
    # scale 0.5: the roughness angle atan(0.3048 / 0.2) = 56.73 deg halves to
    # 28.36 deg; S = 0.2 tan(28.36 deg) = 0.1080 m = 0.354 ft.
    half = small(roughness_m=0.3048)
    half["effects"] = {"slope_roughness": {"scale": 0.5}}
    s_ft = rows(export_crsp(model_from_dict(half)).files["cells.csv"])[0]["S_ft"]
    assert s_ft == "0.35"
    # scale 2: 113 deg, no S can give it.
    steep = small(roughness_m=0.3048)
    steep["effects"] = {"slope_roughness": {"scale": 2.0}}
    with pytest.raises(ArgumentError, match="roughness_m = 0.3048"):
        export_crsp(model_from_dict(steep))


def test_tornado_account(tornado):
    export = export_crsp(tornado)
    unmapped = dict(export.unmapped)
    # RocFall's dip SD is CRSP's roughness angle: S = r tan(35 deg) = 1.67 ft
    # (before issue 19 it was listed as not converted, and S = 0 was written)
    assert "materials.rock.roughness_deg_sd = 35 deg" not in " ".join(unmapped)
    assert any(
        "roughness_deg_sd = 35 deg" in m.fieldkit and "S = 1.67 ft" in m.target
        for m in export.mapped
    )
    assert "materials.rock.friction_deg = 2.86 deg" in unmapped
    assert any(m.startswith("Rt is not CRSP's tangential") for m in export.mismatches)
    assert export.mismatches[0].startswith("The calibrated law cannot be written")
    assert "the calibrated model has no velocity scaling" in export.mismatches[0]
    assert any("1 ft = 0.3048 m" in u for u in export.units)
    assert any("16.018463" in u for u in export.units)
    readme = export.readme("model.json")
    assert (
        "| materials.rock.e_n = 0.75 | rock cells: Rn = 1.000 | written 1 (" in readme
    )


def test_velocity_scaling_and_effects_crsp_lacks():
    data = small()
    data["effects"] = {"velocity_scaled_restitution": {}, "air_drag": {}}
    export = export_crsp(model_from_dict(data))
    assert any("K = 30 ft/s" in m.target for m in export.mapped)
    assert any(what.startswith("effect air_drag") for what, _ in export.unmapped)
    data["effects"] = {"velocity_scaled_restitution": {"k_mps": 20.0}}
    export = export_crsp(model_from_dict(data))
    assert any("k_mps = 20 m/s (65.62 ft/s)" in m for m in export.mismatches)


def test_calibrated_values_carry_their_standard_error():
    model = model_from_dict(small())
    model = replace(
        model,
        provenance={
            "fit": {
                "parameters": {"materials.talus.e_n": {"value": 0.35, "stderr": 0.02}}
            }
        },
    )
    rn = next(m for m in export_crsp(model).mapped if "Rn" in m.target)
    assert rn.fieldkit == "materials.talus.e_n = 0.35 ± 0.02 (fit)"


def test_site_is_ignored(tornado):
    site = site_from_section(tornado, cellsize_m=50, rows=2)
    assert export_crsp(tornado, site).files == export_crsp(tornado).files


def test_no_rock_strikes_anything_clips_and_says_so(cli, tmp_path):
    # the seeder throws every rock past the section's end: nothing to fit or
    # search; e_n 1.3 is clipped to 1 and said, never written raw
    data = small(e_n=1.3)
    data["seeder"] = {"x_m": 30.0, "z_m": 1.0, "vx_mps": 20.0}
    path = tmp_path / "m.json"
    path.write_text(json.dumps(data))
    out = tmp_path / "out"
    r = cli("export", path, "--to", "crsp", "-o", out)
    assert r.exit_code == 0, r.output
    assert rows((out / "cells.csv").read_text())[0]["Rn"] == "1.000"
    readme = " ".join((out / "README.md").read_text().split())
    assert "talus: NO SIMULATED IMPACT on it" in readme
    assert "no simulated rock struck anything" in readme
