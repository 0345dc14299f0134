"""`fieldkit simulate` and `fieldkit effects` against the simulator core.

They need fieldkit.model.simulate and the effects registry (built in parallel): they
skip until both are in the tree. `--measured` parsing needs neither.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fieldkit.cli.simulate import parse_measured
from fieldkit.errors import ArgumentError

MODEL = Path(__file__).resolve().parents[1] / "model" / "data" / "smoke.json"


def test_measured_values_parse_and_refuse_bad_keys():
    m = parse_measured("x=610, speed=18,ke=600e3,height=1.5")
    assert (m.x_m, m.speed_mps, m.ke_j, m.height_m) == (610, 18, 600e3, 1.5)
    with pytest.raises(ArgumentError, match="key one of x, speed, ke, height"):
        parse_measured("x=610,v=18")
    with pytest.raises(ArgumentError, match="lacks x="):
        parse_measured("speed=18")
    with pytest.raises(ArgumentError, match="finite"):
        parse_measured("x=nan")


@pytest.fixture()
def core():
    pytest.importorskip("fieldkit.model.simulate")
    pytest.importorskip("fieldkit.model.effects.registry")
    if not MODEL.exists():
        pytest.skip("no smoke model yet")


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_simulate_writes_summary_impacts_figures_and_recording(
    core, cli, tmp_path, suffix
):
    from fieldkit.impact_table import ImpactTable

    out = tmp_path / "out"
    r = cli(
        "simulate",
        MODEL,
        "--rocks",
        "60",
        "--seed",
        "3",
        "--at",
        "40",
        "--impacts",
        out / f"impacts{suffix}",
        "--summary",
        out / "s.json",
        "--figures",
        out / "fig",
        "--rrd",
        out / "sim.rrd",
        "--trajectories",
        "5",
        "--measured",
        "x=40,speed=10,ke=1e5",
    )
    assert r.exit_code == 0, r.stderr
    s = json.loads((out / "s.json").read_text())
    assert s["rocks"] == 60 and s["seed"] == 3
    table = ImpactTable.read(out / f"impacts{suffix}")
    assert len(table) == s["impacts"]
    assert set(table.frame["path_id"].astype(int)) <= set(range(60))
    assert (out / "fig" / "trajectories.png").exists() and (out / "sim.rrd").exists()
    assert "runout x (m)" in r.stdout and "±" in r.stdout
    # the same seed reproduces the summary exactly (but for the wall time)
    r2 = cli(
        "simulate",
        MODEL,
        "--rocks",
        "60",
        "--seed",
        "3",
        "--at",
        "40",
        "--summary",
        out / "s2.json",
    )
    s2 = json.loads((out / "s2.json").read_text())
    s.pop("wall_s"), s2.pop("wall_s")
    assert r2.exit_code == 0 and s == s2


def test_simulate_refuses_bad_options_without_writing(core, cli, tmp_path, fails):
    fails(cli("simulate", MODEL, "--rocks", "0"), "--rocks")
    fails(cli("simulate", MODEL, "--impacts", tmp_path / "x.txt"), "--impacts")
    fails(cli("simulate", MODEL, "--measured", "speed=3"), "--measured")
    assert list(tmp_path.iterdir()) == []


def test_effects_lists_and_describes(core, cli, fails):
    from fieldkit.model.effects.registry import EFFECTS

    r = cli("effects")
    assert r.exit_code == 0
    for spec in EFFECTS:
        assert spec.name in r.stdout
    one = cli("effects", EFFECTS[0].name)
    assert one.exit_code == 0 and EFFECTS[0].parameters[0].name in one.stdout
    fails(cli("effects", "no_such_effect"), "unknown effect", EFFECTS[0].name)
