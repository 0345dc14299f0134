"""3-D speed and runout: fieldkit's 3-D simulator beside PlatRock's ThreeD engine.

Site: the Tschamut 2014 terrain proxy (``tests/data/tschamut2014/terrain.asc``, 43 x 46
cells of 5 m) and one release, the first row of ``release_points.csv`` (run v004, block
1: 69 kg, radius 0.176667 m, the first tracked position and velocity). Both codes start
every rock there with that velocity.

fieldkit: ``fieldkit.model.simulate3d.simulate3d`` (the contract of issue 21) on the
Tschamut starting model (``examples/tschamut/model_base.json``: one material, e_n 1.0,
e_t 0.62, friction 19.29 deg, roughness SD 8 deg, slope_roughness on) over the whole
DEM, the release as its one release point (z = the ground), the seeder's height the
release's centre above the ground (the radius) and its velocity the release's, with no
spreads; timed by its own ``wall_s`` after a warm-up compile, on 1 and 2 numba
threads. If the 3-D simulator is not built yet, that is said and PlatRock's figures
are still printed.

PlatRock 0.4.6 (the open-source peer; GPL, never a dependency of fieldkit) runs in its
own venv, ``.bench/platrock-venv`` at the repository root, created on the first run
(a few minutes: PlatRock's GDAL bindings are compiled against the system's libgdal, so
``gdal-config`` must be on the PATH: Debian's ``libgdal-dev``). If pip cannot reach the
package index or GDAL is missing, that is said and PlatRock's side is skipped. It is
driven by ``benchmarks/platrock_threed_run.py`` (see its docstring for how and what it
changes), timing ``Simulation.run`` only (not the terrain's triangulation). Its
parameters, mapped from the same starting model: the Classical bounce model (v_n' =
-R_n v_n, v_t' = R_t v_t), R_n = 0.95 (e_n 1.0 capped at PlatRock's largest valid R_n),
R_t = e_t = 0.62, roughness = r tan(12.8 deg) = 0.040 m, so that PlatRock's random
normal tilt (uniform on [0, atan(roughness / r)]) has the mean absolute tilt of
fieldkit's normal tilt (half-normal, SD 8 deg: 6.4 deg); its time step the default 0.02
s. PlatRock has no sliding friction (rolling is a train of small Classical bounces,
one per time step in contact), so friction_deg has no counterpart. PlatRock puts the
grid's values at ``xllcorner + i * cellsize`` (the cell corners); it is handed a copy of
the grid with its corner moved by half a cell so that both codes' surfaces pass through
the same points (the cell centres, as ESRI ASCII defines them): fieldkit's surface is
bilinear between them, PlatRock's two planar triangles per grid square.

What is compared: impacts/s and rocks/s (fieldkit on 1 and 2 threads, PlatRock on one
core: it is single-threaded Python with Cython helpers), the ratio fieldkit / PlatRock
in impacts/s, and the runout (release to final position, in plan) of 1,000 rocks from
each, median and 95th percentile of the rocks that stopped on the DEM (those that left
it, or hit fieldkit's impact cap, are counted, not measured), beside the 80 observed
runs. An "impact" is not quite the same event in both: fieldkit counts impacts
(sliding and rolling are integrated between them), PlatRock every time step with a
rock-soil contact (its rolling is a train of such contacts); the bench prints how many
of PlatRock's contacts are bounces (no contact the step before) and the ratio on
those too. rocks/s depends on how far each code's rocks go, so it is printed beside
the runouts. Printed, not asserted (target of issue 21: fieldkit >= 100x PlatRock in
impacts/s).
"""

from __future__ import annotations

