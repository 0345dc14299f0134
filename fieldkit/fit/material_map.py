"""Survey materials -> model materials: the one mapping fit and diagnose apply.

A survey names the ground at each impact as it was mapped in the field (``talus``,
``bench``); a model names the materials it has parameters for (Table 7-1: ``rock``,
``colluvium``). Before an ImpactTable is compared with a model, each surveyed
material the model does not have must be mapped onto one it has.

Two sources of mappings, one rule:

* ``explicit`` (what the user asked for this run) is always applied, also to a
  material the model has (the user asked for it);
* ``preset`` (a survey preset, :mod:`fieldkit.io.preset`: the mapping the survey's
  documentation settles once) is a fallback: it is applied only to surveyed
  materials the model does *not* have. A model that has its own ``bench`` keeps it
  (``surveys/tornado_mountain/model_path_start.json``), although the preset maps
  ``bench`` onto ``colluvium`` for Table 7-1, which has none.

Every mapping applied and every preset entry left unused because the model has the
material is stated (:attr:`MaterialMapping.notes`), and :attr:`MaterialMapping.applied`
is what a fit records in its provenance.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import pandas as pd

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.impact_table import ImpactTable


@dataclass(frozen=True)
class MaterialMapping:
    """The outcome of :func:`map_materials`.

    Attributes
    ----------
    table
        The table with its ``material`` column mapped (the input is not changed).
    applied
        ``{surveyed: model material}`` of every mapping applied to some row.
    counts
        Rows mapped per surveyed material.
    notes
        One sentence per mapping applied or preset entry not used.
    """

    table: ImpactTable
    applied: dict[str, str] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    def provenance(self) -> dict[str, str]:
        """The ``material_map`` entry of a fit's provenance (surveyed -> model)."""
        return dict(self.applied)


def parse_mapping(items: Iterable[str] | None) -> dict[str, str]:
    """``["talus=colluvium", ...]`` -> ``{"talus": "colluvium", ...}``.

    Raises
    ------
    ArgumentError
        An item that is not ``SURVEYED=MODEL`` with two non-empty names, or a
        surveyed material mapped twice (``source="material"``).

    Examples
    --------
    >>> parse_mapping(["talus=colluvium", " bench = colluvium "])
    {'talus': 'colluvium', 'bench': 'colluvium'}
    """
    out: dict[str, str] = {}
    for item in items or []:
        surveyed, sep, target = (part.strip() for part in item.partition("="))
        if not (sep and surveyed and target) or "=" in target:
            raise ArgumentError(
                f"{item!r}: expected SURVEYED=MODEL (a surveyed material and the "
                "model's material it is, e.g. talus=colluvium)",
                source="material",
            )
        if surveyed in out and out[surveyed] != target:
            raise ArgumentError(
                f"{surveyed} is mapped twice ({out[surveyed]} and {target})",
                source="material",
            )
        out[surveyed] = target
    return out


