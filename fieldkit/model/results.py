"""What a simulation returns: per-rock outcomes, analysis points, envelope, impacts.

:class:`SimulationResult` holds raw per-rock arrays (so any statistic can be computed
later); :meth:`SimulationResult.summary` gives what a designer reads (the
``summary.json`` contract of docs/architecture.md §4), every statistic with its Monte
Carlo standard error.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from fieldkit.impact_table import ImpactTable

if TYPE_CHECKING:  # the Model type is only named in annotations
    from fieldkit.model.model_file import Model

#: Final state of a rock (``SimulationResult.state``).
STOPPED, EXITED_DOWNSLOPE, EXITED_UPSLOPE, MAX_IMPACTS = 0, 1, 2, 3
STATE_NAMES = {
    STOPPED: "stopped on the profile",
    EXITED_DOWNSLOPE: "left the profile at its lower end",
    EXITED_UPSLOPE: "left the profile at its upper end",
    MAX_IMPACTS: "reached the impact limit",
}


@dataclass
class AnalysisPoint:
    """Rocks crossing the vertical line ``x = x_m`` (first crossing of each rock).

    Arrays have one entry per rock; NaN where the rock never crossed.
    """

    x_m: float
    crossed: np.ndarray  # (rocks,) bool
    speed_mps: np.ndarray  # translational speed of the centre [m/s]
    ke_j: np.ndarray  # translational kinetic energy [J]
    re_j: np.ndarray  # rotational energy [J]
    total_j: np.ndarray  # ke + re [J]
    height_m: np.ndarray  # centre height above the ground, vertical [m] (bounce height)


@dataclass
class SimulationResult:
    """Everything one simulation produced (see the module docstring)."""

    model: Model
    rocks: int
    seed: int | None
    wall_s: float  # kernel time only [s]
    impacts: int  # total impacts over all rocks
    runout_x_m: np.ndarray  # (rocks,) x where the rock stopped or left the profile
    state: np.ndarray  # (rocks,) int, one of STATE_NAMES
    impacts_per_rock: np.ndarray  # (rocks,) int
    analysis: list[AnalysisPoint] = field(default_factory=list)
    envelope_x_m: np.ndarray = field(default_factory=lambda: np.zeros(0))  # bin edges
    envelope_height_m: np.ndarray = field(  # (rocks, bins) max height per bin, float32
        default_factory=lambda: np.zeros((0, 0), np.float32)
    )
    trajectories: list[np.ndarray] = field(default_factory=list)  # (n_i, 2) x, z
    impact_table: ImpactTable | None = None
