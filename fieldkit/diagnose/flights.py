"""Flight-level diagnosis of a video track: is ``air_drag`` missing from the flights?

The data are the centre positions of the samples in each ballistic flight of a track
(the flights found by :mod:`fieldkit.tracking.flights`; this module takes them as
plain :class:`FlightSamples`). Two models are compared by their held-out error:

* **baseline** -- the parabola with ``g = 9.81 m/s^2`` fixed; each flight's initial
  position and velocity are nuisance parameters (closed-form least squares);
* **air_drag** -- quadratic drag ``a = g - k |v| v`` with ``k = rho C_d pi r^2 /
  (2 m)`` exactly as in the simulator (:mod:`fieldkit.model.effects.air_drag`), one
  **global** ``k``, the same four nuisance parameters per flight. The fit is
  :func:`fieldkit.model.drag_flight.fit_drag`, the one `fieldkit track` makes of a
  dragged flight, over the same range ``0 <= k <=``
  :data:`~fieldkit.model.drag_flight.MAX_K_PER_M`; it is reported as
  ``air_drag.cd`` for the body (air density held at the registry default) and as
  ``k`` in the notes. The range is one of ``k``, not the registry's ``cd <= 3``
  for rough rocks: a light ball's ``k`` is far beyond it (a 75 mm, 140 g ball with
  ``k = 0.35 1/m`` has ``cd = 18``), and a ``cd`` clipped at 3 left that drag in
  the residuals.

Cross-validation holds out whole flights (the groups of
:func:`~fieldkit.diagnose.groups.make_groups`): ``k`` is fitted on the training
flights (Newton on the sum of squares profiled over the flights' own parameters),
then each held-out flight's initial state is refitted with ``k`` fixed. The
baseline has no global parameter, so its held-out residuals are its per-flight fits;
both models thus get the same freedom per held-out flight, and the gain is the
improvement of the held-out RMS of the position residuals (``cv_rmse_m``, per
coordinate), with its jackknife standard error over flights
(:mod:`fieldkit.diagnose.scoring`). ``air_drag`` is recommended when the gain
exceeds :data:`~fieldkit.diagnose.scoring.MIN_GAIN` and
:data:`~fieldkit.diagnose.scoring.DEFAULT_Z` standard errors, the rule of the
impact-level diagnosis.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import stats

from fieldkit.diagnose.diagnosis import (
    Candidate,
    Dependence,
    Diagnosis,
    ModelScore,
    Step,
)
from fieldkit.diagnose.groups import make_groups
from fieldkit.diagnose.residual_tests import describe, mark_holm
from fieldkit.diagnose.scoring import (
    DEFAULT_Z,
    MIN_GAIN,
    held_out,
    improvement,
    meaningful,
    recommendation_rule,
)
from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.model import drag_flight
from fieldkit.model.effects import air_drag, registry
from fieldkit.physics.constants import G

#: Fewest flights for a held-out comparison (and a jackknife SE) over flights.
MIN_FLIGHTS = 3
#: Fewest samples per flight (four nuisance parameters per flight, plus residuals).
MIN_FLIGHT_SAMPLES = 6
#: Rock density assumed when no mass is given [kg/m^3] (sphere of the radius).
ROCK_DENSITY_KG_M3 = 2650.0
#: Largest body radius a flight diagnosis accepts [m]: a 25 m sphere of rock is
#: 1.7e8 kg, beyond any single rockfall block (rock avalanches are not ballistic).
MAX_RADIUS_M = 25.0
#: Largest body mass a flight diagnosis accepts [kg] (a 25 m sphere of rock).
MAX_MASS_KG = 2.0e8
#: Family-wise level of the residual dependence tests (Holm correction).
DEPENDENCE_ALPHA = 0.05
_SPEC = air_drag.SPEC
_RHO = next(p.default for p in _SPEC.parameters if p.name == "air_density_kg_m3")
_CD_MAX = next(p.upper for p in _SPEC.parameters if p.name == "cd")


@dataclass(frozen=True)
class FlightSamples:
    """The samples of one flight: times [s] and centre positions [m] (x along the
    travel, z up). ``label`` names it in messages (e.g. ``"flight 3 (rows 120-180)"``).
    """

    t_s: np.ndarray
    x_m: np.ndarray
    z_m: np.ndarray
    label: str = ""


@dataclass
class _Data:
    """All flights concatenated (time order within each flight)."""

    t: np.ndarray
    x: np.ndarray
    z: np.ndarray
    start: np.ndarray  # flight f is start[f]:start[f+1]
    flight: np.ndarray  # flight index of each sample
    labels: list[str]

    @property
    def n_flights(self) -> int:
        return self.start.size - 1

    def subset(self, which: np.ndarray) -> _Data:
        """The flights ``which`` (indices, increasing)."""
        parts = [np.arange(self.start[f], self.start[f + 1]) for f in which]
        rows = np.concatenate(parts)
        sizes = np.array([p.size for p in parts])
        return _Data(
            self.t[rows],
            self.x[rows],
            self.z[rows],
            np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
            np.repeat(np.arange(len(parts)), sizes),
            [self.labels[f] for f in which],
        )


@dataclass
class _Fit:
    """A model fitted to flights: drag factor, per-flight states, residuals."""

    k: float
    params: np.ndarray  # (n_flights, 4): x0, z0, vx0, vz0 at each flight's start
    sse: float
    info: float  # sum |j_k perp|^2: the profiled curvature of sse/2 in k
    residual: np.ndarray  # (n, 2)
    speed: np.ndarray  # (n,) model speed


def sphere_mass_kg(radius_m: float) -> float:
    """Mass of a rock sphere of ``radius_m`` at :data:`ROCK_DENSITY_KG_M3`.

    Examples
    --------
    >>> round(sphere_mass_kg(0.2), 2)
    88.8
    """
    return ROCK_DENSITY_KG_M3 * 4.0 / 3.0 * math.pi * radius_m**3


def _collect(flights: list[FlightSamples], source: str | None) -> _Data:
    """Check the flights (count, samples, times) and concatenate them."""
    if len(flights) < MIN_FLIGHTS:
        raise InputFileError(
            f"{len(flights)} flight(s) found; at least {MIN_FLIGHTS} are needed "
            "to diagnose flight-level effects (whole flights are held out)",
            source=source,
        )
    ts, xs, zs, labels = [], [], [], []
    for i, f in enumerate(flights):
        label = f.label or f"flight {i}"
        t, x, z = (np.asarray(a, float) for a in (f.t_s, f.x_m, f.z_m))
        ok = np.isfinite(t) & np.isfinite(x) & np.isfinite(z)
        if ok.sum() < MIN_FLIGHT_SAMPLES:
            raise InputFileError(
                f"{int(ok.sum())} usable samples in the flight; at least "
                f"{MIN_FLIGHT_SAMPLES} are needed",
                source=source,
                where=label,
            )
        t, x, z = t[ok], x[ok], z[ok]
        if np.any(np.diff(t) <= 0):
            raise InputFileError(
                "sample times must increase within a flight", source=source, where=label
            )
        ts.append(t)
        xs.append(x)
        zs.append(z)
        labels.append(label)
    sizes = np.array([t.size for t in ts])
    return _Data(
        np.concatenate(ts),
        np.concatenate(xs),
        np.concatenate(zs),
        np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
        np.repeat(np.arange(len(ts)), sizes),
        labels,
    )


def _fit(data: _Data, k: float | None = None) -> _Fit:
    """Fit the flights with ``k`` fixed (given) or fitted: the fit `fieldkit track`
    makes of a dragged flight (:func:`fieldkit.model.drag_flight.fit_drag`), here
    with one ``k`` shared by the flights."""
    fit = drag_flight.fit_drag(data.t, data.x, data.z, data.start, G, k_per_m=k)
    residual, speed = drag_flight.residuals(
        data.t, data.x, data.z, data.start, fit.k_per_m, G, drag_flight.MAX_STEP_S,
        fit.params,
    )  # fmt: skip
    return _Fit(fit.k_per_m, fit.params, fit.sse_m2, fit.info, residual, speed)


def _held_out_drag(data: _Data, fold: np.ndarray) -> np.ndarray:
    """Held-out residuals ``(n, 2)`` of the drag model: ``k`` from the other folds,
    each held-out flight's state refitted with that ``k``."""
    out = np.empty((data.t.size, 2))
    fold_of_flight = fold[data.start[:-1]]
    for f in np.unique(fold_of_flight):
        test = np.flatnonzero(fold_of_flight == f)
        train = np.flatnonzero(fold_of_flight != f)
        k = _fit(data.subset(train)).k
        rows = np.isin(data.flight, test)
        out[rows] = _fit(data.subset(test), k=k).residual
    return out