def map_materials(
    table: ImpactTable,
    model_materials: Sequence[str] | None,
    explicit: Mapping[str, str] | None = None,
    preset: Mapping[str, str] | None = None,
    *,
    preset_source: str = "the preset",
    required: bool = True,
) -> MaterialMapping:
    """Map ``table``'s surveyed materials onto ``model_materials`` (module docstring).

    Parameters
    ----------
    table
        The ImpactTable (its ``material`` column; a table without one is returned
        unchanged).
    model_materials
        The materials of the model the table is compared with; ``None`` when there
        is no model (targets are then not checked and nothing is required).
    explicit
        Mappings asked for on this run, always applied.
    preset
        Mappings of a survey preset, applied only to materials the model lacks.
    preset_source
        How notes and errors name the preset (its file).
    required
        Whether every surveyed material must end up a material of the model (an
        impact fit, a diagnosis); ``False`` where the table's materials are not
        used (a path fit on the model's own profile): those left out are noted.

    Returns
    -------
    MaterialMapping

    Raises
    ------
    ArgumentError
        An explicit mapping onto a material the model does not have
        (``source="material"``, naming the model's materials).
    InputFileError
        A preset mapping used onto a material the model does not have (naming the
        preset), or a surveyed material the model lacks that nothing maps (naming
        the table and suggesting a mapping).

    Examples
    --------
    >>> t = _example_table(["talus", "bench", "colluvium"], [5.0, 15.0, 25.0])
    >>> m = map_materials(t, ["rock", "colluvium", "bench"],
    ...                   preset={"talus": "colluvium", "bench": "colluvium"})
    >>> m.table.frame["material"].tolist(), m.applied
    (['colluvium', 'bench', 'colluvium'], {'talus': 'colluvium'})
    """
    explicit = dict(explicit or {})
    preset = dict(preset or {})
    known = None if model_materials is None else list(model_materials)
    if known is not None:
        wrong = sorted({t for t in explicit.values() if t not in known})
        if wrong:
            raise ArgumentError(
                f"{', '.join(wrong)} is not a material of the model (it has "
                f"{', '.join(known)})",
                source="material",
            )
    frame = table.frame
    if "material" not in frame.columns:
        return MaterialMapping(table=table)
    labels = frame["material"].astype("string")
    present = set(labels.dropna())
    rules: dict[str, str] = {}
    notes: list[str] = []
    for surveyed, target in preset.items():
        if surveyed not in present or surveyed in explicit:
            continue
        if known is not None and surveyed in known:
            notes.append(
                f"material {surveyed} kept: the model has its own {surveyed} "
                f"({preset_source} maps it to {target} only for models without it)"
            )
            continue
        if known is not None and target not in known:
            raise InputFileError(
                f"maps {surveyed} to {target}, which is not a material of the model "
                f"(it has {', '.join(known)}); map it with `material` "
                f"{surveyed}=<one of these>",
                source=preset_source,
            )
        rules[surveyed] = target
    for surveyed, target in explicit.items():
        if surveyed not in present:
            notes.append(f"material mapping {surveyed}={target} unused: the table "
                         f"has no {surveyed}")  # fmt: skip
            continue
        rules[surveyed] = target
    counts = {s: int((labels == s).sum()) for s in rules}
    applied = {s: t for s, t in rules.items() if s != t}
    for surveyed, target in rules.items():
        origin = "asked for" if surveyed in explicit else f"from {preset_source}"
        notes.append(
            f"material {surveyed} -> {target} ({counts[surveyed]} rows, {origin})"
        )
    mapped = labels.replace(rules) if rules else labels
    if known is not None:
        lacking = sorted(set(mapped.dropna()) - set(known))
        if lacking and not required:
            notes.append(
                f"material(s) {', '.join(lacking)} of the table not in the model: "
                "not used (the model's profile carries the materials)"
            )
        elif lacking:
            raise InputFileError(
                f"material(s) {', '.join(lacking)} not in the model (it has "
                f"{', '.join(known)}); map each onto one of them with `material` "
                f"{lacking[0]}=MODEL",
                source=table.source,
                where="material",
            )
    if not rules:
        return MaterialMapping(table=table, notes=notes)
    out = frame.copy()
    out["material"] = frame["material"].replace(rules)
    return MaterialMapping(
        table=ImpactTable(out, source=table.source),
        applied=applied,
        counts=counts,
        notes=notes,
    )


#: A surveyed point this close to a profile vertex is at the vertex (chainages
#: recomputed from geographic positions differ from the section's by ~1e-5 m).
AT_VERTEX_M = 1e-3


def profile_disagreements(
    table: ImpactTable, x_m: Sequence[float], material: Sequence[str]
) -> tuple[int, list[str]]:
    """Where the table's (mapped) materials differ from a model profile's.

    A path fitted on a model's own profile takes its materials from the profile,
    not from the table; this says whether the two agree. A surveyed point at
    chainage ``x`` is compared with the profile segment that ends at or beyond it
    (a segment takes the material of its downslope end, as in the Tornado models);
    a point within :data:`AT_VERTEX_M` of a vertex is at it; points before the
    profile's first vertex or at it are not compared.

    Parameters
    ----------
    table
        An ImpactTable with ``x_m`` and ``material`` (materials already mapped).
    x_m, material
        The profile's vertex chainages and per-segment materials.

    Returns
    -------
    compared, differences
        How many points were compared, and one ``"point P (x m): surveyed S,
        profile M"`` entry per difference.

    Examples
    --------
    >>> t = _example_table(["rock", "rock", "rock"], [0.0, 5.0, 15.0])
    >>> profile_disagreements(t, [0, 10, 20], ["rock", "soil"])
    (2, ['point 3 (x = 15 m): surveyed rock, profile soil'])
    """
    frame = table.frame
    if "material" not in frame or "x_m" not in frame:
        return 0, []
    edges = list(map(float, x_m))
    compared, out = 0, []
    points = frame["point"] if "point" in frame else pd.Series(range(1, len(frame) + 1))
    for point, x, surveyed in zip(points, frame["x_m"], frame["material"],
                                  strict=True):  # fmt: skip
        x = float(x)
        if pd.isna(surveyed) or not (edges[0] + AT_VERTEX_M < x <= edges[-1]):
            continue
        segment = max(bisect.bisect_left(edges, x - AT_VERTEX_M) - 1, 0)
        compared += 1
        if material[segment] != surveyed:
            out.append(
                f"point {point} (x = {x:g} m): surveyed {surveyed}, "
                f"profile {material[segment]}"
            )
    return compared, out


def _example_table(material: list[str], x_m: list[float]) -> ImpactTable:
    """A small ImpactTable for the examples (points 1, 2, ...)."""
    n = len(material)
    zeros = [0.0] * n
    return ImpactTable(pd.DataFrame({
        "path_id": ["a"] * n, "point": [str(i + 1) for i in range(n)], "x_m": x_m,
        "z_m": [-x for x in x_m], "slope_deg": [30.0] * n, "vi_x_mps": zeros,
        "vi_z_mps": zeros, "vf_x_mps": zeros, "vf_z_mps": zeros,
        "material": material,
    }))  # fmt: skip
