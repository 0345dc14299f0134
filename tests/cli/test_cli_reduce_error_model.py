"""`fieldkit reduce --position-sigma / --height-sigma`: the survey's error model.

References are independent of the propagation's internals: with one seed the Monte
Carlo draws the same standard normals whatever the sigma, so in the linear regime the
standard uncertainties scale exactly with the sigma; and a tree strike's height moves
only the flight it fixes, so with exact points its error shows at that flight's two
ends and nowhere else.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

#: A slope flattening from about 35° to 22°: 40 m between impacts.
X = np.arange(0.0, 321.0, 40.0)
Z = 300.0 - 0.7 * X + 0.001 * X**2
POINTS = "point,x_m,z_m\n" + "".join(
    f"P{i},{x:.3f},{z:.3f}\n" for i, (x, z) in enumerate(zip(X, Z, strict=True))
)


@pytest.fixture()
def path(tmp_path):
    csv = tmp_path / "path.csv"
    csv.write_text(POINTS)
    return csv


def reduce_table(cli, path, tmp_path, *flags):
    out = tmp_path / f"t{len(list(tmp_path.iterdir()))}.csv"
    r = cli("reduce", "--impacts", path, "--theta0", 30, *flags, "-o", out)
    assert r.exit_code == 0, r.stderr
    return pd.read_csv(out), r.stdout


def test_smaller_position_sigma_smaller_e_n_sd(cli, path, tmp_path):
    small, _ = reduce_table(cli, path, tmp_path, "--position-sigma", 0.1)
    double, _ = reduce_table(cli, path, tmp_path, "--position-sigma", 0.2)
    large, text = reduce_table(cli, path, tmp_path, "--position-sigma", 2.0)
    impacts = slice(1, -1)
    sd_small = small["e_n_sd"].to_numpy()[impacts]
    sd_double = double["e_n_sd"].to_numpy()[impacts]
    sd_large = large["e_n_sd"].to_numpy()[impacts]
    assert np.all(sd_small > 0) and np.all(sd_large > 5 * sd_small)
    # linear regime: the same normals at twice the sigma give twice the sd
    assert sd_double / sd_small == pytest.approx(2.0, rel=0.03)
    for column in ("vi_sd_mps", "vin_sd_mps", "vfn_sd_mps", "theta_i_sd_deg"):
        ratio = double[column].to_numpy()[impacts] / small[column].to_numpy()[impacts]
        assert ratio == pytest.approx(2.0, rel=0.03), column
    assert "2 m in plan and 2 m in height per point (given)" in text


def test_summary_states_the_model_and_the_meaningful_e_n(cli, path, tmp_path):
    table, text = reduce_table(cli, path, tmp_path, "--position-sigma", 0.1)
    assert (
        "uncertainty: position error 0.1 m in plan and 0.1 m in height per point "
        "(given), 0.25 m per tree-strike height (the default), 100 Monte Carlo draws"
        in text
    )
    sd = table["e_n_sd"].to_numpy()
    good = int(np.sum(sd[np.isfinite(sd)] < 0.1))
    total = int(np.isfinite(sd).sum())
    assert total == len(X) - 2
    assert f"e_n is known to better than 0.1 (e_n_sd) at {good} of {total}" in text
    _, text = reduce_table(cli, path, tmp_path)
    assert "0.5 m in plan and 0.5 m in height per point (the default)" in text


def test_tree_strike_height_error_moves_only_its_flight(cli, path, tmp_path):
    trees = tmp_path / "trees.csv"
    # a strike 15 m after P3 at the height the 30° parabola passes (about 6 m)
    trees.write_text("after_impact,horizontal_distance_m,strike_height_m\nP3,15,6\n")
    table, text = reduce_table(
        cli,
        path,
        tmp_path,
        "--trees",
        trees,
        "--position-sigma",
        0,
        "--height-sigma",
        0.3,
    )
    assert "0.3 m per tree-strike height (given)" in text
    vf_sd = table["vf_sd_mps"].to_numpy()
    vi_sd = table["vi_sd_mps"].to_numpy()
    assert vf_sd[3] > 0.05 and vi_sd[4] > 0.05  # the flight P3 -> P4
    others_f = np.delete(vf_sd[:-1], 3)  # vf of P0..P7 without P3
    others_i = np.delete(vi_sd[1:], 3)  # vi of P1..P8 without P4
    assert np.all(others_f < 1e-9) and np.all(others_i < 1e-9)  # rounding only


@pytest.mark.parametrize("flag", ["--position-sigma", "--height-sigma"])
@pytest.mark.parametrize(
    ("value", "words"),
    [
        ("-0.5", ">= 0"),
        ("nan", "finite"),
        ("inf", "finite"),
        ("1e300", "<= 100 m"),  # issue 17: accepted, then overflowed in the draws
    ],
)
def test_bad_sigma_one_line_nothing_written(
    cli, fails, path, tmp_path, flag, value, words
):
    trees = tmp_path / "trees.csv"
    trees.write_text("after_impact,horizontal_distance_m,strike_height_m\nP3,15,6\n")
    out = tmp_path / "t.csv"
    figures = tmp_path / "figs"
    r = cli(
        "reduce",
        "--impacts",
        path,
        "--trees",
        trees,
        "--theta0",
        30,
        flag,
        value,
        "-o",
        out,
        "--figures",
        figures,
    )
    fails(r, flag, words)
    assert not out.exists() and not figures.exists()


def test_height_sigma_needs_trees(cli, fails, path, tmp_path):
    out = tmp_path / "t.csv"
    r = cli("reduce", "--impacts", path, "--theta0", 30, "--height-sigma", 0.1)
    fails(r, "--height-sigma", "--trees")
    assert not out.exists()