def _features(data: _Data, fit: _Fit) -> dict[str, np.ndarray]:
    """Per-sample features: |time from mid-flight| / half the flight, model speed."""
    t_mid = np.empty(data.t.size)
    for f in range(data.n_flights):
        a, b = data.start[f], data.start[f + 1]
        half = 0.5 * (data.t[b - 1] - data.t[a])
        t_mid[a:b] = np.abs(data.t[a:b] - 0.5 * (data.t[a] + data.t[b - 1])) / half
    return {"time_from_mid_flight": t_mid, "speed_mps": fit.speed}


def _dependence(
    data: _Data, fit: _Fit, *, alpha: float = DEPENDENCE_ALPHA
) -> list[Dependence]:
    """Spearman tests of the x and z residuals against the time from mid-flight and
    the model speed, Holm-corrected over the four tests."""
    features = _features(data, fit)
    tests = []
    for feature, values in features.items():
        for c, component in enumerate(("x", "z")):
            rho, p = stats.spearmanr(values, fit.residual[:, c])
            rho = 0.0 if not np.isfinite(rho) else float(rho)
            p = 1.0 if not np.isfinite(p) else float(p)
            tests.append((feature, component, rho, p))
    return mark_holm(
        [
            Dependence(
                feature=feature,
                component=f"position_{component}",
                statistic=f"Spearman rho = {rho:+.3f} (n = {data.t.size})",
                p_value=p,
                significant=False,
                p_method="Spearman",
            )
            for feature, component, rho, p in tests
        ],
        alpha,
    )


