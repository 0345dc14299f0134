"""Bad input to the library's diagnosis raises InputFileError, in one line."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from diagnose_cases import SMOKE, hidden_table

from fieldkit.diagnose.impacts import MIN_GROUPS, diagnose_impacts
from fieldkit.errors import InputFileError
from fieldkit.impact_table import ImpactTable
from fieldkit.model.model_file import model_from_dict


@pytest.fixture(scope="module")
def frame() -> pd.DataFrame:
    return hidden_table((), noise=0.05, paths=12, seed=0).frame.copy()


def _fails(table: ImpactTable, *words: str, model=None) -> str:
    with pytest.raises(InputFileError) as err:
        diagnose_impacts(table, model, rng=np.random.default_rng(0))
    text = str(err.value)
    assert "\n" not in text
    for word in words:
        assert word in text, (word, text)
    return text


def test_missing_columns_are_named(frame):
    table = ImpactTable(frame.drop(columns=["material", "radius_m"]), source="t.csv")
    text = _fails(table, "missing column(s)", "material", "radius_m")
    assert text.startswith("t.csv: ")


def test_non_finite_values_name_the_rows(frame):
    bad = frame.copy()
    bad.loc[[2, 6], "vf_x_mps"] = np.nan
    _fails(ImpactTable(bad, source="t.csv"), "vf_x_mps", "rows 3, 7", "finite")
    bad = frame.copy()
    bad.loc[4, "slope_deg"] = np.inf
    _fails(ImpactTable(bad, source="t.csv"), "slope_deg", "row 5")


def test_too_few_groups_says_how_many_are_needed(frame):
    # one path of two impacts: two blocks, fewer than the three a jackknife needs
    two = ImpactTable(frame.iloc[:2].assign(path_id="A"), source="t.csv")
    _fails(
        two,
        "too few impacts",
        "2 independent group(s)",
        f"need at least {MIN_GROUPS}",
    )


def test_too_few_impacts_per_training_fold_says_how_many(frame):
    # four impacts on three materials: each training fold holds three impacts
    # (9 data) for 3 x 2 material parameters + 6 effect parameters (4 of the
    # laws, 2 of affine_rebound) = 12; 12 parameters / 3 data per impact -> at
    # least 5 impacts
    rows = []
    for material in ("rock", "talus", "soil"):
        rows.append(frame[frame["material"] == material].index[0])
    rows.append(frame[frame["material"] == "talus"].index[1])
    few = frame.loc[rows].reset_index(drop=True)
    text = _fails(ImpactTable(few, source="t.csv"), "too few impacts to fit")
    assert "9 data for 12 parameters" in text
    assert "at least 5 impacts" in text
    assert "in every training fold" in text


def test_materials_not_in_the_model_are_named(frame):
    data = json.loads(SMOKE.read_text())
    del data["materials"]["soil"]
    data["profile"]["material"] = ["rock", "talus", "talus", "talus"]
    model = model_from_dict(data, source="m.json")
    assert "soil" in set(frame["material"])
    text = _fails(
        ImpactTable(frame, source="t.csv"), "soil", "not in the model", model=model
    )
    assert "rock, talus" in text
