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
   3-D start, the 2-D calibrated model and the climatology in plan (the calibration
   runs' release-to-deposit vectors) -- fair energy score, fair distance CRPS,
   fair lateral CRPS, 90 % distance coverage, mean distance error -- each
   comparison paired, with its SE over runs, over seeds 1, 2, 3 (a fit per seed).

With ``--full``, also repeated 5-fold cross-validation over the 79 distinct runs
(2 repeats, stratified by block, seed 1): 3-D calibrated against the climatology.

Sizes (default / ``--full``): 3-D fit 60 / 100 rocks per run and 80 / 160
evaluations (Sobol screen 0 / 16 points); held-out 200 / 500 rocks per run; 25 s /
7 min measured (the k-fold's ten fits 6 min of it).

Run:  python examples/calibrate_tschamut_3d.py [OUT_DIR] [--full]
"""

from __future__ import annotations

import json
import sys
import time
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
    plan_climatology,
    repeated_kfold,
    score_runs,
    section_to_plan,
    unique_runs,
)
from fieldkit.io.dem import read_dem
from fieldkit.io.path_observations import read_release_deposit
from fieldkit.model.model_file import read_model
from fieldkit.model.simulate import simulate

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "tschamut2014"
SPLIT = DATA / "calibration_split"
MODEL_3D = ROOT / "examples" / "tschamut" / "model_3d.json"
MODEL_2D = ROOT / "examples" / "tschamut" / "model_base.json"
FREE = [
    f"materials.meadow.{k}" for k in ("e_n", "e_t", "friction_deg", "roughness_deg_sd")
]
SEEDS = (1, 2, 3)
SMALL = {"fit_rocks": 60, "evaluations": 80, "screen": 0, "holdout_rocks": 200}
FULL = {"fit_rocks": 100, "evaluations": 160, "screen": 16, "holdout_rocks": 500}
SCORES = ("energy_fair_m", "distance_crps_fair_m", "lateral_crps_fair_m")


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


def _plan2d(model_2d, hold_obs, rocks, seed):
    runs = path_runs(
        hold_obs, read_dem(DATA / "terrain.asc"), model_2d, section="descent"
    )
    out = []
    with one_kernel_thread():
        for i, run in enumerate(runs):
            rng = np.random.default_rng([seed, plan_fit.HOLDOUT_STREAM, i])
            stops = np.asarray(simulate(run.model, rocks, rng).runout_x_m, float)
            out.append(
                section_to_plan(
                    run.observations["section_x_m"],
                    run.observations["section_y_m"],
                    stops - float(run.model.seeder.x_m),
                )
            )
    return out


def fixed_split(settings: dict) -> dict:
    base3d = read_model(MODEL_3D, terrain=True)
    base2d = read_model(MODEL_2D)
    cal = _dedupe(
        plan_fit.read_plan_runs(
            SPLIT / "calibration_release_points.csv",
            SPLIT / "calibration_observed_deposition.csv",
        )
    )
    hold = plan_fit.read_plan_runs(
        SPLIT / "holdout_release_points.csv", SPLIT / "holdout_observed_deposition.csv"
    )
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
    print(
        f"fixed split: {len(cal)} calibration runs (v033 = v034 counted once), "
        f"{len(hold)} held-out runs; seeds {', '.join(map(str, SEEDS))}"
    )
    print(
        f"sizes: 3-D fit {settings['fit_rocks']} rocks per run, "
        f"{settings['evaluations']} evaluations, Sobol screen {settings['screen']}; "
        f"2-D fit 40 rocks, no bootstrap; held-out {settings['holdout_rocks']} "
        "rocks per run on streams no fit uses"
    )
    forecasts: dict[str, list] = {
        "3-D calibrated": [],
        "3-D start": [],
        "2-D calibrated": [],
    }
    exited = {"3-D calibrated": [], "3-D start": []}
    for seed in SEEDS:
        tic = time.perf_counter()
        fit = plan_fit.fit_plan(
            cal,
            base3d,
            FREE,
            rocks=settings["fit_rocks"],
            seed=seed,
            max_evaluations=settings["evaluations"],
            screen=settings["screen"],
        )
        print(f"seed {seed}: 3-D fit in {time.perf_counter() - tic:.1f} s")
        for line in fit.lines():
            print("  " + line)
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
        print(
            f"seed {seed}: 2-D fit in {time.perf_counter() - tic:.1f} s: "
            + ", ".join(
                f"{n.split('.')[-1]} {v:.3g}"
                for n, v in zip(fit2d.names, fit2d.values, strict=True)
            )
        )
        rocks = settings["holdout_rocks"]
        for name, model in (("3-D calibrated", fit.model), ("3-D start", base3d)):
            ens, share = _plan3d(model, hold, rocks, seed)
            forecasts[name].append(score_runs(ens, rel, dep, u))
            exited[name].append(share)
        ens2d = _plan2d(fit2d.model, hold_obs, rocks, seed)
        forecasts["2-D calibrated"].append(score_runs(ens2d, rel, dep, u))
    clim = score_runs(plan_climatology(cal_rel, cal_dep, rel), rel, dep, u)
    print()
    print(
        f"held-out scores, mean over {len(hold)} runs and seeds 1-3 (lower is "
        "better; fair scores)"
    )
    print(
        f"{'forecast':<16}{'energy':>9}{'dist CRPS':>11}{'lat CRPS':>10}"
        f"{'cov90':>7}{'mean dist err':>15}{'exited':>8}"
    )
    summary: dict = {"forecasts": {}, "comparisons": []}
    rows = {**forecasts, "climatology": [clim]}
    for name, per_seed in rows.items():
        s = [p.summary() for p in per_seed]
        mean = {k: float(np.mean([x[k] for x in s])) for k in s[0]}
        ex = exited.get(name)
        print(
            f"{name:<16}{mean['energy_fair_m']:9.2f}"
            f"{mean['distance_crps_fair_m']:11.2f}"
            f"{mean['lateral_crps_fair_m']:10.2f}"
            f"{100 * mean['distance_coverage_90']:6.0f}%"
            f"{mean['distance_bias_m']:+14.1f} m"
            + (f"{100 * np.mean(ex):7.1f}%" if ex else "       -")
        )
        summary["forecasts"][name] = mean | (
            {"exited_share": float(np.mean(ex))} if ex else {}
        )
    print(
        f"(observed mean distance {mean['distance_observed_mean_m']:.1f} m; "
        "mean dist err = predicted - observed mean distance)"
    )
    print()
    print("paired comparisons (A - B, SE over runs; negative: A better)")
    a_scores = forecasts["3-D calibrated"]
    for other in ("climatology", "2-D calibrated", "3-D start"):
        for score in SCORES:
            a = np.array([getattr(p, score) for p in a_scores])
            b = (
                getattr(clim, score)
                if other == "climatology"
                else np.array([getattr(p, score) for p in rows[other]])
            )
            c = paired_comparison(a, b, score, "3-D calibrated", other, seeds=SEEDS)
            print("\n".join(c.lines()))
            summary["comparisons"].append(c.to_dict())
    return summary


def kfold(settings: dict, repeats: int = 2, k: int = 5, seed: int = 1) -> dict:
    base3d = read_model(MODEL_3D, terrain=True)
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
    for f in folds:
        cal = [runs[i] for i in f.calibration]
        hold = [runs[i] for i in f.holdout]
        u = mean_direction(rel[f.calibration], dep[f.calibration])
        fit = plan_fit.fit_plan(
            cal,
            base3d,
            FREE,
            rocks=settings["fit_rocks"],
            seed=seed,
            max_evaluations=settings["evaluations"],
        )
        ens, _ = _plan3d(fit.model, hold, settings["holdout_rocks"], seed)
        for name, e in (
            ("3-D", ens),
            (
                "clim",
                plan_climatology(
                    rel[f.calibration], dep[f.calibration], rel[f.holdout]
                ),
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


def main(argv: list[str]) -> None:
    full = "--full" in argv
    args = [a for a in argv if a != "--full"]
    out = Path(args[0]) if args else Path("out") / "calibrate_tschamut_3d"
    settings = FULL if full else SMALL
    summary = {"settings": settings, "fixed_split": fixed_split(settings)}
    if full:
        summary["kfold"] = kfold(settings)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "calibrate_tschamut_3d.json"
    path.write_text(json.dumps(summary, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
