"""Run PlatRock's ThreeD engine on one DEM and one release point; print a JSON summary.

Run by ``benchmarks/bench_3d.py`` with the python of PlatRock's own venv (never the
project's): ``python platrock_threed_run.py SETUP.json``. Not a benchmark itself (its
name does not start with ``bench_``, so ``benchmarks/run_all.py`` does not run it).

SETUP.json keys: ``dem`` (ESRI ASCII grid path), ``release_xyz_m`` (rock centre, world
coordinates), ``release_v_mps`` (vx, vy, vz), ``mass_kg``, ``radius_m``, ``soil``
(PlatRock face parameters: ``bounce_model_number``, ``R_n``, ``R_t``, ``roughness``,
...), ``rocks``, ``seed``, ``dt_s``, ``workdir``.

PlatRock ThreeD (``platrock.ThreeD.Simulations.Simulation``) is a time-stepped
simulator: a sphere over the DEM triangulated into two faces per grid square (the
vertices are the grid values), explicit ballistic steps of ``dt``, Verlet lists of
nearby faces, sphere-face contact detection (face, edge, vertex); on contact the face's
bounce model (0 Classical: v_n' = -R_n v_n, v_t' = R_t v_t about a normal tilted at
random by up to atan(roughness / radius)), then the sphere is pushed out of the face
along z. A rock stops when it has at least two contacts and |v| < 0.2 m/s, and leaves
when its centre drops below the DEM's lowest point. Only the release polygon's
``z``/``vz`` set the start in PlatRock; here the start (position and velocity) is set
exactly as given, by overriding ``setup_rock_kinematics``. Every simulation also builds
the rock-tree model (``Toe_Tree_2022``), which downloads a data table on first use;
there is no forest here, so that constructor is replaced by a stub (the only other
change; no network needed).

The JSON printed on the last line of stdout: ``wall_s`` (``Simulation.run`` only, not
the terrain build; it includes PlatRock's per-run set-up, the soil parameters put on
the faces: 0.02 s for the 3,780 faces of Tschamut), ``build_s``, ``rocks``,
``impacts`` (rock-soil contacts, PlatRock's ``Outputs.SOIL`` rows: one per time step
in contact), ``bounces`` (those contacts not preceded by a contact at the step
before), ``steps`` (time steps), ``deposit_xyz_m`` (world coordinates of the last
position), ``left_dem`` (per rock: it left the DEM), ``platrock_version``.
"""

from __future__ import annotations

import json
import os
import sys
import time


