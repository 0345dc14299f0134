"""Detection power and false findings of ``diagnose`` on virtual campaigns (issue 18).

Where ``bench_diagnose_power.py`` diagnoses clean synthetic tables (exact impact
states, noise on the rebound only), this benchmark diagnoses *surveyed* paths: the
rocks are simulated on boulder A's profile, their scars surveyed with GNSS error,
reduced with an assumed launch angle and pieced into paths exactly as the
diagnosis's own null campaigns are (:func:`fieldkit.diagnose.survey_loop.loop_table`).
It is the table a geologist plans a survey with: how many paths, how many scars
per path, with or without tree strikes, to find eq. 7.1 (or eq. 5.4) and not find
what is not there.

Geometry and truth
------------------
Boulder A (``surveys/tornado_mountain/boulder_a_section.csv`` with its trees and
preset, reduced through the library as ``fieldkit reduce --preset`` does, its
talus and bench mapped to colluvium as the preset says). Its
:class:`~fieldkit.diagnose.survey_loop.LoopPath` (:func:`loop_paths`) gives the
profile, the assumed theta0 (32.6 deg), the body and the tree share (30.6 % of its
flights fixed by a tree strike); the GNSS error is set to 0.5 m in plan and height.
The *true* world is :func:`baseline_world` of boulder A's plain diagnosis (no
model; constant e_n, e_t per material with the table's own scatter): what a user's
own null would simulate.

A campaign design is ``(P paths, S scars per path, trees)``: ``P`` copies of the
path with distinct path ids, ``S`` via ``LoopPath.target_scars``, trees as boulder
A's or ``tree_share = 0`` (every flight solved with the assumed theta0). A campaign
is ``loop_table(paths, materials, world, rng)``; it is screened with
:func:`~fieldkit.diagnose.impacts.screen_impacts` (5 folds, the candidates boulder
A's diagnosis tests) by :func:`~fieldkit.diagnose.survey_loop.run_tasks`.

Effects and sizes
-----------------
none; velocity_scaled_restitution (eq. 7.1) ``k_mps`` 7 and 14;
angle_dependent_restitution (eq. 5.4, theta_ref 30 deg) ``b`` 0.5 and 1.03, each
added to the true world. ``A/sigma`` is printed beside each size:

* ``A`` [m/s]: RMS, over the true impacts (``vin``, ``vit`` of the simulation
  behind the scars) of rocks simulated in the world with the effect, of the part
  of the effect the baseline cannot absorb: the clean rebound ``(vfn, vft)`` with
  the effect (material mean e_n, e_t) minus its least-squares constant-(e_n,
  e_t)-per-material fit, over the ``2n`` data (a survey measures no spin).
* ``sigma`` [m/s]: the median held-out RMSE of the baseline (the diagnosis's own
  metric, weighted by the reduction's errors) over the design's threshold null
  campaigns: the scatter plus everything the survey and reduction add.

So ``A/sigma`` is the effect's size against the noise the diagnosis actually sees
on that design, not against the rebound scatter alone.

Rates
-----
Per design, an *oracle* threshold: :func:`null_threshold` (q = 0.95) of the best
gains of ``B`` null campaigns of the true effect-free world. The false-finding
rate is measured on ``N`` *other* null campaigns (a separate seed stream); per
effect and size, ``correct`` = the screen recommends the true effect with a gain
above the threshold, ``wrong`` = it recommends another candidate above the
threshold. ``plain`` is the rule without a null (gain > 2 SE and > 1 %): what
diagnose did before issue 18. Each rate has its binomial SE ``sqrt(p (1-p) / N)``.

The end-to-end check of the done-when runs what a user runs: one-path campaigns
(45 scars, trees as boulder A, no effect) each diagnosed with
``diagnose_surveyed(table, None, seed, folds=5, null_size=19, power_size=0,
workers=1)`` -- its own null from its *own fitted* baseline -- and counts
recommendations. One ``diagnose_surveyed`` of boulder A with the defaults (null
99, power 40 per candidate) is timed on the pool's workers.

``--full`` (``make bench-diagnose``): the done-when rows first (end-to-end >= 100
campaigns; 10 paths x 50 scars at K = 7 m/s, 100 campaigns), then the grid (P in
1, 3, 10; S in 20, 50, 100; both tree settings; ``--campaigns`` per cell) in order
of cost. The short default (``make bench``) runs P in 1, 3 and S in 20, 50 with
boulder A's trees, a handful of campaigns per cell. ``--out FILE`` writes the
markdown as it goes, a row at a time, the key rows so far beside it
(``FILE.key.md``) and every campaign's screen (its gains per candidate) to
``FILE.jsonl``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
HERE = Path(__file__).resolve().parent
SURVEY = ROOT / "surveys" / "tornado_mountain"
#: GNSS error of the virtual surveys, plan and height [m] (issue 18's campaigns).
GNSS_SIGMA_M = 0.5
#: Scars of the end-to-end one-path campaigns (boulder A has 49).
E2E_SCARS = 45
FOLDS = 5
QUANTILE = 0.95
#: (label, effect, parameter, value): the truths of the grid, none first.
TRUTHS = (
    ("none", None, None, None),
    ("eq. 7.1 K=7", "velocity_scaled_restitution", "k_mps", 7.0),
    ("eq. 7.1 K=14", "velocity_scaled_restitution", "k_mps", 14.0),
    ("eq. 5.4 b=0.5", "angle_dependent_restitution", "b", 0.5),
    ("eq. 5.4 b=1.03", "angle_dependent_restitution", "b", 1.03),
)
#: Seed streams (spawn keys under the run's seed): never shared.
STREAM_THRESHOLD, STREAM_NULL, STREAM_POWER, STREAM_E2E, STREAM_SIZE = range(5)


@dataclass(frozen=True)
class Design:
    """A campaign design: ``paths`` surveyed paths of ``scars`` scars each."""

    paths: int
    scars: int
    trees: bool  # boulder A's tree share, or none

    @property
    def label(self) -> str:
        return f"{self.paths}×{self.scars} {'trees' if self.trees else 'no trees'}"


    @property
    def key(self) -> tuple[int, int, int]:
        return (self.paths, self.scars, int(self.trees))

    @property
    def cost(self) -> int:
        return self.paths * self.scars


@dataclass
class World:
    """Boulder A's geometry and the true world of every campaign."""

    table: object
    path: object  # LoopPath
    materials: dict
    candidates: list[str]
    notes: list[str]
    #: The share of flights a tree strike fixes in a "trees" design (None: boulder
    #: A's own, 31 %); ``--tree-share``.
    tree_share: float | None = None
    #: The campaigns' survey error in plan and height [m] (None: GNSS_SIGMA_M);
    #: ``--position-sigma`` (a total station: a few centimetres).
    position_sigma_m: float | None = None