import csv
import dataclasses
import importlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import typing
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
DATA = ROOT / "tests" / "data" / "tschamut2014"
DEM = DATA / "terrain.asc"
BASE_MODEL = ROOT / "examples" / "tschamut" / "model_base.json"
PLATROCK_VERSION = "0.4.6"
PLATROCK_VENV = ROOT / ".bench" / "platrock-venv"
PLATROCK_DRIVER = HERE / "platrock_threed_run.py"
SEED = 21
SPEED_ROCKS = 10_000  # fieldkit's timed runs
RUNOUT_ROCKS = 1_000  # both codes' runout figure (PlatRock's run is also its timing)
THREADS = (1, 2)
PLATROCK_SOIL = {
    "bounce_model_number": 0,  # Classical
    "R_n": 0.95,  # e_n 1.0, capped at PlatRock's largest valid R_n
    "R_t": 0.62,  # e_t
    "roughness": round(0.176667 * float(np.tan(np.radians(12.8))), 4),  # 0.040 m
}
PLATROCK_DT_S = 0.02  # PlatRock's default time step


# --------------------------------------------------------------------------- site
def release() -> dict:
    """The first release of ``release_points.csv``: position, velocity, block."""
    with open(DATA / "release_points.csv", newline="", encoding="utf8") as handle:
        row = next(csv.DictReader(handle))
    return {
        "run": row["trajectory_id"],
        "xyz_m": [float(row["x_m"]), float(row["y_m"]), float(row["z_m"])],
        "ground_z_m": float(row["ground_z_m"]),
        "v_mps": [float(row["vx_mps"]), float(row["vy_mps"]), float(row["vz_mps"])],
        "block": row["block_id"],
        "mass_kg": float(row["mass_kg"]),
        "radius_m": float(row["radius_m"]),
    }


def observed_runouts_m() -> np.ndarray:
    """Plan distances release -> deposit of the 80 observed runs [m]."""

    def read(name: str) -> dict[str, tuple[float, float]]:
        with open(DATA / name, newline="", encoding="utf8") as handle:
            return {
                r["trajectory_id"]: (float(r["x_m"]), float(r["y_m"]))
                for r in csv.DictReader(handle)
            }

    starts, ends = read("release_points.csv"), read("observed_deposition.csv")
    runs = sorted(set(starts) & set(ends))
    return np.array([np.hypot(*np.subtract(ends[r], starts[r])) for r in runs])


def shifted_dem(path: Path) -> None:
    """Write the DEM with its corner moved half a cell NE (PlatRock's convention)."""
    lines = DEM.read_text(encoding="utf8").splitlines()
    header = {line.split()[0].lower(): float(line.split()[1]) for line in lines[:6]}
    half = 0.5 * header["cellsize"]
    out = []
    for line in lines:
        key = line.split()[0].lower() if line.strip() else ""
        if key in ("xllcorner", "yllcorner"):
            line = f"{key} {header[key] + half:.6f}"
        out.append(line)
    path.write_text("\n".join(out) + "\n", encoding="utf8")


def shown(path: Path) -> str:
    """``path`` relative to the repository when it is inside it."""
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def load() -> str:
    one, five, _ = os.getloadavg()
    return (
        f"load average {one:.2f} (1 min), {five:.2f} (5 min) on {os.cpu_count()} CPUs"
    )


def runout_line(
    name: str, distance_m: np.ndarray, stopped: np.ndarray, others: str = ""
) -> str:
    """Median and p95 of the stopped rocks' runouts; ``others``: the rest, said."""
    kept = np.asarray(distance_m)[np.asarray(stopped, bool)]
    figures = (
        "median {:6.1f} m, p95 {:6.1f} m".format(*np.percentile(kept, [50, 95]))
        if len(kept)
        else "none stopped"
    )
    return f"  {name:26s} {len(kept):5d} stopped: {figures}" + (
        f"; {others}" if others else ""
    )


