"""`fieldkit simulate MODEL_3D --impacts`: the 3-D kernel's impacts as an
ImpactTable, checked against closed forms on an inclined plane (a drop, a throw
across the slope, a slide to a convex break) and read back by `fieldkit fit`,
which must recover the model's e_n and e_t (an independent check of the table's
N/T decomposition), and by `fieldkit diagnose`."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from fieldkit.impact_table import ImpactTable

G = 9.81
BETA_DEG, AZIMUTH_DEG = 30.0, 210.0  # the plane dips 30 deg towards azimuth 210
NX = NY = 60
CELL, Z0 = 1.0, 200.0
E_N, E_T = 0.4, 0.7
MASS_KG, RADIUS_M = 100.0, 0.2


def ground(x, y):
    """The test plane's elevation [m]."""
    tb = math.tan(math.radians(BETA_DEG))
    a = math.radians(AZIMUTH_DEG)
    return Z0 - tb * (np.asarray(x) * math.cos(a) + np.asarray(y) * math.sin(a))


def unit_normal() -> np.ndarray:
    b, a = math.radians(BETA_DEG), math.radians(AZIMUTH_DEG)
    return np.array([math.sin(b) * math.cos(a), math.sin(b) * math.sin(a), math.cos(b)])


@pytest.fixture()
def plane_site(tmp_path) -> Path:
    """An ESRI grid of the plane (1 m cells from (0, 0)) and a writer of model
    files on it (one material "rock", e_n 0.4, e_t 0.7, no effects)."""
    xc = (np.arange(NX) + 0.5) * CELL
    yc = (np.arange(NY) + 0.5) * CELL
    z = ground(*np.meshgrid(xc, yc))[::-1]  # row 0 north in the file
    rows = "\n".join(" ".join(f"{v:.12f}" for v in row) for row in z)
    (tmp_path / "plane.asc").write_text(
        f"ncols {NX}\nnrows {NY}\nxllcorner 0\nyllcorner 0\ncellsize {CELL}\n"
        f"NODATA_value -9999\n{rows}\n"
    )
    return tmp_path


def write_model3d(site: Path, seeder: dict, release=(30.5, 30.5)) -> Path:
    data = {
        "terrain": {"dem": "plane.asc", "materials": "rock",
                    "releases": [list(release)]},
        "materials": {"rock": {"e_n": E_N, "e_t": E_T, "friction_deg": 30.0}},
        "body": {"mass_kg": MASS_KG, "radius_m": RADIUS_M, "gyration_m": 0.126},
        "seeder": seeder,
    }  # fmt: skip
    path = site / "model3d.json"
    path.write_text(json.dumps(data))
    return path


def first_rows(table: ImpactTable):
    f = table.frame
    return f[f["point"] == "1"].reset_index(drop=True)


