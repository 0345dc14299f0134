"""Write the five thesis case studies as forward-model files (thesis §7.5, Table 7-1).

Run from the repository root::

    .venv/bin/python surveys/make_case_models.py

It writes ``surveys/<site>/model_rocfall_table_7_1.json`` for Mt. Stephen, Kreuger
Quarry, Ehime, Tornado Mountain (boulder A) and the asphalt impact, in the model-file
format of docs/architecture.md §5. Deterministic: running it again reproduces the
committed files byte for byte (tests/model/test_case_models.py checks it).

What is thesis and what is not. The materials are Table 7-1 exactly (the RocFall 4.0
inputs the thesis used), with the table's footnote SD 0.04 for e_N and e_T. The copy of
the thesis this project works from has the *text* of chapter 7 but not its figures, so
nothing here is "read from Fig. 7.x": the profiles are built from the chapter 2 tables
(impact coordinates lie on the ground) and the slope heights and angles the text gives;
the seeder velocities, which the thesis shows only on Figs. 7.4-7.15, are assumed (a
horizontal launch from the source that lands on the table's first impact point). Every
number's origin is in the file's ``provenance`` block (keys are the model's field paths:
``profile``, ``materials.<name>.<field>``, ``body.<field>``, ``seeder.<field>``, ...).

Effects: ``slope_roughness`` is on wherever Table 7-1 gives a roughness SD (RocFall's
roughness is an SD of the segment dip: the material's ``roughness_deg_sd``). Nothing
else is switched on: Table 7-1 does not say whether RocFall's "scale Rn by velocity"
(eq. 7.1) was used, so it is left off and said so; add
``"velocity_scaled_restitution": {}`` to the ``effects`` block to try it.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

HERE = Path(__file__).resolve().parent
G = 9.81
FILE_NAME = "model_rocfall_table_7_1.json"

#: Table 7-1 footnote: "In RocScience 4.0, default SD for e_N and e_T = 0.04".
ROCFALL_RESTITUTION_SD = 0.04
T71 = "Table 7-1"
SD_NOTE = "Table 7-1 footnote (RocFall 4.0 default SD for e_N and e_T)"

# Table 7-1, typed: site -> material -> (e_N, e_T, friction mean, friction SD,
# roughness SD [deg]). Material names are this project's labels for the table's rows.
TABLE_7_1: dict[str, dict[str, tuple[float, float, float, float, float]]] = {
    "mt_stephen": {"rock": (0.75, 0.59, 5.71, 2.50, 11.50)},
    "kreuger_quarry": {
        "rock_face": (1.00, 0.59, 3.01, 3.01, 5.00),  # "rock face impact"
        "ditch": (0.25, 0.59, 3.01, 3.01, 5.00),  # "ditch impact" (rock)
    },
    "ehime": {
        "rock": (1.00, 0.59, 8.53, 2.00, 3.00),
        "talus": (1.00, 0.72, 19.29, 2.00, 8.00),
    },
    "tornado_mountain": {
        "rock": (0.75, 0.59, 2.86, 1.50, 35.00),
        "colluvium": (1.00, 0.62, 19.29, 2.00, 0.00),
    },
    "asphalt": {
        "asphalt": (0.38, 0.24, 30.5, 15.10, 0.00),
        "rock": (0.75, 0.59, 8.53, 4.00, 10.00),
        "colluvium": (1.00, 0.62, 19.29, 10.00, 0.00),
    },
}
ROW_LABEL = {
    ("mt_stephen", "rock"): "site 1 Mt. Stephen, rock",
    ("kreuger_quarry", "rock_face"): "site 2 Oregon ditch study, rock face impact",
    ("kreuger_quarry", "ditch"): "site 2 Oregon ditch study, ditch impact (rock)",
    ("ehime", "rock"): "site 3 Ehime, rock slope",
    ("ehime", "talus"): "site 3 Ehime, talus slope",
    ("tornado_mountain", "rock"): "site 4 Tornado Mountain, rock",
    ("tornado_mountain", "colluvium"): "site 4 Tornado Mountain, colluvium",
    ("asphalt", "asphalt"): "site 5 Highway, asphalt",
    ("asphalt", "rock"): "site 5 Highway, rock",
    ("asphalt", "colluvium"): "site 5 Highway, colluvium",
}


def r(value: float, digits: int = 3) -> float:
    """Round for the file (and turn -0.0 into 0.0)."""
    return round(float(value), digits) + 0.0


def materials(site: str) -> tuple[dict, dict]:
    """Table 7-1's rows for ``site`` as model-file materials, and their provenance."""
    out, prov = {}, {}
    for name, (e_n, e_t, phi, phi_sd, rough_sd) in TABLE_7_1[site].items():
        row = f"{T71} ({ROW_LABEL[(site, name)]})"
        out[name] = {
            "e_n": e_n,
            "e_t": e_t,
            "friction_deg": phi,
            "e_n_sd": ROCFALL_RESTITUTION_SD,
            "e_t_sd": ROCFALL_RESTITUTION_SD,
            "friction_deg_sd": phi_sd,
            "roughness_deg_sd": rough_sd,
        }
        prov[f"materials.{name}"] = row
        for field in ("e_n", "e_t", "friction_deg", "friction_deg_sd"):
            prov[f"materials.{name}.{field}"] = row
        prov[f"materials.{name}.roughness_deg_sd"] = (
            f"{row}: slope roughness SD [deg] (RocFall: SD of the segment dip)"
        )
        for field in ("e_n_sd", "e_t_sd"):
            prov[f"materials.{name}.{field}"] = SD_NOTE
    return out, prov


