"""`fieldkit impact`: worked example 4A on the command line, figure, JSON, bad input."""

from __future__ import annotations

import json
import math

import pytest

EXAMPLE_4A = (
    "impact", "--speed", "22", "--angle", "25", "--spin", "-15",
    "--shape", "sphere", "--dimensions", "0.75", "--law", "angle",
)  # fmt: skip


def run_json(cli, tmp_path, *args):
    out = tmp_path / "impact.json"
    result = cli(*args, "--json", out)
    assert result.exit_code == 0, result.stderr
    return result, json.loads(out.read_text())


def test_worked_example_4a_from_the_command_line(cli, tmp_path):
    # Thesis §4.6.3: v_fT 17.5, v_fN 6.6 m/s, omega_f -23.3 rad/s, theta_f 20.7 deg.
    result, data = run_json(cli, tmp_path, *EXAMPLE_4A)
    res = data["results"]
    assert res["v_ft_mps"] == pytest.approx(17.5, abs=0.05)
    assert res["v_fn_mps"] == pytest.approx(6.6, abs=0.05)
    assert res["omega_f_radps"] == pytest.approx(-23.3, abs=0.05)
    assert res["theta_f_deg"] == pytest.approx(20.7, abs=0.05)
    assert data["inputs"]["e_n"] == pytest.approx(0.71, abs=0.005)  # eq. 5.4
    # the printed table shows the same numbers
    table = result.stdout
    assert "17.46" in table and "6.58" in table and "-23.28" in table
    assert "20.67" in table


def test_worked_example_4a_without_spin(cli, tmp_path):
    # Thesis: omega_i = 0 -> v_fT 14.2, omega_f -19, theta_f 24.8 deg.
    args = list(EXAMPLE_4A)
    args[args.index("--spin") + 1] = "0"
    _, data = run_json(cli, tmp_path, *args)
    res = data["results"]
    assert res["v_ft_mps"] == pytest.approx(14.2, abs=0.05)
    assert res["omega_f_radps"] == pytest.approx(-19, abs=0.5)
    assert res["theta_f_deg"] == pytest.approx(24.8, abs=0.05)


def test_components_and_explicit_body(cli, tmp_path):
    # Same impact from components, explicit r, k, e_N and a mass: energies printed.
    _, data = run_json(
        cli, tmp_path, "impact", "--vt", "19.939", "--vn", "-9.298", "--spin", "-15",
        "--radius", "0.75", "--gyration", str(0.75 * math.sqrt(0.4)), "--en", "0.708",
        "--mass", "1000",
    )  # fmt: skip
    res = data["results"]
    assert res["v_ft_mps"] == pytest.approx(17.46, abs=0.01)
    ke_i = 0.5 * 1000 * (19.939**2 + 9.298**2)
    assert res["ke_i_j"] == pytest.approx(ke_i)
    assert res["energy_change_j"] < 0
    assert data["minimum_friction_to_stop_slip"] == pytest.approx(0.156, abs=0.001)


def test_without_mass_no_energies(cli, tmp_path):
    result, data = run_json(
        cli, tmp_path, "impact", "--speed", "15", "--angle", "40", "--radius", "0.3",
        "--gyration", "0.245", "--en", "0.4", "--friction", "0.3",
    )  # fmt: skip
    assert data["results"]["ke_i_j"] is None
    assert data["impulse_unit"] == "N s/kg"
    # per unit mass, p_c = -v_iN for a collinear impact (eq. 4.4)
    assert data["results"]["p_c"] == pytest.approx(15 * math.sin(math.radians(40)))
    assert "mass not given" in result.stdout


def test_velocity_law(cli, tmp_path):
    _, data = run_json(
        cli, tmp_path, "impact", "--vt", "5", "--vn", "-9.144", "--radius", "0.3",
        "--gyration", "0.2", "--law", "velocity", "--en", "0.8",
    )  # fmt: skip
    assert data["inputs"]["e_n"] == pytest.approx(0.4)  # eq. 7.1 factor 0.5 at K


def test_boulder_a_shape(cli, tmp_path):
    # Table 4-1 example: ellipsoid 1.6 x 1.3 x 1.3 m -> k 0.46 m, 1.42 m^3, ~3750 kg
    _, data = run_json(
        cli, tmp_path, "impact", "--speed", "11.7", "--angle", "22", "--en", "1.3",
        "--shape", "ellipsoid", "--dimensions", "1.6,1.3,1.3",
    )  # fmt: skip
    body = data["body"]
    assert body["gyration_m"] == pytest.approx(0.46, abs=0.005)
    assert body["volume_m3"] == pytest.approx(1.42, abs=0.005)
    assert body["mass_kg"] == pytest.approx(3750, rel=0.01)
    assert body["radius_m"] == pytest.approx(0.725)