def test_first_impact_of_a_drop_on_an_inclined_plane(cli, plane_site):
    """A rock dropped 5 m onto a plane dipping 30 deg: it lands below its release
    at v = sqrt(2 g h), vin = -v cos 30, vit = v sin 30; in the row's section
    plane (vertical here: the fall line) the impact velocity is vertical, the
    slope the dip; e_n, e_t the model's; KE 1/2 m v^2; energy head the drop's
    top."""
    h = 5.0
    model = write_model3d(plane_site, {"height_m": h})
    out = plane_site / "out"
    result = cli("simulate", model, "--rocks", "3", "--seed", "1",
                 "--impacts", out / "impacts.csv")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert f"wrote {out / 'impacts.csv'}" in result.stdout
    assert "note: --impacts: 3-D impact rows: x_m, y_m, z_m the contact" in (
        result.stderr
    )
    assert "columns left empty in 3-D rows: theta0_deg" in result.stderr
    table = ImpactTable.read(out / "impacts.csv")
    assert table.paths() == ["0", "1", "2"]
    row = first_rows(table).iloc[0]
    v = math.sqrt(2 * G * h)
    b = math.radians(BETA_DEG)
    a = math.radians(AZIMUTH_DEG)
    x0, y0 = 30.5, 30.5
    expected = {
        "x_m": x0, "y_m": y0, "z_m": float(ground(x0, y0)),
        "slope_deg": BETA_DEG, "dip_deg": BETA_DEG,
        "vi_x_mps": 0.0, "vi_z_mps": -v, "vi_mps": v,
        "vin_mps": -v * math.cos(b), "vit_mps": v * math.sin(b),
        "vfn_mps": E_N * v * math.cos(b), "vft_mps": E_T * v * math.sin(b),
        "theta_i_deg": 90.0 - BETA_DEG,
        "theta_f_deg": math.degrees(math.atan2(E_N * math.cos(b), E_T * math.sin(b))),
        "e_n": E_N, "e_t": E_T, "mass_kg": MASS_KG, "radius_m": RADIUS_M,
        "ke_i_j": 0.5 * MASS_KG * v * v,
        "ke_f_j": 0.5 * MASS_KG * v * v * ((E_N * math.cos(b)) ** 2
                                           + (E_T * math.sin(b)) ** 2),
        "energy_head_i_m": float(ground(x0, y0)) + h,
        "omega_i_radps": 0.0, "omega_f_radps": -E_T * v * math.sin(b) / RADIUS_M,
        "normal_x": math.sin(b) * math.cos(a), "normal_y": math.sin(b) * math.sin(a),
        "normal_z": math.cos(b), "tangent_x": math.cos(b) * math.cos(a),
        "tangent_y": math.cos(b) * math.sin(a), "tangent_z": -math.sin(b),
    }  # fmt: skip
    for name, value in expected.items():
        assert row[name] == pytest.approx(value, rel=1e-9, abs=1e-9), name
    assert row["material"] == "rock" and not row["tree_strike"]
    assert row["t_s"] == pytest.approx(math.sqrt(2 * h / G), rel=1e-12)
    for empty in ("theta0_deg", "flight_time_s", "hmax_normal_m"):
        assert math.isnan(row[empty]), empty
    # every rock starts alike (no seeder spread): the three first impacts agree
    np.testing.assert_allclose(first_rows(table)["vin_mps"], expected["vin_mps"])


def test_a_throw_across_the_slope_in_its_plane_of_incidence(cli, plane_site):
    """A rock thrown 4 m/s along the contour from 3 m up lands where the parabola
    meets the plane (closed form); its plane of incidence is not vertical, and
    the row gives it exactly: N the plane's normal, T along the tangential
    velocity, slope_deg = atan2(-t_z, n_z) (not the dip), section velocities on
    the plane's horizontal line X and steepest upward direction Z, speed and
    energy the 3-D ones, e_n and e_t the model's."""
    a = math.radians(AZIMUTH_DEG)
    along = 4.0
    vx, vy = -along * math.sin(a), along * math.cos(a)  # along the contour
    h = 3.0
    x0, y0 = 30.5, 30.5
    model = write_model3d(plane_site, {"height_m": h, "vx_mps": vx, "vy_mps": vy})
    out = plane_site / "out"
    result = cli("simulate", model, "--rocks", "1", "--seed", "2",
                 "--impacts", out / "impacts.parquet")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    row = first_rows(ImpactTable.read(out / "impacts.parquet")).iloc[0]
    # the contour keeps the ground's height: the drop time is that of free fall
    t = math.sqrt(2 * h / G)
    v = np.array([vx, vy, -G * t])
    n = unit_normal()
    vin = float(v @ n)
    tang = v - vin * n
    vit = float(np.linalg.norm(tang))
    tt = tang / vit
    z_up = n[2] * n + tt[2] * tt
    z_up /= np.linalg.norm(z_up)
    x_h = n[2] * tt - tt[2] * n
    x_h /= np.linalg.norm(x_h)
    assert x_h[2] == pytest.approx(0.0, abs=1e-15)  # X is horizontal
    psi = math.degrees(math.atan2(-tt[2], n[2]))
    assert psi < BETA_DEG - 5.0  # a cross-slope impact: not the dip
    expected = {
        "t_s": t, "x_m": x0 + vx * t, "y_m": y0 + vy * t,
        "z_m": float(ground(x0, y0)),
        "vin_mps": vin, "vit_mps": vit, "slope_deg": psi, "dip_deg": BETA_DEG,
        "vi_x_mps": float(v @ x_h), "vi_z_mps": float(v @ z_up),
        "vi_mps": float(np.linalg.norm(v)), "vfn_mps": -E_N * vin,
        "vft_mps": E_T * vit, "e_n": E_N, "e_t": E_T,
        "ke_i_j": 0.5 * MASS_KG * float(v @ v),
        "tangent_x": tt[0], "tangent_y": tt[1], "tangent_z": tt[2],
    }  # fmt: skip
    for name, value in expected.items():
        assert row[name] == pytest.approx(value, rel=1e-9, abs=1e-9), name
    # the rebound lies in the same plane: vfn N + vft T, of speed hypot(vfn, vft)
    assert row["vf_mps"] == pytest.approx(math.hypot(E_N * vin, E_T * vit), rel=1e-12)


