"""`fieldkit diagnose` on the README's boulder A, as a reviewer read it.

Boulder A is reduced and diagnosed through the command line once (about 8 s); the
figures are captured as the command saves them. What is checked is what a person
reads: every material strip ticked with its name and count, one number of impacts
everywhere, titles in words, notes that sit in the panel they describe.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SURVEY = REPO / "surveys" / "tornado_mountain"


@pytest.fixture(scope="module")
def boulder_a(tmp_path_factory):
    """``(out folder, diagnose result, [(png name, figure)])``."""
    from typer.testing import CliRunner

    import fieldkit.viz.diagnose_figure as module
    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("boulder_a")
    preset = str(SURVEY / "boulder_a_preset.toml")
    runner = CliRunner()
    r = runner.invoke(
        app,
        [
            "reduce", "--impacts", str(SURVEY / "boulder_a_impacts.gpx"),
            "--trees", str(SURVEY / "boulder_a_trees.csv"), "--preset", preset,
            "-o", str(out / "b.csv"),
        ],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    saved = []
    original = module.save_png

    def capture(fig, path, **kwargs):
        saved.append((Path(path).name, fig))
        return original(fig, path, **kwargs)

    patch = pytest.MonkeyPatch()
    patch.setattr(module, "save_png", capture)
    try:
        r = runner.invoke(
            app,
            [
                "diagnose", str(out / "b.csv"), "--model",
                str(SURVEY / "model_rocfall_table_7_1.json"), "--preset", preset,
                "--seed", "1", "--json", str(out / "d.json"), "--report",
                str(out / "rep"), "--null", "0",
            ],
        )  # fmt: skip
    finally:
        patch.undo()
    assert r.exit_code == 0, r.output
    return out, r, saved


def _material_axes(figures):
    return [
        ax
        for _, fig in figures
        for ax in fig.get_axes()
        if ax.get_xlabel().startswith("slope material")
    ]


def test_every_material_strip_is_ticked_with_its_count(boulder_a):
    """The two rock impacts sat right of the axis' last tick (the axis was scaled
    to the jittered points, not to the categories): every category is ticked,
    with how many impacts it holds, and every point lies inside its strip."""
    _, _, figures = boulder_a
    axes = _material_axes(figures)
    assert len(axes) == 3  # baseline; step 1 before and after
    for ax in axes:
        ticks = [t.get_text() for t in ax.get_xticklabels()]
        assert ticks == ["colluvium\n(n = 46)", "rock\n(n = 2)"]
        low, high = ax.get_xlim()
        assert low <= -0.5 and high >= 1.5
        for points in ax.collections:
            x = points.get_offsets()[:, 0]
            near = x.round()
            assert (abs(x - near) <= 0.3).all()
            assert sorted(near.tolist()).count(1.0) == 2  # the two rock impacts


def test_one_number_of_impacts_everywhere(boulder_a):
    """50 rows, of which the first is the release and the last the stop point:
    the progress line, the report and the JSON all say 48 impacts."""
    out, r, _ = boulder_a
    said = (
        "48 impacts (of 50 rows; not impacts: row 1, a release point; row 50, a "
        "stop point)"
    )
    assert f"diagnosing {said}: scoring the baseline" in r.stderr
    assert "diagnosing 50 impacts" not in r.stderr
    text = (out / "rep" / "report.md").read_text()
    assert f"* {said}, 96 data; held out:" in text
    assert "48 rows" not in text
    assert json.loads((out / "d.json").read_text())["n_rows"] == 48
    materials = re.findall(r"^\| (rock|colluvium) \| (\d+) \|", text, flags=re.M)
    assert sum(int(n) for _, n in materials) == 48


def test_titles_and_report_name_effects_in_words(boulder_a):
    """The baseline's slope roughness was shown by its code name in the figure
    titles, the report and the printed summary."""
    out, r, figures = boulder_a
    text = (out / "rep" / "report.md").read_text()
    words = "constant e_n, e_t per material + slope roughness (thesis eq. 7.4)"
    assert f"Model: {words}; held-out RMS error" in text
    assert f"baseline, {words}: held-out RMS error" in r.stdout
    # the step accepted on the plain rule is affine_rebound or eq. 7.1 (their gains
    # are within a tenth of an SE of each other); what is checked is the words
    assert re.search(
        r"^Effects: slope roughness \(thesis eq. 7.4\), (velocity-scaled restitution "
        r"\(thesis eq. 7.1\)|affine rebound \(a straight line, not a law\)); "
        r"held-out RMS error",
        text,
        flags=re.M,
    )
    for _, fig in figures:
        title = fig.texts[0].get_text()
        assert "slope_roughness" not in title and "_restitution" not in title
        assert "affine_rebound" not in title
    assert figures[0][1].texts[0].get_text().startswith(f"Baseline, {words}")


def test_features_shown_tested_and_not_tested_add_up(boulder_a):
    """The figure said "6 of 7 features shown" beside "Features tested" listing
    6: the figure names the feature it leaves out, the report the one it could not
    test."""
    out, _, figures = boulder_a
    for _, fig in figures:
        title = " ".join(fig.texts[0].get_text().split())
        assert (
            "6 of 7 features shown (those the residuals depend on first); not shown: "
            "flight before the impact struck a tree; the report lists every test"
        ) in title
    text = (out / "rep" / "report.md").read_text()
    tested = re.search(r"^Features tested: (.*)\.$", text, flags=re.M).group(1)
    assert len(tested.split("; ")) == 6 and "slope material" not in tested
    assert (
        "Not tested (drawn in the figure all the same): slope material: the test "
        "needs two categories of at least 5 impacts (colluvium 46, rock 2)."
    ) in text


def test_dependence_note_sits_inside_its_own_panel(boulder_a):
    """The note "residuals depend on it: v_fn" sat under the v_in axis, where it
    read as the heading of the θi panel below: it is a boxed note inside the v_in
    panel, with room above the points so it hides none."""
    _, _, figures = boulder_a
    axes = figures[0][1].get_axes()
    for ax in axes:
        assert "depend" not in ax.get_xlabel()
    noted = [ax for ax in axes if ax.texts]
    assert [ax.get_xlabel() for ax in noted] == ["normal impact speed v_in (m/s)"]
    ax = noted[0]
    (note,) = ax.texts
    assert note.get_text() == (
        "residuals depend on this feature (Holm p ≤ 0.01): v_fn (Holm p = 0.0004)"
    )
    assert note.get_transform() == ax.transAxes and note.get_position()[1] > 0.9
    top = max(float(c.get_offsets()[:, 1].max()) for c in ax.collections)
    low, high = ax.get_ylim()
    assert (top - low) / (high - low) < 0.85  # the note's box starts above it


def test_summary_nests_no_parentheses(boulder_a):
    """The line "recommended: X (no remaining candidate ... (best: ...))" nested one
    parenthesis in another: the reason follows after "stopped:"."""
    _, r, _ = boulder_a
    assert (
        "recommended: affine_rebound; stopped: no remaining candidate passes the "
        "rule (best: velocity_scaled_restitution, gain +10.4% ± 9.6%)\n"
    ) in r.stdout
    assert "))" not in r.stdout


def test_sensitivity_gives_the_verdict_of_each_variant(boulder_a):
    """Issue 18 item 4: the verdict's sensitivity to the assumed launch angle
    (32.6° ± 10°) and to the material grouping, in the JSON, the report and the
    printed summary. Measured (fold seed 1): theta0 22.6° and 42.6° accept
    affine_rebound too (+21.9 % ± 6.9 %, +18.7 % ± 7.7 %)."""
    out, r, _ = boulder_a
    j = json.loads((out / "d.json").read_text())
    variants = {v["variant"]: v for v in j["sensitivity"]}
    assert list(variants) == ["theta0 - 10 deg", "theta0 + 10 deg", "materials grouped"]
    assert "22.6°" in variants["theta0 - 10 deg"]["description"]
    assert "42.6°" in variants["theta0 + 10 deg"]["description"]
    assert "colluvium, rock" in variants["materials grouped"]["description"]
    for v in variants.values():
        assert v["error"] == ""
        assert set(v) >= {"recommended", "accepted", "best", "gain", "gain_se",
                          "unsolved_flights"}  # fmt: skip
        assert v["accepted"][:1] == ([v["recommended"]] if v["recommended"] else [])
        assert v["gain_se"] > 0.0
    assert variants["materials grouped"]["unsolved_flights"] == 0
    printed = [
        line for line in r.stdout.splitlines() if line.startswith("sensitivity:")
    ]
    assert len(printed) == 3
    text = (out / "rep" / "report.md").read_text()
    assert "## Sensitivity of the verdict" in text
    assert "| theta0 + 10 deg |" in text


def test_theta0_shift_of_zero_reproduces_the_reduced_velocities(boulder_a):
    """An independent check of the re-solve: at theta0 + 0 every flight solved
    again from x, z, slope_deg and theta0_deg gives the reduction's velocities."""
    import numpy as np

    from fieldkit.diagnose.sensitivity import shifted_theta0
    from fieldkit.impact_table import ImpactTable

    out, _, _ = boulder_a
    table = ImpactTable.read(out / "b.csv")
    again, unsolved = shifted_theta0(table, 0.0)
    assert unsolved == 0
    assumed = (table.frame["theta0_source"] == "assumed").fillna(False).to_numpy()
    assert assumed.sum() >= 30
    for column in ("vi_x_mps", "vi_z_mps", "vf_x_mps", "vf_z_mps", "vin_mps",
                   "vfn_mps", "omega_f_radps"):  # fmt: skip
        np.testing.assert_allclose(
            again.column(column), table.column(column), rtol=1e-12, atol=0.0
        )
    shifted, _ = shifted_theta0(table, 10.0)
    moved = ~np.isclose(shifted.column("vf_z_mps"), table.column("vf_z_mps"))
    assert (
        moved[assumed].all()
        and not moved[~assumed & np.isfinite(table.column("vf_z_mps"))].any()
    )


def test_no_sensitivity_switches_it_off(boulder_a, cli, tmp_path):
    out, _, _ = boulder_a
    r = cli("diagnose", out / "b.csv", "--seed", "1", "--no-sensitivity",
            "--json", tmp_path / "d.json", "--null", "0")  # fmt: skip
    assert r.exit_code == 0, r.output
    assert json.loads((tmp_path / "d.json").read_text())["sensitivity"] == []
    assert "sensitivity:" not in r.stdout
