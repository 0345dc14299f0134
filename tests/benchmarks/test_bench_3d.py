"""The 3-D benchmark's set-up: same site for both codes, honest skips, the contract."""

from __future__ import annotations

import dataclasses
import importlib.util
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "benchmarks" / "bench_3d.py"
DEM = ROOT / "tests" / "data" / "tschamut2014" / "terrain.asc"


@dataclasses.dataclass(frozen=True)
class Terrain:
    """The contract's Terrain fields (a stand-in for fieldkit.model.terrain)."""

    x0_m: float
    y0_m: float
    cell_m: float
    z: np.ndarray
    crs: str | None = None


@dataclasses.dataclass(frozen=True)
class Seeder:
    """A 3-D seeder with the release velocity's fields (a stand-in)."""

    vx_mps: float
    vy_mps: float
    vz_mps: float
    vy_sd_mps: float = 1.0


@dataclasses.dataclass(frozen=True)
class Model3D:
    """The contract's Model3D fields (a stand-in)."""

    terrain: Terrain
    materials: dict
    material_index: np.ndarray
    effects: dict
    body: object
    releases: np.ndarray
    release_weights: np.ndarray
    seeder: Seeder
    core: dict
    trees: object = None


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_3d", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_3d"] = module
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop("bench_3d", None)


def test_platrock_grid_passes_through_the_cell_centres(bench, tmp_path):
    """PlatRock puts value (i, j) at xllcorner + i * cellsize: its copy of the DEM has
    the corner moved half a cell (2.5 m) so its vertices are the ESRI cell centres."""
    out = tmp_path / "dem.asc"
    bench.shifted_dem(out)
    got, want = out.read_text().splitlines(), DEM.read_text().splitlines()
    assert got[2] == "xllcorner -32.500000"
    assert got[3] == "yllcorner 87.500000"
    assert got[:2] + got[4:] == want[:2] + want[4:]


def test_release_is_run_v004_block_1(bench):
    site = bench.release()
    assert site["run"] == "v004"
    assert site["xyz_m"] == [33.4, 236.67, 76.276667]
    assert site["ground_z_m"] == 76.1
    assert site["v_mps"] == [0.74314, 1.3547, 0.76954]
    assert (site["mass_kg"], site["radius_m"]) == (69.0, 0.176667)


def test_observed_runouts_are_the_data_sets(bench):
    """80 runs, mean 98.4 m, 27.5-134.7 m (tests/data/tschamut2014/README.md)."""
    runout = bench.observed_runouts_m()
    assert len(runout) == 80
    assert round(float(runout.mean()), 1) == 98.4
    assert (round(float(runout.min()), 1), round(float(runout.max()), 1)) == (
        27.5,
        134.7,
    )


def test_platrock_skipped_without_gdal(bench, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(bench, "PLATROCK_VENV", tmp_path / "venv")
    monkeypatch.setattr(bench.shutil, "which", lambda name: None)
    assert bench.platrock_python() is None
    out = capsys.readouterr().out
    assert "PlatRock: skipped" in out and "gdal-config is not on the PATH" in out
    assert not (tmp_path / "venv").exists()


def test_platrock_skipped_when_pip_cannot_reach_the_index(
    bench, tmp_path, monkeypatch, capsys
):
    venv = tmp_path / "venv"
    monkeypatch.setattr(bench, "PLATROCK_VENV", venv)
    monkeypatch.setattr(bench.shutil, "which", lambda name: "/usr/bin/gdal-config")
    calls = []

    def run(command, **kwargs):
        calls.append(command)
        if command[0] == "/usr/bin/gdal-config":
            return subprocess.CompletedProcess(command, 0, "3.6.2\n", "")
        if "venv" in command:
            venv.mkdir(parents=True)
            return subprocess.CompletedProcess(command, 0, "", "")
        message = "ERROR: No matching distribution found for setuptools\n"
        return subprocess.CompletedProcess(command, 1, "", message)

    monkeypatch.setattr(bench.subprocess, "run", run)
    assert bench.platrock_python() is None
    out = capsys.readouterr().out
    assert "creating its venv" in out
    assert "pip cannot reach the package index" in out
    assert not venv.exists()  # no half-made venv is left to be taken as ready
    assert len(calls) == 3  # gdal-config, venv, the first pip install: then stop


def test_fieldkit_side_not_built_is_said(bench, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "fieldkit.model.simulate3d", None)
    assert bench.run_fieldkit(bench.release()) is None
    assert "the 3-D simulator is not built yet" in capsys.readouterr().out


def test_fieldkit_model_follows_the_contract(bench, monkeypatch):
    """The DEM as the contract's Terrain (row 0 = south), the release on the ground,
    its velocity in the seeder, block 1 as the body."""

    module = types.ModuleType("fieldkit.model.terrain")
    module.Terrain = Terrain
    monkeypatch.setitem(sys.modules, "fieldkit.model.terrain", module)
    monkeypatch.setattr(bench, "find_model3d", lambda: Model3D)
    model = bench.fieldkit_model(bench.release())

    rows = [line.split() for line in DEM.read_text().splitlines()[6:]]
    assert (model.terrain.x0_m, model.terrain.y0_m, model.terrain.cell_m) == (
        -35.0,
        85.0,
        5.0,
    )
    assert model.terrain.z.shape == (46, 43)
    assert model.terrain.z[0, 0] == float(rows[-1][0])  # south-west corner
    assert model.terrain.z[-1, -1] == float(rows[0][-1])  # north-east corner
    assert model.material_index.shape == (46, 43)
    assert model.releases.tolist() == [[33.4, 236.67, 76.1]]
    assert model.release_weights.tolist() == [1]
    assert model.seeder == Seeder(0.74314, 1.3547, 0.76954, 0.0)
    assert (model.body.mass_kg, model.body.radius_m) == (69.0, 0.176667)
    assert list(model.materials) == ["meadow"]