def horizontal_launch(x0: float, z0: float, x1: float, z1: float) -> float:
    """Horizontal speed [m/s] of a level launch at (x0, z0) that lands at (x1, z1).

    ``z1 = z0 - g t^2 / 2`` and ``x1 = x0 + vx t`` (eqs. 3.1, 3.2 with alpha = 0).
    """
    return (x1 - x0) / math.sqrt(2.0 * (z0 - z1) / G)


def read_section(path: Path) -> list[dict]:
    """Rows of a surveys/ section CSV (``point, x_m, z_m, material, ...``)."""
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def effects_for(mats: dict) -> dict:
    """``slope_roughness`` on when any material has a roughness SD (Table 7-1)."""
    if any(m["roughness_deg_sd"] > 0 for m in mats.values()):
        return {"slope_roughness": {}}
    return {}


EFFECTS_NOTE = (
    "slope_roughness on: Table 7-1 gives a roughness SD (RocFall's SD of the segment "
    "dip, material roughness_deg_sd); default scale 1 = the SD as given. "
    "velocity_scaled_restitution (eq. 7.1) is OFF: §7.3.4 says RocFall 4.0 can scale "
    "v_fN by eq. 7.1 but Table 7-1 does not say whether the thesis runs used it - "
    "assumed off; add 'velocity_scaled_restitution': {} to try it. No other effect: "
    "RocFall 4.0 lumped mass has none of them (trees, mass loss, drag)."
)
SEEDER_SD_NOTE = (
    "assumed: the seeder SDs the thesis used are on the figure, not in the text"
)


def model(
    *,
    title: str,
    profile: dict,
    site: str,
    body: dict,
    seeder: dict,
    provenance: dict,
    analysis_points: list[dict] | None = None,
) -> dict:
    """Assemble one model file (dict) with its provenance (and its analysis
    points, where the design quantities are read, when given)."""
    mats, mat_prov = materials(site)
    prov = {"title": title, **provenance, **mat_prov, "effects": EFFECTS_NOTE}
    points = {"analysis_points": analysis_points} if analysis_points else {}
    return {
        "profile": profile,
        "materials": mats,
        "effects": effects_for(mats),
        "body": body,
        "seeder": seeder,
        **points,
        "provenance": prov,
    }


