"""Hostile inputs from issue 17's independent audit, at the readers.

* A track whose times go backwards or repeat (audit dia17, dia18): `diagnose` read it
  with its own reader, found five flights on a four-flight track and exited 0. Every
  track reader now goes through :func:`fieldkit.io.tracking_export.check_track_values`.
* An ImpactTable with an impossible body or measurement (audit vie15, dia20): mass
  ``inf`` (``view`` wrote a recording, a numpy warning leaked) or ``-500``
  (``diagnose``, ``fit`` and ``view`` accepted it).
  :meth:`fieldkit.impact_table.ImpactTable.read` bounds the measured columns
  (:data:`fieldkit.impact_table.READ_BOUNDS`).

Every refusal: exit 1, one ``error:`` line naming file, row and column, no traceback,
nothing written, the input unchanged.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

REPO = Path(__file__).resolve().parents[2]
ASPHALT = REPO / "surveys" / "asphalt" / "model_rocfall_table_7_1.json"


@pytest.fixture(scope="module")
def four_flights(tmp_path_factory) -> Path:
    """The audit's tr.csv: `synth --track --fps 100 --flights 4 --seed 1`."""
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("track") / "tr.csv"
    args = ["synth", str(ASPHALT), "--track", "--fps", "100", "--flights", "4",
            "--seed", "1", "-o", str(out)]  # fmt: skip
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    return out


def _edit_track(source: Path, target: Path, edit) -> Path:
    lines = source.read_text().splitlines()
    rows = [line.split(",") for line in lines[1:]]
    edit(rows)
    target.write_text("\n".join([lines[0], *(",".join(r) for r in rows)]) + "\n")
    return target


def _swap(rows):  # the audit's edit: data rows 151 and 152 (file rows 152, 153)
    rows[150][1], rows[151][1] = rows[151][1], rows[150][1]


def _repeat(rows):
    rows[151][1] = rows[150][1]


def _far(rows):
    rows[200][2] = "1e6"  # x_m 1000 km


TRACK_CASES = {
    "backwards": (_swap, "row 153: times are not increasing: 1.5 s goes back from "
                  "1.51 s of the row before"),
    "repeated": (_repeat, "row 153: times are not increasing: 1.5 s repeats 1.5 s"),
    "far": (_far, "row 202: x_m 1e+06: beyond 100000 m"),
}  # fmt: skip


@pytest.mark.parametrize("case", list(TRACK_CASES))
@pytest.mark.parametrize("command", ["diagnose", "view"])
def test_every_track_reader_refuses_bad_times_and_coordinates(
    case, command, four_flights, tmp_path, cli, fails, digest
):
    edit, fragment = TRACK_CASES[case]
    track = _edit_track(four_flights, tmp_path / f"tr_{case}.csv", edit)
    before = digest(track)
    out = tmp_path / "out"
    if command == "diagnose":
        args = ["diagnose", track, "--radius", "0.725", "--seed", "1",
                "--json", out / "d.json"]  # fmt: skip
    else:
        args = ["view", track, "--radius", "0.36", "-o", out / "t.rrd"]
    r = cli(*args)
    assert r.exit_code == 1, r.output
    fails(r, f"tr_{case}.csv", fragment)
    assert "Traceback" not in r.output
    assert not out.exists()
    assert digest(track) == before


def test_the_unedited_track_still_diagnoses_four_flights(four_flights, tmp_path, cli):
    """The check refuses only the edited rows: the audit's own track diagnoses."""
    out = tmp_path / "d.json"
    r = cli("diagnose", four_flights, "--seed", "1", "--json", out)
    assert r.exit_code == 0, r.output
    assert "4 flights from" in out.read_text()


def _table(path: Path, **cells) -> Path:
    """A derived three-path ImpactTable, with ``cells`` = {column: (row, value)}."""
    from fieldkit.impact_table import ImpactTable

    n = 9
    frame = pd.DataFrame(
        {
            "path_id": np.repeat(["A", "B", "C"], 3),
            "point": np.tile(["1", "2", "3"], 3),
            "x_m": np.tile([5.0, 12.0, 20.0], 3),
            "z_m": np.tile([100.0, 94.0, 88.0], 3),
            "slope_deg": np.full(n, 35.0),
            "material": ["rock"] * n,
            "mass_kg": np.full(n, 500.0),
            "radius_m": np.full(n, 0.36),
            "gyration_m": np.full(n, 0.295),
            "vi_x_mps": np.linspace(6.0, 9.0, n),
            "vi_z_mps": np.linspace(-5.0, -7.0, n),
            "vf_x_mps": np.linspace(5.0, 7.0, n),
            "vf_z_mps": np.linspace(1.0, 2.0, n),
            "omega_i_radps": np.full(n, -10.0),
            "omega_f_radps": np.full(n, -12.0),
        }
    )
    frame = ImpactTable(frame, source="test").derive().frame
    for column, (row, value) in cells.items():
        frame.loc[row, column] = value
    frame.to_csv(path, index=False)
    return path


