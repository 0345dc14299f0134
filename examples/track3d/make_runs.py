"""Write raw 3-D trajectories for `fieldkit track3d` to try: 8 rocks of the 3-D
simulator on an analytic valley (fieldkit.tracking.trajectory3d.synthetic.valley_runs),
sampled at 200 Hz with 2 cm Gaussian noise per coordinate, with the DEM and the
simulator's impacts (the truth) beside them.

Usage: python examples/track3d/make_runs.py OUT_DIR
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

from fieldkit.tracking.trajectory3d.synthetic import valley_runs, write_site

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/track3d")
terrain, runs = valley_runs(fps=200.0, noise_sd_m=0.02)
samples, dem = write_site(out, terrain, runs)
truth = out / "truth.csv"
pd.concat([r.truth for r in runs]).to_csv(truth, index=False)
for path in (samples, dem, truth):
    print(f"wrote {path}")