def test_figure(cli, tmp_path):
    png = tmp_path / "pnv.png"
    result = cli(*EXAMPLE_4A, "--friction", "0.5", "--figure", png)
    assert result.exit_code == 0, result.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert png.stat().st_size > 20_000


def test_help_has_runnable_example(cli):
    result = cli("impact", "--help")
    assert result.exit_code == 0
    assert "--speed 22 --angle 25 --spin -15" in result.stdout
    assert "--law angle" in result.stdout


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("--mass", "-3"), "error: --mass must be > 0 (got -3)"),
        (("--radius", "-1"), "error: --radius must be > 0 (got -1)"),
        (("--radius", "0.9"), "error: --radius must be between 0.75 and 0.75 m"),
        (("--angle", "200"), "error: --angle must be between 0 and 180"),
        (("--angle", "0"), "error: --angle must be between 0 and 180"),
        (("--speed", "-4"), "error: --speed must be > 0 (got -4)"),
        (("--friction", "-0.2"), "error: --friction must be >= 0"),
        (("--dimensions", "-0.75"), "error: --dimensions must be > 0 (got -0.75)"),
        (("--dimensions", "a,b"), "error: --dimensions must be numbers"),
        (("--shape", "blob"), "error: --shape must be one of cube, sphere"),
        (("--law", "magic"), "error: --law must be one of constant, angle, velocity"),
        (("--en", "0.5"), "error: --en is not used with --law angle"),
        (("--a", "-1"), "error: --a must be > 0"),
        (("--unit-weight", "0"), "error: --unit-weight must be > 0"),
    ],
)
def test_bad_input_one_line_error(cli, tmp_path, change, message):
    args = list(EXAMPLE_4A)
    option, value = change
    if option in args:
        args[args.index(option) + 1] = value
    else:
        args += [option, value]
    png, out = tmp_path / "f.png", tmp_path / "o.json"
    result = cli(*args, "--figure", png, "--json", out)
    assert result.exit_code != 0
    assert result.stderr.startswith(message), result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert not png.exists() and not out.exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--vt", "10", "--vn", "-5", "--radius", "0.5", "--gyration", "0.6",
          "--en", "0.5"), "error: --gyration must be <= --radius"),
        (("--vt", "10", "--vn", "-5", "--radius", "0.5", "--gyration", "0.3",
          "--en", "-0.5"), "error: --en must be >= 0 (got -0.5)"),
        (("--vt", "10", "--vn", "3", "--radius", "0.5", "--gyration", "0.3",
          "--en", "0.5"), "error: --vn must be < 0"),
        (("--vt", "-5", "--vn", "-3", "--radius", "0.5", "--gyration", "0.3",
          "--law", "angle"), "error: the impact angle (--angle, or atan(-vn/vt)) must"),
        (("--vt", "10", "--vn", "-5", "--radius", "0.5", "--gyration", "0.3"),
         "error: give --en"),
        (("--vt", "10", "--vn", "-5", "--en", "0.5"),
         "error: fieldkit impact: body needs --radius and --gyration (or --shape)"),
        (("--speed", "10", "--angle", "30", "--vt", "3", "--radius", "0.5",
          "--gyration", "0.3", "--en", "0.5"), "error: give --speed and --angle, or"),
        (("--vt", "10", "--vn", "-5", "--radius", "0.5", "--gyration", "0.3",
          "--en", "0.5", "--offset", "0.2"), "error: --friction must be finite"),
        (("--speed", "10", "--angle", "30", "--shape", "sphere", "--dimensions",
          "0.5", "--gyration", "0.3", "--en", "0.5"), "error: --gyration is computed"),
        (("--vt", "10", "--vn", "-5", "--radius", "0.5", "--gyration", "0.3",
          "--en", "0.5", "--mass", "nan"), "error: --mass must be a finite number"),
    ],
)  # fmt: skip
def test_bad_combinations(cli, args, message):
    result = cli("impact", *args)
    assert result.exit_code != 0
    assert result.stderr.startswith(message), result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_energy_gain_is_flagged(cli):
    # eq. 5.4 gives e_N = 1.82 at 10 deg; with a smooth contact the collinear model
    # then returns more energy than came in: the command warns (and still answers).
    result = cli(
        "impact", "--speed", "10", "--angle", "10", "--radius", "0.5",
        "--gyration", "0.3", "--law", "angle", "--friction", "0",
    )  # fmt: skip
    assert result.exit_code == 0
    assert result.stderr.startswith("warning: the rock leaves with more energy")
    quiet = cli(*EXAMPLE_4A)
    assert quiet.exit_code == 0 and quiet.stderr == ""
