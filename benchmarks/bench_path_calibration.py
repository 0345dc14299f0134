"""Simulation-based calibration check of the path-level fit's 90 % intervals.

For each of ``--sites`` synthetic sites (:func:`fieldkit.fit.synthetic_paths.
synthetic_site`, ``--runs`` runs each): true parameters are drawn uniformly from a
prior box (``e_t`` in [0.6, 0.9], ``friction_deg`` in [27, 36] deg of material
``talus``), the observed runouts are simulated with them, and
:func:`fieldkit.fit.path_fit.fit_paths` fits both from the base model's values
(0.8, 30 deg). The printed figure is, per parameter, the fraction of sites whose
90 % interval contains the truth, with its binomial SE sqrt(c (1 - c) / N).
Target (issue 11): 85-95 %. Also printed: wall time per fit and per objective
evaluation. Printed, not asserted.

Usage: ``python benchmarks/bench_path_calibration.py [--sites N] [--runs R]``
(default 6 sites, about a minute on 2 cores: the ``make bench`` setting).
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from fieldkit.fit.path_fit import fit_paths
from fieldkit.fit.synthetic_paths import synthetic_site

SEED = 11
PRIOR = {
    "materials.talus.e_t": (0.6, 0.9),
    "materials.talus.friction_deg": (27.0, 36.0),
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sites", type=int, default=6)
    parser.add_argument("--runs", type=int, default=15)
    parser.add_argument("--rocks", type=int, default=200)
    parser.add_argument("--bootstrap", type=int, default=40)
    args = parser.parse_args(argv)
    rng = np.random.default_rng(SEED)
    names = list(PRIOR)
    covered = np.zeros((args.sites, len(names)), bool)
    walls, evals = [], []
    tic = time.perf_counter()
    for s in range(args.sites):
        truth = {n: float(rng.uniform(*PRIOR[n])) for n in names}
        site = synthetic_site(truth, args.runs, rng)
        result = fit_paths(
            site,
            site[0].model,
            names,
            rocks=args.rocks,
            seed=1000 + s,
            bootstrap=args.bootstrap,
        )
        walls.append(result.wall_s)
        evals.append(result.n_evaluations)
        for j, n in enumerate(names):
            lo, hi = result.interval(n)
            covered[s, j] = lo <= truth[n] <= hi
        print(
            f"site {s:3d}: "
            + "  ".join(
                f"{n.split('.')[-1]} true {truth[n]:.3f} fit {result.value(n):.3f} "
                f"[{result.interval(n)[0]:.3f}, {result.interval(n)[1]:.3f}]"
                for n in names
            )
            + f"  {result.wall_s:.1f} s",
            flush=True,
        )
    total = time.perf_counter() - tic
    n = args.sites
    print(f"\n{n} sites x {args.runs} runs, {args.rocks} rocks, B = {args.bootstrap}")
    for j, name in enumerate(names):
        c = covered[:, j].mean()
        se = math.sqrt(c * (1.0 - c) / n)
        print(f"  90 % interval covers {name}: {c:.1%} ± {se:.1%} (target 85-95 %)")
    per_eval = 1e3 * sum(walls) / sum(evals)
    print(
        f"  wall: {total:.0f} s total, {np.mean(walls):.1f} s per fit "
        f"({np.mean(evals):.0f} evaluations, {per_eval:.1f} ms each)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
