"""Collinear vertices are no break: a rock slides over them as over one segment.

Found by the 3-D kernel's comparison with the 2-D one (issue 21): the 2-D kernel took
any increase of the dip at a vertex, even rounding's 1e-13 deg, for a convex break and
launched the rock there, which then landed again and lost speed to e_t at every vertex
(63 impacts per rock and a runout 15 m short on the profile below).
"""

from __future__ import annotations

import json

import numpy as np

SLOPE = 0.7002075382097097  # an irrational-ish gradient: rounding differs per vertex


def model_file(path, vertices: int):
    x = [*np.linspace(0.0, 100.0, vertices).tolist(), 200.0]
    z = [70.0 - SLOPE * xi for xi in x[:-1]] + [70.0 - SLOPE * 100.0]
    path.write_text(json.dumps({
        "profile": {"x_m": x, "z_m": z, "material": "soil"},
        "materials": {"soil": {"e_n": 0.3, "e_t": 0.8, "friction_deg": 30}},
        "body": {"mass_kg": 100, "radius_m": 0.2},
        "seeder": {"x_m": 1, "z_m": 70.5, "vx_mps": 2.0},
    }))  # fmt: skip
    return path


def test_collinear_vertices_change_nothing(cli, tmp_path):
    runs = {}
    for n in (3, 150):
        summary = tmp_path / f"s{n}.json"
        r = cli("simulate", model_file(tmp_path / f"m{n}.json", n), "--rocks", "300",
                "--seed", "1", "--summary", summary)  # fmt: skip
        assert r.exit_code == 0, r.output
        runs[n] = json.loads(summary.read_text())
    # the same rocks, the same impacts: the 148 extra vertices lie on one line
    assert runs[150]["impacts"] == runs[3]["impacts"] == 2 * 300
    for q in ("p50", "p95", "max"):
        assert abs(runs[150]["runout_x_m"][q] - runs[3]["runout_x_m"][q]) < 1e-6
