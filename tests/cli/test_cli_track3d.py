"""`fieldkit track3d`: 3-D trajectories sampled from the 3-D simulator (exact truth:
its impact rows) at 100 and 200 Hz with 2 cm Gaussian noise per coordinate, reduced
on the DEM they were simulated on. Every impact is found (none extra), e_n and e_t
within 0.05, the lateral deflection within 2 deg; a flight bent in mid-air is a
misfit, never an impact; bad input is one line and writes nothing."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fieldkit.impact_table import ImpactTable
from fieldkit.tracking.trajectory3d.synthetic import (
    VALLEY_MASS_KG as MASS_KG,
)
from fieldkit.tracking.trajectory3d.synthetic import (
    VALLEY_RADIUS_M as RADIUS_M,
)
from fieldkit.tracking.trajectory3d.synthetic import (
    valley_runs,
    write_site,
)

NOISE_SD_M = 0.02


def simulated_runs(fps: float, seed: int = 2, rocks: int = 8):
    """Runs of the 3-D simulator on the analytic valley (e_n 0.6, e_t 0.85),
    sampled at ``fps`` with 2 cm noise."""
    return valley_runs(fps=fps, noise_sd_m=NOISE_SD_M, rocks=rocks, seed=seed)


def match(found: pd.DataFrame, truth: pd.DataFrame, window_s: float = 0.02):
    """(pairs of row indices, missed truth rows, extra found rows) by run and time."""
    pairs, missed = [], []
    used = set()
    for i, row in truth.iterrows():
        same = found[(found["path_id"] == row["path_id"])]
        d = (same["t_s"] - row["t_s"]).abs()
        if len(d) and d.min() <= window_s:
            j = d.idxmin()
            pairs.append((i, j))
            used.add(j)
        else:
            missed.append(i)
    return pairs, missed, [j for j in found.index if j not in used]


@pytest.mark.parametrize("fps", [100.0, 200.0])
def test_every_impact_found_with_en_et_lateral_recovered(cli, tmp_path, fps):
    terrain, runs = simulated_runs(fps)
    assert len(runs) >= 6
    samples, dem = write_site(tmp_path, terrain, runs)
    out = tmp_path / "out" / "impacts.csv"
    result = cli("track3d", samples, "--dem", dem, "--radius", RADIUS_M,
                 "--mass", MASS_KG, "-o", out)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert f"wrote {out}" in result.stdout
    assert "no air drag" in result.stderr
    assert "disc of radius 0.2 m (the block radius)" in result.stderr
    assert "0 misfits" in result.stdout and "misfit" not in result.stderr
    found = ImpactTable.read(out).frame
    truth = pd.concat([r.truth for r in runs], ignore_index=True)
    pairs, missed, extra = match(found, truth)
    assert not missed and not extra and len(pairs) == len(truth) >= 18
    t_idx, f_idx = map(list, zip(*pairs, strict=True))
    t, f = truth.loc[t_idx].reset_index(), found.loc[f_idx].reset_index()
    assert np.abs(f["e_n"] - t["e_n"]).max() <= 0.05
    assert np.abs(f["e_t"] - t["e_t"]).max() <= 0.05
    assert np.abs(f["lateral_deg"] - t["lateral_deg"]).max() <= 2.0
    assert np.ptp(t["lateral_deg"]) > 20.0  # the deflections are real, both ways
    # the stated uncertainties (from the noise through the flights' fits) match
    # the errors: median |error| / SD near a normal's 0.67
    for name, sd in (("e_n", "e_n_sd"), ("e_t", "e_t_sd"),
                     ("lateral_deg", "lateral_sd_deg")):  # fmt: skip
        z = np.abs(f[name] - t[name]) / f[sd]
        assert 0.3 < np.median(z) < 1.2, (name, np.median(z))
    # the same convention as the simulator's rows: N, T and the dip agree (to
    # 1e-9 inside a DEM patch; where the footprint disc straddles a patch edge the
    # plane averages the two patches' slopes, the simulator takes one side's)
    for c in ("normal_x", "normal_y", "normal_z", "tangent_x", "tangent_y"):
        assert np.abs(f[c] - t[c]).max() < 0.03, c
        assert np.median(np.abs(f[c] - t[c])) < 0.005, c
    assert np.abs(f["dip_deg"] - t["dip_deg"]).max() < 1.0
    # ... and the other columns of the simulator's rows, column by column
    for name, tol in (("t_s", 0.005), ("x_m", 0.05), ("y_m", 0.05), ("z_m", 0.05),
                      ("slope_deg", 1.0), ("vi_mps", 0.15), ("vf_mps", 0.15),
                      ("vin_mps", 0.15), ("vfn_mps", 0.15), ("vit_mps", 0.15),
                      ("vft_mps", 0.15), ("theta_i_deg", 1.0),
                      ("energy_head_i_m", 0.1)):  # fmt: skip
        assert np.abs(f[name] - t[name]).max() < tol, name
    # the lumped-mass contact is on the DEM: within a few noise SDs of the plane
    assert np.abs(f["contact_height_m"]).max() < 3 * NOISE_SD_M
    assert (f["surface_footprint_m"] == RADIUS_M).all()
    assert f["contact_duration_s"].isna().all()  # instantaneous contacts
    # chainage: plan distance from the release (the first sample is < 1/fps later)
    for run in runs:
        tr = run.truth
        pid = tr["path_id"].iloc[0]
        s = run.samples
        xy = np.r_[[[s["x_m"].iloc[0], s["y_m"].iloc[0]]], tr[["x_m", "y_m"]]]
        expected = np.cumsum(np.hypot(*np.diff(xy, axis=0).T))
        got = found.loc[found["path_id"] == pid, "chainage_m"].to_numpy()
        np.testing.assert_allclose(got, expected, atol=0.15)
    # spin is in the data: measured
    assert (f["omega_source"] == "measured").all()
    np.testing.assert_allclose(f["omega_f_radps"], t["omega_f_radps"], atol=1e-9)


def test_a_flight_bent_in_mid_air_is_a_misfit_not_an_impact(cli, tmp_path):
    """A sideways push of 2 m/s halfway through a run's second flight (no flight is
    ballistic across it) splits the flight in mid-air: reported as a misfit, with
    its height; the run's true impacts are still found and nothing is added."""
    terrain, runs = simulated_runs(200.0)
    run = runs[0]
    tr = run.truth
    s = run.samples.copy()
    t_kick = 0.5 * (tr["t_s"].iloc[0] + tr["t_s"].iloc[1])
    late = s["t_s"] > t_kick
    s.loc[late, "y_m"] += 2.0 * np.minimum(s.loc[late, "t_s"] - t_kick,
                                           tr["t_s"].iloc[1] - t_kick)  # fmt: skip
    run = type(run)(s, tr.iloc[:1])  # impacts after the push moved: keep the first
    samples, dem = write_site(tmp_path, terrain, [run])
    result = cli("track3d", samples, "--dem", dem, "--radius", RADIUS_M,
                 "-o", tmp_path / "i.csv")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "a mid-air split, not an impact" in result.stderr
    assert "1 misfits" in result.stdout
    found = ImpactTable.read(tmp_path / "i.csv").frame
    pairs, missed, extra = match(found, tr)
    assert not missed and not extra and len(found) == len(tr)


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda s: s.replace(s.splitlines()[5].split(",")[4], "abc", 1),
         ["trajectories.csv", "row 6", "z_m", "abc"]),
        (lambda s: "\n".join(s.splitlines()[:1] + s.splitlines()[1:][::-1]),
         ["trajectories.csv", "row 3", "t_s", "increase"]),
        (lambda s: s.replace("y_m", "north", 1), ["trajectories.csv", "y_m"]),
    ],
)  # fmt: skip
def test_bad_samples_are_one_line_and_write_nothing(cli, fails, tmp_path, digest,
                                                    edit, words):  # fmt: skip
    terrain, runs = simulated_runs(100.0, rocks=2)
    samples, dem = write_site(tmp_path, terrain, runs[:1])
    samples.write_text(edit(samples.read_text()))
    before = digest(samples)
    out = tmp_path / "out" / "impacts.csv"
    fails(cli("track3d", samples, "--dem", dem, "--radius", RADIUS_M, "-o", out),
          *words)  # fmt: skip
    assert not out.exists() and not out.parent.exists()
    assert digest(samples) == before


