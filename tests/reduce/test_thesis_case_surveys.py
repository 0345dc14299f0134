"""The other thesis case studies in surveys/ against the rows that reproduce.

docs/thesis-notes.md: Tables 2-1, 2-2, 2-3 were derived partly from instrument data the
thesis does not give, so only some rows reproduce from coordinates: asphalt #2 (Table
2-5: e_N 0.38, e_T 0.24, V_i 21.5 m/s, theta_i 50° in §2.3) and the Oregon ditch impact
#3 (Table 2-2: e_N 0.24, e_T 0.55). Those are checked to the table's printed precision.

The section files carry the thesis's restitution angle per point as ``theta0_deg``
(theta0 = 180 - alpha_f + psi); the points reader does not keep that column yet, so
this test attaches it from the same file and reduces at library level.
"""

from __future__ import annotations

from dataclasses import replace

import pandas as pd
import pytest

from fieldkit.io.impacts import read_impacts
from fieldkit.physics.bodies import resolve_body
from fieldkit.reduce.pipeline import ReduceOptions, reduce_survey
from fieldkit.survey import Survey


def reduce_section(path, mass_kg):
    points = read_impacts(path)
    given = pd.read_csv(path)["theta0_deg"].to_numpy(float)
    frame = points.frame.copy()
    frame["theta0_deg"] = given
    options = ReduceOptions(path_id=path.stem, body=resolve_body(mass_kg=mass_kg))
    table = reduce_survey(Survey(replace(points, frame=frame), None), options)
    return table.frame.set_index("point")


def test_asphalt_impact_2(repo):
    """Table 2-5 #2 (asphalt, psi 0): e_N 0.38, e_T 0.24; §2.3: V_i 21.5, 50°."""
    t = reduce_section(repo / "surveys" / "asphalt" / "asphalt_section.csv", 500)
    row = t.loc["2"]
    assert row["e_n"] == pytest.approx(0.38, abs=0.005)
    assert row["e_t"] == pytest.approx(0.24, abs=0.005)
    assert row["vi_mps"] == pytest.approx(21.5, abs=0.05)
    assert row["theta_i_deg"] == pytest.approx(50.0, abs=0.5)
    assert row["slope_deg"] == 0.0 and row["slope_source"] == "surveyed"
    # Thesis prints -106,024 J; the printed inputs give -102.3 kJ (not reproducible).
    assert row["dke_j"] == pytest.approx(-102.3e3, rel=0.01)


def test_kreuger_ditch_impact_3_from_a_feet_survey(repo):
    """Table 2-2 #3 (ditch, psi 0): e_N 0.24, e_T 0.55; the file is in feet."""
    t = reduce_section(
        repo / "surveys" / "kreuger_quarry" / "kreuger_section_ft.csv", 580
    )
    assert t.loc["ditch", "x_m"] == pytest.approx(6.25, abs=1e-3)
    assert t.loc["ditch", "e_n"] == pytest.approx(0.24, abs=0.005)
    assert t.loc["ditch", "e_t"] == pytest.approx(0.55, abs=0.005)
    # Not reproducible: the face impact #2 (printed e_N -2.51, e_T 0.59) depends on
    # the unknown flight from the crest; here the least-speed launch gives 2.75, 0.70.
    assert t.loc["face", "theta0_source"] == "given"
    assert t.loc["crest", "theta0_source"] == "assumed"


def test_every_survey_reduces_from_the_command_line(cli, repo, tmp_path):
    """Each shipped survey runs through `fieldkit reduce` (angles assumed, 30°)."""
    surveys = {
        "ehime/cube_section.csv": ("--mass", "520"),
        "asphalt/asphalt_section.csv": ("--mass", "500"),
        "kreuger_quarry/kreuger_section_ft.csv": ("--mass", "580"),
        "mt_stephen/stephen_section.csv": ("--mass", "44"),
    }
    for name, body in surveys.items():
        out = tmp_path / (name.replace("/", "_") + ".csv")
        result = cli(
            "reduce",
            "--impacts",
            repo / "surveys" / name,
            "--theta0",
            "30",
            *body,
            "-o",
            out,
        )
        assert result.exit_code == 0, (name, result.stderr)
        assert len(pd.read_csv(out)) == len(pd.read_csv(repo / "surveys" / name))
