"""Corridor scans through the Dask engine on 1 and 2 local workers: throughput and
parallel efficiency, and that the tables are the same.

Site: the Tschamut 2014 DEM (``tests/data/tschamut2014/terrain.asc``) with the
alignment ``examples/tschamut/alignment.csv`` across the slope foot (110 m).

* 2-D: 2-D sections every 5 m (23 stations, 80 m upslope), the starting model
  ``examples/tschamut/model_base.json``, ``ROCKS_2D`` rocks per station;
* 3-D: the 3-D starting model ``examples/tschamut/model_3d.json`` from its 80
  release points, ``ROCKS_3D`` rocks in units of 2,000.

Each scan runs in this process (numba on every core: the reference a single user
gets without Dask), on a LocalCluster of 1 worker process and of 2 (one thread
each). The clusters are started before the clock (a worker's start-up and the
kernel load from numba's cache are paid once per worker, not per scan); each
timing is a scan's wall time from its first unit sent to its last result back,
so it includes Dask's scheduling and the transfer of the results. Printed:
rocks/s and impacts/s of each, the speed-up of 2 workers over 1 and the parallel
efficiency (speed-up / 2), the load average before and after, and whether the
tables of all three runs are identical (they must be: seed per unit).

``--quick`` (the test suite's run): a tenth of the rocks.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DEM = ROOT / "tests" / "data" / "tschamut2014" / "terrain.asc"
ALIGNMENT = ROOT / "examples" / "tschamut" / "alignment.csv"
MODEL_2D = ROOT / "examples" / "tschamut" / "model_base.json"
MODEL_3D = ROOT / "examples" / "tschamut" / "model_3d.json"
ROCKS_2D = 20_000
ROCKS_3D = 200_000
REPEATS = 2


def _scan(kind, engine, grid, xy, models, rocks):
    from fieldkit.corridor.scan import scan2d, scan3d
    from fieldkit.corridor.sections import SectionSetup

    tic = time.perf_counter()
    if kind == "2-D":
        s = scan2d(grid, xy, 5.0, models[0], rocks, 1, engine,
                   setup=SectionSetup(upslope_m=80.0))  # fmt: skip
    else:
        s = scan3d(models[1], grid, xy, 5.0, rocks, 1, engine)
    return time.perf_counter() - tic, s


def main(argv: list[str]) -> None:
    from fieldkit.io.alignment import read_alignment
    from fieldkit.io.dem import read_dem
    from fieldkit.model.model_file import read_model
    from fieldkit.model.simulate import warm_kernel
    from fieldkit.model.simulate3d import warm_kernel3d
    from fieldkit.parallel.engine import Engine, EngineSpec

    quick = "--quick" in argv
    scale = 10 if quick else 1
    grid = read_dem(DEM)
    xy = read_alignment(ALIGNMENT)
    models = (read_model(MODEL_2D), read_model(MODEL_3D, terrain=True))
    warm_kernel(), warm_kernel3d()
    load0 = os.getloadavg()
    print(f"machine: {os.cpu_count()} cores; load average before "
          f"{load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}")  # fmt: skip
    engines = {
        "this process": Engine(EngineSpec(workers=0)),
        "1 worker": Engine(EngineSpec(workers=1)),
        "2 workers": Engine(EngineSpec(workers=2)),
    }
    try:
        for engine in engines.values():
            engine.start()
        for kind, rocks in (("2-D", ROCKS_2D // scale), ("3-D", ROCKS_3D // scale)):
            what = (f"{rocks:,} rocks per station" if kind == "2-D"
                    else f"{rocks:,} rocks in all")  # fmt: skip
            print(f"{kind} corridor scan, 5 m stations, {what} "
                  f"(best of {REPEATS}):")  # fmt: skip
            seconds, tables, counts = {}, {}, {}
            for name, engine in engines.items():
                # the first scan on a worker loads its kernel: not timed
                _scan(kind, engine, grid, xy, models, 10 if kind == "2-D" else 100)
                best = np.inf
                for _ in range(REPEATS):
                    t, s = _scan(kind, engine, grid, xy, models, rocks)
                    best = min(best, t)
                seconds[name], tables[name] = best, s.frame
                total = rocks * len(s.stations) if kind == "2-D" else rocks
                counts[name] = (total, s.impacts, s.units)
                print(f"  {name:13s} {best:7.2f} s  {total / best:12,.0f} rocks/s  "
                      f"{s.impacts / best:14,.0f} impacts/s  ({s.units} units)")
            speedup = seconds["1 worker"] / seconds["2 workers"]
            same = all(t.equals(tables["this process"]) for t in tables.values())
            print(f"  2 workers / 1 worker: speed-up {speedup:.2f}x, parallel "
                  f"efficiency {speedup / 2:.0%}; 1 worker / this process "
                  f"{seconds['this process'] / seconds['1 worker']:.2f}x of its "
                  "speed")  # fmt: skip
            print(f"  tables identical on all three: {same}")
    finally:
        for engine in engines.values():
            engine.close()
    load1 = os.getloadavg()
    print(f"load average after {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}")


if __name__ == "__main__":
    main(sys.argv[1:])