# --------------------------------------------------------------------------- sites
def tornado_mountain() -> dict:
    """Boulder A (§2.2.2, §7.5.4): the mapped impact points are the ground line."""
    rows = read_section(HERE / "tornado_mountain" / "boulder_a_section.csv")
    x = [float(p["x_m"]) for p in rows]
    z = [float(p["z_m"]) for p in rows]
    # Segment j ends at point j+1; it takes that point's mapped material. Table 7-1 has
    # only rock and colluvium for this site: the talus (D, E) and the bench (43-45,
    # excavated in the colluvium, §2.2.2) are modelled as colluvium.
    label = {"rock": "rock", "talus": "colluvium", "colluvium": "colluvium"}
    label["bench"] = "colluvium"
    material = [label[p["material"]] for p in rows[1:]]
    x_end = 700.0  # flat run-on past the stop point #45 (assumed)
    x.append(x_end)
    z.append(z[-1])
    material.append("colluvium")
    radius = 0.725
    z0 = z[0] + radius
    vx = horizontal_launch(x[0], z0, x[1], z[1])
    return model(
        title="Tornado Mountain boulder A, RocFall 4.0 inputs of Table 7-1 (§7.5.4)",
        site="tornado_mountain",
        profile={
            "x_m": [r(v, 2) for v in x],
            "z_m": [r(v, 2) for v in z],
            "material": material,
        },
        body={"mass_kg": 3750.0, "radius_m": radius, "gyration_m": 0.46},
        seeder={
            "x_m": 0.0,
            "z_m": r(z0),
            "vx_mps": r(vx),
            "vz_mps": 0.0,
            "omega_radps": 0.0,
            "vx_sd_mps": 0.5,
            "vz_sd_mps": 0.5,
        },
        analysis_points=[{"x_m": 610.0, "name": "railway bench"}],
        provenance={
            "profile": (
                "vertices = the 50 mapped points of boulder A in Table 2-4: A "
                "(source), B-E and 1-44 (impacts), 45 (stopped); x = horizontal "
                "distance from the source, z = "
                "elevation [m]: surveys/tornado_mountain/boulder_a_section.csv = "
                "Table 2-4 as printed (the GPX in the same folder reduces to the same "
                "x, z: cumulative geodesic plan distance = x, ele = z + 1352 m). "
                "Impact scars lie on the ground, so joining them is the best ground "
                "line we have; the thesis's own Fig. 7.12 profile is not in the text. "
                "Last vertex x = 700 m, z = -4 m: flat run-on past the stop point "
                "(assumed) so a runout beyond #45 is measured, not cut off. Text "
                "check (§2.2.2, §7.5.4): ~50 m cliff (A-C: 350 -> 295 m), talus ~35 "
                "deg (C-E), colluvium ~22 deg, bench at the railway (43-45)."
            ),
            "profile.material": (
                "segment j takes the mapped material of its downslope end point "
                "(boulder_a_section.csv: A-C rock, D-E talus, 1-42 colluvium, 43-45 "
                "bench). Table 7-1 lists rock and colluvium only, so talus and the "
                "bench (excavated in the colluvium, §2.2.2) use colluvium (assumed)."
            ),
            "body.mass_kg": "§2.2.2, §7.5.4 (3750 kg)",
            "body.radius_m": (
                "contact radius (a + b)/2 = (0.8 + 0.65)/2 = 0.725 m of the 1.6 x 1.3 "
                "x 1.3 m ellipsoid (§2.2.2, Table 2-6, worked example 6B)"
            ),
            "body.gyration_m": "§2.2.2 (k = 0.46 m), Table 4-1",
            "seeder": (
                "source A (Table 2-4) at x = 0; Fig. 7.12's seeder values are not in "
                "the text, so the seeder is assumed"
            ),
            "seeder.x_m": "Table 2-4, point A (source)",
            "seeder.z_m": "Table 2-4 A (350 m) + body radius (centre above the scar)",
            "seeder.vx_mps": (
                "assumed: horizontal launch from A that lands on the first mapped "
                "impact B (8.0, 316.0), eqs. 3.1-3.2"
            ),
            "seeder.vz_mps": "assumed: 0 (horizontal launch)",
            "seeder.omega_radps": "assumed: 0",
            "seeder.vx_sd_mps": SEEDER_SD_NOTE,
            "seeder.vz_sd_mps": SEEDER_SD_NOTE,
            "analysis_point": (
                "x = 610 m, just above the railway bench (§7.5.4, Fig. 7.14); "
                "measured there: 18 m/s, KE 600 kJ (+ RE 90 kJ if I = 800 kg m^2, "
                "omega = 15 rad/s = 690 kJ total)"
            ),
            "measured_flight_height": (
                "mean max flight height normal to the chord between impacts, flights "
                "leaving impacts 1-44: 1.68 m recomputed from Table 2-4 (thesis "
                "prints 1.3 m in §2.2.2 and 1.5 m in §7.5.4; docs/thesis-notes.md)"
            ),
        },
    )


