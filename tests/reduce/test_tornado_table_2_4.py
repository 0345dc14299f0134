"""`fieldkit reduce` on the Tornado Mountain survey against thesis Table 2-4.

Reference: Wyllie, Rock fall engineering (thesis), Table 2-4 "Tornado Mountain rock fall
A trajectory from source, fall height 350 m" (§2.2.2), the output of the thesis
spreadsheet (§7.1). Columns typed below: point, alpha_f [deg], psi_s [deg], e_N, e_T,
kinetic energy lost during impact [J]. Thesis conventions: alpha = 180 - alpha_f,
theta0 = alpha + psi (eq. 3.6).

The survey files (surveys/tornado_mountain) are Table 2-4's x, z as GPX waypoints and
one reconstructed tree strike on each flight whose printed alpha_f does not give
theta0 = 32.6° (see that folder's README). The command is the one of issue 2's
"Done when": --theta0 32.6 --mass 3750 --radius 0.725 --gyration 0.46.

Tolerances (issue 2): KE loss within 1 %, e_T within 0.05, e_N within 0.06. Rows that
do not reproduce from the thesis's own printed inputs are listed explicitly with the
reason (docs/thesis-notes.md errata); they are not hidden behind a looser tolerance.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

# point, alpha_f, psi_s, e_N, e_T, dKE [J]   (thesis Table 2-4; "-" = not printed)
TABLE_2_4 = """\
B 213.0 76.7 0.24 0.97 -597368
C 205.0 46.4 0.98 0.74 -636093
D 200.0 36.9 1.12 0.84 -383565
E 185.0 32.0 1.19 0.74 -649674
1 167.6 20.2 1.35 0.35 -968096
2 176.2 28.8 0.78 0.53 -428292
3 177.0 29.6 0.88 0.53 -346394
4 176.4 29.0 1.11 0.60 -227818
5 168.0 30.8 1.23 0.52 -291750
6 177.1 29.7 0.82 0.60 -349399
7 175.8 28.4 0.82 0.48 -396086
8 175.1 27.7 1.29 0.72 -119311
9 176.4 29.0 0.63 0.41 -458078
10 174.9 27.5 1.50 0.79 -42725
11 177.3 29.9 0.90 0.60 -294735
12 174.7 27.3 1.26 0.68 -188389
13 175.7 28.3 0.68 0.44 -498765
14 174.2 26.8 1.10 0.62 -163044
15 175.1 27.7 1.00 0.54 -218672
16 178.3 30.9 0.99 0.62 -195226
17 177.6 30.2 1.46 0.79 -80514
18 178.8 31.4 0.85 0.48 -585150
19 179.6 32.2 1.02 0.65 -312023
20 194.5 29.1 0.59 0.85 -218275
21 175.3 27.9 1.44 0.44 -542278
22 189.0 27.3 0.72 0.60 -259761
23 171.0 33.4 1.36 0.57 -200941
24 173.3 25.9 0.94 0.65 -179329
25 171.7 24.3 0.89 0.53 -224677
26 142.6 24.8 1.29 0.27 -179883
27 172.5 25.1 0.89 1.03 -6012
28 158.0 23.1 1.03 0.42 -248912
29 169.1 21.7 0.78 0.65 -117853
30 166.0 22.2 1.24 0.75 -56926
31 168.0 20.9 1.10 0.67 -114798
32 171.9 24.5 1.00 0.69 -165182
33 174.0 23.4 1.17 0.71 -190159
34 167.3 19.9 0.89 0.48 -296884
35 168.4 21.0 0.95 0.65 -116052
36 145.0 21.2 1.21 0.32 -148602
37 171.0 23.6 0.85 0.92 -29584
38 170.4 23.0 0.90 0.55 -158313
39 171.7 24.3 0.98 0.60 -106242
40 173.2 25.8 0.98 0.76 -71215
41 168.5 21.1 1.24 0.68 -87017
42 171.8 22.9 1.30 1.22 135811
43 164.0 16.6 0.57 0.73 -296779
44 147.4 0.0 0.40 0.12 -
"""

#: Rows whose printed value the thesis's own printed inputs do not reproduce.
#: 22/23 and 32/33: coordinate typos (docs/thesis-notes.md), row 23's psi is not
#: the chord.
TYPOS = {"22", "23", "32", "33"}
NOT_REPRODUCIBLE_KE = {
    **dict.fromkeys(TYPOS, "coordinate typo in Table 2-4 (docs/thesis-notes.md)"),
    "B": "thesis uses free fall from rest, sqrt(2 g 34 m) = 25.8 m/s, at B; no "
    "ballistic path from rest reaches a point 8 m out (least-speed path: -615 kJ "
    "vs -597 kJ printed)",
    "27": "a 6 kJ loss, the difference of two ~185 kJ energies: rounding alpha_f to "
    "0.1° moves it between -5.8 and -6.4 kJ, wider than 1 %",
    "44": "no KE loss printed",
}
NOT_REPRODUCIBLE_ET = {
    **dict.fromkeys(TYPOS, "coordinate typo in Table 2-4"),
    "B": "impact velocity at B taken as free fall from rest (see KE)",
    "E": "recomputes to 0.68 vs 0.74 printed (insensitive to rounding: ±0.005)",
    "42": "recomputes to 1.15 vs 1.22 printed (insensitive to rounding)",
    "43": "recomputes to 0.64 vs 0.73 printed (insensitive to rounding)",
    "44": "recomputes to 0.87 vs 0.12 printed: the last flight (44 -> stop at 45) "
    "is not the one the spreadsheet used",
}
NOT_REPRODUCIBLE_EN = {
    **dict.fromkeys(TYPOS, "coordinate typo in Table 2-4"),
    **dict.fromkeys(
        ["B", "C", "D", "E", "1"],
        "shallow impact (theta_i 7-13°): small v_iN; printed e_N (0.24-1.35) differs "
        "from the recomputed 1.1-4.3 by far more than rounding (±0.02) explains",
    ),
    **dict.fromkeys(
        ["10", "11", "15", "19", "31", "40"],
        "recomputed e_N differs by 0.07-0.15 from the printed value; rounding of the "
        "printed x, z, alpha_f moves it by at most ±0.02",
    ),
    "42": "recomputes to 1.60 vs 1.30 printed",
    "43": "recomputes to 1.12 vs 0.57 printed",
    "44": "recomputes to 1.95 vs 0.40 printed (last flight, see e_T)",
}


def thesis_rows() -> pd.DataFrame:
    rows = []
    for line in TABLE_2_4.strip().splitlines():
        p, af, psi, en, et, dke = line.split()
        rows.append(
            {
                "point": p,
                "alpha_f": float(af),
                "psi": float(psi),
                "e_n": float(en),
                "e_t": float(et),
                "dke": math.nan if dke == "-" else float(dke),
            }
        )
    return pd.DataFrame(rows).set_index("point")


@pytest.fixture(scope="module")
def reduced(repo, tmp_path_factory) -> pd.DataFrame:
    """The issue-2 command, run once through the CLI; the written CSV, by point."""
    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("tornado") / "t.csv"
    folder = repo / "surveys" / "tornado_mountain"
    result = CliRunner().invoke(
        app,
        [
            "reduce",
            "--impacts",
            str(folder / "boulder_a_impacts.gpx"),
            "--trees",
            str(folder / "boulder_a_trees.csv"),
            "--theta0",
            "32.6",
            "--mass",
            "3750",
            "--radius",
            "0.725",
            "--gyration",
            "0.46",
            "-o",
            str(out),
        ],
    )
    assert result.exit_code == 0, result.stderr
    return pd.read_csv(out, dtype={"point": str}).set_index("point")


def _outside(reduced, column, ref, within) -> set[str]:
    table = thesis_rows()
    got = reduced.loc[table.index, column]
    bad = set()
    for point, value in got.items():
        printed = table.loc[point, ref]
        if math.isnan(printed):
            bad.add(point)
        elif not within(value, printed):
            bad.add(point)
    return bad


def test_ke_loss_within_1_percent_for_reproducible_rows(reduced):
    table = thesis_rows()
    rows = [p for p in table.index if p not in NOT_REPRODUCIBLE_KE]
    assert len(rows) == 41  # docs/thesis-notes.md: 41 of 48 rows reproduce
    ratio = reduced.loc[rows, "dke_j"] / table.loc[rows, "dke"]
    assert np.all(np.abs(ratio - 1.0) < 0.01), ratio[np.abs(ratio - 1) >= 0.01]


def test_e_t_within_0_05_for_reproducible_rows(reduced):
    table = thesis_rows()
    rows = [p for p in table.index if p not in NOT_REPRODUCIBLE_ET]
    assert len(rows) == 39  # docs/thesis-notes.md: 39 of 48
    diff = reduced.loc[rows, "e_t"] - table.loc[rows, "e_t"]
    assert np.all(np.abs(diff) <= 0.05), diff[np.abs(diff) > 0.05]


def test_e_n_within_0_06_for_reproducible_rows(reduced):
    table = thesis_rows()
    rows = [p for p in table.index if p not in NOT_REPRODUCIBLE_EN]
    assert len(rows) == 30  # docs/thesis-notes.md: 30 of 48
    diff = reduced.loc[rows, "e_n"] - table.loc[rows, "e_n"]
    assert np.all(np.abs(diff) <= 0.06), diff[np.abs(diff) > 0.06]


def test_listed_rows_are_exactly_the_ones_that_do_not_reproduce(reduced):
    """The exclusion lists are not padding: every listed row really misses."""
    assert _outside(reduced, "dke_j", "dke", lambda v, p: abs(v / p - 1) < 0.01) == set(
        NOT_REPRODUCIBLE_KE
    )
    assert _outside(reduced, "e_t", "e_t", lambda v, p: abs(v - p) <= 0.05) == set(
        NOT_REPRODUCIBLE_ET
    )
    assert _outside(reduced, "e_n", "e_n", lambda v, p: abs(v - p) <= 0.06) == set(
        NOT_REPRODUCIBLE_EN
    )


def test_impact_26_matches_the_thesis_detail(reduced):
    """§2.2.2 / Fig. 2.8: at #A26 the tree-defined theta_i = 22°, e_N 1.29, e_T 0.27."""
    row = reduced.loc["26"]
    assert row["theta0_source"] == "tree"  # the flight leaving 26 struck a tree
    assert reduced.loc["27", "tree_strike"]
    assert abs(row["theta_i_deg"] - 22.0) < 0.5
    assert abs(row["e_n"] - 1.29) <= 0.02
    assert abs(row["e_t"] - 0.27) <= 0.02


