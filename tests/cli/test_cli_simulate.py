"""`fieldkit simulate` and `fieldkit effects` against the simulator core.

They need fieldkit.model.simulate and the effects registry (built in parallel): they
skip until both are in the tree. `--measured` parsing needs neither.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fieldkit.cli.simulate import parse_measured
from fieldkit.errors import ArgumentError

MODEL = Path(__file__).resolve().parents[1] / "model" / "data" / "smoke.json"


def test_measured_values_parse_and_refuse_bad_keys():
    m = parse_measured("x=610, speed=18,ke=600e3,height=1.5")
    assert (m.x_m, m.speed_mps, m.ke_j, m.height_m) == (610, 18, 600e3, 1.5)
    with pytest.raises(ArgumentError, match="key one of x, speed, ke, total, height"):
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
        "--measured",
        "x=40,speed=10,ke=1e5",
        "--envelope-dx",
        "0.5",  # the default --figures used and stated for this 90 m profile
    )
    s2 = json.loads((out / "s2.json").read_text())
    for key in ("wall_s", "compile_s"):  # timings: the first run may compile
        s.pop(key, None), s2.pop(key, None)
    assert r2.exit_code == 0 and s == s2
    assert "--envelope-dx not given" in r.stderr and "0.5 m bins" in r.stderr


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


def test_effects_says_impact_table_export_and_held_from_the_metadata(core, cli):
    """``fieldkit effects NAME`` prints what the consumers read (issue 21): whether
    an ImpactTable informs it, how CRSP and RocFall take it, which parameters an
    impact fit holds."""
    r = cli("effects", "angle_dependent_restitution")
    assert r.exit_code == 0
    out = r.stdout
    assert "from an ImpactTable: yes" in out
    assert "export to CRSP: not mapped: CRSP's Rn depends on the impact velocity" in out
    assert "export to RocFall: not mapped: RocFall's lumped-mass Rn" in out
    assert out.count("held by an impact fit: ") == 2  # theta_ref_deg and a
    r = cli("effects", "velocity_scaled_restitution")
    assert "export to CRSP: mapped: CRSP's own scaling of Rn (K = 30 ft/s)" in r.stdout
    assert "held by an impact fit" not in r.stdout
    r = cli("effects", "air_drag")
    assert "from an ImpactTable: no: acts in flight" in r.stdout
    r = cli("effects", "affine_rebound")
    assert "export to RocFall: not mapped: affine_rebound is not a physical law" in (
        r.stdout
    )


# ---------------------------------------------------------------- issue 17 items

#: RocFall's Table 7-1 colluvium (e_n 1.0 +- 0.04, e_t 0.62) on a 45 deg slope that
#: runs out onto level ground: the case where rocks bounced in place until the cap.
POGO = {
    "profile": {"x_m": [0, 30, 130], "z_m": [30, 0, 0], "material": "colluvium"},
    "materials": {
        "colluvium": {
            "e_n": 1.0,
            "e_t": 0.62,
            "friction_deg": 20,
            "e_n_sd": 0.04,
            "e_t_sd": 0.04,
        }
    },
    "body": {"mass_kg": 3750, "radius_m": 0.725, "gyration_m": 0.46},
    "seeder": {"x_m": 1, "z_m": 32, "vx_mps": 3.0},
}


def _model(tmp_path, data=POGO, **core) -> Path:
    model = dict(data, core=core) if core else data
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model))
    return path


def test_rocks_with_e_n_near_one_stop_instead_of_bouncing_in_place(core, cli, tmp_path):
    """e_n drawn around 1 let the normal speed random-walk up at every impact: on
    level ground the rocks bounced in place (up to 20 m high) until the 500-impact
    cap -- all 200 here before the fix. An impact now gains no energy, so they
    stop on the flat."""
    model = _model(tmp_path)
    r = cli("simulate", model, "--rocks", "200", "--seed", "5", "--summary",
            tmp_path / "s.json")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    assert s["final_state"]["capped"] == 0
    assert s["final_state"]["stopped"] == 200
    assert 30.0 < s["runout_x_m"]["p50"] < 130.0  # on the level run-out
    assert "warning" not in r.stderr


def test_capped_rocks_are_their_own_state_with_a_warning(core, cli, tmp_path):
    model = _model(tmp_path, max_impacts=3)  # most rocks need more than 3 impacts
    r = cli("simulate", model, "--rocks", "200", "--seed", "5", "--summary",
            tmp_path / "s.json", "--figures", tmp_path / "figs")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    capped = s["final_state"]["capped"]
    assert capped > 100
    assert s["capped"]["rocks"] == capped and s["capped"]["max_impacts"] == 3
    assert s["capped"]["fraction"] == pytest.approx(capped / 200)
    # never counted as stopped or as run out
    assert s["final_state"]["stopped"] + s["final_state"]["exited_downslope"] == (
        200 - capped
    )
    assert s["stopped_fraction"] == pytest.approx(s["final_state"]["stopped"] / 200)
    assert s["runout_x_m"]["n"] == 200 - capped
    assert "left out" in s["runout_over"]
    bounds = s["runout_bounds_x_m"]
    assert bounds["lower"]["p50"] <= bounds["upper"]["p50"]
    assert bounds["upper"]["max"] == 130.0
    # one warning line: the fraction, what it means, how to raise the cap
    warning = [line for line in r.stderr.splitlines() if line.startswith("warning:")]
    assert len(warning) == 1
    assert f"({capped} of 200)" in warning[0] and "max_impacts" in warning[0]
    assert "left out of the runout statistics" in warning[0]
    assert f"{capped} capped left out" in r.stdout


def test_compiling_is_announced_and_timed_apart(core, cli, tmp_path, monkeypatch):
    """When the kernel is not cached the command says so and reports the compile
    apart from the simulation (here the compile is a stand-in taking 0.2 s)."""
    import sys
    import time

    import fieldkit.model.kernel as kernel

    simulation = sys.modules["fieldkit.model.simulate"]  # the module, not the function

    def slow_warm() -> float:
        time.sleep(0.2)
        return 0.2

    simulation.warm_kernel()  # the real kernel, loaded before the stand-in
    monkeypatch.setattr(kernel, "kernel_ready", lambda: False)
    monkeypatch.setattr(simulation, "warm_kernel", slow_warm)
    r = cli("simulate", MODEL, "--rocks", "20", "--seed", "1", "--summary",
            tmp_path / "s.json")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    assert "compiling the simulator, first run only" in r.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    assert s["compile_s"] == 0.2 and s["wall_s"] < 0.2
    assert "compiling the simulator took 0.20 s (first run only)" in r.stdout


def test_cached_kernel_is_not_announced(core, cli, tmp_path):
    import fieldkit.model.kernel as kernel
    from fieldkit.model.simulate import warm_kernel

    warm_kernel()
    assert kernel.kernel_ready() and kernel.kernel_loaded()
    r = cli("simulate", MODEL, "--rocks", "20", "--seed", "1", "--summary",
            tmp_path / "s.json")  # fmt: skip
    assert r.exit_code == 0 and "compiling" not in r.stderr + r.stdout
    assert json.loads((tmp_path / "s.json").read_text())["compile_s"] == 0.0


@pytest.mark.slow
def test_a_fresh_copy_compiles_once_then_loads_from_its_cache(tmp_path, repo):
    """numba caches by source path: a fresh clone compiles on its first run (or at
    install, make's warm-up) and every later run loads the cache."""
    import shutil
    import subprocess
    import sys

    shutil.copytree(repo / "fieldkit", tmp_path / "fieldkit",
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    env = {"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)}

    def run():
        return subprocess.run(
            [sys.executable, "-m", "fieldkit", "simulate", str(MODEL), "--rocks",
             "50", "--seed", "1", "--summary", str(tmp_path / "s.json")],
            capture_output=True, text=True, env=env, cwd=tmp_path, check=True,
        )  # fmt: skip

    first = run()
    assert "compiling the simulator, first run only" in first.stderr
    assert json.loads((tmp_path / "s.json").read_text())["compile_s"] > 1.0
    second = run()
    assert "compiling" not in second.stderr + second.stdout
    assert json.loads((tmp_path / "s.json").read_text())["compile_s"] == 0.0


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--at", "900"], ["--at", "900 m lies outside the profile", "0 to 90 m"]),
        (["--at", "nan"], ["--at must be a finite number (got nan)"]),
        (["--at", "-inf"], ["--at must be a finite number (got -inf)"]),
        (["--seed", "-1"], ["--seed", "from 0"]),
        (["--seed", str(2**64)], ["--seed", "2**64 - 1"]),
        (["--rocks", "1000000000"], ["--rocks", "10,000,000"]),
        (["--trajectories", "100000"], ["--trajectories", "1,000"]),
        (["--envelope-dx", "1e-9"], ["--envelope-dx", "at most 100,000", "0.0009 m"]),
        (["--envelope-dx", "inf"], ["--envelope-dx", "finite"]),
        (["--envelope-dx", "nan"], ["--envelope-dx", "finite"]),
        ([a for _ in range(101) for a in ("--at", "5")], ["--at", "at most 100"]),
        (
            ["--rocks", "9000000", "--at", "5", "--at", "6", "--envelope-dx", "0.01"],
            ["--rocks", "GiB", "at most"],
        ),
        (["--at", "40", "--measured", "x=50,speed=3"], ["--measured", "--at 50"]),
    ],
)
def test_hostile_options_are_one_line_refusals(core, cli, fails, tmp_path, args, words):
    out = tmp_path / "out"
    r = cli("simulate", MODEL, "--summary", out / "s.json", "--figures", out / "f",
            *args)  # fmt: skip
    fails(r, *words)
    assert not out.exists()


def test_impacts_to_dev_null_and_every_written_file_is_reported(core, cli, tmp_path):
    r = cli("simulate", MODEL, "--rocks", "20", "--seed", "2", "--impacts",
            "/dev/null", "--summary", tmp_path / "s.json", "--figures",
            tmp_path / "f", "--at", "40")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    wrote = [line[6:] for line in r.stdout.splitlines() if line.startswith("wrote ")]
    expected = {"/dev/null", str(tmp_path / "s.json")} | {
        str(tmp_path / "f" / name)
        for name in ("trajectories.png", "envelope.png", "runout.png",
                     "point_1_x40.png")
    }  # fmt: skip
    assert set(wrote) == expected and len(wrote) == len(expected)
    assert "simulating 20 rocks" in r.stderr  # the step is named off a terminal


def test_figures_get_a_stated_envelope_and_measured_percentiles(core, cli, tmp_path):
    import numpy as np

    from fieldkit.model.model_file import read_model
    from fieldkit.model.simulate import simulate

    r = cli("simulate", MODEL, "--rocks", "60", "--seed", "3", "--at", "40",
            "--measured", "x=40,speed=17,ke=72e3", "--summary", tmp_path / "s.json",
            "--figures", tmp_path / "f")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    # envelope.png is not empty: a stated default bin width (90 m / 200 -> 0.5 m)
    assert "0.5 m bins" in r.stderr
    assert len(s["envelope"]["x_m"]) == 180 and s["envelope"]["reached"][0] == 60
    assert s["envelope"]["bin_width_m"] == 0.5
    # each measured value's percentile among the rocks crossing x = 40 m
    point = simulate(read_model(MODEL), 60, np.random.default_rng(3),
                     analysis_x_m=[40.0]).analysis[0]  # fmt: skip
    speeds = point.speed_mps[point.crossed]
    ke = point.ke_j[point.crossed]  # translational, as measured
    m = s["measured"][0]
    assert m["x_m"] == 40.0
    assert m["speed_mps"]["percentile"] == pytest.approx(
        100 * ((speeds < 17).sum() + 0.5 * (speeds == 17).sum()) / speeds.size
    )
    assert m["ke_j"]["percentile"] == pytest.approx(100 * (ke < 72e3).sum() / ke.size)
    assert 0 < m["ke_j"]["percentile"] < 100 and m["ke_j"]["beyond"] is None
    assert m["speed_mps"]["n"] == speeds.size
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("measured at"))
    assert f"percentile {m['speed_mps']['percentile']:.1f}" in line
    assert "translational KE 72 kJ" in line


