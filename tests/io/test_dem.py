"""DEM grids: ESRI ASCII read strictly, GeoTIFF through rasterio, bilinear elevation."""

from __future__ import annotations

import doctest

import numpy as np
import pytest

from fieldkit.errors import InputFileError
from fieldkit.io.dem import ESRI_DEFAULT_NODATA, DemGrid, read_dem

TSCHAMUT = "tests/data/tschamut2014/terrain.asc"


def plane(x, y):
    """An analytic plane: bilinear interpolation must reproduce it exactly."""
    return 100.0 - 0.3 * x + 0.45 * y


def write_asc(path, values, *, x0=10.0, y0=20.0, cell=2.0, corner=True, nodata=-9999,
              extra=""):  # fmt: skip
    nrows, ncols = values.shape
    kind = "corner" if corner else "center"
    head = (
        f"NCOLS {ncols}\nnrows {nrows}\nxll{kind} {x0}\nYLL{kind.upper()} {y0}\n"
        f"cellsize {cell}\n"
    )
    if nodata is not None:
        head += f"NODATA_value {nodata}\n"
    rows = "\n".join(" ".join(f"{v:.10g}" for v in row) for row in values)
    path.write_text(head + extra + rows + "\n")
    return path


def plane_grid(nrows=6, ncols=8, x0=10.0, y0=20.0, cell=2.0):
    """Values of :func:`plane` at the cell centres of a corner-referenced grid."""
    x = x0 + cell * (np.arange(ncols) + 0.5)
    y = y0 + cell * (nrows - np.arange(nrows) - 0.5)
    return plane(*np.meshgrid(x, y))


def test_esri_plane_elevations_are_exact(tmp_path):
    grid = read_dem(write_asc(tmp_path / "plane.asc", plane_grid()))
    assert grid.shape == (6, 8)
    assert grid.cellsize_m == 2.0
    assert grid.x_m[0] == 11.0 and grid.y_m[0] == 31.0 and grid.y_m[-1] == 21.0
    rng = np.random.default_rng(1)
    x = rng.uniform(grid.x_m[0], grid.x_m[-1], 200)
    y = rng.uniform(grid.y_m[-1], grid.y_m[0], 200)
    np.testing.assert_allclose(grid.elevation(x, y), plane(x, y), rtol=0, atol=1e-9)
    _, gx, gy, _ = grid.sample(x, y)
    np.testing.assert_allclose(gx, -0.3, atol=1e-12)
    np.testing.assert_allclose(gy, 0.45, atol=1e-12)


def test_bilinear_surface_reproduced_exactly(tmp_path):
    # z = x y is bilinear: its interpolant from the cell centres is the function
    nrows, ncols = 5, 7
    x = 0.5 + np.arange(ncols)
    y = nrows - 0.5 - np.arange(nrows)
    values = np.outer(y, x)
    grid = DemGrid.from_corner(values, x_left_m=0, y_top_m=nrows, cellsize_m=1)
    px, py = np.array([0.5, 3.3, 6.5, 2.71]), np.array([4.5, 1.2, 0.5, 3.99])
    np.testing.assert_allclose(grid.elevation(px, py), px * py, atol=1e-12)


def test_xllcenter_means_the_first_cell_centre(tmp_path):
    corner = read_dem(write_asc(tmp_path / "a.asc", plane_grid()))
    center = read_dem(
        write_asc(tmp_path / "b.asc", plane_grid(), x0=11.0, y0=21.0, corner=False)
    )
    np.testing.assert_array_equal(corner.x_m, center.x_m)
    np.testing.assert_array_equal(corner.y_m, center.y_m)


def test_tschamut_header(external_data):
    grid = read_dem(external_data / "tschamut2014" / "terrain.asc")
    # ncols 43, nrows 46, xllcorner -35, yllcorner 85, cellsize 5
    assert grid.shape == (46, 43)
    assert grid.cellsize_m == 5.0
    assert (grid.x_m[0], grid.x_m[-1]) == (-32.5, 177.5)
    assert (grid.y_m[0], grid.y_m[-1]) == (312.5, 87.5)
    assert grid.values[0, 0] == 125.494105  # first value of the file (north-west)
    assert not np.isnan(grid.values).any() and grid.crs is None and grid.notes == ()


def test_nodata_is_nan_and_default_is_stated(tmp_path):
    values = plane_grid()
    values[2, 3] = -9999
    grid = read_dem(write_asc(tmp_path / "a.asc", values, nodata=None))
    assert np.isnan(grid.values[2, 3]) and np.isfinite(grid.values).sum() == 47
    assert str(int(ESRI_DEFAULT_NODATA)) in grid.notes[0]
    values[2, 3] = -1
    grid = read_dem(write_asc(tmp_path / "b.asc", values, nodata=-1))
    assert np.isnan(grid.values[2, 3]) and grid.notes == ()


def test_prj_gives_the_crs(tmp_path):
    path = write_asc(tmp_path / "a.asc", plane_grid())
    (tmp_path / "a.prj").write_text('PROJCS["CH1903+ / LV95"]\n')
    assert read_dem(path).crs == 'PROJCS["CH1903+ / LV95"]'


