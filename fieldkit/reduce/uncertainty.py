"""Standard uncertainties of reduced values, from the survey's position error.

The ``<column>_sd`` columns of an ImpactTable (docs/architecture.md §3: ``e_n_sd``,
``e_t_sd``, ``vi_sd_mps``, ``vf_sd_mps``, ``vin_sd_mps``, ``vit_sd_mps``,
``vfn_sd_mps``, ``vft_sd_mps``, ``theta_i_sd_deg``; :data:`OUTPUTS`) come from
:func:`propagate`: a Monte Carlo that perturbs every surveyed point and tree-strike
height, runs the *same* reduction again (passed in as a callable) and takes the
standard deviation of each output over the draws. Nothing is linearised, so
the non-linear three-point and eq. 3.5 solutions, the chord slopes and the N/T
decomposition all carry the error the way they carry the data.

Error model (:class:`PositionError`)
    Each point's section coordinates get independent normal errors: ``x_m`` with
    standard deviation ``position_sigma_m`` and ``z_m`` with ``elevation_sigma_m``;
    each tree strike's height above the ground gets ``strike_height_sigma_m``.
    ``position_sigma_m`` is the standard uncertainty of a point's plan position along
    any horizontal direction. For points placed in plan (GPS, rangefinder) the section
    ``x`` is the cumulative plan distance, so a point's along-path error moves its own
    ``x`` by the same amount to first order (an across-path error changes plan
    distances only to second order); the common offset of the first point cancels.
    A tree strike's height fixes a three-point parabola (eq. 3.5) and so moves with
    its own error; its tape distance from the launch point and surveyed slopes are
    taken as exact (a taped distance is good to centimetres, far below the plan error
    of the points it is measured from).

Defaults, and why
    What the reduction feels is the error of one impact *relative to the next*,
    surveyed minutes apart: the errors a GNSS fix shares between nearby points (orbit,
    clock, atmosphere) cancel and what remains is multipath and how well the antenna or
    the laser spot is put on the centre of the scar. :data:`DEFAULT_POSITION_SIGMA_M` =
    0.5 m in plan suits a handheld receiver held on each scar under open sky, or a
    laser rangefinder (TruPulse 360: about ±0.3 m in distance at these ranges) with a
    scar half a metre across, as at Tornado Mountain (thesis §2.2.2: "a GPS unit and a
    laser rangefinder"). A consumer handheld GNSS is good to only 3-5 m *absolute* in
    the open, but most of that is the shared part that cancels between neighbouring
    fixes; averaging a fix over a minute on each scar brings the point-to-point part
    to about half a metre, which is what the default assumes. Under forest canopy the
    point-to-point error itself reaches metres: give ``position_sigma_m`` of 2-5 m
    there. :data:`DEFAULT_ELEVATION_SIGMA_M` = 0.5 m in height: GNSS heights are
    1.5-2 times worse than plan positions, a rangefinder's inclination is better;
    0.5 m covers the handheld case without overstating the rangefinder. The command
    line sets both from one number (a point's plan and height error). A survey with a
    total station (centimetres) needs its own values; the reduction states the values
    it used. :data:`DEFAULT_STRIKE_HEIGHT_SIGMA_M` = 0.25 m for a tree strike: the
    scar on the trunk is taped to centimetres, but where on a scar of a rock a metre
    across its centre passed (and where "the ground" at the tree's foot is on a
    slope) is uncertain by a quarter of a metre.

Sampling
    :data:`DEFAULT_DRAWS` = 100 draws from ``numpy.random.default_rng(seed)`` with the
    fixed :data:`DEFAULT_SEED`, so a reduction is reproducible. The standard deviation
    of 100 draws is itself uncertain by about 7 % (``1/sqrt(2(N-1))``): enough to tell
    an ``e_n`` known to 0.05 from one known to 0.3, at 10-15 ms per draw for a
    50-point path (each draw solves every flight again). A flight with no ballistic
    solution in a draw (a point pushed past the next one, a tree strike no parabola
    reaches) leaves only that flight's outputs NaN in that draw (the reduction keeps
    it as an unsolved flight), counted per launch point (``Propagated.unsolved``); a
    point's sd uses the draws in which its value is finite, and is NaN where fewer
    than half are: leaving out the extreme draws makes the spread a little too small,
    and the report says how many. A draw the reduction refuses whole (every flight
    unsolved) is left out and counted.

Correlations
    An impact's arrival and rebound velocities both hang on the surveyed point between
    the two flights, so their errors are correlated. ``propagate(...,
    correlations=(("vin_mps", "vfn_mps"), ...))`` keeps the draws and gives each
    point the correlation coefficient of the pair over the draws where both are
    finite (NaN where fewer than half the draws are, or where either does not vary):
    the ``vin_vfn_corr`` and ``vit_vft_corr`` columns
    (:data:`fieldkit.impact_table.CORR_COLUMNS`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from fieldkit.errors import ArgumentError, FieldkitError
from fieldkit.impact_table import CORR_COLUMNS, SD_COLUMNS

__all__ = [
    "DEFAULT_DRAWS",
    "DEFAULT_ELEVATION_SIGMA_M",
    "DEFAULT_POSITION_SIGMA_M",
    "DEFAULT_SEED",
    "DEFAULT_STRIKE_HEIGHT_SIGMA_M",
    "OUTPUTS",
    "UNSOLVED",
    "PositionError",
    "Propagated",
    "corr_column",
    "propagate",
    "sd_column",
]

#: Standard uncertainty of a point's plan position, relative to its neighbours [m].
DEFAULT_POSITION_SIGMA_M = 0.5
#: Standard uncertainty of a point's elevation, relative to its neighbours [m].
DEFAULT_ELEVATION_SIGMA_M = 0.5
#: Standard uncertainty of a tree strike's height above the ground at the tree [m].
DEFAULT_STRIKE_HEIGHT_SIGMA_M = 0.25
#: Largest standard uncertainty of a position or height (m): beyond a hand-held GPS's
#: worst case under canopy (tens of metres) the point no longer locates an impact.
MAX_SIGMA_M = 100.0
#: Monte Carlo draws.
DEFAULT_DRAWS = 100
#: Seed of ``numpy.random.default_rng`` (fixed: the same survey gives the same sd).
DEFAULT_SEED = 2004

#: Reduced values whose standard uncertainty a reduction reports (``sd_column`` of
#: each is its column).
OUTPUTS = tuple(SD_COLUMNS)

#: Output a reduction may add (one 0/1 per point: the flight leaving it had no
#: solution in that draw); :func:`propagate` counts it per point, not as a value.
UNSOLVED = "flight_unsolved"

#: Unit suffixes kept last in a column name: ``vi_mps`` -> ``vi_sd_mps``.
_UNITS = ("_mps", "_m", "_deg", "_j", "_s", "_radps", "_kg")


def sd_column(name: str) -> str:
    """The standard-uncertainty column of ``name`` (docs/architecture.md §3).

    Examples
    --------
    >>> sd_column("e_n"), sd_column("vi_mps"), sd_column("theta_i_deg")
    ('e_n_sd', 'vi_sd_mps', 'theta_i_sd_deg')
    """
    for unit in _UNITS:
        if name.endswith(unit) and len(name) > len(unit):
            return f"{name[: -len(unit)]}_sd{unit}"
    return f"{name}_sd"


def corr_column(a: str, b: str) -> str:
    """The error-correlation column of values ``a`` and ``b`` (units dropped).

    Examples
    --------
    >>> corr_column("vin_mps", "vfn_mps"), corr_column("e_n", "e_t")
    ('vin_vfn_corr', 'e_n_e_t_corr')
    """
    if (a, b) in CORR_COLUMNS:
        return CORR_COLUMNS[(a, b)]

    def bare(name: str) -> str:
        for unit in _UNITS:
            if name.endswith(unit) and len(name) > len(unit):
                return name[: -len(unit)]
        return name

    return f"{bare(a)}_{bare(b)}_corr"


@dataclass(frozen=True)
class PositionError:
    """The survey's position error model and how it is sampled.

    Attributes
    ----------
    position_sigma_m
        Standard uncertainty of each point's plan position [m] (module docstring).
    elevation_sigma_m
        Standard uncertainty of each point's elevation [m].
    strike_height_sigma_m
        Standard uncertainty of each tree strike's height above the ground [m].
    draws
        Monte Carlo draws (>= 10).
    seed
        Seed of the ``numpy.random.Generator``.
    """

    position_sigma_m: float = DEFAULT_POSITION_SIGMA_M
    elevation_sigma_m: float = DEFAULT_ELEVATION_SIGMA_M
    strike_height_sigma_m: float = DEFAULT_STRIKE_HEIGHT_SIGMA_M
    draws: int = DEFAULT_DRAWS
    seed: int = DEFAULT_SEED

    def __post_init__(self) -> None:
        for name in ("position_sigma_m", "elevation_sigma_m", "strike_height_sigma_m"):
            value = getattr(self, name)
            if not (
                isinstance(value, int | float)
                and not isinstance(value, bool)
                and math.isfinite(value)
            ):
                raise ArgumentError(f"{name} must be a finite number", source=name)
            if value < 0:
                raise ArgumentError(f"{name} must be >= 0 (got {value:g})", source=name)
            if value > MAX_SIGMA_M:
                raise ArgumentError(
                    f"{name} must be <= {MAX_SIGMA_M:g} m (got {value:g}): a point "
                    "known no better than that does not locate an impact on a slope",
                    source=name,
                )
        if int(self.draws) != self.draws or self.draws < 10:
            raise ArgumentError(
                f"draws must be a whole number >= 10 (got {self.draws})",
                source="draws",
            )

    def describe(self) -> str:
        """One line: the model, whether it is the default, the sampling."""
        points = (self.position_sigma_m, self.elevation_sigma_m) == (
            DEFAULT_POSITION_SIGMA_M,
            DEFAULT_ELEVATION_SIGMA_M,
        )
        strikes = self.strike_height_sigma_m == DEFAULT_STRIKE_HEIGHT_SIGMA_M
        return (
            f"position error {self.position_sigma_m:g} m in plan and "
            f"{self.elevation_sigma_m:g} m in height per point "
            f"({'the default' if points else 'given'}), "
            f"{self.strike_height_sigma_m:g} m per tree-strike height "
            f"({'the default' if strikes else 'given'}), "
            f"{self.draws} Monte Carlo draws, seed {self.seed}"
        )


@dataclass(frozen=True)
class Propagated:
    """Standard deviations over the draws, by sd column name, and the bookkeeping.

    Attributes
    ----------
    sd
        ``sd_column(name)`` -> per point standard deviation.
    model
        The error model and sampling.
    used, failed
        Draws the reduction solved, and refused whole (every flight unsolved).
    first_failure
        The first refused draw's error.
    corr
        ``corr_column(a, b)`` -> per point correlation coefficient over the draws.
    unsolved
        Per point, in how many used draws the flight leaving it had no solution
        (None when the reduction does not report :data:`UNSOLVED`).
    """

    sd: dict[str, np.ndarray]
    model: PositionError
    used: int
    failed: int
    first_failure: str | None = None
    corr: dict[str, np.ndarray] = field(default_factory=dict)
    unsolved: np.ndarray | None = None

    def describe(self) -> str:
        """One line for the report: model, columns, failed draws."""
        columns = ", ".join([*self.sd, *self.corr])
        text = f"{self.model.describe()} -> {columns}"
        if self.unsolved is not None and self.unsolved.any():
            worst = int(np.argmax(self.unsolved))
            text += (
                f"; in {int(self.unsolved.sum())} (flight, draw) pairs a flight had "
                f"no ballistic solution and only its values were left out of that "
                f"draw (most: {int(self.unsolved[worst])} of {self.used} draws, the "
                f"flight leaving row {worst + 1})"
            )
        if self.failed:
            text += (
                f"; {self.failed} of {self.model.draws} draws had no ballistic "
                f"solution and were left out (first: {self.first_failure})"
            )
        return text


def propagate(
    reduction: Callable[..., Mapping[str, np.ndarray]],
    x_m: Sequence[float] | np.ndarray,
    z_m: Sequence[float] | np.ndarray,
    model: PositionError | None = None,
    *,
    outputs: Sequence[str] = OUTPUTS,
    strike_heights_m: Sequence[float] | np.ndarray | None = None,
    correlations: Sequence[tuple[str, str]] = (),
) -> Propagated:
    """Standard uncertainty of a reduction's outputs from the position error.

    Parameters
    ----------
    reduction
        ``reduction(x_m, z_m) -> {name: array}``: the reduction of the survey with its
        points moved to ``(x_m, z_m)``, one value per point for each name in
        ``outputs``. It may raise :class:`~fieldkit.errors.FieldkitError` for a
        geometry with no solution (the draw is left out and counted).
    x_m, z_m
        The surveyed section coordinates [m].
    model
        Position error and sampling (default :class:`PositionError`).
    outputs
        Names to propagate; the result is keyed by :func:`sd_column` of each.
    strike_heights_m
        Tree-strike heights [m], if the survey has any: then ``reduction`` is called
        as ``reduction(x_m, z_m, strike_heights_m)`` with the heights perturbed by
        ``model.strike_height_sigma_m`` too.
    correlations
        Pairs of ``outputs`` whose error correlation to compute per point.

    Returns
    -------
    Propagated
        ``sd[sd_column(name)]``: sample standard deviation (ddof 1) per point over
        the draws where the value is finite; NaN where fewer than half the draws
        gave a finite value (e.g. the source has no impact velocity).
        ``corr[corr_column(a, b)]``: Pearson correlation per point over the draws
        where both are finite, NaN where fewer than half are (or one is constant).
        ``unsolved``: the per-point sum of the reduction's :data:`UNSOLVED` output,
        if it gives one.

    Examples
    --------
    A straight line's slope from its end points: sd of (z1 - z0)/(x1 - x0).

    >>> def slope(x, z):
    ...     return {"k": np.full(2, (z[1] - z[0]) / (x[1] - x[0]))}
    >>> out = propagate(slope, [0.0, 100.0], [0.0, 0.0],
    ...                 PositionError(0.0, 1.0, draws=4000), outputs=("k",))
    >>> round(float(out.sd["k_sd"][0]), 3)  # sqrt(2) * 1 m / 100 m
    0.014
    """
    model = model or PositionError()
    x = np.asarray(x_m, dtype=float)
    z = np.asarray(z_m, dtype=float)
    heights = None
    if strike_heights_m is not None and len(strike_heights_m):
        heights = np.asarray(strike_heights_m, dtype=float)
    for pair in correlations:
        missing = [name for name in pair if name not in outputs]
        if missing:
            raise ArgumentError(
                f"correlation of {pair[0]} and {pair[1]}: {missing[0]} is not among "
                "the outputs propagated",
                source="correlations",
            )
    rng = np.random.default_rng(model.seed)
    samples: dict[str, list[np.ndarray]] = {name: [] for name in outputs}
    unsolved: np.ndarray | None = None
    failed, first = 0, None
    for _ in range(model.draws):
        dx = rng.normal(0.0, model.position_sigma_m, x.shape)
        dz = rng.normal(0.0, model.elevation_sigma_m, z.shape)
        try:
            if heights is None:
                values = reduction(x + dx, z + dz)
            else:
                dh = rng.normal(0.0, model.strike_height_sigma_m, heights.shape)
                values = reduction(x + dx, z + dz, heights + dh)
        except FieldkitError as error:
            failed += 1
            first = first or str(error)
            continue
        for name in outputs:
            samples[name].append(np.asarray(values[name], dtype=float))
        if UNSOLVED in values:
            counted = np.asarray(values[UNSOLVED], dtype=float)
            unsolved = counted if unsolved is None else unsolved + counted
    used = model.draws - failed
    enough = max(2, used / 2)
    stacks: dict[str, np.ndarray] = {}
    sd: dict[str, np.ndarray] = {}
    for name in outputs:
        if used < 2:
            sd[sd_column(name)] = np.full(x.shape, np.nan)
            continue
        stack = np.vstack(samples[name])
        stack = np.where(np.isfinite(stack), stack, np.nan)
        stacks[name] = stack
        finite = np.isfinite(stack).sum(axis=0)
        with warnings.catch_warnings():  # all-NaN columns: no impact there
            warnings.simplefilter("ignore", RuntimeWarning)
            spread = np.nanstd(stack, axis=0, ddof=1)
        sd[sd_column(name)] = np.where(finite >= enough, spread, np.nan)
    corr = {
        corr_column(a, b): (
            _correlation(stacks[a], stacks[b], enough)
            if used >= 2
            else np.full(x.shape, np.nan)
        )
        for a, b in correlations
    }
    return Propagated(
        sd=sd,
        model=model,
        used=used,
        failed=failed,
        first_failure=first,
        corr=corr,
        unsolved=None if unsolved is None else unsolved.astype(int),
    )


def _correlation(a: np.ndarray, b: np.ndarray, enough: float) -> np.ndarray:
    """Per column Pearson correlation of ``a`` and ``b`` (draws x points) over the
    rows where both are finite; NaN where fewer than ``enough`` are or one of them
    does not vary."""
    both = np.isfinite(a) & np.isfinite(b)
    count = both.sum(axis=0)
    a = np.where(both, a, 0.0)
    b = np.where(both, b, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        da = a - a.sum(axis=0) / count
        db = b - b.sum(axis=0) / count
        da, db = np.where(both, da, 0.0), np.where(both, db, 0.0)
        r = (da * db).sum(axis=0) / np.sqrt((da**2).sum(axis=0) * (db**2).sum(axis=0))
    return np.where((count >= enough) & np.isfinite(r), np.clip(r, -1.0, 1.0), np.nan)
