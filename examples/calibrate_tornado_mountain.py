"""Walk-through: calibrate on boulder A's surveyed path, compare with Table 7-1.

Thesis §7.5.4 ran RocFall 4.0 on Tornado Mountain with hand-calibrated inputs
(Table 7-1) and found its trajectories "significantly higher" than boulder A's. This
script does the comparison with fieldkit, on the same simulator for both models:

1. reduce boulder A's survey (46 impacts, 21 tree strikes) to an ImpactTable, as
   ``fieldkit reduce`` does, with the default survey error model (``*_sd`` columns);
2. diagnose it against the Table 7-1 model (materials mapped as boulder A's preset
   and the model's provenance state: Table 7-1 lists rock and colluvium only, so the
   survey's ``talus`` and ``bench`` impacts use colluvium) — the rebound velocities
   pick the impact law and fit its parameters and each material's e_n, e_t (held
   out in blocks: one surveyed path);
3. calibrate the simulator on the whole path (``fieldkit fit --paths`` on an
   ImpactTable: :func:`fieldkit.fit.path_fit.fit_paths`), starting from Table 7-1
   with two changes a path fit needs: RocFall's velocity scaling of e_n (eq. 7.1,
   K = 9.144 m/s to start) -- with a constant e_n the lumped-mass rocks either roll
   (e_n below ~0.8) or fly ever higher (e_n ~ 1), never boulder A's steady 1-2 m
   flights -- and the railway bench (impacts 43-45, §8.1) as its own material,
   which Table 7-1 lumps into the colluvium. Fitted: the colluvium's e_n, e_t, K,
   and the bench's e_n, e_t, so that the simulated rocks' runout, length-weighted
   flight heights, impact spacings and speeds at the 49 surveyed points match
   boulder A's (each kind a mean CRPS, scaled by its value at the start), with
   bootstrap standard errors over the surveyed points;
4. report what a designer needs, consequence first (issue 20): the 90 % intervals of
   the path fit -- the bootstrap over the path's points (a lower bound: one path)
   beside the objective's profile (the others re-optimised, the seed spread in the
   threshold); the path fit refitted without the observations resting on impacts
   the reduction flags (energy gained, e_t > 1) and without the flights resting on
   the assumed theta0; the path fit with the bench's friction and roughness free too
   (does a bench of its own stop the rock and keep its speed?); the realised e_n of
   each calibrated colluvium at its simulated impacts, and the path fit constrained
   to realised e_n <= 1;
5. simulate 5,000 rocks of every model on one held-out stream (common random
   numbers, a stream no fit uses) and print the design quantities -- passing
   fraction, p50/p95/p99/max of speed, translational and total energy and bounce
   height, with Monte Carlo errors -- at x = 610 m beside the measured 18 m/s and
   600 kJ (§7.5.4), and at x = 587 m beside boulder A's arrival at impact 42 (the
   last colluvium impact, flagged as gaining energy), with a line for every model
   that is unconservative against a measured value; then the mean normal flight
   height beside the measured 1.68 m (recomputed from Table 2-4; the thesis prints
   1.5 m) and the uninterrupted flights per rock launched at x = 98-614.5 m beside
   boulder A's 44.

Friction, roughness, the e_n, e_t scatter, the rock segments and the seeder stay
Table 7-1's (but in the bench-free fit). One path is one realisation: its bootstrap
intervals resample its points, not boulders, and are a lower bound on the
uncertainty.

Run:  python examples/calibrate_tornado_mountain.py [OUT_DIR]
"""

from __future__ import annotations

import importlib.util
import itertools
from dataclasses import replace
from pathlib import Path

import numpy as np

from fieldkit.diagnose.impacts import diagnose_impacts
from fieldkit.fit.consequences import design_quantities
from fieldkit.fit.leave_out import leave_out_lines, leave_out_models, path_leave_outs
from fieldkit.fit.material_map import map_materials
from fieldkit.fit.path_fit import fit_paths
from fieldkit.fit.path_runs import section_runs
from fieldkit.fit.plausibility import simulated_restitution
from fieldkit.impact_table import ImpactTable
from fieldkit.io.impacts import read_impacts
from fieldkit.io.path_observations import observations_from_impact_table
from fieldkit.io.preset import read_preset
from fieldkit.io.trees import read_trees
from fieldkit.measured import Measured
from fieldkit.model import read_model, simulate
from fieldkit.physics.bodies import resolve_body
from fieldkit.reduce.pipeline import ReduceOptions, reduce_path
from fieldkit.survey import Survey

