"""3-D trajectories -> ImpactTable rows in the 3-D simulator's convention.

Each impact found by :mod:`.contacts` becomes a row exactly as
:func:`fieldkit.model.results3d.impact_table3d` makes one from a simulated impact:
N the normal of the local ground plane, T along the incoming tangential velocity
(in the plane of incidence), ``vin = vi . N``, ``vit = |vi - vin N|``, ``vfn = vf .
N``, ``vft = vf . T`` (a measured rebound may also leave the plane of incidence;
that part shows in ``lateral_deg``), the section-frame columns in the plane of
incidence, so a track3d table and a simulated one compare column by column. Added
per row (extension columns, :mod:`fieldkit.impact_table`): ``chainage_m`` (plan
distance along the path from its first sample: flights are straight in plan),
``lateral_deg`` (change of the plan direction at the impact, counter-clockwise
positive seen from above), ``contact_duration_s`` (where the sampling resolves it,
else empty), ``contact_height_m`` (the centre's distance above the ground plane at
the contact) and ``surface_footprint_m`` (the radius of the disc the plane was
fitted over).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fieldkit.impact_table import ImpactTable
from fieldkit.model.results3d import impact_table3d
from fieldkit.model.terrain import Terrain
from fieldkit.tracking.trajectory3d.contacts import (
    Contact,
    classify_join,
    on_the_ground,
    refine_joins,
)
from fieldkit.tracking.trajectory3d.flights import (
    MIN_NOISE_SD_M,
    fit_flight,
    noise_sd,
    segment_flights,
)
from fieldkit.tracking.trajectory3d.samples import Trajectory3D


@dataclass(frozen=True)
class Body3D:
    """The block: contact radius [m], mass [kg] and radius of gyration [m] (NaN
    when not given)."""

    radius_m: float
    mass_kg: float = float("nan")
    gyration_m: float = float("nan")


@dataclass
class Reduction3D:
    """One trajectory reduced: its noise, flights and joins (impacts and misfits)."""

    path_id: str
    samples: int
    interval_s: float
    noise_sd_m: float
    noise_estimated: bool
    flights: list = field(default_factory=list)
    contacts: list[Contact] = field(default_factory=list)

    @property
    def impacts(self) -> list[Contact]:
        return [c for c in self.contacts if c.kind == "impact"]

    @property
    def misfits(self) -> list[Contact]:
        return [c for c in self.contacts if c.kind == "misfit"]


def reduce_trajectory(
    trajectory: Trajectory3D,
    terrain: Terrain,
    body: Body3D,
    *,
    tolerance_m: float,
    footprint_m: float,
    noise_sd_m: float | None = None,
    drag_per_m: float = 0.0,
) -> Reduction3D:
    """Flights, impacts and misfits of one trajectory on a DEM (``drag_per_m``:
    the quadratic air drag parameter ``k = rho C_d A / (2 m)`` of the flights
    [1/m]; 0 = ballistic)."""
    t, p = trajectory.t_s, trajectory.xyz_m
    sigma = noise_sd(t, p) if noise_sd_m is None else float(noise_sd_m)
    ranges = segment_flights(t, p, sigma, drag_per_m)
    ranges = refine_joins(t, p, ranges, sigma, drag_per_m)
    flights = [fit_flight(t, p, a, b, sigma, drag_per_m) for a, b in ranges]
    ground = [
        on_the_ground(t, p, f, terrain, radius_m=body.radius_m,
                      tolerance_m=tolerance_m, footprint_m=footprint_m,
                      sigma_m=sigma)  # fmt: skip
        for f in flights
    ]
    flights = [f for f, g in zip(flights, ground, strict=True) if not g]
    out = Reduction3D(
        trajectory.path_id,
        len(t),
        trajectory.interval_s,
        max(sigma, MIN_NOISE_SD_M),
        noise_sd_m is None,
        flights,
    )
    for j in range(len(flights) - 1):
        out.contacts.append(
            classify_join(
                j + 1, t, flights[j], flights[j + 1], terrain,
                radius_m=body.radius_m, tolerance_m=tolerance_m,
                footprint_m=footprint_m, omega=trajectory.omega_radps, xyz_m=p,
                omega_vector=trajectory.omega_vector_radps,
            )  # fmt: skip
        )
    return out


def lateral_deg(vi_mps: np.ndarray, vf_mps: np.ndarray) -> float:
    """Change of the plan direction from ``vi`` to ``vf`` [deg], counter-clockwise
    positive seen from above, in (-180, 180].

    Examples
    --------
    >>> lateral_deg(np.array([1.0, 0, -1]), np.array([1.0, 1.0, 1]))
    45.0
    """
    cross = vi_mps[0] * vf_mps[1] - vi_mps[1] * vf_mps[0]
    dot = vi_mps[0] * vf_mps[0] + vi_mps[1] * vf_mps[1]
    return float(np.degrees(np.arctan2(cross, dot)))


#: Uncertainty columns of a track3d row (from the sampling noise).
SD_NAMES = ("vin_sd_mps", "vit_sd_mps", "vfn_sd_mps", "vft_sd_mps", "e_n_sd",
            "e_t_sd", "lateral_sd_deg")  # fmt: skip
#: The plan direction of a velocity is undefined when its plan speed is below this
#: many of its standard uncertainties: ``lateral_deg`` is then empty.
LATERAL_MIN_SDS = 3.0


def _uncertainties(c: Contact, vin, vit, vfn, vft) -> dict:
    """Standard uncertainties from the two flights' velocity SDs (linearised;
    the DEM's normal taken as exact), and ``lateral_deg`` (NaN when a plan
    direction is undefined: plan speed below :data:`LATERAL_MIN_SDS` SDs)."""
    si, sf = c.vi_sd_mps, c.vf_sd_mps
    en, et = -vfn / vin, vft / vit if vit > 0 else float("nan")
    pi_, pf = float(np.hypot(*c.vi_mps[:2])), float(np.hypot(*c.vf_mps[:2]))
    defined = pi_ > LATERAL_MIN_SDS * si and pf > LATERAL_MIN_SDS * sf
    if not (np.isfinite(si) and np.isfinite(sf)):
        defined = pi_ > 0 and pf > 0
    return {
        "vin_sd_mps": si, "vit_sd_mps": si, "vfn_sd_mps": sf, "vft_sd_mps": sf,
        "e_n_sd": float(np.hypot(sf, en * si) / abs(vin)),
        "e_t_sd": float(np.hypot(sf, et * si) / vit) if vit > 0 else float("nan"),
        "lateral_sd_deg": float(np.degrees(np.hypot(si / pi_, sf / pf)))
        if defined else float("nan"),
        "_lateral": lateral_deg(c.vi_mps, c.vf_mps) if defined else float("nan"),
    }  # fmt: skip


def _chainage(red: Reduction3D, trajectory: Trajectory3D) -> dict[int, float]:
    """Plan distance from the first fitted sample to each join (by flight number)."""
    if not red.flights:
        return {}
    first = red.flights[0]
    here = first.position(trajectory.t_s[first.start])[:2]
    total = 0.0
    out = {}
    for c in red.contacts:
        total += float(np.hypot(*(c.point_m[:2] - here)))
        here = c.point_m[:2]
        out[c.flight] = total
    return out


def impact_rows(
    reductions: list[tuple[Reduction3D, Trajectory3D]],
    body: Body3D,
    footprint_m: float,
    material: str | None = None,
) -> ImpactTable:
    """The impacts of every reduced trajectory as one derived ImpactTable
    (``material`` the slope material label of every row; None leaves it empty)."""
    recs: list[dict] = []
    for k, (red, traj) in enumerate(reductions):
        chain = _chainage(red, traj)
        for c in red.impacts:
            n = c.plane.normal
            vin = float(c.vi_mps @ n)
            vt = c.vi_mps - vin * n
            vit = float(np.linalg.norm(vt))
            tang = vt / vit if vit > 0 else np.array([n[2], 0.0, -n[0]]) / np.hypot(
                n[2], n[0]
            )
            vft = float(c.vf_mps @ tang)
            spin_i, spin_f = c.omega_i_radps, c.omega_f_radps
            if c.omega_vector_i_radps is not None:
                axis = np.cross(n, tang)  # rolling toward T: w along N x T
                spin_i = -float(c.omega_vector_i_radps @ axis)
                spin_f = -float(c.omega_vector_f_radps @ axis)
            sd = _uncertainties(c, vin, vit, float(c.vf_mps @ n), vft)
            recs.append({
                "rock": k, "t_s": c.t_s, "x_m": c.point_m[0], "y_m": c.point_m[1],
                "z_m": c.point_m[2], "material_index": 0, "vin_mps": vin,
                "vit_mps": vit, "vfn_mps": float(c.vf_mps @ n), "vft_mps": vft,
                "omega_i_radps": spin_i, "omega_f_radps": spin_f,
                "normal_x": n[0], "normal_y": n[1], "normal_z": n[2],
                "tangent_x": tang[0], "tangent_y": tang[1], "tangent_z": tang[2],
                "mass_kg": body.mass_kg, "radius_m": body.radius_m,
                "gyration_m": body.gyration_m, "tree_strike": 0.0,
                "_path": red.path_id, "_chainage": chain[c.flight],
                "_lateral": sd.pop("_lateral"), **sd,
                "_duration": c.duration_s, "_height": c.height_m,
            })  # fmt: skip
    cols = [
        "rock", "t_s", "x_m", "y_m", "z_m", "material_index", "vin_mps", "vit_mps",
        "vfn_mps", "vft_mps", "omega_i_radps", "omega_f_radps", "normal_x",
        "normal_y", "normal_z", "tangent_x", "tangent_y", "tangent_z", "mass_kg",
        "radius_m", "gyration_m", "tree_strike",
    ]  # fmt: skip
    rows = {c: np.array([r[c] for r in recs], float) for c in cols}
    frame = impact_table3d(rows, [""]).frame
    frame["path_id"] = [r["_path"] for r in recs]
    frame["material"] = np.nan if material is None else material
    frame = frame.drop(columns=["tree_strike"])  # trees are not seen in a trajectory
    for name in SD_NAMES:
        frame[name] = [r[name] for r in recs]
    frame["chainage_m"] = [r["_chainage"] for r in recs]
    frame["lateral_deg"] = [r["_lateral"] for r in recs]
    frame["contact_duration_s"] = [r["_duration"] for r in recs]
    frame["contact_height_m"] = [r["_height"] for r in recs]
    frame["surface_footprint_m"] = footprint_m
    frame["omega_source"] = np.where(
        np.isfinite(frame["omega_i_radps"].to_numpy(float)), "measured", "none"
    )
    return ImpactTable(frame, source="track3d").derive()
