"""Rerun recording of a simulation: profile, trajectories, impacts by speed."""

from __future__ import annotations

import numpy as np
import pandas as pd
from rerun.chunk import RrdReader

from fieldkit.impact_table import ImpactTable
from fieldkit.viz.rerun_log import _speed_colours, write_simulation_recording


def _entities(path) -> dict[str, int]:
    out: dict[str, int] = {}
    for line in RrdReader(path).store().summary().splitlines():
        name, rest = line.split(" ", 1)
        rows = int(rest.split("rows=")[1].split()[0])
        out[name] = out.get(name, 0) + (0 if "static=True" in rest else rows)
    return out


def test_simulation_recording(tmp_path, synthetic_simulation):
    result = synthetic_simulation(rocks=50)
    impacts = ImpactTable(
        pd.DataFrame(
            {
                "path_id": ["0", "0", "1"],
                "point": ["1", "2", "1"],
                "x_m": [10.0, 20.0, 15.0],
                "z_m": [52.0, 44.0, 48.0],
                "slope_deg": [38.7] * 3,
                "vi_x_mps": [3.0, 5.0, 4.0],
                "vi_z_mps": [-4.0, -6.0, -5.0],
                "vf_x_mps": [3.0, 4.0, 3.0],
                "vf_z_mps": [1.0, 1.0, 1.0],
                "t_s": [1.0, 2.0, 1.5],
            }
        )
    ).derive()
    path = write_simulation_recording(tmp_path / "sim.rrd", result, impacts)
    e = _entities(path)
    assert "/simulation/profile" in e
    assert sum(1 for name in e if name.startswith("/simulation/trajectories/")) == 3
    assert e["/simulation/impacts/0"] == 2 and e["/simulation/impacts/1"] == 1


def test_speed_colours_run_from_blue_to_red():
    c = _speed_colours(np.array([1.0, 5.0, np.nan, 3.0]))
    assert c[0, 2] > c[0, 0] and c[1, 0] > c[1, 2]  # slowest blue, fastest red
    assert c.dtype == np.uint8 and c.shape == (4, 3)