def test_runout_beyond_the_profile_end_is_a_lower_bound(core, cli, tmp_path):
    """Rocks that leave the profile at its lower end ran out at least that far: a
    runout statistic that uses them is a lower bound, printed '≥ 100 m (end of
    profile; 14 % of rocks left it)' and flagged per statistic in summary.json
    (it printed 'p90 100 ± 0' as if measured)."""
    cut = dict(POGO, profile=dict(POGO["profile"], x_m=[0, 30, 100]))
    model = _model(tmp_path, cut)
    r = cli("simulate", model, "--rocks", "200", "--seed", "5", "--summary",
            tmp_path / "s.json")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    left = s["final_state"]["exited_downslope"]
    assert left == 29 and s["runout_censored"]["rocks"] == left
    assert s["runout_censored"]["fraction"] == pytest.approx(29 / 200)
    assert s["runout_censored"]["end_x_m"] == 100.0
    runout = s["runout_x_m"]
    assert runout["censored"] == 29 and runout["p90"] == 100.0  # keys kept
    # 171 stopped before x = 100 m: the median is theirs, p90 and up use left rocks
    assert runout["lower_bound"] == {
        "mean": True, "p50": False, "p90": True, "p95": True, "p99": True, "max": True
    }  # fmt: skip
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("runout x"))
    assert "p90, p95, p99, max ≥ 100 m (end of profile; 14 % of rocks left it)" in line
    assert f"p50 {runout['p50']:.4g} ± " in line and "mean ≥ " in line
    assert "100 ± 0" not in line
    # the same rocks on the 130 m profile: the bound holds (p90 101.6 >= 100 m)
    r = cli("simulate", _model(tmp_path), "--rocks", "200", "--seed", "5",
            "--summary", tmp_path / "whole.json")  # fmt: skip
    whole = json.loads((tmp_path / "whole.json").read_text())["runout_x_m"]
    assert whole["p50"] == runout["p50"] and whole["p90"] > 100.0
    assert not any(whole["lower_bound"].values())


