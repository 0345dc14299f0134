"""Hostile inputs to profile, synth, impact, fence and the files they read.

Every case runs the command line and checks what a user sees: the exit code (1 for
bad input, 2 for a usage error), ONE ``error:`` line on stderr holding a fragment
that names the file and field or the flag, no traceback, nothing written and every
input left as it was. The cases come from issue 17's third hostile set: wrongly
typed DEM-profile fields in a model file, flags the running command does not have,
sizes without an upper bound, non-finite and absurd numbers, corrupt tables.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

REPO = Path(__file__).resolve().parents[2]
DEM = REPO / "tests" / "data" / "tschamut2014" / "terrain.asc"
SMOKE = REPO / "tests" / "model" / "data" / "smoke.json"

#: A release point on the Tschamut DEM (README's profile example).
START = "30.602,235.28"

REST = {
    "materials": {"ground": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30}},
    "body": {"mass_kg": 60, "radius_m": 0.18, "gyration_m": 0.114},
    "seeder": {"x_m": 0.5, "z_m": 240.0},
}

#: Model files whose DEM or CSV profile entry is hostile: name -> profile entry.
DEM_ENTRIES = {
    "step_negative": {"dem": "terrain.asc", "from": [30.602, 235.28], "step_m": -1},
    "step_tiny": {"dem": "terrain.asc", "from": [30.602, 235.28], "step_m": 1e-9},
    "line_step_tiny": {
        "dem": "terrain.asc", "line": [[30.6, 235.3], [102.2, 151.5]], "step_m": 1e-9,
    },
    "from_text": {"dem": "terrain.asc", "from": "abc"},
    "from_object": {"dem": "terrain.asc", "from": {"x": 1}},
    "from_bool": {"dem": "terrain.asc", "from": True},
    "max_length_text": {
        "dem": "terrain.asc", "from": [30.602, 235.28], "max_length_m": "x",
    },
    "csv_units": {"csv": "section.csv", "units": "yards"},
}  # fmt: skip


@pytest.fixture()
def site(tmp_path) -> Path:
    """A folder of inputs: the DEM, model files, a section CSV, corrupt tables."""
    shutil.copy(DEM, tmp_path / "terrain.asc")
    shutil.copy(SMOKE, tmp_path / "smoke.json")
    (tmp_path / "section.csv").write_text("x,z\n0,100\n100,50\n200,20\n")
    for name, entry in DEM_ENTRIES.items():
        data = {**REST, "profile": entry}
        (tmp_path / f"{name}.json").write_text(json.dumps(data))
    rising = json.loads(SMOKE.read_text())
    rising["profile"]["z_m"] = rising["profile"]["z_m"][::-1]
    (tmp_path / "rising.json").write_text(json.dumps(rising))
    (tmp_path / "corrupt.xlsx").write_bytes(b"PK\x03\x04 not a workbook")
    with zipfile.ZipFile(tmp_path / "other_zip.xlsx", "w") as z:
        z.writestr("a.txt", "not a workbook")
    (tmp_path / "text.parquet").write_text("path_id,x_m\n1,2\n")
    (tmp_path / "binary.csv").write_bytes(b"\x00\x01\x02\x03" * 64)
    tornado = REPO / "surveys" / "tornado_mountain"
    book = (tornado / "boulder_a_fieldbook.csv").read_text().splitlines()
    book[0] += ",slope_deg"
    book[1:] = [line + (",200" if i == 2 else ",30") for i, line in enumerate(book[1:])]
    (tmp_path / "book.csv").write_text("\n".join(book) + "\n")
    shutil.copy(tornado / "boulder_a_stations.gpx", tmp_path / "stations.gpx")
    _sparse_geotiff(tmp_path / "bomb.tif", 20_000)
    (tmp_path / "z_huge.csv").write_text("x_m,z_m\n0,1e308\n10,-1e308\n")
    (tmp_path / "x_huge.csv").write_text("x_m,z_m\n0,100\n1e308,0\n")
    (tmp_path / "x_tiny.csv").write_text("x_m,z_m\n0,100\n1e-300,0\n")
    table = pd.DataFrame({"path_id": ["1", "1"], "point": ["A", "B"],
                          "x_m": [0.0, 5.0], "z_m": [10.0, 7.0],
                          "slope_deg": [30.0, 400.0], "vi_x_mps": [5.0, 5.0],
                          "vi_z_mps": [-3.0, -3.0], "vf_x_mps": [4.0, 4.0],
                          "vf_z_mps": [1.0, 1.0]})  # fmt: skip
    table.to_csv(tmp_path / "slope400.csv", index=False)
    return tmp_path


def _sparse_geotiff(path: Path, size: int) -> None:
    """A GeoTIFF declaring ``size`` x ``size`` cells in a few kB (tiles left out)."""
    import rasterio
    from rasterio.transform import Affine
    from rasterio.windows import Window

    profile = dict(driver="GTiff", width=size, height=size, count=1, dtype="float32",
                   crs="EPSG:2056", transform=Affine(1, 0, 0, 0, -1, size), tiled=True,
                   compress="deflate", sparse_ok=True)  # fmt: skip
    with rasterio.open(path, "w", **profile) as grid:
        grid.write(np.ones((256, 256), "float32"), 1, window=Window(0, 0, 256, 256))


def _state(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` and its SHA-256."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def _profile(*args: str) -> tuple[str, ...]:
    return ("profile", "{d}/terrain.asc", "--from", START, *args, "-o", "{d}/out/p.csv")


def _simulate(model: str) -> tuple[str, ...]:
    return ("simulate", f"{{d}}/{model}.json", "--rocks", "2", "--seed", "1",
            "--summary", "{d}/out/summary.json")  # fmt: skip


def _synth(*args: str, model: str = "smoke") -> tuple[str, ...]:
    return ("synth", f"{{d}}/{model}.json", *args, "-o", "{d}/out/s.csv")


_IMPACT = ("impact", "--vt", "3", "--vn", "-5", "--radius", "0.2", "--gyration", "0.1",
           "--mass", "10", "--json", "{d}/out/i.json")  # fmt: skip
_FENCE = ("fence", "--mass", "520", "--gyration", "0.35", "--speed-in", "22",
          "--spin-in", "18", "--speed-out", "11.5", "-o", "{d}/out/f.json")  # fmt: skip

#: (id, argv, exit code, fragments of the error line, words it must not hold).
CASES = [
    # profile: a step that never ends, sizes without an upper bound, non-finite
    ("profile-step-tiny", _profile("--step", "1e-9"), 1,
     ["--step must be >= 0.01 of the cell size, 0.05 m"], []),
    ("profile-line-step-tiny", _profile("--to", "102.22,151.49", "--step", "1e-9"), 1,
     ["--step 1e-09 m", "more than the limit of 20,000"], []),
    ("profile-max-length-huge", _profile("--step", "0.06", "--max-length", "1e9"), 1,
     ["--max-length 1e+09 m", "limit of 20,000"], []),
    ("profile-step-inf", _profile("--step", "inf"), 2,
     ["--step must be a finite number (got inf)"], []),
    ("profile-step-nan", _profile("--step", "nan"), 2,
     ["--step must be a finite number (got nan)"], []),
    ("profile-max-length-minus-inf", _profile("--max-length", "-inf"), 2,
     ["--max-length must be a finite number"], []),
    ("profile-dem-too-many-cells", ("profile", "{d}/bomb.tif", "--from", "5,5", "-o",
                                    "{d}/out/p.csv"), 1,
     ["bomb.tif: grid of 20,000 x 20,000 cells, more than the limit of 50,000,000"],
     []),
    ("profile-csv-z-huge", ("profile", "{d}/z_huge.csv", "-o", "{d}/out/p.csv"), 1,
     ["z_huge.csv: row 2: column 'z_m': 1e+308 m is not an elevation on Earth"], []),
    ("profile-csv-x-huge", ("profile", "{d}/x_huge.csv", "-o", "{d}/out/p.csv"), 1,
     ["x_huge.csv: row 3: column 'x_m': 1e+308 m is not a chainage"], []),
    ("profile-csv-x-tiny-step", ("profile", "{d}/x_tiny.csv", "-o", "{d}/out/p.csv"),
     1, ["x_tiny.csv: row 3: column 'x_m': vertices 1e-300 m apart"], []),
    # a model file's DEM or CSV profile read by simulate: never a flag simulate does
    # not have (the model reader names the file and field: engineer "safety"'s part,
    # so the fragments here hold with and without it)
    ("model-step-negative", _simulate("step_negative"), 1,
     ["step_m", "(got -1)"], ["--step"]),
    ("model-step-tiny", _simulate("step_tiny"), 1,
     ["step_m must be >= 0.01 of the cell size, 0.05 m (got 1e-09)"], ["--step"]),
    ("model-line-step-tiny", _simulate("line_step_tiny"), 1,
     ["1e-09 m would make about", "more than the limit of 20,000"], ["--step"]),
    ("model-from-text", _simulate("from_text"), 1, ["must be [x, y]"], ["--from"]),
    ("model-from-object", _simulate("from_object"), 1, ["must be [x, y]"], ["--from"]),
    ("model-from-bool", _simulate("from_bool"), 1, ["must be [x, y]"], ["--from"]),
    ("model-max-length-text", _simulate("max_length_text"), 1,
     ["must be a number (got 'x')"], ["--max-length"]),
    ("model-csv-units", _simulate("csv_units"), 1,
     ["must be 'm' or 'ft', not 'yards'"], ["--units"]),
    # synth: sizes, seeds, a block bouncing uphill, absurd effect values
    ("synth-paths-huge", _synth("--paths", "1000000", "--seed", "1"), 1,
     ["--paths must be from 1 to 5,000 (got 1000000)"], []),
    ("synth-paths-zero", _synth("--paths", "0", "--seed", "1"), 1,
     ["--paths must be from 1 to 5,000"], []),
    ("synth-seed-negative", _synth("--paths", "2", "--seed", "-1"), 1,
     ["--seed must be an integer from 0 to 2**128 - 1 (got -1)"], []),
    ("synth-track-seed-negative", _synth("--track", "--seed", "-5"), 1,
     ["--seed must be an integer from 0"], []),
    ("synth-flights-huge", _synth("--track", "--seed", "1", "--flights", "1000000"),
     1, ["--flights must be from 1 to 1,000 (got 1000000)"], []),
    ("synth-fps-huge", _synth("--track", "--seed", "1", "--fps", "1e9"), 1,
     ["--fps must be in (0, 100,000] frames/s"], []),
    ("synth-track-rows", _synth("--track", "--seed", "1", "--fps", "100000",
                                "--flights", "200"), 1,
     ["--fps: the first", "a track holds at most 600 s and 1,000,000 samples"], []),
    ("synth-track-too-long", _synth("--track", "--seed", "1", "--flights", "1000",
                                    "--launch-speed", "100", "--launch-angle", "80"),
     1, ["--flights: the first 27 of 1000 flights already last 613.1 s"], []),
    ("synth-launch-speed-absurd", _synth("--track", "--seed", "1", "--launch-speed",
                                         "1e6"), 1,
     ["--launch-speed must be in (0, 100] m/s"], []),
    ("synth-launch-angle-backwards", _synth("--track", "--seed", "1",
                                            "--launch-angle", "88"), 1,
     ["--launch-angle must be in (5, 85) deg"], []),
    ("synth-noise-m-absurd", _synth("--track", "--seed", "1", "--noise-m", "1e300"),
     1, ["--noise-m must be in [0, 1] m"], []),
    ("synth-track-rising-profile", _synth("--track", "--seed", "1", model="rising"),
     1, ["rising.json: profile: the profile rises 46.0 m", "mean dip -27.1 deg"], []),
    ("synth-effect-huge", _synth("--paths", "2", "--seed", "1", "--effects",
                                 "air_drag=cd=1e308"), 1,
     ["effects.air_drag.cd: must be in [0, 3]"], []),
    ("synth-effect-inf", _synth("--paths", "2", "--seed", "1", "--effects",
                                "angle_dependent_restitution=b=inf"), 1,
     ["effects.angle_dependent_restitution.b: must be", "(got inf)"], []),
    ("synth-noise-nan", _synth("--paths", "2", "--seed", "1", "--noise", "nan"), 2,
     ["--noise must be a finite number (got nan)"], []),
    # impact and fence: non-finite and absurd numbers
    ("impact-mass-inf", (*_IMPACT, "--en", "0.5", "--mass", "inf"), 2,
     ["--mass must be a finite number (got inf)"], []),
    ("impact-en-huge", (*_IMPACT, "--en", "1e308"), 1,
     ["--en must be at most 10 in size (got 1e+308)", "Table 2-4"], []),
    ("impact-vt-huge", (*_IMPACT[:2], "1e300", *_IMPACT[3:], "--en", "0.5"), 1,
     ["--vt must be at most 100 m/s in size (got 1e+300)"], []),
    ("impact-spin-huge", (*_IMPACT, "--en", "0.5", "--spin", "1e300"), 1,
     ["--spin must be at most 1000 rad/s in size"], []),
    ("impact-friction-huge", (*_IMPACT, "--en", "0.5", "--friction", "1e308"), 1,
     ["--friction must be at most 100 in size"], []),
    ("impact-friction-nan", (*_IMPACT, "--en", "0.5", "--friction", "nan"), 2,
     ["--friction must be a finite number (got nan)"], []),
    ("impact-angle-law-a-huge", (*_IMPACT, "--law", "angle", "--a", "1e308"), 1,
     ["--a must be at most 1000 in size (got 1e+308)"], []),
    ("impact-angle-law-e-n-absurd", (*_IMPACT, "--law", "angle", "--a", "999"), 1,
     ["e_N by eq. 5.4", "must be at most 10 in size (got 14.9732)"], []),
    ("impact-body-huge", ("impact", "--vt", "3", "--vn", "-5", "--en", "0.5",
                          "--mass", "1e300", "--radius", "1e300", "--gyration",
                          "1e300"), 1,
     ["--mass must be at most 1e+07 kg in size (got 1e+300)"], []),
    ("impact-shape-huge", ("impact", "--vt", "3", "--vn", "-5", "--en", "0.5",
                           "--shape", "cube", "--dimensions", "20"), 1,
     ["the body's mass (from --shape and --dimensions) must be at most 1e+07 kg"],
     []),
    ("impact-gyration-tiny", ("impact", "--vt", "3", "--vn", "-5", "--en", "0.5",
                              "--radius", "0.2", "--gyration", "1e-300"), 1,
     ["--gyration must be at least 0.001 m (got 1e-300)"], []),
    ("impact-dimensions-huge", ("impact", "--speed", "22", "--angle", "25",
                                "--shape", "sphere", "--dimensions", "1e300",
                                "--law", "angle"), 1,
     ["--dimensions must be at most 20 m in size (got 1e+300)"], []),
    ("impact-grazing-angle-law", ("impact", "--speed", "22", "--angle", "1e-300",
                                  "--shape", "sphere", "--dimensions", "0.75",
                                  "--law", "angle"), 1,
     ["e_N by eq. 5.4", "must be at most 10 in size (got inf)"], ["Warning"]),
    ("fence-grazing-angle-law", (*_FENCE[:9], "--radius", "0.43", "--angle-in",
                                 "1e-300", *_FENCE[11:]), 1,
     ["e_N by eq. 5.4 at --angle-in 1e-300 deg must be at most 10"], ["--e-n"]),
    ("impact-offset-huge", (*_IMPACT, "--en", "0.5", "--friction", "0.5",
                            "--offset", "1e300"), 1,
     ["--offset must be at most 10 m in size"], []),
    ("fence-impulse-huge", (*_FENCE[:-2], "--impulse", "1e308", *_FENCE[-2:]), 1,
     ["--impulse must be at most 1e+09 N s in size"], []),
    ("fence-law-absurd", (*_FENCE[:-2], "--stiff", "1e-308,1e-308", *_FENCE[-2:]), 1,
     ["--stiff: coefficient must be in [1, 1e12] N/s^x"], []),
    ("fence-angle-out-huge", (*_FENCE[:-2], "--angle-out", "1e300", *_FENCE[-2:]),
     1, ["--angle-out must be at most 180 deg in size"], []),
    ("fence-speed-huge", (*_FENCE[:6], "1e9", *_FENCE[7:]), 1,
     ["--speed-in must be at most 100 m/s in size (got 1e+09)"], []),
    ("fence-e-n-huge", (*_FENCE[:9], "--radius", "0.43", "--angle-in", "50",
                        "--e-n", "1e308", *_FENCE[11:]), 1,
     ["--e-n must be at most 10 in size"], []),
    ("fence-spin-inf", (*_FENCE[:8], "inf", *_FENCE[9:]), 2,
     ["--spin-in must be a finite number (got inf)"], []),
    # slopes outside (-180, 180] (a dip; beyond +-90 deg an overhang)
    ("table-slope-400", ("diagnose", "{d}/slope400.csv", "--model", "{d}/smoke.json",
                         "--seed", "1"), 1,
     ["slope400.csv: row 2: slope_deg 400 is outside (-180, 180] deg"], []),
    ("fieldbook-slope-200", ("reduce", "--fieldbook", "{d}/book.csv", "--stations",
                             "{d}/stations.gpx", "--declination", "14.2", "--theta0",
                             "30", "-o", "{d}/out/r.csv"), 1,
     ["book.csv: row 4: column 'slope_deg': 200° is not a ground dip"], []),
    # ImpactTables that are not what their extension says
    ("table-corrupt-xlsx", ("diagnose", "{d}/corrupt.xlsx", "--model",
                            "{d}/smoke.json", "--seed", "1"), 1,
     ["corrupt.xlsx: not a readable XLSX file"], []),
    ("table-zip-not-xlsx", ("diagnose", "{d}/other_zip.xlsx", "--model",
                            "{d}/smoke.json", "--seed", "1"), 1,
     ["other_zip.xlsx: not a readable XLSX file"], []),
    ("table-text-parquet", ("diagnose", "{d}/text.parquet", "--model",
                            "{d}/smoke.json", "--seed", "1"), 1,
     ["text.parquet: not a readable PARQUET file"], []),
    ("table-binary-csv", ("diagnose", "{d}/binary.csv", "--model", "{d}/smoke.json",
                          "--seed", "1"),
     1, ["binary.csv: not a UTF-8 text CSV file (NUL bytes"], []),
]  # fmt: skip


@pytest.mark.parametrize(
    ("argv", "code", "fragments", "forbidden"),
    [pytest.param(*case[1:], id=case[0]) for case in CASES],
)
def test_hostile_input_is_one_clean_line(cli, site, argv, code, fragments, forbidden):
    before = _state(site)
    result = cli(*(a.replace("{d}", str(site)) for a in argv))
    stderr = result.stderr.replace(str(site) + "/", "")
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert result.exit_code == code, (result.exit_code, stderr, result.exception)
    assert "Traceback" not in stderr + result.stdout
    assert len(lines) == 1 and lines[0].startswith("error: "), stderr
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    for word in forbidden:
        assert word not in lines[0], (word, lines[0])
    assert _state(site) == before  # nothing written, no input changed
    assert not (site / "out").exists()


def test_an_all_empty_column_is_called_empty_not_missing(cli, site, tmp_path):
    """A column the table has but never fills is 'present but empty'; one it lacks is
    'missing' (the two used to read the same)."""
    table = site / "synth.csv"
    made = cli("synth", site / "smoke.json", "--paths", "12", "--seed", "0",
               "-o", table)  # fmt: skip
    assert made.exit_code == 0, made.stderr
    frame = pd.read_csv(table)
    frame["radius_m"] = np.nan
    frame.drop(columns=["material"]).to_csv(site / "holes.csv", index=False)
    result = cli("fit", site / "holes.csv", "--model", site / "smoke.json",
                 "-o", tmp_path / "fit.json")  # fmt: skip
    line = result.stderr.strip()
    assert result.exit_code == 1 and "\n" not in line, result.stderr
    assert "missing column(s) material;" in line
    assert "column(s) radius_m present but empty (no value in any row)" in line


def test_an_infinite_friction_is_still_accepted(cli):
    """--friction's default is inf (slip always stops): the non-finite check and
    the physical size both let it through."""
    result = cli(*_IMPACT[:-2], "--en", "0.5", "--friction", "inf")
    assert result.exit_code == 0, result.stderr
    assert "mu = inf (slip stops before separation" in result.stdout


def test_synthetic_track_goes_down_the_slope(cli, site):
    """Every flight of `synth --track` lands lower and further along +x than it left
    (x increases in the direction of travel, ARCHITECTURE §2), and every file
    written is reported."""
    out = site / "track.csv"
    result = cli("synth", site / "smoke.json", "--track", "--seed", "3", "--flights",
                 "6", "--launch-angle", "80", "--noise-m", "0", "-o", out)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert result.stdout.strip().splitlines()[-1] == f"wrote {out}"
    frame = pd.read_csv(out)
    for _, flight in frame.groupby("flight_true"):
        assert flight["x_m_true"].is_monotonic_increasing
        assert flight["z_m_true"].iloc[-1] < flight["z_m_true"].iloc[0]


def test_profile_and_fence_report_every_file_written(cli, site):
    profile = site / "p.csv"
    result = cli("profile", site / "terrain.asc", "--from", START, "-o", profile)
    assert result.exit_code == 0, result.stderr
    assert f"wrote {profile}" in result.stdout.splitlines()
    fence_json, fence_png = site / "f.json", site / "f.png"
    result = cli(*_FENCE[:-2], "-o", fence_json, "--figure", fence_png)
    assert result.exit_code == 0, result.stderr
    written = [line for line in result.stdout.splitlines() if line.startswith("wrote")]
    assert sorted(written) == sorted([f"wrote {fence_json}", f"wrote {fence_png}"])


def test_a_descent_reaching_the_vertex_limit_says_so(cli, site, monkeypatch):
    """The default length (the grid's width plus height) is not refused up front;
    a line that reaches the vertex limit stops there and the output says why."""
    import fieldkit.model.dem_profile as dem_profile

    monkeypatch.setattr(dem_profile, "MAX_SECTION_VERTICES", 50)
    out = site / "p.csv"
    result = cli("profile", site / "terrain.asc", "--from", START, "--step", "0.05",
                 "-o", out)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "ended: reached the limit of 50 vertices" in result.stdout
    assert len(out.read_text().splitlines()) == 1 + 50


def test_an_undefined_e_t_is_said_not_printed_as_nan(cli):
    """v_iT = 0: e_T = v_fT/v_iT has no value; the report says so instead of 'nan'."""
    result = cli("impact", "--vt", "0", "--vn", "-5", "--en", "0.5", "--radius", "0.2",
                 "--gyration", "0.1", "--mass", "10")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "not defined (v_iT = 0)" in result.stdout
    assert "nan" not in result.stdout
