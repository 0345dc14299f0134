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
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace

import numba
import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.model.model_file import Body, Model
from fieldkit.model.simulate import simulate
from fieldkit.path_observations import PathObservations


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
    run: PathRun,
    model: Model,
    rocks: int,
    seed: int,
    index: int,
    on_impacts: Callable[[dict[str, np.ndarray]], None] | None = None,
) -> np.ndarray:
    """Runouts [m] of ``rocks`` rocks of ``model`` (``run``'s section) with common
    random numbers ``default_rng([seed, index])``: the chainage of the stop less
    that of the release (``model.seeder.x_m``; the profile may start upslope of it,
    at negative chainage). ``on_impacts``, when given, receives the simulated
    impacts' kernel columns (``simulate``'s ``on_impact_columns``)."""
    result = simulate(
        model, rocks, np.random.default_rng([seed, index]),
        record_impacts=on_impacts is not None, on_impact_columns=on_impacts,
    )  # fmt: skip
    return np.asarray(result.runout_x_m, float) - float(model.seeder.x_m)


def run_body(body: Body, row) -> Body:
    """The block of a run: ``body`` with the run's ``mass_kg``, ``radius_m`` and
    ``gyration_m`` where they are finite (a new radius without a gyration: that of
    a solid sphere, sqrt(0.4) r)."""
    mass, radius = float(row["mass_kg"]), float(row["radius_m"])
    if not (math.isfinite(mass) or math.isfinite(radius)):
        return body
    r = radius if math.isfinite(radius) else body.radius_m
    gyration = float(row["gyration_m"])
    if not math.isfinite(gyration):
        gyration = math.sqrt(0.4) * r if math.isfinite(radius) else body.gyration_m
    return Body(
        mass_kg=mass if math.isfinite(mass) else body.mass_kg,
        radius_m=r,
        gyration_m=gyration,
    )


def along_arrays(along, chainage_m: np.ndarray) -> dict[str, np.ndarray]:
    """:attr:`PathRun.observations` of a run's along-path points (the rows of
    :meth:`PathObservations.along_path`): their chainage on the run's section, their
    elevation, and every value column as ``along_<name>``."""
    out = {
        "along_chainage_m": np.asarray(chainage_m, float),
        "along_z_m": along["z_m"].to_numpy(float),
    }
    for name in along.columns[5:]:
        out[f"along_{name}"] = along[name].to_numpy(float)
    return out


#: Fewest surveyed points of a path fitted on a model's own profile: its release
#: (the first), one impact and where it stopped (the last). The runout is the
#: distance from the first to the last, and the impacts between them are what the
#: along-path kinds score; one or two points leave nothing but a runout of a point.
MIN_SURVEYED_POINTS = 3


def section_runs(observations: PathObservations, base_model: Model) -> list[PathRun]:
    """Runs observed along the base model's own profile (section coordinates).

    For observations already on one 2-D section -- an ImpactTable from ``reduce``
    through :func:`fieldkit.io.path_observations.observations_from_impact_table` --
    whose x is the chainage of ``base_model``'s profile (its elevations may be on
    another datum: only chainages are used). Each run keeps the base model with its
    own block (mass, radius, gyration where given) and the seeder moved to the
    release chainage at the seeder's own height above the ground; the observed
    runout and every along-path chainage are measured from the release.

    Raises
    ------
    InputFileError
        Plan observations, a release or deposit off the profile, a deposit not
        beyond its release, or a surveyed path of fewer than
        :data:`MIN_SURVEYED_POINTS` points (the file and the run named).

    Examples
    --------
    >>> import pandas as pd
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 50], "z_m": [30, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 0, "z_m": 31}})
    >>> obs = PathObservations(pd.DataFrame({"path_id": ["a"],
    ...     "release_x_m": [5.0], "release_y_m": [0.0], "release_z_m": [800.0],
    ...     "deposit_x_m": [45.0], "deposit_y_m": [0.0], "deposit_z_m": [760.0]}),
    ...     coordinates="section")
    >>> run = section_runs(obs, m)[0]
    >>> run.observed_runout_m, run.model.seeder.x_m, run.model.seeder.z_m
    (40.0, 5.0, 28.0)
    """
    source = observations.source or "observations"
    if observations.coordinates != "section":
        raise InputFileError(
            "the observations are in a plan grid: cut their sections from a DEM "
            "(fieldkit.fit.path_sections.path_runs)",
            source=source,
        )
    profile = base_model.profile
    x0, x1 = float(profile.x_m[0]), float(profile.x_m[-1])
    seeder = base_model.seeder
    above = seeder.z_m - float(np.interp(seeder.x_m, profile.x_m, profile.z_m))
    runs = []
    for path_id in observations.path_ids():
        row = observations.row(path_id)
        release = float(row["release_x_m"])
        deposit = float(row["deposit_x_m"])
        for what, x in (("release", release), ("deposit", deposit)):
            if math.isfinite(x) and not x0 <= x <= x1:
                raise InputFileError(
                    f"the {what} (x = {x:g} m) is off the model's profile "
                    f"[{x0:g}, {x1:g}] m",
                    source=source,
                    where=path_id,
                )
        along = observations.along_path(path_id)
        if 0 < len(along) < MIN_SURVEYED_POINTS:
            raise InputFileError(
                f"{len(along)} surveyed point(s); a path needs at least "
                f"{MIN_SURVEYED_POINTS} to be calibrated on: its release (the first), "
                "an impact and where it stopped (the last)",
                source=source,
                where=f"path {path_id}",
            )
        if math.isfinite(deposit) and not deposit > release:
            raise InputFileError(
                f"the deposit (x = {deposit:g} m) is not beyond the release "
                f"(x = {release:g} m): no runout to calibrate on",
                source=source,
                where=f"path {path_id}",
            )
        body = run_body(base_model.body, row)
        ground = float(np.interp(release, profile.x_m, profile.z_m))
        moved = replace(seeder, x_m=release, z_m=ground + above)
        model = replace(base_model, body=body, seeder=moved)
        extra = {}
        if len(along):
            extra = along_arrays(along, along["x_m"].to_numpy(float) - release)
        runs.append(
            PathRun(
                path_id=path_id,
                model=model,
                observed_runout_m=deposit - release,
                lateral_offset_m=0.0,
                group=str(row["group"]),
                observations=extra,
            )
        )
    if not runs:
        raise ArgumentError("no runs in the observations", source="observations")
    return runs


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
