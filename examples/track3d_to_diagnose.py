"""From a raw 3-D trajectory to `fieldkit diagnose` (issue 22, item 4).

Eight rocks are simulated by the 3-D simulator on an analytic valley DEM (constant
e_n 0.6, e_t 0.85, no roughness), their centres sampled at 200 Hz with 2 cm Gaussian
noise per coordinate -- a full-scale test's raw trajectories -- and written with the
DEM. `fieldkit track3d` reduces them to an ImpactTable on that DEM; the impacts are
compared with the simulator's own impact rows (the truth), and `fieldkit diagnose`
reads the table: constant e_n, e_t explain the rebounds, so no effect is recommended.

Usage: python examples/track3d_to_diagnose.py [OUT_DIR]
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.impact_table import ImpactTable
from fieldkit.tracking.trajectory3d.synthetic import valley_runs, write_site

OUT = Path(sys.argv[1] if len(sys.argv) > 1 else "out/track3d")
FPS, NOISE_SD_M = 200.0, 0.02


def fieldkit(*args) -> str:
    done = subprocess.run([sys.executable, "-m", "fieldkit", *map(str, args)],
                          capture_output=True, text=True)  # fmt: skip
    if done.returncode:
        sys.exit(done.stderr)
    return done.stdout


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    terrain, runs = valley_runs(fps=FPS, noise_sd_m=NOISE_SD_M)
    write_site(OUT, terrain, runs)
    samples = pd.concat([r.samples for r in runs])
    print(
        f"raw trajectories: {len(runs)} runs, {len(samples)} samples at "
        f"{FPS:.0f} Hz, noise SD {100 * NOISE_SD_M:.0f} cm per coordinate"
    )
    reduced = fieldkit(
        "track3d", OUT / "trajectories.csv", "--dem", OUT / "valley.asc",
        "--radius", 0.2, "--mass", 100, "--gyration", 0.126,
        "--material", "ground", "-o", OUT / "impacts.csv",
    )  # fmt: skip
    print(reduced, end="")
    found = ImpactTable.read(OUT / "impacts.csv").frame
    truth = pd.concat([r.truth for r in runs], ignore_index=True)
    hits, errors = 0, {"e_n": [], "e_t": [], "lateral_deg": []}
    for _, row in truth.iterrows():
        same = found[found["path_id"] == row["path_id"]]
        d = (same["t_s"] - row["t_s"]).abs()
        if len(d) and d.min() <= 0.02:
            hits += 1
            for name in errors:
                errors[name].append(same.loc[d.idxmin(), name] - row[name])
    print(f"truth (the simulator's impact rows): {len(truth)} impacts; found "
          f"{hits}, missed {len(truth) - hits}, extra {len(found) - hits}")  # fmt: skip
    for name, err in errors.items():
        a = np.abs(err)
        print(f"  {name} error: median {np.median(a):.3f}, max {a.max():.3f}")
    (OUT / "model2d.json").write_text(json.dumps({
        "profile": {"x_m": [0, 20, 40], "z_m": [40, 28, 20],
                    "material": ["ground", "ground"]},
        "materials": {"ground": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30.0}},
        "body": {"mass_kg": 100, "radius_m": 0.2, "gyration_m": 0.126},
        "seeder": {"x_m": 0.5, "z_m": 41.0, "vx_mps": 2.0, "vz_mps": 0.0},
    }))  # fmt: skip
    fieldkit("diagnose", OUT / "impacts.csv", "--model", OUT / "model2d.json",
             "--seed", 1, "--json", OUT / "diagnosis.json")  # fmt: skip
    report = json.loads((OUT / "diagnosis.json").read_text())
    print(f"diagnose: baseline held-out error {report['baseline']['cv_rmse_mps']:.4f} "
          f"m/s; recommended {report['recommended']}")  # fmt: skip


if __name__ == "__main__":
    main()
