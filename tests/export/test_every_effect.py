"""No effect left behind (issue 19, item 5): every effect of the registry appears in
every target's README -- mapped, or listed as not mapped with its reason -- whether
or not the exported model uses it. A new effect fails this test until each target
says what it does with it."""

from __future__ import annotations

import re

import pytest

from fieldkit.export.site import site_from_section
from fieldkit.export.targets import TARGETS
from fieldkit.model.effects.registry import EFFECTS


@pytest.fixture(scope="module")
def readmes(tornado):
    out = {}
    for name, target in TARGETS.items():
        site = site_from_section(tornado, cellsize_m=5, rows=5) if target.grid else None
        out[name] = target.export(tornado, site).readme("model.json")
    return out


@pytest.mark.parametrize("target", list(TARGETS))
@pytest.mark.parametrize("effect", [s.name for s in EFFECTS])
def test_every_effect_is_accounted_for_in_every_readme(readmes, target, effect):
    text = readmes[target]
    lines = [line for line in text.splitlines() if re.search(rf"\b{effect}\b", line)]
    assert lines, f"{target}'s README does not mention {effect}"
    # a mention with a reason: more than the bare name on its line
    assert any(len(line.replace(effect, "").strip(" *|`:-")) > 15 for line in lines)


@pytest.mark.parametrize("target", [t for t in TARGETS if t != "json"])
def test_every_target_readme_has_sources_and_a_translation_error(readmes, target):
    text = readmes[target]
    assert "## Sources of the target's rules" in text
    assert "## Translation error" in text
