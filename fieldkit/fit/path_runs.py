"""Observed runs prepared for the simulator: one section model per run.

A :class:`PathRun` is what the path-level fit and the held-out validation read: the
base model moved onto the run's own 2-D section (profile from the DEM, seeder at the
release point, the run's block as body) and what was observed along it. The
simulated runout of a rock is the horizontal distance along the section from the
release to where it stopped (the section's chainage; ``runout_x_m`` of the
simulator minus the release chainage ``model.seeder.x_m``: 0 on the sections of
:func:`fieldkit.fit.path_sections.path_runs`, whose profiles start upslope of the
release at negative chainage).

Common random numbers: :func:`simulated_runouts` draws every rock of a run from
``numpy.random.default_rng([seed, index])``, and the kernel's random streams are
counter-based per rock and impact, so for a fixed seed the same rocks meet the same
random numbers whatever the parameters: the objective of a fit is deterministic and
changes smoothly with them.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numba
import numpy as np

from fieldkit.model.model_file import Model
from fieldkit.model.simulate import simulate


@dataclass(frozen=True)
class PathRun:
    """One observed run on its own section.

    Attributes
    ----------
    path_id
        The run's id (e.g. Tschamut ``trajectory_id``).
    model
        The model on this run's section: profile (chainage from the release),
        seeder at the release, body of the run's block.
    observed_runout_m
        Observed stop, as chainage along the section [m] (NaN: not observed).
    lateral_offset_m
        Plan distance of the observed deposit from the section line [m] (how far
        the 2-D section misses the real path; NaN when not known).
    group
        A label to report by (e.g. the block).
    observations
        Optional observations along the path (name -> array), e.g.
        ``impact_chainage_m``, ``flight_height_m``.
    """

    path_id: str
    model: Model
    observed_runout_m: float
    lateral_offset_m: float = math.nan
    group: str = ""
    observations: dict[str, np.ndarray] = field(default_factory=dict)


def simulated_runouts(
    run: PathRun, model: Model, rocks: int, seed: int, index: int
) -> np.ndarray:
    """Runouts [m] of ``rocks`` rocks of ``model`` (``run``'s section) with common
    random numbers ``default_rng([seed, index])``: the chainage of the stop less
    that of the release (``model.seeder.x_m``; the profile may start upslope of it,
    at negative chainage)."""
    result = simulate(model, rocks, np.random.default_rng([seed, index]))
    return np.asarray(result.runout_x_m, float) - float(model.seeder.x_m)


@contextmanager
def one_kernel_thread() -> Iterator[None]:
    """Run the simulator's kernel on one thread inside the block.

    A path fit makes thousands of small simulations (tens to hundreds of rocks):
    on a shared 2-core machine the kernel's parallel loop then waits on busy cores
    (the Tschamut fit took 101 s beside a test run, 6-8 s alone), while one thread
    costs 25 % when the machine is idle (7.9 s against 6.3 s, measured).
    """
    before = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(before)