def write_profile_model(site: Path) -> Path:
    """A 2-D model file with the same material, started away from the truth."""
    data = {
        "profile": {"x_m": [0, 20, 40], "z_m": [40, 28, 20],
                    "material": ["rock", "rock"]},
        "materials": {"rock": {"e_n": 0.6, "e_t": 0.9, "friction_deg": 30.0}},
        "body": {"mass_kg": MASS_KG, "radius_m": RADIUS_M, "gyration_m": 0.126},
        "seeder": {"x_m": 0.5, "z_m": 41.0, "vx_mps": 2.0, "vz_mps": 0.0},
    }  # fmt: skip
    path = site / "model2d.json"
    path.write_text(json.dumps(data))
    return path


def test_fit_on_the_3d_impacts_recovers_e_n_and_e_t(cli, plane_site):
    """Rocks thrown in every direction onto the plane (constant e_n, e_t, no
    roughness): `fieldkit fit` on the written table, started at 0.6 / 0.9,
    returns the model's 0.4 / 0.7 -- the table's vin, vit, vfn, vft are the
    kernel's in N/T axes, whatever the direction of travel."""
    model = write_model3d(plane_site, {
        "height_m": 2.0, "height_sd_m": 1.0, "vx_mps": 0.0, "vy_mps": 0.0,
        "vx_sd_mps": 3.0, "vy_sd_mps": 3.0})  # fmt: skip
    out = plane_site / "out"
    result = cli("simulate", model, "--rocks", "30", "--seed", "5",
                 "--impacts", out / "impacts.csv")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    table = ImpactTable.read(out / "impacts.csv")
    f = table.frame
    assert len(f) >= 40 and f["path_id"].nunique() == 30
    # directions of travel in plan cover more than a half turn
    heading = np.degrees(np.arctan2(f["tangent_y"], f["tangent_x"]))
    assert np.ptp(heading) > 180.0
    np.testing.assert_allclose(f["e_n"], E_N, rtol=1e-12)
    np.testing.assert_allclose(f["e_t"], E_T, rtol=1e-12)
    fitted = cli("fit", out / "impacts.csv", "--model",
                 write_profile_model(plane_site), "-o", out / "calibrated.json",
                 "--design-rocks", "200")  # fmt: skip
    assert fitted.exit_code == 0, fitted.stderr
    rock = json.loads((out / "calibrated.json").read_text())["materials"]["rock"]
    assert rock["e_n"] == pytest.approx(E_N, abs=1e-6)
    assert rock["e_t"] == pytest.approx(E_T, abs=1e-6)
    # diagnose reads it too: constant e_n, e_t explain every held-out rebound
    diagnosed = cli("diagnose", out / "impacts.csv", "--model",
                    plane_site / "model2d.json", "--json", out / "d.json")  # fmt: skip
    assert diagnosed.exit_code == 0, diagnosed.stderr
    report = json.loads((out / "d.json").read_text())
    assert report["baseline"]["cv_rmse_mps"] < 1e-9


def test_impacts_target_refused_before_the_run(cli, fails, plane_site):
    """An --impacts file of no table format: one line naming --impacts, before
    any simulation, nothing written."""
    model = write_model3d(plane_site, {"height_m": 1.0})
    out = plane_site / "out"
    fails(cli("simulate", model, "--rocks", "2", "--seed", "1",
              "--impacts", out / "impacts.txt", "--deposits", out / "d.csv"),
          "--impacts", ".csv or .parquet")  # fmt: skip
    assert not out.exists()


