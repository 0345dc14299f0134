"""A rerun recording of a 3-D simulation: the DEM as a mesh, the sampled
trajectories, simulated deposits beside observed ones."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import rerun as rr

from fieldkit.model.terrain import Terrain
from fieldkit.model.terrain_file import cell_centres
from fieldkit.outputs import OutputSet, write_file
from fieldkit.viz.rerun_log import open_recording

#: Most trajectories a recording draws (the first rocks).
MAX_RECORDED_PATHS = 200


def terrain_mesh(terrain: Terrain) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices (k, 3), triangles (m, 3))`` of the cell centres, two triangles
    per square of four valid centres.

    Examples
    --------
    >>> v, t = terrain_mesh(Terrain(0.0, 0.0, 2.0, np.zeros((2, 3))))
    >>> v.shape, t.shape, v[1].tolist()
    ((6, 3), (4, 3), [3.0, 1.0, 0.0])
    """
    ny, nx = terrain.shape
    xc, yc = cell_centres(terrain)
    gx, gy = np.meshgrid(xc, yc)
    vertices = np.column_stack([gx.ravel(), gy.ravel(), terrain.z.ravel()])
    j, i = np.meshgrid(np.arange(ny - 1), np.arange(nx - 1), indexing="ij")
    a = (j * nx + i).ravel()
    b, c, d = a + 1, a + nx, a + nx + 1
    valid = np.isfinite(vertices[:, 2])
    keep = valid[a] & valid[b] & valid[c] & valid[d]
    triangles = np.concatenate(
        [np.column_stack([a, b, d])[keep], np.column_stack([a, d, c])[keep]]
    )
    return np.where(np.isfinite(vertices), vertices, 0.0), triangles.astype(np.uint32)


def write_terrain_recording(
    path: str | os.PathLike[str],
    terrain: Terrain,
    result,
    *,
    observed: np.ndarray | None = None,
    paths: int = MAX_RECORDED_PATHS,
    outputs: OutputSet | None = None,
) -> Path:
    """Write the recording (module docstring): the trajectories of the first
    ``paths`` rocks (at most :data:`MAX_RECORDED_PATHS`) on the ``rock`` timeline,
    every deposit, observed deposits ``(m, 2)`` placed on the ground when given."""
    vertices, triangles = terrain_mesh(terrain)
    offsets = np.asarray(result.path_offsets, np.int64)
    px = np.asarray(result.path["x_m"], float)
    py = np.asarray(result.path["y_m"], float)
    pz = np.asarray(result.path["z_m"], float)
    deposits = np.asarray(result.deposit_xyz, float)

    def record(tmp: Path) -> None:
        rec = open_recording(tmp, "simulation3d")
        try:
            rec.log("terrain", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
            rec.log(
                "terrain/dem",
                rr.Mesh3D(vertex_positions=vertices, triangle_indices=triangles,
                          vertex_colors=np.full((len(vertices), 3), 170, np.uint8)),
                static=True,
            )  # fmt: skip
            rec.log("terrain/deposits", rr.Points3D(deposits, radii=0.4,
                    colors=[(230, 120, 30)]), static=True)  # fmt: skip
            if observed is not None and len(observed):
                z = terrain.heights(observed[:, 0], observed[:, 1])
                rec.log("terrain/observed", rr.Points3D(
                    np.column_stack([observed, np.nan_to_num(z)]), radii=0.5,
                    colors=[(40, 90, 220)]), static=True)  # fmt: skip
            for i in range(min(len(offsets) - 1, paths, MAX_RECORDED_PATHS)):
                s = slice(offsets[i], offsets[i + 1])
                rec.set_time("rock", sequence=i)
                rec.log(f"terrain/trajectories/{i}", rr.LineStrips3D(
                    [np.column_stack([px[s], py[s], pz[s]])],
                    colors=[(40, 120, 220)]))  # fmt: skip
        finally:
            rec.disconnect()

    return write_file(path, record, outputs)
