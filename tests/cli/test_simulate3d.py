"""`fieldkit simulate` on a 3-D model file (a terrain block), with fabricated
kernel results: straight sampled paths whose crossings, cells and values are known.

The 3-D kernel is reached through one function
(:func:`fieldkit.model.results3d.simulator3d`); these tests replace it so the
model file, the outputs and the command are checked on their own.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fieldkit.model.results import STOPPED

X0, Y0, CELL, NY, NX = 1000.0, 2000.0, 5.0, 20, 16
MASS_KG = 100.0


@dataclass
class FakeResult3D:
    """The fields of the 3-D result contract the outputs read."""

    rocks: int
    release_index: np.ndarray
    deposit_xyz: np.ndarray
    state: np.ndarray
    path_offsets: np.ndarray
    path: dict
    impacts: int = 0
    wall_s: float = 0.01
    seed: int | None = None
    impacts_per_rock: np.ndarray = field(default_factory=lambda: np.zeros(0))


def fake_result(paths: list[np.ndarray], releases: list[int]) -> FakeResult3D:
    """Rocks along the given plan polylines ``(k, 2)``: speed = plan distance
    travelled [m/s], ke = 1/2 m v^2, bounce height = 1 + distance / 100; z on the
    test plane; each rock stops at its last sample."""
    cols = {k: [] for k in ("x_m", "y_m", "z_m", "speed_mps", "ke_j", "re_j",
                            "height_m")}  # fmt: skip
    offsets = [0]
    for xy in paths:
        d = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])
        cols["x_m"].append(xy[:, 0])
        cols["y_m"].append(xy[:, 1])
        cols["z_m"].append(plane_z(xy[:, 0], xy[:, 1]) + 1.0)
        cols["speed_mps"].append(d)
        cols["ke_j"].append(0.5 * MASS_KG * d**2)
        cols["re_j"].append(np.zeros_like(d))
        cols["height_m"].append(1.0 + d / 100)
        offsets.append(offsets[-1] + len(xy))
    path = {k: np.concatenate(v) for k, v in cols.items()}
    ends = np.array([xy[-1] for xy in paths])
    n = len(paths)
    return FakeResult3D(
        rocks=n,
        release_index=np.array(releases),
        deposit_xyz=np.column_stack([ends, plane_z(ends[:, 0], ends[:, 1])]),
        state=np.full(n, STOPPED),
        path_offsets=np.array(offsets, np.int64),
        path=path,
        impacts=3 * n,
        impacts_per_rock=np.full(n, 3),
    )


def fake_impact_rows(result: FakeResult3D) -> dict[str, np.ndarray]:
    """Three impacts per rock at its first three samples, on the test plane (dip
    atan 0.5 to the south), travelling south: vin -5, vit 3, vfn 2.5, vft 2.4."""
    a = np.asarray(result.path_offsets)[:-1]
    at = np.concatenate([a + k for k in range(3)])
    at.sort()
    n = at.size
    s = np.sqrt(1.25)
    full = lambda v: np.full(n, float(v))  # noqa: E731
    return {
        "rock": np.repeat(np.arange(result.rocks), 3), "t_s": np.tile([1.0, 2, 3],
        result.rocks), "x_m": result.path["x_m"][at],
        "y_m": result.path["y_m"][at], "z_m": result.path["z_m"][at] - 1.0,
        "material_index": np.zeros(n, np.int64), "vin_mps": full(-5),
        "vit_mps": full(3), "vfn_mps": full(2.5), "vft_mps": full(2.4),
        "omega_i_radps": full(0), "omega_f_radps": full(-12), "normal_x": full(0),
        "normal_y": full(-0.5 / s), "normal_z": full(1 / s), "tangent_x": full(0),
        "tangent_y": full(-1 / s), "tangent_z": full(-0.5 / s),
        "mass_kg": full(MASS_KG), "radius_m": full(0.2), "gyration_m": full(0.126),
        "tree_strike": full(0),
    }  # fmt: skip


def plane_z(x, y):
    """The test DEM: a plane rising 0.5 m per metre northwards."""
    return 0.5 * (np.asarray(y) - Y0) + 0.0 * np.asarray(x)


def straight(x, y0, y1, step=1.0) -> np.ndarray:
    """A path from (x, y0) to (x, y1) sampled every ``step`` m."""
    n = int(round(abs(y1 - y0) / step))
    return np.column_stack([np.full(n + 1, x), np.linspace(y0, y1, n + 1)])


@pytest.fixture()
def site(tmp_path) -> Path:
    """A 16 x 20-cell DEM of 5 m cells from (1000, 2000) with a CRS (.prj), and a
    3-D model file releasing at (1020.5, 2080.5) and (1032.5, 2090.5)."""
    from rasterio.crs import CRS

    xc = X0 + CELL * (np.arange(NX) + 0.5)
    yc = Y0 + CELL * (np.arange(NY) + 0.5)
    z = plane_z(*np.meshgrid(xc, yc))[::-1]  # row 0 north in the file
    rows = "\n".join(" ".join(f"{v:.3f}" for v in row) for row in z)
    dem = tmp_path / "terrain.asc"
    dem.write_text(
        f"ncols {NX}\nnrows {NY}\nxllcorner {X0}\nyllcorner {Y0}\ncellsize {CELL}\n"
        f"NODATA_value -9999\n{rows}\n"
    )
    (tmp_path / "terrain.prj").write_text(CRS.from_epsg(2056).to_wkt())
    (tmp_path / "releases.csv").write_text("x_m,y_m,count\n1020.5,2080.5,1\n"
                                           "1032.5,2090.5,2\n")  # fmt: skip
    write_model(tmp_path / "model3d.json", {})
    return tmp_path


def write_model(path: Path, changes: dict, drop: tuple[str, ...] = ()) -> Path:
    data = {
        "terrain": {"dem": "terrain.asc", "materials": "grass",
                    "releases": "releases.csv"},
        "materials": {"grass": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30}},
        "body": {"mass_kg": MASS_KG, "radius_m": 0.2},
    }  # fmt: skip
    for key, value in changes.items():
        *head, last = key.split(".")
        target = data
        for part in head:
            target = target[part]
        target[last] = value
    for key in drop:
        *head, last = key.split(".")
        target = data
        for part in head:
            target = target[part]
        del target[last]
    path.write_text(json.dumps(data))
    return path


@pytest.fixture()
def kernel(monkeypatch):
    """Replace the 3-D kernel by fabricated paths: ``kernel.paths`` (set by the
    test) or, by default, every rock straight south 50 m from its release."""
    import fieldkit.model.results3d as results3d

    class Fake:
        paths: list[np.ndarray] | None = None
        releases: list[int] | None = None
        nan_height_at: int | None = None  # a path sample whose height is NaN
        calls: list = []

        def __call__(self, model, rocks, rng, *, sample_m=None,
                     record_impacts=False, on_impact_rows=None):  # fmt: skip
            self.calls.append((model, rocks))
            if self.paths is not None:
                result = fake_result(self.paths, self.releases or [0] * len(self.paths))
                if self.nan_height_at is not None:
                    result.path["height_m"][self.nan_height_at] = np.nan
            else:
                starts = model.releases
                which = [i % len(starts) for i in range(rocks)]
                paths = [straight(x, y, y - 50) for x, y, _z in starts[which]]
                result = fake_result(paths, which)
            if record_impacts:
                on_impact_rows(fake_impact_rows(result))
            return result

    fake = Fake()
    monkeypatch.setattr(results3d, "simulator3d", lambda: fake)
    return fake


def test_line_crossing_counted_once_with_its_values(cli, site, kernel, tmp_path):
    """A rock crossing y = 2050 southwards at 30 m, back north across it at 45 m
    and south again is counted once, at its first crossing (speed 30 m/s, KE
    1/2 m 30^2, height 1.3 m); a rock stopping short never passes."""
    there_and_back = np.concatenate([
        straight(1020.5, 2080.5, 2040.5),
        straight(1020.5, 2040.5, 2060.5)[1:],
        straight(1020.5, 2060.5, 2030.5)[1:],
    ])  # fmt: skip
    kernel.paths = [there_and_back, straight(1032.5, 2090.5, 2070.5)]
    kernel.releases = [0, 1]
    out = tmp_path / "out"
    result = cli("simulate", site / "model3d.json", "--rocks", "2", "--seed", "3",
                 "--line", "1000,2050.5,1080,2050.5", "--summary",
                 out / "summary.json")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    s = json.loads((out / "summary.json").read_text())
    line = s["lines"][0]
    assert line["passing"] == 1
    assert line["passing_fraction"] == 0.5
    assert line["passing_fraction_se"] == pytest.approx(np.sqrt(0.25 / 2))
    assert line["speed_mps"]["p50"] == pytest.approx(30.0)
    assert line["ke_j"]["p99"] == pytest.approx(0.5 * MASS_KG * 30.0**2)
    assert line["height_m"]["p95"] == pytest.approx(1.3)
    assert s["rocks"] == 2 and s["seed"] == 3 and s["dimension"] == 3
    assert s["final_state"] == {"stopped": 2, "left_dem": 0, "capped": 0}
    assert "line 1: passing 0.500" in result.stdout
    assert f"wrote {out / 'summary.json'}" in result.stdout


def test_line_crossing_between_samples_is_interpolated(cli, site, kernel, tmp_path):
    """Samples 10 m apart straddling the line: the crossing's values are linear
    between them (speed 25 m/s at y = 2055.5, 25 m from the start)."""
    kernel.paths = [straight(1020.5, 2080.5, 2030.5, step=10.0)]
    out = tmp_path / "o"
    result = cli("simulate", site / "model3d.json", "--rocks", "1", "--seed", "1",
                 "--line", "1000,2055.5,1040,2055.5", "--summary",
                 out / "s.json")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    line = json.loads((out / "s.json").read_text())["lines"][0]
    assert line["passing"] == 1
    assert line["speed_mps"]["p50"] == pytest.approx(25.0)


def test_rasters_georeferenced_on_the_dem_grid(cli, site, kernel, tmp_path):
    """A rock sampled at one point (1012.5, 2047.5) lands in the cell of column 2,
    row 9 from the south; the GeoTIFFs carry the DEM's transform and CRS."""
    import rasterio
    from rasterio.crs import CRS
    from rasterio.transform import Affine

    kernel.paths = [np.array([[1012.5, 2047.5]])]
    out = tmp_path / "r"
    result = cli("simulate", site / "model3d.json", "--rocks", "1", "--seed", "1",
                 "--rasters", out)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    for name in ("passing_count", "max_ke_j", "max_height_m",
                 "deposit_density_per_m2"):  # fmt: skip
        assert f"wrote {out / (name + '.tif')}" in result.stdout
    with rasterio.open(out / "passing_count.tif") as src:
        assert src.transform == Affine(CELL, 0, X0, 0, -CELL, Y0 + NY * CELL)
        assert src.crs == CRS.from_epsg(2056)
        assert (src.height, src.width) == (NY, NX)
        count = src.read(1)
        row, col = src.index(1012.5, 2047.5)
    assert (row, col) == (NY - 1 - 9, 2)
    assert count[row, col] == 1 and count.sum() == 1
    with rasterio.open(out / "deposit_density_per_m2.tif") as src:
        density = src.read(1)
    assert density[row, col] == pytest.approx(1 / CELL**2)
    assert density.sum() == pytest.approx(1 / CELL**2)
    with rasterio.open(out / "max_height_m.tif") as src:
        height = src.read(1)
    assert height[row, col] == pytest.approx(1.0)
    assert np.isnan(height).sum() == NY * NX - 1


