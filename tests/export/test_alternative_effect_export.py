"""An export of a model with the diagnosis's statistical alternative
(``affine_rebound``) states that the target has no such law (issue 18 item 4).

Before, CRSP and RocFall listed only the effects of their hand-kept reason lists
as not mappable, so an effect outside them vanished from the export's README.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
TORNADO = REPO / "surveys" / "tornado_mountain" / "model_rocfall_table_7_1.json"
AFFINE = "affine_rebound"


@pytest.mark.parametrize(
    ("target", "words"), [("crsp", "CRSP"), ("rocfall", "RocFall")]
)
def test_export_states_the_target_has_no_such_law(cli, tmp_path, target, words):
    data = json.loads(TORNADO.read_text())
    data.setdefault("effects", {})[AFFINE] = {"b_n_mps": 1.5}
    model = tmp_path / "m.json"
    model.write_text(json.dumps(data))
    out = tmp_path / "out"
    args = ["export", model, "--to", target, "-o", out]
    r = cli(*args)
    assert r.exit_code == 0, r.output
    readme = " ".join((out / "README.md").read_text().split())
    assert f"{AFFINE} is a statistical alternative" in readme
    assert f"not a physical law: {words} has no such law" in readme
