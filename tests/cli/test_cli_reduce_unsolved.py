"""`fieldkit reduce` past a flight it cannot solve, and the error model it records.

A flight with no ballistic solution (issue 18: under the assumed theta0 the next scar
lies above the launch line) is kept as an unsolved flight -- its reason in
``flight_unsolved``, both ends' velocities NaN -- and the rest of the path is reduced;
fit and diagnose leave its two ends out and name them. The reduction records its error
model (``x_sd_m``, ``z_sd_m``, ``strike_height_sd_m``) and the correlation of the
errors of each impact's arrival and rebound (``vin_vfn_corr``, ``vit_vft_corr``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fieldkit.impact_table import ImpactTable
from fieldkit.reduce.uncertainty import DEFAULT_SEED, PositionError, propagate
from fieldkit.viz.section_figure import unsolved_chords

REPO = Path(__file__).resolve().parents[2]
SURVEY = REPO / "surveys" / "tornado_mountain"
G = 9.81

#: Point P2 lies 3 m above P1: under theta0 = 30° on the 31° slope at P1 the flight
#: P1 -> P2 launches at -1° and no ballistic path reaches it.
UPHILL = (
    "point,x_m,z_m,material\nP0,0,100,rock\nP1,10,94,rock\nP2,20,97,rock\n"
    "P3,30,88,rock\nP4,40,80,rock\nP5,50,73,rock\n"
)
BODY = ("--mass", "1000", "--radius", "0.5", "--gyration", "0.3")
VELOCITIES = ["vi_x_mps", "vi_z_mps", "vf_x_mps", "vf_z_mps", "e_n", "e_t"]


def reduce(cli, tmp_path, text, *options, name="p.csv"):
    points = tmp_path / name
    points.write_text(text)
    out = tmp_path / f"{points.stem}_table.csv"
    result = cli("reduce", "--impacts", points, "--theta0", "30", *BODY, "-o", out,
                 *options)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    return pd.read_csv(out, dtype={"point": str}), result


def test_one_impossible_flight_leaves_the_rest_of_the_path_reduced(
    cli, tmp_path, digest
):
    """Rows before the unsolved flight equal the reduction of P0-P1 alone; rows from
    its arrival on equal the reduction of P2-P5 with the slope and theta0 the full
    path used at P2 given (so the flight leaving P2 is the same). Before the fix the
    whole path failed ("point P2: ... no ballistic path")."""
    full, result = reduce(cli, tmp_path, UPHILL)
    assert (tmp_path / "p.csv").read_text() == UPHILL  # input untouched
    reason = full["flight_unsolved"]
    assert reason.notna().tolist() == [False, True, False, False, False, False]
    assert reason[1].startswith("point P2: flight from point P1 to point P2")
    assert "no ballistic path" in reason[1] and "p.csv" not in reason[1]
    # exactly there: P1's rebound and P2's impact unknown, no flight columns for P1
    assert np.isnan(full.loc[1, ["vf_x_mps", "vf_z_mps", "flight_time_s"]]).all()
    assert np.isnan(full.loc[2, ["vi_x_mps", "vi_z_mps"]].to_numpy(float)).all()
    assert np.isfinite(full.loc[1, ["vi_x_mps", "vi_z_mps"]].to_numpy(float)).all()
    assert np.isfinite(full.loc[2, ["vf_x_mps", "vf_z_mps"]].to_numpy(float)).all()

    first, _ = reduce(cli, tmp_path, UPHILL.split("P2,")[0], name="first.csv")
    psi = float(full.loc[2, "slope_deg"])
    assert psi == pytest.approx(-np.degrees(np.arctan2(3.0, 10.0)))
    rest = "".join(UPHILL.splitlines(keepends=True)[3:])
    second_text = "point,x_m,z_m,material,slope_deg,theta0_deg\n" + "".join(
        line.rstrip("\n") + (f",{psi!r},30\n" if i == 0 else ",,\n")
        for i, line in enumerate(rest.splitlines(keepends=True))
    )
    second, _ = reduce(cli, tmp_path, second_text, name="second.csv")
    halves = pd.concat([first[VELOCITIES], second[VELOCITIES]], ignore_index=True)
    np.testing.assert_allclose(
        full[VELOCITIES].to_numpy(float), halves.to_numpy(float), rtol=1e-12
    )

    out = result.stdout
    warning = next(line for line in out.splitlines() if "unsolved" in line and
                   line.startswith("warning:"))  # fmt: skip
    assert "1 of 5 flights has no ballistic solution" in warning
    assert "leaving point P1" in warning and "point P2: flight from" in warning
    assert "not impacts for fit and diagnose" in warning
    assert "flights fixed by assumed 4, unsolved 1" in out
    # correlations: finite in [-1, 1] on the impacts, NaN at the unsolved ends
    corr = full[["vin_vfn_corr", "vit_vft_corr"]].to_numpy(float)
    impacts = np.isfinite(full["e_n"].to_numpy(float))
    assert impacts.tolist() == [False, False, False, True, True, False]
    assert np.isfinite(corr[impacts]).all() and np.isnan(corr[~impacts]).all()
    assert (np.abs(corr[impacts]) <= 1).all()
    assert np.isnan(full["e_n_sd"][~impacts]).all()
    assert (full["x_sd_m"] == 0.5).all() and (full["z_sd_m"] == 0.5).all()
    assert "strike_height_sd_m" not in full  # no tree file


def test_a_tree_no_parabola_reaches_leaves_its_flight_unsolved(cli, tmp_path):
    """The strike 4 m below the chord: that flight unsolved (the tree file's row
    named), the others reduced; the error model records the strike-height sd."""
    points = "point,x_m,z_m\nP0,0,100\nP1,10,94\nP2,20,88\nP3,30,82\nP4,40,76\n"
    trees = tmp_path / "low_tree.csv"
    trees.write_text(
        "after_impact,horizontal_distance_m,strike_height_m,ground_z_m\n"
        "P2,5.0,1.0,80.0\n"
    )  # strike at 81 m, chord there at 85 m
    figures = tmp_path / "figures"
    table, result = reduce(
        cli, tmp_path, points, "--trees", trees, "--height-sigma", "0.3",
        "--figures", figures,
    )  # fmt: skip
    # the figures draw the NaN rows (the unsolved flight as its dotted chord)
    for name in ("section", "en_theta", "et_impacts", "energy_partition"):
        assert f"wrote {figures / name}.png" in result.stdout
    (xs, zs), *others = unsolved_chords(ImpactTable.read(tmp_path / "p_table.csv"))
    assert not others and xs.tolist() == [20.0, 30.0] and zs.tolist() == [88.0, 82.0]
    reason = table["flight_unsolved"]
    assert reason.notna().tolist() == [False, False, True, False, False]
    assert reason[2].startswith("tree row 2: tree strike 1.00 m high")
    assert "no parabola" in reason[2]
    assert table["tree_strike"].tolist()[3] is True  # it still struck a tree
    assert np.isfinite(table["e_n"]).tolist() == [False, True, False, False, False]
    assert (table["strike_height_sd_m"] == 0.3).all()
    assert "1 of 4 flights has no ballistic solution" in result.stdout


def test_every_flight_unsolved_is_an_error(cli, tmp_path, fails, digest):
    points = tmp_path / "two.csv"
    points.write_text("point,x_m,z_m\nP0,0,100\nP1,10,94\n")
    trees = tmp_path / "trees.csv"
    trees.write_text(
        "after_impact,horizontal_distance_m,strike_height_m,ground_z_m\n"
        "P0,5.0,0.5,95.0\n"
    )  # strike at 95.5 m, chord there at 97 m
    before = digest(points), digest(trees)
    out = tmp_path / "t.csv"
    result = cli("reduce", "--impacts", points, "--trees", trees, *BODY, "-o", out)
    fails(result, "trees.csv", "row 2", "no parabola")
    assert not out.exists()
    assert (digest(points), digest(trees)) == before


@pytest.fixture(scope="module")
def boulder_a_with_a_raised_scar(tmp_path_factory):
    """Boulder A's section with scar 8 put 6.9 m higher (row 13, a GNSS height
    error): the flight 7 -> 8 then rises 1.55 m over 10.2 m, above the 4.2° launch
    line of theta0 = 32.6° on the 28.4° slope."""
    from typer.testing import CliRunner

    from fieldkit.cli import app

    folder = tmp_path_factory.mktemp("raised")
    text = (SURVEY / "boulder_a_section.csv").read_text()
    assert "\n8,202.40,197.10,colluvium\n" in text
    points = folder / "raised.csv"
    points.write_text(text.replace("\n8,202.40,197.10,", "\n8,202.40,204.00,"))
    table = folder / "raised_table.csv"
    preset = SURVEY / "boulder_a_preset.toml"
    result = CliRunner().invoke(
        app, ["reduce", "--impacts", str(points), "--preset", str(preset), "-o",
              str(table)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    return table, preset


ROWS_NAMED = (
    "row 1, a release point; row 12, leaves on an unsolved flight; row 13, arrives by "
    "an unsolved flight; row 50, a stop point"
)


def test_fit_leaves_out_and_names_the_ends_of_an_unsolved_flight(
    cli, boulder_a_with_a_raised_scar, tmp_path
):
    table, preset = boulder_a_with_a_raised_scar
    frame = pd.read_csv(table, dtype={"point": str})
    assert frame["flight_unsolved"].notna().to_numpy().nonzero()[0].tolist() == [11]
    model = SURVEY / "model_rocfall_table_7_1.json"
    out = tmp_path / "fit.json"
    result = cli("fit", table, "--model", model, "--preset", preset, "-o", out)
    assert result.exit_code == 0, result.stderr
    text = " ".join((result.stdout + result.stderr).split())
    left = "4 rows left out: no arriving or leaving flight, not an impact"
    assert f"{left} ({ROWS_NAMED})" in text


def test_diagnose_counts_and_names_the_ends_of_an_unsolved_flight(
    cli, boulder_a_with_a_raised_scar, tmp_path
):
    table, preset = boulder_a_with_a_raised_scar
    model = SURVEY / "model_rocfall_table_7_1.json"
    result = cli("diagnose", table, "--model", model, "--preset", preset, "--seed",
                 "1")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    text = " ".join((result.stdout + result.stderr).split())
    assert f"diagnosing 46 impacts (of 50 rows; not impacts: {ROWS_NAMED})" in text


def _least_speed_arrival(dx, dz):
    """Arrival velocity of the slowest ballistic path over ``(dx, dz)``."""
    alpha = np.radians(45.0) + 0.5 * np.arctan2(dz, dx)
    v0 = np.sqrt(G * (np.hypot(dx, dz) + dz))
    vx = v0 * np.cos(alpha)
    return vx, v0 * np.sin(alpha) - G * dx / vx


def test_vin_vfn_correlation_matches_an_independent_monte_carlo(cli, tmp_path):
    """Three points: the impact at P1 arrives by the least-speed launch from P0 and
    leaves at theta0 = 30° to the chord P0-P1 towards P2. vin and vfn are written out
    here with numpy (eq. 3.5) over the reduction's own draws (seed 2004, 0.5 m in
    plan and height per point); their correlation is the table's."""
    text = "point,x_m,z_m\nP0,0,100\nP1,10,94\nP2,22,86\n"
    table, _ = reduce(cli, tmp_path, text)
    x0, z0 = np.array([0.0, 10.0, 22.0]), np.array([100.0, 94.0, 86.0])

    def vin_vfn(x, z):
        vx, vz = _least_speed_arrival(x[..., 1] - x[..., 0], z[..., 1] - z[..., 0])
        psi = np.arctan2(-(z[..., 1] - z[..., 0]), x[..., 1] - x[..., 0])
        vin = vx * np.sin(psi) + vz * np.cos(psi)  # on the ground normal
        alpha = np.radians(30.0) - psi
        dx, dz = x[..., 2] - x[..., 1], z[..., 2] - z[..., 1]
        v0 = np.sqrt(G * dx**2 / (2 * np.cos(alpha) ** 2 * (dx * np.tan(alpha) - dz)))
        return vin, v0 * np.sin(np.radians(30.0))

    vin, vfn = vin_vfn(x0, z0)
    assert table.loc[1, "vin_mps"] == pytest.approx(vin, rel=1e-9)
    assert table.loc[1, "vfn_mps"] == pytest.approx(vfn, rel=1e-9)
    rng = np.random.default_rng(DEFAULT_SEED)
    draws = [
        (x0 + rng.normal(0, 0.5, 3), z0 + rng.normal(0, 0.5, 3)) for _ in range(100)
    ]
    xs, zs = (np.array(d) for d in zip(*draws, strict=True))
    vin_d, vfn_d = vin_vfn(xs, zs)
    expected = np.corrcoef(vin_d, vfn_d)[0, 1]
    assert table.loc[1, "vin_vfn_corr"] == pytest.approx(expected, abs=1e-9)
    assert table.loc[1, "vin_sd_mps"] == pytest.approx(np.std(vin_d, ddof=1), rel=1e-9)
    assert abs(expected) > 0.2  # a real correlation, not a zero by construction