def ehime() -> dict:
    """Concrete cube test (§2.1.3, §7.5.3): Table 2-3's impact points as the ground."""
    rows = read_section(HERE / "ehime" / "cube_section.csv")
    x = [float(p["x_m"]) for p in rows]
    z = [float(p["z_m"]) for p in rows]
    material = [p["material"] for p in rows[1:]]
    # The rock face is 26 m high (§2.1.3): rock down to z = 45 - 26 = 19 m. The chord
    # 5 -> 6 (29.67 -> 18.23 m) crosses that level; split it there.
    z_contact = 45.0 - 26.0
    f = (z[5] - z_contact) / (z[5] - z[6])
    x_contact = x[5] + f * (x[6] - x[5])
    x.insert(6, x_contact)
    z.insert(6, z_contact)
    material[5:5] = ["rock"]  # segment 5 -> contact is rock, contact -> 6 talus
    x.append(70.0)
    z.append(z[-1])
    material.append("talus")
    radius = 0.3
    z0 = z[0] + radius
    vx = horizontal_launch(x[0], z0, x[1], z[1])
    return model(
        title="Ehime concrete cube, RocFall 4.0 inputs of Table 7-1 (§7.5.3)",
        site="ehime",
        profile={
            "x_m": [r(v, 2) for v in x],
            "z_m": [r(v, 2) for v in z],
            "material": material,
        },
        body={"mass_kg": 520.0, "radius_m": radius, "gyration_m": 0.245},
        seeder={
            "x_m": 0.0,
            "z_m": r(z0),
            "vx_mps": r(vx),
            "vz_mps": 0.0,
            "omega_radps": 0.0,
            "vx_sd_mps": 0.3,
            "vz_sd_mps": 0.3,
        },
        provenance={
            "profile": (
                "vertices = Table 2-3's impact points 0 (source) to 9 (stop) "
                "(surveys/ehime/cube_section.csv), plus the rock/talus contact at "
                f"z = 19.0 m (x = {x_contact:.2f} m on the chord 5-6) from §2.1.3's "
                "26 m rock face above a 16 m talus slope, plus a flat run-on to x = "
                "70 m (assumed). Text check: §2.1.3 gives the face at 44 deg and the "
                "talus at 35 deg; the impact chords run 37-53 deg on rock and "
                "34-41 deg on talus. Fig. 7.9's profile is not in the text."
            ),
            "profile.material": (
                "Table 2-3: points 1-5 rock, 6-9 talus; rock above z = 19 m (§2.1.3)"
            ),
            "body.mass_kg": "§2.1.3, §7.5.3 (concrete cube, 520 kg)",
            "body.radius_m": "half the 0.6 m cube side (Table 2-6 contact radius)",
            "body.gyration_m": "§2.1.3 (k = 0.245 m)",
            "seeder": (
                "source point 0 (Table 2-3); Fig. 7.9's seeder values are not in the "
                "text, so the seeder is assumed"
            ),
            "seeder.x_m": "Table 2-3, point 0",
            "seeder.z_m": "Table 2-3 point 0 (45.0 m) + body radius",
            "seeder.vx_mps": (
                "assumed: horizontal launch landing on impact 1 (1.0, 44.0), "
                "eqs. 3.1-3.2"
            ),
            "seeder.vz_mps": "assumed: 0",
            "seeder.omega_radps": "assumed: 0",
            "seeder.vx_sd_mps": SEEDER_SD_NOTE,
            "seeder.vz_sd_mps": SEEDER_SD_NOTE,
            "analysis_point": (
                "x = 52.1 m, base of the talus (§7.5.3, Fig. 7.11); measured at "
                "H = 41 m: 5 to 15 m/s (Fig. 3.6); 95 % of trajectory heights < 1.5 "
                "m, 99 % < 2 m (normal to the slope, Fig. 3.5)"
            ),
        },
    )


