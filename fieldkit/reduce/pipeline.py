"""Survey -> ImpactTable: the thesis spreadsheet of §7.1, one step per function.

:func:`reduce_survey` reads like the spreadsheet:

1. :func:`section_slopes` -- the ground dip psi at each point: the chord from the
   previous point (thesis "slope angle above impact point"), or the surveyed slope;
2. :meth:`Survey.trees_by_launch` -- tree strikes keyed by the flight they fix;
3. :func:`fieldkit.reduce.flights.solve_flights` -- each flight's parabola (tree
   three-point solve, given angle, or assumed ``theta0_deg``);
4. :func:`impact_rows` -- primary ImpactTable columns: velocities at the end of each
   flight (impact) and start of the next (restitution), body, spin, flight heights;
5. :func:`next_chord_e_n` -- ``e_n`` again with the chord to the *next* point as the
   slope, where the slope is the default chord from the previous one
   (``e_n_next_chord``): how much ``e_n`` hangs on that choice;
6. :func:`~fieldkit.reduce.uncertainty.propagate` -- ``e_n_sd``, ``e_t_sd``,
   ``vi_sd_mps`` and the other ``*_sd`` columns of
   :data:`~fieldkit.reduce.uncertainty.OUTPUTS` from the position error, by repeating
   steps 1-4 on perturbed points and tree-strike heights (:func:`point_kinematics`);
7. :meth:`ImpactTable.derive` -- N/T components, angles, e_n, e_t, energies, heads and
   the quality flags (``qa_flags``);
8. :func:`add_flight_energy` -- KE gained in each flight (``flight_dke_j``).
9. :func:`~fieldkit.reduce.impact_theory.add_theory_columns` -- impact-mechanics
   energy change beside the measured one (``dke_theory_j``, thesis §6.3).

The source (first point) has no impact velocity and the stopped point (last) no
restitution velocity: those stay NaN; so do both ends of a flight with no ballistic
solution (``flight_unsolved`` says why), which the fit and the diagnosis leave out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.impact_table import (
    CORR_COLUMNS,
    ERROR_MODEL_COLUMNS,
    SD_COLUMNS,
    ImpactTable,
    restitution,
)
from fieldkit.physics.bodies import ResolvedBody
from fieldkit.physics.energy import kinetic_energy
from fieldkit.reduce.flights import SolvedFlight, solve_flights
from fieldkit.reduce.impact_theory import DEFAULT_FRICTION, add_theory_columns
from fieldkit.reduce.uncertainty import (
    OUTPUTS,
    UNSOLVED,
    PositionError,
    Propagated,
    propagate,
)
from fieldkit.survey import Survey, TreeStrike


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
    position_error
        The survey's position error, propagated to ``e_n_sd``, ``e_t_sd``,
        ``vi_sd_mps`` and the other ``*_sd`` columns
        (:mod:`fieldkit.reduce.uncertainty`; default 0.5 m in plan and in height per
        point, 0.25 m per tree-strike height); None leaves those columns out.
    """

    path_id: str
    theta0_deg: float | None = None
    body: ResolvedBody = field(default_factory=ResolvedBody)
    friction: float = DEFAULT_FRICTION
    position_error: PositionError | None = field(default_factory=PositionError)


@dataclass(frozen=True)
class Reduction:
    """A reduced path: the table and how its uncertainties were obtained."""

    table: ImpactTable
    uncertainty: Propagated | None = None


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

    An unsolved flight leaves its launch row's restitution velocity, spin and flight
    columns and its arrival row's impact velocity NaN (and ``t_s`` from its arrival
    on: the time of the flight is unknown), and puts its reason in the launch row's
    ``flight_unsolved`` (NA on every other row).
    """
    n = len(frame)
    nan = np.full(n, np.nan)
    vi_x, vi_z, vf_x, vf_z = flight_velocities(flights, n)
    t_flight, length, h_vert, h_norm = nan.copy(), nan.copy(), nan.copy(), nan.copy()
    theta0 = nan.copy()
    theta0_source: list[str | None] = [None] * n
    tree_strike: list[bool | None] = [None] * n
    unsolved: list[str | None] = [None] * n
    for j, f in enumerate(flights):
        if trees_given:
            tree_strike[j + 1] = f.tree is not None
        fl = f.flight
        if fl is None:
            unsolved[j] = f.unsolved
            continue
        t_flight[j], length[j] = float(fl.time_s), float(fl.dx_m)
        h_vert[j], h_norm[j] = float(fl.hmax_vertical_m), float(fl.hmax_normal_m)
        theta0[j], theta0_source[j] = f.theta0_deg, f.theta0_source
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
            "flight_unsolved": pd.array(unsolved, dtype="string"),
        }
    )
    out["material"] = out["material"].astype("string")
    return out


def flight_velocities(
    flights: list[SolvedFlight], n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``vi_x, vi_z, vf_x, vf_z`` [m/s] of ``n`` points from the ``n - 1`` flights.

    Point ``j`` arrives at the end of flight ``j - 1`` and leaves on flight ``j``;
    NaN where there is no such flight (the source's impact, the stop's restitution)
    or it is unsolved.
    """
    vi_x, vi_z, vf_x, vf_z = (np.full(n, np.nan) for _ in range(4))
    for j, f in enumerate(flights):
        fl = f.flight
        if fl is None:
            continue
        vf_x[j], vf_z[j] = float(fl.launch_vx_mps), float(fl.launch_vz_mps)
        vi_x[j + 1], vi_z[j + 1] = float(fl.arrival_vx_mps), float(fl.arrival_vz_mps)
    return vi_x, vi_z, vf_x, vf_z


