"""Issue 17: the fit's uncertainty and reports say what they mean (through the CLI)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

TORNADO = Path(__file__).parents[2] / "surveys" / "tornado_mountain"
TABLE_7_1 = TORNADO / "model_rocfall_table_7_1.json"
E_N, E_T = "materials.colluvium.e_n", "materials.colluvium.e_t"




def test_zero_width_slice_is_no_evidence_of_pinning(cli, tmp_path, boulder_a):
    """--bootstrap 2 on one path: the slice, refined by bisection, resolves no range
    for either parameter (the objective is kinked at the optimum); that is said, and
    is not reported as pinned down."""
    r = cli(
        "fit", "--paths", boulder_a, "--model", TABLE_7_1, "--free", E_N,
        "--free", E_T, "--rocks", "50", "--bootstrap", "2",
        "-o", tmp_path / "m.json", "--json", tmp_path / "f.json",
        "--report", tmp_path / "rep",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    fit = json.loads((tmp_path / "f.json").read_text())
    for p in fit["parameters"]:
        assert p["pinned"] is None and p["range_resolved"] is False, p
        assert 0 < p["slice_resolution"] < 0.003  # 1/64 of the 9-point grid step
        assert p["stderr"] is None and p["stderr_is_lower_bound"] is False
    assert fit["parameters"][0]["value"] == pytest.approx(0.3223, abs=1e-4)
    lines = {x.split(":")[0]: x for x in r.stdout.splitlines()}
    for name in (E_N, E_T):
        assert "no range resolved" in lines[name], lines[name]
        assert "[no evidence that these runs pin it down]" in lines[name]
    assert "fit 2 parameters to 1 run (50 rocks" in r.stderr
    report = (tmp_path / "rep" / "report.md").read_text()
    for code in (E_N, "runout_m", "flight_height_m", "speed_mps", "1 runs",
                 "sections: descent"):  # fmt: skip
        assert code not in report, code
    row = "| colluvium: normal restitution e_n | 1 | 0.3223 | none | none resolved"
    assert row in report
    assert "| normal flight height between impacts (m) | 48 |" in report
    assert "1 run, 50 simulated rocks per run" in report
    assert "no evidence (no range resolved)" in report


def test_one_path_standard_errors_are_lower_bounds(cli, tmp_path, boulder_a):
    """--bootstrap 10 on one path: the ± is flagged a lower bound where it is printed
    (a line above the values, each value, report.md's table, the JSON), and the 90 %
    interval is explained as ±6.31 SE (Student's t, 1 degree of freedom)."""
    r = cli(
        "fit", "--paths", boulder_a, "--model", TABLE_7_1, "--free", E_T,
        "--rocks", "20", "--bootstrap", "10", "--screen", "0", "--seed", "1",
        "-o", tmp_path / "m.json", "--json", tmp_path / "f.json",
        "--report", tmp_path / "rep",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    fit = json.loads((tmp_path / "f.json").read_text())
    (p,) = fit["parameters"]
    assert p["stderr"] > 0 and p["stderr_is_lower_bound"] is True
    assert fit["t_dof"] == 1 and fit["t_quantile"] == pytest.approx(6.3138, abs=1e-4)
    lo, hi = p["interval90"]
    assert hi - lo >= 2 * 6.3138 * p["stderr"] * 0.999 or lo == p["bounds"][0]
    assert "lower bounds" in fit["interval90_method"]
    out = r.stdout.splitlines()
    at = next(i for i, x in enumerate(out) if x.startswith(E_T))
    assert out[at - 2].startswith("one surveyed path:") and "lower bound" in out[at - 2]
    assert "± 6.31 standard errors (Student's t with 1 degree of" in out[at - 1]
    assert ", a lower bound (90 %" in out[at]
    report = (tmp_path / "rep" / "report.md").read_text()
    assert "| standard error (a lower bound) |" in report
    assert f"| at least {p['stderr']:.2g} |" in report
    assert "±6.3 SE: Student's t (95 % quantile) with 1 degree of freedom" in report
    assert "**Lower bounds.** One surveyed path" in report


def test_impact_fit_report_gives_a_verdict_in_words(cli, tmp_path, boulder_a):
    """Impact fit of boulder A: a reduced chi2 far above 1 is called so, with what it
    means and where to look; report.md is markdown in words, not the console text."""
    r = cli(
        "fit", boulder_a, "--model", TABLE_7_1, "--material", "talus=colluvium",
        "--material", "bench=colluvium", "-o", tmp_path / "m.json",
        "--report", tmp_path / "rep",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    redchi = json.loads((tmp_path / "m.json").read_text())["provenance"]["fit"][
        "redchi"
    ]
    assert redchi > 3
    assert f"reduced chi2 {redchi:.4g} is far above 1" in r.stdout
    assert "fieldkit diagnose" in r.stdout and "ftol" not in r.stdout
    report = (tmp_path / "rep" / "report.md").read_text()
    assert "```" not in report
    for code in ("ftol", "vfn_sd_mps", "materials.colluvium.e_n"):
        assert code not in report, code
    assert f"**Goodness of fit:** reduced chi2 {redchi:.4g} is far above 1" in report
    assert "`fieldkit diagnose` ranks the effects that may be missing" in report
    assert "| colluvium: normal restitution e_n | 1 |" in report
    assert "the normal rebound velocity (m/s)" in report


def test_holdout_figure_marks_censored_and_release_stops():
    """A bar that reaches the section's end, and one that starts at the release, are
    marked, and the legend says what each mark means."""
    from fieldkit.viz.holdout_figure import holdout_figure

    rng = np.random.default_rng(0)
    validation = {
        "path_ids": ["a", "b"],
        "observed": np.array([50.0, 80.0]),
        "section_end_m": [100.0, 120.0],
        "ensembles": {
            "calibrated": [
                np.r_[np.zeros(30), rng.uniform(40, 90, 70)],
                rng.uniform(50, 110, 100),
            ],
            "uncalibrated": [
                rng.uniform(40, 90, 100),
                np.r_[rng.uniform(60, 110, 40), np.full(60, 120.0)],
            ],
            "climatology": [np.array([40.0, 60, 80])] * 2,
        },  # fmt: skip
        "forecasts": {"calibrated": {"mean_crps": 1.0}},
    }
    fig = holdout_figure(validation)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any("that left the section" in t for t in labels), labels
    assert any("stopped within 5 m" in t for t in labels), labels
    texts = [t.get_text() for t in fig.axes[0].texts]
    # the share of calibrated rocks stopped at run a's release, of starting-model
    # rocks that left run b's section
    assert texts == ["30%", "60%"]
    ends = [ln for ln in fig.axes[0].lines if ln.get_marker() == ">"]
    assert len(ends) == 2 and ends[0].get_xdata()[0] == pytest.approx(120.0)
    # the longer legend sits below the axes, clear of them and of the x label
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw_without_rendering()
    box = fig.legends[0].get_window_extent(renderer)
    ax = fig.axes[0]
    assert not box.overlaps(ax.bbox)
    assert not box.overlaps(ax.xaxis.label.get_window_extent(renderer))
