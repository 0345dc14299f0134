"""`fieldkit diagnose` reads as an engineer expects: words with units, labelled
p-values, one table per ranking, one rule, every file written named, long steps named.

Each test runs the command line on a synthetic table or track with a known hidden
effect and reads what a person reads: the printed summary, report.md, the figures'
axes and legends (captured as the command saves them).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from diagnose_cases import ANGLE, ROTATION, chainage_trend_table, hidden_table

from fieldkit.diagnose import labels
from fieldkit.diagnose.flights import sphere_mass_kg
from fieldkit.diagnose.scoring import recommendation_rule
from fieldkit.fit.synthetic_track import synthetic_track

#: Column names that must not reach a reader as labels.
CODE_NAMES = ("theta_i_deg", "vin_mps", "vit_mps", "omega_i_radps", "[depends]")


@pytest.fixture(scope="module")
def figures():
    """Every figure the command saves, captured (and still written)."""
    import fieldkit.viz.diagnose_figure as module

    saved = []
    original = module.save_png

    def capture(fig, path, **kwargs):
        saved.append((Path(path).name, fig))
        return original(fig, path, **kwargs)

    patch = pytest.MonkeyPatch()
    patch.setattr(module, "save_png", capture)
    yield saved
    patch.undo()


@pytest.fixture(scope="module")
def two_effects(tmp_path_factory, figures):
    """angle law and rotation friction hidden (two steps), diagnosed with every
    output; returns (out folder, result, figures)."""
    from typer.testing import CliRunner

    from fieldkit.cli import app

    folder = tmp_path_factory.mktemp("reading")
    table = folder / "two.csv"
    hidden_table((ANGLE, ROTATION), noise=0.05, paths=15, seed=0).write(table)
    out = folder / "out"
    figures.clear()
    r = CliRunner().invoke(
        app,
        [
            "diagnose", str(table), "--seed", "0", "--json", str(out / "d.json"),
            "--report", str(out / "rep"), "--rrd", str(out / "d.rrd"),
        ],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    return out, r, list(figures)


def test_two_steps_report_one_table_per_ranking(two_effects):
    out, r, _ = two_effects
    text = (out / "rep" / "report.md").read_text()
    steps = re.findall(r"^## Step (\d): add `(\w+)`", text, flags=re.M)
    assert sorted(s[1] for s in steps) == [ANGLE, ROTATION]
    # round 1 (which effect is missing), round 2 (step 2), round 3 (after: none
    # passes); step 1 points to round 1 instead of repeating it
    assert text.count("| rank | effect |") == 3
    assert "Ranked in *Which effect is missing* above." in text
    assert "Candidates ranked against the model after step 1:" in text
    assert "Candidates ranked against the model after step 2 (none passes" in text
    # the later rankings are printed too
    assert "  then, against the model after step 2: " in r.stdout


def test_report_names_quantities_in_words_with_units(two_effects):
    out, r, _ = two_effects
    text = (out / "rep" / "report.md").read_text()
    for code in CODE_NAMES:
        assert code not in text, code
        assert code not in r.stdout, code
    assert "± —" not in text and "± —" not in r.stdout
    # the JSON name appears once, to find the value in the JSON
    assert text.count("cv_rmse_mps") == 1 and "cv_rmse_mps" not in r.stdout
    assert "held-out RMS error of the rebound velocities" in r.stdout
    assert "rebound spin as surface speed r·ω_f, all in m/s" in text
    assert "normal rebound velocity v_fn" in text
    assert "impact angle to the ground θi (deg)" in text
    # fitted parameters in words: material, quantity, value ± SE, unit
    assert re.search(r"\| rock: normal restitution e_n \| [\d.]+ ± [\d.]+ \|", text)
    assert re.search(r"\| angle-dependent restitution \(thesis eq. 5.4\): b, ", text)


def test_each_p_value_says_which_it_is(two_effects):
    out, _, _ = two_effects
    text = (out / "rep" / "report.md").read_text()
    assert "*Holm p* is *p* adjusted by Holm's method over all" in text
    assert (
        "the smaller of the Spearman and the binned Kruskal-Wallis p, doubled" in text
    )
    rows = re.findall(
        r"^\| normal rebound velocity v_fn \| (.+?) \| (Spearman rho = .+?) \| "
        r"([\de.+-]+) \| ([\de.+-]+) \|$",
        text,
        flags=re.M,
    )
    assert rows, "no labelled dependence rows"
    for feature, statistic, p, p_holm in rows:
        assert feature in labels.FEATURES.values()
        assert "Spearman p = " in statistic and "Kruskal-Wallis over" in statistic
        assert float(p) <= float(p_holm) <= 0.01


def test_help_report_and_summary_state_the_same_rule(two_effects, cli):
    out, r, _ = two_effects
    rule = recommendation_rule()
    assert rule == (
        "it lowers the held-out error by more than 1 % and by more than 2 standard "
        "errors of that gain"
    )
    help_text = " ".join(cli("diagnose", "--help").stdout.split())
    assert f"one is recommended only when {rule} (jackknife" in help_text
    flights = recommendation_rule()
    assert f"air_drag is recommended when {flights}." in help_text
    text = (out / "rep" / "report.md").read_text()
    assert f"A candidate is recommended when {rule};" in text
    assert f"* rule: a candidate is recommended when {rule}" in text
    assert f"rule: a candidate is recommended (*) when {rule}" in r.stdout


def test_every_file_written_is_named_and_long_steps_are_announced(two_effects):
    out, r, _ = two_effects
    written = [line[len("wrote ") :] for line in r.stdout.splitlines()
               if line.startswith("wrote ")]  # fmt: skip
    files = sorted(str(p) for p in out.rglob("*") if p.is_file())
    assert sorted(written) == files
    assert len(files) == 6  # json, report.md, 3 figures, recording
    assert re.search(r"^diagnosing \d+ impacts: scoring the baseline", r.stderr, re.M)
    assert "writing the report and its figures to" in r.stderr


def test_figures_label_axes_in_words_and_explain_every_mark(two_effects):
    out, _, figures = two_effects
    added = json.loads((out / "d.json").read_text())["after"]["effects"]
    assert [name for name, _ in figures] == [
        "baseline.png", f"step_1_{added[0]}.png", f"step_2_{added[1]}.png",
    ]  # fmt: skip
    for name, fig in figures:
        axes = fig.get_axes()
        for ax in axes:
            # the axis names its feature only (wrapped to the column's width)
            label = ax.get_xlabel().replace("\n", " ")
            assert label in labels.FEATURES.values(), (name, label)
            notes = [t.get_text() for t in ax.texts]
            assert all(
                n.startswith("residuals depend on this feature (Holm p ≤ 0.01): ")
                for n in notes
            ), notes
            assert ax.get_ylabel() in ("", "residual, measured − model (m/s)")
        legend = fig.legends[0]
        texts = [t.get_text() for t in legend.get_texts()]
        assert len(texts) == len(legend.legend_handles) == 5  # 3 residuals + 2 lines
        assert texts[2].startswith("rebound spin as surface speed r·ω_f (m/s)")
        assert texts[3].startswith("binned median") and texts[4].startswith("zero")
        titles = " ".join(ax.get_title() for ax in axes)
        assert "held-out RMS error" in titles
        for code in CODE_NAMES:
            assert code not in fig.texts[0].get_text() + titles
    # the baseline's angle dependence is noted inside the angle's own panel (under
    # the axis it read as the heading of the panel below), with its Holm p
    baseline = figures[0][1].get_axes()
    noted = {ax.get_xlabel(): [t.get_text() for t in ax.texts] for ax in baseline}
    angle = noted["impact angle to the ground θi (deg)"]
    assert len(angle) == 1, noted
    assert re.search(r": .*v_fn \(Holm p = [\de.+-]+\)", angle[0])
    assert not any("depend" in x for x in noted)


def test_residual_structure_left_is_said_in_words(tmp_path, cli):
    """A trend outside the vocabulary (vfn rises along x) is printed as words with
    both p-values labelled."""
    table = tmp_path / "chainage.csv"
    chainage_trend_table(np.random.default_rng(0)).write(table)
    r = cli("diagnose", table, "--seed", "0")
    assert r.exit_code == 0, r.output
    left = [
        x
        for x in r.stdout.splitlines()
        if x.startswith(
            "residuals still: normal rebound velocity v_fn residuals depend on x, "
            "horizontal distance along the path (m): Spearman rho = +"
        )
    ]
    assert len(left) == 1, r.stdout
    assert re.search(
        r"; Spearman p = [\de.+-]+; Kruskal-Wallis over 5 quantile bins p = "
        r"[\de.+-]+; p = [\de.+-]+ \(the smaller p doubled\), "
        r"Holm-adjusted p = [\de.+-]+ ≤ 0.01$",
        left[0],
    ), left[0]
    assert "recommended: nothing" in r.stdout


@pytest.fixture(scope="module")
def track_csv(tmp_path_factory) -> Path:
    """Eight flights of a 0.2 m rock sphere with drag (cd 0.3) on a 35° plane."""
    rng = np.random.default_rng(4)
    track = synthetic_track(
        radius_m=0.2, mass_kg=sphere_mass_kg(0.2), cd=0.3,
        launch_speed_mps=15.0 * rng.uniform(0.8, 1.2, 8),
        launch_angle_deg=rng.uniform(10.0, 20.0, 8), surface_angle_deg=35.0,
        fps=200.0, noise_m=0.005, rng=rng,
    )  # fmt: skip
    path = tmp_path_factory.mktemp("track") / "track.csv"
    track.write(path)
    return path


def test_track_report_names_flights_once_and_says_what_is_fixed(
    track_csv, tmp_path, cli, figures
):
    figures.clear()
    r = cli("diagnose", track_csv, "--radius", "0.2", "--seed", "0",
            "--report", tmp_path / "rep")  # fmt: skip
    assert r.exit_code == 0, r.output
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "flight flight" not in text and "± —" not in text
    assert re.search(r"^\* flight \d \(rows \d+-\d+\): RMS position residual", text,
                     flags=re.M)  # fmt: skip
    assert "| gravity g | 9.81 m/s² (fixed, not fitted) |" in text
    assert "air_density_kg_m3, air density (sea level) | 1.225 kg/m^3 (fixed" in text
    assert f"air_drag is recommended when {recommendation_rule()}" in text
    assert "*p* is a test's own p-value (Spearman)" in text
    assert "horizontal position x, vertical position z, all in m" in text
    assert re.search(r"^diagnosing the flights of .*track.csv", r.stderr, re.M)
    written = {x[len("wrote ") :] for x in r.stdout.splitlines()
               if x.startswith("wrote ")}  # fmt: skip
    assert written == {str(p) for p in (tmp_path / "rep").iterdir()}
    for _, fig in figures:
        texts = [t.get_text() for t in fig.legends[0].get_texts()]
        assert texts[0] == "horizontal position x (m), one point per sample of a flight"
        for ax in fig.get_axes():
            assert ax.get_xlabel().replace("\n", " ") in labels.FEATURES.values()


def test_legend_leaves_out_a_residual_without_data(tmp_path, cli, figures):
    """Spins estimated (not measured): no spin residual is drawn, so the legend
    does not promise one; wide column titles are wrapped, not cut."""
    import pandas as pd

    from fieldkit.impact_table import ImpactTable

    frame = hidden_table((ANGLE,), noise=0.05, paths=15, seed=0).frame.copy()
    frame["omega_source"] = pd.Series(["estimated"] * len(frame), dtype="string")
    table = tmp_path / "estimated.csv"
    ImpactTable(frame, source="estimated").write(table)
    figures.clear()
    r = cli("diagnose", table, "--seed", "0", "--report", tmp_path / "rep")
    assert r.exit_code == 0, r.output
    assert len(figures) == 2
    for _, fig in figures:
        texts = [t.get_text() for t in fig.legends[0].get_texts()]
        assert len(texts) == 4 and not any("ω_f" in t for t in texts), texts
    after = figures[1][1].get_axes()[1].get_title()
    assert (
        after.startswith("after adding angle-dependent restitution") and "\n" in after
    )


def test_confounded_structure_is_not_called_unexplained(tmp_path, cli):
    """Angle and speed laws that the data cannot tell apart: the residual trend
    left is the one they would both explain, and the report says so."""
    from diagnose_cases import narrow_speed_table

    table = tmp_path / "narrow.csv"
    narrow_speed_table(np.random.default_rng(0)).write(table)
    r = cli("diagnose", table, "--seed", "0", "--report", tmp_path / "rep")
    assert r.exit_code == 0, r.output
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "### Confounded" in text
    assert "**Residual structure left**: the confounded candidates" in text
    assert "no candidate explains" not in text
    assert "|v_in| = |v_i| sin θi rises with the impact angle θi" in text


def test_track_time_axis_and_level_say_what_they_are(track_csv, tmp_path, cli, figures):
    """The time feature is |t - t_mid| / half the flight (0 to 1): its axis says
    absolute and what 0 and 1 are; the track's tests use Holm p ≤ 0.05 (an
    ImpactTable's 0.01): the report, the figure's note and --help say which; the
    figure's residual kind is not nested in a second parenthesis."""
    from fieldkit.diagnose import flights, residual_tests

    figures.clear()
    r = cli("diagnose", track_csv, "--radius", "0.2", "--seed", "0",
            "--report", tmp_path / "rep")  # fmt: skip
    assert r.exit_code == 0, r.output
    assert (residual_tests.ALPHA, flights.DEPENDENCE_ALPHA) == (0.01, 0.05)
    axis = (
        "absolute time from mid-flight / half the flight's duration\n"
        "(0 mid-flight, 1 take-off or landing)"
    )
    time_axes = [ax for _, fig in figures for ax in fig.get_axes()
                 if ax.get_xlabel() == axis]  # fmt: skip
    assert len(time_axes) == 3, [ax.get_xlabel() for _, f in figures
                                 for ax in f.get_axes()]  # fmt: skip
    assert time_axes[0].get_xticks().min() >= -0.2
    notes = [t.get_text() for ax in time_axes for t in ax.texts]
    assert notes and all(
        n.startswith("residuals depend on this feature (Holm p ≤ 0.05): x (Holm p")
        for n in notes
    ), notes
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "((" not in text and "))" not in text.replace("(s))", "")
    assert (
        "![baseline residuals against each feature; residuals in-sample (each "
        "flight's own fit)](baseline.png)"
    ) in text
    assert (
        "A residual depends on a feature when its Holm p ≤ 0.05 (the level of a "
        "track's flight tests; an ImpactTable's tests use 0.01). These tests "
        "describe the residuals only: no recommendation rests on them"
    ) in text
    help_text = " ".join(cli("diagnose", "--help").stdout.split())
    assert "a residual depends on a feature when its Holm-adjusted p <= 0.01." in (
        help_text
    )
    assert (
        "(4 tests; a residual depends on a feature when its Holm-adjusted p <= 0.05). "
        "The dependence tests only describe the residuals: no recommendation rests "
        "on them."
    ) in help_text


def test_impact_report_states_its_level_and_the_tracks(two_effects):
    out, _, _ = two_effects
    text = (out / "rep" / "report.md").read_text()
    assert (
        "A residual depends on a feature when its Holm p ≤ 0.01 (the level of an "
        "ImpactTable's tests; a track's flight tests use 0.05). These tests "
        "describe the residuals only: no recommendation rests on them"
    ) in text