# --------------------------------------------------------------------------- PlatRock
def platrock_python() -> Path | None:
    """PlatRock's venv python, created on first use; None (said why) if it cannot be."""
    python = PLATROCK_VENV / "bin" / "python"
    stamp = PLATROCK_VENV / ".installed"
    if stamp.exists() and stamp.read_text().strip() == PLATROCK_VERSION:
        return python
    gdal = shutil.which("gdal-config")
    if gdal is None:
        print(
            "PlatRock: skipped: its GDAL bindings build against the system's libgdal "
            "and gdal-config is not on the PATH (Debian: apt-get install libgdal-dev "
            "g++ python3-dev)"
        )
        return None
    gdal_version = subprocess.run(
        [gdal, "--version"], capture_output=True, text=True, check=True
    ).stdout.strip()
    print(
        f"PlatRock: creating its venv {shown(PLATROCK_VENV)} (first run "
        f"only, a few minutes): platrock=={PLATROCK_VERSION}, GDAL {gdal_version} "
        "bindings built with numpy",
        flush=True,
    )
    shutil.rmtree(PLATROCK_VENV, ignore_errors=True)
    pip = [
        str(python),
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
    ]
    steps = [
        [sys.executable, "-m", "venv", str(PLATROCK_VENV)],
        [*pip, "setuptools", "wheel", "numpy<2.1"],
        # its numpy support (gdal_array) needs numpy at build time: no build isolation
        # (and not a wheel cached by an earlier build without numpy: no cache)
        [
            *pip,
            "--no-build-isolation",
            "--no-cache-dir",
            f"gdal[numpy]=={gdal_version}",
        ],
        [*pip, f"platrock=={PLATROCK_VERSION}"],
        [str(python), "-c", "from osgeo import gdal_array; import platrock.ThreeD"],
    ]
    for step in steps:
        done = subprocess.run(step, capture_output=True, text=True)
        if done.returncode != 0:
            text = done.stdout + done.stderr
            network = any(
                s in text
                for s in (
                    "No matching distribution", "Could not find a version",
                    "Network is unreachable", "Failed to establish",
                    "Temporary failure in name resolution", "NewConnectionError",
                )
            )  # fmt: skip
            reason = (
                "pip cannot reach the package index"
                if network
                else (text.strip().splitlines() or ["(no message)"])[-1]
            )
            print(
                f"PlatRock: skipped: {' '.join(step[:1] + step[-1:])} failed: {reason}"
            )
            shutil.rmtree(PLATROCK_VENV, ignore_errors=True)
            return None
    stamp.write_text(PLATROCK_VERSION + "\n")
    return python


def run_platrock(python: Path, site: dict, rocks: int) -> dict | None:
    """PlatRock ThreeD on the site (a subprocess in its venv); None if it failed."""
    with tempfile.TemporaryDirectory(prefix="bench3d-platrock-") as tmp:
        work = Path(tmp)
        dem = work / "terrain_cell_centres.asc"
        shifted_dem(dem)
        setup = {
            "dem": str(dem),
            "release_xyz_m": site["xyz_m"],
            "release_v_mps": site["v_mps"],
            "mass_kg": site["mass_kg"],
            "radius_m": site["radius_m"],
            "soil": PLATROCK_SOIL,
            "rocks": rocks,
            "seed": SEED,
            "dt_s": PLATROCK_DT_S,
            "workdir": str(work / "run"),
        }
        (work / "setup.json").write_text(json.dumps(setup), encoding="utf8")
        done = subprocess.run(
            [str(python), str(PLATROCK_DRIVER), str(work / "setup.json")],
            capture_output=True, text=True,
        )  # fmt: skip
    if done.returncode != 0:
        tail = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        print(f"PlatRock: the run failed: {tail}")
        return None
    return json.loads(done.stdout.strip().splitlines()[-1])


# --------------------------------------------------------------------------- fieldkit
def find_model3d():
    """The contract's ``Model3D`` class, wherever the 3-D modules define it."""
    for name in (
        "fieldkit.model.simulate3d", "fieldkit.model.model3d",
        "fieldkit.model.model_file", "fieldkit.model.terrain",
    ):  # fmt: skip
        try:
            module = importlib.import_module(name)
        except ImportError:
            continue
        if hasattr(module, "Model3D"):
            return module.Model3D
    raise ImportError("no Model3D class in fieldkit.model")


