"""Walk-through: the 3-D model calibrated and scored in plan on Tschamut 2014.

Issue 21, item 3. On the fixed split (tests/data/tschamut2014/calibration_split:
18 calibration runs, v033 = v034 counted once, so 17; 18 held-out runs):

1. calibrate ``examples/tschamut/model_3d.json``'s e_n, e_t, friction angle and
   roughness SD (:func:`fieldkit.fit.plan_fit.fit_plan`): every run simulated from
   its own release with its own block, objective the mean fair energy score of the
   deposits in plan, common random numbers ``default_rng([seed, run])``;
2. calibrate the 2-D model as the README's ``fieldkit fit --paths ... --deposits
   ... --dem ...`` does (:func:`fieldkit.fit.path_fit.fit_paths` on the runs'
   steepest-descent sections; 40 rocks, no bootstrap), its stops placed in plan
   (:func:`fieldkit.fit.plan_scores.section_to_plan`);
3. score on the held-out runs, with streams no fit uses
   (``default_rng([seed, HOLDOUT_STREAM, run])``): the 3-D calibrated model, the
   3-D start, the 2-D calibrated model, the climatology in plan (the calibration
   runs' release-to-deposit vectors) and the climatology of the run's own block
   (the most per-run information an empirical forecast has here) -- fair energy
   score, fair distance CRPS, fair lateral CRPS, 90 % distance coverage, mean
   distance error -- each comparison paired, with its SE over runs, over seeds 1,
   2, 3 (a fit per seed).

What the split can show at all (:mod:`fieldkit.fit.plan_power`): the
climatology's fair score is an unbiased estimate of the score of the distribution
its vectors come from, so a forecast beats it only by what it knows about each run.
Virtual campaigns drawn from each seed's calibrated model measure how often a
perfect forecast of that world beats the climatology by 2 paired SEs on 18
held-out runs; the climatology of the run's own block against the pooled one, by
repeated 5-fold over all 79 runs, measures what the block is worth from the data
alone -- and so the held-out runs a test would need.

Two assumptions, each shown moved in a last table (with two choices: the fit's
objective plus the distance CRPS, and three slope classes of material instead of
one meadow):

* **The tracked extent.** The observed deposits are the last samples of the
  laser-scan tracks, and six lie within 1.5 m of the scan's southern edge: rocks
  seen leaving. Every forecast is censored at its first exit from the scanned area
  as the observations are (:mod:`fieldkit.fit.tracked_extent`), taken as the DEM
  less metadata.json's ``padding_m`` (the proxy DEM was built from the scan's
  ground points and padded by 45 m; beyond, its ground is the trend plane falling
  at 22 degrees, so rocks there ran on to the grid's edge).
* **The release.** The model file drops each block 0.5 m onto the DEM (its
  provenance says why); at rest, a block on a cell flatter than its friction
  angle never moves (run v086's release, 12 degrees).

Where GRASS GIS and r.stone are present (``tools/r.stone/install.sh``; else one
line says why it was skipped), r.stone runs with the exported parameters of each
seed's calibrated model on the held-out runs, one source cell and as many stones
as held-out rocks per run (:mod:`fieldkit.export.rstone3d`; its random numbers are
seeded with the constant 1). r.stone writes no deposits, so only footprints in
plan are compared (:mod:`fieldkit.fit.footprint`: reach, passage distance, the
observed deposit's cell passed or missed), beside fieldkit's 3-D calibrated model
read the same way.

With ``--full``, also repeated 5-fold cross-validation over the 79 distinct runs
(2 repeats, stratified by block, seed 1): 3-D calibrated against the climatology.

Sizes (``--quick`` / default / ``--full``): 3-D fit 30 / 60 / 100 rocks per run
and 30 / 80 / 160 evaluations (Sobol screen 0 / 0 / 16 points); held-out 60 / 200 /
500 rocks per run; virtual campaigns 50 / 200 / 1000 per seed. Measured on one
core of an idle machine: about 30 s (no assumption table, no r.stone), 4.5 min
(r.stone's section 105 s of it, where GRASS is present; 2.5 min without) and
40 min (the assumption table at full size, r.stone 4.5 min, the k-fold's ten fits
10 min).

The seeds' fits, and the k-fold's, are independent units
(:mod:`fieldkit.fit.plan_sweep`): ``--workers N`` runs them on N local Dask
processes, ``--scheduler ADDRESS`` on a running cluster, with the same numbers.

Run:  python examples/calibrate_tschamut_3d.py [OUT_DIR] [--quick | --full]
      [--workers N | --scheduler ADDRESS]
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from fieldkit.fit import plan_fit
from fieldkit.fit.path_fit import fit_paths
from fieldkit.fit.path_runs import one_kernel_thread
from fieldkit.fit.path_sections import path_runs
from fieldkit.fit.plan_scores import (
    duplicate_runs,
    mean_direction,
    paired_comparison,
    repeated_kfold,
    score_runs,
    section_to_plan,
    unique_runs,
)
from fieldkit.fit.plan_sweep import PlanFitUnit, plan_fit_sweep
from fieldkit.fit.tracked_extent import (
    Extent,
    censor_chainage,
    censored_climatology,
    clip_model,
    exit_chainage,
)
from fieldkit.io.dem import read_dem
from fieldkit.io.path_observations import read_release_deposit
from fieldkit.model.model_file import read_model
from fieldkit.model.simulate import simulate
from fieldkit.parallel.engine import Engine, EngineSpec

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "tschamut2014"
SPLIT = DATA / "calibration_split"
MODEL_3D = ROOT / "examples" / "tschamut" / "model_3d.json"
MODEL_2D = ROOT / "examples" / "tschamut" / "model_base.json"
FREE = [
    f"materials.meadow.{k}" for k in ("e_n", "e_t", "friction_deg", "roughness_deg_sd")
]
SEEDS = (1, 2, 3)
SMALL = {"fit_rocks": 60, "evaluations": 80, "screen": 0, "holdout_rocks": 200,
         "campaigns": 200}  # fmt: skip
FULL = {"fit_rocks": 100, "evaluations": 160, "screen": 16, "holdout_rocks": 500,
        "campaigns": 1000}  # fmt: skip
#: --quick (the fast test suite's run): every section but the assumption table and
#: r.stone, on small ensembles -- the figures are noisier, the verdicts the same.
QUICK = {"fit_rocks": 30, "evaluations": 30, "screen": 0, "holdout_rocks": 60,
         "campaigns": 50}  # fmt: skip
SCORES = ("energy_fair_m", "distance_crps_fair_m", "lateral_crps_fair_m")
#: The release drop of the model file's seeder [m] (its provenance says why).
DROP_M = float(
    json.loads(MODEL_3D.read_text(encoding="utf-8"))["seeder"].get("height_m", 0.0)
)


def _xy(runs, what):
    return np.array([getattr(r, what) for r in runs])


def _dedupe(runs):
    rel, dep = _xy(runs, "release_xy"), _xy(runs, "deposit_xy")
    return [runs[i] for i in unique_runs(len(runs), duplicate_runs(rel, dep))]


def _plan3d(model, runs, rocks, seed):
    ens = plan_fit.plan_ensembles(
        model, runs, rocks, seed, stream=plan_fit.HOLDOUT_STREAM
    )
    return ens.deposits_xy, ens.exited_share


def _plan2d(model_2d, hold_obs, rocks, seed, extent):
    """The 2-D model's stops on each held-out run's section, in plan; with an
    extent, censored where the section leaves it (as the 3-D rocks are)."""
    runs = path_runs(
        hold_obs, read_dem(DATA / "terrain.asc"), model_2d, section="descent"
    )
    out, cut = [], 0
    with one_kernel_thread():
        for i, run in enumerate(runs):
            rng = np.random.default_rng([seed, plan_fit.HOLDOUT_STREAM, i])
            sx = run.observations["section_x_m"]
            sy = run.observations["section_y_m"]
            c = np.asarray(simulate(run.model, rocks, rng).runout_x_m, float)
            c = c - float(run.model.seeder.x_m)
            if extent is not None:
                c, was_cut = censor_chainage(c, exit_chainage(sx, sy, extent))
                cut += int(was_cut.sum())
            out.append(section_to_plan(sx, sy, c))
    return out, cut / (rocks * len(runs))


def _block_climatology(cal, hold, cal_rel, cal_dep, rel, extent):
    """The climatology of the held-out run's own block only (6 or 5 vectors): the
    most per-run information an empirical forecast has here."""
    g = np.array([r.group for r in cal])
    out = []
    for i, r in enumerate(hold):
        ens, _ = censored_climatology(cal_rel[g == r.group], cal_dep[g == r.group],
                              rel[[i]], extent)  # fmt: skip
        out.append(ens[0])
    return out


def tracked_extent() -> Extent:
    """The area the laser scan tracked, as the terrain proxy records it: the DEM
    less its ``padding_m`` on every side (metadata.json; the proxy was built from
    the scan's ground points and padded by that much)."""
    meta = json.loads((DATA / "metadata.json").read_text(encoding="utf-8"))
    t = meta["terrain_proxy"]
    pad, cell = t["padding_m"], t["cellsize_m"]
    x0, y0 = t["xllcorner_m"], t["yllcorner_m"]
    return Extent(x0 + pad, y0 + pad, x0 + t["ncols"] * cell - pad,
                  y0 + t["nrows"] * cell - pad)  # fmt: skip


def _runs():
    cal = _dedupe(
        plan_fit.read_plan_runs(
            SPLIT / "calibration_release_points.csv",
            SPLIT / "calibration_observed_deposition.csv",
        )
    )
    hold = plan_fit.read_plan_runs(
        SPLIT / "holdout_release_points.csv", SPLIT / "holdout_observed_deposition.csv"
    )
    return cal, hold


def _model3d(extent, height):
    """The 3-D start model with the release drop ``height`` [m], on the DEM
    clipped to ``extent`` (None: the whole DEM); and the extent all forecasts are
    censored on (the clipped surface's)."""
    base = read_model(MODEL_3D, terrain=True)
    base = replace(base, seeder=replace(base.seeder, height_m=height))
    if extent is None:
        return base, None
    return clip_model(base, extent)


def slope_classes(model):
    """``model`` with three materials by the DEM's slope (an alternative material
    grouping to the one meadow): ``flat`` below 12 deg (the deposition zone),
    ``slope`` 12-35 deg, ``cliff`` above 35 deg (the release band), each starting
    from the meadow's values; and the parameters a fit frees: the shared e_n, e_t
    and roughness of the slope class, and each class's friction angle."""
    t = model.terrain
    gy, gx = np.gradient(np.asarray(t.z, float), t.cell_m, t.cell_m)
    slope = np.degrees(np.arctan(np.hypot(gx, gy)))
    index = np.digitize(np.nan_to_num(slope, nan=20.0), SLOPE_CLASS_EDGES_DEG)
    meadow = model.materials["meadow"]
    materials = {n: replace(meadow, name=n) for n in SLOPE_CLASSES}
    free = [f"materials.slope.{k}" for k in ("e_n", "e_t", "roughness_deg_sd")]
    free += [f"materials.{n}.friction_deg" for n in SLOPE_CLASSES]
    index = index.astype(model.material_index.dtype)
    grouped = replace(model, materials=materials, material_index=index)
    return grouped, free


#: The slope classes of :func:`slope_classes` (names by rising slope) and their
#: edges [deg].
SLOPE_CLASSES = ("flat", "slope", "cliff")
SLOPE_CLASS_EDGES_DEG = (12.0, 35.0)


def fixed_split(settings: dict, extent: Extent | None, height: float,
                verbose: bool = True, fits: list | None = None, *,
                distance_weight: float = 0.0,
                grouping=None) -> dict:  # fmt: skip
    """The fixed split over seeds 1-3: fits, held-out scores, paired comparisons.
    ``extent``: censor every forecast at the tracked extent (None: not);
    ``height``: the release drop [m]; ``fits``: a list the 3-D calibrated model of
    each seed is appended to; ``distance_weight``: the fit's weight of the
    distance CRPS beside the energy score; ``grouping``: a function giving another
    material grouping and its free parameters (:func:`slope_classes`)."""
    say = print if verbose else (lambda *a, **k: None)
    base3d, censor = _model3d(extent, height)
    free = FREE
    if grouping is not None:
        base3d, free = grouping(base3d)
    base2d = read_model(MODEL_2D)
    cal, hold = _runs()
    cal_obs = read_release_deposit(
        SPLIT / "calibration_release_points.csv",
        SPLIT / "calibration_observed_deposition.csv",
    )
    hold_obs = read_release_deposit(
        SPLIT / "holdout_release_points.csv", SPLIT / "holdout_observed_deposition.csv"
    )
    cal2d = path_runs(
        cal_obs, read_dem(DATA / "terrain.asc"), base2d, section="descent"
    )
    cal_rel, cal_dep = _xy(cal, "release_xy"), _xy(cal, "deposit_xy")
    rel, dep = _xy(hold, "release_xy"), _xy(hold, "deposit_xy")
    u = mean_direction(cal_rel, cal_dep)
    say(
        f"fixed split: {len(cal)} calibration runs (v033 = v034 counted once), "
        f"{len(hold)} held-out runs; seeds {', '.join(map(str, SEEDS))}"
    )
    say(
        f"sizes: 3-D fit {settings['fit_rocks']} rocks per run, "
        f"{settings['evaluations']} evaluations, Sobol screen {settings['screen']}; "
        f"2-D fit 40 rocks, no bootstrap; held-out {settings['holdout_rocks']} "
        "rocks per run on streams no fit uses"
    )
    say(f"release: a drop of {height:g} m onto the DEM (assumed; model seeder)")
    if censor is None:
        say("tracked extent: none -- every forecast scored where its rocks stop")
    else:
        say(
            f"tracked extent {censor.describe()} (the scan's, assumed: "
            "metadata.json's DEM less its padding, to the cell centres inside): "
            "every forecast censored at its first exit, as the observed last "
            "samples are"
        )
    # the sensitivity cases (verbose False) need only the 3-D calibrated model
    names = ("3-D calibrated", "3-D start", "2-D calibrated") if verbose else (
        "3-D calibrated",)  # fmt: skip
    forecasts: dict[str, list] = {name: [] for name in names}
    exited = {name: [] for name in forecasts}
    # the three seeds' 3-D fits (and their held-out ensembles) are independent
    # units: through the Dask engine (--workers / --scheduler), same numbers
    units = [
        PlanFitUnit(
            f"3-D fit, seed {seed}", tuple(cal), tuple(hold), tuple(free), seed,
            rocks=settings["fit_rocks"],
            max_evaluations=settings["evaluations"] * (2 if grouping else 1),
            screen=settings["screen"], distance_weight=distance_weight,
            holdout_rocks=settings["holdout_rocks"],
        )
        for seed in SEEDS
    ]  # fmt: skip
    swept = plan_fit_sweep(base3d, units, ENGINE)
    for seed, fit in zip(SEEDS, swept, strict=True):
        model = fit.model(base3d)
        if fits is not None:
            fits.append(model)
        say(f"seed {seed}: 3-D fit in {fit.seconds:.1f} s")
        for line in fit.lines:
            say("  " + line)
        rocks = settings["holdout_rocks"]
        ens, share = fit.holdout_xy, fit.holdout_exited_share
        forecasts["3-D calibrated"].append(score_runs(ens, rel, dep, u))
        exited["3-D calibrated"].append(share)
        if not verbose:
            continue
        ens, share = _plan3d(base3d, hold, rocks, seed)
        forecasts["3-D start"].append(score_runs(ens, rel, dep, u))
        exited["3-D start"].append(share)
        tic = time.perf_counter()
        fit2d = fit_paths(
            cal2d,
            base2d,
            [f"materials.meadow.{k}" for k in ("e_n", "e_t", "friction_deg")],
            rocks=40,
            seed=seed,
            bootstrap=0,
            profile_points=0,
            profile_seeds=0,
            slice_points=0,
        )
        say(
            f"seed {seed}: 2-D fit in {time.perf_counter() - tic:.1f} s: "
            + ", ".join(
                f"{n.split('.')[-1]} {v:.3g}"
                for n, v in zip(fit2d.names, fit2d.values, strict=True)
            )
        )
        ens2d, share = _plan2d(fit2d.model, hold_obs, rocks, seed, censor)
        forecasts["2-D calibrated"].append(score_runs(ens2d, rel, dep, u))
        exited["2-D calibrated"].append(share)
    ens_c, clim_cut = censored_climatology(cal_rel, cal_dep, rel, censor)
    clim = score_runs(ens_c, rel, dep, u)
    block = score_runs(
        _block_climatology(cal, hold, cal_rel, cal_dep, rel, censor), rel, dep, u
    )
    exited["climatology"] = [clim_cut]
    say()
    say(
        f"held-out scores, mean over {len(hold)} runs and seeds 1-3 (lower is "
        "better; fair scores; 'left': share of members censored at the DEM's "
        "or the tracked extent's edge)"
    )
    say(
        f"{'forecast':<22}{'energy':>8}{'dist CRPS':>11}{'lat CRPS':>10}"
        f"{'cov90':>7}{'mean dist err':>15}{'left':>8}"
    )
    summary: dict = {
        "release_drop_m": height,
        "tracked_extent": None if censor is None else list(vars(censor).values()),
        "forecasts": {},
        "comparisons": [],
    }
    rows = {**forecasts, "climatology": [clim], "climatology of the block": [block]}
    for name, per_seed in rows.items():
        s = [p.summary() for p in per_seed]
        mean = {k: float(np.mean([x[k] for x in s])) for k in s[0]}
        ex = exited.get(name)
        say(
            f"{name:<22}{mean['energy_fair_m']:8.2f}"
            f"{mean['distance_crps_fair_m']:11.2f}"
            f"{mean['lateral_crps_fair_m']:10.2f}"
            f"{100 * mean['distance_coverage_90']:6.0f}%"
            f"{mean['distance_bias_m']:+14.1f} m"
            + (f"{100 * np.mean(ex):7.1f}%" if ex else "       -")
        )
        summary["forecasts"][name] = mean | (
            {"left_share": float(np.mean(ex))} if ex else {}
        )
    say(
        f"(observed mean distance {mean['distance_observed_mean_m']:.1f} m; "
        "mean dist err = predicted - observed mean distance)"
    )
    say()
    say("paired comparisons (A - B, SE over runs; negative: A better)")
    pairs = [("3-D calibrated", o) for o in
             ("climatology", "2-D calibrated", "3-D start") if o in rows]  # fmt: skip
    pairs.append(("climatology of the block", "climatology"))
    for a_name, other in pairs:
        for score in SCORES:
            a = np.array([getattr(p, score) for p in rows[a_name]])
            b = np.array([getattr(p, score) for p in rows[other]])
            if b.shape[0] == 1:
                b = b[0]
            if a.shape[0] == 1:
                a = a[0]
            c = paired_comparison(a, b, score, a_name, other,
                                  seeds=SEEDS if a.ndim == 2 else [0])  # fmt: skip
            say("\n".join(c.lines()))
            summary["comparisons"].append(c.to_dict())
    return summary


def sensitivity(settings: dict, main: dict) -> list[dict]:
    """The fixed split's 3-D calibrated model against the climatology as the
    assumptions and choices move: the tracked extent (on / off), the release drop,
    the fit's objective (energy score alone, or plus the distance CRPS) and the
    material grouping (one meadow, or three slope classes)."""
    cases = [(True, 0.0, "energy", "meadow"), (False, DROP_M, "energy", "meadow"),
             (False, 0.0, "energy", "meadow"), (True, 1.0, "energy", "meadow"),
             (True, DROP_M, "+ distance", "meadow"),
             (True, DROP_M, "energy", "3 slope classes")]  # fmt: skip
    print()
    print(
        "how the verdict moves with the assumptions (3-D calibrated - climatology, "
        "paired SE over runs, seeds 1-3)"
    )
    print(
        f"{'extent':<7}{'drop':>5}{'objective':>11}{'materials':>16}"
        f"{'3-D energy':>11}{'clim':>7}{'difference':>16}{'3-D dist':>9}{'clim':>6}"
        f"{'difference':>16}"
    )
    out = []
    for on, height, objective, materials in [
        (True, DROP_M, "energy", "meadow"),
        *cases,
    ]:
        s = (
            main
            if (on, height, objective, materials)
            == (True, DROP_M, "energy", "meadow")
            else fixed_split(
                settings, tracked_extent() if on else None, height, verbose=False,
                distance_weight=1.0 if objective == "+ distance" else 0.0,
                grouping=slope_classes if materials != "meadow" else None,
            )
        )  # fmt: skip
        c = {(x["a"], x["b"], x["score"]): x for x in s["comparisons"]}
        e = c[("3-D calibrated", "climatology", "energy_fair_m")]
        d = c[("3-D calibrated", "climatology", "distance_crps_fair_m")]
        print(
            f"{'on' if on else 'off':<7}{height:4.1f}m{objective:>11}{materials:>16}"
            f"{e['mean_a']:11.2f}{e['mean_b']:7.2f}"
            f"{e['mean_difference']:+9.2f} +- {e['se']:4.2f}"
            f"{d['mean_a']:9.2f}{d['mean_b']:6.2f}"
            f"{d['mean_difference']:+9.2f} +- {d['se']:4.2f}"
        )
        out.append({"tracked_extent": on, "release_drop_m": height,
                    "objective": objective, "materials": materials,
                    "energy": e, "distance_crps": d})  # fmt: skip
    return out


def attainable(settings: dict, fits: list) -> dict:
    """What the fixed split can show at all (:mod:`fieldkit.fit.plan_power`):
    virtual campaigns from each seed's calibrated model (a perfect forecast of
    that world against each campaign's climatology), and the climatology of the
    run's own block against the pooled one by repeated 5-fold over all 79 runs
    (the most the block can be worth to any forecast, from the data alone)."""
    from fieldkit.fit.plan_power import group_climatology_skill, virtual_campaigns

    _, censor = _model3d(tracked_extent(), DROP_M)
    cal, hold = _runs()
    print()
    print(
        "what the fixed split can show (the climatology's fair score is unbiased: a "
        "forecast beats it only by what it knows of each run)"
    )
    out: dict = {"virtual_campaigns": []}
    for seed, model in zip(SEEDS, fits, strict=True):
        v = virtual_campaigns(model, cal, hold, campaigns=settings["campaigns"],
                              holdout_rocks=settings["holdout_rocks"], seed=seed,
                              extent=censor)  # fmt: skip
        lines = v.lines()
        print(f"seed {seed}: " + lines[0])
        print("\n".join(lines[1:-2]))
        out["virtual_campaigns"].append(v.to_dict())
    runs = _dedupe(
        plan_fit.read_plan_runs(
            DATA / "release_points.csv", DATA / "observed_deposition.csv"
        )
    )
    g = group_climatology_skill(
        _xy(runs, "release_xy"), _xy(runs, "deposit_xy"), [r.group for r in runs],
        extent=censor, split_runs=len(hold), label="block",
    )  # fmt: skip
    print("\n".join(g.lines()))
    out["block_climatology"] = g.to_dict()
    return out


#: r.stone's own default lateral spread of the launch angle [deg] (main.c), run
#: beside the exported 0 to show what the spread no one calibrated does.
RSTONE_DEFAULT_ANGLE = 10


def rstone_comparison(settings: dict, fits: list) -> dict:
    """r.stone with the exported parameters of each seed's 3-D calibrated model on
    the held-out runs, beside fieldkit's 3-D calibrated model read the same way.

    r.stone writes no deposits, only rasters: each run's footprint in plan
    (:mod:`fieldkit.fit.footprint`) is read from r.stone's ``counter`` and from
    fieldkit's ``passing_count`` (the held-out streams' rocks, with paths), both
    with the held-out ensemble's size, both censored at the tracked extent: fieldkit
    runs on the clipped DEM; r.stone on the whole DEM (on the clipped one a release
    cell at the extent's edge would have nodata among the 8 neighbours its launch
    direction reads), its counter set to 0 outside the extent. r.stone runs twice:
    as exported (launch angle range 0) and with its own default range
    (:data:`RSTONE_DEFAULT_ANGLE`)."""
    from fieldkit.export.rstone3d import (
        rstone_inputs3d,
        rstone_missing,
        run_rstone_batch,
        source_cell,
    )
    from fieldkit.fit.footprint import footprint
    from fieldkit.model.results3d import rasters
    from fieldkit.model.simulate3d import simulate3d

    print()
    missing = rstone_missing()
    if missing:
        print(f"r.stone comparison skipped: {missing}")
        return {"skipped": missing}
    _, hold = _runs()
    whole, _ = _model3d(None, DROP_M)
    _, censor = _model3d(tracked_extent(), DROP_M)
    rocks = settings["holdout_rocks"]
    keys = ("reach_m", "passage_mean_m", "miss_m", "observed_m", "deposit_passed")
    spread = f"r.stone, ang {RSTONE_DEFAULT_ANGLE}"
    names = ("r.stone", spread, "3-D calibrated")
    per = {n: {k: [] for k in keys} for n in names}
    tic, notes, short = time.perf_counter(), {}, 0

    def outside(x, y):
        mx, my = np.meshgrid(x, y)
        return ~censor.contains(np.column_stack([mx.ravel(), my.ravel()]))

    for seed, model in zip(SEEDS, fits, strict=True):
        exported = replace(model, terrain=whole.terrain,
                           material_index=whole.material_index)  # fmt: skip
        inputs = rstone_inputs3d(exported)
        notes[seed] = inputs.notes
        g = inputs.grid
        cells = {r.run_id: source_cell(inputs, *r.release_xy) for r in hold}
        counters = {
            "r.stone": run_rstone_batch(inputs, cells, rocks),
            spread: run_rstone_batch(
                replace(inputs, options=inputs.options
                        | {"ang_stoch_range": RSTONE_DEFAULT_ANGLE}),
                cells, rocks,
            ),
        }  # fmt: skip
        short += sum(int(c[cells[r.run_id]] < rocks)
                     for grids in counters.values()
                     for r, c in ((r, grids[r.run_id]) for r in hold))  # fmt: skip
        t = model.terrain
        tx = t.x0_m + t.cell_m * (np.arange(t.shape[1]) + 0.5)
        ty = t.y0_m + t.cell_m * (np.arange(t.shape[0]) + 0.5)
        off_r, off_f = outside(g.x_m, g.y_m), outside(tx, ty)
        rows = {n: [] for n in names}
        with one_kernel_thread():
            for i, run in enumerate(hold):
                for name, grids in counters.items():
                    counter = grids[run.run_id].copy()
                    counter.ravel()[off_r] = 0.0
                    rows[name].append(
                        footprint(counter, g.x_m, g.y_m, run.release_xy, run.deposit_xy)
                    )
                res = simulate3d(
                    plan_fit.run_model(model, run),
                    rocks,
                    np.random.default_rng([seed, plan_fit.HOLDOUT_STREAM, i]),
                )
                count = rasters(res, t)["passing_count"].astype(float)
                count.ravel()[off_f] = 0.0
                rows["3-D calibrated"].append(
                    footprint(count, tx, ty, run.release_xy, run.deposit_xy)
                )
        for name, fps in rows.items():
            for k in keys:
                per[name][k].append([float(getattr(f, k)) for f in fps])
    arrays = {n: {k: np.array(v) for k, v in d.items()} for n, d in per.items()}
    n_runs = len(SEEDS) * len(hold) * 2
    print(
        f"r.stone (GRASS) with the exported parameters on the {len(hold)} held-out "
        f"runs, seeds 1-3 (each seed's calibrated model; {rocks} stones per run from "
        f"its release cell; {time.perf_counter() - tic:.0f} s with fieldkit's "
        "paths), beside fieldkit's 3-D calibrated model read the same way"
    )
    first = notes[SEEDS[0]]
    for line in first:
        if all(line in notes[s] for s in SEEDS):
            print(f"  {line}")
    for seed in SEEDS:
        for line in notes[seed]:
            if not all(line in notes[s] for s in SEEDS):
                print(f"  seed {seed}: {line}")
    print(
        f"  '{spread}': the same files with r.stone's default launch-angle range "
        f"{RSTONE_DEFAULT_ANGLE} (a lateral spread nobody calibrated)"
    )
    print(
        f"  stones traced: {n_runs - short} of {n_runs} r.stone runs count all "
        f"{rocks} in their release cell (r.stone's counter there)"
    )
    print(
        "  compared: each run's footprint in plan, censored at the tracked extent -- "
        "reach (farthest passed cell from the release), passage (count-weighted "
        "mean distance of the passed cells), whether the observed deposit's cell "
        "was passed and else its distance to the nearest passed cell (miss)"
    )
    print(
        "  not compared: deposit energy score, distance CRPS, 90 % coverage -- "
        "r.stone writes no deposits, only counter, maxvel and maxdz rasters"
    )
    print(
        f"{'forecast':<18}{'reach':>8}{'reach-obs':>11}{'obs<=reach':>12}"
        f"{'passage':>9}{'dep passed':>12}{'miss':>7}"
    )
    out: dict = {
        "stones_per_run": rocks,
        "notes": {str(k): list(v) for k, v in notes.items()},
        "runs_short_of_stones": short,
        "forecasts": {},
        "comparisons": [],
    }
    observed = arrays["r.stone"]["observed_m"]
    for name, a in arrays.items():
        reach = a["reach_m"]
        row = {
            "reach_m": float(reach.mean()),
            "reach_minus_observed_m": float((reach - observed).mean()),
            "observed_within_reach": float((observed <= reach).mean()),
            "passage_mean_m": float(a["passage_mean_m"].mean()),
            "deposit_cell_passed": float(a["deposit_passed"].mean()),
            "miss_m": float(a["miss_m"].mean()),
        }
        out["forecasts"][name] = row
        print(
            f"{name:<18}{row['reach_m']:7.1f}m{row['reach_minus_observed_m']:+10.1f}m"
            f"{100 * row['observed_within_reach']:11.0f}%"
            f"{row['passage_mean_m']:8.1f}m{100 * row['deposit_cell_passed']:11.0f}%"
            f"{row['miss_m']:6.1f}m"
        )
    print(
        f"(observed mean distance {observed.mean():.1f} m over the held-out runs; "
        "reach-obs and obs<=reach over runs and seeds)"
    )
    print("paired over runs, A - 3-D calibrated (SE over runs, seeds 1-3):")
    for name in names[:2]:
        parts = []
        for k in ("reach_m", "passage_mean_m", "miss_m"):
            c = paired_comparison(arrays[name][k], arrays["3-D calibrated"][k], k,
                                  name, "3-D calibrated", seeds=SEEDS)  # fmt: skip
            parts.append(f"{k.removesuffix('_m')} {c.mean_difference:+.1f} +- "
                         f"{c.se:.1f} m")  # fmt: skip
            out["comparisons"].append(c.to_dict())
        print(f"  {name:<16}" + ", ".join(parts))
    return out


def kfold(settings: dict, repeats: int = 2, k: int = 5, seed: int = 1) -> dict:
    base3d, censor = _model3d(tracked_extent(), DROP_M)
    runs = _dedupe(
        plan_fit.read_plan_runs(
            DATA / "release_points.csv", DATA / "observed_deposition.csv"
        )
    )
    rel, dep = _xy(runs, "release_xy"), _xy(runs, "deposit_xy")
    folds = repeated_kfold(
        len(runs), k=k, repeats=repeats, seed=21, groups=[r.group for r in runs]
    )
    per_run = {n: np.zeros((repeats, len(runs), 2)) for n in ("3-D", "clim")}
    tic = time.perf_counter()
    units = [
        PlanFitUnit(
            f"fold {f.fold} of repeat {f.repeat}",
            tuple(runs[i] for i in f.calibration), tuple(runs[i] for i in f.holdout),
            tuple(FREE), seed, rocks=settings["fit_rocks"],
            max_evaluations=settings["evaluations"],
            holdout_rocks=settings["holdout_rocks"],
        )
        for f in folds
    ]  # fmt: skip
    for f, fit in zip(folds, plan_fit_sweep(base3d, units, ENGINE), strict=True):
        u = mean_direction(rel[f.calibration], dep[f.calibration])
        ens = fit.holdout_xy
        for name, e in (
            ("3-D", ens),
            (
                "clim",
                censored_climatology(
                    rel[f.calibration], dep[f.calibration], rel[f.holdout], censor
                )[0],
            ),
        ):
            s = score_runs(e, rel[f.holdout], dep[f.holdout], u)
            per_run[name][f.repeat, f.holdout] = np.column_stack(
                [s.energy_fair_m, s.distance_crps_fair_m]
            )
    print()
    print(
        f"repeated {k}-fold over the {len(runs)} distinct runs ({repeats} repeats, "
        f"by block, seed {seed}; {time.perf_counter() - tic:.0f} s; the 'seed' lines "
        "below are the repeats)"
    )
    out = []
    for j, score in enumerate(("energy_fair_m", "distance_crps_fair_m")):
        c = paired_comparison(
            per_run["3-D"][:, :, j],
            per_run["clim"][:, :, j],
            score,
            "3-D calibrated",
            "climatology",
            seeds=list(range(repeats)),
        )
        print("\n".join(c.lines()))
        out.append(c.to_dict())
    return {"comparisons": out}


#: Where the fits run (main sets it from --workers N / --scheduler ADDRESS).
ENGINE = Engine(EngineSpec(workers=0))


def _engine_options(argv: list[str]) -> tuple[EngineSpec, list[str]]:
    """``--workers N`` (local Dask processes) / ``--scheduler ADDRESS`` out of argv;
    default: this process."""
    spec, rest, it = EngineSpec(workers=0), [], iter(argv)
    for a in it:
        if a == "--workers":
            spec = EngineSpec(workers=int(next(it)))
        elif a == "--scheduler":
            spec = EngineSpec(scheduler=next(it))
        else:
            rest.append(a)
    return spec.check(), rest


def main(argv: list[str]) -> None:
    global ENGINE
    spec, argv = _engine_options(argv)
    ENGINE = Engine(spec, notify=print)
    try:
        _main(argv)
    finally:
        ENGINE.close()


def _main(argv: list[str]) -> None:
    full = "--full" in argv
    quick = "--quick" in argv
    args = [a for a in argv if a not in ("--full", "--quick")]
    out = Path(args[0]) if args else Path("out") / "calibrate_tschamut_3d"
    settings = FULL if full else QUICK if quick else SMALL
    if quick:
        print(
            "--quick: small ensembles and searches; no assumption table, no r.stone "
            "(run without --quick for them)"
        )
    fits: list = []
    main_split = fixed_split(settings, tracked_extent(), DROP_M, fits=fits)
    summary = {
        "settings": settings,
        "fixed_split": main_split,
        "attainable": attainable(settings, fits),
    }
    if not quick:
        summary["sensitivity"] = sensitivity(settings, main_split)
        summary["rstone"] = rstone_comparison(settings, fits)
    if full:
        summary["kfold"] = kfold(settings)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "calibrate_tschamut_3d.json"
    path.write_text(json.dumps(summary, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