def kreuger_quarry() -> dict:
    """15 m cut at 76 deg above a horizontal ditch (§2.1.2, §7.5.2, Table 2-2)."""
    face = math.radians(76.0)
    x_face, z_face = 1.50, 7.00  # Table 2-2 face impact (2)
    x_toe = x_face + z_face / math.tan(face)
    x = [-5.0, 0.0, x_face, x_toe, 40.0]
    z = [15.0, 15.0, z_face, 0.0, 0.0]
    material = ["rock_face", "rock_face", "rock_face", "ditch"]
    radius = 0.3
    return model(
        title="Kreuger Quarry 15 m cut at 76 deg, RocFall 4.0 inputs of Table 7-1 "
        "(§7.5.2)",
        site="kreuger_quarry",
        profile={
            "x_m": [r(v, 2) for v in x],
            "z_m": [r(v, 2) for v in z],
            "material": material,
        },
        body={"mass_kg": 580.0, "radius_m": radius, "gyration_m": 0.245},
        seeder={
            "x_m": 0.0,
            "z_m": r(15.0 + radius),
            "vx_mps": 0.5,
            "vz_mps": 0.0,
            "omega_radps": 0.0,
            "vx_sd_mps": 0.2,
            "vz_sd_mps": 0.1,
        },
        provenance={
            "profile": (
                "crest (0, 15) of the 15 m cut (§2.1.2, Table 2-2 crest); the face "
                "through Table 2-2's face impact (1.5, 7.0), then down at 76 deg "
                f"(§2.1.2: 1/4H:1V) to the toe at x = {x_toe:.2f} m; horizontal ditch "
                "to x = 40 m (length assumed; Table 2-2's ditch impacts 6.25 and 9.0 "
                "m lie on it). 5 m of flat crest behind (assumed). The upper face "
                "(0, 15) -> (1.5, 7.0) is 79 deg: Table 2-2's face point sits 0.5 m "
                "inside a straight 76 deg line from the crest. Fig. 7.7's profile is "
                "not in the text."
            ),
            "profile.material": (
                "Table 7-1 gives the Oregon rock twice: 'rock face impact' (face, "
                "crest) and 'ditch impact' (ditch floor)"
            ),
            "body.mass_kg": "§2.1.2, §7.5.2, Fig. 7.7 caption (580 kg)",
            "body.radius_m": "half the 0.6 m cube side (§2.1.2, Table 2-6)",
            "body.gyration_m": "§2.1.2 (k = 0.245 m)",
            "seeder": (
                "rocks pushed off the crest with low x and z velocities (§7.5.2); the "
                "values on Fig. 7.7 are not in the text, so they are assumed"
            ),
            "seeder.x_m": "crest edge (Table 2-2 crest, x = 0)",
            "seeder.z_m": "crest (15 m) + body radius",
            "seeder.vx_mps": "assumed: 0.5 m/s ('low values', §7.5.2)",
            "seeder.vz_mps": "assumed: 0 ('low values', §7.5.2)",
            "seeder.omega_radps": "assumed: 0",
            "seeder.vx_sd_mps": SEEDER_SD_NOTE,
            "seeder.vz_sd_mps": SEEDER_SD_NOTE,
            "analysis_point": (
                f"x = {x_toe + 1.4:.1f} m: 1.4 m from the base of the cut (§7.5.2). "
                "The thesis calls it x = 10 m in Fig. 7.7's frame, whose origin the "
                "text does not give (its 95th-percentile first ditch impact is at "
                "11.8 m there and 6.25 m in Table 2-2: an offset of about 5 m)"
            ),
        },
    )


