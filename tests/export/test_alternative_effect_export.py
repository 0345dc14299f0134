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


@pytest.mark.parametrize("target", ["crsp", "rocfall", "json"])
def test_every_registry_effect_is_in_the_readme(cli, tmp_path, target):
    # issue 19 item 5: on or off, mapped or not, each effect with its reason
    from fieldkit.model.effects import registry

    out = tmp_path / "out"
    r = cli("export", TORNADO, "--to", target, "-o", out)
    assert r.exit_code == 0, r.output
    readme = (out / "README.md").read_text()
    for spec in registry.EFFECTS:
        state = "on" if spec.name == "slope_roughness" else "off"
        line = next(
            (x for x in readme.splitlines() if x.startswith(f"* effect {spec.name} (")),
            None,
        )
        assert line is not None, spec.name
        assert line.startswith(f"* effect {spec.name} ({state} in this model): ")
        assert "mapped: " in line and len(line.split("mapped: ", 1)[1]) > 10


@pytest.mark.parametrize(
    ("target", "words"), [("crsp", "CRSP"), ("rocfall", "RocFall")]
)
def test_a_new_effect_is_not_left_out_silently(
    cli, tmp_path, monkeypatch, target, words
):
    # an effect added to the registry after the exporter: said, not dropped (the
    # exporters' view of the registry only: the simulator has no such kernel)
    from types import SimpleNamespace

    from fieldkit.export import lumped
    from fieldkit.model.effects import registry
    from fieldkit.model.effects.spec import EffectSpec

    spec = EffectSpec("future_law", "impact", "new", "vfn = ?", (), "none")
    view = SimpleNamespace(EFFECTS=(*registry.EFFECTS, spec), effect=registry.effect)
    monkeypatch.setattr(lumped, "registry", view)
    out = tmp_path / "out"
    r = cli("export", TORNADO, "--to", target, "-o", out)
    assert r.exit_code == 0, r.output
    readme = " ".join((out / "README.md").read_text().split())
    assert (
        f"effect future_law (off in this model): not mapped: NOT MAPPED: the {words} "
        "export has no rule for future_law" in readme
    )
