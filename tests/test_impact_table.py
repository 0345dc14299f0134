"""ImpactTable contract: required columns, derivation conventions, file round trips."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fieldkit.errors import InputFileError
from fieldkit.impact_table import CONTRACT_COLUMNS, REQUIRED_COLUMNS, ImpactTable
from fieldkit.physics.local_axes import to_local, to_section


def _table(**over):
    base = {
        "path_id": ["A", "A"],
        "point": ["1", "2"],
        "x_m": [0.0, 10.0],
        "z_m": [10.0, 5.0],
        "slope_deg": [30.0, 30.0],
        "vi_x_mps": [5.0, 6.0],
        "vi_z_mps": [-8.0, -7.0],
        "vf_x_mps": [4.0, 5.0],
        "vf_z_mps": [1.0, 2.0],
        "mass_kg": [100.0, 100.0],
        "gyration_m": [0.3, 0.3],
        "omega_i_radps": [-2.0, np.nan],
        "omega_f_radps": [-5.0, np.nan],
    }
    base.update(over)
    return ImpactTable(pd.DataFrame(base))


def test_columns_in_contract_order_and_extras_kept():
    t = _table(my_note=["a", "b"])
    names = [c.name for c in CONTRACT_COLUMNS]
    assert list(t.frame.columns[: len(names)]) == names
    assert t.frame.columns[-1] == "my_note"


def test_derive_matches_hand_decomposition():
    t = _table().derive().frame
    psi = np.radians(30.0)
    # T = (cos psi, -sin psi), N = (sin psi, cos psi)
    vit = 5.0 * np.cos(psi) + 8.0 * np.sin(psi)
    vin = 5.0 * np.sin(psi) - 8.0 * np.cos(psi)
    vft = 4.0 * np.cos(psi) - 1.0 * np.sin(psi)
    vfn = 4.0 * np.sin(psi) + 1.0 * np.cos(psi)
    assert t.loc[0, "vin_mps"] < 0 < t.loc[0, "vfn_mps"]
    assert t.loc[0, "e_n"] == pytest.approx(-vfn / vin, rel=1e-12)
    assert t.loc[0, "e_t"] == pytest.approx(vft / vit, rel=1e-12)
    assert t.loc[0, "theta_i_deg"] == pytest.approx(np.degrees(np.arctan(-vin / vit)))
    assert t.loc[0, "ke_i_j"] == pytest.approx(0.5 * 100 * (25 + 64))
    assert t.loc[0, "re_f_j"] == pytest.approx(0.5 * 100 * 0.09 * 25)
    assert np.isnan(t.loc[1, "re_i_j"])  # no spin measured: no rotational energy
    assert t.loc[0, "energy_head_i_m"] == pytest.approx(10 + 89 / (2 * 9.81))


def test_local_axes_round_trip():
    rng = np.random.default_rng(1)
    vx, vz, psi = rng.normal(size=(3, 50)) * [[10], [10], [40]]
    assert np.allclose(to_section(*to_local(vx, vz, psi), psi), (vx, vz))
    # speed is preserved by the rotation
    assert np.allclose(np.hypot(*to_local(vx, vz, psi)), np.hypot(vx, vz))


@pytest.mark.parametrize("ext", [".csv", ".parquet", ".xlsx"])
def test_file_round_trip(tmp_path, ext):
    t = _table(material=["rock", "talus"], tree_strike=[True, False]).derive()
    path = t.write(tmp_path / f"t{ext}")
    back = ImpactTable.read(path)
    assert list(back.frame.columns) == list(t.frame.columns)
    assert back.frame["point"].tolist() == ["1", "2"]
    assert np.allclose(back.column("e_n"), t.column("e_n"))
    assert back.frame["tree_strike"].tolist() == [True, False]


def test_missing_required_column_is_named():
    frame = _table().frame.drop(columns=["vf_z_mps"])
    with pytest.raises(InputFileError, match="vf_z_mps"):
        ImpactTable(frame, source="t.csv")
    assert "vf_z_mps" in REQUIRED_COLUMNS


def test_bad_values_name_the_row(tmp_path):
    with pytest.raises(
        InputFileError, match=r"row 2: column x_m: 'abc' is not a number"
    ):
        _table(x_m=["0", "abc"])
    with pytest.raises(InputFileError, match=r"row 2: duplicated point 1"):
        _table(point=["1", "1"])
    with pytest.raises(InputFileError, match="theta0_source"):
        _table(theta0_source=["tree", "guess"])
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(InputFileError, match="empty.csv: file is empty"):
        ImpactTable.read(tmp_path / "empty.csv")
    with pytest.raises(InputFileError, match="unknown table format"):
        _table().write(tmp_path / "t.txt")
    assert not (tmp_path / "t.txt").exists()


def test_outputs_get_normal_permissions(tmp_path):
    import os

    mask = os.umask(0o022)
    try:
        path = _table().write(tmp_path / "t.csv")
    finally:
        os.umask(mask)
    assert path.stat().st_mode & 0o777 == 0o644
    assert [p.name for p in tmp_path.iterdir()] == ["t.csv"]  # no temporary left


# ------------------------------------------------------------------ quality flags
def _flags(**over):
    return _table(**over).derive().frame["qa_flags"].tolist()


def test_every_flag_has_a_meaning_and_derive_fills_the_column():
    from fieldkit.impact_table import QA_FLAGS

    assert all(name.isidentifier() and text for name, text in QA_FLAGS.items())
    assert "qa_flags" in [c.name for c in CONTRACT_COLUMNS]
    assert _flags() == [pd.NA, pd.NA]  # a clean table: no flag, not an empty string


@pytest.mark.parametrize(
    ("over", "row", "flag"),
    [
        # restitution speed 10.3 > impact speed 9.4
        ({"vf_x_mps": [10.0, 5.0], "vf_z_mps": [2.5, 2.0]}, 0, "energy_gained"),
        # rebound into the ground: vfn < 0
        ({"vf_x_mps": [4.0, 5.0], "vf_z_mps": [-6.0, 2.0]}, 0, "e_n_negative"),
        # tangential speed grows: e_t > 1
        ({"vf_x_mps": [12.0, 5.0], "vf_z_mps": [0.0, 2.0]}, 0, "e_t_above_1"),
        ({"vi_x_mps": [5.0, 50.0], "vi_z_mps": [-8.0, -40.0]}, 1, "speed_high"),
        ({"hmax_normal_m": [1.5, 10.5]}, 1, "flight_high"),
        ({"slope_source": ["surveyed", "chord"]}, 1, "slope_from_chord"),
        ({"omega_source": ["estimated", "measured"]}, 0, "spin_estimated"),
        (
            {"e_n_next_chord": [0.9, 0.9], "e_n_sd": [0.05, 5.0]},
            0,
            "slope_sensitive",
        ),
    ],
)
def test_each_flag_is_raised_by_its_own_condition(over, row, flag):
    flags = _flags(**over)
    assert flag in str(flags[row]).split(";")
    assert flag not in str(flags[1 - row]).split(";")


def test_flags_need_known_values_and_keep_a_producers_own():
    t = _table(
        vi_x_mps=[np.nan, 6.0],
        vi_z_mps=[np.nan, -7.0],
        slope_source=["chord", "chord"],
        slope_deg=[np.nan, 30.0],
        omega_source=["estimated", "estimated"],
        omega_i_radps=[np.nan, np.nan],
        omega_f_radps=[np.nan, -3.0],
        qa_flags=["few_frames;energy_gained", pd.NA],
    ).derive()
    flags = t.frame["qa_flags"].tolist()
    # row 1 has no impact velocity, no slope and no spin: nothing to flag but the
    # producer's own; its stale energy_gained is recomputed away
    assert flags[0] == "few_frames"
    assert flags[1] == "slope_from_chord;spin_estimated"


def test_limits_are_the_documented_ones():
    from fieldkit.impact_table import (
        MAX_PLAUSIBLE_FLIGHT_HEIGHT_M,
        MAX_PLAUSIBLE_SPEED_MPS,
    )

    at = _flags(
        vi_x_mps=[5.0, MAX_PLAUSIBLE_SPEED_MPS],
        vi_z_mps=[-8.0, 0.0],
        hmax_normal_m=[MAX_PLAUSIBLE_FLIGHT_HEIGHT_M, 0.0],
    )
    assert "speed_high" not in str(at) and "flight_high" not in str(at)


def test_qa_flags_survive_a_file_round_trip(tmp_path):
    t = _table(vf_x_mps=[10.0, 5.0], vf_z_mps=[2.5, 2.0]).derive()
    back = ImpactTable.read(t.write(tmp_path / "t.csv")).derive()
    assert back.frame["qa_flags"].tolist() == t.frame["qa_flags"].tolist()


def test_quality_flags_match_the_row_by_row_rule_on_a_mixed_table():
    """The vectorised flags equal the definition: raised flags in QA_FLAGS order, then
    a producer's own flags (kept, deduplicated), NA when none."""
    from fieldkit.impact_table import QA_FLAGS, quality_flags

    rng = np.random.default_rng(4)
    n = 500
    frame = pd.DataFrame(
        {
            "vi_mps": rng.uniform(0, 70, n),
            "vf_mps": rng.uniform(0, 70, n),
            "e_n": rng.uniform(-0.2, 1, n),
            "e_t": rng.uniform(0, 1.2, n),
            "qa_flags": rng.choice(
                [None, "", "mine", "e_n_negative;mine; mine", " ; ", "x;y"], n
            ),
        }
    )
    got = quality_flags(frame).tolist()
    for i in range(n):
        raised = []
        if frame.vf_mps[i] ** 2 > frame.vi_mps[i] ** 2 * (1 + 1e-6):
            raised.append("energy_gained")
        if frame.e_n[i] < 0:
            raised.append("e_n_negative")
        if frame.e_t[i] > 1 + 1e-9:
            raised.append("e_t_above_1")
        if max(frame.vi_mps[i], frame.vf_mps[i]) > 60:
            raised.append("speed_high")
        given = frame.qa_flags[i] if isinstance(frame.qa_flags[i], str) else ""
        own = [p.strip() for p in given.split(";") if p.strip()]
        names = list(dict.fromkeys(raised + [p for p in own if p not in QA_FLAGS]))
        expected = ";".join(names) or None
        assert (got[i] if got[i] is not pd.NA else None) == expected, i