def test_a_measured_value_beyond_every_rock_has_no_percentile(core, cli, tmp_path):
    """A measured speed above every crossing rock said '100th percentile ± 0.0'; the
    sample only says it lies above all of them."""
    r = cli("simulate", MODEL, "--rocks", "60", "--seed", "3", "--at", "40",
            "--measured", "x=40,speed=95,ke=1", "--summary", tmp_path / "s.json",
            "--figures", tmp_path / "f")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    m = json.loads((tmp_path / "s.json").read_text())["measured"][0]
    speed, ke = m["speed_mps"], m["ke_j"]
    assert speed["beyond"] == "above" and speed["percentile"] is None
    assert speed["percentile_se"] is None and speed["simulated_max"] < 95
    assert ke["beyond"] == "below" and ke["percentile"] is None
    assert ke["simulated_min"] > 1
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("measured at"))
    n = speed["n"]
    assert (
        f"speed 95 m/s: above all {n} simulated rocks (their maximum "
        f"{speed['simulated_max']:.3g} m/s)" in line
    )
    assert f"below all {n} simulated rocks (their minimum" in line
    assert "percentile" not in line


@pytest.fixture()
def drawn(monkeypatch):
    """The figures `simulate --figures` saves, by file name (then saved as usual)."""
    import fieldkit.viz.simulation_figure as figures

    kept: dict = {}
    save = figures.save_png

    def keep(fig, path, **kwargs):
        kept[Path(path).name] = fig
        return save(fig, path, **kwargs)

    monkeypatch.setattr(figures, "save_png", keep)
    return kept