def boulder_a() -> World:
    """Boulder A reduced as ``fieldkit reduce --preset`` does, its plain diagnosis,
    its loop path (GNSS error 0.5 m) and the true world (its fitted baseline)."""
    from fieldkit.diagnose.impacts import diagnose_impacts
    from fieldkit.diagnose.survey_loop import baseline_world, loop_paths
    from fieldkit.fit.material_map import map_materials
    from fieldkit.io.impacts import read_impacts
    from fieldkit.io.preset import read_preset
    from fieldkit.io.trees import read_trees
    from fieldkit.physics.bodies import resolve_body
    from fieldkit.reduce.pipeline import ReduceOptions, reduce_path
    from fieldkit.reduce.uncertainty import PositionError
    from fieldkit.survey import Survey

    preset = read_preset(SURVEY / "boulder_a_preset.toml")
    given = preset.reduce
    points = read_impacts(SURVEY / "boulder_a_section.csv", units="m")
    trees = read_trees(SURVEY / "boulder_a_trees.csv", points, units="m")
    body = resolve_body(
        mass_kg=given["mass_kg"],
        radius_m=given["radius_m"],
        gyration_m=given["gyration_m"],
    )
    options = ReduceOptions(
        path_id=given["path_id"],
        theta0_deg=given["theta0_deg"],
        body=body,
        position_error=PositionError(
            position_sigma_m=GNSS_SIGMA_M, elevation_sigma_m=GNSS_SIGMA_M
        ),
    )
    table = reduce_path(Survey(points, trees), options).table
    table = map_materials(table, None, None, preset.materials).table
    first = diagnose_impacts(table, None, rng=np.random.default_rng(1), folds=FOLDS)
    paths, notes = loop_paths(table)
    path = replace(
        paths[0], position_sigma_m=GNSS_SIGMA_M, elevation_sigma_m=GNSS_SIGMA_M
    )
    materials, _ = baseline_world(table, first.baseline.params, None)
    return World(table, path, materials, [c.effect for c in first.candidates], notes)


