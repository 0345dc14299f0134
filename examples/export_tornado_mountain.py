"""End to end for boulder A: survey -> reduce -> fit -> export to every simulator.

Runs the command lines a user types (``python -m fieldkit ...``), writing only into
OUT_DIR (default ``out/export_tornado_mountain``; nothing generated is committed):

1. ``fieldkit reduce`` -- boulder A's surveyed impacts and tree strikes (thesis §2.2.2)
   to an ImpactTable;
2. ``fieldkit fit --paths`` -- the simulator calibrated on the whole surveyed path
   (runout, flight heights, impact spacing, impact speeds; see
   ``examples/calibrate_tornado_mountain.py``) from
   ``surveys/tornado_mountain/model_path_start.json`` (Table 7-1 + eq. 7.1 + the
   bench as a material): colluvium e_n, e_t, the velocity scale K, bench e_n, e_t;
3. ``fieldkit export`` -- the calibrated model to RocFall, CRSP and JSON, and to the
   grid simulators Rockyfor3D, RAMMS::ROCKFALL and r.stone on the 2-D section
   extruded across (``--extrude``: boulder A's site has no DEM in the thesis).

For every target it prints the files written and the README's account of what could
not be mapped and of the mismatch left where a class or category was chosen.

Run:  python examples/export_tornado_mountain.py [OUT_DIR]
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
SURVEY = HERE.parent / "surveys" / "tornado_mountain"
SEED = 2004
#: (target, extra arguments): grid targets on the extruded section, 5 m cells
#: (r.stone steps 5 m).
TARGETS = [
    ("rocfall", []),
    ("crsp", []),
    ("json", []),
    ("rockyfor3d", ["--extrude", "--cellsize", "5"]),
    ("ramms", ["--extrude", "--cellsize", "5"]),
    ("rstone", ["--extrude", "--cellsize", "5"]),
]

_spec = importlib.util.spec_from_file_location(
    "calibrate_tornado_mountain", HERE / "calibrate_tornado_mountain.py"
)
calibrate = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(calibrate)


def fieldkit(*args: object) -> str:
    """Run ``fieldkit ARGS`` as a user would; print the command and its output."""
    words = [str(a) for a in args]
    shown = " ".join(w if " " not in w else f"'{w}'" for w in words)
    print(f"\n$ fieldkit {shown}")
    done = subprocess.run(
        [sys.executable, "-m", "fieldkit", *words],
        capture_output=True,
        text=True,
    )
    if done.returncode != 0:
        sys.exit(f"fieldkit {words[0]} failed:\n{done.stderr}")
    print(done.stdout.rstrip())
    return done.stdout


def section(readme: str, title: str) -> list[str]:
    """The bullet lines under ``## title`` of a README."""
    lines, inside = [], False
    for line in readme.splitlines():
        if line.startswith("## "):
            inside = line[3:].startswith(title)
            continue
        if inside and line.startswith("* "):
            lines.append(line)
    return lines


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    table = out / "boulder_a.csv"
    fieldkit(
        "reduce", "--impacts", SURVEY / "boulder_a_impacts.gpx",
        "--trees", SURVEY / "boulder_a_trees.csv",
        "--preset", SURVEY / "boulder_a_preset.toml", "-o", table,
    )  # fmt: skip
    bounds = []
    for name, (lo, hi) in calibrate.PATH_FREE.items():
        bounds += ["--free", name, "--bound", f"{name}={lo},{hi}"]
    calibrated = out / "calibrated.json"
    fieldkit(
        "fit", "--paths", table, "--model", SURVEY / "model_path_start.json",
        "--preset", SURVEY / "boulder_a_preset.toml", *bounds,
        "--rocks", str(calibrate.PATH_ROCKS),
        "--bootstrap", str(calibrate.PATH_BOOTSTRAP), "--seed", str(SEED),
        "-o", calibrated, "--json", out / "fit.json",
    )  # fmt: skip
    for name, extra in TARGETS:
        folder = out / name
        fieldkit("export", calibrated, "--to", name, "-o", folder, "--force", *extra)
        files = sorted(p.name for p in folder.iterdir())
        print(f"  files: {', '.join(files)}")
        readme = (folder / "README.md").read_text(encoding="utf-8")
        for line in section(readme, "Residual mismatch"):
            print(f"  mismatch: {line[2:]}")


if __name__ == "__main__":
    default = Path("out/export_tornado_mountain")
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else default)
