"""Simulate rocks and survey their paths as a geologist would (issue 18, item 1).

:func:`virtual_campaign` runs the model's rocks (with whatever hidden effects the
model carries) and turns each rock into a :class:`VirtualPath`: the
:class:`~fieldkit.survey.Survey` a geologist would bring back -- scars, not impacts;
positions with survey error; tree strikes with height error; no launch angle -- and
the truth beside it (the simulated impact behind each scar). The survey rules are
:class:`~fieldkit.campaign.design.CampaignDesign`'s.

Random numbers come from one ``numpy.random.Generator``: each batch of rocks is
simulated first, then each kept rock is surveyed in turn (its trees, then its
position errors, then its strike-height errors), so a seed reproduces a campaign
exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from fieldkit.campaign.design import MIN_SCARS, CampaignDesign
from fieldkit.errors import ArgumentError
from fieldkit.impact_table import ImpactTable
from fieldkit.model.model_file import Model
from fieldkit.model.simulate import simulate
from fieldkit.physics.constants import G
from fieldkit.survey import PointSet, Survey, TreeStrikes

#: Most paths of one campaign (each is one rock surveyed; a campaign of a hundred
#: paths is already more than any field season).
MAX_PATHS = 1_000
#: Rocks simulated per kept path before the campaign gives up: a model whose rocks
#: leave fewer than :data:`~fieldkit.campaign.design.MIN_SCARS` scars.
MAX_TRIES_PER_PATH = 20
#: Lowest tree strike recorded [m]: below it the rock rolled past the trunk.
MIN_STRIKE_HEIGHT_M = 0.3

#: Columns of a path's truth table (one row per surveyed point).
TRUTH_COLUMNS = (
    "point",
    "x_true_m",
    "z_true_m",
    "x_m",
    "z_m",
    "material",
    "impacts_merged",
    "vin_mps",
    "vit_mps",
    "vfn_mps",
    "vft_mps",
    "e_n",
    "e_t",
    "theta_i_deg",
    "theta_f_deg",
    "ke_n_j",
)


@dataclass(frozen=True)
class VirtualPath:
    """One surveyed rock: what the geologist brings back and what really happened.

    Attributes
    ----------
    path_id
        ``path01``, ``path02``, ...
    survey
        The points (source first, then the scars in order) with their survey error,
        and the tree strikes (None when the design has no trees).
    truth
        One row per point (:data:`TRUTH_COLUMNS`): true and surveyed position, how
        many simulated impacts the scar stands for, and the simulated impact's
        velocities and coefficients (NaN at the source).
    impacts
        Every simulated impact of the rock (the ImpactTable of the simulation).
    """

    path_id: str
    survey: Survey
    truth: pd.DataFrame
    impacts: ImpactTable


@dataclass(frozen=True)
class VirtualCampaign:
    """Paths surveyed under one design, and the bookkeeping a report needs."""

    paths: list[VirtualPath]
    design: CampaignDesign
    model: Model
    rocks_simulated: int
    rocks_too_short: int
    notes: list[str] = field(default_factory=list)

    @property
    def scars(self) -> int:
        """Surveyed impact points over all paths (sources not counted)."""
        return sum(len(p.survey.points) - 1 for p in self.paths)


def check_paths(paths: int) -> None:
    """Refuse a campaign size outside 1 .. :data:`MAX_PATHS`."""
    if not (isinstance(paths, int | np.integer) and 1 <= paths <= MAX_PATHS):
        raise ArgumentError(
            f"must be from 1 to {MAX_PATHS:,} surveyed paths (got {paths})",
            source="paths",
        )


def virtual_campaign(
    model: Model,
    design: CampaignDesign,
    paths: int,
    rng: np.random.Generator,
    *,
    source: str = "virtual campaign",
) -> VirtualCampaign:
    """Simulate rocks of ``model`` until ``paths`` of them leave a surveyable path.

    A rock whose path leaves fewer than :data:`~fieldkit.campaign.design.MIN_SCARS`
    points (source included) is not a path a geologist could survey; it is counted
    in ``rocks_too_short`` and the next rock taken.

    Raises
    ------
    ArgumentError
        Bad ``paths``; or :data:`MAX_TRIES_PER_PATH` rocks per path did not give
        enough surveyable paths (the message says what the rocks did).

    Examples
    --------
    >>> from fieldkit.model.model_file import read_model
    >>> m = read_model("surveys/tornado_mountain/model_rocfall_table_7_1.json")
    >>> c = virtual_campaign(m, CampaignDesign(), 2, np.random.default_rng(3))
    >>> [p.path_id for p in c.paths], c.scars > 10
    (['path01', 'path02'], True)
    """
    check_paths(paths)
    kept: list[VirtualPath] = []
    simulated = too_short = 0
    batch = max(4, int(math.ceil(paths * 1.25)))
    while len(kept) < paths:
        if simulated >= MAX_TRIES_PER_PATH * paths:
            raise ArgumentError(
                f"{simulated} simulated rocks gave only {len(kept)} paths with at "
                f"least {max(MIN_SCARS - 1, design.min_scars)} scars (m vin^2/2 >= "
                f"{design.scar_energy_j:g} J, {design.scar_spacing_m:g} m apart): "
                "lower the scar energy or spacing, or release the rocks higher",
                source="paths",
            )
        result = simulate(model, batch, rng, record_impacts=True)
        simulated += batch
        frame = result.impact_table.frame if result.impact_table is not None else None
        groups = (
            {} if frame is None else dict(list(frame.groupby("path_id", sort=False)))
        )
        for rock in range(batch):
            if len(kept) == paths:
                break
            rows = groups.get(str(rock))
            path = None
            if rows is not None:
                path = survey_rock(
                    model,
                    rows.reset_index(drop=True),
                    design,
                    rng,
                    path_id=f"path{len(kept) + 1:02d}",
                    source=source,
                )
            if path is None:
                too_short += 1
                continue
            kept.append(path)
    notes = [
        f"survey: {design.describe()}",
        f"{simulated} rocks simulated, {len(kept)} surveyed, {too_short} left fewer "
        f"than {max(MIN_SCARS - 1, design.min_scars)} scars (not surveyed)",
        "source point: the seeder's mean release chainage on the ground (a release "
        "scatter in the model is not surveyed)",
    ]
    if "air_drag" in model.effects:
        notes.append(
            "tree-strike heights use drag-free parabolas between impacts (the "
            "model's air_drag makes the true heights a little lower)"
        )
    return VirtualCampaign(kept, design, model, simulated, too_short, notes)


def scar_rows(
    x_m: np.ndarray,
    ke_n_j: np.ndarray,
    x_source_m: float,
    design: CampaignDesign,
) -> tuple[np.ndarray, np.ndarray]:
    """Which impacts a geologist finds as scars, and how many each one stands for.

    An impact marks the ground when ``ke_n_j >= design.scar_energy_j``; it is a new
    scar when it lies more than ``design.scar_spacing_m`` downslope of the last scar
    kept (or of the source). Returns the kept row indices and, per kept scar, the
    number of simulated impacts up to the next kept scar (itself included).

    Examples
    --------
    >>> x = np.array([5.0, 6.0, 12.0, 11.0, 20.0])
    >>> ke = np.array([9e3, 9e3, 1e2, 9e3, 9e3])
    >>> scar_rows(x, ke, 0.0, CampaignDesign())
    (array([0, 3, 4]), array([3, 1, 1]))
    """
    kept: list[int] = []
    last = float(x_source_m)
    for i, (x, ke) in enumerate(zip(x_m, ke_n_j, strict=True)):
        if ke >= design.scar_energy_j and x > last + design.scar_spacing_m:
            kept.append(i)
            last = float(x)
            if design.max_scars is not None and len(kept) >= design.max_scars:
                break
    idx = np.asarray(kept, int)
    if idx.size == 0:
        return idx, idx
    ends = np.append(idx[1:], len(x_m))
    return idx, ends - idx


def survey_rock(
    model: Model,
    rows: pd.DataFrame,
    design: CampaignDesign,
    rng: np.random.Generator,
    *,
    path_id: str,
    source: str = "virtual campaign",
) -> VirtualPath | None:
    """Survey one simulated rock's impacts ``rows`` (in time order); None when it
    leaves fewer than :data:`~fieldkit.campaign.design.MIN_SCARS` points."""
    x = rows["x_m"].to_numpy(float)
    z = rows["z_m"].to_numpy(float)
    mass = rows["mass_kg"].to_numpy(float)
    vin = rows["vin_mps"].to_numpy(float)
    ke_n = 0.5 * mass * vin**2
    x0 = float(model.seeder.x_m)
    z0 = float(model.profile.ground_z(x0))
    idx, merged = scar_rows(x, ke_n, x0, design)
    if idx.size + 1 < MIN_SCARS or idx.size < design.min_scars:
        return None
    x_true = np.concatenate([[x0], x[idx]])
    z_true = np.concatenate([[z0], z[idx]])
    materials = np.concatenate(
        [
            [model.profile.material[int(model.profile.segment_at(x0))]],
            rows["material"].astype(str).to_numpy()[idx],
        ]
    )
    names = [str(k) for k in range(len(x_true))]
    trees = _tree_strikes(model, rows, idx, x_true, names, design, rng)
    dx, dz = _position_errors(x_true, design, rng)
    if trees is not None and len(trees):
        sd_h = design.strike_height_sigma_m
        noisy = trees["strike_height_m"].to_numpy(float) + rng.normal(
            0.0, sd_h, len(trees)
        )
        trees["strike_height_m"] = np.maximum(noisy, 0.05)
    x_obs = x_true + dx
    z_obs = z_true + dz
    # a surveyed path is in order of travel: a scar pushed behind the previous one
    # by the error is still surveyed after it (the geologist walked down the path)
    frame = pd.DataFrame(
        {
            "point": names,
            "x_m": x_obs,
            "z_m": z_obs,
            "lat_deg": np.nan,
            "lon_deg": np.nan,
            "easting_m": np.nan,
            "northing_m": np.nan,
            "material": pd.array(materials, dtype="string"),
        }
    )
    points = PointSet(frame, source=f"{source}: {path_id} points")
    tree_set = None
    if trees is not None:
        tree_set = TreeStrikes(trees, source=f"{source}: {path_id} trees")
    truth = _truth(rows, idx, merged, names, x_true, z_true, x_obs, z_obs, materials)
    return VirtualPath(
        path_id=path_id,
        survey=Survey(points, tree_set),
        truth=truth,
        impacts=ImpactTable(rows, source=source),
    )


def _position_errors(
    x_true: np.ndarray, design: CampaignDesign, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """Plan and height errors of the points: AR(1) along the path (rho =
    exp(-dx/L); independent when L = 0), SD per point from the canopy ranges."""
    plan_sd, height_sd = design.sigma_at(x_true)
    n = x_true.size
    white = rng.standard_normal((2, n))
    if design.correlation_length_m > 0:
        gaps = np.abs(np.diff(x_true))
        rho = np.exp(-gaps / design.correlation_length_m)
        for k in range(1, n):
            white[:, k] = (
                rho[k - 1] * white[:, k - 1]
                + math.sqrt(1.0 - rho[k - 1] ** 2) * white[:, k]
            )
    return plan_sd * white[0], height_sd * white[1]


def _tree_strikes(
    model: Model,
    rows: pd.DataFrame,
    idx: np.ndarray,
    x_true: np.ndarray,
    names: list[str],
    design: CampaignDesign,
    rng: np.random.Generator,
) -> pd.DataFrame | None:
    """True tree strikes (heights before their measurement error) per surveyed
    flight, or None when the design has no trees. The flight from the source
    (detachment, velocity not recorded) gets none."""
    if design.tree_spacing_m <= 0:
        return None
    span = float(x_true[-1] - x_true[0])
    count = rng.poisson(span / design.tree_spacing_m) if span > 0 else 0
    trees_x = np.sort(rng.uniform(x_true[0], x_true[-1], count))
    x = rows["x_m"].to_numpy(float)
    z = rows["z_m"].to_numpy(float)
    vx = rows["vf_x_mps"].to_numpy(float)
    vz = rows["vf_z_mps"].to_numpy(float)
    out = []
    for k in range(1, len(x_true) - 1):
        first, last = idx[k - 1], idx[k]
        for xt in trees_x[(trees_x > x_true[k]) & (trees_x < x_true[k + 1])]:
            height = _height_at(xt, x[first:last], z[first:last], vx[first:last],
                                vz[first:last], model)  # fmt: skip
            if MIN_STRIKE_HEIGHT_M <= height <= design.tree_height_m:
                out.append(
                    {
                        "after_impact": names[k],
                        "horizontal_distance_m": float(xt - x_true[k]),
                        "strike_height_m": float(height),
                        "ground_z_m": np.nan,
                        "species": pd.NA,
                        "dbh_mm": np.nan,
                        "tree": f"T{len(out) + 1}",
                        "row": len(out) + 2,
                        "offset_m": np.nan,
                    }
                )
                break  # one strike per flight
            if math.isfinite(height):
                break  # the rock passed over this tree's crown: the flight has none
    columns = ["after_impact", "horizontal_distance_m", "strike_height_m", "ground_z_m",
               "species", "dbh_mm", "tree", "row", "offset_m"]  # fmt: skip
    return pd.DataFrame(out, columns=columns)


def _height_at(
    xt: float,
    x: np.ndarray,
    z: np.ndarray,
    vx: np.ndarray,
    vz: np.ndarray,
    model: Model,
) -> float:
    """Height of the rock's centre above the ground at ``xt`` [m]: the first
    simulated flight (from impacts ``x, z`` with launch velocities ``vx, vz``) that
    crosses ``xt``; NaN when none does."""
    for i in range(x.size):
        if not (vx[i] > 0 and math.isfinite(vz[i])):
            continue
        end = x[i + 1] if i + 1 < x.size else math.inf
        if x[i] <= xt < end or (i + 1 == x.size and x[i] <= xt):
            t = (xt - x[i]) / vx[i]
            zc = z[i] + vz[i] * t - 0.5 * G * t * t
            return float(zc - model.profile.ground_z(xt))
    return math.nan


def _truth(rows, idx, merged, names, x_true, z_true, x_obs, z_obs, materials):
    n = len(names)

    def col(name: str) -> np.ndarray:
        return np.concatenate([[np.nan], rows[name].to_numpy(float)[idx]])

    mass = col("mass_kg")
    return pd.DataFrame(
        {
            "point": names,
            "x_true_m": x_true,
            "z_true_m": z_true,
            "x_m": x_obs,
            "z_m": z_obs,
            "material": materials,
            "impacts_merged": np.concatenate([[0], merged]).astype(int)[:n],
            "vin_mps": col("vin_mps"),
            "vit_mps": col("vit_mps"),
            "vfn_mps": col("vfn_mps"),
            "vft_mps": col("vft_mps"),
            "e_n": col("e_n"),
            "e_t": col("e_t"),
            "theta_i_deg": col("theta_i_deg"),
            "theta_f_deg": col("theta_f_deg"),
            "ke_n_j": 0.5 * mass * col("vin_mps") ** 2,
        },
        columns=list(TRUTH_COLUMNS),
    )