def test_a_trajectory_off_the_dem_is_refused(cli, fails, tmp_path):
    """Samples in other coordinates than the DEM (shifted 5 km): one line naming
    the file, the trajectory's first row and the DEM's extent; nothing written."""
    terrain, runs = simulated_runs(100.0, rocks=2)
    run = runs[0]
    s = run.samples.copy()
    s["x_m"] += 5000.0
    samples, dem = write_site(tmp_path, terrain, [type(run)(s, run.truth)])
    out = tmp_path / "out.csv"
    fails(cli("track3d", samples, "--dem", dem, "--radius", RADIUS_M, "-o", out),
          "trajectories.csv", "row 2", "no sample lies over the DEM",
          "same coordinates")  # fmt: skip
    assert not out.exists()


def test_no_dem_no_radius(cli, fails, tmp_path):
    terrain, runs = simulated_runs(100.0, rocks=2)
    samples, dem = write_site(tmp_path, terrain, runs[:1])
    fails(cli("track3d", samples, "--radius", RADIUS_M), "--dem")
    fails(cli("track3d", samples, "--dem", dem), "--radius")


def test_a_contact_the_sampling_resolves_has_its_duration(cli, tmp_path):
    """The block rests 60 ms at its first impact point (12 samples at 200 Hz)
    before leaving as the simulator says: the contact's duration is measured
    (within one sampling interval), its e_n and e_t are still the truth's; the
    instantaneous contacts keep an empty duration."""
    terrain, runs = simulated_runs(200.0)
    run = runs[0]
    tr = run.truth.reset_index(drop=True)
    s = run.samples.copy()
    t1, rest = float(tr["t_s"].iloc[0]), 0.06
    s.loc[s["t_s"] > t1, "t_s"] += rest
    still = np.arange(t1 + 0.0025, t1 + rest, 1 / 200.0)
    rng = np.random.default_rng(5)
    xyz = tr[["x_m", "y_m", "z_m"]].iloc[0].to_numpy() + rng.normal(
        0.0, NOISE_SD_M, (still.size, 3)
    )
    pad = pd.DataFrame({"path_id": s["path_id"].iloc[0], "t_s": still,
                        "x_m": xyz[:, 0], "y_m": xyz[:, 1], "z_m": xyz[:, 2],
                        "omega_radps": 0.0})  # fmt: skip
    s = pd.concat([s, pad]).sort_values("t_s")
    truth = tr.copy()
    truth.loc[1:, "t_s"] += rest
    samples, dem = write_site(tmp_path, terrain, [type(run)(s, truth)])
    out = tmp_path / "i.csv"
    result = cli("track3d", samples, "--dem", dem, "--radius", RADIUS_M, "-o", out)
    assert result.exit_code == 0, result.stderr
    assert "contact_duration_s: 1 of 3 impacts resolved" in result.stderr
    found = ImpactTable.read(out).frame
    pairs, missed, extra = match(found, truth)
    assert not missed and not extra
    first = found.iloc[0]
    assert first["contact_duration_s"] == pytest.approx(rest, abs=1 / 200.0)
    assert first["t_s"] == pytest.approx(t1, abs=1 / 200.0)
    assert first["e_n"] == pytest.approx(truth["e_n"].iloc[0], abs=0.05)
    assert first["e_t"] == pytest.approx(truth["e_t"].iloc[0], abs=0.05)
    assert found["contact_duration_s"].iloc[1:].isna().all()