def seeder_value(model3d_cls, site: dict):
    """The release velocity as the seeder type ``Model3D.seeder`` declares."""
    values = {
        # the rock's centre above the ground (the release file's z is the centre)
        "height_m": max(site["xyz_m"][2] - site["ground_z_m"], site["radius_m"]),
        "vx_mps": site["v_mps"][0], "vy_mps": site["v_mps"][1],
        "vz_mps": site["v_mps"][2], "omega_radps": 0.0,
        "vx_sd_mps": 0.0, "vy_sd_mps": 0.0, "vz_sd_mps": 0.0, "mass_sd_kg": 0.0,
    }  # fmt: skip
    try:
        seeder_type = typing.get_type_hints(model3d_cls).get("seeder")
    except Exception:  # an unresolvable annotation: fall back to a plain dict
        seeder_type = None
    for candidate in typing.get_args(seeder_type) or (seeder_type,):
        if dataclasses.is_dataclass(candidate):
            names = {f.name for f in dataclasses.fields(candidate)}
            return candidate(**{k: v for k, v in values.items() if k in names})
    return values


def fieldkit_model(site: dict):
    """The Tschamut starting model on the DEM, built to the issue-21 contract."""
    from fieldkit.io.dem import read_dem
    from fieldkit.model.model_file import model_from_dict
    from fieldkit.model.terrain import Terrain

    base = json.loads(BASE_MODEL.read_text(encoding="utf8"))
    base["body"] = {"mass_kg": site["mass_kg"], "radius_m": site["radius_m"]}
    two_d = model_from_dict(base, source=str(BASE_MODEL))
    grid = read_dem(DEM)
    cell = float(abs(grid.x_m[1] - grid.x_m[0]))
    terrain = Terrain(
        float(grid.x_m[0]) - 0.5 * cell, float(grid.y_m[-1]) - 0.5 * cell, cell,
        np.asarray(grid.values, dtype=float)[::-1], grid.crs,
    )  # fmt: skip
    model3d = find_model3d()
    fields = {
        "terrain": terrain,
        "materials": two_d.materials,
        "material_index": np.zeros(terrain.z.shape, dtype=np.int64),
        "effects": two_d.effects,
        "body": two_d.body,
        "releases": np.array([[*site["xyz_m"][:2], site["ground_z_m"]]]),
        "release_weights": np.array([1], dtype=np.int64),
        "seeder": seeder_value(model3d, site),
        "core": two_d.core,
        "trees": None,
        "crs": grid.crs,
        "provenance": {"benchmark": "benchmarks/bench_3d.py"},
        "source": f"{BASE_MODEL.name} on {DEM.name}",
    }
    names = {f.name for f in dataclasses.fields(model3d)}
    return model3d(**{k: v for k, v in fields.items() if k in names})


def run_fieldkit(site: dict) -> dict | None:
    """fieldkit's timed runs (1 and 2 threads) and its runout run; None if not built."""
    try:
        simulate3d = importlib.import_module("fieldkit.model.simulate3d").simulate3d
    except (ImportError, AttributeError) as error:
        print(
            "fieldkit: the 3-D simulator is not built yet "
            f"(fieldkit.model.simulate3d.simulate3d: {error}); PlatRock's side only"
        )
        return None
    try:
        model = fieldkit_model(site)
    except Exception as error:  # the contract's model not there yet: say, go on
        print(f"fieldkit: could not build the 3-D model to the contract: {error!r}")
        return None
    import numba

    from fieldkit.model.results import (
        EXITED_DOWNSLOPE,
        EXITED_UPSLOPE,
        MAX_IMPACTS,
        STOPPED,
    )

    simulate3d(model, 20, np.random.default_rng(0))  # warm-up (compile / load cache)
    out: dict = {"threads": {}}
    threads_before = numba.get_num_threads()
    try:
        for threads in THREADS:
            numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
            result = simulate3d(model, SPEED_ROCKS, np.random.default_rng(SEED))
            out["threads"][numba.get_num_threads()] = {
                "rocks": int(result.rocks),
                "impacts": int(result.impacts),
                "wall_s": float(result.wall_s),
            }
    finally:  # run_all.py runs the next benchmarks in this process
        numba.set_num_threads(threads_before)
    result = simulate3d(model, RUNOUT_ROCKS, np.random.default_rng(SEED))
    start = np.asarray(model.releases)[np.asarray(result.release_index)][:, :2]
    deposit = np.asarray(result.deposit_xyz)[:, :2]
    distance = np.hypot(*(deposit - start).T)
    state = np.asarray(result.state)
    left = np.count_nonzero((state == EXITED_DOWNSLOPE) | (state == EXITED_UPSLOPE))
    capped = np.count_nonzero(state == MAX_IMPACTS)
    out["runout"] = (
        distance,
        state == STOPPED,
        f"left the DEM {left}, capped {capped}",
    )
    return out