def mt_stephen() -> dict:
    """Lower 120 m of the slope above the barrier (§2.1.1, §7.5.1, Table 2-1)."""
    psi_a = math.radians(41.0)  # surveyed slope at impact A (Table 2-1)
    x_a, z_a = 60.0, 71.5
    x = [40.0, 52.0, x_a, 68.0, 74.0, 104.0, 110.0, 130.0]
    z = [
        112.0,
        z_a + 8.0 * math.tan(psi_a),
        z_a,
        z_a - 8.0 * math.tan(psi_a),
        40.0,
        10.0,
        0.0,
        0.0,
    ]
    material = ["rock"] * 7
    radius = 0.2
    z0 = z[0] + radius
    vx = horizontal_launch(x[0], z0, x_a, z_a)
    return model(
        title="Mt. Stephen lower slope, RocFall 4.0 inputs of Table 7-1 (§7.5.1)",
        site="mt_stephen",
        profile={
            "x_m": [r(v, 2) for v in x],
            "z_m": [r(v, 2) for v in z],
            "material": material,
        },
        body={"mass_kg": 50.0, "radius_m": radius, "gyration_m": 0.13},
        seeder={
            "x_m": 40.0,
            "z_m": r(z0),
            "vx_mps": r(vx),
            "vz_mps": 0.0,
            "omega_radps": 0.0,
            "vx_sd_mps": 1.0,
            "vz_sd_mps": 1.0,
        },
        provenance={
            "profile": (
                "only three points are in the text: source S (40, 112), impact A "
                "(60, 71.5) on ground dipping 41 deg, barrier impact (117, 8) "
                "(Table 2-1); the lidar section of Fig. 2.2 / Fig. 7.4 is not in "
                "the text. Built: S; a steep face to (52, 78.45) (assumed); the 41 "
                "deg surface through A from x = 52 to 68 (Table 2-1 surveyed slope); "
                "a step to (74, 40) (assumed); the lower face at 45 deg to (104, "
                "10) (§7.5.1: 'the lower face sloping at about 45 degrees'); the "
                "ditch behind the barrier at z = 0 = track level from x = 110 "
                "(assumed) to 130 m. The 11.6 m MSE barrier (§2.1.1) is NOT ground "
                "in this model: the analysis point at its face records the height "
                "at which rocks cross it (Fig. 7.5's vertical distribution)."
            ),
            "profile.material": (
                "rock for the whole slope (§7.5.1); the ditch soil behind the "
                "barrier has no Table 7-1 row, so it is rock too (assumed)"
            ),
            "body.mass_kg": (
                "§7.5.1 (50 kg; §2.1.1 gives 44 kg for the same 0.4 x 0.4 x 0.2 m "
                "ellipsoid)"
            ),
            "body.radius_m": "semi-axis 0.2 m of the 0.4 x 0.4 x 0.2 m ellipsoid "
            "(§2.1.1, Table 2-6 contact radius)",
            "body.gyration_m": "§2.1.1 (k = 0.13 m)",
            "seeder": (
                "falls originate above 118 m, so the seeder has velocities (§7.5.1); "
                "Fig. 7.4's values are not in the text, so they are assumed"
            ),
            "seeder.x_m": "Table 2-1 source S",
            "seeder.z_m": "Table 2-1 S (112 m) + body radius",
            "seeder.vx_mps": (
                "assumed: horizontal launch from S that lands on A (60, 71.5) - "
                "impact speed about 29 m/s, §2.1.1: 'as great as 30 m/s'"
            ),
            "seeder.vz_mps": "assumed: 0",
            "seeder.omega_radps": "assumed: 0",
            "seeder.vx_sd_mps": SEEDER_SD_NOTE,
            "seeder.vz_sd_mps": SEEDER_SD_NOTE,
            "analysis_point": (
                "x = 116.3 m, the barrier (§7.5.1, Fig. 7.6); thesis: calculated "
                "velocities up to 44 m/s, about 60 kJ for 50 kg; field: 466 impacts "
                "over the 11.6 m height, most at the base"
            ),
        },
    )


