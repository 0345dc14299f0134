"""What was observed along a path, and the same quantities from simulated rocks.

A path fit compares observed and simulated distributions of these *kinds*
(:data:`KINDS`), each in its own unit:

``runout_m``
    The run's stop, chainage from the release along its section, against the
    simulated rocks' runouts (one observation per run).
``flight_height_m``
    Observed normal flight heights (``along_hmax_normal_m``, e.g. from ``reduce``:
    the flight leaving each point) against the normal heights of the simulated
    flights between consecutive impacts of one rock (eq. 3.12 on the chord, as the
    reduction does), both *weighted by the flight's length*: the distribution of the
    height of the flight over a point taken uniformly along the observed stretch.
    Where a simulated rock rolls or slides in that stretch it counts with height 0
    for that length, so a model whose rocks roll where the boulder flew scores
    badly (a per-flight pool would only see the few flights such a model makes).
``impact_spacing_m``
    Horizontal spacing of consecutive observed points (``along_chainage_m``) against
    that of consecutive impacts of one simulated rock, in the same stretch.
``speed_mps``
    Observed impact speeds (``along_vi_mps``) at their chainage against the speeds of
    the simulated rocks at that chainage (a vertical analysis line).

A point at the release (chainage <= 0) starts no scar-to-scar flight and is left
out of heights and spacings. Two conventions keep every score defined whatever the
parameters: a rock that stops before an analysis line counts with speed 0 there (it
is not moving there; leaving it out would reward models whose rocks never arrive),
and a simulation without any flight in the stretch counts as one flight of spacing
0.

Only uninterrupted flights count (the flight's parabola from the launch velocity
reaches the next impact within 1 cm: no rolling, sliding or tree strike between), as
a scar-to-scar flight in the field.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from fieldkit.fit.path_runs import PathRun
from fieldkit.fit.suspect import SuspectCount, SuspectPolicy, count
from fieldkit.impact_table import ImpactTable
from fieldkit.model.model_file import Model
from fieldkit.model.simulate import simulate
from fieldkit.physics.constants import G
from fieldkit.physics.flight_heights import max_normal_height

#: Kind -> what it is (the unit is in the name).
KINDS: dict[str, str] = {
    "runout_m": "runout along the section",
    "flight_height_m": "normal flight heights between impacts",
    "impact_spacing_m": "horizontal spacing of consecutive impacts",
    "speed_mps": "speed at the observed impacts' chainages",
}
#: Tolerance of the landing check of an uninterrupted flight [m].
LANDING_TOLERANCE_M = 0.01


@dataclass(frozen=True)
class AlongObservations:
    """The observed values of each kind of one run (chainages from the release).

    Attributes
    ----------
    values
        Kind -> observed values (finite only; a kind without any is absent).
    speed_chainage_m
        Chainage of each observed speed (same order as ``values["speed_mps"]``).
    launch_range_m
        Chainage stretch the observed flights cover, from the first launch to the
        last landing (None: no flights).
    weights
        Kind -> weight of each value (absent: equal weights); flight heights are
        weighted by their flight's length.
    """

    values: dict[str, np.ndarray]
    speed_chainage_m: np.ndarray
    launch_range_m: tuple[float, float] | None
    weights: dict[str, np.ndarray] = field(default_factory=dict)
    #: Kind -> how many of its values are suspect and what the fit's
    #: :class:`~fieldkit.fit.suspect.SuspectPolicy` did with them (kinds whose
    #: values rest on flights: flight heights and speeds).
    suspect: dict[str, SuspectCount] = field(default_factory=dict)

    def weight(self, kind: str) -> np.ndarray:
        """Weights of the observed values of ``kind`` (ones unless given)."""
        w = self.weights.get(kind)
        return np.ones(self.values[kind].size) if w is None else w


def observed_along(
    run: PathRun, suspect: SuspectPolicy | None = None
) -> AlongObservations:
    """The observed values of every kind of ``run`` (module docstring).

    ``suspect`` says what to do with the flight heights and speeds that rest on a
    flagged impact or an assumed launch angle (the run's ``along_<value>_flags``
    and ``along_<value>_theta0_assumed`` markers, :mod:`fieldkit.fit.suspect`):
    excluded values are dropped, weighted ones have their weight multiplied. None
    (or keeping both groups) leaves every value as observed.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 50], "z_m": [30, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 0, "z_m": 31}})
    >>> run = PathRun("a", m, 40.0, observations={
    ...     "along_chainage_m": np.array([0.0, 10.0, 25.0]),
    ...     "along_vi_mps": np.array([np.nan, 8.0, 11.0]),
    ...     "along_hmax_normal_m": np.array([1.0, 0.5, np.nan])})
    >>> obs = observed_along(run)
    >>> sorted(obs.values), obs.values["impact_spacing_m"].tolist()
    (['flight_height_m', 'impact_spacing_m', 'runout_m', 'speed_mps'], [15.0])
    >>> obs.speed_chainage_m.tolist(), obs.launch_range_m, obs.weight("flight_height_m")
    ([10.0, 25.0], (10.0, 25.0), array([15.]))
    """
    policy = suspect or SuspectPolicy()
    values: dict[str, np.ndarray] = {}
    weights: dict[str, np.ndarray] = {}
    counts: dict[str, SuspectCount] = {}
    if math.isfinite(run.observed_runout_m):
        values["runout_m"] = np.array([run.observed_runout_m])
    obs = run.observations
    chainage = np.asarray(obs.get("along_chainage_m", np.zeros(0)), float)
    speed_at = np.zeros(0)
    stretch = None
    ok = np.isfinite(chainage)
    order = np.flatnonzero(ok)[np.argsort(chainage[ok], kind="stable")]
    c = chainage[order]
    launches = c[:-1] > 0.0  # scar-to-scar flights: not from the release
    spacing = np.diff(c)[launches]
    if spacing.size:
        values["impact_spacing_m"] = spacing
        first, last = c[:-1][launches][[0, -1]]
        stretch = (float(first), float(last + spacing[-1]))
        heights = obs.get("along_hmax_normal_m")
        if heights is not None:
            h = np.asarray(heights, float)[order][:-1][launches]
            good = np.isfinite(h)
            flags, assumed = _markers(obs, "hmax_normal_m", order)
            flags, assumed = flags[:-1][launches], assumed[:-1][launches]
            counts["flight_height_m"] = count(policy, flags[good], assumed[good])
            good &= policy.factors(flags, assumed) > 0
            if good.any():
                values["flight_height_m"] = h[good]
                weights["flight_height_m"] = (
                    spacing[good] * policy.factors(flags, assumed)[good]
                    if not policy.is_default
                    else spacing[good]
                )
    speeds = obs.get("along_vi_mps")
    if speeds is not None:
        v = np.asarray(speeds, float)[order]
        good = np.isfinite(v)
        flags, assumed = _markers(obs, "vi_mps", order)
        counts["speed_mps"] = count(policy, flags[good], assumed[good])
        factor = policy.factors(flags, assumed)
        good &= factor > 0
        if good.any():
            values["speed_mps"] = v[good]
            speed_at = c[good]
            if np.any(factor[good] < 1.0):
                weights["speed_mps"] = factor[good]
    return AlongObservations(values, speed_at, stretch, weights, counts)


def _markers(
    obs: Mapping[str, np.ndarray], name: str, order: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(flag code, assumed)`` of the along-path value ``name`` in ``order``
    (none suspect where the run carries no markers)."""
    flags = obs.get(f"along_{name}_flags")
    assumed = obs.get(f"along_{name}_theta0_assumed")
    if flags is None or assumed is None:
        return np.zeros(order.size, np.int64), np.zeros(order.size, bool)
    f = np.nan_to_num(np.asarray(flags, float)[order], nan=0.0).astype(np.int64)
    a = np.nan_to_num(np.asarray(assumed, float)[order], nan=0.0) > 0
    return f, a


