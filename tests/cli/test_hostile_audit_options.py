"""Hostile command options from the independent audit of issue 17 (third set).

Each case ran and exited 0 with a wrong or silently chosen result: a measured
value outside physics (sim29, sim71-sim73), a key or an effect parameter given
twice (sim74, ro05), a fence rebound with more energy than the impact (fen02), a
fit calibrated from one impact (fit16).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

SMOKE = Path(__file__).resolve().parents[1] / "model" / "data" / "smoke.json"


@pytest.fixture()
def smoke_copy(tmp_path) -> Path:
    """The smoke model copied into a folder of its own (outputs land beside it)."""
    path = tmp_path / "model.json"
    path.write_bytes(SMOKE.read_bytes())
    return path


# ------------------------------------------------------- simulate --measured


@pytest.mark.parametrize(
    ("measured", "words"),
    [
        ("x=40,speed=-5", ("speed=-5", "from 0 to 100 m/s")),  # sim29
        ("x=40,speed=1e300", ("speed=1e300", "from 0 to 100 m/s")),  # sim71
        ("x=40,ke=-1", ("ke=-1", "from 0 to 5e+10 J")),  # sim72
        ("x=40,ke=6e10", ("ke=6e10", "from 0 to 5e+10 J")),
        ("x=40,height=-3", ("height=-3", "from 0 to 509.7 m")),  # sim73
        ("x=40,height=600", ("height=600", "from 0 to 509.7 m")),
        ("x=40,speed=5,speed=30", ("speed given twice", "speed=5", "speed=30")),
        ("x=40,x=50,speed=5", ("x given twice",)),  # sim74 and its like
    ],
)
def test_simulate_refuses_an_impossible_or_repeated_measured_value(
    cli, fails, digest, smoke_copy, measured, words
):
    before = digest(smoke_copy)
    summary = smoke_copy.parent / "s.json"
    r = cli(
        "simulate", smoke_copy, "--rocks", "5", "--seed", "1", "--at", "40",
        "--measured", measured, "--summary", summary,
    )  # fmt: skip
    fails(r, "--measured", *words)
    assert r.exit_code == 1
    assert not summary.exists() and digest(smoke_copy) == before


def test_simulate_takes_measured_values_at_their_bounds(cli, smoke_copy):
    """Zero and the bounds themselves are physical: ranked, not refused."""
    summary = smoke_copy.parent / "s.json"
    r = cli(
        "simulate", smoke_copy, "--rocks", "20", "--seed", "1", "--at", "40",
        "--measured", "x=40,speed=0,ke=0", "--measured", "x=40,speed=100,ke=5e10",
        "--summary", summary,
    )  # fmt: skip
    assert r.exit_code == 0, r.stderr
    low, high = json.loads(summary.read_text())["measured"]
    assert low["speed_mps"]["measured"] == 0.0
    assert high["speed_mps"]["measured"] == 100.0
    assert high["ke_j"]["measured"] == 5e10


# ---------------------------------------------------------- synth --effects


def test_synth_refuses_an_effect_parameter_given_twice(cli, fails, smoke_copy):
    out = smoke_copy.parent / "o.csv"
    for effects in (
        ["--effects", "air_drag=cd=0.5", "--effects", "air_drag=cd=0.9"],  # ro05
        ["--effects", "air_drag=cd=0.5,cd=0.9"],
    ):
        r = cli("synth", smoke_copy, "--paths", "2", "--seed", "1", "-o", out, *effects)
        fails(r, "--effects", "air_drag", "cd given twice", "cd=0.5", "cd=0.9")
        assert r.exit_code == 1 and not out.exists()


def test_synth_prints_every_effect_parameter_it_used(cli, smoke_copy):
    out = smoke_copy.parent / "o.csv"
    r = cli(
        "synth", smoke_copy, "--paths", "2", "--seed", "1", "-o", out,
        "--effects", "air_drag=cd=0.5", "--effects", "air_drag=air_density_kg_m3=1.1",
    )  # fmt: skip
    assert r.exit_code == 0, r.stderr
    # the two values of one effect are merged; the defaults it used are printed too
    assert "air_drag (cd 0.5, air_density_kg_m3 1.1)" in r.stdout
    assert "angle_dependent_restitution (b 1.03, theta_ref_deg 30, a 0)" in r.stdout
    assert f"wrote {out}" in r.stdout


# --------------------------------------------------------------------- fence


@pytest.mark.parametrize(
    ("rebound", "words"),
    [
        # fen02: printed "absorbed by the fence: -208.00 kJ (-800.0%)"
        (
            ["--speed-out", "30"],
            ("--speed-out 30 m/s", "--spin-out 0 rad/s", "E_f = 234.00 kJ",
             "E_i = 26.00 kJ", "passive", "eq. 8.1"),
        ),
        (
            ["--speed-out", "10", "--spin-out", "50"],
            ("--spin-out 50 rad/s", "E_f = 105.62 kJ", "E_i = 26.00 kJ"),
        ),
    ],
)  # fmt: skip
def test_fence_refuses_a_measured_rebound_with_more_energy(
    cli, fails, tmp_path, rebound, words
):
    figure = tmp_path / "fence.png"
    r = cli(
        "fence", "--mass", "520", "--gyration", "0.35", "--speed-in", "10",
        *rebound, "--figure", figure,
    )  # fmt: skip
    fails(r, "--speed-out", *words)
    assert r.exit_code == 1 and not figure.exists()
    assert "absorbed" not in r.stdout


@pytest.mark.parametrize(
    ("options", "words"),
    [
        (["--e-n", "1.5", "--angle-in", "40"], ("--e-n 1.5 at 40 deg", "1.28 times")),
        # eq. 5.4 at 5 deg gives e_N 3.72 (a spin against the slip adds the rest)
        (
            ["--angle-in", "5", "--spin-in=-30"],
            ("e_N 3.72 (eq. 5.4; no --e-n given) at 5 deg", "1.03 times"),
        ),
    ],
)
def test_fence_refuses_a_computed_rebound_with_more_energy(cli, fails, options, words):
    r = cli(
        "fence", "--mass", "520", "--gyration", "0.35", "--radius", "0.43",
        "--speed-in", "10", *options,
    )  # fmt: skip
    fails(r, "--e-n", "passive", "at most 1", *words)
    assert r.exit_code == 1


def test_fence_keeps_a_rebound_with_all_the_energy(cli):
    """Efficiency 100 % (nothing absorbed) is the limit, not beyond it."""
    r = cli(
        "fence", "--mass", "520", "--gyration", "0.35", "--speed-in", "10",
        "--speed-out", "10",
    )  # fmt: skip
    assert r.exit_code == 0, r.stderr
    assert "absorbed by the fence: 0.00 kJ (0.0% of the impact energy)" in r.stdout
    assert "energy efficiency E_f/E_i (eq. 8.1): 100.0%" in r.stdout


# ----------------------------------------------------------------------- fit

ASPHALT = SMOKE.parents[3] / "surveys" / "asphalt" / "model_rocfall_table_7_1.json"


@pytest.fixture(scope="module")
def asphalt_synth(tmp_path_factory) -> Path:
    """`synth` of the asphalt Table 7-1 model, 4 rocks: 37 impacts (19 asphalt,
    14 rock, 4 colluvium), spins and their SDs included."""
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("fit") / "syn.csv"
    r = CliRunner().invoke(
        app, ["synth", str(ASPHALT), "--paths", "4", "--seed", "1", "-o", str(out)]
    )
    assert r.exit_code == 0, r.stderr
    return out


def _rows(source: Path, target: Path, keep) -> Path:
    import pandas as pd

    frame = pd.read_csv(source)
    frame[keep(frame)].to_csv(target, index=False)
    return target


def test_fit_refuses_one_impact(cli, fails, digest, tmp_path, asphalt_synth):
    """fit16: one impact gave 'e_n 0.771 ± 0.057' from 1 residual degree of freedom."""
    one = _rows(asphalt_synth, tmp_path / "one.csv", lambda f: f.index < 1)
    before = digest(one)
    out = tmp_path / "c.json"
    r = cli("fit", one, "--model", ASPHALT, "-o", out, "--report", tmp_path / "rep")
    fails(
        r, "one.csv", "too few impacts for standard errors",
        "material rock has 1 impact (at least 2 per fitted material)",
        "3 data for 2 parameters leave 1 residual degree of freedom (at least 3)",
    )  # fmt: skip
    assert r.exit_code == 1
    assert not out.exists() and not (tmp_path / "rep").exists()
    assert digest(one) == before


def test_fit_refuses_a_material_with_one_impact(cli, fails, tmp_path, asphalt_synth):
    """34 impacts leave dof to spare, but colluvium's e_n, e_t rest on one."""
    few = _rows(
        asphalt_synth,
        tmp_path / "few.csv",
        lambda f: (f["material"] != "colluvium")
        | f.index.isin(f.index[f["material"] == "colluvium"][:1]),
    )  # fmt: skip
    out = tmp_path / "c.json"
    r = cli("fit", few, "--model", ASPHALT, "-o", out)
    fails(r, "few.csv", "material colluvium has 1 impact", "at least 2 per fitted")
    assert "degree" not in r.stderr and not out.exists()