def test_a_non_spherical_block_gives_its_gyration(cli, tmp_path):
    """Block dimensions (--shape ellipsoid --dimensions) set the rows' radius of
    gyration (and so the rotational energies), as for `track` and `reduce`."""
    terrain, runs = simulated_runs(100.0, rocks=2)
    samples, dem = write_site(tmp_path, terrain, runs[:1])
    out = tmp_path / "i.csv"
    result = cli("track3d", samples, "--dem", dem, "--shape", "ellipsoid",
                 "--dimensions", "0.6,0.4,0.4", "--radius", RADIUS_M,
                 "--mass", MASS_KG, "-o", out)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    f = ImpactTable.read(out).frame
    # ellipsoid rotating about c: k^2 = (a^2 + b^2) / 5 with a = 0.3, b = 0.2 m
    assert f["gyration_m"].iloc[0] == pytest.approx(np.sqrt((0.09 + 0.04) / 5))
    assert "solid sphere" not in result.stderr


def test_air_drag_off_splits_in_mid_air_on_gives_the_impacts(cli, tmp_path):
    """A bouncing mass with strong quadratic air drag (k = 0.03 1/m, 200 Hz, 2 cm
    noise; its truth integrated directly). Ballistic flights (the default) split
    it in mid-air: those joins are misfits naming air_drag, never impacts, so only
    the true impacts are rows. With --air-drag 0.03 there is no misfit and e_n,
    e_t, the lateral deflection are recovered within 0.05, 0.05 and 2 deg."""
    from fieldkit.tracking.trajectory3d.synthetic import drag_run

    terrain, _ = simulated_runs(100.0, rocks=1)
    run = drag_run(terrain, [5.5, 28.0, 101.0], [8.0, 1.0, 3.0], drag_per_m=0.03,
                   e_n=0.6, e_t=0.85, impacts=3, fps=200.0, noise_sd_m=NOISE_SD_M,
                   rng=np.random.default_rng(0))  # fmt: skip
    samples, dem = write_site(tmp_path, terrain, [run])
    plain = cli("track3d", samples, "--dem", dem, "--radius", RADIUS_M,
                "-o", tmp_path / "plain.csv")  # fmt: skip
    assert plain.exit_code == 0, plain.stderr
    assert "no air drag (--air-drag 0, the default)" in plain.stderr
    assert plain.stderr.count("a mid-air split, not an impact") >= 3
    assert "try air_drag" in plain.stderr
    found = ImpactTable.read(tmp_path / "plain.csv").frame
    pairs, missed, extra = match(found, run.truth)
    assert not extra  # a split in mid-air is never an impact
    dragged = cli("track3d", samples, "--dem", dem, "--radius", RADIUS_M,
                  "--air-drag", "0.03", "-o", tmp_path / "drag.csv")  # fmt: skip
    assert dragged.exit_code == 0, dragged.stderr
    assert "quadratic air drag k = 0.03 1/m" in dragged.stderr
    assert "0 misfits" in dragged.stdout
    found = ImpactTable.read(tmp_path / "drag.csv").frame
    pairs, missed, extra = match(found, run.truth)
    assert not missed and not extra and len(pairs) == 3
    t = run.truth.reset_index(drop=True)
    np.testing.assert_allclose(found["e_n"], t["e_n"], atol=0.05)
    np.testing.assert_allclose(found["e_t"], t["e_t"], atol=0.05)
    np.testing.assert_allclose(found["lateral_deg"], t["lateral_deg"], atol=2.0)