def test_propagate_correlation_of_neighbouring_chords_is_minus_a_half():
    """z1 - z0 and z2 - z1 share z1: correlation -1/2 (variances 2s^2, covariance
    -s^2)."""

    def steps(x, z):
        return {"a": np.full(3, z[1] - z[0]), "b": np.full(3, z[2] - z[1])}

    out = propagate(
        steps,
        [0.0, 1.0, 2.0],
        [0.0, 0.0, 0.0],
        PositionError(0.0, 1.0, draws=4000),
        outputs=("a", "b"),
        correlations=(("a", "b"),),
    )
    assert out.corr["a_b_corr"] == pytest.approx(np.full(3, -0.5), abs=0.03)


@pytest.mark.parametrize(
    ("column", "value", "words"),
    [
        ("vin_vfn_corr", 1.5, "outside [-1, 1]: not a correlation coefficient"),
        ("z_sd_m", -0.5, "outside [0, 1e+07] m: not a standard uncertainty"),
    ],
)
def test_reading_a_table_checks_the_error_model_columns(
    cli, tmp_path, fails, column, value, words
):
    table, _ = reduce(cli, tmp_path, UPHILL)
    table.loc[3, column] = value
    bad = tmp_path / "bad.csv"
    table.to_csv(bad, index=False)
    result = cli("view", bad, "-o", tmp_path / "v.rrd")
    fails(result, "bad.csv", "row 4", f"column {column}", words)
    assert not (tmp_path / "v.rrd").exists()