def campaign_paths(world: World, design: Design, scars: int | None = None) -> list:
    """``design.paths`` copies of boulder A's path with distinct ids."""
    share = (world.tree_share or world.path.tree_share) if design.trees else 0.0
    sigma = world.position_sigma_m or world.path.position_sigma_m
    return [
        replace(
            world.path,
            position_sigma_m=sigma,
            elevation_sigma_m=sigma,
            path_id=f"{world.path.path_id}-{k + 1}",
            target_scars=scars or design.scars,
            tree_share=share,
        )
        for k in range(design.paths)
    ]


def truth_effects(effect: str | None, param: str | None, value: float | None) -> dict:
    return {} if effect is None else {effect: {param: float(value)}}


def seeds(seed: int, stream: int, key: tuple, n: int) -> list[np.random.SeedSequence]:
    """``n`` seeds of ``stream`` for the cell ``key`` (independent of which other
    cells a run holds)."""
    return np.random.SeedSequence(seed, spawn_key=(stream, *key)).spawn(n)


# ---------------------------------------------------------------------- effect size
def effect_size(
    world: World,
    effects: dict,
    rocks: int,
    seed: int,
    key: int,
    simulated_with: dict | None = None,
) -> float:
    """``A`` [m/s] of ``effects`` over the true impacts of ``rocks`` rocks simulated
    in the world with them (or with ``simulated_with``: two effects compared on the
    same impacts), started as the loop starts them, at random observed scars;
    module docstring."""
    from fieldkit.campaign.virtual import virtual_campaign
    from fieldkit.diagnose.survey_loop import PIECE_SCARS, path_design, path_model
    from fieldkit.fit.impact_model import ImpactInputs, predict_arrays

    path = world.path
    rng = np.random.default_rng(seeds(seed, STREAM_SIZE, (key,), 1)[0])
    design = replace(path_design(path), max_scars=PIECE_SCARS, min_scars=2)
    frames = []
    for _ in range(rocks):
        start = int(rng.integers(1, len(path.x_m) - 2))
        world_effects = effects if simulated_with is None else simulated_with
        model = path_model(path, world.materials, world_effects, start)
        truth = virtual_campaign(model, design, 1, rng, source="size").paths[0].truth
        frames.append(truth.iloc[1:])  # the release point is no impact
    vin = np.concatenate([f["vin_mps"].to_numpy(float) for f in frames])
    vit = np.concatenate([f["vit_mps"].to_numpy(float) for f in frames])
    material = np.concatenate([f["material"].astype(str).to_numpy() for f in frames])
    ok = np.isfinite(vin) & np.isfinite(vit)
    vin, vit, material = vin[ok], vit[ok], material[ok]
    names = tuple(world.materials)
    index = np.array([names.index(m) for m in material])
    n = len(vin)
    inputs = ImpactInputs(
        vin_mps=np.ascontiguousarray(vin),
        vit_mps=np.ascontiguousarray(vit),
        omega_i_radps=np.zeros(n),
        radius_m=np.full(n, path.radius_m),
        gyration_m=np.full(n, path.gyration_m),
        material_index=index,
        material_names=names,
    )
    e_n = np.array([world.materials[m]["e_n"] for m in names])
    e_t = np.array([world.materials[m]["e_t"] for m in names])
    clean = predict_arrays(inputs, e_n, e_t, effects)[:, :2]
    resid = np.empty_like(clean)
    for m in np.unique(index):
        rows = index == m
        for col, x in ((0, vin), (1, vit)):
            c = np.sum(clean[rows, col] * x[rows]) / np.sum(x[rows] ** 2)
            resid[rows, col] = clean[rows, col] - c * x[rows]
    return float(np.sqrt(np.mean(resid**2)))


