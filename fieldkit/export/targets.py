"""The export targets fieldkit knows, by the name ``fieldkit export --to`` takes."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from fieldkit.errors import ArgumentError
from fieldkit.export.crsp import export_crsp
from fieldkit.export.json_model import export_json
from fieldkit.export.ramms import export_ramms
from fieldkit.export.result import Export
from fieldkit.export.rocfall import export_rocfall
from fieldkit.export.rockyfor3d import export_rockyfor3d
from fieldkit.export.rstone import export_rstone, section_site
from fieldkit.export.site import ExportSite, site_from_section
from fieldkit.model.model_file import Model


@dataclass(frozen=True)
class Target:
    """One export target.

    Attributes
    ----------
    name
        What ``--to`` takes.
    export
        ``(model, site) -> Export``.
    grid
        Whether it writes rasters and so needs an :class:`ExportSite`.
    what
        One line for the help.
    extrude
        ``(model, cellsize_m=, rows=) -> ExportSite``: the model's section extruded
        as the target needs it (``None`` arguments: the target's defaults).
    """

    name: str
    export: Callable[[Model, ExportSite | None], Export]
    grid: bool
    what: str
    extrude: Callable[..., ExportSite] = site_from_section


#: Target name -> Target, in the order the help lists them.
TARGETS: dict[str, Target] = {
    t.name: t
    for t in (
        Target("rocfall", export_rocfall, False, "RocFall blocks and slope"),
        Target("crsp", export_crsp, False, "CRSP slope cells (feet) and rock"),
        Target("rockyfor3d", export_rockyfor3d, True, "Rockyfor3D ASCII grids"),
        Target("ramms", export_ramms, True, "RAMMS categories and the DEM"),
        Target(
            "rstone", export_rstone, True, "r.stone (GRASS GIS) rasters", section_site
        ),
        Target("json", export_json, False, "the model with uncertainties"),
    )
}


def target(name: str) -> Target:
    """The target called ``name``.

    Raises
    ------
    ArgumentError
        An unknown name, listing the known ones.

    Examples
    --------
    >>> target("json").grid
    False
    >>> try:
    ...     target("rocfal")
    ... except ArgumentError as e:
    ...     print(e)
    to: unknown target 'rocfal' (known: rocfall, crsp, rockyfor3d, ramms, rstone, json)
    """
    if name not in TARGETS:
        raise ArgumentError(
            f"unknown target {name!r} (known: {', '.join(TARGETS)})", source="to"
        )
    return TARGETS[name]
