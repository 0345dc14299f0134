"""Every observed run on its own 2-D section of the DEM: :func:`path_runs`.

A 3-D site is simulated run by run on a vertical section through the DEM:

* ``section="descent"`` (default, the only honest choice for prediction): the line
  of steepest descent from the release point
  (:func:`fieldkit.model.dem_profile.steepest_descent_line`), which depends on the
  release alone;
* ``section="release-deposit"``: the straight plan line from the release through
  the observed deposit, extended to the edge of the DEM. It uses the observed
  deposit to choose the section, so it is only honest for *calibration*: never use
  it to predict a run (the deposit is what is being predicted).

On the section, chainage is the horizontal distance from the release (0 at the
release). The base model is moved onto it:

* profile: the section's chainage and ground z; every segment takes the base
  model's single material (a base model with several materials needs ``materials``
  chainage ranges, :meth:`fieldkit.model.dem_profile.Section.with_materials`);
* ground upslope: ``upslope_m`` (two cells) of straight line back from the
  release against the section's first plan direction, at negative chainage (a
  profile starting at the release would lose every rock that bounces back at its
  first impact: on the Tschamut proxy, with the releases on 40-50 deg ground and
  release speeds of a few cm/s, 100 of 100 rocks left it upslope);
* seeder: a point seeder at chainage 0, ``release_z - ground z`` above the DEM
  ground of the section's first vertex (at least the block radius), with the
  release velocity projected on the section's first plan
  direction (the horizontal component along it as ``vx``, ``vz`` as given); the
  base seeder's SDs and spin are kept; a run without a release velocity takes the
  base seeder's ``vx_mps``, ``vz_mps``;
* body: the run's mass and radius (gyration as given, else a solid sphere's
  ``sqrt(2/5) r``); a run without them keeps the base body.

Which ground: the height of the release above the ground is measured on the
ground the observations give (``release_ground_z_m``) when they give it, else on
the DEM; the release is refused when it is more than ``below_ground_tolerance_m``
below that ground. The observations' own ground is preferred because a data set's
z and a DEM need not agree: the Tschamut calibration split gives z on the proxy's
*trend plane* plus the block radius, 1.1-5.1 m below ``terrain.asc`` (trend plane
plus IDW residuals) at the 18 calibration releases; measured on the DEM, every one
of them would be "below the ground".

Observed runout: the chainage of the point of the section nearest in plan to the
deposit; ``lateral_offset_m`` is that plan distance (how far the 2-D section
misses the real path). A deposit nearest to the section's last vertex has an
observed chainage of the section length: the section ended (a local minimum, the
grid edge) before the run did.

What the simulator does at the end of a section: a rock reaching its lower end
leaves the profile -- ``SimulationResult.state`` is ``EXITED_DOWNSLOPE`` ("left the
profile at its lower end") and its ``runout_x_m`` is the last vertex's chainage,
the section length, whether it was flying or sliding there. So a simulated runout
equal to the section length is a censored value (the rock would have gone
further), and a section ending above the observed deposit caps every simulated
runout below it. On a steepest-descent line that stops at a local minimum, the
ground beyond the last vertex rises, so a real rock could stop there; the 2-D
profile cannot show that.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.fit.path_runs import PathRun, along_arrays, run_body
from fieldkit.io.dem import INSIDE, DemGrid
from fieldkit.model.dem_profile import (
    Section,
    profile_along_polyline,
    steepest_descent_line,
)
from fieldkit.model.model_file import Model
from fieldkit.model.profile import Profile
from fieldkit.path_observations import PathObservations

SECTIONS = ("descent", "release-deposit")
#: A release more than this below the DEM ground is refused [m].
BELOW_GROUND_TOLERANCE_M = 0.5


def path_runs(
    observations: PathObservations,
    grid: DemGrid,
    base_model: Model,
    *,
    section: str = "descent",
    step_m: float | None = None,
    materials: str | None = None,
    upslope_m: float | None = None,
    min_runs: int = 1,
    below_ground_tolerance_m: float = BELOW_GROUND_TOLERANCE_M,
) -> list[PathRun]:
    """Each observed run as a :class:`PathRun` on its own section (module docstring).

    Parameters
    ----------
    observations
        Runs in plan coordinates (the DEM's grid), e.g. from
        :func:`fieldkit.io.path_observations.read_release_deposit`.
    grid
        The DEM.
    base_model
        The model to move onto each section (its profile is replaced).
    section
        ``"descent"`` (steepest descent from the release) or ``"release-deposit"``
        (calibration only: it uses the observed deposit).
    step_m
        Plan step of the section [m] (None: half the cell size).
    materials
        Chainage ranges ``"0-40:rock,40-:talus"`` for the section (names must be
        materials of ``base_model``); None: the base model's single material.
    upslope_m
        Ground kept upslope of the release [m] (None: two cells), so a rock
        bouncing back at the start does not leave the profile at once; its
        chainage is negative.
    min_runs
        Fewest runs accepted (e.g. what a fit needs).
    below_ground_tolerance_m
        A release centre more than this below the ground is refused [m]: the
        observations' ``release_ground_z_m`` where given, else the DEM's.

    Returns
    -------
    list of PathRun
        In the order of ``observations``; ``group`` the run's group, and
        ``observations`` the section (``section_x_m``, ``section_y_m`` plan
        vertices) and, for along-path points, ``along_chainage_m``,
        ``along_offset_m`` plus any value columns (``along_<name>``).

    Raises
    ------
    InputFileError
        Fewer than ``min_runs`` runs; a release outside the DEM or on nodata, or
        below the ground; a deposit higher than its release; a release-deposit
        section without a deposit; section-coordinate observations -- each naming
        the observations' file and the run.
    ArgumentError
        An unknown ``section``; a base model with several materials and no
        ``materials``, or with trees.

    Examples
    --------
    >>> import pandas as pd
    >>> from fieldkit.model.model_file import model_from_dict
    >>> g = DemGrid.from_corner(np.add.outer(np.zeros(11), -0.5 * np.arange(21.0)),
    ...                         x_left_m=0, y_top_m=110, cellsize_m=10)
    >>> base = model_from_dict({"profile": {"x_m": [0, 1], "z_m": [1, 0],
    ...     "material": ["meadow"]}, "materials": {"meadow": {"e_n": 0.3,
    ...     "e_t": 0.8, "friction_deg": 30}}, "body": {"mass_kg": 50,
    ...     "radius_m": 0.2}, "seeder": {"x_m": 0, "z_m": 1}})
    >>> obs = PathObservations(pd.DataFrame({"path_id": ["a"],
    ...     "release_x_m": [15.0], "release_y_m": [55.0], "release_z_m": [-0.3],
    ...     "deposit_x_m": [115.0], "deposit_y_m": [52.0],
    ...     "deposit_z_m": [-5.3]}))
    >>> run = path_runs(obs, g, base)[0]
    >>> round(run.observed_runout_m, 6), round(run.lateral_offset_m, 6)
    (100.0, 3.0)
    """
    if section not in SECTIONS:
        raise ArgumentError(
            f"section must be one of {', '.join(SECTIONS)} (got {section!r})",
            source="section",
        )
    source = observations.source or "observations"
    if len(observations) < min_runs:
        raise InputFileError(
            f"{len(observations)} run(s); at least {min_runs} are needed",
            source=source,
        )
    if observations.coordinates != "plan":
        raise InputFileError(
            "the observations are along a section (an ImpactTable), not in the "
            "DEM's plan grid: simulate them on their own profile instead",
            source=source,
        )
    if base_model.trees is not None:
        raise ArgumentError(
            "the base model has trees: their positions belong to its own profile, "
            "not to the runs' sections; remove them",
            source="base_model",
        )
    if materials is None and len(base_model.materials) != 1:
        raise ArgumentError(
            f"the base model has {len(base_model.materials)} materials "
            f"({', '.join(base_model.materials)}): give `materials` chainage ranges "
            "to place them on the sections, or keep one material",
            source="base_model",
        )
    step = 0.5 * grid.cellsize_m if step_m is None else float(step_m)
    upslope = 2.0 * grid.cellsize_m if upslope_m is None else float(upslope_m)
    if not (math.isfinite(upslope) and upslope >= 0):
        raise ArgumentError(
            f"upslope_m must be >= 0 (got {upslope:g})", source="upslope_m"
        )
    sections = path_sections(
        observations,
        grid,
        section=section,
        step_m=step,
        below_ground_tolerance_m=below_ground_tolerance_m,
    )
    runs = []
    for path_id, cut in sections.items():
        row = observations.row(path_id)
        if materials is not None:
            cut = cut.with_materials(materials)
            unknown = sorted(set(cut.material) - set(base_model.materials))
            if unknown:
                raise ArgumentError(
                    f"materials names {', '.join(unknown)}, not a material of the "
                    f"base model ({', '.join(base_model.materials)})",
                    source="materials",
                )
            names = cut.material
        else:
            names = (next(iter(base_model.materials)),) * (len(cut.chainage_m) - 1)
        back = _upslope(grid, cut, upslope)
        model = _run_model(base_model, cut, names, row, back)
        chainage, offset = nearest_on_section(
            cut, float(row["deposit_x_m"]), float(row["deposit_y_m"])
        )
        extra = {
            "section_x_m": cut.plan_x_m.copy(),
            "section_y_m": cut.plan_y_m.copy(),
        }
        along = observations.along_path(path_id)
        if len(along):
            c, o = np.array(
                [
                    nearest_on_section(cut, x, y)
                    for x, y in zip(along["x_m"], along["y_m"], strict=True)
                ]
            ).T
            extra |= along_arrays(along, c)
            extra["along_offset_m"] = o
        runs.append(
            PathRun(
                path_id=path_id,
                model=model,
                observed_runout_m=chainage,
                lateral_offset_m=offset,
                group=str(row["group"]),
                observations=extra,
            )
        )
    return runs


def path_sections(
    observations: PathObservations,
    grid: DemGrid,
    *,
    section: str = "descent",
    step_m: float | None = None,
    below_ground_tolerance_m: float = BELOW_GROUND_TOLERANCE_M,
) -> dict[str, Section]:
    """The section of every run (path id -> :class:`Section`), checked as in
    :func:`path_runs`; :attr:`Section.ending` says how each ended."""
    if section not in SECTIONS:
        raise ArgumentError(
            f"section must be one of {', '.join(SECTIONS)} (got {section!r})",
            source="section",
        )
    source = observations.source or "observations"
    step = 0.5 * grid.cellsize_m if step_m is None else float(step_m)
    out = {}
    for path_id in observations.path_ids():
        row = observations.row(path_id)
        x, y, z = (float(row[f"release_{k}_m"]) for k in "xyz")
        ground, _, _, status = grid.sample(x, y)
        if status[0] != INSIDE:
            raise InputFileError(
                f"the release (x, y) = ({x:g}, {y:g}) has no ground in the DEM "
                f"{grid.source}: " + grid.problem_at(x, y, int(status[0])),
                source=source,
                where=path_id,
            )
        own = float(row["release_ground_z_m"])
        base, where = (own, "its release_ground_z_m") if math.isfinite(own) else (
            float(ground[0]), f"the ground of the DEM {grid.source}")  # fmt: skip
        if z < base - below_ground_tolerance_m:
            raise InputFileError(
                f"the release (z = {z:.2f} m) is {base - z:.2f} m below {where} "
                f"(z = {base:.2f} m; at most {below_ground_tolerance_m:g} m "
                "accepted)",
                source=source,
                where=path_id,
            )
        dz = float(row["deposit_z_m"])
        if dz > z:
            raise InputFileError(
                f"the deposit (z = {dz:.2f} m) is higher than its release "
                f"(z = {z:.2f} m): upslope",
                source=source,
                where=path_id,
            )
        if section == "descent":
            out[path_id] = extend_to_edge(
                grid, steepest_descent_line(grid, (x, y), step), step
            )
        else:
            out[path_id] = _release_deposit_line(grid, row, step, source, path_id)
    return out


def _release_deposit_line(grid, row, step, source, path_id) -> Section:
    """The straight plan line release -> deposit, extended to the grid's edge."""
    x0, y0 = float(row["release_x_m"]), float(row["release_y_m"])
    x1, y1 = float(row["deposit_x_m"]), float(row["deposit_y_m"])
    if not (math.isfinite(x1) and math.isfinite(y1)):
        raise InputFileError(
            "a release-deposit section needs the deposit (x, y)",
            source=source,
            where=path_id,
        )
    length = math.hypot(x1 - x0, y1 - y0)
    if length <= 0:
        raise InputFileError(
            "the deposit is at the release in plan: no direction for a "
            "release-deposit section",
            source=source,
            where=path_id,
        )
    ux, uy = (x1 - x0) / length, (y1 - y0) / length
    t = _reach_edge(grid, x0, y0, ux, uy)
    cut = profile_along_polyline(grid, [(x0, y0), (x0 + t * ux, y0 + t * uy)], step)
    return replace(cut, ending="grid edge")


def _reach_edge(grid, x0: float, y0: float, ux: float, uy: float) -> float:
    """Plan distance from (x0, y0) along the unit vector (ux, uy) to the grid edge."""
    lo_x, hi_x = float(grid.x_m[0]), float(grid.x_m[-1])
    lo_y, hi_y = float(grid.y_m[-1]), float(grid.y_m[0])
    reach = []
    for u, p, lo, hi in ((ux, x0, lo_x, hi_x), (uy, y0, lo_y, hi_y)):
        if u > 0:
            reach.append((hi - p) / u)
        elif u < 0:
            reach.append((lo - p) / u)
    return min(reach) * (1 - 1e-9)


def extend_to_edge(grid, section: Section, step: float) -> Section:
    """A descent line that ended in a pit or a flat, continued straight along its
    last plan direction to the grid's edge.

    The line of steepest descent stops where the ground stops falling (a local
    minimum or flat of the DEM); a rock arriving there with speed runs on and up the
    far slope. Without the extension the simulator would let it leave the section
    there and cut its runout at the section's length.
    """
    if section.ending not in ("local minimum", "flat area"):
        return section
    px, py = section.plan_x_m, section.plan_y_m
    dx, dy = px[-1] - px[-2], py[-1] - py[-2]
    norm = math.hypot(dx, dy)
    t = _reach_edge(grid, float(px[-1]), float(py[-1]), dx / norm, dy / norm)
    if t <= step:
        return section
    vertices = np.column_stack([px, py]).tolist()
    vertices.append([px[-1] + t * dx / norm, py[-1] + t * dy / norm])
    cut = profile_along_polyline(grid, vertices, step)
    return replace(cut, ending=f"{section.ending}, then straight on to the grid edge")


def nearest_on_section(section: Section, x: float, y: float) -> tuple[float, float]:
    """Chainage [m] of the point of the section's plan line nearest to (x, y), and
    the plan distance to it [m] (NaN, NaN for a NaN point).

    Examples
    --------
    >>> s = Section(np.array([0.0, 10.0]), np.array([5.0, 0.0]), np.array([0.0, 6.0]),
    ...             np.array([0.0, 8.0]), ("ground",))
    >>> nearest_on_section(s, 3.0 + 4.0, 4.0 - 3.0)
    (5.0, 5.0)
    """
    if not (math.isfinite(x) and math.isfinite(y)):
        return math.nan, math.nan
    px, py = section.plan_x_m, section.plan_y_m
    ax, ay = px[:-1], py[:-1]
    dx, dy = np.diff(px), np.diff(py)
    seg2 = dx * dx + dy * dy
    t = np.clip(((x - ax) * dx + (y - ay) * dy) / np.where(seg2 > 0, seg2, 1), 0, 1)
    qx, qy = ax + t * dx, ay + t * dy
    dist = np.hypot(x - qx, y - qy)
    i = int(np.argmin(dist))
    chainage = section.chainage_m[i] + t[i] * (
        section.chainage_m[i + 1] - section.chainage_m[i]
    )
    return float(chainage), float(dist[i])


def _upslope(grid: DemGrid, cut: Section, length: float) -> Section | None:
    """The straight line from ``length`` upslope of the release (against the
    section's first plan direction, cut at the grid's edge) to the release, or
    None (length 0, or no room)."""
    ux = cut.plan_x_m[1] - cut.plan_x_m[0]
    uy = cut.plan_y_m[1] - cut.plan_y_m[0]
    norm = math.hypot(ux, uy)
    ux, uy = -ux / norm, -uy / norm
    x0, y0 = float(cut.plan_x_m[0]), float(cut.plan_y_m[0])
    reach = [length]
    for u, p, lo, hi in (
        (ux, x0, float(grid.x_m[0]), float(grid.x_m[-1])),
        (uy, y0, float(grid.y_m[-1]), float(grid.y_m[0])),
    ):
        if u > 0:
            reach.append((hi - p) / u * (1 - 1e-9))
        elif u < 0:
            reach.append((lo - p) / u * (1 - 1e-9))
    t = min(reach)
    if t < 1e-6:
        return None
    step = float(np.diff(cut.chainage_m).max())
    try:
        back = profile_along_polyline(
            grid, [(x0 + t * ux, y0 + t * uy), (x0, y0)], min(step, t)
        )
    except InputFileError:  # nodata upslope: keep none
        return None
    return replace(back, chainage_m=back.chainage_m - back.chainage_m[-1])


def _run_model(base: Model, cut: Section, names, row, back=None) -> Model:
    """The base model on the section ``cut`` with the run's release and block
    (and the ground ``back`` upslope of the release, at negative chainage)."""
    x, z = cut.chainage_m, cut.z_m
    names = list(names)
    if back is not None:
        x = np.concatenate([back.chainage_m[:-1], x])
        z = np.concatenate([back.z_m[:-1], z])
        names = [names[0]] * (len(back.chainage_m) - 1) + names
    profile = Profile.from_arrays(x, z, names, source=base.source)
    body = run_body(base.body, row)
    ground = float(cut.z_m[0])
    own = float(row["release_ground_z_m"])
    above = float(row["release_z_m"]) - (own if math.isfinite(own) else ground)
    height = max(above, body.radius_m)
    ux = cut.plan_x_m[1] - cut.plan_x_m[0]
    uy = cut.plan_y_m[1] - cut.plan_y_m[0]
    norm = math.hypot(ux, uy)
    vx_plan, vy_plan = float(row["release_vx_mps"]), float(row["release_vy_mps"])
    vz = float(row["release_vz_mps"])
    seeder = base.seeder
    if math.isfinite(vx_plan) and math.isfinite(vy_plan):
        vx = (vx_plan * ux + vy_plan * uy) / norm
    else:
        vx = seeder.vx_mps
    seeder = replace(
        seeder,
        x_m=0.0,
        z_m=ground + height,
        vx_mps=vx,
        vz_mps=vz if math.isfinite(vz) else seeder.vz_mps,
        x_max_m=None,
        height_m=None,
    )
    return replace(base, profile=profile, body=body, seeder=seeder)