# ----------------------------------------------------------------------- the grid
def rate(k: int, n: int) -> str:
    """``"12% ± 3% "`` (binomial SE) or ``"-"``."""
    if n == 0:
        return "-"
    p = k / n
    return f"{p:.0%} ± {math.sqrt(p * (1 - p) / n):.0%}"


class Out:
    """Markdown to stdout and, with ``--out``, to a file flushed line by line."""

    def __init__(self, path: Path | None) -> None:
        self.file = open(path, "w") if path is not None else None  # noqa: SIM115

    def __call__(self, line: str = "") -> None:
        print(line, flush=True)
        if self.file is not None:
            self.file.write(line + "\n")
            self.file.flush()

    def close(self) -> None:
        if self.file is not None:
            self.file.close()


HEAD = (
    "| design (paths × scars) | truth | A/σ | N | correct | wrong | false | "
    "plain correct | plain wrong / false |"
)
RULE = "|---|---|---|---|---|---|---|---|---|"


def classify(results: list[dict], effect: str | None, threshold: float) -> dict:
    """Counts of one cell from :func:`run_task`'s results (screened with the plain
    rule, ``gain_floor`` 0): under the oracle ``threshold`` a recommendation counts
    only when the best gain exceeds it (the screen's recommendation is always its
    best candidate); ``plain_*`` are the plain rule's own recommendations.
    ``correct``/``wrong`` are None for a null cell, ``false`` for an effect cell.

    Examples
    --------
    >>> rs = [{"failed": None, "recommended": "v", "best_gain": 0.05},
    ...       {"failed": None, "recommended": "v", "best_gain": 0.20},
    ...       {"failed": None, "recommended": "a", "best_gain": 0.30},
    ...       {"failed": None, "recommended": None, "best_gain": 0.00},
    ...       {"failed": "no scars"}]
    >>> c = classify(rs, "v", 0.10)
    >>> c["n"], c["correct"], c["wrong"], c["plain_correct"], c["plain_other"]
    (4, 1, 1, 2, 1)
    >>> classify(rs, None, 0.10)["false"], classify(rs, None, 0.10)["failed"]
    (2, 1)
    """
    ok = [r for r in results if r["failed"] is None]
    above = [
        r for r in ok if r["recommended"] is not None and r["best_gain"] > threshold
    ]
    if effect is None:
        correct = wrong = plain_c = None
        false = len(above)
        plain_w = sum(r["recommended"] is not None for r in ok)
    else:
        correct = sum(r["recommended"] == effect for r in above)
        wrong = len(above) - correct
        false = None
        plain_c = sum(r["recommended"] == effect for r in ok)
        plain_w = sum(r["recommended"] not in (None, effect) for r in ok)
    return {
        "n": len(ok),
        "correct": correct,
        "wrong": wrong,
        "false": false,
        "plain_correct": plain_c,
        "plain_other": plain_w,
        "failed": len(results) - len(ok),
    }