def test_theta0_is_assumed_or_from_the_tree_strike(reduced):
    """Assumed flights use exactly 32.6°; tree flights recover the thesis's alpha_f."""
    table = thesis_rows()
    assumed = reduced[reduced["theta0_source"] == "assumed"].drop(index="A")
    assert np.allclose(assumed["theta0_deg"], 32.6)
    tree = reduced[reduced["theta0_source"] == "tree"]
    assert len(tree) == 15
    alpha = tree["theta0_deg"] - tree["slope_deg"]
    # Tree position to 0.1 m and height to 0.01 m: alpha back within 0.2°.
    assert np.allclose(alpha, 180.0 - table.loc[tree.index, "alpha_f"], atol=0.2)
    arriving = reduced["tree_strike"].fillna(False).astype(bool)
    assert arriving.sum() == 15


def test_energy_in_flight_is_conserved(reduced):
    """KE gained in each flight is m g times the drop (drag-free flight, eq. 3.1)."""
    z = reduced["z_m"].to_numpy()
    expected = 3750 * 9.81 * (z[:-1] - z[1:])
    np.testing.assert_allclose(
        reduced["flight_dke_j"].to_numpy()[1:], expected, rtol=1e-9
    )
    assert math.isnan(reduced["flight_dke_j"].iloc[0])


