"""The material-mapping options of fit, the path fit and diagnose, and the one call
that applies them (:func:`fieldkit.fit.material_map.map_materials`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import note

MaterialOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--material",
        help="Map a surveyed material onto one of the model's: SURVEYED=MODEL, e.g. "
        "talus=colluvium (repeatable; always applied).",
    ),
]
PresetOpt = Annotated[
    Path | None,
    typer.Option(
        "--preset",
        help="A survey preset (TOML, e.g. surveys/tornado_mountain/"
        "boulder_a_preset.toml): its [materials] mapping, applied only to surveyed "
        "materials the model does not have; --material overrides it.",
    ),
]


def mapped_table(
    table, model, material: list[str] | None, preset: Path | None, required=True
):
    """``table`` with its materials mapped onto ``model``'s (one rule for fit, the
    path fit and diagnose: :func:`fieldkit.fit.material_map.map_materials`); each
    mapping is stated on stderr. ``model`` None: no model to check against."""
    from fieldkit.fit.material_map import map_materials, parse_mapping
    from fieldkit.io.preset import read_preset

    explicit = parse_mapping(material)
    preset_map, source = {}, "the preset"
    if preset is not None:
        preset_map, source = read_preset(preset).materials, str(preset)
    mapping = map_materials(
        table,
        None if model is None else list(model.materials),
        explicit,
        preset_map,
        preset_source=source,
        required=required,
    )
    for text in mapping.notes:
        note(text)
    return mapping