def run_design(world, design, truths, args, out, sizes, rows, workers, cache) -> dict:
    """Threshold nulls and the cells ``truths`` of ``design``: one pool run; prints
    a row per cell and returns the design's figures. ``cache`` keeps each design's
    threshold campaigns, so a design run in two parts draws them once."""
    from fieldkit.diagnose.survey_loop import LoopTask, null_threshold, run_tasks

    paths = campaign_paths(world, design)

    def tasks(kind, stream, key, n, effects):
        return [
            LoopTask(
                kind, paths, world.materials, effects, world.candidates, FOLDS, 0.0, s
            )
            for s in seeds(args.seed, stream, key, n)
        ]

    batch = []
    if design not in cache:
        batch += tasks(
            "threshold", STREAM_THRESHOLD, design.key, args.threshold_campaigns, {}
        )
    for label, effect, param, value in truths:
        k = TRUTHS.index((label, effect, param, value))
        stream = STREAM_NULL if effect is None else STREAM_POWER
        n = args.campaigns_for(design, label)
        batch += tasks(
            label, stream, (*design.key, k), n, truth_effects(effect, param, value)
        )
    t0 = time.perf_counter()
    results = run_tasks(batch, workers)
    wall = time.perf_counter() - t0
    by_kind: dict[str, list] = {"threshold": cache.get(design, [])}
    for r in results:
        by_kind.setdefault(r["kind"], []).append(r)
    cache[design] = by_kind["threshold"]
    thr_ok = [r for r in by_kind["threshold"] if r["failed"] is None]
    gains = np.array([r["best_gain"] for r in thr_ok], float)
    threshold = null_threshold(gains, QUANTILE) if gains.size else math.inf
    sigma = (
        float(np.median([r["baseline_cv_rmse"] for r in thr_ok]))
        if thr_ok
        else math.nan
    )
    summary = {"threshold": threshold, "B": len(thr_ok), "sigma": sigma, "cells": {}}
    for label, effect, _, _ in truths:
        cell = classify(by_kind.get(label, []), effect, threshold)
        n, correct, wrong, false = (cell[k] for k in ("n", "correct", "wrong", "false"))
        plain_c, plain_w = cell["plain_correct"], cell["plain_other"]
        a = sizes.get(label, 0.0)
        ratio = "0" if effect is None else f"{a / sigma:.2f}"
        summary["cells"][label] = cell

        def r_(k, n=n):
            return "—" if k is None else rate(k, n)

        line = (
            f"| {design.label} | {label} | {ratio} | {n} | {r_(correct)} | "
            f"{r_(wrong)} | {r_(false)} | {r_(plain_c)} | {r_(plain_w)} |"
        )
        rows.append(line)
        out(line)
    out(
        f"<!-- {design.label}: oracle threshold {threshold:+.1%} from B = "
        f"{len(thr_ok)} null campaigns; sigma {sigma:.2f} m/s; "
        f"{sum(r['failed'] is not None for r in results)} campaign(s) failed; "
        f"{len(batch)} campaigns in {wall:.0f} s -->"
    )
    spread = own_gains(by_kind, truths)
    if spread:
        out(f"<!-- {design.label}: the true law's own gain, {spread} -->")
    if args.out is not None:
        dump = args.out.with_suffix(".jsonl")
        with dump.open("a") as f:
            for r in results:
                f.write(json.dumps({"design": design.label, **r}) + "\n")
    return summary


def own_gains(by_kind: dict, truths) -> str:
    """Per effect cell, the true law's *own* held-out gain (median over the cell's
    campaigns) against the 95 % quantile of that law's gain on the threshold's null
    campaigns: how far the law itself stands out of the null, whichever candidate
    won the screen (the oracle threshold is on the best candidate's gain)."""
    nulls = [r for r in by_kind.get("threshold", []) if r["failed"] is None]
    parts = []
    for label, effect, _, _ in truths:
        rs = [r for r in by_kind.get(label, []) if r["failed"] is None]
        if effect is None or not rs or not nulls:
            continue
        own = np.median([r["gains"].get(effect, np.nan) for r in rs])
        q = np.quantile([r["gains"].get(effect, np.nan) for r in nulls], QUANTILE)
        parts.append(f"{label}: median {own:+.1%} (null q95 {q:+.1%})")
    return "; ".join(parts)


# ----------------------------------------------------------------- end to end
def e2e_task(job: tuple) -> dict:
    """One user's run: a one-path campaign with no effect, diagnosed with its own
    null (:func:`diagnose_surveyed`, null 19, no power, one worker)."""
    from fieldkit.diagnose.impacts import diagnose_impacts
    from fieldkit.diagnose.survey_loop import diagnose_surveyed, loop_table
    from fieldkit.errors import FieldkitError

    path, materials, seed, null_size = job
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    try:
        table, _, _ = loop_table([path], materials, {}, rng)
        seed_int = int(rng.integers(2**31))
        plain = diagnose_impacts(
            table, None, rng=np.random.default_rng(seed_int), folds=FOLDS
        ).recommended
        d = diagnose_surveyed(
            table,
            None,
            seed=seed_int,
            folds=FOLDS,
            null_size=null_size,
            power_size=0,
            workers=1,
        )
    except FieldkitError as exc:
        return {"failed": str(exc)}
    return {
        "failed": None,
        "recommended": d.recommended,
        "plain": plain,
        "threshold": (d.null or {}).get("threshold"),
        "impacts": len(table),
        "seconds": time.perf_counter() - t0,
    }


