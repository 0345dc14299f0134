"""The ImpactTable: one row per impact, the spine every stage reads or writes.

Survey reduction and video tracking produce it; fitting, diagnosis, figures and exports
consume it. The column names and meanings are a contract (docs/architecture.md §3);
units are in the names. Primary columns (positions, slope, section-frame velocities,
body, spin) are what a producer measures; :meth:`ImpactTable.derive` computes every
derived column from them with the conventions of docs/architecture.md §2, so both
producers agree by construction.

Every derived table carries ``qa_flags`` (docs/architecture.md §3): the quality flags
of :data:`QA_FLAGS`, ``;``-separated, computed in one place (:func:`quality_flags`,
applied by :meth:`ImpactTable.derive`) from the table's own columns, so survey
reduction, video tracking and simulation all flag the same things the same way.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.outputs import (
    OutputSet,
    escape_formulas,
    protect_formula_cells,
    unescape_formulas,
    write_file,
)
from fieldkit.physics.constants import (
    MAX_LENGTH_M,
    MAX_MASS_KG,
    MAX_SPEED_MPS,
    MIN_LENGTH_M,
    MIN_MASS_KG,
)
from fieldkit.physics.energy import energy_head, kinetic_energy, rotational_energy
from fieldkit.physics.local_axes import angle_to_ground_deg, to_local


@dataclass(frozen=True)
class Column:
    """One ImpactTable column: name (with unit), kind, whether required, meaning."""

    name: str
    kind: str  # "str", "float", "bool"
    required: bool
    description: str


#: Contract columns in their canonical order (docs/architecture.md §3).
CONTRACT_COLUMNS: tuple[Column, ...] = (
    Column("path_id", "str", True, "rock / test identifier"),
    Column("point", "str", True, "impact identifier"),
    Column("x_m", "float", True, "impact x in the section plane [m]"),
    Column("z_m", "float", True, "impact elevation [m]"),
    Column("slope_deg", "float", True, "ground dip psi used for N/T axes [deg]"),
    Column("material", "str", False, "slope material label"),
    Column("mass_kg", "float", False, "body mass [kg]"),
    Column("radius_m", "float", False, "body contact radius [m]"),
    Column("gyration_m", "float", False, "radius of gyration k [m]"),
    Column(
        "theta0_deg",
        "float",
        False,
        "restitution angle to ground for the next flight [deg]",
    ),
    Column("theta0_source", "str", False, "tree | assumed | video | given"),
    Column("vi_x_mps", "float", True, "impact velocity, x [m/s]"),
    Column("vi_z_mps", "float", True, "impact velocity, z [m/s]"),
    Column("vf_x_mps", "float", True, "restitution velocity, x [m/s]"),
    Column("vf_z_mps", "float", True, "restitution velocity, z [m/s]"),
    Column("vi_mps", "float", False, "impact speed [m/s]"),
    Column("vf_mps", "float", False, "restitution speed [m/s]"),
    Column("vin_mps", "float", False, "impact normal velocity (<0) [m/s]"),
    Column("vit_mps", "float", False, "impact tangential velocity [m/s]"),
    Column("vfn_mps", "float", False, "restitution normal velocity (>0) [m/s]"),
    Column("vft_mps", "float", False, "restitution tangential velocity [m/s]"),
    Column("theta_i_deg", "float", False, "impact angle to the ground [deg]"),
    Column("theta_f_deg", "float", False, "restitution angle to the ground [deg]"),
    Column(
        "e_n", "float", False, "normal coefficient of restitution -vfn/vin (eq. 4.6)"
    ),
    Column(
        "e_t", "float", False, "tangential coefficient of restitution vft/vit (eq. 4.7)"
    ),
    Column("omega_i_radps", "float", False, "angular velocity before impact [rad/s]"),
    Column("omega_f_radps", "float", False, "angular velocity after impact [rad/s]"),
    Column("ke_i_j", "float", False, "kinetic energy before impact [J]"),
    Column("ke_f_j", "float", False, "kinetic energy after impact [J]"),
    Column("dke_j", "float", False, "ke_f - ke_i (negative = loss) [J]"),
    Column("re_i_j", "float", False, "rotational energy before impact [J]"),
    Column("re_f_j", "float", False, "rotational energy after impact [J]"),
    Column(
        "energy_head_i_m", "float", False, "energy head z + v^2/2g before impact [m]"
    ),
    Column("energy_head_f_m", "float", False, "energy head after impact [m]"),
    Column(
        "flight_time_s",
        "float",
        False,
        "duration of the flight leaving this impact [s]",
    ),
    Column("flight_length_m", "float", False, "horizontal length of that flight [m]"),
    Column(
        "hmax_vertical_m", "float", False, "max vertical height above the chord [m]"
    ),
    Column("hmax_normal_m", "float", False, "max height normal to the chord [m]"),
    Column("tree_strike", "bool", False, "the flight arriving here struck a tree"),
    Column("t_s", "float", False, "time of the impact [s]"),
    Column("qa_flags", "str", False, "';'-separated quality flags (see QA_FLAGS)"),
)

#: Documented extension columns that fieldkit producers may add (kept on read/write).
EXTENSION_COLUMNS: tuple[Column, ...] = (
    Column("omega_source", "str", False, "measured | estimated (v/r, eq. 3.17) | none"),
    Column("slope_source", "str", False, "chord | surveyed | given | video | assumed"),
    Column("flight_dke_j", "float", False, "KE gained in the flight arriving here [J]"),
    Column("contact_duration_s", "float", False, "time in contact at this impact [s]"),
    Column(
        "dke_theory_j",
        "float",
        False,
        "impact-mechanics change of KE + RE from the contact impulse [J] (§6.3)",
    ),
    Column(
        "theory_loss_fraction", "float", False, "dke_theory_j / dke_j (thesis §6.3)"
    ),
    Column(
        "e_n_next_chord",
        "float",
        False,
        "e_n with the chord to the next point as the slope (where slope_deg is the "
        "chord from the previous point)",
    ),
    Column("e_n_sd", "float", False, "standard uncertainty of e_n [-]"),
    Column("e_t_sd", "float", False, "standard uncertainty of e_t [-]"),
    Column("vi_sd_mps", "float", False, "standard uncertainty of vi_mps [m/s]"),
    Column("vf_sd_mps", "float", False, "standard uncertainty of vf_mps [m/s]"),
    Column("vin_sd_mps", "float", False, "standard uncertainty of vin_mps [m/s]"),
    Column("vit_sd_mps", "float", False, "standard uncertainty of vit_mps [m/s]"),
    Column("vfn_sd_mps", "float", False, "standard uncertainty of vfn_mps [m/s]"),
    Column("vft_sd_mps", "float", False, "standard uncertainty of vft_mps [m/s]"),
    Column(
        "theta_i_sd_deg", "float", False, "standard uncertainty of theta_i_deg [deg]"
    ),
    Column(
        "flight_unsolved",
        "str",
        False,
        "why the flight leaving this point has no ballistic solution (NA: solved or "
        "no flight); then vf here and vi at the next point are unknown",
    ),
    Column(
        "x_sd_m", "float", False, "standard uncertainty of x_m the reduction used [m]"
    ),
    Column(
        "z_sd_m", "float", False, "standard uncertainty of z_m the reduction used [m]"
    ),
    Column(
        "strike_height_sd_m",
        "float",
        False,
        "standard uncertainty of a tree-strike height the reduction used [m]",
    ),
    Column(
        "y_m",
        "float",
        False,
        "3-D rows: contact y in the DEM's coordinates [m] (x_m, z_m: its x and "
        "elevation)",
    ),
    *(
        Column(f"normal_{a}", "float", False, f"3-D rows: unit normal N, DEM {a} [-]")
        for a in "xyz"
    ),
    *(
        Column(
            f"tangent_{a}",
            "float",
            False,
            f"3-D rows: unit tangent T (plane of incidence), DEM {a} [-]",
        )
        for a in "xyz"
    ),
    Column(
        "dip_deg", "float", False, "3-D rows: dip of the surface N is normal to [deg]"
    ),
    Column(
        "chainage_m",
        "float",
        False,
        "3-D rows from a trajectory (fieldkit track3d): plan distance along the path "
        "from its first sample to the impact (unrolled; flights are straight in "
        "plan) [m]",
    ),
    Column(
        "lateral_deg",
        "float",
        False,
        "3-D rows from a trajectory: change of the plan direction of travel at the "
        "impact, from the incoming to the outgoing velocity, counter-clockwise "
        "positive seen from above, in (-180, 180] [deg]",
    ),
    Column(
        "lateral_sd_deg",
        "float",
        False,
        "standard uncertainty of lateral_deg from the sampling noise [deg]",
    ),
    Column(
        "contact_height_m",
        "float",
        False,
        "3-D rows from a trajectory: the centre's distance above the local ground "
        "plane at the impact, along N (about the radius for a block, 0 for a "
        "simulated lumped mass) [m]",
    ),
    Column(
        "surface_footprint_m",
        "float",
        False,
        "3-D rows from a trajectory: radius of the disc of DEM the local ground "
        "plane (N) was fitted over [m]",
    ),
    Column(
        "vin_vfn_corr",
        "float",
        False,
        "correlation of the errors of vin_mps and vfn_mps (one surveyed point) [-]",
    ),
    Column(
        "vit_vft_corr",
        "float",
        False,
        "correlation of the errors of vit_mps and vft_mps (one surveyed point) [-]",
    ),
)

#: Value column -> its standard-uncertainty column (docs/architecture.md §3
#: ``<column>_sd``, the unit suffix kept last), for every value a reduction or a
#: track analysis propagates its measurement error to.
SD_COLUMNS: dict[str, str] = {
    "e_n": "e_n_sd",
    "e_t": "e_t_sd",
    "vi_mps": "vi_sd_mps",
    "vf_mps": "vf_sd_mps",
    "vin_mps": "vin_sd_mps",
    "vit_mps": "vit_sd_mps",
    "vfn_mps": "vfn_sd_mps",
    "vft_mps": "vft_sd_mps",
    "theta_i_deg": "theta_i_sd_deg",
}

#: Pairs of values whose errors are correlated -> their correlation column
#: (``<a>_<b>_corr``, units dropped): an impact's arrival and rebound velocities
#: share the surveyed point between the two flights, so a reduction's Monte Carlo
#: gives each row the correlation coefficient of their errors over the draws.
CORR_COLUMNS: dict[tuple[str, str], str] = {
    ("vin_mps", "vfn_mps"): "vin_vfn_corr",
    ("vit_mps", "vft_mps"): "vit_vft_corr",
}

#: The measurement error model a reduction used, on every row: surveyed quantity ->
#: its standard-uncertainty column (``strike_height_sd_m`` only with a tree file).
ERROR_MODEL_COLUMNS: dict[str, str] = {
    "x_m": "x_sd_m",
    "z_m": "z_sd_m",
    "strike_height_m": "strike_height_sd_m",
}

COLUMNS_BY_NAME: dict[str, Column] = {
    c.name: c for c in CONTRACT_COLUMNS + EXTENSION_COLUMNS
}
REQUIRED_COLUMNS: tuple[str, ...] = tuple(
    c.name for c in CONTRACT_COLUMNS if c.required
)
THETA0_SOURCES: frozenset[str] = frozenset({"tree", "assumed", "video", "given"})
#: Key of the frame's attrs holding the columns the table's source had.
_GIVEN = "fieldkit_given_columns"


class _ColumnNames(tuple):
    """The given column names kept in a frame's attrs. pandas deep-copies attrs at
    every operation (each column read); names are immutable, so the copy is the
    object itself (a tuple of 60 names was copied a million times per reduction's
    Monte Carlo)."""

    __slots__ = ()

    def __deepcopy__(self, memo: dict) -> _ColumnNames:
        return self

FORMATS: dict[str, str] = {".csv": "csv", ".parquet": "parquet", ".xlsx": "xlsx"}

_EPS = 1e-12

#: Quality flags: short stable names -> one-line meanings (the ``qa_flags`` column).
QA_FLAGS: dict[str, str] = {
    "energy_gained": "the rock left faster than it arrived (ke_f > ke_i beyond "
    "rounding): kinetic energy gained at the impact",
    "e_n_negative": "e_n < 0: the restitution velocity points into the ground",
    "e_t_above_1": "e_t > 1: tangential speed gained at the impact (spin turned "
    "into translation, or survey error)",
    "speed_high": "impact or restitution speed above 60 m/s, beyond any rock fall "
    "the thesis reports (48 m/s at Mt. Stephen, §2.1.1)",
    "flight_high": "the flight leaving the impact rises more than 10 m normal to its "
    "chord (thesis §3.2: usually 1-2 m, 4 m the highest observed)",
    "slope_from_chord": "slope_deg is the chord from the previous point, not a "
    "surveyed slope (docs/architecture.md §2 default)",
    "slope_sensitive": "taking the chord to the next point as the slope moves e_n by "
    "more than its standard uncertainty e_n_sd",
    "spin_estimated": "omega is estimated as v/r (eq. 3.17), not measured",
}

#: Short words for each quality flag, for figure legends (matplotlib mathtext).
QA_FLAG_LABELS: dict[str, str] = {
    "energy_gained": "kinetic energy gained",
    "e_n_negative": "$e_N$ < 0",
    "e_t_above_1": "$e_T$ > 1",
    "speed_high": "speed above 60 m/s",
    "flight_high": "flight more than 10 m high",
    "slope_from_chord": "slope from the chord to the previous point",
    "slope_sensitive": "$e_N$ depends on the chord taken as slope",
    "spin_estimated": "spin estimated as v/r",
}

#: Quality flags that record how a value was obtained (a method) rather than that a
#: row is doubtful: a survey reduced without surveyed slopes or measured spin carries
#: them on (nearly) every row. Figures state them once instead of ringing each row.
METHOD_QA_FLAGS: frozenset[str] = frozenset({"slope_from_chord", "spin_estimated"})

#: ``energy_gained``: relative KE gain that is more than rounding (KE ~ v^2).
ENERGY_GAIN_TOLERANCE = 1e-6
#: ``speed_high`` limit [m/s]: 25 % above the fastest impact the thesis reports (48
#: m/s, a barrier 70-100 m below the source at Mt. Stephen, §2.1.1); free fall from
#: 180 m without any impact loss.
MAX_PLAUSIBLE_SPEED_MPS = 60.0
#: ``flight_high`` limit [m]: 2.5 times the highest trajectory the thesis reports
#: (4 m on a polished 43° slope, §3.2; 99 % of the 235 Ehime flights < 2 m).
MAX_PLAUSIBLE_FLIGHT_HEIGHT_M = 10.0


#: Bounds :meth:`ImpactTable.read` puts on a table's measured (primary) columns:
#: column -> (smallest, largest, unit, what a value outside is not). NaN (not measured)
#: passes; infinities and values beyond a bound are refused, naming file, row and
#: column. The body and speed bounds are :mod:`fieldkit.physics.constants`', shared
#: with the body options (``--mass``, ``--radius``, ``--gyration``: 1 g to 10,000 t,
#: 1 mm to 10 m; speeds within 100 m/s: free fall from 500 m reaches 99 m/s);
#: coordinates within the 10,000 km of a plan coordinate and the 11,000 m of an
#: elevation on Earth the point readers use; error correlations within [-1, 1] and
#: the error model's standard uncertainties not negative.
READ_BOUNDS: dict[str, tuple[float, float, str, str]] = {
    "x_m": (-1.0e7, 1.0e7, "m", "a distance along a fall path"),
    "y_m": (-1.0e7, 1.0e7, "m", "a plan coordinate (3-D rows)"),
    "z_m": (-11_000.0, 11_000.0, "m", "an elevation on Earth"),
    "mass_kg": (MIN_MASS_KG, MAX_MASS_KG, "kg", "a rock's mass (1 g to 10,000 t)"),
    "radius_m": (MIN_LENGTH_M, MAX_LENGTH_M, "m", "a rock's contact radius"),
    "gyration_m": (MIN_LENGTH_M, MAX_LENGTH_M, "m", "a rock's radius of gyration"),
    **{
        name: (-MAX_SPEED_MPS, MAX_SPEED_MPS, "m/s", "a rockfall velocity")
        for name in ("vi_x_mps", "vi_z_mps", "vf_x_mps", "vf_z_mps")
    },
    **{
        name: (-1.0, 1.0, "", "a correlation coefficient")
        for name in CORR_COLUMNS.values()
    },
    **{
        name: (0.0, 1.0e7, "m", "a standard uncertainty of a position")
        for name in ERROR_MODEL_COLUMNS.values()
    },
}
#: Measured columns without a bound of their own that must still be finite when
#: given (an infinity turns every energy and residual into NaN or inf).
READ_FINITE: tuple[str, ...] = ("theta0_deg", "omega_i_radps", "omega_f_radps", "t_s")


def check_read_values(frame: pd.DataFrame, source: str | None) -> None:
    """Raise :class:`InputFileError` naming the first row (and its column) whose
    measured value is impossible: beyond :data:`READ_BOUNDS` or infinite in
    :data:`READ_FINITE`. Rows count data rows from 1.

    ``k <= r`` is not checked: it holds for compact bodies only, and a table names
    no shape (an ellipsoid 3 x 0.5 x 0.5 m landing on its side has k = 0.68 m on a
    contact radius of 0.25 m, :func:`fieldkit.physics.bodies.shape_body`).

    Examples
    --------
    >>> check_read_values(pd.DataFrame({"mass_kg": [500.0, -500.0]}), "t.csv")
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.InputFileError: t.csv: row 2: column mass_kg: -500 is outside ...
    """
    first: tuple[int, str] | None = None

    def consider(bad: np.ndarray, message: str) -> None:
        nonlocal first
        hits = np.flatnonzero(bad)
        if len(hits) and (first is None or hits[0] < first[0]):
            first = (int(hits[0]), message)

    def values(name: str) -> np.ndarray:
        return pd.to_numeric(frame[name], errors="coerce").to_numpy(float)

    for name, (low, high, unit, what) in READ_BOUNDS.items():
        if name not in frame:
            continue
        v = values(name)
        with np.errstate(invalid="ignore"):
            bad = ~np.isnan(v) & ~((v >= low) & (v <= high))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            consider(
                bad,
                f"column {name}: {v[i]:g} is outside [{low:g}, {high:g}]"
                f"{' ' + unit if unit else ''}: "
                f"not {what}",
            )
    for name in READ_FINITE:
        if name in frame:
            v = values(name)
            bad = np.isinf(v)
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                consider(bad, f"column {name}: {v[i]:g} is not a finite number")
    if first is not None:
        i, message = first
        raise InputFileError(message, source=source, where=f"row {i + 1}")


def flight_sides(frame: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """``(arrives, leaves)`` per row: a flight arrives (impact velocity ``vi`` known)
    and a flight leaves (restitution velocity ``vf`` known). A reduced path's release
    point has no arriving flight and its stop point no leaving one: they are points
    of the path, not impacts. A table without those columns arrives and leaves
    everywhere (a velocity is unknown only when every component the frame has is
    empty).

    Examples
    --------
    >>> nan = np.nan
    >>> f = pd.DataFrame({"vi_x_mps": [nan, 1.0, 1.0], "vi_z_mps": [nan, -1.0, -1.0],
    ...                   "vf_x_mps": [1.0, 1.0, nan], "vf_z_mps": [1.0, 1.0, nan]})
    >>> [a.tolist() for a in flight_sides(f)]
    [[False, True, True], [True, True, False]]
    """

    def known(*columns: str) -> np.ndarray:
        present = [c for c in columns if c in frame]
        if not present:
            return np.ones(len(frame), bool)
        return frame[present].notna().any(axis=1).to_numpy()

    return known("vi_x_mps", "vi_z_mps"), known("vf_x_mps", "vf_z_mps")


def unsolved_sides(frame: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """``(arrives_unsolved, leaves_unsolved)`` per row: the flight arriving at the
    row, resp. leaving it, is one the reduction could not solve (``flight_unsolved``
    of the launch row; the arrival is the next row of the same path). All False
    without a ``flight_unsolved`` column.

    Examples
    --------
    >>> f = pd.DataFrame({"path_id": ["a"] * 3 + ["b"],
    ...                   "flight_unsolved": [None, "point 3: ...", None, None]})
    >>> [a.tolist() for a in unsolved_sides(f)]
    [[False, False, True, False], [False, True, False, False]]
    """
    n = len(frame)
    if "flight_unsolved" not in frame:
        return np.zeros(n, bool), np.zeros(n, bool)
    text = frame["flight_unsolved"].astype("string").str.strip()
    leaves = (text.notna() & text.ne("")).to_numpy(dtype=bool, na_value=False)
    arrives = np.zeros(n, bool)
    arrives[1:] = leaves[:-1]
    if "path_id" in frame:
        path = frame["path_id"].astype("string").to_numpy(dtype=object)
        arrives[1:] &= path[1:] == path[:-1]
    return arrives, leaves


def path_point_kind(
    arrives: bool,
    leaves: bool,
    arrives_unsolved: bool = False,
    leaves_unsolved: bool = False,
) -> str:
    """What a row without an impact is (:func:`flight_sides`,
    :func:`unsolved_sides`), in words.

    Examples
    --------
    >>> path_point_kind(False, True), path_point_kind(True, False)
    ('a release point', 'a stop point')
    >>> path_point_kind(False, True, arrives_unsolved=True)
    'arrives by an unsolved flight'
    >>> path_point_kind(True, False, leaves_unsolved=True)
    'leaves on an unsolved flight'
    """
    unsolved = [
        words
        for flag, words in (
            (arrives_unsolved, "arrives by an unsolved flight"),
            (leaves_unsolved, "leaves on an unsolved flight"),
        )
        if flag
    ]
    if unsolved:
        return " and ".join(unsolved)
    if not arrives and not leaves:
        return "a point with no flight on either side"
    return "a release point" if not arrives else "a stop point"


def path_point_kinds(frame: pd.DataFrame) -> list[tuple[int, str]]:
    """``(row, what)`` of every row that is not an impact (no arriving or no leaving
    flight, or one of them unsolved), row 1-based, in words
    (:func:`path_point_kind`)."""
    arrives, leaves = flight_sides(frame)
    arrives_unsolved, leaves_unsolved = unsolved_sides(frame)
    return [
        (
            int(i) + 1,
            path_point_kind(
                arrives[i], leaves[i], arrives_unsolved[i], leaves_unsolved[i]
            ),
        )
        for i in np.flatnonzero(~(arrives & leaves))
    ]


def quality_flags(frame: pd.DataFrame) -> pd.Series:
    """The ``qa_flags`` of every row, from the table's own columns (:data:`QA_FLAGS`).

    A flag is raised only where its columns are known (NaN never raises one). Flags
    already in ``qa_flags`` that are not in :data:`QA_FLAGS` (a producer's own) are
    kept; those in it are recomputed. Rows without a flag get ``<NA>``.

    Examples
    --------
    >>> f = pd.DataFrame({"vi_mps": [10.0, 5.0], "vf_mps": [8.0, 6.0],
    ...                   "e_n": [0.5, -0.1], "slope_source": ["chord", "surveyed"]})
    >>> quality_flags(f).tolist()
    ['slope_from_chord', 'energy_gained;e_n_negative']
    """
    n = len(frame)

    def col(name: str) -> np.ndarray:
        if name not in frame:
            return np.full(n, np.nan)
        return pd.to_numeric(frame[name], errors="coerce").to_numpy(float)

    def text(name: str) -> np.ndarray:
        if name not in frame:
            return np.full(n, "", dtype=object)
        return frame[name].astype("string").fillna("").to_numpy(dtype=object)

    vi, vf = col("vi_mps"), col("vf_mps")
    e_n, e_t = col("e_n"), col("e_t")
    spin = np.isfinite(col("omega_i_radps")) | np.isfinite(col("omega_f_radps"))
    slope_known = np.isfinite(col("slope_deg")) if "slope_deg" in frame else True
    with np.errstate(invalid="ignore"):
        raised = {
            "energy_gained": vf**2 > vi**2 * (1.0 + ENERGY_GAIN_TOLERANCE),
            "e_n_negative": e_n < 0.0,
            "e_t_above_1": e_t > 1.0 + 1e-9,
            "speed_high": (vi > MAX_PLAUSIBLE_SPEED_MPS)
            | (vf > MAX_PLAUSIBLE_SPEED_MPS),
            "flight_high": col("hmax_normal_m") > MAX_PLAUSIBLE_FLIGHT_HEIGHT_M,
            "slope_from_chord": (text("slope_source") == "chord") & slope_known,
            "slope_sensitive": np.abs(col("e_n_next_chord") - e_n) > col("e_n_sd"),
            "spin_estimated": (text("omega_source") == "estimated") & spin,
        }
    given = text("qa_flags")
    # A row's flags depend only on (raised flags, given text): build each distinct
    # combination's string once (vectorised; a million rows in well under a second).
    code = np.zeros(n, np.int64)
    for bit, name in enumerate(QA_FLAGS):
        code |= np.asarray(raised[name], bool).astype(np.int64) << bit
    given_id, given_text = pd.factorize(pd.Series(given, dtype=object), sort=False)
    given_id = np.where(given_id < 0, len(given_text), given_id)  # missing -> ""
    given_text = [*map(str, given_text), ""]
    keys, index = np.unique(code * len(given_text) + given_id, return_inverse=True)
    strings = []
    for key in keys.tolist():
        bits, text_id = divmod(key, len(given_text))
        names = [name for bit, name in enumerate(QA_FLAGS) if bits >> bit & 1]
        names += [
            name
            for name in given_text[text_id].split(";")
            if name.strip() and name.strip() not in QA_FLAGS
        ]
        strings.append(";".join(dict.fromkeys(name.strip() for name in names)) or None)
    out = np.array(strings, dtype=object)[index.reshape(-1)]
    return pd.Series(out, index=frame.index, dtype="string")


#: ``qa_flags`` that make an impact suspect (the reduction's physics checks; what a
#: fit does with them: :mod:`fieldkit.fit.suspect`).
SUSPECT_FLAGS: tuple[str, ...] = ("energy_gained", "e_t_above_1")
#: Observed value columns of a surveyed path that rest on flights (path fit).
FLIGHT_VALUES = ("hmax_normal_m", "vi_mps")


def flag_codes(frame: pd.DataFrame) -> np.ndarray:
    """Per row a bit code of its :data:`SUSPECT_FLAGS` (bit ``k`` = flag ``k``).

    Read from ``qa_flags`` when the table has it (as reduced), else computed
    (:func:`fieldkit.impact_table.quality_flags`).

    Examples
    --------
    >>> flag_codes(pd.DataFrame({"qa_flags": ["e_t_above_1;spin_estimated", None,
    ...     "energy_gained;e_t_above_1"]})).tolist()
    [2, 0, 3]
    """
    text = frame["qa_flags"] if "qa_flags" in frame else quality_flags(frame)
    names = [
        set(str(v).split(";")) if isinstance(v, str) else set()
        for v in text.astype("string").fillna("").tolist()
    ]
    code = np.zeros(len(frame), np.int64)
    for bit, flag in enumerate(SUSPECT_FLAGS):
        code |= np.array([flag in n for n in names], bool).astype(np.int64) << bit
    return code


def _assumed(frame: pd.DataFrame) -> np.ndarray:
    """Per row: the flight leaving it rests on an assumed θ0."""
    if "theta0_source" not in frame:
        return np.zeros(len(frame), bool)
    src = frame["theta0_source"].astype("string").fillna("")
    return (src.str.strip().str.lower() == "assumed").to_numpy(bool)


def _previous_in_path(frame: pd.DataFrame) -> np.ndarray:
    """Per row: the previous row belongs to the same path (rows in path order)."""
    if len(frame) == 0:
        return np.zeros(0, bool)
    path = frame["path_id"].astype(str).to_numpy()
    return np.concatenate([[False], path[1:] == path[:-1]])


def _shift_down(values: np.ndarray, same: np.ndarray) -> np.ndarray:
    """``values`` of the previous row where it is in the same path, else 0."""
    out = np.zeros_like(values)
    out[1:] = values[:-1]
    out[~same] = 0
    return out


def impact_markers(frame: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """``(flag code, assumed)`` of each row's impact datum (impact fit).

    The flag code is the row's own (:func:`flag_codes`); assumed when the flight
    arriving at the impact (the previous row's, same path) or the flight leaving
    it rests on an assumed θ0.

    Examples
    --------
    >>> f = pd.DataFrame({"path_id": "a", "theta0_source": ["assumed", "tree",
    ...     "tree", "assumed", "tree"], "qa_flags": [None, "energy_gained", None,
    ...     None, None]})
    >>> codes, assumed = impact_markers(f)
    >>> codes.tolist(), assumed.tolist()
    ([0, 1, 0, 0, 0], [True, True, False, True, True])
    """
    leaving = _assumed(frame)
    arriving = _shift_down(leaving.astype(np.int64), _previous_in_path(frame)) > 0
    return flag_codes(frame), leaving | arriving


def flight_value_markers(frame: pd.DataFrame) -> dict[str, np.ndarray]:
    """Markers of each point's flight-borne values (path fit), as float columns.

    For each of :data:`FLIGHT_VALUES` ``v``: ``v_flags`` (the flag bit code of
    the impacts the flight carrying the value joins) and ``v_theta0_assumed`` (1
    when that flight's θ0 was assumed, else 0). ``hmax_normal_m`` at a point comes
    from the flight leaving it; ``vi_mps`` from the flight arriving at it.

    Examples
    --------
    >>> f = pd.DataFrame({"path_id": "a", "theta0_source": ["assumed", "tree",
    ...     "assumed", None], "qa_flags": [None, None, "e_t_above_1", None]})
    >>> m = flight_value_markers(f)
    >>> m["hmax_normal_m_flags"].tolist(), m["vi_mps_flags"].tolist()
    ([0.0, 2.0, 2.0, 0.0], [0.0, 0.0, 2.0, 2.0])
    >>> m["hmax_normal_m_theta0_assumed"].tolist(), m["vi_mps_theta0_assumed"].tolist()
    ([1.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 1.0])
    """
    same = _previous_in_path(frame)
    code = flag_codes(frame)
    n = len(frame)
    # the flight leaving row j joins impacts j and j + 1 (same path)
    nxt = np.zeros(n, np.int64)
    nxt[:-1] = code[1:]
    has_next = np.concatenate([same[1:], [False]])
    leaving_flags = code | np.where(has_next, nxt, 0)
    leaving_flags[~has_next] = 0  # the last point launches no flight
    leaving_assumed = _assumed(frame).astype(np.int64)
    leaving_assumed[~has_next] = 0
    return {
        "hmax_normal_m_flags": leaving_flags.astype(float),
        "hmax_normal_m_theta0_assumed": leaving_assumed.astype(float),
        "vi_mps_flags": _shift_down(leaving_flags, same).astype(float),
        "vi_mps_theta0_assumed": _shift_down(leaving_assumed, same).astype(float),
    }


def restitution(
    vi_x_mps: np.ndarray,
    vi_z_mps: np.ndarray,
    vf_x_mps: np.ndarray,
    vf_z_mps: np.ndarray,
    slope_deg: np.ndarray,
) -> dict[str, np.ndarray]:
    """Speeds, N/T components, angles to the ground and ``e_n``, ``e_t`` [arrays].

    The kinematic half of :meth:`ImpactTable.derive` (docs/architecture.md §2; eqs. 4.6,
    4.7), as plain arrays so that a Monte Carlo can repeat it without building tables.

    Examples
    --------
    >>> r = restitution(np.array([3.0]), np.array([-4.0]), np.array([3.0]),
    ...                 np.array([2.0]), np.array([0.0]))
    >>> float(r["e_n"][0]), float(r["e_t"][0])
    (0.5, 1.0)
    """
    vit, vin = to_local(vi_x_mps, vi_z_mps, slope_deg)
    vft, vfn = to_local(vf_x_mps, vf_z_mps, slope_deg)
    with np.errstate(divide="ignore", invalid="ignore"):
        e_n = np.where(np.abs(vin) > _EPS, -vfn / vin, np.nan)
        e_t = np.where(np.abs(vit) > _EPS, vft / vit, np.nan)
    return {
        "vi_mps": np.hypot(vi_x_mps, vi_z_mps),
        "vf_mps": np.hypot(vf_x_mps, vf_z_mps),
        "vin_mps": vin,
        "vit_mps": vit,
        "vfn_mps": vfn,
        "vft_mps": vft,
        "theta_i_deg": angle_to_ground_deg(vit, vin),
        "theta_f_deg": angle_to_ground_deg(vft, vfn),
        "e_n": e_n,
        "e_t": e_t,
    }


class ImpactTable:
    """A validated, column-ordered table of impacts.

    Parameters
    ----------
    frame
        One row per impact. Must hold the required contract columns; missing optional
        contract columns are added as NaN; extra columns are kept after them.
    source
        Where the table came from (file name), used in error messages.

    Examples
    --------
    >>> t = ImpactTable(pd.DataFrame({"path_id": ["A"], "point": ["1"], "x_m": [0.0],
    ...     "z_m": [0.0], "slope_deg": [0.0], "vi_x_mps": [3.0], "vi_z_mps": [-4.0],
    ...     "vf_x_mps": [3.0], "vf_z_mps": [2.0]})).derive()
    >>> float(t.frame.loc[0, "e_n"])
    0.5
    """

    def __init__(self, frame: pd.DataFrame, *, source: str | None = None) -> None:
        self.source = source
        self.frame = self._normalise(frame)

    # ------------------------------------------------------------------ construction
    def _normalise(self, frame: pd.DataFrame) -> pd.DataFrame:
        missing = [c for c in REQUIRED_COLUMNS if c not in frame.columns]
        if missing:
            raise InputFileError(
                f"ImpactTable lacks required column(s) {', '.join(missing)}",
                source=self.source,
            )
        out = frame.copy()
        # the columns the source had, before the contract's are added as NaN (kept
        # in the frame's attrs, which copies and row selections carry along)
        given = out.attrs.get(_GIVEN, out.columns)
        out.attrs[_GIVEN] = _ColumnNames(c for c in given if c in out.columns)
        for col in CONTRACT_COLUMNS:
            if col.name not in out.columns:
                out[col.name] = pd.NA if col.kind in ("str", "bool") else np.nan
        # a column already of its kind is left alone: a table built from another
        # one (every stage does it) then costs no conversion
        wanted = {"float": "float64", "str": "string", "bool": "boolean"}
        for name in out.columns:
            spec = COLUMNS_BY_NAME.get(name)
            if spec is None or str(out[name].dtype) == wanted.get(spec.kind):
                continue
            if spec.kind == "float":
                out[name] = self._as_float(out[name], name)
            elif spec.kind == "str":
                out[name] = out[name].astype("string")
            elif spec.kind == "bool":
                out[name] = out[name].astype("boolean")
        slope = out["slope_deg"].to_numpy(float)
        # a dip, beyond +-90 deg an overhang (§2); a non-finite value is left to
        # the check of each use ("not finite", with every row named)
        outside = np.isfinite(slope) & ~((slope > -180.0) & (slope <= 180.0))
        if outside.any():
            i = int(np.flatnonzero(outside)[0])
            raise InputFileError(
                f"slope_deg {slope[i]:g} is outside (-180, 180] deg",
                source=self.source,
                where=f"row {i + 1}",
            )
        for key in ("path_id", "point"):
            bad = out.index[out[key].isna()]
            if len(bad):
                raise InputFileError(
                    f"empty {key}", source=self.source, where=f"row {bad[0] + 1}"
                )
        dup = out.duplicated(["path_id", "point"])
        if dup.any():
            i = int(np.flatnonzero(dup.to_numpy())[0])
            raise InputFileError(
                f"duplicated point {out['point'].iloc[i]!s} "
                f"in path {out['path_id'].iloc[i]!s}",
                source=self.source,
                where=f"row {i + 1}",
            )
        src = out["theta0_source"].dropna()
        bad_src = src[~src.isin(sorted(THETA0_SOURCES))]
        if len(bad_src):
            raise InputFileError(
                f"theta0_source {bad_src.iloc[0]!r} is not one of "
                f"{sorted(THETA0_SOURCES)}",
                source=self.source,
                where=f"row {bad_src.index[0] + 1}",
            )
        contract = [c.name for c in CONTRACT_COLUMNS]
        extras = [c for c in out.columns if c not in contract]
        return out[contract + extras].reset_index(drop=True)

    def _as_float(self, series: pd.Series, name: str) -> pd.Series:
        values = pd.to_numeric(series, errors="coerce")
        bad = series.notna() & values.isna()
        if bad.any():
            i = int(np.flatnonzero(bad.to_numpy())[0])
            raise InputFileError(
                f"column {name}: {series.iloc[i]!r} is not a number",
                source=self.source,
                where=f"row {i + 1}",
            )
        return values.astype(float)

    # ------------------------------------------------------------------ physics
    def derive(self) -> ImpactTable:
        """Return a copy with every derived column recomputed from the primary ones.

        Speeds, N/T components on ``slope_deg`` (docs/architecture.md §2), angles to
        the ground, ``e_n = -vfn/vin`` and ``e_t = vft/vit`` (eqs. 4.6, 4.7), kinetic
        and rotational energies (``I = m k^2``), ``dke_j``, energy heads (eq. 6.14) and
        ``qa_flags`` (:func:`quality_flags`). Values the data do not allow (no mass, no
        spin) stay NaN.
        """
        f = self.frame.copy()
        kinematics = restitution(
            f["vi_x_mps"].to_numpy(),
            f["vi_z_mps"].to_numpy(),
            f["vf_x_mps"].to_numpy(),
            f["vf_z_mps"].to_numpy(),
            f["slope_deg"].to_numpy(),
        )
        for name, values in kinematics.items():
            f[name] = values
        vi, vf = kinematics["vi_mps"], kinematics["vf_mps"]
        m = f["mass_kg"].to_numpy()
        k = f["gyration_m"].to_numpy()
        f["ke_i_j"], f["ke_f_j"] = kinetic_energy(m, vi), kinetic_energy(m, vf)
        f["dke_j"] = f["ke_f_j"] - f["ke_i_j"]
        f["re_i_j"] = rotational_energy(m, k, f["omega_i_radps"].to_numpy())
        f["re_f_j"] = rotational_energy(m, k, f["omega_f_radps"].to_numpy())
        z = f["z_m"].to_numpy()
        f["energy_head_i_m"], f["energy_head_f_m"] = (
            energy_head(z, vi),
            energy_head(z, vf),
        )
        f["qa_flags"] = quality_flags(f)
        return ImpactTable(f, source=self.source)

    # ------------------------------------------------------------------ access
    def __len__(self) -> int:
        return len(self.frame)

    def __repr__(self) -> str:
        paths = self.frame["path_id"].nunique()
        return f"ImpactTable({len(self)} impacts, {paths} path(s))"

    def paths(self) -> list[str]:
        """Path identifiers in order of first appearance."""
        return list(dict.fromkeys(self.frame["path_id"].tolist()))

    def unusable_columns(self, names: Sequence[str]) -> str | None:
        """Which of ``names`` cannot be used, in words, or None when all can.

        A column the table does not have is *missing*; one it has with no value
        in any row is *empty* (an export that left it blank), and the two are
        told apart.

        Examples
        --------
        >>> t = ImpactTable(pd.DataFrame({"path_id": ["A"], "point": ["1"],
        ...     "x_m": [0.0], "z_m": [0.0], "slope_deg": [0.0], "vi_x_mps": [np.nan],
        ...     "vi_z_mps": [-4.0], "vf_x_mps": [3.0], "vf_z_mps": [2.0]}))
        >>> print(t.unusable_columns(["vi_x_mps", "vi_z_mps", "material"]))
        ... # doctest: +NORMALIZE_WHITESPACE
        missing column(s) material; column(s) vi_x_mps present but empty (no value in
        any row)
        """
        frame = self.frame
        given = set(frame.attrs.get(_GIVEN, frame.columns))
        unusable = [c for c in names if c not in frame.columns or frame[c].isna().all()]
        missing = [c for c in unusable if c not in given]
        empty = [c for c in unusable if c in given]
        parts = []
        if missing:
            parts.append(f"missing column(s) {', '.join(missing)}")
        if empty:
            parts.append(
                f"column(s) {', '.join(empty)} present but empty (no value in any row)"
            )
        return "; ".join(parts) or None

    def column(self, name: str) -> np.ndarray:
        """A float column as a numpy array (NaN where missing)."""
        return self.frame[name].to_numpy(dtype=float, na_value=np.nan)

    # ------------------------------------------------------------------ files
    @classmethod
    def read(cls, path: str | os.PathLike[str]) -> ImpactTable:
        """Read a CSV, Parquet or XLSX ImpactTable (format from the extension).

        In a CSV, the ``'`` that :meth:`write` puts before formula-like text cells is
        removed (:func:`fieldkit.outputs.unescape_formulas`).

        Raises
        ------
        InputFileError
            An unreadable file, a missing required column, text in a number, or an
            impossible measured value (:func:`check_read_values`), naming the row.
        """
        p = Path(path)
        fmt = table_format(p)
        if not p.is_file():
            raise InputFileError("file not found", source=p)
        if p.stat().st_size == 0:
            raise InputFileError("file is empty", source=p)
        text_cols = {
            c.name: "string"
            for c in CONTRACT_COLUMNS + EXTENSION_COLUMNS
            if c.kind == "str"
        }
        if fmt == "csv":  # NUL bytes: binary, UTF-16 or UTF-32, not a UTF-8 CSV
            with p.open("rb") as handle:
                if b"\x00" in handle.read(4096):
                    raise InputFileError(
                        "not a UTF-8 text CSV file (NUL bytes: binary, UTF-16 or "
                        "UTF-32 content)",
                        source=p,
                    )
        try:
            if fmt == "csv":
                frame = pd.read_csv(p, dtype=text_cols)
            elif fmt == "parquet":
                frame = pd.read_parquet(p)
            else:
                frame = pd.read_excel(p, dtype=text_cols)
        except MemoryError:
            raise
        except Exception as exc:  # noqa: BLE001 - any parser failure is the file's
            # pandas, pyarrow and openpyxl raise their own types for a file that
            # is not what its extension says (BadZipFile, KeyError, ArrowInvalid)
            reason = " ".join(str(exc).split())[:160] or type(exc).__name__
            raise InputFileError(
                f"not a readable {fmt.upper()} file ({reason})", source=p
            ) from None
        if frame.empty:
            raise InputFileError("table has no rows", source=p)
        if fmt == "csv":  # written by `write`: formula-like text was quoted
            frame = unescape_formulas(frame)
        table = cls(frame, source=str(p))
        check_read_values(table.frame, table.source)
        return table

    def write(
        self, path: str | os.PathLike[str], *, outputs: OutputSet | None = None
    ) -> Path:
        """Write as CSV, Parquet or XLSX (format from the extension).

        The file goes into ``outputs`` (written when the set commits) or, without
        one, is written at once on its own (:func:`fieldkit.outputs.write_file`).
        Text cells a spreadsheet would run as formulas are kept as text: quoted with
        ``'`` in CSV (removed again by :meth:`read`), typed as text in XLSX
        (:mod:`fieldkit.outputs`, "Spreadsheet safety").
        """
        p = Path(path)
        fmt = table_format(p)
        frame = self.frame
        if fmt == "csv":
            safe = escape_formulas(frame)
            return write_file(p, lambda tmp: safe.to_csv(tmp, index=False), outputs)
        if fmt == "parquet":
            return write_file(
                p, lambda tmp: frame.to_parquet(tmp, index=False), outputs
            )

        _check_xlsx_text(frame, p)

        def write_xlsx(tmp: Path) -> None:
            with pd.ExcelWriter(tmp, engine="openpyxl") as book:
                frame.to_excel(book, index=False, sheet_name="impacts")
                protect_formula_cells(book.sheets["impacts"])

        return write_file(p, write_xlsx, outputs)


#: Characters XLSX cannot hold (control characters other than tab, LF, CR).
_XLSX_ILLEGAL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f]")


def _check_xlsx_text(frame: pd.DataFrame, path: Path) -> None:
    """One-line error naming the column and row of a text cell XLSX cannot hold."""
    for name in frame.columns:
        column = frame[name]
        if column.dtype.kind not in "OUT" and str(column.dtype) not in (
            "string",
            "str",
        ):
            continue
        # a plain bool array: Series.map keeps a string dtype on an empty column,
        # which has no any() (a run without impacts wrote no XLSX)
        bad = np.fromiter(
            (isinstance(v, str) and bool(_XLSX_ILLEGAL.search(v)) for v in column),
            dtype=bool,
            count=len(column),
        )
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputFileError(
                f"column {name}: {column.iloc[i]!r} holds a control character that "
                "XLSX cannot store; write CSV or Parquet, or remove it",
                source=path,
                where=f"row {i + 1}",
            )


def is_stream_device(path: str | os.PathLike[str]) -> bool:
    """True for a FIFO or a character device (``/dev/null``, ``/dev/stdout``): a
    target written in place, whose name need not carry a format extension."""
    import stat

    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return False
    return stat.S_ISFIFO(mode) or stat.S_ISCHR(mode)


def table_format(path: Path) -> str:
    """The table format of ``path`` from its extension; CSV (the default format) for
    a FIFO or character device without one (``-o /dev/null``)."""
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None and is_stream_device(path):
        return "csv"
    if fmt is None:
        raise InputFileError(
            f"unknown table format {path.suffix!r}; use one of {', '.join(FORMATS)}",
            source=path,
        )
    return fmt