def test_source_and_stop_are_not_invented(reduced):
    first, last = reduced.iloc[0], reduced.iloc[-1]
    assert math.isnan(first["vi_x_mps"]) and math.isnan(first["e_n"])
    assert math.isnan(last["vf_x_mps"]) and math.isnan(last["e_t"])
    assert math.isnan(last["flight_time_s"])
    assert np.isfinite(reduced["e_n"].iloc[1:-1]).all()


def test_spin_is_v_over_r_and_constant_in_flight(reduced):
    """Eq. 3.17: omega_0 = V_0 / r, clockwise (negative) for travel toward +x."""
    omega_f = reduced["omega_f_radps"].to_numpy()[:-1]
    np.testing.assert_allclose(omega_f, -reduced["vf_mps"].to_numpy()[:-1] / 0.725)
    np.testing.assert_allclose(reduced["omega_i_radps"].to_numpy()[1:], omega_f)
    assert set(reduced["omega_source"]) == {"estimated"}
    re_f = 0.5 * 3750 * 0.46**2 * omega_f**2
    np.testing.assert_allclose(reduced["re_f_j"].to_numpy()[:-1], re_f)


def test_flight_heights_and_times(reduced):
    """Flight columns describe the flight leaving each point; h' = h cos(chord)."""
    dx = np.diff(reduced["x_m"].to_numpy())
    dz = np.diff(reduced["z_m"].to_numpy())
    np.testing.assert_allclose(reduced["flight_length_m"].to_numpy()[:-1], dx)
    np.testing.assert_allclose(
        reduced["flight_time_s"].to_numpy()[:-1],
        dx / reduced["vf_x_mps"].to_numpy()[:-1],
    )
    ratio = (
        reduced["hmax_normal_m"].to_numpy()[:-1]
        / reduced["hmax_vertical_m"].to_numpy()[:-1]
    )
    np.testing.assert_allclose(ratio, dx / np.hypot(dx, dz))
    # Thesis §2.2.2: average normal trajectory height about 1.3 m (impacts 1-44).
    mean = reduced.loc[[str(i) for i in range(1, 45)], "hmax_normal_m"].mean()
    assert 1.0 < mean < 2.0


def test_colluvium_averages_match_section_2_2_2(reduced):
    """§2.2.2: mean e_N 1.02 and e_T 0.65 over the colluvium impacts of boulders A and
    B (114 impacts); boulder A's impacts 1-42 alone must land close to both."""
    colluvium = reduced.loc[[str(i) for i in range(1, 43)]]
    assert colluvium["e_n"].mean() == pytest.approx(1.02, abs=0.05)
    assert colluvium["e_t"].mean() == pytest.approx(0.65, abs=0.05)