def spawn_map(fn, jobs: list, workers: int):
    """``fn`` over ``jobs`` through the Dask engine on ``workers`` local processes
    (1: this process), in order."""
    from fieldkit.parallel.engine import Engine, EngineSpec

    with Engine(EngineSpec(workers=0 if workers == 1 else workers)) as engine:
        yield from engine.map(fn, jobs, label="campaign")


def run_e2e(world, args, out, workers) -> dict:
    """The done-when's false-finding rate, end to end."""
    # the worker function must be importable by name in a spawned process
    sys.path.insert(0, str(HERE))
    from bench_campaign_power import e2e_task as task

    path = replace(world.path, target_scars=E2E_SCARS)
    jobs = [
        (path, world.materials, s, args.e2e_null)
        for s in seeds(args.seed, STREAM_E2E, (), args.e2e)
    ]
    out(
        f"\n### End to end: one path, {E2E_SCARS} scars, trees as boulder A, "
        "no effect; "
        f"each campaign diagnosed with diagnose_surveyed(null_size={args.e2e_null}, "
        "power_size=0, folds=5, workers=1)\n"
    )
    t0 = time.perf_counter()
    done, found, plain, failed, secs = 0, 0, 0, 0, []
    for r in spawn_map(task, jobs, workers):
        if r["failed"] is not None:
            failed += 1
        else:
            done += 1
            found += r["recommended"] is not None
            plain += r["plain"] is not None
            secs.append(r["seconds"])
        if (done + failed) % 20 == 0 and done + failed < len(jobs):
            out(
                f"- after {done} campaigns: false findings {rate(found, done)} "
                f"(plain rule {rate(plain, done)})"
            )
    wall = time.perf_counter() - t0
    med = float(np.median(secs)) if secs else math.nan
    out(
        f"- **false findings with its own null: {found} of {done} = "
        f"{rate(found, done)}**"
        f" (done-when <= 5 %); plain rule (no null): {plain} of {done} = "
        f"{rate(plain, done)}; {failed} campaign(s) could not be made; "
        f"{wall:.0f} s wall on {workers} worker(s), median {med:.0f} s per campaign "
        f"(null {args.e2e_null} campaigns each)"
    )
    return {"n": done, "found": found, "plain": plain, "failed": failed}


def time_diagnosis(world, args, out, workers) -> None:
    """One ``diagnose_surveyed`` of boulder A, as ``fieldkit diagnose`` runs it."""
    from fieldkit.diagnose.survey_loop import diagnose_surveyed

    load0 = os.getloadavg()
    t0 = time.perf_counter()
    d = diagnose_surveyed(
        world.table,
        None,
        seed=1,
        folds=FOLDS,
        null_size=args.time_null,
        power_size=args.time_power,
        workers=workers,
    )
    wall = time.perf_counter() - t0
    load1 = os.getloadavg()
    power = "; ".join(
        f"{k} {e['rate']:.0%}"
        for k, e in (d.power or {}).items()
        if e.get("rate") is not None
    )
    out(
        f"\n### One diagnosis of boulder A with the reduction in the loop\n\n"
        f"diagnose_surveyed(null_size={args.time_null}, power_size={args.time_power}, "
        f"folds={FOLDS}, workers={workers}): **{wall:.0f} s** wall; recommended "
        f"{d.recommended}; threshold {(d.null or {}).get('threshold')}; "
        f"power: {power}. "
        f"nproc {os.cpu_count()}, load average before {load0[0]:.2f} {load0[1]:.2f} "
        f"{load0[2]:.2f}, after {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}"
    )


# ------------------------------------------------------------------------- main
def designs(full: bool, paths: list[int], scars: list[int], trees: list[bool]) -> list:
    out = [Design(p, s, t) for p in paths for s in scars for t in trees]
    return sorted(out, key=lambda d: (d.cost, not d.trees))


