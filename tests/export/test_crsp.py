"""CRSP export: feet, cells = segments, the rock's density, refusals (hand numbers)."""

from __future__ import annotations

import csv
import io
import math
from dataclasses import replace

import pytest

from fieldkit.errors import ArgumentError
from fieldkit.export.crsp import export_crsp
from fieldkit.export.site import site_from_section
from fieldkit.model.model_file import model_from_dict


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
    # Thesis Table 7-1, site 4: rock e_N 0.75, e_T 0.59; colluvium 1.00, 0.62.
    surface = {c["material"]: (c["Rn"], c["Rt"], c["S_ft"]) for c in cells}
    assert surface == {
        "rock": ("0.750", "0.590", "0.00"),
        "colluvium": ("1.000", "0.620", "0.00"),
    }
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
def test_coefficients_outside_crsp_refused(field, value, target):
    model = model_from_dict(small(**{field: value}))
    with pytest.raises(ArgumentError) as error:
        export_crsp(model)
    message = str(error.value)
    assert "\n" not in message
    assert f"materials.talus.{field} = {value:g}" in message
    assert f"CRSP's {target} range (0, 1]" in message


def test_rn_above_one_with_velocity_scaling_is_written_with_its_mismatch():
    data = small(e_n=1.25)
    data["effects"] = {"velocity_scaled_restitution": {}}
    export = export_crsp(model_from_dict(data))
    assert rows(export.files["cells.csv"])[0]["Rn"] == "1.250"
    # scaled Rn = 1.25 / (1 + (v/K)^2) < 1 for v > K sqrt(0.25) = 15 ft/s (K 30 ft/s)
    assert any("above 15 ft/s" in m for m in export.mismatches), export.mismatches


def test_restitution_of_one_is_accepted():
    cells = rows(export_crsp(model_from_dict(small(e_n=1.0))).files["cells.csv"])
    assert cells[0]["Rn"] == "1.000"


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
    # RocFall's dip SD has no CRSP input: said, with S = r tan(35 deg) = 0.508 m.
    reason = unmapped["materials.rock.roughness_deg_sd = 35 deg"]
    assert "0.508 m" in reason
    assert "materials.rock.friction_deg = 2.86 deg" in unmapped
    assert export.mismatches[0].startswith("Rt is not CRSP's tangential restitution")
    assert any("velocity_scaled_restitution off" in m for m in export.mismatches)
    assert any("1 ft = 0.3048 m" in u for u in export.units)
    assert any("16.018463" in u for u in export.units)
    readme = export.readme("model.json")
    assert "| materials.rock.e_n = 0.75 | rock cells: Rn = 0.750 |" in readme


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
