"""`fieldkit synth MODEL.json --track`: a synthetic video track with air drag."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fieldkit.cli.diagnose_track import track_flights
from fieldkit.track import Track

MODEL = Path(__file__).resolve().parents[1] / "model" / "data" / "smoke.json"


def test_synth_track_writes_a_segmentable_track_with_its_truth(cli, tmp_path):
    out = tmp_path / "track.csv"
    result = cli(
        "synth", MODEL, "--track", "--fps", "200", "--noise-m", "0.004",
        "--flights", "6", "--seed", "3", "--effects", "air_drag=cd=0.8", "-o", out,
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "track of 6 flights" in result.stdout and "cd = 0.8" in result.stdout
    track = Track.read(out)
    f = track.frame
    assert sorted(set(f["flight_true"])) == list(range(6))
    np.testing.assert_allclose(np.diff(f["t_s"]), 1 / 200, atol=1e-9)
    noise = np.concatenate([f["x_m"] - f["x_m_true"], f["z_m"] - f["z_m_true"]])
    assert abs(noise.std() - 0.004) < 0.0004 and abs(noise.mean()) < 0.0004
    # the smoke model's profile dips 46 m over 90 m: the rock lands on that plane
    dip = np.arctan2(46, 90)
    starts = f.groupby("flight_true")["x_m_true"].idxmin()
    x0, z0 = f.loc[0, ["x_m_true", "z_m_true"]]
    height = f.loc[starts, "z_m_true"] - (
        z0 - (f.loc[starts, "x_m_true"] - x0) * np.tan(dip)
    )
    assert np.all(np.abs(height) < 0.6)  # within one frame of a landing
    assert len(track_flights(track, radius_m=0.36)) == 6


def test_synth_track_without_drag_is_exact_parabolas(cli, tmp_path):
    out = tmp_path / "track.csv"
    result = cli(
        "synth", MODEL, "--track", "--noise-m", "0", "--flights", "3",
        "--seed", "1", "-o", out,
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    f = Track.read(out).frame
    for _, g in f.groupby("flight_true"):
        t = g["t_s"].to_numpy()
        coef = np.polyfit(t, g["z_m"], 2)
        assert abs(coef[0] + 4.905) < 1e-5  # z'' = -9.81, x linear: no drag
        assert np.abs(np.polyval(np.polyfit(t, g["x_m"], 1), t) - g["x_m"]).max() < 1e-6


def test_synth_track_refuses_bad_options_without_writing(cli, fails, tmp_path):
    out = tmp_path / "o" / "track.csv"
    fails(cli("synth", MODEL, "--track", "--flights", "0", "-o", out), "--flights")
    fails(cli("synth", MODEL, "--track", "--fps", "-5", "-o", out), "--fps")
    assert not out.exists() and not out.parent.exists()


def test_synth_track_says_which_effects_do_not_act_on_it(cli, repo, tmp_path):
    # issue 17: effects other than air_drag were dropped from a track without a word
    model = repo / "surveys" / "tornado_mountain" / "model_rocfall_table_7_1.json"
    result = cli(
        "synth", model, "--track", "--flights", "2", "--seed", "1",
        "--effects", "mass_loss=rate_per_m=0.01", "-o", tmp_path / "t.csv",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    note = next(line for line in result.stderr.splitlines() if "do not act" in line)
    assert "mass_loss, slope_roughness" in note  # --effects and the model's own