HERE = Path(__file__).resolve().parent
SURVEY = HERE.parent / "surveys" / "tornado_mountain"
ROCKS, SEED = 5000, 2004
#: Path-level fit: free parameters and their search bounds (e_n above 1 is what
#: RocFall enters with eq. 7.1's velocity scaling: 0.5 of it at v_N = K), rocks per
#: evaluation, Sobol screen points, bootstrap resamples.
PATH_FREE = {
    "materials.colluvium.e_n": (0.2, 2.0),
    "materials.colluvium.e_t": (0.3, 0.98),
    "velocity_scaled_restitution.k_mps": (2.0, 30.0),
    "materials.bench.e_n": (0.05, 1.2),
    "materials.bench.e_t": (0.1, 0.98),
}
PATH_ROCKS, PATH_SCREEN, PATH_BOOTSTRAP = 150, 16, 10
#: The bench grid: values of each bench parameter, rocks per setting, the speed
#: at x = 610 m and the stop before which "fast and stopping" is asked of it.
GRID_BENCH = {
    "materials.bench.e_n": (0.2, 0.5, 0.8, 1.1),
    "materials.bench.e_t": (0.5, 0.7, 0.9, 0.98),
    "materials.bench.friction_deg": (5.0, 15.0, 30.0, 45.0),
    "materials.bench.roughness_m": (0.0, 0.3),
}
GRID_ROCKS, GRID_FAST_MPS, GRID_STOP_X_M = 300, 14.0, 635.0
#: Design quantities also just upslope of impact 42 (x = 587.2 m), the last impact
#: on the colluvium before the railway bench.
BEFORE_42_X_M = 587.0
#: The bench-free fit frees the bench's friction and roughness too (CRSP's
#: roughness height; RocFall's dip SD stays Table 7-1's 0 on the bench).
BENCH_FREE = {
    "materials.bench.friction_deg": (5.0, 60.0),
    "materials.bench.roughness_m": (0.0, 1.0),
}
#: Boulder A's reduce options and material mapping, stated once
#: (``fieldkit reduce --preset``, ``fieldkit fit --preset``).
PRESET = read_preset(SURVEY / "boulder_a_preset.toml")

_spec = importlib.util.spec_from_file_location(
    "simulate_tornado_mountain", HERE / "simulate_tornado_mountain.py"
)
sim = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sim)


def reduced_table() -> ImpactTable:
    """Boulder A's ImpactTable (surveyed materials), reduced with the preset."""
    points = read_impacts(SURVEY / "boulder_a_impacts.gpx")
    trees = read_trees(SURVEY / "boulder_a_trees.csv", points)
    options = ReduceOptions(
        path_id=PRESET.reduce["path_id"],
        theta0_deg=PRESET.reduce["theta0_deg"],
        body=resolve_body(**PRESET.body()),
    )
    return reduce_path(Survey(points, trees), options).table


def figures(name: str, model) -> dict:
    """Mean normal flight height and flights per rock of ``model`` (x = 98-614.5 m)."""
    heights: list[np.ndarray] = []
    result = simulate(
        model,
        ROCKS,
        np.random.default_rng(SEED),
        record_impacts=True,
        on_impact_chunk=lambda chunk: heights.append(sim.chunk_flight_heights(chunk)),
    )
    h = np.concatenate(heights) if heights else np.zeros(0)
    reached = int(np.sum(np.asarray(result.runout_x_m) >= sim.FLIGHTS_X_M[1]))
    return {
        "model": name,
        "mean flight height m": float(h.mean()) if h.size else np.nan,
        # per rock that reached the end of the stretch (none: no figure)
        "flights per rock": h.size / reached if reached else np.nan,
    }


def bench_grid(model) -> list[tuple[float, float]]:
    """(median speed at x = 610 m, share stopped before GRID_STOP_X_M) of every
    bench in the grid, the rest of ``model`` unchanged (common random numbers)."""
    out = []
    for en, et, friction, rough in itertools.product(*GRID_BENCH.values()):
        bench = model.with_parameters(
            dict(zip(GRID_BENCH, (en, et, friction, rough), strict=True))
        )
        result = simulate(bench, GRID_ROCKS, np.random.default_rng([SEED, 5]),
                          analysis_x_m=[sim.X_ANALYSIS_M])  # fmt: skip
        point = result.analysis[0]
        speed = point.speed_mps[point.crossed]
        stopped = float(np.mean(np.asarray(result.runout_x_m) < GRID_STOP_X_M))
        out.append((float(np.median(speed)) if speed.size else 0.0, stopped))
    return out


def path_fit(runs, start, free: dict, **settings):
    """``fit_paths`` of boulder A's run with the example's sizes."""
    options = {"rocks": PATH_ROCKS, "seed": SEED, "screen": PATH_SCREEN,
               "bootstrap": PATH_BOOTSTRAP, **settings}  # fmt: skip
    return fit_paths(runs, start, list(free), bounds=free, **options)


