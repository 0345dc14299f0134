"""Fine DEMs in national grids (issue 31): a 5 cm DEM in Swiss LV95 (EPSG:2056,
lower-left corner near Chant Sura) and a 1 m DEM in UTM zone 32N (EPSG:32632), as
ESRI ASCII grids (with a .prj and nodata around the edge, as a clipped UAS DEM) and
as GeoTIFFs, through reading, ``simulate``, ``track3d``, ``corridor``, ``profile``
and ``export``.

The reference is translation invariance: the same scene with its origin at (0, 0)
and in the national grid gives the same numbers (to 1e-6 m, the rounding of a
coordinate near 5e6 m being 1e-9 m). Besides: the cell size read is the header's
number exactly, and the normals of a plane are the analytic ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
import pytest

from fieldkit.errors import InputFileError
from fieldkit.io.dem import read_dem
from fieldkit.model.terrain import Terrain
from fieldkit.model.terrain_file import terrain_from_dem

#: Lower-left corners: LV95 near Chant Sura (E 2 780 000, N 1 185 000), and UTM 32N.
LV95 = (2_780_000.0, 1_185_000.0)
UTM32 = (500_000.0, 5_170_000.0)
LOCAL = (0.0, 0.0)
NODATA = -9999.0


@dataclass(frozen=True)
class Scene:
    """A slope of ``nx`` x ``ny`` cells of ``cell`` m: dipping 35 deg to the south,
    rippled down the slope and curved across it (so rocks bounce and turn)."""

    cell: float
    nx: int
    ny: int
    epsg: int

    @property
    def width_m(self) -> float:
        return self.nx * self.cell

    @property
    def height_m(self) -> float:
        return self.ny * self.cell

    def ground(self, x, y):
        """Elevation [m] at local plan coordinates (origin at the lower-left)."""
        x, y = np.asarray(x, float), np.asarray(y, float)
        return (0.7 * y + 0.3 * np.sin(y / 3.0)
                + 0.02 * (x - self.width_m / 2) ** 2)  # fmt: skip

    def values(self, *, ragged: bool = False) -> np.ndarray:
        """The elevations, row 0 north; ``ragged``: a nodata fringe along the
        west, east and south edges, 1-4 cells wide, as a clipped UAS DEM has."""
        xc = (np.arange(self.nx) + 0.5) * self.cell
        yc = (np.arange(self.ny) + 0.5) * self.cell
        z = self.ground(*np.meshgrid(xc, yc))[::-1].copy()
        if ragged:
            rows = np.arange(self.ny)
            width = 1 + rows % 4
            cols = np.arange(self.nx)
            z[cols[None, :] < width[:, None]] = np.nan
            z[cols[None, :] >= self.nx - width[::-1, None]] = np.nan
            z[-2:, :] = np.nan
            z[-3, ::7] = np.nan
        return z


#: A 5 cm UAS DEM (12 x 30 m) in LV95 and a 1 m DEM (60 x 120 m) in UTM 32N.
FINE = Scene(0.05, 240, 600, 2056)
METRE = Scene(1.0, 60, 120, 32632)
GRIDS = [pytest.param(FINE, LV95, id="5cm-LV95"),
         pytest.param(METRE, UTM32, id="1m-UTM32")]  # fmt: skip
#: The same, for the commands whose cost grows with the cells (a 6 x 10 m crop).
SMALL_GRIDS = [pytest.param(Scene(0.05, 120, 200, 2056), LV95, id="5cm-LV95"),
               pytest.param(METRE, UTM32, id="1m-UTM32")]  # fmt: skip


def write_asc(path, scene: Scene, origin, *, ragged: bool = True):
    """An ESRI ASCII grid as a GIS writes it (corner to the mm, ``cellsize 0.05``),
    with its .prj; nodata as -9999."""
    from rasterio.crs import CRS

    z = scene.values(ragged=ragged)
    rows = "\n".join(" ".join("-9999" if v != v else f"{v:.4f}" for v in row)
                     for row in z)  # fmt: skip
    path.write_text(
        f"ncols {scene.nx}\nnrows {scene.ny}\nxllcorner {origin[0]:.3f}\n"
        f"yllcorner {origin[1]:.3f}\ncellsize {scene.cell:g}\n"
        f"NODATA_value {NODATA:g}\n{rows}\n"
    )
    path.with_suffix(".prj").write_text(CRS.from_epsg(scene.epsg).to_wkt())
    return path


def write_tif(path, scene: Scene, origin, *, ragged: bool = True):
    """A float32 GeoTIFF with its nodata value and EPSG code."""
    import rasterio
    from rasterio.transform import from_origin

    z = np.where(np.isnan(v := scene.values(ragged=ragged)), NODATA, v)
    top = origin[1] + scene.ny * scene.cell
    with rasterio.open(
        path, "w", driver="GTiff", width=scene.nx, height=scene.ny, count=1,
        dtype="float32", crs=f"EPSG:{scene.epsg}", nodata=NODATA,
        transform=from_origin(origin[0], top, scene.cell, scene.cell),
    ) as dst:  # fmt: skip
        dst.write(z.astype("float32"), 1)
    return path


WRITERS = {"asc": write_asc, "tif": write_tif}


# -- reading -------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["asc", "tif"])
@pytest.mark.parametrize(("scene", "origin"), GRIDS)
def test_cell_size_and_origin_are_the_headers(tmp_path, scene, origin, kind):
    grid = read_dem(WRITERS[kind](tmp_path / f"dem.{kind}", scene, origin))
    assert grid.dx_m == scene.cell and grid.dy_m == scene.cell  # the header's number
    assert grid.x_left_m == origin[0]
    assert grid.y_bottom_m == pytest.approx(origin[1], abs=1e-9)
    assert np.isnan(grid.values).sum() > scene.ny  # the ragged fringe is nodata
    t = terrain_from_dem(grid)  # square: refused before (5 cm at 2.8e6 m)
    assert t.cell_m == scene.cell and t.x0_m == origin[0]
    assert "EPSG" in t.crs or str(scene.epsg) in t.crs
    # the centres (computed from the header) sit where they belong
    np.testing.assert_allclose(grid.x_m[[0, -1]] - origin[0],
                               [scene.cell / 2, scene.width_m - scene.cell / 2],
                               rtol=0, atol=1e-9)  # fmt: skip


def test_centre_differences_miss_the_old_tolerance():
    """Why the issue happened: differences of 5 cm cell centres near 2.78e6 m are
    off by more than 1e-9 relative, so a square-cell test on them fails."""
    grid_x = LV95[0] + FINE.cell * (np.arange(4) + 0.5)
    rel = np.abs(np.diff(grid_x) / FINE.cell - 1)
    assert rel.max() > 1e-9


def test_non_square_cells_still_refused(tmp_path, fails):
    path = tmp_path / "rect.asc"
    path.write_text(f"ncols 3\nnrows 2\nxllcorner {UTM32[0]}\nyllcorner {UTM32[1]}\n"
                    "dx 1\ndy 2\n1 2 3\n4 5 6\n")  # fmt: skip
    with pytest.raises(InputFileError) as err:
        terrain_from_dem(read_dem(path))
    assert str(err.value) == (
        f"{path}: cells are 1 x 2 m; the 3-D model needs square cells "
        "(resample it: gdalwarp -tr)"
    )


@pytest.mark.parametrize(("scene", "origin"), GRIDS)
def test_plane_normals_and_cells_exact_in_the_national_grid(tmp_path, scene, origin):
    """A plane z = 400 + 0.3 x' - 0.7 y' (x', y' local): the upward normal from
    the DEM is the analytic one to < 0.01 deg at points all over the grid, and the
    cell holding a point near a cell edge is found (no cell index lost)."""
    a, b = 0.3, -0.7
    ncols, nrows = scene.nx, scene.ny
    xc = (np.arange(ncols) + 0.5) * scene.cell
    yc = (np.arange(nrows) + 0.5) * scene.cell
    xx, yy = np.meshgrid(xc, yc)
    t = Terrain(origin[0], origin[1], scene.cell, 400 + a * xx + b * yy)
    expect = np.array([-a, -b, 1.0]) / math.sqrt(a * a + b * b + 1)
    rng = np.random.default_rng(5)
    px = rng.uniform(scene.cell, scene.width_m - scene.cell, 50)
    py = rng.uniform(scene.cell, scene.height_m - scene.cell, 50)
    worst = 0.0
    for x, y in zip(px, py, strict=True):
        n = np.array(t.normal(origin[0] + x, origin[1] + y))
        worst = max(worst, math.degrees(math.acos(min(1.0, float(n @ expect)))))
        assert t.height(origin[0] + x, origin[1] + y) == pytest.approx(
            400 + a * x + b * y, abs=1e-6)  # fmt: skip
    assert worst < 0.01
    # a point 1e-6 of a cell inside a cell's south-west corner is in that cell
    col, row = ncols // 2 + 7, nrows // 3 + 1
    x = origin[0] + (col + 1e-6) * scene.cell
    y = origin[1] + (row + 1 - 1e-6) * scene.cell
    r, c = t.cell_index(x, y)
    assert (int(r), int(c)) == (row, col)


def test_ascii_grid_written_with_the_header_numbers(tmp_path):
    """The ESRI grid writer writes the header's corner and cell size so that
    they read back exactly (``%g`` wrote 2780000.025 as 2.78e+06)."""
    from fieldkit.export.ascii_grid import ascii_grid_text
    from fieldkit.io.dem import DemGrid

    g = DemGrid.from_corner(np.ones((3, 4)), x_left_m=2780000.025,
                            y_top_m=1185030.15, cellsize_m=0.05)  # fmt: skip
    (tmp_path / "out.asc").write_text(ascii_grid_text(g.values, g))
    back = read_dem(tmp_path / "out.asc")
    assert (back.x_left_m, back.dx_m, back.dy_m) == (2780000.025, 0.05, 0.05)
    assert back.y_bottom_m == g.y_bottom_m


# -- simulate ------------------------------------------------------------------


def write_model3d(folder, scene: Scene, origin, kind: str, *, rough: bool = True):
    """A 3-D model file on the scene's DEM, releasing at two points near the top;
    ``rough``: with slope roughness and a spread of e_n (else constant)."""
    import json

    folder.mkdir(parents=True, exist_ok=True)
    dem = WRITERS[kind](folder / f"dem.{kind}", scene, origin)
    ox, oy = origin
    w, h = scene.width_m, scene.height_m
    releases = [[ox + 0.5 * w, oy + 0.9 * h], [ox + 0.42 * w, oy + 0.87 * h]]
    (folder / "model3d.json").write_text(json.dumps({
        "terrain": {"dem": dem.name, "materials": "ground", "releases": releases},
        "materials": {"ground": {"e_n": 0.6, "e_t": 0.85, "friction_deg": 30}
                      | ({"e_n_sd": 0.05, "roughness_deg_sd": 3.0} if rough else {})},
        "effects": {"slope_roughness": {}} if rough else {},
        "body": {"mass_kg": 100.0, "radius_m": 0.2},
        "seeder": {"height_m": 1.0, "vy_mps": -4.0 * math.sqrt(scene.cell) - 2,
                   "vz_mps": 2.0, "vx_sd_mps": 1.0, "vy_sd_mps": 1.0},
    }))  # fmt: skip
    return folder / "model3d.json"


def simulate_cli(cli, model, out, origin, scene):
    ox, oy = origin
    line = (ox, oy + 0.4 * scene.height_m, ox + scene.width_m,
            oy + 0.4 * scene.height_m)  # fmt: skip
    r = cli("simulate", model, "--rocks", "12", "--seed", "3", "--deposits",
            out / "deposits.csv", "--line", ",".join(f"{v:.3f}" for v in line),
            "--rasters", out / "rasters")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    return r


@pytest.mark.parametrize("kind", ["asc", "tif"])
@pytest.mark.parametrize(("scene", "origin"), GRIDS)
def test_simulate_same_in_the_national_grid_as_at_the_origin(
    cli, tmp_path, scene, origin, kind
):
    """`fieldkit simulate` on the DEM (with its nodata fringe) at (0, 0) and in
    the national grid: the same deposits, line crossings and rasters."""
    import rasterio

    runs = {}
    for name, o in (("local", LOCAL), ("national", origin)):
        model = write_model3d(tmp_path / name, scene, o, kind)
        r = simulate_cli(cli, model, tmp_path / name / "out", o, scene)
        dep = pd.read_csv(tmp_path / name / "out" / "deposits.csv")
        dep["x_m"] -= o[0]
        dep["y_m"] -= o[1]
        runs[name] = (dep, r.stdout)
    (a, out_a), (b, out_b) = runs["local"], runs["national"]
    assert len(a) == 12 and a["state"].tolist() == b["state"].tolist()
    # the rocks travel: most get past the line at 40 % of the slope's length
    assert (a["y_m"] < 0.4 * scene.height_m).sum() >= 6
    for c in ("x_m", "y_m", "z_m"):
        np.testing.assert_allclose(b[c], a[c], rtol=0, atol=1e-6, err_msg=c)
    # the crossing summary (counts, energies) prints the same numbers
    assert [ln for ln in out_a.splitlines() if "line" in ln and "wrote" not in ln] \
        == [ln for ln in out_b.splitlines() if "line" in ln and "wrote" not in ln]
    rasters = sorted((tmp_path / "local" / "out" / "rasters").glob("*.tif"))
    assert rasters
    for path in rasters:
        with rasterio.open(path) as ra, rasterio.open(
            tmp_path / "national" / "out" / "rasters" / path.name
        ) as rb:
            assert rb.transform.a == scene.cell and rb.transform.c == origin[0]
            # the same values, but for the odd cell: a path sample on a cell edge
            # (the kernel samples where a path crosses one) may be binned in the
            # neighbour once its coordinate is rounded to 2e-10 m at 2.8e6 m
            same = np.isclose(rb.read(1), ra.read(1), rtol=1e-9, equal_nan=True)
            assert same.mean() > 0.999, (path.name, same.mean())


def test_simulate_library_national_grid_not_capped(tmp_path):
    """The kernel runs in the DEM's own frame: in LV95 coordinates on a 5 cm DEM
    no rock is capped at the impact limit by false contacts (before, every rock
    was), and the impacts are those of the local scene to 1e-6 m."""
    from fieldkit.model.model_file import read_model
    from fieldkit.model.results import MAX_IMPACTS
    from fieldkit.model.simulate3d import simulate3d

    res = {}
    for name, o in (("local", LOCAL), ("national", LV95)):
        model = read_model(write_model3d(tmp_path / name, FINE, o, "asc"),
                           terrain=True)  # fmt: skip
        res[name] = simulate3d(model, 6, np.random.default_rng(8),
                               record_impacts=True)  # fmt: skip
    a, b = res["local"], res["national"]
    assert not (b.state == MAX_IMPACTS).any()
    assert a.impacts == b.impacts >= 12
    ra, rb = a.impact_rows, b.impact_rows
    np.testing.assert_allclose(rb["x_m"] - LV95[0], ra["x_m"], atol=1e-6)
    np.testing.assert_allclose(rb["y_m"] - LV95[1], ra["y_m"], atol=1e-6)
    for c in ("z_m", "t_s", "vin_mps", "vfn_mps", "vit_mps", "vft_mps"):
        np.testing.assert_allclose(rb[c], ra[c], rtol=1e-6, atol=1e-9, err_msg=c)
    np.testing.assert_allclose(b.path["x_m"] - LV95[0], a.path["x_m"], atol=1e-6)


# -- track3d -------------------------------------------------------------------


@pytest.mark.parametrize(("scene", "origin"), GRIDS)
def test_track3d_same_in_the_national_grid_as_at_the_origin(
    cli, tmp_path, scene, origin
):
    """Trajectories of the 3-D simulator on the scene (2 cm noise, 100 Hz) reduced
    by `fieldkit track3d` on the DEM at (0, 0) and in the national grid: the same
    impacts, e_n, e_t and lateral deflections (to 1e-6); and near the truth."""
    from fieldkit.impact_table import ImpactTable
    from fieldkit.model.model_file import read_model
    from fieldkit.model.simulate3d import simulate3d
    from fieldkit.tracking.trajectory3d.synthetic import sampled_runs, write_site

    found, truth = {}, None
    for name, o in (("local", LOCAL), ("national", origin)):
        folder = tmp_path / name
        model = read_model(write_model3d(folder, scene, o, "asc", rough=False),
                           terrain=True)  # fmt: skip
        result = simulate3d(model, 8, np.random.default_rng(1), record_impacts=True)
        runs = sampled_runs(result, fps=100.0, noise_sd_m=0.02, min_flight_s=0.25,
                            rng=np.random.default_rng(2))  # fmt: skip
        samples, dem = write_site(folder, model.terrain, runs)
        out = folder / "impacts.csv"
        r = cli("track3d", samples, "--dem", dem, "--radius", 0.2, "--mass", 100.0,
                "-o", out)  # fmt: skip
        assert r.exit_code == 0, r.stderr
        f = ImpactTable.read(out).frame
        f["x_m"] -= o[0]
        f["y_m"] -= o[1]
        found[name] = f
        if name == "local":
            truth = pd.concat([run.truth for run in runs], ignore_index=True)
    a, b = found["local"], found["national"]
    assert len(a) == len(b) == len(truth) >= 6
    for c in ("t_s", "x_m", "y_m", "z_m", "e_n", "e_t", "lateral_deg", "vin_mps",
              "dip_deg", "chainage_m"):  # fmt: skip
        np.testing.assert_allclose(b[c], a[c], rtol=1e-6, atol=1e-6, err_msg=c)
    # and the reduction is right, not only the same
    for c in ("e_n", "e_t"):
        err = np.abs(a[c].to_numpy() - truth[c].to_numpy())
        assert err.max() < 0.1, (c, err)


# -- corridor, profile, export -------------------------------------------------


def write_alignment(path, scene: Scene, origin):
    ox, oy = origin
    y = oy + 0.35 * scene.height_m
    path.write_text(f"x_m,y_m\n{ox + 0.1 * scene.width_m:.3f},{y:.3f}\n"
                    f"{ox + 0.9 * scene.width_m:.3f},{y:.3f}\n")  # fmt: skip
    return path


def shifted(frame: pd.DataFrame, origin) -> pd.DataFrame:
    """The corridor table with its station coordinates relative to ``origin``
    (the CSV keeps them to the mm: 2780001.2 was written 2.78e+06)."""
    frame["x_m"] -= origin[0]
    frame["y_m"] -= origin[1]
    return frame


@pytest.mark.parametrize(("scene", "origin"), GRIDS)
def test_corridor_3d_same_in_the_national_grid(cli, tmp_path, scene, origin):
    frames = {}
    for name, o in (("local", LOCAL), ("national", origin)):
        folder = tmp_path / name
        model = write_model3d(folder, scene, o, "tif")
        align = write_alignment(folder / "alignment.csv", scene, o)
        out = folder / "corridor.csv"
        r = cli("corridor", folder / "dem.tif", "--alignment", align, "--model",
                model, "--spacing", scene.width_m / 4, "--rocks", "40", "--seed",
                "2", "--workers", "0", "-o", out)  # fmt: skip
        assert r.exit_code == 0, r.stderr
        frames[name] = shifted(pd.read_csv(out), o)
    a, b = frames["local"], frames["national"]
    assert a["passing"].sum() >= 20  # the rocks reach the alignment
    pd.testing.assert_frame_equal(a, b, rtol=1e-6)


def test_corridor_2d_on_the_5cm_lv95_dem(cli, tmp_path, repo):
    """A 2-D scan (sections cut from the DEM every 3 m) with the Tschamut base
    model: the same table at (0, 0) and in LV95."""
    frames = {}
    for name, o in (("local", LOCAL), ("national", LV95)):
        folder = tmp_path / name
        folder.mkdir()
        dem = write_asc(folder / "dem.asc", FINE, o)
        align = write_alignment(folder / "alignment.csv", FINE, o)
        out = folder / "corridor.csv"
        r = cli("corridor", dem, "--alignment", align, "--model",
                repo / "examples" / "tschamut" / "model_base.json", "--spacing", 3,
                "--upslope", 15, "--rocks", "30", "--seed", "4", "--workers", "0",
                "-o", out)  # fmt: skip
        assert r.exit_code == 0, r.stderr
        frames[name] = shifted(pd.read_csv(out), o)
    a, b = frames["local"], frames["national"]
    assert len(a) >= 3 and a["passing"].sum() > 0
    # the sections' heights differ by the rounding of national coordinates
    # (~1e-10 m): energies and heights agree to 1e-7 (measured); the Monte Carlo
    # SEs of 30 rocks' p99, a difference of two extreme rocks, to 6e-5
    se = [c for c in a.columns if c.endswith(("_se_kj", "_se_m"))]
    pd.testing.assert_frame_equal(a.drop(columns=se), b.drop(columns=se), rtol=1e-6)
    pd.testing.assert_frame_equal(a[se], b[se], rtol=1e-4)


@pytest.mark.parametrize("kind", ["asc", "tif"])
@pytest.mark.parametrize(("scene", "origin"), SMALL_GRIDS)
def test_profile_same_in_the_national_grid(cli, tmp_path, scene, origin, kind):
    """`fieldkit profile --from` (steepest descent) on the DEM at (0, 0) and in the
    national grid: the same chainages and heights; the heights those of the
    analytic ground."""
    frames = {}
    for name, o in (("local", LOCAL), ("national", origin)):
        folder = tmp_path / name
        folder.mkdir()
        dem = WRITERS[kind](folder / f"dem.{kind}", scene, o)
        start = f"{o[0] + 0.37 * scene.width_m:.4f},{o[1] + 0.8 * scene.height_m:.4f}"
        r = cli("profile", dem, "--from", start, "-o", folder / "p.csv")
        assert r.exit_code == 0, r.stderr
        assert f"of {scene.cell:g} m" in r.stderr + r.stdout
        frames[name] = pd.read_csv(folder / "p.csv")
    a, b = frames["local"], frames["national"]
    assert a["x_m"].iloc[-1] > 0.3 * scene.height_m
    np.testing.assert_allclose(b["x_m"], a["x_m"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(b["z_m"], a["z_m"], rtol=0, atol=1e-6)


@pytest.mark.parametrize(("scene", "origin"), SMALL_GRIDS)
def test_export_rockyfor3d_grids_keep_the_header(cli, tmp_path, repo, scene, origin):
    """`fieldkit export --to rockyfor3d --dem` writes its grids with the DEM's own
    corner and cell size, read back exactly; the same grids as at (0, 0)."""
    texts = {}
    for name, o in (("local", LOCAL), ("national", origin)):
        folder = tmp_path / name
        folder.mkdir()
        dem = write_asc(folder / "dem.asc", scene, o)
        release = f"{o[0] + 0.5 * scene.width_m:.3f},{o[1] + 0.9 * scene.height_m:.3f}"
        r = cli("export", repo / "examples" / "tschamut" / "model_base.json", "--to",
                "rockyfor3d", "--dem", dem, "--release", release, "-o",
                folder / "r3d")  # fmt: skip
        assert r.exit_code == 0, r.stderr
        grids = sorted((folder / "r3d").glob("*.asc"))
        assert len(grids) >= 3
        for path in grids:
            g = read_dem(path)
            assert g.dx_m == scene.cell and g.x_left_m == o[0]
            assert g.y_bottom_m == pytest.approx(o[1], abs=1e-9)
        texts[name] = {p.name: p.read_text().splitlines()[5:] for p in grids}
    assert texts["local"] == texts["national"]  # the values, row by row


def test_a_3d_scan_refuses_the_dem_shifted_by_one_cell(tmp_path):
    """The corridor's same-DEM check compares header numbers with a tolerance of
    the coordinates' rounding: a 5 cm DEM one cell off in LV95 is another DEM
    (a relative tolerance of 1e-5 let through 28 m there)."""
    from fieldkit.corridor.scan import check_same_dem
    from fieldkit.errors import ArgumentError
    from fieldkit.model.model_file import read_model

    model = read_model(write_model3d(tmp_path, FINE, LV95, "asc"), terrain=True)
    check_same_dem(model, read_dem(tmp_path / "dem.asc"))  # its own: accepted
    shifted_dem = write_asc(tmp_path / "shifted.asc", FINE,
                            (LV95[0] + FINE.cell, LV95[1]))  # fmt: skip
    with pytest.raises(ArgumentError, match="is not the DEM of the terrain model"):
        check_same_dem(model, read_dem(shifted_dem))


def test_a_point_on_a_row_of_centres_beside_nodata_has_data():
    """A point on a row of cell centres whose southern neighbour row is nodata,
    off by one rounding of its coordinate (2.3e-10 m in LV95, 5e-9 of a 5 cm
    cell): it has data, in LV95 as at the origin (it would lean on the nodata
    row)."""
    from fieldkit.io.dem import INSIDE, DemGrid

    values = np.arange(20.0).reshape(4, 5)
    values[3, :] = np.nan  # the southern row
    for ox, oy in (LOCAL, LV95):
        g = DemGrid.from_corner(values, x_left_m=ox, y_top_m=oy + 0.2,
                                cellsize_m=0.05)  # fmt: skip
        # row 2's centres, one rounding of the coordinate (2.3e-10 m in LV95) south
        y = g.y_m[2] - math.ulp(g.y_m[2])
        z, _, _, status = g.sample(np.array([ox + 0.1]), np.array([y]))
        assert status.tolist() == [INSIDE]
        assert z[0] == pytest.approx(values[2, 1] + 0.5, abs=1e-6)