def test_xlsx_impacts_equal_the_csv(cli, plane_site):
    """The same run written as XLSX (whole) and CSV (streamed): same rows."""
    model = write_model3d(plane_site, {"height_m": 2.0, "vx_sd_mps": 2.0})
    out = plane_site / "out"
    for name in ("i.csv", "i.xlsx"):
        result = cli("simulate", model, "--rocks", "4", "--seed", "9",
                     "--impacts", out / name)  # fmt: skip
        assert result.exit_code == 0, result.stderr
    a = ImpactTable.read(out / "i.csv").frame
    b = ImpactTable.read(out / "i.xlsx").frame
    assert list(a.columns) == list(b.columns) and len(a) == len(b) > 4
    np.testing.assert_allclose(b["vin_mps"], a["vin_mps"], rtol=1e-12)
    assert (a["point"] == b["point"]).all()


def test_rows_carry_the_body_after_mass_loss(cli, plane_site):
    """With mass_loss each row's mass is the block's at that impact, eqs.
    6.15-6.16 with the plan distance from the release: m0 n^-p / (1 + d lambda),
    radius and gyration by the cube root; its energies use it."""
    model = write_model3d(plane_site, {"height_m": 3.0, "vx_mps": 2.0,
                                       "vy_mps": 1.0})  # fmt: skip
    data = json.loads(model.read_text())
    data["effects"] = {"mass_loss": {"rate_per_m": 0.02, "impact_exponent": 0.8}}
    model.write_text(json.dumps(data))
    out = plane_site / "out"
    result = cli("simulate", model, "--rocks", "1", "--seed", "4",
                 "--impacts", out / "impacts.csv")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    f = ImpactTable.read(out / "impacts.csv").frame
    assert len(f) >= 3
    n = f["point"].astype(int).to_numpy()
    d = np.hypot(f["x_m"] - 30.5, f["y_m"] - 30.5).to_numpy()
    ratio = n**-0.8 / (1.0 + 0.02 * d)
    np.testing.assert_allclose(f["mass_kg"], MASS_KG * ratio, rtol=1e-12)
    np.testing.assert_allclose(f["radius_m"], RADIUS_M * np.cbrt(ratio), rtol=1e-12)
    np.testing.assert_allclose(
        f["ke_i_j"], 0.5 * MASS_KG * ratio * f["vi_mps"] ** 2, rtol=1e-12
    )


def test_impact_rows_handed_chunk_by_chunk_equal_the_whole(plane_site):
    """simulate3d(on_impact_rows=...) in chunks of 2 rocks hands the same rows, in
    the same order, as one run keeping them; the tables built per chunk number
    each rock's impacts from 1 (chunks hold whole rocks)."""
    from fieldkit.model.model_file import read_model
    from fieldkit.model.results3d import impact_table3d
    from fieldkit.model.simulate3d import simulate3d

    path = write_model3d(plane_site, {"height_m": 2.0, "vx_sd_mps": 2.0,
                                      "vy_sd_mps": 2.0})  # fmt: skip
    model = read_model(path, terrain=True)
    whole = simulate3d(model, 7, np.random.default_rng(3), record_impacts=True)
    chunks: list = []
    part = simulate3d(model, 7, np.random.default_rng(3), record_impacts=True,
                      chunk_rocks=2, on_impact_rows=chunks.append)  # fmt: skip
    assert part.impact_rows is None and len(chunks) == 4
    for name, values in whole.impact_rows.items():
        np.testing.assert_array_equal(
            np.concatenate([c[name] for c in chunks]), values
        )
    one = impact_table3d(whole.impact_rows, ["rock"]).frame
    parts = [impact_table3d(c, ["rock"]).frame for c in chunks]
    assert list(one["point"]) == [p for f in parts for p in f["point"]]


def test_a_3d_table_with_an_impossible_y_refused_in_one_line(cli, fails, plane_site):
    """A 3-D table read back with y_m beyond any plan coordinate: one line naming
    the file, the row and the column; nothing written."""
    model = write_model3d(plane_site, {"height_m": 2.0})
    out = plane_site / "out"
    assert cli("simulate", model, "--rocks", "2", "--seed", "1",
               "--impacts", out / "i.csv").exit_code == 0  # fmt: skip
    table = ImpactTable.read(out / "i.csv").frame
    table.loc[1, "y_m"] = 3e7
    table.to_csv(plane_site / "bad.csv", index=False)
    fails(cli("fit", plane_site / "bad.csv", "--model",
              write_profile_model(plane_site), "-o", out / "cal.json"),
          "bad.csv", "row 2", "column y_m", "a plan coordinate")  # fmt: skip
    assert not (out / "cal.json").exists()