def _inside(fig, artist) -> bool:
    """True when ``artist`` is drawn wholly inside ``fig`` (not clipped)."""
    fig.draw_without_rendering()
    box, page = artist.get_window_extent(), fig.bbox
    return box.x0 >= page.x0 - 1 and box.x1 <= page.x1 + 1 and box.y1 <= page.y1 + 1


def test_readme_run_figures_say_what_the_profile_end_hides(core, cli, tmp_path, drawn):
    """The README's run: 71 % of the rocks leave the 700 m profile. runout.png was
    squashed to ~170 px by its legend (title and x label clipped), its bar of rocks
    that left hidden behind four percentile lines at 700 m, each '(capped rocks left
    out)'; the point figure's legends sat on the bars ('1.8e+03 kJ'); trajectories
    at 1:1 left 60 % of the plot empty."""
    from matplotlib.patches import Rectangle

    model = Path(__file__).resolve().parents[2] / "surveys" / "tornado_mountain"
    r = cli("simulate", model / "model_rocfall_table_7_1.json", "--rocks", "2000",
            "--seed", "1", "--at", "610", "--measured", "x=610,speed=18,ke=600e3",
            "--summary", tmp_path / "s.json", "--figures", tmp_path / "f")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    left = s["final_state"]["exited_downslope"]
    share = f"{100 * left / s['runout_x_m']['n']:.0f} %"
    assert share == "71 %"
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("runout x"))
    assert (
        "p50, p90, p95, p99, max ≥ 700 m (end of profile; 71 % of rocks left it)"
        in line
    )
    assert all(s["runout_x_m"]["lower_bound"].values())

    fig = drawn["runout.png"]
    ax = fig.axes[0]
    labels = ax.get_legend_handles_labels()[1]
    assert ax.get_position().width > 0.6  # the axes, not the legend, fill the width
    assert _inside(fig, ax.title) and _inside(fig, ax.xaxis.label)
    assert ax.title.get_text().startswith("Runout")
    # no percentile line stands on the profile's end; one '≥' entry says why
    lines = {ln.get_label() for ln in ax.get_lines()}
    assert not any(lab.startswith("runout") and "=" in lab for lab in lines)
    bound = [lab for lab in labels if lab.startswith("runout")]
    assert bound == [
        "runout 50th, 90th, 95th, 99th percentiles ≥ 700 m (end of profile; 71 % of "
        "rocks left it)"
    ]
    # the rocks that left: their own bar beyond x = 700 m, with their count
    bars = [p for p in ax.patches if isinstance(p, Rectangle) and p.get_x() > 700]
    assert [p.get_height() for p in bars] == [left]
    assert f"{left:,}\n↑" in [t.get_text() for t in ax.texts]
    capped = s["final_state"]["capped"]
    assert sum("left out" in lab for lab in labels) == (1 if capped else 0)

    fig = drawn["point_1_x610.png"]
    for ax in fig.axes[:3]:  # the histograms: no legend on them, none over them
        assert ax.get_legend() is None
    for key, ax in zip(fig.axes[3:], fig.axes[:3], strict=True):
        fig.draw_without_rendering()
        legend = key.get_legend().get_window_extent()
        assert legend.y1 < ax.get_window_extent().y0 and _inside(fig, key.get_legend())
    texts = [t.get_text() for t in fig.axes[4].get_legend().get_texts()]
    p50 = s["analysis_points"][0]["ke_j"]["p50"] / 1e3
    assert f"50th percentile = {p50:,.0f} kJ" in texts
    assert not any("e+" in t for t in texts)
    measured = next(t for t in texts if t.startswith("measured translational KE"))
    assert measured.startswith("measured translational KE = 600 kJ: percentile 26 ± 1")

    fig = drawn["trajectories.png"]
    section, heights = fig.axes[:2]
    z0, z1 = section.get_ylim()
    paths = [ln for ln in section.get_lines() if ln.get_linewidth() == 0.9]
    ground = next(
        ln for ln in section.get_lines() if ln.get_label().startswith("ground")
    )
    top, low = max(max(ln.get_ydata()) for ln in paths), min(ground.get_ydata())
    assert len(paths) == 20 and low > z0 and top < z1  # nothing cut off
    assert (z1 - z0) < 1.15 * (top - low)  # and nothing empty above or below
    assert section.get_position().height > 0.5  # the section fills its panel
    assert section.get_ylabel().endswith(("true scale", "x"))  # its scale stated
    # below: the same paths as height above the ground, off the ground line
    above = [ln for ln in heights.get_lines() if ln.get_linewidth() == 0.9]
    assert len(above) == 20 and heights.get_ylabel().startswith("centre above")
    assert max(max(ln.get_ydata()) for ln in above) > 20.0


