"""3-D trajectories sampled from the 3-D simulator, with exact truth.

The simulator's impact rows (:func:`fieldkit.model.simulate3d.simulate3d` with
``record_impacts``) give every contact's time, point and the velocities in and out
(``vin N + vit T``, ``vfn N + vft T``); between two contacts a flight is an exact
parabola (no drag in 3-D). :func:`sampled_runs` rebuilds each rock's flights from
them, keeps the rock only while each flight ends exactly where the next impact row
says (a slide or a tree strike between two impacts ends the kept part there), ends
the kept part before the first flight shorter than ``min_flight_s`` (a sampling at
100-200 Hz cannot fit it), samples the flights at ``fps`` from a random phase, and
adds Gaussian noise of SD ``noise_sd_m`` to every coordinate. The truth is the
impact rows of the kept part that have a kept flight on both sides, with the
lateral deflection of their velocities (NaN where one has no plan component: a
vertical drop).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from fieldkit.io.dem import header_number_text
from fieldkit.physics.constants import G

#: Largest mismatch of a rebuilt flight with the next impact row [m].
CHAIN_TOLERANCE_M = 1e-6


@dataclass(frozen=True)
class SampledRun:
    """One rock's sampled trajectory and its truth.

    Attributes
    ----------
    samples
        ``path_id, t_s, x_m, y_m, z_m, omega_radps`` (noisy positions, spin exact).
    truth
        The simulator's impact rows kept (``t_s, x_m, y_m, z_m, e_n, e_t,
        lateral_deg, ...``) as a frame.
    """

    samples: pd.DataFrame
    truth: pd.DataFrame


def _vectors(rows, i):
    n = np.array([rows["normal_x"][i], rows["normal_y"][i], rows["normal_z"][i]])
    t = np.array([rows["tangent_x"][i], rows["tangent_y"][i], rows["tangent_z"][i]])
    vi = rows["vin_mps"][i] * n + rows["vit_mps"][i] * t
    vf = rows["vfn_mps"][i] * n + rows["vft_mps"][i] * t
    p = np.array([rows["x_m"][i], rows["y_m"][i], rows["z_m"][i]])
    return p, vi, vf


def sampled_runs(
    result,
    *,
    fps: float,
    noise_sd_m: float,
    rng: np.random.Generator,
    min_flight_s: float = 0.1,
    min_impacts: int = 2,
    material_names=("ground",),
) -> list[SampledRun]:
    """Sampled, noisy trajectories of every rock of a 3-D result with truth.

    Parameters
    ----------
    result
        A :class:`fieldkit.model.simulate3d.Result3D` run with ``record_impacts``
        and ``keep_paths`` (the release point is the path's first sample).
    fps
        Sampling rate [Hz].
    noise_sd_m
        SD of the Gaussian noise added to each coordinate [m].
    rng
        Random numbers (sampling phase, noise).
    min_flight_s
        A rock's kept part ends before its first flight shorter than this.
    min_impacts
        Rocks with fewer truth impacts are left out.
    material_names
        The model's material names (in the order of its material index).
    """
    from fieldkit.model.results3d import impact_table3d

    rows = result.impact_rows
    rock = rows["rock"]
    out = []
    for k in range(result.rocks):
        idx = np.flatnonzero(rock == k)
        if idx.size == 0:
            continue
        start = result.rock_path(k)
        p0 = np.array([start["x_m"][0], start["y_m"][0], start["z_m"][0]])
        t1 = rows["t_s"][idx[0]]
        p1, vi1, _ = _vectors(rows, idx[0])
        v0 = vi1 + np.array([0.0, 0.0, G * t1])
        # flights: (t_start, p_start, v_start, t_end); the first from the release
        flights = [(0.0, p0, v0, t1)]
        if np.linalg.norm(p0 + v0 * t1 - [0, 0, 0.5 * G * t1 * t1] - p1) > 1e-6:
            continue  # the rock did not fly straight to its first impact
        for a, b in zip(idx[:-1], idx[1:], strict=True):
            pa, _, vfa = _vectors(rows, a)
            pb, vib, _ = _vectors(rows, b)
            dt = rows["t_s"][b] - rows["t_s"][a]
            end = pa + vfa * dt - np.array([0.0, 0.0, 0.5 * G * dt * dt])
            if np.linalg.norm(end - pb) > CHAIN_TOLERANCE_M or dt < min_flight_s:
                break
            flights.append((rows["t_s"][a], pa, vfa, rows["t_s"][b]))
        if flights[0][3] < min_flight_s:
            continue
        kept = idx[: len(flights) - 1]  # impacts with a kept flight on each side
        if kept.size < min_impacts:
            continue
        t_end = flights[-1][3]
        t = np.arange(rng.uniform(0.0, 1.0 / fps), t_end, 1.0 / fps)
        which = np.searchsorted([f[0] for f in flights], t, side="right") - 1
        xyz = np.empty((t.size, 3))
        omega = np.empty(t.size)
        for j, (ts, ps, vs, _) in enumerate(flights):
            sel = which == j
            tau = (t[sel] - ts)[:, None]
            xyz[sel] = ps + vs * tau - np.array([0.0, 0.0, 0.5 * G]) * tau * tau
            omega[sel] = 0.0 if j == 0 else rows["omega_f_radps"][idx[j - 1]]
        xyz += rng.normal(0.0, noise_sd_m, xyz.shape)
        samples = pd.DataFrame({"path_id": f"run{k}", "t_s": t, "x_m": xyz[:, 0],
                                "y_m": xyz[:, 1], "z_m": xyz[:, 2],
                                "omega_radps": omega})  # fmt: skip
        sub = {name: values[kept] for name, values in rows.items()}
        truth = impact_table3d(sub, list(material_names)).frame
        lat = []
        for i in kept:
            _, vi, vf = _vectors(rows, i)
            cross = vi[0] * vf[1] - vi[1] * vf[0]
            plan = min(np.hypot(*vi[:2]), np.hypot(*vf[:2]))
            lat.append(np.degrees(np.arctan2(cross, vi[0] * vf[0] + vi[1] * vf[1]))
                       if plan > 1e-9 else np.nan)  # fmt: skip
        truth["lateral_deg"] = lat
        truth["path_id"] = f"run{k}"
        out.append(SampledRun(samples, truth))
    return out


#: The analytic valley of :func:`valley_runs`: cells, size, material, body.
VALLEY_CELLS = (60, 120)
VALLEY_CELL_M = 1.0
VALLEY_E_N, VALLEY_E_T = 0.6, 0.85
VALLEY_MASS_KG, VALLEY_RADIUS_M, VALLEY_GYRATION_M = 100.0, 0.2, 0.126


def valley_ground(x_m, y_m):
    """The analytic valley's elevation [m]: dipping ~35 deg toward +x, curved
    across (so rocks are deflected sideways) and rippled along (varying dips)."""
    x, y = np.asarray(x_m, float), np.asarray(y_m, float)
    return 100.0 - 0.7 * x + 0.02 * (y - 30.0) ** 2 + 0.3 * np.sin(x / 7.0)


def valley_runs(
    *, fps: float, noise_sd_m: float, rocks: int = 8, seed: int = 2
) -> tuple:
    """Rocks of the 3-D simulator on the analytic valley, sampled with noise.

    Constant ``e_n`` 0.6, ``e_t`` 0.85 (no roughness, no trees), 100 kg, r 0.2 m;
    released 1 m above two points at 6 m/s down the valley (1 m/s SD) and 2 m/s
    across it (SD) with 2 m/s upward; the simulation uses seed 1, the sampling
    ``seed``; kept parts end before the first flight shorter than 0.25 s.

    Returns
    -------
    (Terrain, list[SampledRun])
    """
    from fieldkit.model.materials import Material
    from fieldkit.model.model3d import Model3D, Seeder3D
    from fieldkit.model.model_file import Body
    from fieldkit.model.simulate3d import simulate3d
    from fieldkit.model.terrain import Terrain

    ny, nx = VALLEY_CELLS
    c = VALLEY_CELL_M
    xc, yc = (np.arange(nx) + 0.5) * c, (np.arange(ny) + 0.5) * c
    terrain = Terrain(0.0, 0.0, c, valley_ground(*np.meshgrid(xc, yc)))
    model = Model3D(
        terrain=terrain,
        materials={"ground": Material("ground", VALLEY_E_N, VALLEY_E_T, 30.0)},
        material_index=np.zeros((ny, nx), np.int64),
        effects={},
        body=Body(VALLEY_MASS_KG, VALLEY_RADIUS_M, VALLEY_GYRATION_M),
        releases=np.array([[5.5, 25.0, 0.0], [5.5, 35.0, 0.0]]),
        release_weights=np.ones(2),
        seeder=Seeder3D(height_m=1.0, vx_mps=6.0, vz_mps=2.0, vx_sd_mps=1.0,
                        vy_sd_mps=2.0),  # fmt: skip
    )
    result = simulate3d(model, rocks, np.random.default_rng(1), record_impacts=True)
    runs = sampled_runs(result, fps=fps, noise_sd_m=noise_sd_m,
                        rng=np.random.default_rng(seed), min_flight_s=0.25)  # fmt: skip
    return terrain, runs


def write_site(folder, terrain, runs, *, samples_name: str = "trajectories.csv",
               dem_name: str = "valley.asc") -> tuple:  # fmt: skip
    """Write the runs' samples (CSV) and the DEM (ESRI ASCII grid) into ``folder``;
    returns their paths."""
    from pathlib import Path

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    ny, nx = terrain.shape
    rows = "\n".join(" ".join(f"{v:.9f}" for v in row) for row in terrain.z[::-1])
    dem = folder / dem_name
    dem.write_text(
        f"ncols {nx}\nnrows {ny}\nxllcorner {header_number_text(terrain.x0_m)}\n"
        f"yllcorner {header_number_text(terrain.y0_m)}\n"
        f"cellsize {header_number_text(terrain.cell_m)}\nNODATA_value -9999\n{rows}\n"
    )
    samples = folder / samples_name
    pd.concat([r.samples for r in runs]).to_csv(samples, index=False)
    return samples, dem


def drag_run(
    terrain,
    start_m,
    v_mps,
    *,
    drag_per_m: float,
    e_n: float,
    e_t: float,
    impacts: int,
    fps: float,
    noise_sd_m: float,
    rng: np.random.Generator,
    path_id: str = "drag",
) -> SampledRun:
    """A lumped mass bouncing on ``terrain`` with quadratic air drag (the 3-D
    simulator has none yet), sampled with noise; truth exact to the integration.

    Flights follow :func:`fieldkit.tracking.trajectory3d.flights.drag_path` (RK4,
    1 ms); a contact is where the centre's height above the DEM's bilinear surface
    changes sign (linear between steps); the rebound is ``-e_n vin N + e_t vit
    T`` with N the surface normal there and T along the incoming tangential
    velocity (the simulator's law without spin). The samples end at the contact
    after the last truth impact.
    """
    from fieldkit.tracking.trajectory3d.flights import drag_path

    p = np.asarray(start_m, float)
    v = np.asarray(v_mps, float)
    t0 = 0.0
    flights, rows = [], []
    horizon = np.arange(1, 6001) * 1e-3
    for k in range(impacts + 1):
        d, vel = drag_path(v, drag_per_m, horizon)
        pos = p + d
        h = pos[:, 2] - terrain.heights(pos[:, 0], pos[:, 1])
        i = int(np.flatnonzero(h < 0)[0])
        w = h[i - 1] / (h[i - 1] - h[i])
        tau = horizon[i - 1] + w * 1e-3
        flights.append((t0, p, v, t0 + tau))
        pc = pos[i - 1] + w * (pos[i] - pos[i - 1])
        vi = vel[i - 1] + w * (vel[i] - vel[i - 1])
        n = np.array(terrain.normal(pc[0], pc[1]))
        vin = float(vi @ n)
        vt = vi - vin * n
        tang = vt / np.linalg.norm(vt)
        vf = -e_n * vin * n + e_t * float(np.linalg.norm(vt)) * tang
        t0 += tau
        if k < impacts:
            cross = vi[0] * vf[1] - vi[1] * vf[0]
            rows.append({"path_id": path_id, "t_s": t0, "x_m": pc[0], "y_m": pc[1],
                         "z_m": pc[2], "e_n": e_n, "e_t": e_t,
                         "lateral_deg": float(np.degrees(np.arctan2(
                             cross, vi[0] * vf[0] + vi[1] * vf[1])))})  # fmt: skip
        p, v = pc, vf
    t = np.arange(rng.uniform(0.0, 1.0 / fps), flights[-1][3], 1.0 / fps)
    xyz = np.empty((t.size, 3))
    for ts, ps, vs, te in flights:
        sel = (t >= ts) & (t < te)
        if sel.any():
            xyz[sel] = ps + drag_path(vs, drag_per_m, t[sel] - ts)[0]
    xyz += rng.normal(0.0, noise_sd_m, xyz.shape)
    samples = pd.DataFrame({"path_id": path_id, "t_s": t, "x_m": xyz[:, 0],
                            "y_m": xyz[:, 1], "z_m": xyz[:, 2]})  # fmt: skip
    return SampledRun(samples, pd.DataFrame(rows))