def _free_g_note(data: _Data) -> str:
    """The g of a free-g parabola per flight, against 9.81."""
    values = []
    for f in range(data.n_flights):
        a, b = data.start[f], data.start[f + 1]
        tau = data.t[a:b] - data.t[a]
        design = np.column_stack([np.ones_like(tau), tau, tau * tau])
        coef = np.linalg.lstsq(design, data.z[a:b], rcond=None)[0]
        values.append(-2.0 * coef[2])
    shown = ", ".join(f"{g:.3f}" for g in values)
    return (
        f"free-g parabola per flight: g = {shown} m/s^2 (the models use {G:g}); "
        "quadratic drag lowers the apparent g of falling flights, raises it on "
        "rising ones, and slows x (which a parabola keeps linear)"
    )


def _drag_note(
    k: float, k_sd: float, cd: float, radius_m: float, mass_kg: float
) -> str:
    """The fitted drag factor as `fieldkit track` states it, and its ``cd``; a
    ``cd`` beyond the registry's range is said to be so (a light body, or a mass or
    radius that is not the body's)."""
    text = (
        f"air_drag fitted: k = {k:.4g} ± {k_sd:.2g} 1/m in a = g - k |v| v (one k "
        f"for all flights, the fit `fieldkit track` makes of a dragged flight), "
        f"cd = {cd:.4g} for radius {radius_m:g} m and mass {mass_kg:.4g} kg"
    )
    if cd > _CD_MAX:
        text += (
            f"; cd is beyond the registry's {_CD_MAX:g} for a rough block: check the "
            "mass and radius, and a model file takes cd only within its range"
        )
    return text