def test_a_spin_vector_gives_the_spin_about_the_axis_across_travel(cli, tmp_path):
    """Angular velocity vectors (omega_x/y/z_radps) instead of a scalar: at each
    impact the spin is -w . (N x T); a block rolling without slip toward T at the
    rebound (w = vft/r along N x T) gives omega_f = -vft/r, the ImpactTable's
    rolling sign; before the first impact it does not spin."""
    terrain, runs = simulated_runs(200.0, rocks=2)
    run = runs[0]
    tr = run.truth.reset_index(drop=True)
    s = run.samples.drop(columns="omega_radps")
    w = np.zeros((len(s), 3))
    for _, row in tr.iterrows():
        n = row[["normal_x", "normal_y", "normal_z"]].to_numpy(float)
        tang = row[["tangent_x", "tangent_y", "tangent_z"]].to_numpy(float)
        w[s["t_s"].to_numpy() > row["t_s"]] = (row["vft_mps"] / RADIUS_M
                                               * np.cross(n, tang))  # fmt: skip
    for c, name in enumerate(("omega_x_radps", "omega_y_radps", "omega_z_radps")):
        s[name] = w[:, c]
    samples, dem = write_site(tmp_path, terrain, [type(run)(s, tr)])
    out = tmp_path / "i.csv"
    result = cli("track3d", samples, "--dem", dem, "--radius", RADIUS_M, "-o", out)
    assert result.exit_code == 0, result.stderr
    assert "omega = -w . (N x T)" in result.stderr
    f = ImpactTable.read(out).frame
    assert f["omega_i_radps"].iloc[0] == 0.0
    rolling = -tr["vft_mps"] / RADIUS_M
    np.testing.assert_allclose(f["omega_f_radps"], rolling, rtol=0.02)
    assert (f["omega_source"] == "measured").all()
