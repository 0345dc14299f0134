"""A rerun scene of a corridor scan: the DEM as a mesh, the alignment, the
stations as bars as tall as their p99 bounce height coloured by p99 energy, the
sample trajectories and (2-D) the sections."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import rerun as rr
from matplotlib import colormaps

from fieldkit.outputs import OutputSet, write_file
from fieldkit.viz.rerun_log import open_recording
from fieldkit.viz.terrain_recording import terrain_mesh


def _colours(values: np.ndarray) -> np.ndarray:
    v = np.asarray(values, float)
    top = np.nanmax(v) if np.isfinite(v).any() else 1.0
    scaled = np.where(np.isfinite(v), v / (top or 1.0), 0.0)
    rgba = colormaps["inferno_r"](scaled)
    rgba[~np.isfinite(v)] = (0.6, 0.6, 0.6, 1.0)
    return (rgba[:, :3] * 255).astype(np.uint8)


def write_corridor_recording(
    path: str | os.PathLike[str], terrain, scan, *, outputs: OutputSet | None = None
) -> Path:
    """Write the scene (module docstring) of a :class:`~fieldkit.corridor.scan.
    CorridorScan` on its DEM (a :class:`~fieldkit.model.terrain.Terrain`)."""
    vertices, triangles = terrain_mesh(terrain)
    st = scan.stations
    f = scan.frame
    ground = np.nan_to_num(terrain.heights(st.xy_m[:, 0], st.xy_m[:, 1]))
    xy = st.alignment_xy
    line_z = np.nan_to_num(terrain.heights(xy[:, 0], xy[:, 1]))
    height = np.nan_to_num(f["height_p99_m"].to_numpy(float))
    colours = _colours(f["energy_p99_kj"].to_numpy(float))
    labels = [
        f"{c:.0f} m: p99 {e:.0f} kJ, {h:.1f} m" if np.isfinite(e) else f"{c:.0f} m: -"
        for c, e, h in zip(f["chainage_m"], f["energy_p99_kj"], f["height_p99_m"],
                           strict=True)
    ]  # fmt: skip

    def record(tmp: Path) -> None:
        rec = open_recording(tmp, "corridor")
        try:
            rec.log("corridor", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
            rec.log("corridor/dem", rr.Mesh3D(
                vertex_positions=vertices, triangle_indices=triangles,
                vertex_colors=np.full((len(vertices), 3), 170, np.uint8)),
                static=True)  # fmt: skip
            rec.log("corridor/alignment", rr.LineStrips3D(
                [np.column_stack([xy, line_z + 0.2])], colors=[(0, 0, 0)]),
                static=True)  # fmt: skip
            bars = [
                np.array([[x, y, z], [x, y, z + h]])
                for (x, y), z, h in zip(st.xy_m, ground, height, strict=True)
            ]
            rec.log(
                "corridor/stations/p99_height",
                rr.LineStrips3D(bars, colors=colours, radii=0.4, labels=labels),
                static=True,
            )
            rec.log("corridor/stations/points", rr.Points3D(
                np.column_stack([st.xy_m, ground]), colors=colours, radii=0.8),
                static=True)  # fmt: skip
            if scan.sections is not None:
                strips = []
                for i, s in enumerate(scan.sections):
                    sign = 1 if s.side == "left" else -1
                    n = sign * st.normal_xy[i]
                    top = st.xy_m[i] + s.alignment_x_m * n
                    x = np.asarray(s.model.profile.x_m, float)
                    plan = top - x[:, None] * n
                    strips.append(
                        np.column_stack(
                            [plan, np.asarray(s.model.profile.z_m, float) + 0.1]
                        )
                    )
                rec.log(
                    "corridor/sections",
                    rr.LineStrips3D(strips, colors=[(40, 90, 220)], radii=0.1),
                    static=True,
                )
            if scan.paths:
                rec.log(
                    "corridor/trajectories",
                    rr.LineStrips3D(
                        [np.asarray(p, float) for p in scan.paths],
                        colors=[(140, 60, 200)],
                        radii=0.08,
                    ),
                    static=True,
                )
        finally:
            rec.disconnect()

    return write_file(path, record, outputs)