def parse(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "--full",
        action="store_true",
        help="the measured run (make bench-diagnose): long",
    )
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=18)
    ap.add_argument(
        "--out",
        type=Path,
        default=None,
        help="also write the markdown here, a row at a time",
    )
    ap.add_argument("--paths", default=None, help="comma list (short 1,3; full 1,3,10)")
    ap.add_argument(
        "--scars", default=None, help="comma list (short 20,50; full 20,50,100)"
    )
    ap.add_argument(
        "--position-sigma",
        type=float,
        default=None,
        help="the campaigns' survey error in plan and height, m (default 0.5: "
        "handheld GNSS; 0.05: a total station)",
    )
    ap.add_argument(
        "--tree-share",
        type=float,
        default=None,
        help="share of flights a tree strike fixes in a 'trees' design (default: "
        "boulder A's 0.31; 0.95 nearly every flight, no launch angle assumed)",
    )
    ap.add_argument(
        "--trees",
        default=None,
        help="'a' (boulder A's), 'none' or 'a,none' (short a, full a,none)",
    )
    ap.add_argument(
        "--campaigns",
        type=int,
        default=None,
        help="campaigns per cell (short 3, full 40)",
    )
    ap.add_argument(
        "--threshold-campaigns",
        type=int,
        default=None,
        help="null campaigns B per design for the oracle threshold (short 19, full 39)",
    )
    ap.add_argument(
        "--target-campaigns",
        type=int,
        default=None,
        help="campaigns of the done-when's 10-path K = 7 cell (full 100)",
    )
    ap.add_argument(
        "--e2e",
        type=int,
        default=None,
        help="end-to-end campaigns (short 2, full 100; 0 skips)",
    )
    ap.add_argument("--e2e-null", type=int, default=19)
    ap.add_argument("--time-null", type=int, default=None, help="(short 19, full 99)")
    ap.add_argument("--time-power", type=int, default=None, help="(short 4, full 40)")
    ap.add_argument(
        "--size-rocks",
        type=int,
        default=None,
        help="rocks whose true impacts give A (short 10, full 60)",
    )
    ap.add_argument("--grid", action=argparse.BooleanOptionalAction, default=True)
    args = ap.parse_args(argv)
    full = args.full

    def pick(value, short, long):
        return value if value is not None else (long if full else short)

    def ints(text, default):
        return [int(v) for v in text.split(",")] if text else default

    args.paths = ints(args.paths, [1, 3, 10] if full else [1, 3])
    args.scars = ints(args.scars, [20, 50, 100] if full else [20, 50])
    trees = args.trees or ("a,none" if full else "a")
    args.trees = [t.strip() != "none" for t in trees.split(",")]
    args.campaigns = pick(args.campaigns, 3, 40)
    args.threshold_campaigns = pick(args.threshold_campaigns, 19, 39)
    args.target_campaigns = pick(args.target_campaigns, args.campaigns, 100)
    args.e2e = pick(args.e2e, 2, 100)
    args.time_null = pick(args.time_null, 19, 99)
    args.time_power = pick(args.time_power, 4, 40)
    args.size_rocks = pick(args.size_rocks, 10, 60)
    target = Design(10, 50, True)

    def campaigns_for(design: Design, label: str) -> int:
        if design == target and label == "eq. 7.1 K=7":
            return max(args.target_campaigns, args.campaigns)
        return args.campaigns

    args.campaigns_for = campaigns_for
    args.target = target
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse(sys.argv[1:] if argv is None else argv)
    out = Out(args.out)
    t_start = time.perf_counter()
    workers = args.workers
    out(
        "# Detection power on virtual campaigns "
        f"({'full' if args.full else 'short'} run)\n"
    )
    out(
        f"started {time.strftime('%Y-%m-%d %H:%M:%S', time.gmtime())} UTC; "
        f"{workers} worker(s); nproc {os.cpu_count()}; load average "
        + " ".join(f"{v:.2f}" for v in os.getloadavg())
    )
    world = boulder_a()
    if args.tree_share is not None:
        world = replace(world, tree_share=args.tree_share)
    if args.position_sigma is not None:
        world = replace(world, position_sigma_m=args.position_sigma)
    p = world.path
    out(
        f"\nBoulder A: {p.scars} scars, theta0 assumed {p.theta0_deg:g} deg, "
        "tree share "
        f"{p.tree_share:.1%}, GNSS error {GNSS_SIGMA_M:g} m; candidates "
        f"{', '.join(world.candidates)}; true world "
        + "; ".join(
            f"{m}: e_n {v['e_n']:.2f} ± {v['e_n_sd']:.2f}, e_t {v['e_t']:.2f} ± "
            f"{v['e_t_sd']:.2f}"
            for m, v in world.materials.items()
        )
    )
    sizes = {}
    for k, (label, effect, param, value) in enumerate(TRUTHS[1:], 1):
        sizes[label] = effect_size(
            world, truth_effects(effect, param, value), args.size_rocks, args.seed, k
        )
    out(
        "A [m/s] over the true impacts of "
        f"{args.size_rocks} rocks per effect: "
        + ", ".join(f"{k} {v:.3f}" for k, v in sizes.items())
    )
    if args.e2e > 0:
        run_e2e(world, args, out, workers)

    rows: list[str] = []
    summaries = {}
    cache: dict = {}
    all_designs = designs(args.full, args.paths, args.scars, args.trees)
    timed = False
    if args.grid:
        out(
            f"\n### Power table (oracle threshold: q = {QUANTILE} of B = "
            f"{args.threshold_campaigns} null campaigns per design; rates on other "
            "campaigns)\n"
        )
        out(HEAD)
        out(RULE)
        order = list(all_designs)
        if args.full and args.target in order:
            # the done-when cell first (with its none row: the threshold's check),
            # then the one timed diagnosis, then the grid from the cheapest design
            summaries[("target", args.target)] = run_design(
                world, args.target, TRUTHS[:2], args, out, sizes, rows, workers, cache
            )
            write_key_rows(args, summaries, all_designs)
            timed = True
            time_diagnosis(world, args, out, workers)
        for design in order:
            truths = TRUTHS[2:] if ("target", design) in summaries else TRUTHS
            summaries[design] = run_design(
                world, design, truths, args, out, sizes, rows, workers, cache
            )
            write_key_rows(args, summaries, all_designs)
        out("\n### Key rows (for the README)\n")
        for line in key_rows(summaries, all_designs):
            out(line)
    if not timed and args.time_null + args.time_power > 0:
        time_diagnosis(world, args, out, workers)
    out(f"\ntotal {time.perf_counter() - t_start:.0f} s")
    out.close()
    return 0


