"""A 3-D forward model: a DEM with materials, the rock, its releases and the effects.

:class:`Model3D` is what :func:`fieldkit.model.simulate3d.simulate3d` runs; the model
file's ``terrain`` block (:mod:`fieldkit.model.terrain_file`) builds one. Materials,
body, effects and core settings mean what they mean in 2-D
(:mod:`fieldkit.model.model_file`);
``material_index`` gives every DEM cell an index into ``list(materials)``.

Releases are points ``(x, y, z)`` with ``z`` the ground there, each with a weight
(a count of rocks or a relative weight); every rock picks a release point with
probability proportional to its weight, then its start is drawn by
:class:`Seeder3D`: ``height_m`` above the DEM's surface at the point's (x, y) (the
surface's height, so a release's z rounded in a file cannot start it inside the
ground) (with its SD, reflected to stay
above), velocity ``(vx, vy, vz)`` and spin with their SDs, mass with its SD (at least
1 % of the body's mass), as the 2-D seeder does.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from fieldkit.model.model_blocks import Body
from fieldkit.model.terrain import Terrain

if TYPE_CHECKING:
    from fieldkit.model.terrain_file import Trees3D


@dataclass(frozen=True)
class Seeder3D:
    """Spreads of a rock's start around its release point (module docstring)."""

    height_m: float = 0.0
    vx_mps: float = 0.0
    vy_mps: float = 0.0
    vz_mps: float = 0.0
    omega_radps: float = 0.0
    height_sd_m: float = 0.0
    vx_sd_mps: float = 0.0
    vy_sd_mps: float = 0.0
    vz_sd_mps: float = 0.0
    omega_sd_radps: float = 0.0
    mass_sd_kg: float = 0.0


@dataclass(frozen=True)
class Model3D:
    """A complete 3-D forward model (see the module docstring).

    Attributes
    ----------
    terrain
        The DEM.
    materials
        Material name -> :class:`fieldkit.model.materials.Material`.
    material_index
        int grid of the DEM's shape: index into ``list(materials)`` per cell.
    effects
        Active effect -> parameter values (as in 2-D).
    body
        The rock's mass, radius, gyration.
    releases
        float (n, 3): x, y, z of the release points [m], z = the ground.
    release_weights
        (n,) rocks (or relative weights) per release point, >= 0, not all 0.
    seeder
        Spreads of the start around a release point.
    core
        Core settings (as in 2-D: slide_vn_mps, stop_speed_mps, max_impacts, ...).
    trees
        Tree stems in plan with their trunk diameters and heights
        (:class:`fieldkit.model.terrain_file.Trees3D`), struck with
        ``tree_impacts`` on; or None.
    crs
        The DEM's coordinate reference system (WKT) or None.
    analysis_lines
        Barrier polylines of the model file
        (:class:`fieldkit.model.terrain_file.AnalysisLine`).
    source_files
        Every file read to build the model: the model file, the DEM, rasters, CSVs
        (:func:`fieldkit.model.model_file.read_model` adds them to a command's
        inputs).
    """

    terrain: Terrain
    materials: dict
    material_index: np.ndarray
    effects: dict[str, dict[str, float]]
    body: Body
    releases: np.ndarray
    release_weights: np.ndarray
    seeder: Seeder3D = field(default_factory=Seeder3D)
    core: dict[str, float] = field(default_factory=dict)
    trees: Trees3D | None = None
    crs: str | None = None
    provenance: dict = field(default_factory=dict)
    source: str = ""
    analysis_lines: tuple = ()
    source_files: tuple[str, ...] = ()
