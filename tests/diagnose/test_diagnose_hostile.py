"""Hostile input to `fieldkit diagnose`: one line, exit 1, nothing written, inputs kept.

Each case names its argv (``{table}``, ``{track}``, ``{folder}``, ``{missing}`` are
files the test makes) and a fragment of the one error line. Every refusal happens
before any work: the checks never need a real diagnosis.
"""

from __future__ import annotations

import numpy as np
import pytest

#: (argv after ``diagnose``, fragment of the error line)
CASES = {
    "missing-file": (["{missing}"], "nothing.csv: file not found"),
    "folder": (["{folder}"], "is a folder, not a file"),
    "folder-named-csv": (["{folder_csv}"], "is a folder, not a file"),
    "negative-seed": (["{table}", "--seed", "-1"], "--seed must be between 0 and"),
    "huge-seed": (["{table}", "--seed", str(2**64)], "--seed must be between 0 and"),
    "too-many-folds": (
        ["{table}", "--seed", "1", "--folds", "101"],
        "--folds must be between 2 and 100 (got 101)",
    ),
    "huge-folds": (
        ["{table}", "--seed", "1", "--folds", str(10**12)],
        "--folds must be between 2 and 100",
    ),
    "radius-inf": (
        ["{track}", "--seed", "1", "--radius", "inf"],
        "--radius must be a finite number (got inf)",
    ),
    "radius-minus-inf": (
        ["{track}", "--seed", "1", "--radius", "-inf"],
        "--radius must be a finite number (got -inf)",
    ),
    "radius-nan": (["{track}", "--seed", "1", "--radius", "nan"], "(got nan)"),
    "radius-huge": (
        ["{track}", "--seed", "1", "--radius", "1e200"],
        "<= 25 m (got 1e+200)",
    ),
    "radius-negative": (
        ["{track}", "--seed", "1", "--radius", "-0.5"],
        "--radius must be > 0",
    ),
    "mass-nan": (
        ["{track}", "--seed", "1", "--radius", "0.5", "--mass", "nan"],
        "--mass must be a finite number (got nan)",
    ),
    "mass-huge": (
        ["{track}", "--seed", "1", "--radius", "0.5", "--mass", "1e300"],
        "--mass must be > 0 and <= 2e+08 kg",
    ),
    "track-without-radius": (["{track}", "--seed", "1"], "a track needs --radius"),
    "radius-on-a-table": (
        ["{table}", "--seed", "1", "--radius", "0.5"],
        "--radius and --mass apply to a track only",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_hostile_input_is_one_line_and_writes_nothing(
    case, tmp_path, cli, fails, digest
):
    argv, fragment = CASES[case]
    table = tmp_path / "table.csv"
    table.write_text("path_id,point,x_m,z_m,slope_deg,vi_x_mps\nA,1,0,0,30,1\n")
    track = tmp_path / "track.csv"
    track.write_text("t_s,x_m,z_m\n0,0,0\n0.01,0.1,0\n")
    (tmp_path / "folder").mkdir()
    (tmp_path / "folder.csv").mkdir()
    files = {
        "table": table,
        "track": track,
        "folder": tmp_path / "folder",
        "folder_csv": tmp_path / "folder.csv",
        "missing": tmp_path / "nothing.csv",
    }
    before = {p: digest(p) for p in (table, track)}
    out = tmp_path / "out"
    args = [a.format(**files) for a in argv]
    r = cli("diagnose", *args, "--json", out / "d.json", "--report", out / "rep")
    # a non-finite option value is a usage error (exit 2, the shared option check)
    assert r.exit_code == (2 if {"inf", "-inf", "nan"} & set(argv) else 1), r.output
    fails(r, fragment)
    assert "Traceback" not in r.output
    assert not out.exists()
    assert {p: digest(p) for p in (table, track)} == before


def test_input_refused_after_reading_is_still_one_line(tmp_path, cli, fails):
    """Checks made while diagnosing (too few impacts, too few flights) refuse before
    any progress is announced: stderr holds the error line alone."""
    from diagnose_cases import hidden_table

    from fieldkit.diagnose.flights import sphere_mass_kg
    from fieldkit.fit.synthetic_track import synthetic_track
    from fieldkit.impact_table import ImpactTable

    table = tmp_path / "two.csv"
    frame = hidden_table((), noise=0.05, paths=3, seed=0).frame.iloc[:2]
    ImpactTable(frame.assign(path_id="A"), source="two").write(table)
    r = cli("diagnose", table, "--seed", "1", "--json", tmp_path / "out" / "d.json")
    fails(r, "two.csv", "too few impacts to diagnose", "need at least 3")
    rng = np.random.default_rng(0)
    track = synthetic_track(
        radius_m=0.2, mass_kg=sphere_mass_kg(0.2), cd=0.0,
        launch_speed_mps=np.full(2, 15.0), launch_angle_deg=np.full(2, 15.0),
        surface_angle_deg=35.0, fps=200.0, noise_m=0.005, rng=rng,
    )  # fmt: skip
    path = tmp_path / "two_flights.csv"
    track.write(path)
    r = cli("diagnose", path, "--radius", "0.2", "--seed", "1",
            "--report", tmp_path / "out" / "rep")  # fmt: skip
    fails(r, "two_flights.csv", "2 flight(s) found; at least 3 are needed")
    assert not (tmp_path / "out").exists()