def main(setup_path: str) -> None:
    with open(setup_path, encoding="utf8") as handle:
        setup = json.load(handle)
    os.makedirs(setup["workdir"], exist_ok=True)
    os.chdir(setup["workdir"])  # PlatRock writes its log/results beside the cwd

    import numpy as np
    import platrock
    import shapely.geometry
    from platrock.Common import BounceModels, Debug, Math, Outputs
    from platrock.ThreeD import Objects, Simulations

    Debug.current_level = Debug.ERROR  # its INFO log per step would time the console

    def no_forest_table(self):
        """No forest here: skip the rock-tree model's table (downloaded at run time)."""
        self.data_file = None
        self.last_computed_data = {}

    BounceModels.Toe_Tree_2022.__init__ = no_forest_table

    release = np.asarray(setup["release_xyz_m"], dtype=float)
    velocity = np.asarray(setup["release_v_mps"], dtype=float)
    radius = float(setup["radius_m"])
    volume = 4.0 / 3.0 * np.pi * radius**3
    density = float(setup["mass_kg"]) / volume

    steps = []  # time steps per rock
    soil_steps = []  # (rock, time step) of every rock-soil contact

    class Run(Simulations.Simulation):
        """PlatRock's ThreeD simulation with an exact start (position, velocity)."""

        def setup_rock_kinematics(self):
            terrain = self.terrain
            local = release - [
                terrain.Z_raster.xllcorner,
                terrain.Z_raster.yllcorner,
                0,
            ]
            self.current_rock.setup_kinematics(
                pos=local.copy(), vel=Math.Vector3(velocity.copy()),
                angVel=[0, 0, 0], ori=[0, 0, 0],
            )  # fmt: skip

        def after_rock_propagation_tasks(self, *args, **kwargs):
            steps.append(self.iter)
            super().after_rock_propagation_tasks(*args, **kwargs)

    add_contact = Outputs.Output.add_contact

    def add_contact_noting_step(output, rock, normal, type_):
        """PlatRock's add_contact, noting the time step of a rock-soil contact."""
        if type_ == Outputs.SOIL:
            soil_steps.append((sim.current_rock_number, sim.iter))
        add_contact(output, rock, normal, type_)

    Outputs.Output.add_contact = add_contact_noting_step  # per contact, not per step

    start = time.perf_counter()
    terrain = Objects.Terrain(DEM_asc=setup["dem"])
    # ThreeD's Terrain(default_faces_params=...) does not reach the faces in 0.4.6
    # (its parent class is called without them, so every face gets the descriptors'
    # defaults); soil parameters go in as one polygon over the whole DEM instead, as
    # a soil geojson would (world coordinates; PlatRock shifts them as it runs).
    raster = terrain.Z_raster
    x0, y0 = raster.xllcorner, raster.yllcorner
    span = (raster.nx + raster.ny) * raster.cell_length
    soil = {
        d.inst_name: d.type_(setup["soil"].get(d.inst_name, d.default_value))
        for d in Objects.Terrain.valid_input_soil_geojson_attrs.parameters
    }
    terrain.soil_params = [
        {
            "shapely_polygon": shapely.geometry.box(
                x0 - span, y0 - span, x0 + span, y0 + span
            ),
            "params": soil,
            "color": [0.5, 0.5, 0.5],
        }
    ]
    terrain._geojson_polygon_soil_offset_applied = False
    sim = Run(
        terrain=terrain, random_seed=int(setup["seed"]), dt=float(setup["dt_s"]),
        name="platrock_threed",
    )  # fmt: skip
    half = 0.05  # a 10 cm square around the release (the start is set exactly above)
    local_xy = release[:2]  # the start polygon, in world coordinates like the soil's
    sim.rocks_start_params = [
        {
            "shapely_polygon": shapely.geometry.box(
                local_xy[0] - half,
                local_xy[1] - half,
                local_xy[0] + half,
                local_xy[1] + half,
            ),  # fmt: skip
            "params": {
                "number": int(setup["rocks"]),
                "z": 0.0,
                "vz": float(velocity[2]),
                "rocks_min_vol": volume,
                "rocks_max_vol": volume,
                "density": density,
            },  # fmt: skip
            "color": [0.5, 0.5, 0.5],
        }
    ]
    sim.__init_arrays__()
    build = time.perf_counter() - start

    start = time.perf_counter()
    sim.run()
    wall = time.perf_counter() - start
    if sim.status != "finished":
        raise SystemExit(f"PlatRock ThreeD run ended with status {sim.status!r}")

    # a bounce: a contact whose rock was not in contact at the step before (rolling
    # is a train of contacts at successive steps)
    noted = np.array(soil_steps, dtype=np.int64).reshape(-1, 2)
    continued = (np.diff(noted[:, 0]) == 0) & (np.diff(noted[:, 1]) == 1)
    bounces = int(len(noted) - np.count_nonzero(continued))
    impacts = 0
    left = []
    deposits = []
    for contacts in sim.output.contacts:
        types = contacts[:, 0].astype(int)
        impacts += int(np.count_nonzero(types == Outputs.SOIL))
        left.append(bool(types[-1] == Outputs.OUT))
        x, y, z = (float(v) for v in contacts[-1, 1:4])
        deposits.append([x + x0, y + y0, z])
    print(
        json.dumps(
            {
                "platrock_version": platrock.version,
                "rocks": len(sim.output.contacts),
                "impacts": impacts,
                "bounces": bounces,
                "steps": int(sum(steps)),
                "left_dem": left,
                "wall_s": wall,
                "build_s": build,
                "deposit_xyz_m": deposits,
            }
        )  # fmt: skip
    )


if __name__ == "__main__":
    main(sys.argv[1])