# --------------------------------------------------------------------------- main
def main() -> None:
    site = release()
    print(load())
    print(
        f"site: Tschamut 2014 terrain proxy ({shown(DEM)}); release of run "
        f"{site['run']} at x {site['xyz_m'][0]:.2f}, y {site['xyz_m'][1]:.2f} m, "
        f"v ({', '.join(f'{v:.2f}' for v in site['v_mps'])}) m/s; block "
        f"{site['block']}: {site['mass_kg']:g} kg, radius {site['radius_m']:g} m"
    )
    fieldkit = run_fieldkit(site)
    platrock = None
    python = platrock_python()
    if python is not None:
        print(
            f"PlatRock {PLATROCK_VERSION} ThreeD: {RUNOUT_ROCKS} rocks, Classical "
            f"R_n {PLATROCK_SOIL['R_n']}, R_t {PLATROCK_SOIL['R_t']}, roughness "
            f"{PLATROCK_SOIL['roughness']} m, dt {PLATROCK_DT_S} s (one core) ...",
            flush=True,
        )
        platrock = run_platrock(python, site, RUNOUT_ROCKS)

    print(
        f"\n{'code':24s} {'threads':>7s} {'rocks':>7s} {'impacts':>9s} "
        f"{'impacts/s':>11s} {'rocks/s':>10s} {'s':>7s}"
    )
    if fieldkit is not None:
        for threads, row in fieldkit["threads"].items():
            rate = row["impacts"] / row["wall_s"]
            rocks_per_s = row["rocks"] / row["wall_s"]
            print(
                f"{'fieldkit simulate3d':24s} {threads:7d} {row['rocks']:7d} "
                f"{row['impacts']:9d} {rate:11,.0f} {rocks_per_s:10,.1f} "
                f"{row['wall_s']:7.2f}"
            )
    if platrock is not None:
        wall = platrock["wall_s"]
        p_rate = platrock["impacts"] / wall
        print(
            f"{'PlatRock ThreeD':24s} {1:7d} {platrock['rocks']:7d} "
            f"{platrock['impacts']:9d} {p_rate:11,.0f} "
            f"{platrock['rocks'] / wall:10,.1f} {wall:7.2f}"
        )
        print(
            f"  PlatRock: {platrock['steps']:,} time steps of {PLATROCK_DT_S} s "
            f"({platrock['steps'] / wall:,.0f} steps/s); its impacts are rock-soil "
            f"contacts, one per time step in contact, {platrock['bounces']:,} of them "
            "bounces (no contact the step before); terrain build "
            f"{platrock['build_s']:.2f} s, not timed"
        )
        for threads, row in (fieldkit or {"threads": {}})["threads"].items():
            rate = row["impacts"] / row["wall_s"]
            per_bounce = rate / (platrock["bounces"] / wall)
            print(
                f"fieldkit ({threads} thread{'s' if threads > 1 else ''}) / PlatRock "
                f"in impacts/s: {rate / p_rate:,.0f}x (target >= 100x); against "
                f"PlatRock's bounces/s: {per_bounce:,.0f}x"
            )
    print(load())

    print("\nrunout, release to final position in plan:")
    observed = observed_runouts_m()
    print(runout_line("observed (80 runs)", observed, np.ones(len(observed), bool)))
    if fieldkit is not None:
        print(runout_line("fieldkit simulate3d", *fieldkit["runout"]))
    if platrock is not None:
        deposit = np.asarray(platrock["deposit_xyz_m"])[:, :2]
        distance = np.hypot(*(deposit - site["xyz_m"][:2]).T)
        stopped = ~np.asarray(platrock["left_dem"], bool)
        left = f"left the DEM {np.count_nonzero(~stopped)}"
        print(runout_line("PlatRock ThreeD", distance, stopped, left))


if __name__ == "__main__":
    start = time.perf_counter()
    main()
    print(f"bench_3d: {time.perf_counter() - start:.0f} s")