def test_simulate_every_effect_matches_the_interpreted_stages(core, cli, tmp_path):
    """Issue 21, item 1: ``fieldkit simulate`` runs the kernel through its named
    bundles; its impacts with every effect on (trees, sliding, the alternative
    included) are those of the interpreted driver and stages (``fly``, ``impact``,
    ``slide``), rock by rock."""
    from fieldkit.impact_table import ImpactTable
    from fieldkit.model import kernel
    from fieldkit.model.effects.registry import EFFECTS
    from fieldkit.model.model_file import read_model
    from fieldkit.model.reference import INTERPRETED, simulate_reference

    assert {"fly", "impact", "slide"} <= set(INTERPRETED)
    data = json.loads(MODEL.read_text())
    data["effects"] = {spec.name: {} for spec in EFFECTS}
    data["trees"] = {"x_m": [20.0, 45.0, 70.0], "diameter_m": [0.3, 0.4, 0.3],
                     "height_m": [12.0, 15.0, 10.0]}  # fmt: skip
    model_path = tmp_path / "every.json"
    model_path.write_text(json.dumps(data))
    out = tmp_path / "impacts.parquet"
    r = cli("simulate", model_path, "--rocks", "30", "--seed", "4", "--impacts", out)
    assert r.exit_code == 0, r.stderr
    assert f"wrote {out}" in r.stdout
    frame = ImpactTable.read(out).frame
    refs = simulate_reference(read_model(model_path), 30, np.random.default_rng(4))
    assert len(frame) == sum(len(one.impacts) for one in refs) > 30
    for rock, one in enumerate(refs):
        rows = frame[frame["path_id"].astype(str) == str(rock)]
        for name in ("x_m", "vi_x_mps", "vf_z_mps", "omega_f_radps", "mass_kg"):
            want = one.impacts[:, kernel.RECORD_COLUMNS.index(name)]
            assert np.array_equal(rows[name].to_numpy(float), want), (rock, name)