def flights(
    impacts: ImpactTable | Mapping[str, np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Uninterrupted flights between consecutive impacts of one rock.

    Parameters
    ----------
    impacts
        Impacts in rock order: an ImpactTable (rocks by ``path_id``) or the
        simulator's named arrays (:func:`fieldkit.model.simulate.impact_columns`,
        rocks by ``rock``).

    Returns
    -------
    launch_x_m, spacing_m, height_m
        Launch x, horizontal length and greatest normal height (eq. 3.12 with the
        chord's dip as the slope and eq. 3.6 for the launch angle to it) of every
        flight whose parabola from the launch velocity reaches the next impact
        within :data:`LANDING_TOLERANCE_M`.
    """
    if isinstance(impacts, ImpactTable):
        f, rock_key = impacts.frame, "path_id"
    else:
        f, rock_key = impacts, "rock"
    x = np.asarray(f["x_m"], float)
    if x.size < 2:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    z = np.asarray(f["z_m"], float)
    rock = np.asarray(f[rock_key])
    vx = np.asarray(f["vf_x_mps"], float)[:-1]
    vz = np.asarray(f["vf_z_mps"], float)[:-1]
    dx, dz = np.diff(x), np.diff(z)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t = dx / vx
        landed = np.abs(vz * t - 0.5 * G * t**2 - dz) < LANDING_TOLERANCE_M
    ok = (rock[:-1] == rock[1:]) & landed & (dx > 0) & (vx > 0)
    with np.errstate(invalid="ignore"):
        psi = np.degrees(np.arctan2(-dz, dx))  # chord dip, + descending
        theta0 = np.degrees(np.arctan2(vz, vx)) + psi  # eq. 3.6
    # A parabola through both ends leaves above its chord; a launch at or below it
    # "lands" only within the tolerance of a hop of a few millimetres.
    ok &= theta0 > 0.0
    height = max_normal_height(np.hypot(vx[ok], vz[ok]), theta0[ok], psi[ok])
    return x[:-1][ok], dx[ok], np.atleast_1d(height)


def simulated_along(
    run: PathRun,
    model: Model,
    observed: AlongObservations,
    rocks: int,
    seed: int,
    index: int,
    on_impacts: Callable[[dict[str, np.ndarray]], None] | None = None,
) -> dict[str, list[np.ndarray]]:
    """Simulated ensembles for every observed value of ``run`` (module docstring).

    Rocks are drawn from ``default_rng([seed, index])`` (common random numbers, as
    :func:`fieldkit.fit.path_runs.simulated_runouts`); ``on_impacts``, when given,
    also receives the simulated impacts' kernel columns.

    Returns
    -------
    dict
        Kind -> one ensemble per observed value, in the order of
        ``observed.values[kind]`` (pooled kinds share one object); the flight
        heights' ensemble is a (values, weights) pair.
    """
    kinds = observed.values
    release = float(model.seeder.x_m)
    need_flights = "flight_height_m" in kinds or "impact_spacing_m" in kinds
    launches, spacings, heights = [], [], []

    def collect(columns: dict[str, np.ndarray]) -> None:
        if on_impacts is not None:
            on_impacts(columns)
        if not need_flights:
            return
        lx, sp, h = flights(columns)
        launches.append(lx)
        spacings.append(sp)
        heights.append(h)

    record = need_flights or on_impacts is not None
    result = simulate(
        model,
        rocks,
        np.random.default_rng([seed, index]),
        analysis_x_m=release + observed.speed_chainage_m,
        record_impacts=record,
        on_impact_columns=collect if record else None,
    )
    out: dict[str, list[np.ndarray]] = {}
    runout = np.asarray(result.runout_x_m, float) - release
    if "runout_m" in kinds:
        out["runout_m"] = [runout]
    if need_flights:
        lo, hi = observed.launch_range_m
        lx = np.concatenate(launches) - release
        sp, h = np.concatenate(spacings), np.concatenate(heights)
        inside = (lx >= lo) & (lx < hi)
        sp, h = sp[inside], h[inside]
        if "impact_spacing_m" in kinds:
            sample = sp if sp.size else np.zeros(1)
            out["impact_spacing_m"] = [sample] * kinds["impact_spacing_m"].size
        if "flight_height_m" in kinds:
            travelled = float(np.sum(np.clip(runout, lo, hi) - lo))
            grounded = max(travelled - float(sp.sum()), 0.0)
            sample = (np.append(h, 0.0), np.append(sp, grounded))
            if sample[1].sum() <= 0:
                sample = (np.zeros(1), np.ones(1))
            out["flight_height_m"] = [sample] * kinds["flight_height_m"].size
    if "speed_mps" in kinds:
        out["speed_mps"] = [
            np.where(point.crossed, point.speed_mps, 0.0) for point in result.analysis
        ]
    return out