def key_rows(summaries, all_designs) -> list[str]:
    """The rows for the README: per design, false findings, eq. 7.1 at K = 7 and
    eq. 5.4 at b = 1.03 found (under the oracle threshold), with N."""
    lines = [
        "| paths × scars | trees | false finding | eq. 7.1 K=7 found "
        "| eq. 5.4 b=1.03 found |",
        "|---|---|---|---|---|",
    ]
    for design in all_designs:
        cells = {}
        for key in (("target", design), design):
            if key in summaries:
                cells.update(summaries[key]["cells"])
        if not cells:
            continue

        def get(label, what, cells=cells):
            c = cells.get(label)
            if c is None or c[what] is None:
                return "—"
            return f"{rate(c[what], c['n'])} (N {c['n']})"

        lines.append(
            f"| {design.paths} × {design.scars} | "
            f"{'as boulder A' if design.trees else 'none'}"
            f" | {get('none', 'false')} | {get('eq. 7.1 K=7', 'correct')} | "
            f"{get('eq. 5.4 b=1.03', 'correct')} |"
        )
    return lines


def write_key_rows(args, summaries, all_designs) -> None:
    """With ``--out``, the key rows so far beside it (``*.key.md``), so a run
    stopped early still leaves them."""
    if args.out is not None:
        path = args.out.with_suffix(".key.md")
        path.write_text("\n".join(key_rows(summaries, all_designs)) + "\n")


if __name__ == "__main__":
    raise SystemExit(main())