#: case -> ({column: (0-based row, value)}, fragment of the error line)
TABLE_CASES = {
    "mass-inf": ({"mass_kg": (0, np.inf)},
                 "row 1: column mass_kg: inf is outside [0.001, 1e+07] kg"),
    "mass-negative": ({"mass_kg": (3, -500.0)},
                      "row 4: column mass_kg: -500 is outside [0.001, 1e+07] kg"),
    "mass-huge": ({"mass_kg": (2, 1e12)}, "row 3: column mass_kg: 1e+12 is outside"),
    "radius-zero": ({"radius_m": (4, 0.0)},
                    "row 5: column radius_m: 0 is outside [0.001, 10] m"),
    "radius-huge": ({"radius_m": (4, 50.0)},
                    "row 5: column radius_m: 50 is outside [0.001, 10] m"),
    "gyration-minus-inf": ({"gyration_m": (1, -np.inf)},
                           "row 2: column gyration_m: -inf is outside"),
    "gyration-huge": ({"gyration_m": (6, 30.0)},
                      "row 7: column gyration_m: 30 is outside [0.001, 10] m"),
    "speed-huge": ({"vi_z_mps": (5, -1e5)},
                   "row 6: column vi_z_mps: -100000 is outside [-100, 100] m/s"),
    "x-huge": ({"x_m": (8, 1e308)},
               "row 9: column x_m: 1e+308 is outside [-1e+07, 1e+07] m"),
    "z-huge": ({"z_m": (0, 20000.0)},
               "row 1: column z_m: 20000 is outside [-11000, 11000] m"),
    "spin-inf": ({"omega_f_radps": (2, np.inf)},
                 "row 3: column omega_f_radps: inf is not a finite number"),
    "first-row-wins": ({"vf_x_mps": (7, 1e3), "mass_kg": (2, -1.0)},
                       "row 3: column mass_kg: -1 is outside"),
}  # fmt: skip


def _args(command: str, table: Path, out: Path) -> list:
    if command == "view":
        return ["view", table, "-o", out / "t.rrd"]
    if command == "diagnose":
        return ["diagnose", table, "--seed", "1", "--json", out / "d.json"]
    return ["fit", table, "--model", ASPHALT, "-o", out / "m.json"]


@pytest.mark.parametrize("case", list(TABLE_CASES))
def test_table_reader_refuses_impossible_values(case, tmp_path, cli, fails, digest):
    cells, fragment = TABLE_CASES[case]
    table = _table(tmp_path / f"{case}.csv", **cells)
    before = digest(table)
    out = tmp_path / "out"
    r = cli(*_args("diagnose", table, out))
    assert r.exit_code == 1, r.output
    fails(r, f"{case}.csv", fragment)
    assert "Traceback" not in r.output and "Warning" not in r.output
    assert not out.exists()
    assert digest(table) == before


@pytest.mark.parametrize("command", ["view", "diagnose", "fit"])
@pytest.mark.parametrize("mass", [np.inf, -500.0])
def test_every_table_command_refuses_an_impossible_mass(
    command, mass, tmp_path, cli, fails
):
    """The audit's vie15 (view, mass inf) and dia20 (diagnose, mass -500), and fit."""
    table = _table(tmp_path / "t.csv", mass_kg=(0, mass))
    out = tmp_path / "out"
    r = cli(*_args(command, table, out))
    assert r.exit_code == 1, r.output
    fails(r, "t.csv: row 1: column mass_kg", f"{mass:g} is outside")
    assert "RuntimeWarning" not in r.output
    assert not out.exists()


def test_missing_body_values_are_still_read(tmp_path, cli):
    """NaN (not measured) passes the bounds: a table without a mass on a row views."""
    table = _table(tmp_path / "t.csv", mass_kg=(0, np.nan), omega_i_radps=(1, np.nan))
    r = cli("view", table, "-o", tmp_path / "t.rrd")
    assert r.exit_code == 0, r.output
    assert (tmp_path / "t.rrd").stat().st_size > 0


def test_an_elongated_body_with_k_beyond_r_is_read(tmp_path, cli, repo):
    """k <= r holds for compact bodies only: a table from `reduce --shape ellipsoid`
    landing on its side (k = 0.68 m, r = 0.25 m) is read back by `view`."""
    gpx = repo / "surveys" / "tornado_mountain" / "boulder_a_impacts.gpx"
    table = tmp_path / "long.csv"
    r = cli("reduce", "--impacts", gpx, "--theta0", "32.6", "--shape", "ellipsoid",
            "--dimensions", "3,0.5,0.5", "--radius", "0.25", "-o", table)  # fmt: skip
    assert r.exit_code == 0, r.output
    frame = pd.read_csv(table)
    assert (frame["gyration_m"] > 2.7 * frame["radius_m"]).all()
    r = cli("view", table, "-o", tmp_path / "long.rrd")
    assert r.exit_code == 0, r.output


def test_read_bounds_are_the_body_option_bounds():
    """One set of numbers: the table's body bounds are those of --mass/--radius."""
    from fieldkit.cli.common import BODY_MINIMA, PHYSICAL_LIMITS
    from fieldkit.impact_table import READ_BOUNDS

    assert READ_BOUNDS["mass_kg"][:2] == (
        BODY_MINIMA["mass_kg"][0], PHYSICAL_LIMITS["mass_kg"][0],
    )  # fmt: skip
    for name in ("radius_m", "gyration_m"):
        assert READ_BOUNDS[name][:2] == (
            BODY_MINIMA["length_m"][0], PHYSICAL_LIMITS["length_m"][0],
        )  # fmt: skip
    assert READ_BOUNDS["vi_x_mps"][1] == PHYSICAL_LIMITS["speed_mps"][0]