def test_impact_times_are_those_of_the_flights_between(cli, plane_site):
    """t_s (time since the release): between two impacts of a rock that flew
    (vfn above core.slide_vn_mps, 0.5 m/s), the contacts are joined by the
    parabola leaving the first with its 3-D rebound velocity vfn N + vft T over
    exactly t_s(next) - t_s."""
    model = write_model3d(plane_site, {"height_m": 2.0, "vx_sd_mps": 3.0,
                                       "vy_sd_mps": 3.0})  # fmt: skip
    out = plane_site / "out"
    result = cli("simulate", model, "--rocks", "10", "--seed", "8",
                 "--impacts", out / "impacts.csv")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    f = ImpactTable.read(out / "impacts.csv").frame
    same = (f["path_id"].to_numpy()[1:] == f["path_id"].to_numpy()[:-1])
    flew = same & (f["vfn_mps"].to_numpy()[:-1] > 0.5)
    assert flew.sum() >= 10
    assert (np.diff(f["t_s"].to_numpy())[same] > 0).all()
    dt = np.diff(f["t_s"].to_numpy())[flew]
    assert (dt > 0).all()
    vf = (f["vfn_mps"].to_numpy()[:, None] * f[["normal_x", "normal_y", "normal_z"]]
          .to_numpy() + f["vft_mps"].to_numpy()[:, None]
          * f[["tangent_x", "tangent_y", "tangent_z"]].to_numpy())[:-1][flew]
    start = f[["x_m", "y_m", "z_m"]].to_numpy()[:-1][flew]
    end = f[["x_m", "y_m", "z_m"]].to_numpy()[1:][flew]
    expected = start + vf * dt[:, None]
    expected[:, 2] -= 0.5 * G * dt**2
    np.testing.assert_allclose(end, expected, rtol=0, atol=1e-8)


def test_impact_time_after_a_slide_and_a_launch(cli, tmp_path):
    """A rock released at rest on a 20 deg slope (friction 10 deg) slides 15 m
    (plan) to a convex break onto 45 deg, launches there and lands: its first
    impact comes at t1 + t2 -- the slide, L = a t1^2 / 2 with a = g (sin 20 - tan
    10 cos 20), then the flight from the break at v1 = a t1 along the upper
    slope, t2 = 2 v1 (tan 45 cos 20 - sin 20) / g -- where that flight meets the
    lower slope."""
    b1, b2, phi = (math.radians(d) for d in (20.0, 45.0, 10.0))
    xb, x0, y0 = 20.5, 5.5, 4.5
    xc = np.arange(60) + 0.5
    z = np.where(xc <= xb, 100.0 - math.tan(b1) * xc,
                 100.0 - math.tan(b1) * xb - math.tan(b2) * (xc - xb))  # fmt: skip
    rows = "\n".join(" ".join(f"{v:.12f}" for v in z) for _ in range(10))
    (tmp_path / "break.asc").write_text(
        "ncols 60\nnrows 10\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
        f"NODATA_value -9999\n{rows}\n"
    )
    (tmp_path / "m.json").write_text(json.dumps({
        "terrain": {"dem": "break.asc", "materials": "rock", "releases": [[x0, y0]]},
        "materials": {"rock": {"e_n": E_N, "e_t": E_T,
                               "friction_deg": math.degrees(phi)}},
        "body": {"mass_kg": MASS_KG, "radius_m": RADIUS_M, "gyration_m": 0.126},
    }))  # fmt: skip
    out = tmp_path / "out"
    result = cli("simulate", tmp_path / "m.json", "--rocks", "1", "--seed", "1",
                 "--impacts", out / "impacts.csv")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    row = ImpactTable.read(out / "impacts.csv").frame.iloc[0]
    a = G * (math.sin(b1) - math.tan(phi) * math.cos(b1))
    t1 = math.sqrt(2 * (xb - x0) / math.cos(b1) / a)
    v1 = a * t1
    t2 = 2 * v1 * (math.tan(b2) * math.cos(b1) - math.sin(b1)) / G
    assert row["point"] == "1"
    assert row["t_s"] == pytest.approx(t1 + t2, rel=1e-7)
    assert row["x_m"] == pytest.approx(xb + v1 * math.cos(b1) * t2, rel=1e-7)
    assert row["dip_deg"] == pytest.approx(45.0, rel=1e-12)
    assert row["vi_mps"] == pytest.approx(
        math.hypot(v1 * math.cos(b1), v1 * math.sin(b1) + G * t2), rel=1e-7
    )


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".xlsx"])
def test_a_run_without_impacts_writes_the_header(cli, plane_site, suffix):
    """Rocks released on the ground of a 30 deg plane with a 40 deg friction
    angle never move, so never impact: the table is written with its columns and
    no row in every format (XLSX used to end in a traceback here)."""
    model = write_model3d(plane_site, {})
    data = json.loads(model.read_text())
    data["materials"]["rock"]["friction_deg"] = 40.0  # above the 30 deg dip
    model.write_text(json.dumps(data))
    target = plane_site / "out" / f"impacts{suffix}"
    result = cli("simulate", model, "--rocks", "2", "--seed", "1",
                 "--impacts", target)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "2 rocks, 0 impacts" in result.stdout
    assert f"wrote {target}" in result.stdout
    import pandas as pd

    read = {".csv": pd.read_csv, ".parquet": pd.read_parquet,
            ".xlsx": pd.read_excel}[suffix]  # fmt: skip
    frame = read(target)
    assert len(frame) == 0
    assert {"path_id", "vin_mps", "y_m", "normal_z", "t_s"} <= set(frame.columns)