def asphalt() -> dict:
    """138 m slope above a highway (§2.3, §7.5.5, Table 2-5)."""
    rock_h, face = 56.0, math.radians(60.0)
    x_crest, z_crest = 0.0, 637.0  # Table 2-5 source
    x_rock = x_crest + rock_h / math.tan(face)
    z_rock = z_crest - rock_h
    x_cut, z_cut = 113.0, 511.0  # Table 2-5 impact 1 (rock, crest of the cut)
    cut_h = 10.0
    x_road = x_cut + cut_h / math.tan(math.radians(76.0))
    x = [-10.0, x_crest, x_rock, x_cut, x_road, 160.0]
    z = [z_crest, z_crest, z_rock, z_cut, z_cut - cut_h, z_cut - cut_h]
    material = ["rock", "rock", "colluvium", "rock", "asphalt"]
    colluvium_deg = math.degrees(math.atan2(z_rock - z_cut, x_cut - x_rock))
    radius = 0.36
    return model(
        title="Asphalt impact, 138 m slope above a highway, RocFall 4.0 inputs of "
        "Table 7-1 (§7.5.5)",
        site="asphalt",
        profile={
            "x_m": [r(v, 2) for v in x],
            "z_m": [r(v, 2) for v in z],
            "material": material,
        },
        body={"mass_kg": 500.0, "radius_m": radius, "gyration_m": 0.295},
        seeder={
            "x_m": 0.0,
            "z_m": r(z_crest + radius),
            "vx_mps": 1.0,
            "vz_mps": 0.0,
            "omega_radps": 0.0,
            "vx_sd_mps": 0.3,
            "vz_sd_mps": 0.3,
        },
        provenance={
            "profile": (
                "crest = Table 2-5 source (0, 637) with 10 m of flat ground behind "
                "(assumed); rock at 60 deg for 56 m (§7.5.5; §2.3 says 58 m, but "
                "56 + 70 + 10 = 136 m = the 637 - 501 m drop of Table 2-5); "
                f"colluvium from there to Table 2-5 impact 1 (113, 511) at "
                f"{colluvium_deg:.1f} deg (text: 70 m high at 42 deg); the 10 m rock "
                "cut (§2.3) at 76 deg (angle assumed) to the road at z = 501 m (Table "
                "2-5 impact 2); road to x = 160 m (assumed). Fig. 7.15's profile is "
                "not in the text."
            ),
            "profile.material": "§2.3 / §7.5.5: rock, colluvium, rock cut, asphalt",
            "body.mass_kg": "§7.5.5 (500 kg)",
            "body.radius_m": "contact radius of the 0.84 x 0.58 x 0.4 m cuboid "
            "(Table 2-6)",
            "body.gyration_m": "§7.5.5 (k = 0.295 m)",
            "seeder": (
                "a single fall from the crest (§2.3); Fig. 7.15's seeder values are "
                "not in the text, so they are assumed"
            ),
            "seeder.x_m": "Table 2-5 source",
            "seeder.z_m": "Table 2-5 source (637 m) + body radius",
            "seeder.vx_mps": "assumed: 1.0 m/s (toppling off the crest)",
            "seeder.vz_mps": "assumed: 0",
            "seeder.omega_radps": "assumed: 0",
            "seeder.vx_sd_mps": SEEDER_SD_NOTE,
            "seeder.vz_sd_mps": SEEDER_SD_NOTE,
            "analysis_point": (
                f"x = 120 m, over the road between the cut toe ({x_road:.1f} m) and "
                "Table 2-5's asphalt impact (124 m): 'just before the impact with "
                "the asphalt' (§7.5.5). The thesis's x = 140 m is in Fig. 7.15's "
                "frame, which the text does not give. Measured: v_i 21.5 m/s, KE "
                "115 kJ, RE 4.8 kJ (omega 15 rad/s)"
            ),
        },
    )


SITES = {
    "mt_stephen": mt_stephen,
    "kreuger_quarry": kreuger_quarry,
    "ehime": ehime,
    "tornado_mountain": tornado_mountain,
    "asphalt": asphalt,
}


def model_text(site: str) -> str:
    """The JSON text of one site's model file."""
    return json.dumps(SITES[site](), indent=1, ensure_ascii=False) + "\n"


def write(path: Path, text: str) -> None:
    """Write one file (LF line ends, UTF-8)."""
    path.write_text(text, encoding="utf-8", newline="\n")


def main() -> None:
    for site in SITES:
        write(HERE / site / FILE_NAME, model_text(site))


if __name__ == "__main__":
    main()