def _skipped() -> dict[str, str]:
    """Every registered effect but air_drag, with why flight positions cannot
    inform it."""
    out = {}
    for spec in registry.EFFECTS:
        if spec.name == "air_drag":
            continue
        if spec.name == "tree_impacts":
            out[spec.name] = "no tree strikes in a video flight"
        elif spec.stage == "impact":
            out[spec.name] = (
                "acts at contact (impact stage): flight positions do not inform it; "
                "diagnose the track's ImpactTable instead"
            )
        else:
            out[spec.name] = f"{spec.stage}-stage effect not modelled in flights"
    return out


def check_body(radius_m: float, mass_kg: float | None) -> None:
    """Refuse a radius or mass that is not finite, not positive or beyond the bounds
    (:data:`MAX_RADIUS_M`, :data:`MAX_MASS_KG`)."""
    if not (math.isfinite(radius_m) and 0 < radius_m <= MAX_RADIUS_M):
        raise ArgumentError(
            f"radius_m must be > 0 and <= {MAX_RADIUS_M:g} m (got {radius_m:g})",
            source="radius_m",
        )
    if mass_kg is not None and not (
        math.isfinite(mass_kg) and 0 < mass_kg <= MAX_MASS_KG
    ):
        raise ArgumentError(
            f"mass_kg must be > 0 and <= {MAX_MASS_KG:g} kg (got {mass_kg:g})",
            source="mass_kg",
        )