def test_impact_after_a_tree_strike_in_flight(cli, tmp_path):
    """A rock thrown at 5 m/s from 3 m above a plane (dip atan 0.6 towards +x)
    strikes a 30 cm stem 2 m ahead where its centre is d/2 + r from the stem's
    axis (t = 0.33 s); the trunk takes E = c (100 d)^p (c 0.5, p 2.31), the
    direction is kept; its next impact -- flagged tree_strike -- comes where the
    slower parabola from the strike meets the plane, at t = 0.33 s + its flight."""
    xc = np.arange(40) + 0.5
    rows = "\n".join(" ".join(f"{v:.12f}" for v in 60.0 - 0.6 * xc)
                     for _ in range(20))  # fmt: skip
    (tmp_path / "t.asc").write_text(
        "ncols 40\nnrows 20\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
        f"NODATA_value -9999\n{rows}\n"
    )
    (tmp_path / "m.json").write_text(json.dumps({
        "terrain": {"dem": "t.asc", "materials": "rock", "releases": [[10.0, 10.0]]},
        "materials": {"rock": {"e_n": E_N, "e_t": E_T, "friction_deg": 30.0}},
        "body": {"mass_kg": MASS_KG, "radius_m": RADIUS_M, "gyration_m": 0.126},
        "seeder": {"height_m": 3.0, "vx_mps": 5.0},
        "effects": {"tree_impacts": {"energy_factor": 0.5}},
        "trees": {"x_m": [12.0], "y_m": [10.0], "diameter_m": [0.3],
                  "height_m": [20.0]},
    }))  # fmt: skip
    out = tmp_path / "out"
    result = cli("simulate", tmp_path / "m.json", "--rocks", "1", "--seed", "1",
                 "--impacts", out / "impacts.csv")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    row = ImpactTable.read(out / "impacts.csv").frame.iloc[0]
    ts = (12.0 - 0.15 - RADIUS_M - 10.0) / 5.0
    xs, zs = 10.0 + 5.0 * ts, 60.0 - 0.6 * 10.0 + 3.0 - 0.5 * G * ts**2
    v = np.array([5.0, -G * ts])
    energy = 0.5 * (100 * 0.3) ** 2.31
    v_after = v * math.sqrt(1.0 - 2.0 * energy / MASS_KG / (v @ v))
    # zs + vz tau - g tau^2 / 2 = 60 - 0.6 (xs + vx tau)
    qa, qb, qc = -0.5 * G, v_after[1] + 0.6 * v_after[0], zs - (60.0 - 0.6 * xs)
    tau = (-qb - math.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    assert bool(row["tree_strike"])
    assert row["t_s"] == pytest.approx(ts + tau, rel=1e-9)
    assert row["x_m"] == pytest.approx(xs + v_after[0] * tau, rel=1e-9)
    assert row["vi_mps"] == pytest.approx(
        math.hypot(v_after[0], v_after[1] - G * tau), rel=1e-9
    )
