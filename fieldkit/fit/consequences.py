"""The consequence first: design quantities of fitted models at the analysis points.

A calibration is judged by what a designer reads from it at the asset -- how many
rocks pass a barrier's x, how fast, with how much energy, how high -- not by its
objective. :func:`design_quantities` simulates any number of named models (the
start and the calibrated one; later the refits without flagged data) on **one**
held-out random stream, ``default_rng([seed, DESIGN_STREAM])``:

* the same stream for every model (common random numbers): the same rocks are
  released with the same random draws, so two columns differ by the models only,
  and identical models give identical columns;
* a stream no calibration uses (a path fit simulates with ``[seed, run index]``
  and ``[seed + 1 + b, run index]`` for its bootstrap, its screen and resampling
  use streams 3 and 7,919), so the design quantities are not read on the random
  numbers the parameters were tuned to.

At each point and for each model: the passing fraction, the p50, p95, p99 and
maximum of the speed, translational kinetic energy (1/2 m v^2), total energy
(translational + rotational) and bounce height of the rocks crossing it, each
with its Monte Carlo standard error (:mod:`fieldkit.model.statistics`), the
runout percentiles, and each measured value's place among the crossing rocks
(:func:`fieldkit.model.statistics.rank_of`).

The rule of the verdicts (:meth:`Consequences.verdicts`)
---------------------------------------------------------
A model is **unconservative** against a value measured at a point when

* no rock of the model reaches the point (the measured rock did), or
* the measured value lies above every rock of the model crossing it, or
* the measured value lies above the model's estimated p99 there (a barrier or
  bench designed on the model's p99 would be overrun by the rock that was
  measured; the p99's standard error is printed beside it).

A measured value above the p95 but not the p99 gets a weaker line, "lies above
the p95" (a common design percentile). A value at or below the p95 gets none.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.measured import QUANTITIES, Measured
from fieldkit.model.results import readable
from fieldkit.model.statistics import distribution, fraction_se, rank_of

#: Seed offset of the design quantities' stream: ``default_rng([seed, this])``,
#: never used by a calibration (module docstring).
DESIGN_STREAM = 1_000_003
#: Percentiles of the design quantities (and the maximum).
DESIGN_PERCENTILES: tuple[int, ...] = (50, 95, 99)
#: Percentile above which a measured value makes a model unconservative; the one
#: above which it earns a note.
UNCONSERVATIVE_ABOVE, NOTE_ABOVE = "p99", "p95"
#: :class:`fieldkit.model.results.AnalysisPoint` array of each measured quantity.
_ARRAYS = {"speed_mps": "speed_mps", "ke_j": "ke_j", "total_j": "total_j",
           "height_m": "height_m"}  # fmt: skip
#: The rule in one sentence (JSON, report).
RULE = (
    "unconservative: no rock of the model reaches the point, or the measured value "
    "lies above every crossing rock or above the model's p99 there; a note: above "
    "the p95 only. Percentiles over the rocks crossing the point (first crossing), "
    "each with its Monte Carlo SE"
)


@dataclass(frozen=True)
class ModelAtPoint:
    """One model's design quantities at one point.

    ``quantities`` maps each of :data:`fieldkit.measured.QUANTITIES` to
    :func:`fieldkit.model.statistics.distribution` over the crossing rocks
    (``p50``, ``p95``, ``p99``, ``max``, each with ``se``); ``ranks`` holds, per
    measured value at the point, ``{quantity: rank_of(...)}``.
    """

    passing: int
    passing_fraction: float
    passing_fraction_se: float
    quantities: dict[str, dict]
    ranks: tuple[dict[str, dict], ...]


@dataclass(frozen=True)
class DesignPoint:
    """The design quantities at ``x_m`` (named ``name``) of every model, with the
    values measured there."""

    x_m: float
    name: str
    measured: tuple[Measured, ...]
    models: dict[str, ModelAtPoint]

    def where(self) -> str:
        """``x = 610 m`` (with its name when it has one)."""
        return f"x = {self.x_m:g} m" + (f" ({self.name})" if self.name else "")


@dataclass(frozen=True)
class Consequences:
    """What :func:`design_quantities` returns (module docstring).

    Attributes
    ----------
    rocks, seed
        Rocks per model and the seed of the stream ``[seed, DESIGN_STREAM]``.
    model_names
        The models, in column order.
    points
        One :class:`DesignPoint` per analysis point.
    runout
        Per model: ``n``, ``p50``, ``p95``, ``p99``, ``max`` of the runout x [m]
        (rocks that stopped on or left the profile), ``se`` and ``lower_bound``
        (the statistic uses rocks that left the profile's end).
    """

    rocks: int
    seed: int
    model_names: tuple[str, ...]
    points: tuple[DesignPoint, ...]
    runout: dict[str, dict]

    def has_measured(self) -> bool:
        """Whether any point has a measured value."""
        return any(p.measured for p in self.points)

    def verdicts(self) -> list[str]:
        """One line per (model, measured value) against which the model is
        unconservative or lies above the p95 (the rule of the module docstring);
        unconservative lines first."""
        strong: list[str] = []
        weak: list[str] = []
        for model in self.model_names:
            for point in self.points:
                for j, m in enumerate(point.measured):
                    at = point.models[model]
                    if at.passing == 0:
                        strong.append(
                            f"unconservative: no rock of the {model} model reaches "
                            f"{point.where()}; the measured rock did"
                            + _source(m)
                        )
                        continue
                    for key, value in m.values().items():
                        line = _verdict(point, model, at, key, value, at.ranks[j][key])
                        if line is None:
                            continue
                        (strong if line.startswith("unconservative") else weak).append(
                            line + _source(m)
                        )
        return strong + weak

    def heading(self) -> str:
        """What the table holds and how it was simulated, in one line."""
        return (
            f"design quantities: {self.rocks:,} rocks per model on one held-out "
            f"stream (seed {self.seed}, stream {DESIGN_STREAM}: the same rocks for "
            "every model); ± = Monte Carlo standard error; over the rocks crossing "
            "each point"
        )

    def lines(self) -> list[str]:
        """The table a designer reads: one block per point, a column per model,
        the measured values beside."""
        out = [self.heading()]
        for rows in self.tables():
            out += ["", *_table(rows)]
        return out

    def markdown(self) -> list[str]:
        """:meth:`lines` as markdown tables (one per point, then the runout)."""
        out = [self.heading() + "."]
        for rows in self.tables():
            out += [""]
            for i, row in enumerate(rows):
                cells = [c.strip() or " " for c in row]
                out.append("| " + " | ".join(cells) + " |")
                if i == 0:
                    out.append("|" + "---|" * len(row))
        return out

    def tables(self) -> list[list[list[str]]]:
        """The rows of each table (the first row its head): one per point and
        the runout."""
        tables: list[list[list[str]]] = []
        heads = list(self.model_names)
        for point in self.points:
            rows: list[list[str]] = []
            measured = "measured" if point.measured else ""
            rows.append([point.where(), *heads, measured])
            rows.append(
                ["passing fraction"]
                + [
                    _pm(point.models[n].passing_fraction,
                        point.models[n].passing_fraction_se, 3)
                    + f" ({point.models[n].passing:,})"
                    for n in heads
                ]
                + [""]
            )  # fmt: skip
            for key, (words, scale, unit) in QUANTITIES.items():
                given = [
                    (j, m) for j, m in enumerate(point.measured)
                    if getattr(m, key) is not None
                ]  # fmt: skip
                for stat in (*(f"p{q}" for q in DESIGN_PERCENTILES), "max"):
                    cells = []
                    for n in heads:
                        d = point.models[n].quantities[key]
                        cells.append(_stat(d, stat, scale))
                    side = ""
                    if stat == "p50" and given:
                        side = ", ".join(
                            f"{readable(getattr(m, key) * scale, 3)}" for _, m in given
                        )
                    rows.append([f"{words} {stat} ({unit})", *cells, side])
                for j, m in given:
                    rows.append(
                        [f"  measured {readable(getattr(m, key) * scale, 3)} {unit}: "
                         "percentile"]
                        + [_rank_cell(point.models[n].ranks[j][key]) for n in heads]
                        + [""]
                    )  # fmt: skip
            tables.append(rows)
        censored = any(any(r.get("lower_bound", {}).values())
                       for r in self.runout.values())  # fmt: skip
        head = "runout x (m)" + (
            "; ≥: a lower bound, rocks left the profile's end" if censored else ""
        )
        rows = [[head, *heads, ""]]
        for stat in (*(f"p{q}" for q in DESIGN_PERCENTILES), "max"):
            rows.append(
                [f"runout {stat}"]
                + [_stat(self.runout[n], stat, 1.0) for n in heads]
                + [""]
            )
        tables.append(rows)
        return tables

    def to_dict(self) -> dict:
        """JSON-ready: settings, the rule, per point and model the distributions
        and ranks, the runout, and the verdict lines."""
        return {
            "rocks": self.rocks,
            "seed": self.seed,
            "stream": DESIGN_STREAM,
            "rng": f"numpy default_rng([seed, {DESIGN_STREAM}]), the same for every "
            "model (common random numbers), never used by the calibration",
            "rule": RULE,
            "models": list(self.model_names),
            "points": [
                {
                    "x_m": p.x_m,
                    "name": p.name,
                    "measured": [_measured_dict(m) for m in p.measured],
                    "models": {
                        n: {
                            "passing": a.passing,
                            "passing_fraction": a.passing_fraction,
                            "passing_fraction_se": a.passing_fraction_se,
                            **a.quantities,
                            "measured_rank": [dict(r) for r in a.ranks],
                        }
                        for n, a in p.models.items()
                    },
                }
                for p in self.points
            ],
            "runout_x_m": self.runout,
            "verdicts": self.verdicts(),
        }


def design_quantities(
    models: Mapping[str, object],
    x_m: Sequence[float],
    measured: Sequence[Measured],
    *,
    rocks: int,
    seed: int,
    names: Sequence[str] | None = None,
) -> Consequences:
    """Simulate every model on one held-out stream and read the design quantities.

    Parameters
    ----------
    models
        Named models (``{"start": ..., "calibrated": ...}``), in column order.
    x_m
        The analysis points [m] (may be empty: the runout only).
    measured
        Values measured at some of the points (each ``x_m`` must be one of them).
    rocks
        Rocks per model.
    seed
        Seed of the stream ``default_rng([seed, DESIGN_STREAM])``.
    names
        Optional names of the points (one per ``x_m``).

    Returns
    -------
    Consequences

    Raises
    ------
    ArgumentError
        No model; ``rocks`` < 1; a point outside a model's profile
        (``analysis_x_m``); a measured value at no point (``measured``).

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> slope = model_from_dict({
    ...     "profile": {"x_m": [0, 30, 60], "z_m": [30, 0, 0],
    ...                 "material": ["rock", "rock"]},
    ...     "materials": {"rock": {"e_n": 0.4, "e_t": 0.8, "friction_deg": 30}},
    ...     "body": {"mass_kg": 100, "radius_m": 0.2},
    ...     "seeder": {"x_m": 0.5, "z_m": 31.0, "vx_mps": 2.0, "vx_sd_mps": 0.5}})
    >>> c = design_quantities({"a": slope, "b": slope}, [20.0],
    ...                       [Measured(20.0, speed_mps=99.0)], rocks=200, seed=1)
    >>> c.verdicts()[0][:62]
    'unconservative: measured 99.0 m/s (speed) at x = 20 m lies abo'
    >>> c.points[0].models["a"] == c.points[0].models["b"]  # the same rocks
    True
    """
    from fieldkit.model.simulate import check_run, simulate

    if not models:
        raise ArgumentError("no model to simulate", source="models")
    xs = [float(x) for x in x_m]
    labels = list(names) if names is not None else [""] * len(xs)
    if len(labels) != len(xs):
        raise ArgumentError(
            f"{len(labels)} names for {len(xs)} points", source="names"
        )
    for m in measured:
        if not any(np.isclose(m.x_m, x) for x in xs):
            raise ArgumentError(
                f"x={m.x_m:g} is not an analysis point "
                f"({', '.join(f'{x:g} m' for x in xs) or 'none'})",
                source="measured",
            )
    results = {}
    for name, model in models.items():
        profile = model.profile
        check_run(rocks, (float(profile.x_m[0]), float(profile.x_m[-1])), xs)
        rng = np.random.default_rng([int(seed), DESIGN_STREAM])
        results[name] = simulate(model, rocks, rng, analysis_x_m=xs)
    points = []
    for i, x in enumerate(xs):
        here = tuple(m for m in measured if np.isclose(m.x_m, x))
        points.append(
            DesignPoint(
                x_m=x,
                name=labels[i],
                measured=here,
                models={n: _at_point(r, i, here) for n, r in results.items()},
            )
        )
    runout = {}
    for name, result in results.items():
        r = result.summary()["runout_x_m"]
        runout[name] = {k: r[k] for k in ("n", "p50", "p95", "p99", "max")}
        runout[name]["se"] = {k: r["se"][k] for k in ("p50", "p95", "p99", "max")}
        runout[name]["lower_bound"] = {
            k: r["lower_bound"][k] for k in ("p50", "p95", "p99", "max")
        }
    return Consequences(
        rocks=int(rocks),
        seed=int(seed),
        model_names=tuple(models),
        points=tuple(points),
        runout=runout,
    )


def _at_point(result, index: int, measured: Sequence[Measured]) -> ModelAtPoint:
    """One model's quantities at analysis point ``index`` of ``result``."""
    point = result.analysis[index]
    crossed = np.asarray(point.crossed, bool)
    n = int(crossed.sum())
    fraction, fraction_err = fraction_se(n, int(result.rocks))
    quantities = {}
    for key in QUANTITIES:
        values = np.asarray(getattr(point, _ARRAYS[key]), float)[crossed]
        d = distribution(values, DESIGN_PERCENTILES)
        quantities[key] = {k: d[k] for k in ("n", "p50", "p95", "p99", "max")}
        quantities[key]["se"] = {k: d["se"][k] for k in ("p50", "p95", "p99", "max")}
    ranks = tuple(
        {
            key: rank_of(np.asarray(getattr(point, _ARRAYS[key]), float)[crossed], v)
            for key, v in m.values().items()
        }
        for m in measured
    )
    return ModelAtPoint(
        passing=n,
        passing_fraction=fraction,
        passing_fraction_se=fraction_err,
        quantities=quantities,
        ranks=ranks,
    )


def _verdict(
    point: DesignPoint, model: str, at: ModelAtPoint, key: str, value: float,
    rank: dict,
) -> str | None:  # fmt: skip
    """The line for one measured quantity against one model (None: conservative)."""
    words, scale, unit = QUANTITIES[key]
    what = (
        f"measured {readable(value * scale, 3)} {unit} ({words}) at x = "
        f"{point.x_m:g} m"
    )
    d = at.quantities[key]
    if rank["beyond"] == "above":
        return (
            f"unconservative: {what} lies above every one of the {rank['n']:,} "
            f"crossing rocks of the {model} model (their maximum "
            f"{readable(rank['simulated_max'] * scale, 3)} {unit})"
        )
    for stat, head in ((UNCONSERVATIVE_ABOVE, "unconservative"), (NOTE_ABOVE, "note")):
        level = d.get(stat)
        if level is not None and value > level:
            return (
                f"{head}: {what} lies above the {stat} of the {model} model "
                f"({_pm(level * scale, _se(d, stat, scale), 3)} {unit})"
            )
    return None


def _source(m: Measured) -> str:
    return f" [measured: {m.source}]" if m.source else ""


def _se(d: dict, stat: str, scale: float) -> float:
    se = d["se"].get(stat)
    return math.nan if se is None else se * scale


def _pm(value: float | None, se: float | None, digits: int) -> str:
    """``12.3 ± 0.4`` (no ± without an SE; ``-`` without a value)."""
    if value is None or not math.isfinite(value):
        return "-"
    text = readable(value, digits)
    if se is not None and math.isfinite(se):
        text += f" ± {readable(se, 2)}"
    return text


def _stat(d: dict, stat: str, scale: float) -> str:
    """One statistic of a distribution dict with its SE; ``≥`` and no SE for a
    lower bound (a statistic that uses rocks that left the profile)."""
    v = d.get(stat)
    if v is None:
        return "-"
    if d.get("lower_bound", {}).get(stat):  # uses rocks that left the profile
        return "≥ " + _pm(v * scale, None, 3)
    return _pm(v * scale, _se(d, stat, scale), 3)


def _rank_cell(rank: dict) -> str:
    """A measured value's percentile among a model's crossing rocks, short."""
    if not rank["n"]:
        return "no rock crosses"
    if rank["beyond"] is not None:
        return f"{rank['beyond']} all {rank['n']:,}"
    return f"{rank['percentile']:.1f} ± {rank['percentile_se']:.1f}"


def _measured_dict(m: Measured) -> dict:
    out: dict = {"x_m": m.x_m, **m.values()}
    if m.source:
        out["source"] = m.source
    return out


def _table(rows: list[list[str]]) -> list[str]:
    """Rows padded into columns (two spaces apart)."""
    width = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return ["  ".join(c.ljust(w) for c, w in zip(r, width, strict=True)).rstrip()
            for r in rows]  # fmt: skip