def test_elevation_outside_or_on_nodata_names_the_point(tmp_path):
    values = plane_grid()
    values[0, 0] = np.nan
    grid = DemGrid.from_corner(values, x_left_m=10, y_top_m=32, cellsize_m=2,
                               source="g.asc")  # fmt: skip
    with pytest.raises(InputFileError, match=r"g.asc: point \(x, y\) = \(10.50, 25.00\)"
                       r": outside the grid"):  # fmt: skip
        grid.elevation([12.0, 10.5], [25.0, 25.0])  # 10.5 < first centre 11
    with pytest.raises(InputFileError, match="nodata in the grid at row 1, column 1"):
        grid.elevation(11.5, 30.5)
    # a node next to the nodata cell uses no weight from it
    assert grid.elevation(13.0, 29.0)[0] == pytest.approx(plane(13.0, 29.0))


BAD_ASC = [
    ("ncols 3\nnrows 2\nxllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n",
     "line 5: header yllcorner or yllcenter missing"),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5\n",
     "line 7: 2 values in a row of ncols = 3"),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 x5 6\n",
     "line 7: value 'x5' is not a number"),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n",
     "1 rows of values for nrows = 2"),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n7 8 9\n",
     "line 8: more than nrows = 2 rows"),
    ("ncols 3.5\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n",
     "line 1: header ncols must be a whole number >= 2"),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize -1\n1 2 3\n4 5 6\n",
     "line 5: header cell size must be > 0"),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner abc\ncellsize 1\n1 2 3\n4 5 6\n",
     "line 4: header yllcorner 'abc' is not a number"),
    ("ncols 3\nnrows 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n",
     "line 3: header key nrows appears twice"),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsze 1\n1 2 3\n4 5 6\n",
     "line 5: unknown header key 'cellsze'"),
    ("ncols 3\nnrows 2\nxllcorner 0\nxllcenter 0\nyllcorner 0\ncellsize 1\n1 2 3\n"
     "4 5 6\n", "header xllcorner or xllcenter given twice"),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 inf\n4 5 6\n",
     "line 6: value 'inf' is not a finite number"),
    ("ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -1\n"
     "-1 -1\n-1 -1\n", "every cell is nodata"),
]  # fmt: skip


@pytest.mark.parametrize(("text", "message"), BAD_ASC)
def test_malformed_esri_grid_is_one_line_naming_file_and_line(tmp_path, text, message):
    path = tmp_path / "bad.asc"
    path.write_text(text)
    with pytest.raises(InputFileError) as info:
        read_dem(path)
    line = str(info.value)
    assert "\n" not in line and line.startswith(str(path)) and message in line, line


def test_binary_and_missing_files(tmp_path):
    with pytest.raises(InputFileError, match="file not found"):
        read_dem(tmp_path / "none.asc")
    (tmp_path / "b.asc").write_bytes(b"\x00\x01\x02" * 100)
    with pytest.raises(InputFileError, match="binary"):
        read_dem(tmp_path / "b.asc")


rasterio = pytest.importorskip("rasterio")


def write_tif(path, values, *, crs="EPSG:2056", nodata=None, bands=1):
    from affine import Affine

    with rasterio.open(
        path, "w", driver="GTiff", height=values.shape[0], width=values.shape[1],
        count=bands, dtype="float64", crs=crs, nodata=nodata,
        transform=Affine(2.0, 0.0, 10.0, 0.0, -2.0, 32.0),
    ) as dst:  # fmt: skip
        for band in range(1, bands + 1):
            dst.write(values, band)
    return path


def test_geotiff_round_trip_matches_the_esri_grid(tmp_path):
    values = plane_grid()
    values[5, 7] = -32768.0
    tif = read_dem(write_tif(tmp_path / "plane.tif", values, nodata=-32768.0))
    asc = read_dem(write_asc(tmp_path / "plane.asc", values, nodata=-32768))
    assert tif.crs == "EPSG:2056" and tif.shape == (6, 8)
    np.testing.assert_array_equal(tif.x_m, asc.x_m)
    np.testing.assert_array_equal(tif.y_m, asc.y_m)
    # NaN at the same cell; the ASCII file holds 10 significant digits
    np.testing.assert_allclose(tif.values, asc.values, rtol=1e-10, equal_nan=True)
    x, y = np.array([11.0, 16.3, 24.9]), np.array([21.7, 28.0, 31.0])
    np.testing.assert_allclose(tif.elevation(x, y), plane(x, y), atol=1e-9)


def test_geotiff_in_degrees_or_with_bands_is_refused(tmp_path):
    values = plane_grid()
    with pytest.raises(InputFileError, match="degrees"):
        read_dem(write_tif(tmp_path / "deg.tif", values, crs="EPSG:4326"))
    with pytest.raises(InputFileError, match="has 3 bands"):
        read_dem(write_tif(tmp_path / "rgb.tif", values, bands=3))


def test_truncated_geotiff_is_one_line(tmp_path):
    path = write_tif(tmp_path / "a.tif", plane_grid())
    data = path.read_bytes()
    path.write_bytes(data[:200])
    with pytest.raises(InputFileError) as info:
        read_dem(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)


@pytest.mark.filterwarnings("ignore::rasterio.errors.NotGeoreferencedWarning")
def test_plain_tiff_without_georeferencing_is_refused(tmp_path):
    path = tmp_path / "image.tif"
    with rasterio.open(
        path, "w", driver="GTiff", height=4, width=4, count=1, dtype="float32"
    ) as dst:
        dst.write(np.ones((4, 4), "float32"), 1)
    with pytest.raises(InputFileError, match="not georeferenced"):
        read_dem(path)


def test_doctests():
    import fieldkit.io.dem as module

    result = doctest.testmod(module)
    assert result.attempted > 0 and result.failed == 0