def diagnose_flights(
    flights: list[FlightSamples],
    *,
    radius_m: float,
    mass_kg: float | None = None,
    rng: np.random.Generator,
    folds: int = 5,
    z: float = DEFAULT_Z,
    source: str | None = None,
    progress: Callable[[str], None] | None = None,
) -> Diagnosis:
    """Whether ``air_drag`` improves the held-out fit of a track's flights.

    Parameters
    ----------
    flights
        The flights (at least :data:`MIN_FLIGHTS`, each with at least
        :data:`MIN_FLIGHT_SAMPLES` samples).
    radius_m, mass_kg
        The body; without a mass, a sphere of rock (:data:`ROCK_DENSITY_KG_M3`).
    rng
        Random generator for the folds.
    folds
        Folds of the cross-validation (whole flights held out).
    z
        Standard errors a gain must exceed to be meaningful.
    source
        The track file, for messages.
    progress
        Called with a short message once the flights have passed every check and
        the fitting starts (a caller shows progress from then on).

    Returns
    -------
    Diagnosis
        Metric ``cv_rmse_m``: held-out RMS of the x and z position residuals [m].

    Raises
    ------
    InputFileError
        Fewer than three flights, or a flight with too few samples.
    ArgumentError
        ``radius_m`` or ``mass_kg`` not finite, not positive or beyond
        :data:`MAX_RADIUS_M`, :data:`MAX_MASS_KG`; ``folds`` out of range.
    """
    check_body(radius_m, mass_kg)
    data = _collect(flights, source)
    if progress is not None:
        progress("fitting")
    notes = [f"air density held at {_RHO:g} kg/m^3 (registry default)"]
    if mass_kg is None:
        mass_kg = sphere_mass_kg(radius_m)
        notes.append(
            f"mass not given: a sphere of rock ({ROCK_DENSITY_KG_M3:g} kg/m^3) of "
            f"radius {radius_m:g} m, {mass_kg:.4g} kg; the fitted cd scales with "
            "the assumed mass / radius^2"
        )
    per_cd = float(air_drag.drag_factor(1.0, _RHO, radius_m, mass_kg))

    groups = make_groups(data.flight, rng, folds=folds, min_paths=MIN_FLIGHTS)
    n_groups = groups.n_groups
    base = _fit(data, k=0.0)
    base_ho = held_out(base.residual, 1.0, groups.group, n_groups)
    drag_ho = held_out(_held_out_drag(data, groups.fold), 1.0, groups.group, n_groups)
    gain, se = improvement(base_ho, drag_ho)
    # the impact-level rule, 1 % floor included: detection errors correlated over
    # frames let a tiny cd absorb them with a small jackknife SE (the plain
    # bounce_short clip, no drag: +0.2 % +/- 0.1 %), and such a gain is not worth
    # a parameter
    ok = meaningful(gain, se, z=z, min_gain=MIN_GAIN)

    full = _fit(data)
    n_obs = 2 * data.t.size
    dof = max(1, n_obs - 4 * data.n_flights - 1)
    sigma2 = full.sse / dof
    k_sd = math.sqrt(sigma2 / full.info) if full.info > 0 else math.inf
    cd, cd_sd = full.k / per_cd, k_sd / per_cd
    notes.append(_drag_note(full.k, k_sd, cd, radius_m, mass_kg))
    drag_params = {"air_drag.cd": cd, "air_drag.air_density_kg_m3": _RHO}
    candidate = Candidate(
        effect="air_drag",
        cv_rmse=drag_ho.rmse,
        improvement=gain,
        improvement_se=se,
        meaningful=ok,
        params={"air_drag.cd": cd},
        params_sd={"air_drag.cd": cd_sd},
    )
    baseline = ModelScore(
        effects=[],
        cv_rmse=base_ho.rmse,
        params={"gravity_mps2": G},
        fit_rmse=math.sqrt(base.sse / n_obs),
    )
    if ok:
        after = ModelScore(
            effects=["air_drag"],
            cv_rmse=drag_ho.rmse,
            params=drag_params,
            params_sd={"air_drag.cd": cd_sd},
            fit_rmse=math.sqrt(full.sse / n_obs),
        )
        steps = [Step("air_drag", base_ho.rmse, drag_ho.rmse, [candidate])]
        stopped = "no flight-level candidate left (air_drag is the only one)"
        final = full
    else:
        after, steps, final = baseline, [], base
        stopped = (
            f"air_drag does not improve the held-out error meaningfully "
            f"(gain {gain:+.1%} ± {se:.1%}; needs more than {MIN_GAIN:.0%} and "
            f"{z:g} standard errors)"
        )
    before = _dependence(data, base)
    after_dep = _dependence(data, final)
    notes.append(_free_g_note(data))
    per_flight = [
        math.sqrt(
            float((base.residual[data.flight == f] ** 2).sum())
            / (2 * (data.start[f + 1] - data.start[f]))
        )
        for f in range(data.n_flights)
    ]
    worst = [
        {"flight": data.labels[f], "baseline_rmse_m": per_flight[f]}
        for f in np.argsort(per_flight)[::-1][:3]
    ]
    return Diagnosis(
        metric="cv_rmse_m",
        baseline=baseline,
        candidates=[candidate],
        recommended="air_drag" if ok else None,
        steps=steps,
        confounded=[],
        after=after,
        rule=(
            f"air_drag is recommended when {recommendation_rule(z, MIN_GAIN)} "
            "(jackknife over flights)"
        ),
        groups=(
            f"{data.n_flights} flights (whole flights held out); "
            f"{groups.n_folds}-fold cross-validation; each held-out flight's "
            "initial position and velocity refitted for both models"
        ),
        stopped=stopped,
        skipped=_skipped(),
        dependence_before=before,
        dependence_after=after_dep,
        unexplained=describe(after_dep),
        worst=worst,
        notes=notes,
        n_data=n_obs,
        n_rows=int(data.t.size),
        size=f"{int(data.t.size)} samples of {data.n_flights} flights",
        arrays={
            "features": _features(data, base),
            "baseline": base.residual,
            "steps": [full.residual] if ok else [],
            "after": final.residual,
            "components": ("x", "z"),
            "dependence": [before] + ([after_dep] if ok else []),
            "residual_kind": "in-sample (each flight's own fit)",
        },
    )