def test_fit_refuses_too_few_residual_degrees_of_freedom(
    cli, fails, tmp_path, asphalt_synth
):
    """Two rock impacts without spin SDs: 4 data for rock's e_n, e_t."""
    import pandas as pd

    frame = pd.read_csv(asphalt_synth)
    frame = frame[frame["material"] == "rock"].head(2)
    frame.drop(columns=["omega_f_sd_radps"]).to_csv(tmp_path / "two.csv", index=False)
    r = cli("fit", tmp_path / "two.csv", "--model", ASPHALT, "-o", tmp_path / "c.json")
    fails(
        r, "two.csv",
        "4 data for 2 parameters leave 2 residual degrees of freedom (at least 3)",
    )  # fmt: skip
    assert "material rock" not in r.stderr and not (tmp_path / "c.json").exists()


def test_fit_takes_two_impacts_per_material(cli, tmp_path, asphalt_synth):
    """The bound itself: two colluvium impacts (the synthetic table has four)."""
    two = _rows(
        asphalt_synth,
        tmp_path / "two.csv",
        lambda f: (f["material"] != "colluvium")
        | f.index.isin(f.index[f["material"] == "colluvium"][:2]),
    )  # fmt: skip
    out = tmp_path / "c.json"
    r = cli("fit", two, "--model", ASPHALT, "-o", out)
    assert r.exit_code == 0, r.stderr
    assert json.loads(out.read_text())["provenance"]["fit"]
    assert f"wrote {out}" in r.stdout


def test_fit_help_states_the_minimum(cli):
    text = " ".join(cli("fit", "--help").stdout.split())
    assert "at least 2 impacts per fitted material and 3 residual degrees" in text