def next_chord_e_n(
    x_m: np.ndarray,
    z_m: np.ndarray,
    slope_source: list[str | None],
    velocities: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> np.ndarray:
    """``e_n`` with the chord to the next point as the slope [-].

    The default slope at an impact is the chord from the previous point (thesis "slope
    angle above impact point"); the chord to the next point is the ground on the other
    side. On a bent slope the two bracket the ground at the impact, so the difference
    of the two ``e_n`` is how much the result hangs on the choice. NaN where the slope
    was surveyed (no choice made) and at the last point (no next point).
    """
    x = np.asarray(x_m, float)
    z = np.asarray(z_m, float)
    psi = np.full(len(x), np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        psi[:-1] = np.degrees(np.arctan2(-(z[1:] - z[:-1]), x[1:] - x[:-1]))
    chord = np.array([source == "chord" for source in slope_source], dtype=bool)
    psi = np.where(chord, psi, np.nan)
    return restitution(*velocities, psi)["e_n"]


def _solve(
    survey: Survey, options: ReduceOptions, x: np.ndarray, z: np.ndarray
) -> tuple[np.ndarray, list[str | None], list[SolvedFlight]]:
    """Steps 1-3 for points at ``(x, z)``: slopes, their sources and the flights."""
    frame = survey.points.frame
    surveyed = frame["slope_deg"].to_numpy(float) if "slope_deg" in frame else None
    given = frame["theta0_deg"].to_numpy(float) if "theta0_deg" in frame else None
    slope, slope_source = section_slopes(x, z, surveyed)
    flights = solve_flights(
        survey.points.names,
        x,
        z,
        slope,
        theta0_deg=options.theta0_deg,
        given_theta0_deg=given,
        trees=survey.trees_by_launch(),
        points_source=survey.source,
        trees_source=None if survey.trees is None else survey.trees.source,
    )
    return slope, slope_source, flights


def point_kinematics(
    survey: Survey,
    options: ReduceOptions,
    x_m: np.ndarray,
    z_m: np.ndarray,
    strike_heights_m: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """The :data:`~fieldkit.reduce.uncertainty.OUTPUTS` of every point with the points
    moved to ``(x_m, z_m)`` and the tree strikes to ``strike_heights_m`` (in the rows'
    order; None: as surveyed): steps 1-4 of :func:`reduce_survey` without building a
    table (what :func:`~fieldkit.reduce.uncertainty.propagate` repeats). Tree strikes
    keep their distance from the (moved) launch point.
    """
    return PointKinematics(survey, options)(x_m, z_m, strike_heights_m)


class PointKinematics:
    """:func:`point_kinematics` prepared once for one survey: the Monte Carlo of
    :func:`~fieldkit.reduce.uncertainty.propagate` calls it a hundred times, so what
    does not move with the points (names, surveyed slopes and angles, which flight
    each tree strike fixes, its taped distance) is read from the frames once."""

    def __init__(self, survey: Survey, options: ReduceOptions) -> None:
        frame = survey.points.frame.reset_index(drop=True)
        self.n = len(frame)
        self.names = survey.points.names
        self.surveyed = (
            frame["slope_deg"].to_numpy(float) if "slope_deg" in frame else None
        )
        self.given = (
            frame["theta0_deg"].to_numpy(float) if "theta0_deg" in frame else None
        )
        self.options = options
        self.source = survey.source
        self.trees_source = None if survey.trees is None else survey.trees.source
        launch = {name: j for j, name in enumerate(self.names)}
        # (row in the tree file's order, launch index, tree strike as surveyed,
        # ground given in the file or NaN)
        self.trees: list[tuple[int, int, TreeStrike, float]] = []
        if survey.trees is not None:
            by_launch = survey.trees_by_launch()  # validates, as the nominal solve
            grounds = survey.trees.frame["ground_z_m"].to_numpy(float)
            keys = survey.trees.frame["after_impact"].astype(str).to_list()
            for row, key in enumerate(keys):
                tree = by_launch[key]
                self.trees.append((row, launch[key], tree, float(grounds[row])))

    def __call__(
        self,
        x_m: np.ndarray,
        z_m: np.ndarray,
        strike_heights_m: np.ndarray | None = None,
    ) -> dict[str, np.ndarray]:
        x = np.asarray(x_m, float)
        z = np.asarray(z_m, float)
        slope, _ = section_slopes(x, z, self.surveyed)
        trees = {}
        for row, j, tree, ground in self.trees:
            if not math.isfinite(ground):
                dx = x[j + 1] - x[j]
                ground = (
                    float(z[j] + (z[j + 1] - z[j]) * tree.distance_m / dx)
                    if dx > 0
                    else math.nan
                )
            height = (
                tree.height_m
                if strike_heights_m is None
                else float(strike_heights_m[row])
            )
            trees[tree.after_impact] = replace(tree, height_m=height, ground_z_m=ground)
        flights = solve_flights(
            self.names,
            x,
            z,
            slope,
            theta0_deg=self.options.theta0_deg,
            given_theta0_deg=self.given,
            trees=trees,
            points_source=self.source,
            trees_source=self.trees_source,
        )
        values = restitution(*flight_velocities(flights, self.n), slope)
        out = {name: values[name] for name in OUTPUTS}
        unsolved = np.zeros(self.n)
        unsolved[[j for j, f in enumerate(flights) if f.flight is None]] = 1.0
        out[UNSOLVED] = unsolved
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
        Path id, assumed ``theta0_deg``, body, friction and position error.

    Returns
    -------
    ImpactTable
        Every contract column the data allow, plus ``omega_source``, ``slope_source``,
        ``flight_unsolved``, ``flight_dke_j``, ``e_n_next_chord``, the ``*_sd``
        columns, the error correlations ``vin_vfn_corr`` and ``vit_vft_corr`` and
        the error model used (``x_sd_m``, ``z_sd_m``, with trees
        ``strike_height_sd_m``) (:func:`reduce_path` also says how the
        uncertainties were obtained). A flight with no ballistic solution is kept
        unsolved (:func:`fieldkit.reduce.flights.solve_flights`): its reason in
        ``flight_unsolved``, its two ends' velocities NaN.

    Raises
    ------
    FieldkitError
        One line naming the file and point or row (see
        :func:`fieldkit.reduce.flights.solve_flights`).
    """
    return reduce_path(survey, options).table


def reduce_path(survey: Survey, options: ReduceOptions | None = None) -> Reduction:
    """:func:`reduce_survey`, with the record of the uncertainty propagation."""
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
    slope, slope_source, flights = _solve(survey, options, x, z)
    rows = impact_rows(
        frame,
        slope,
        slope_source,
        flights,
        options,
        trees_given=survey.trees is not None,
    )
    rows["e_n_next_chord"] = next_chord_e_n(
        x, z, slope_source, flight_velocities(flights, len(frame))
    )
    spread = None
    if options.position_error is not None:
        heights = None
        if survey.trees is not None:
            heights = survey.trees.frame["strike_height_m"].to_numpy(float)
        spread = propagate(
            PointKinematics(survey, options),
            x,
            z,
            options.position_error,
            strike_heights_m=heights,
            correlations=tuple(CORR_COLUMNS),
        )
        nominal = restitution(*flight_velocities(flights, len(frame)), slope)
        known = {name: np.isfinite(nominal[name]) for name in OUTPUTS}
        for name, values in spread.sd.items():
            value = next(v for v, c in SD_COLUMNS.items() if c == name)
            rows[name] = np.where(known[value], values, np.nan)  # no value, no sd
        for (a, b), name in CORR_COLUMNS.items():
            rows[name] = np.where(known[a] & known[b], spread.corr[name], np.nan)
        model = options.position_error
        rows[ERROR_MODEL_COLUMNS["x_m"]] = model.position_sigma_m
        rows[ERROR_MODEL_COLUMNS["z_m"]] = model.elevation_sigma_m
        if survey.trees is not None:
            rows[ERROR_MODEL_COLUMNS["strike_height_m"]] = model.strike_height_sigma_m
    table = ImpactTable(rows, source=source).derive()
    table = add_flight_energy(table)
    table = add_theory_columns(table, friction=options.friction)
    return Reduction(table=table, uncertainty=spread)
