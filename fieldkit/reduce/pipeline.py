"""Survey -> ImpactTable: the thesis spreadsheet of §7.1, one step per function.

:func:`reduce_survey` reads like the spreadsheet:

1. :func:`section_slopes` -- the ground dip psi at each point: the chord from the
   previous point (thesis "slope angle above impact point"), or the surveyed slope;
2. :meth:`Survey.trees_by_launch` -- tree strikes keyed by the flight they fix;
3. :func:`fieldkit.reduce.flights.solve_flights` -- each flight's parabola (tree
   three-point solve, given angle, or assumed ``theta0_deg``);
4. :func:`impact_rows` -- primary ImpactTable columns: velocities at the end of each
   flight (impact) and start of the next (restitution), body, spin, flight heights;
5. :meth:`ImpactTable.derive` -- N/T components, angles, e_n, e_t, energies, heads;
6. :func:`add_flight_energy` -- KE gained in each flight (``flight_dke_j``).
7. :func:`~fieldkit.reduce.impact_theory.add_theory_columns` -- impact-mechanics
   energy change beside the measured one (``dke_theory_j``, thesis §6.3).

The source (first point) has no impact velocity and the stopped point (last) no
restitution velocity: those stay NaN.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.impact_table import ImpactTable
from fieldkit.physics.bodies import ResolvedBody
from fieldkit.physics.energy import kinetic_energy
from fieldkit.reduce.flights import SolvedFlight, solve_flights
from fieldkit.reduce.impact_theory import DEFAULT_FRICTION, add_theory_columns
from fieldkit.survey import Survey


@dataclass(frozen=True)
class ReduceOptions:
    """What the command line adds to the survey files.

    Attributes
    ----------
    path_id
        Rock / path identifier written to every row.
    theta0_deg
        Assumed restitution angle to the ground [deg] where no tree or measured angle
        defines a flight (None: every flight must be defined).
    body
        Mass, contact radius, radius of gyration
        (:func:`fieldkit.physics.bodies.resolve_body`); unknown values leave their
        columns NaN.
    friction
        Contact friction coefficient mu [-] for the impact-mechanics energy beside
        the measured one (:func:`fieldkit.reduce.impact_theory.add_theory_columns`).
    """

    path_id: str
    theta0_deg: float | None = None
    body: ResolvedBody = field(default_factory=ResolvedBody)
    friction: float = DEFAULT_FRICTION


def section_slopes(
    x_m: np.ndarray, z_m: np.ndarray, surveyed_deg: np.ndarray | None = None
) -> tuple[np.ndarray, list[str | None]]:
    """Ground dip psi at each point [deg] and where it came from.

    Default: the chord from the previous point, ``psi = atan(-(z_j - z_{j-1}) /
    (x_j - x_{j-1}))`` (positive descending toward +x); a finite surveyed slope
    overrides it. The first point has no previous point: NaN unless surveyed.

    Examples
    --------
    >>> import numpy as np
    >>> x, z = np.array([0.0, 10.0, 20.0]), np.array([10.0, 0.0, 0.0])
    >>> psi, src = section_slopes(x, z)
    >>> (psi + 0.0).round(1).tolist(), src
    ([nan, 45.0, 0.0], [None, 'chord', 'chord'])
    """
    x = np.asarray(x_m, float)
    z = np.asarray(z_m, float)
    psi = np.full(len(x), np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        psi[1:] = np.degrees(np.arctan2(-(z[1:] - z[:-1]), x[1:] - x[:-1]))
    source: list[str | None] = [None] + ["chord"] * (len(x) - 1)
    if surveyed_deg is not None:
        surveyed = np.asarray(surveyed_deg, float)
        for i in np.flatnonzero(np.isfinite(surveyed)):
            psi[i] = surveyed[i]
            source[i] = "surveyed"
    return psi, source


def impact_rows(
    frame: pd.DataFrame,
    slope_deg: np.ndarray,
    slope_source: list[str | None],
    flights: list[SolvedFlight],
    options: ReduceOptions,
    *,
    trees_given: bool,
) -> pd.DataFrame:
    """Primary ImpactTable columns, one row per point (impacts plus source and stop).

    Row ``j`` gets the impact velocity at the end of flight ``j-1`` and the
    restitution velocity at the start of flight ``j``; the flight columns describe the
    flight leaving ``j``. Spin is estimated as ``omega_f = -V_f / r`` (eq. 3.17,
    clockwise negative for travel toward +x) and carried unchanged through the flight,
    so ``omega_i`` of the next impact equals it (§3.1.3: no torque in flight).
    """
    n = len(frame)
    nan = np.full(n, np.nan)
    vi_x, vi_z, vf_x, vf_z = nan.copy(), nan.copy(), nan.copy(), nan.copy()
    t_flight, length, h_vert, h_norm = nan.copy(), nan.copy(), nan.copy(), nan.copy()
    theta0 = nan.copy()
    theta0_source: list[str | None] = [None] * n
    tree_strike: list[bool | None] = [None] * n
    for j, f in enumerate(flights):
        fl = f.flight
        vf_x[j], vf_z[j] = float(fl.launch_vx_mps), float(fl.launch_vz_mps)
        vi_x[j + 1], vi_z[j + 1] = float(fl.arrival_vx_mps), float(fl.arrival_vz_mps)
        t_flight[j], length[j] = float(fl.time_s), float(fl.dx_m)
        h_vert[j], h_norm[j] = float(fl.hmax_vertical_m), float(fl.hmax_normal_m)
        theta0[j], theta0_source[j] = f.theta0_deg, f.theta0_source
        if trees_given:
            tree_strike[j + 1] = f.tree is not None
    t_s = np.concatenate([[0.0], np.cumsum(t_flight[:-1])])

    body = options.body
    mass, r, k = (
        math.nan if value is None else value
        for value in (body.mass_kg, body.radius_m, body.gyration_m)
    )
    speed_f = np.hypot(vf_x, vf_z)
    omega_f = -speed_f / r if math.isfinite(r) else nan.copy()
    omega_i = np.concatenate([[np.nan], omega_f[:-1]])

    out = pd.DataFrame(
        {
            "path_id": options.path_id,
            "point": frame["point"].astype(str).to_numpy(),
            "x_m": frame["x_m"].to_numpy(float),
            "z_m": frame["z_m"].to_numpy(float),
            "slope_deg": slope_deg,
            "material": (frame["material"] if "material" in frame else pd.NA),
            "mass_kg": mass,
            "radius_m": r,
            "gyration_m": k,
            "theta0_deg": theta0,
            "theta0_source": pd.array(theta0_source, dtype="string"),
            "vi_x_mps": vi_x,
            "vi_z_mps": vi_z,
            "vf_x_mps": vf_x,
            "vf_z_mps": vf_z,
            "omega_i_radps": omega_i,
            "omega_f_radps": omega_f,
            "flight_time_s": t_flight,
            "flight_length_m": length,
            "hmax_vertical_m": h_vert,
            "hmax_normal_m": h_norm,
            "tree_strike": pd.array(tree_strike, dtype="boolean"),
            "t_s": t_s,
            "omega_source": "estimated" if math.isfinite(r) else "none",
            "slope_source": pd.array(slope_source, dtype="string"),
        }
    )
    out["material"] = out["material"].astype("string")
    return out


def add_flight_energy(table: ImpactTable) -> ImpactTable:
    """Add ``flight_dke_j``: KE gained in the flight arriving at each point [J].

    ``flight_dke_j[j] = ke_i_j[j] - ke_f_j[j-1]``; by energy conservation in
    drag-free flight it equals ``m g (z_{j-1} - z_j)`` (NaN at the source).
    """
    f = table.frame.copy()
    m = f["mass_kg"].to_numpy(float)
    ke_i = kinetic_energy(m, f["vi_mps"].to_numpy(float))
    ke_f_prev = np.concatenate(
        [[np.nan], kinetic_energy(m, f["vf_mps"].to_numpy(float))[:-1]]
    )
    gained = ke_i - ke_f_prev
    same_path = f["path_id"].eq(f["path_id"].shift()).fillna(False).to_numpy(bool)
    f["flight_dke_j"] = np.where(same_path, gained, np.nan)
    return ImpactTable(f, source=table.source)


def reduce_survey(survey: Survey, options: ReduceOptions | None = None) -> ImpactTable:
    """Reduce a surveyed path to an :class:`ImpactTable` (thesis §7.1).

    Parameters
    ----------
    survey
        The path's points (``frame`` with ``point, x_m, z_m`` and optional
        ``material``, ``slope_deg`` (surveyed psi) and ``theta0_deg`` (measured
        restitution angle)) and its tree strikes, if a tree file was given.
    options
        Path id, assumed ``theta0_deg``, body and friction.

    Returns
    -------
    ImpactTable
        Every contract column the data allow, plus ``omega_source``, ``slope_source``
        and ``flight_dke_j``.

    Raises
    ------
    FieldkitError
        One line naming the file and point or row (see
        :func:`fieldkit.reduce.flights.solve_flights`).
    """
    frame = survey.points.frame.reset_index(drop=True)
    source = survey.source
    options = options or ReduceOptions(path_id="path")
    if len(frame) < 2:
        raise InputFileError(
            "a path needs at least two points (a source and an impact); "
            f"got {len(frame)}",
            source=source,
        )
    x = frame["x_m"].to_numpy(float)
    z = frame["z_m"].to_numpy(float)
    surveyed = frame["slope_deg"].to_numpy(float) if "slope_deg" in frame else None
    given = frame["theta0_deg"].to_numpy(float) if "theta0_deg" in frame else None

    slope, slope_source = section_slopes(x, z, surveyed)
    names = frame["point"].astype(str).tolist()
    by_launch = survey.trees_by_launch()
    flights = solve_flights(
        names,
        x,
        z,
        slope,
        theta0_deg=options.theta0_deg,
        given_theta0_deg=given,
        trees=by_launch,
        points_source=source,
        trees_source=None if survey.trees is None else survey.trees.source,
    )
    rows = impact_rows(
        frame,
        slope,
        slope_source,
        flights,
        options,
        trees_given=survey.trees is not None,
    )
    table = ImpactTable(rows, source=source).derive()
    table = add_flight_energy(table)
    return add_theory_columns(table, friction=options.friction)