def colluvium_share(model) -> str:
    """The colluvium's realised e_n of ``model``'s simulated impacts, in words."""
    (r,) = [
        r for r in simulated_restitution(model, seed=SEED) if r.material == "colluvium"
    ]
    return (
        f"realised e_n > 1 on {100 * r.share_e_n_above_1:.1f} % of {r.impacts:,} "
        f"simulated colluvium impacts (median {r.median_e_n:.3f})"
        + (": a regulator, not a restitution" if r.regulator else "")
    )


def main() -> None:
    table = reduced_table()
    thesis = read_model(SURVEY / "model_rocfall_table_7_1.json")
    mapped = map_materials(table, list(thesis.materials), preset=PRESET.materials,
                           preset_source="the preset")  # fmt: skip
    for text in mapped.notes:
        print(text)
    d = diagnose_impacts(mapped.table, thesis, rng=np.random.default_rng(SEED))
    print(
        f"boulder A: {d.n_rows} impacts; held out: {d.groups}\n"
        f"Table 7-1 impact laws: held-out RMSE {d.baseline.cv_rmse:.3f} m/s"
    )
    for c in d.candidates:
        print(
            f"  + {c.effect}: {c.cv_rmse:.3f} m/s, gain {c.improvement:+.1%} "
            f"± {c.improvement_se:.1%}{'  (meaningful)' if c.meaningful else ''}"
        )
    print(f"recommended: {d.recommended or 'nothing'}; stopped: {d.stopped}")
    calibrated = d.arrays["after_model"]
    fitted = {
        k: (v, d.after.params_sd.get(k, np.nan)) for k, v in d.after.params.items()
    }
    print("calibrated on the impacts: " + ", ".join(
        f"{k} = {v:.3f} ± {s:.3f}" for k, (v, s) in fitted.items()
    ))  # fmt: skip
    calibrated = replace(calibrated, provenance=dict(thesis.provenance))

    # surveys/tornado_mountain/model_path_start.json: Table 7-1 + eq. 7.1 (K =
    # 9.144 m/s) + the bench (segments from x = 587.2 m) as its own material.
    start = read_model(SURVEY / "model_path_start.json")
    runs = section_runs(observations_from_impact_table(table), start)
    fit = path_fit(runs, start, PATH_FREE)
    print(
        f"\ncalibrated on boulder A's path ({fit.n_evaluations} evaluations, "
        f"{PATH_ROCKS} rocks each, {fit.wall_s:.0f} s): "
        + ", ".join(
            f"{n} = {v:.3f} ± {e:.3f}"
            for n, v, e in zip(fit.names, fit.values, fit.stderr, strict=True)
        )
    )
    print("  mean CRPS, start (Table 7-1 + eq. 7.1 + bench) -> calibrated:")
    for kind in fit.kinds:
        print(
            f"  {kind:18s} {fit.kind_start[kind]:8.3f} -> "
            f"{fit.kind_optimum[kind]:7.3f} ({fit.kind_counts[kind]} observed)"
        )
    for note in fit.notes:
        print(f"  note: {note}")

    # Honest intervals: the bootstrap over one path's points, the objective's slice
    # and its profile (the others re-optimised, the seed spread in the threshold).
    prof = fit.profile
    print(
        f"\nintervals (90 %): bootstrap over the path's points (a lower bound: one "
        f"path), profile with the others re-optimised; the objective's SD over "
        f"{prof.seeds} other seeds at the optimum is {prof.optimum_seed_sd:.3g} "
        f"of {prof.objective_optimum:.3g}"
    )
    for j, n in enumerate(fit.names):
        (blo, bhi), (plo, phi) = fit.interval90[j], prof.interval90[j]
        print(f"  {n:36s} {fit.values[j]:8.3f}  bootstrap {blo:.3f} to {bhi:.3f}  "
              f"profile {plo:.3f} to {phi:.3f}  widest: {prof.widest[j]}")  # fmt: skip

    # Suspect data: the values resting on flagged impacts, or on an assumed launch
    # angle, left out in turn (a search from the calibrated values, same rocks).
    frame = table.frame
    flagged = [
        str(p) for p, f in zip(frame["point"], frame["qa_flags"].fillna(""),
                               strict=True)
        if {"energy_gained", "e_t_above_1"} & set(str(f).split(";"))
    ]  # fmt: skip
    arrival = frame.iloc[(frame["x_m"] - sim.X_ANALYSIS_M).abs().argsort()[:1]]
    print(
        f"\nsuspect data: impacts {', '.join(flagged)} are flagged (energy gained or "
        f"e_t > 1); the measured {sim.MEASURED_SPEED_MPS:g} m/s is boulder A's "
        f"arrival at impact {arrival['point'].iloc[0]} (x = "
        f"{float(arrival['x_m'].iloc[0]):.1f} m, {float(arrival['vi_mps'].iloc[0]):.1f}"
        f" m/s), by the flight leaving flagged impact 42"
    )
    leave_outs = path_leave_outs(runs, fit)
    for line in leave_out_lines(leave_outs):
        print(line)

    # Free what the question needs: does a bench with its own friction and
    # roughness stop the rock within 30 m and keep its speed at the railway?
    bench_free = {**PATH_FREE, **BENCH_FREE}
    bench = path_fit(runs, start, bench_free, profile_points=0, bootstrap=0)
    print(
        f"\nbench free ({', '.join(BENCH_FREE)} also fitted; {bench.n_evaluations} "
        f"evaluations): objective {bench.objective_optimum:.3f} against "
        f"{fit.objective_optimum:.3f} with the bench's friction and roughness fixed; "
        + ", ".join(f"{n} = {v:.3f}" for n, v in zip(bench.names, bench.values,
                                                     strict=True))
    )  # fmt: skip

    # The explanation directly: with the colluvium as calibrated, is there a
    # bench (e_n, e_t, friction, roughness) that passes the railway fast and still
    # stops the rocks within 25 m of it?
    fast = bench_grid(fit.model)
    print(
        f"bench grid ({len(fast)} settings of e_n, e_t, friction, roughness, colluvium "
        f"as calibrated, {GRID_ROCKS} rocks each): the fastest median speed at "
        f"x = 610 m is {max(fast)[0]:.1f} m/s (stopping {100 * max(fast)[1]:.0f} % "
        f"of its rocks by x = {GRID_STOP_X_M:g} m); settings passing at a median "
        f"of {GRID_FAST_MPS:g} m/s or more and stopping half the rocks by x = "
        f"{GRID_STOP_X_M:g} m: "
        f"{sum(1 for r in fast if r[0] >= GRID_FAST_MPS and r[1] >= 0.5)}"
    )

    # Physical plausibility: what the fitted laws do at the simulated impacts, and
    # the path fit constrained to realised e_n <= 1.
    constrained = path_fit(runs, start, PATH_FREE, profile_points=0, bootstrap=0,
                           max_realised_e_n=1.0)  # fmt: skip
    print("\nplausibility (the colluvium, simulated on its own stream):")
    for name, model in (
        ("calibrated on the impacts", calibrated),
        ("calibrated on the path", fit.model),
        ("bench free", bench.model),
        ("constrained to realised e_n <= 1", constrained.model),
    ):
        print(f"  {name:34s} {colluvium_share(model)}")  # fmt: skip
    print(
        "  constrained to realised e_n <= 1: "
        + ", ".join(f"{n} = {v:.3f}" for n, v in zip(constrained.names,
                                                     constrained.values, strict=True))
        + "; mean CRPS " + ", ".join(
            f"{k} {fit.kind_optimum[k]:.2f} -> {constrained.kind_optimum[k]:.2f}"
            for k in fit.kinds)
    )  # fmt: skip

    # The consequence: the design quantities at the railway (x = 610 m) of every
    # model, on one held-out stream, beside what boulder A did there.
    models = {
        "Table 7-1": thesis,
        "start": start,
        "impacts": calibrated,
        "path": fit.model,
        **{f"path, {k}": m for k, m in leave_out_models(leave_outs).items()},
        "path, bench free": bench.model,
        "path, e_n <= 1": constrained.model,
    }
    # Upslope of the bench too: just before impact 42 (x = 587.2 m), where the
    # reduction says boulder A arrived at 11.8 m/s and left faster.
    before = frame.loc[frame["point"].astype(str) == "42"].iloc[0]
    upslope = Measured(
        BEFORE_42_X_M,
        speed_mps=float(before["vi_mps"]),
        ke_j=float(before["ke_i_j"]),
        source="boulder A's arrival at impact 42, x = 587.2 m (reduced; the flight "
        "from 41 rests on the assumed θ0)",
    )
    design = design_quantities(
        models,
        [BEFORE_42_X_M, sim.X_ANALYSIS_M],
        [upslope, *PRESET.measured],
        rocks=ROCKS,
        seed=SEED,
    )
    print()
    for line in design.lines():
        print(line)
    print()
    for line in design.verdicts():
        print(line)

    rows = [figures(name, model) for name, model in models.items()]
    measured, n = sim.measured_mean_flight_height_m()
    print(
        f"\nmeasured: 18 m/s and 600 kJ at x = 610 m (§7.5.4); mean normal flight "
        f"height {measured:.2f} m over {n} flights (recomputed from Table 2-4)"
    )
    keys = list(rows[0])[1:]
    print(f"{'':36s}" + "".join(f"{k:>22s}" for k in keys))
    for r in rows:
        print(f"{r['model']:36s}" + "".join(f"{r[k]:>22.4g}" for k in keys))


if __name__ == "__main__":
    main()