def test_passing_count_counts_a_rock_once_per_cell(cli, site, kernel, tmp_path):
    """A path 50 m south, sampled every 20 m, crosses 11 cells (its start cell and
    ten more): each counts it once, though several samples or pieces lie there;
    the largest KE in the last cell is the rock's at the end."""
    import rasterio

    kernel.paths = [straight(1021.0, 2081.0, 2031.0, step=25.0)]
    out = tmp_path / "r"
    result = cli("simulate", site / "model3d.json", "--rocks", "1", "--seed", "1",
                 "--rasters", out)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    with rasterio.open(out / "passing_count.tif") as src:
        count = src.read(1)[::-1]  # row 0 south
    with rasterio.open(out / "max_ke_j.tif") as src:
        ke = src.read(1)[::-1]
    assert count.sum() == 11 and count.max() == 1
    assert count[6:17, 4].tolist() == [1] * 11
    assert ke[6, 4] == pytest.approx(0.5 * MASS_KG * 50.0**2)


def test_all_outputs_written_once_each(cli, site, kernel, tmp_path):
    """Deposits CSV (one row per rock), rasters, map.png and the recording; every
    file named on a `wrote` line; the release weights of the CSV's count column."""
    (tmp_path / "observed.csv").write_text("x_m,y_m\n1020,2035\n1030,2040\n")
    out = tmp_path / "all"
    result = cli(
        "simulate", site / "model3d.json", "--rocks", "6", "--seed", "2",
        "--line", "1000,2050,1080,2050", "--observed", tmp_path / "observed.csv",
        "--summary", out / "summary.json", "--deposits", out / "deposits.csv",
        "--rasters", out / "rasters", "--figures", out / "figures",
        "--rrd", out / "sim.rrd",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    written = [ln[len("wrote "):] for ln in result.stdout.splitlines()
               if ln.startswith("wrote ")]  # fmt: skip
    assert len(written) == 8 and len(set(written)) == 8
    for path in written:
        assert Path(path).stat().st_size > 0
    deposits = pd.read_csv(out / "deposits.csv")
    assert list(deposits.columns) == ["rock", "release", "x_m", "y_m", "z_m", "state"]
    assert deposits["rock"].tolist() == list(range(6))
    assert deposits["state"].eq("stopped").all()
    assert deposits["y_m"].iloc[0] == pytest.approx(2080.5 - 50)
    ((model, rocks),) = kernel.calls
    assert rocks == 6 and model.release_weights.tolist() == [1, 2]
    assert model.releases[1].tolist() == pytest.approx([1032.5, 2090.5, 45.25])
    s = json.loads((out / "summary.json").read_text())
    assert s["deposits"]["distance_m"]["p50"] == pytest.approx(50.0)
    from rerun.chunk import RrdReader

    summary = RrdReader(out / "sim.rrd").store().summary()
    entities = {line.split(" ", 1)[0] for line in summary.splitlines()}
    assert {"/terrain/dem", "/terrain/deposits", "/terrain/observed"} <= entities
    assert {f"/terrain/trajectories/{i}" for i in range(6)} <= entities


def test_model_file_lines_used_and_stated(cli, site, kernel, tmp_path):
    write_model(site / "lined.json", {"analysis_lines": [
        {"name": "road", "xy_m": [[1000, 2050.5], [1080, 2050.5]]}]})  # fmt: skip
    result = cli("simulate", site / "lined.json", "--rocks", "2", "--seed", "1")
    assert result.exit_code == 0, result.stderr
    assert "--line not given: analysis lines from the model file, road" in (
        result.stderr
    )
    assert "road: passing 1.000" in result.stdout


@pytest.mark.parametrize(
    ("changes", "drop", "words"),
    [
        ({}, ("terrain.dem",), ("model3d.json", "terrain.dem", "missing")),
        ({"terrain.dem": "nowhere.asc"}, (), ("terrain.dem", "file not found")),
        ({"terrain.materials": "rock"}, (),
         ("terrain.materials", "neither a material", "grass")),
        ({"terrain.materials": [{"material": "grass",
                                 "polygon": [[1000, 2000], [1040, 2000],
                                             [1040, 2040]]}]}, (),
         ("terrain.materials", "outside every polygon")),
        ({"terrain.materials": [{"material": "gras"}]}, (),
         ("terrain.materials[0].material", "'gras'")),
        ({"terrain.releases": [[900, 2050]]}, (),
         ("terrain.releases[0]", "(900, 2050) is off the DEM")),
        ({"terrain.releases": [[1010, 2050, 3]]}, (),
         ("terrain.releases", "[x, y] pairs")),
        ({"terrain.profile": 1}, (), ("terrain.profile", "unknown field")),
        ({"profile": {}}, (), ("profile", "unknown field")),
        ({"analysis_lines": [{"xy_m": [[1000, 2050]]}]}, (),
         ("analysis_lines[0].xy_m", "at least 2")),
        ({"seeder": {"vy_mps": 500}}, (), ("seeder.vy_mps", "100")),
        ({"analysis_lines": [{"xy_m": [[0, 0], [10, 50]]}]}, (),
         ("analysis_lines[0].xy_m", "never enters the DEM (x 1000 to 1080 m")),
    ],
)  # fmt: skip
def test_bad_terrain_block_one_line(cli, fails, site, kernel, changes, drop, words):
    out = site / "out"
    write_model(site / "model3d.json", changes, drop)
    result = cli("simulate", site / "model3d.json", "--rocks", "2", "--seed", "1",
                 "--summary", out / "summary.json")  # fmt: skip
    fails(result, *words)
    assert result.exit_code == 1
    assert not out.exists() and not kernel.calls


def test_release_csv_row_off_the_dem_named(cli, fails, site, kernel):
    (site / "releases.csv").write_text("x_m,y_m\n1020,2050\n2020,2050\n")
    fails(cli("simulate", site / "model3d.json", "--rocks", "2"),
          "releases.csv", "row 3", "(2020, 2050) is off the DEM")  # fmt: skip


def test_material_raster_not_on_the_dem_grid(cli, fails, site, kernel):
    (site / "materials.asc").write_text(
        "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 5\n0 0\n0 0\n"
    )
    write_model(site / "model3d.json", {"terrain.materials": "materials.asc"})
    fails(cli("simulate", site / "model3d.json", "--rocks", "2"),
          "terrain.materials", "not on the DEM's grid")  # fmt: skip


def test_option_for_the_other_dimension_refused(cli, fails, site, kernel, repo):
    fails(cli("simulate", site / "model3d.json", "--at", "5"),
          "--at", "is for a profile model", "describes a DEM")  # fmt: skip
    fails(cli("simulate", site / "model3d.json", "--line", "1000,2050,1000"),
          "--line", "x1,y1,x2,y2")  # fmt: skip
    fails(cli("simulate", repo / "examples/tschamut/model_base.json",
              "--line", "0,0,1,1"),
          "--line", "is for a terrain (3-D) model")  # fmt: skip
    assert not kernel.calls


def test_material_polygons_and_rest(site):
    """Polygons: a cell takes the last polygon holding its centre; one item
    without a polygon names the material of every other cell."""
    from fieldkit.model.model_file import read_model

    write_model(site / "poly.json", {
        "materials.rock": {"e_n": 0.3, "e_t": 0.9, "friction_deg": 40},
        "terrain.materials": [
            {"material": "grass"},
            {"material": "rock", "polygon": [[1000, 2050], [1080, 2050],
                                             [1080, 2100], [1000, 2100]]},
        ]})  # fmt: skip
    model = read_model(site / "poly.json", terrain=True)
    assert model.material_index.shape == (NY, NX)
    assert (model.material_index[:10] == 0).all()  # south of y = 2050: grass
    assert (model.material_index[10:] == 1).all()
    assert model.crs == model.terrain.crs and "2056" in model.crs


def test_tschamut_example_model(repo):
    """examples/tschamut/model_3d.json: the DEM, one material, the 80 releases."""
    from fieldkit.model.model_file import read_model

    model = read_model(repo / "examples/tschamut/model_3d.json", terrain=True)
    assert model.terrain.shape == (46, 43)
    assert (model.terrain.x0_m, model.terrain.y0_m, model.terrain.cell_m) == (
        -35.0, 85.0, 5.0)  # fmt: skip
    assert model.releases.shape == (80, 3) and model.release_weights.sum() == 80
    base = json.loads((repo / "examples/tschamut/model_base.json").read_text())
    assert model.materials["meadow"].e_t == base["materials"]["meadow"]["e_t"]
    assert list(model.effects) == ["slope_roughness"]
    assert model.body.mass_kg == 69.0


def test_help_example_3d_runs(cli, kernel, repo_copy, shell_commands, run_shell):
    """The 3-D example of `simulate --help`, pasted at the repository root, runs
    (kernel fabricated) and writes every file it names."""
    text = cli("simulate", "--help").output
    lines = [c for c in shell_commands(text) if "model_3d.json" in c]
    assert len(lines) == 1
    code, output = run_shell(lines[0], repo_copy)
    assert code == 0, output
    for name in ("summary.json", "deposits.csv", "impacts.csv",
                 "rasters/max_ke_j.tif", "figures/map.png", "sim.rrd"):  # fmt: skip
        assert (repo_copy / "out3d" / name).stat().st_size > 0
    s = json.loads((repo_copy / "out3d/summary.json").read_text())
    assert s["rocks"] == 800 and len(s["lines"]) == 1
    from fieldkit.impact_table import ImpactTable

    table = ImpactTable.read(repo_copy / "out3d/impacts.csv")
    assert len(table) == 3 * 800 and table.paths()[:2] == ["0", "1"]
    assert set(table.frame["material"]) == {"meadow"}


def test_rasters_independent_of_chunking(cli, site, kernel, tmp_path, monkeypatch):
    """Rasters computed in blocks of a few rocks equal those computed at once."""
    import rasterio

    import fieldkit.model.results3d as results3d

    kernel.paths = [straight(1001.0 + 3 * i, 2095.0, 2095.0 - 7 * i - 5, step=2.0)
                    for i in range(12)]  # fmt: skip
    grids = []
    for chunk in (results3d.CHUNK_POINTS, 7):
        monkeypatch.setattr(results3d, "CHUNK_POINTS", chunk)
        out = tmp_path / f"c{chunk}"
        result = cli("simulate", site / "model3d.json", "--rocks", "12", "--seed",
                     "1", "--rasters", out)  # fmt: skip
        assert result.exit_code == 0, result.stderr
        grid = {}
        for name in results3d.RASTERS:
            with rasterio.open(out / f"{name}.tif") as src:
                grid[name] = src.read(1)
        grids.append(grid)
    for name in results3d.RASTERS:
        np.testing.assert_array_equal(grids[0][name], grids[1][name])
    assert grids[0]["passing_count"].sum() > 12


@pytest.mark.parametrize(
    "args",
    [
        ("export", "{model}", "--to", "json", "-o", "{out}/m.json"),
        ("synth", "{model}", "-o", "{out}/t.csv"),
    ],
)
def test_profile_commands_refuse_a_terrain_model(cli, fails, repo, tmp_path, args):
    """Commands that read a profile model say so in one line for a 3-D model."""
    model = repo / "examples/tschamut/model_3d.json"
    argv = [a.format(model=model, out=tmp_path / "out") for a in args]
    fails(
        cli(*argv),
        "model_3d.json",
        "terrain",
        "a 3-D model (a terrain block, a DEM) where a profile model is needed",
    )
    assert not (tmp_path / "out").exists()


def _grid_file(path: Path, values: np.ndarray) -> Path:
    """An ESRI grid on the test DEM's grid; ``values`` row 0 south."""
    rows = "\n".join(" ".join(f"{v:g}" for v in row) for row in values[::-1])
    path.write_text(f"ncols {NX}\nnrows {NY}\nxllcorner {X0}\nyllcorner {Y0}\n"
                    f"cellsize {CELL}\nNODATA_value -9999\n{rows}\n")  # fmt: skip
    return path


def test_material_and_release_rasters(cli, site, kernel):
    """A material raster (cell value = index into "materials") and a raster of
    release cells with counts: releases at the cell centres on the ground, the
    counts their weights; the run states them."""
    codes = np.zeros((NY, NX))
    codes[12:, :] = 1
    _grid_file(site / "materials.asc", codes)
    counts = np.zeros((NY, NX))
    counts[15, 3], counts[17, 10] = 2, 5
    _grid_file(site / "release_cells.asc", counts)
    write_model(site / "rasters.json", {
        "materials.rock": {"e_n": 0.3, "e_t": 0.9, "friction_deg": 40},
        "terrain.materials": "materials.asc",
        "terrain.releases": "release_cells.asc"})  # fmt: skip
    result = cli("simulate", site / "rasters.json", "--rocks", "7", "--seed", "1")
    assert result.exit_code == 0, result.stderr
    assert "released from 2 points (weights 7 in all) at v = (0, 0, 0) m/s" in (
        result.stdout
    )
    ((model, _rocks),) = kernel.calls
    assert (model.material_index[:12] == 0).all()
    assert (model.material_index[12:] == 1).all()
    x = X0 + CELL * np.array([3.5, 10.5])
    y = Y0 + CELL * np.array([15.5, 17.5])
    np.testing.assert_allclose(model.releases, np.column_stack([x, y, plane_z(x, y)]))
    assert model.release_weights.tolist() == [2, 5]


def test_material_raster_bad_code_named(cli, fails, site, kernel):
    codes = np.zeros((NY, NX))
    codes[4, 7] = 3
    _grid_file(site / "materials.asc", codes)
    write_model(site / "model3d.json", {"terrain.materials": "materials.asc"})
    fails(cli("simulate", site / "model3d.json", "--rocks", "2"),
          "terrain.materials", "x = 1037.5, y = 2022.5", "holds 3",
          "0 to 0 (grass)")  # fmt: skip


def test_observed_file_errors_one_line(cli, fails, site, kernel, tmp_path):
    (tmp_path / "obs.csv").write_text("x_m,y_m\n1020,2035\n1030,abc\n")
    out = tmp_path / "out"
    fails(cli("simulate", site / "model3d.json", "--rocks", "2", "--observed",
              tmp_path / "obs.csv", "--figures", out),
          "obs.csv", "row 3", "y_m")  # fmt: skip
    assert not out.exists() and not kernel.calls


def test_nan_sample_does_not_blank_a_cell(cli, site, kernel, tmp_path):
    """A sample without a height (NaN, e.g. a rock's last sample off the surface)
    leaves the cell's max height that of the other samples there."""
    import rasterio

    kernel.paths = [np.array([[1012.0, 2047.0], [1013.0, 2047.0]])]
    kernel.nan_height_at = 1
    out = tmp_path / "r"
    result = cli("simulate", site / "model3d.json", "--rocks", "1", "--seed", "1",
                 "--rasters", out)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "RuntimeWarning" not in result.stderr
    with rasterio.open(out / "max_height_m.tif") as src:
        height = src.read(1)[::-1]
    assert height[9, 2] == pytest.approx(1.0)


def test_line_off_the_dem_and_trajectories_bound(cli, fails, site, kernel):
    """A --line that never enters the DEM is refused (a line partly outside, or
    crossing the whole DEM without a vertex in it, is not)."""
    fails(cli("simulate", site / "model3d.json", "--line", "0,0,10,50"),
          "--line", "0,0,10,50", "never enters the DEM")  # fmt: skip
    fails(cli("simulate", site / "model3d.json", "--trajectories", "5000"),
          "--trajectories", "from 0 to 1,000")  # fmt: skip
    assert not kernel.calls
    result = cli("simulate", site / "model3d.json", "--rocks", "2", "--seed", "1",
                 "--line", "900,2050.5,1200,2050.5")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "line 1: passing 1.000" in result.stdout
