"""Writing simulated impacts: rows per second of each path, per million rows.

Prints ImpactTable.derive, pandas ``to_csv`` (what ``ImpactTable.write`` uses), the
streamed pyarrow CSV and Parquet writers (fieldkit.io.impact_stream), for a derived
table of ``ROWS`` impacts in chunks of ``CHUNK`` rows.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.impact_table import ImpactTable
from fieldkit.io.impact_stream import ImpactStreamWriter
from fieldkit.outputs import escape_formulas

ROWS = 1_000_000
CHUNK = 200_000


def table(rows: int, seed: int = 0) -> ImpactTable:
    rng = np.random.default_rng(seed)
    return ImpactTable(
        pd.DataFrame(
            {
                "path_id": (np.arange(rows) // 10).astype(str),
                "point": (np.arange(rows) % 10 + 1).astype(str),
                "x_m": rng.uniform(0, 100, rows),
                "z_m": rng.uniform(0, 50, rows),
                "slope_deg": rng.uniform(10, 40, rows),
                "material": np.where(rng.random(rows) < 0.5, "rock", "talus"),
                "mass_kg": 1000.0,
                "radius_m": 0.5,
                "gyration_m": 0.4,
                "vi_x_mps": rng.normal(5, 1, rows),
                "vi_z_mps": -rng.uniform(1, 10, rows),
                "vf_x_mps": rng.normal(4, 1, rows),
                "vf_z_mps": rng.uniform(0.5, 3, rows),
                "omega_i_radps": rng.normal(0, 5, rows),
                "omega_f_radps": rng.normal(0, 5, rows),
                "t_s": rng.uniform(0, 20, rows),
                "tree_strike": False,
            }
        )
    )


def _report(name: str, seconds: float) -> None:
    print(
        f"{name:34s} {seconds * 1e6 / ROWS:7.2f} s per 1e6 rows "
        f"({ROWS / seconds:12,.0f} rows/s)"
    )


def main() -> None:
    raw = table(ROWS)
    t0 = time.perf_counter()
    derived = raw.derive()
    _report("ImpactTable.derive", time.perf_counter() - t0)
    chunks = [
        ImpactTable(derived.frame.iloc[i : i + CHUNK]) for i in range(0, ROWS, CHUNK)
    ]
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        t0 = time.perf_counter()
        escape_formulas(derived.frame).to_csv(out / "pandas.csv", index=False)
        _report("pandas to_csv (ImpactTable.write)", time.perf_counter() - t0)
        for fmt in ("csv", "parquet"):
            t0 = time.perf_counter()
            with ImpactStreamWriter(out / f"stream.{fmt}", fmt) as writer:
                for chunk in chunks:
                    writer.write(chunk)
            _report(f"streamed {fmt} (pyarrow)", time.perf_counter() - t0)


if __name__ == "__main__":
    main()
