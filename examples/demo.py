"""`make demo`: the whole loop on boulder A in about a minute.

Tornado Mountain boulder A (thesis §2.2.2, §7.5.4), surveyed impact by impact, runs
through every stage a user would run, as the command lines a user types
(``python -m fieldkit ...``), writing only into OUT_DIR (default ``out/demo``):

1. ``fieldkit reduce`` -- the GPS impacts and tree strikes to an ImpactTable, with the
   survey's preset (θ0, body, material mapping:
   ``surveys/tornado_mountain/boulder_a_preset.toml``);
2. ``fieldkit diagnose`` -- Table 7-1's model against the measured rebounds: held-out
   error and which effect (if any) the impacts ask for;
3. ``fieldkit fit --paths`` -- the simulator calibrated on the whole surveyed path
   (runout, flight heights, impact spacing, impact speeds), from
   ``surveys/tornado_mountain/model_path_start.json``;
4. ``fieldkit simulate`` -- the calibrated model, 2,000 rocks, compared with what
   boulder A did at x = 610 m (18 m/s, 600 kJ; §7.5.4);
5. ``fieldkit export`` -- the calibrated model as RocFall input blocks.

Each step prints one line; the commands' own output goes to ``OUT_DIR/logs/``, and
``OUT_DIR/index.md`` links every figure and report. The numbers are a small-sample
demonstration (few rocks, few bootstrap resamples): the README and
``examples/calibrate_tornado_mountain.py`` give the measured ones.

Run:  python examples/demo.py [OUT_DIR]
"""

from __future__ import annotations

import importlib.util
import json
import shlex
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
SURVEY = REPO / "surveys" / "tornado_mountain"
PRESET = SURVEY / "boulder_a_preset.toml"
SEED = 1
#: The path fit of examples/calibrate_tornado_mountain.py (its free parameters and
#: search bounds: PATH_FREE), smaller: rocks per evaluation, Sobol screen, bootstrap.
PATH_ROCKS, PATH_SCREEN, PATH_BOOTSTRAP = 60, 8, 10
#: The diagnosis's null and power campaigns, fewer than the command's defaults (99
#: and 40) so the demo stays near a minute: 19 is the least for a 5 % test; the
#: power (40 per candidate, minutes) is the README command's.
DIAGNOSE_NULL, DIAGNOSE_POWER = 19, 0
_spec = importlib.util.spec_from_file_location(
    "calibrate_tornado_mountain", HERE / "calibrate_tornado_mountain.py"
)
_calibrate = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_calibrate)
PATH_FREE = _calibrate.PATH_FREE
SIM_ROCKS, X_ANALYSIS_M = 2000, 610.0
MEASURED = "x=610,speed=18,ke=600e3"  # §7.5.4


def relative(path: Path) -> str:
    """A path as the user would type it from the repository root."""
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


class Demo:
    """Runs the steps, keeps their logs and the lines of index.md."""

    def __init__(self, out: Path) -> None:
        self.out = out
        self.logs = out / "logs"
        self.logs.mkdir(parents=True, exist_ok=True)
        self.index: list[str] = []
        self.step = 0

    def run(self, name: str, *args: object) -> str:
        """Run ``fieldkit ARGS``; its output goes to logs/NN-name.txt."""
        self.step += 1
        words = [relative(a) if isinstance(a, Path) else str(a) for a in args]
        command = "fieldkit " + shlex.join(words)
        start = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-m", "fieldkit", *words],
            capture_output=True,
            text=True,
        )
        seconds = time.perf_counter() - start
        log = self.logs / f"{self.step:02d}-{name}.txt"
        log.write_text(
            f"$ {command}\n\n{done.stdout}\n{done.stderr}", encoding="utf-8"
        )
        if done.returncode != 0:
            sys.exit(
                f"step {self.step} ({name}) failed: {command}\n{done.stderr.strip()}"
            )
        self.index += [f"## {self.step}. {name}", "", "```", command, "```", ""]
        self.index.append(f"Output: [{log.name}](logs/{log.name}) ({seconds:.0f} s)")
        self.index.append("")
        return done.stdout

    def say(self, line: str) -> None:
        """The one line a step prints (also the step's summary in index.md)."""
        print(f"{self.step}. {line}", flush=True)
        self.index.append(line)
        self.index.append("")

    def link(self, folder: Path, about: str = "") -> None:
        """Link every PNG and markdown report in ``folder`` from index.md."""
        files = sorted(
            p for p in folder.rglob("*") if p.suffix in (".png", ".md") and p.is_file()
        )
        kinds = {p.suffix for p in files}
        title = {
            frozenset({".png"}): "Figures",
            frozenset({".md"}): "Report",
        }.get(frozenset(kinds), "Report and figures")
        if files:
            self.index.append(f"{title}{about}:")
            self.index.append("")
            for p in files:
                rel = p.relative_to(self.out).as_posix()
                self.index.append(f"- [{rel}]({rel})")
            self.index.append("")


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    demo = Demo(out)
    start = time.perf_counter()

    # 1. survey -> ImpactTable
    table = out / "boulder_a_impacts.csv"
    demo.run(
        "reduce", "reduce", "--preset", PRESET,
        "--impacts", SURVEY / "boulder_a_impacts.gpx",
        "--trees", SURVEY / "boulder_a_trees.csv",
        "-o", table, "--figures", out / "reduce",
    )  # fmt: skip
    frame = pd.read_csv(table)
    impacts = frame["e_n"].notna()
    sensitive = int(frame["qa_flags"].fillna("").str.contains("slope_sensitive").sum())
    demo.say(
        f"reduce: {impacts.sum()} impacts of boulder A, median e_n "
        f"{frame.loc[impacts, 'e_n'].median():.2f}, e_t "
        f"{frame.loc[impacts, 'e_t'].median():.2f} ({sensitive} e_n rest on the "
        f"slope assumed) -> {relative(table)}"
    )
    demo.index.append(
        f"At {sensitive} of the {impacts.sum()} impacts e_n rests more on the slope "
        "assumed (the chord from the previous point) than on the survey (quality flag "
        "`slope_sensitive`): the medians are of surveyed points, not surveyed slopes."
    )
    demo.index.append("")
    demo.link(out / "reduce")

    # 2. where Table 7-1's model fails on the measured rebounds
    diagnosis = out / "diagnose" / "diagnosis.json"
    demo.run(
        "diagnose", "diagnose", table,
        "--model", SURVEY / "model_rocfall_table_7_1.json", "--preset", PRESET,
        "--seed", SEED, "--json", diagnosis, "--report", out / "diagnose",
        "--null", DIAGNOSE_NULL, "--power", DIAGNOSE_POWER,
    )  # fmt: skip
    found = json.loads(diagnosis.read_text(encoding="utf-8"))
    demo.say(f"diagnose: {diagnosis_line(found)}")
    demo.index += [
        "The diagnosis scores impact laws on the measured *rebounds* (held out in "
        "blocks of consecutive impacts); the fit below calibrates the simulator on "
        "the whole *path* (runout, flight heights, spacing, speeds) from another "
        "start model. A velocity scale K from one is not the other's: they answer "
        "different questions with different data.",
        "",
    ]
    demo.link(out / "diagnose")

    # 3. calibrate the simulator on the whole path
    calibrated = out / "calibrated_model.json"
    fit_json = out / "fit" / "fit.json"
    bounds = []
    for name, (lo, hi) in PATH_FREE.items():
        bounds += ["--free", name, "--bound", f"{name}={lo},{hi}"]
    demo.run(
        "fit", "fit", "--paths", table,
        "--model", SURVEY / "model_path_start.json", "--preset", PRESET, *bounds,
        "--rocks", PATH_ROCKS, "--screen", PATH_SCREEN,
        "--bootstrap", PATH_BOOTSTRAP, "--seed", SEED,
        "-o", calibrated, "--json", fit_json, "--report", out / "fit",
    )  # fmt: skip
    fit = json.loads(fit_json.read_text(encoding="utf-8"))
    demo.say(f"fit: {fit_line(fit)} -> {relative(calibrated)}{consequence(fit)}")
    demo.index += [
        "One surveyed path: the ± are bootstrap standard errors over its surveyed "
        "points, a lower bound on the uncertainty (the points of one path are not "
        "independent).",
        "",
    ]
    demo.link(out / "fit")

    # 4. simulate the calibrated model, compare with boulder A at x = 610 m
    summary = out / "simulate" / "summary.json"
    demo.run(
        "simulate", "simulate", calibrated, "--rocks", SIM_ROCKS, "--seed", SEED,
        "--at", X_ANALYSIS_M, "--measured", MEASURED,
        "--summary", summary, "--figures", out / "simulate",
    )  # fmt: skip
    stats = json.loads(summary.read_text(encoding="utf-8"))
    demo.say(f"simulate: {simulate_line(stats)}")
    demo.link(out / "simulate")

    # 5. the calibrated model as RocFall input
    export = out / "export" / "rocfall"
    demo.run("export", "export", calibrated, "--to", "rocfall", "-o", export, "--force")
    files = sorted(p.name for p in export.iterdir())
    demo.say(f"export: {len(files)} RocFall files -> {relative(export)}")
    demo.link(export, " (what was mapped, and what could not be)")

    seconds = time.perf_counter() - start
    index = out / "index.md"
    head = [
        "# fieldkit demo: Tornado Mountain boulder A, the whole loop",
        "",
        "Survey -> ImpactTable -> diagnosis -> path calibration -> simulation -> "
        f"export, {seconds:.0f} s. Small samples (a demonstration): the README "
        "gives the measured figures.",
        "",
    ]
    index.write_text("\n".join(head + demo.index) + "\n", encoding="utf-8")
    print(f"wrote {relative(index)} (every figure and report, {seconds:.0f} s)")


def diagnosis_line(found: dict) -> str:
    """Recommended effects, the held-out error before and after, and the verdict
    against the null campaigns (the survey and the reduction in the loop)."""
    before = found["baseline"]["cv_rmse_mps"]
    added = [step["added"] for step in found["steps"]]
    null = found.get("null") or {}
    against = ""
    if null:
        best = null["observed_gain"]
        against = (
            f"; best gain {best:+.1%} against {null['size']} effect-free campaigns "
            f"through the same survey and reduction (threshold "
            f"{null['threshold']:+.1%}): {null['verdict']}"
        )
    if not added:
        return (
            f"no effect recommended; held-out error of Table 7-1's model "
            f"{before:.2f} m/s{against}"
        )
    after = found["steps"][-1]["cv_rmse_mps"]
    return (
        f"recommends {', '.join(added)}: held-out error of the rebound velocities "
        f"{before:.2f} -> {after:.2f} m/s ({1 - after / before:.0%} lower){against}"
    )


def consequence(fit: dict) -> str:
    """The fit's first word on the calibrated model at the asset: its first
    unconservative verdict (``fieldkit fit`` prints them all first), or none."""
    for verdict in fit.get("design", {}).get("verdicts", []):
        if verdict.startswith("unconservative") and "calibrated model" in verdict:
            return "; " + verdict.split(" [measured:")[0]
    return ""


def fit_line(fit: dict) -> str:
    """The fitted values (± bootstrap SE) and the fall of the score."""
    values = []
    for p in fit["parameters"]:
        owner, name = p["name"].split(".")[-2:]
        se = f" ± {p['stderr']:.2g}" if p.get("stderr") is not None else ""
        se += "*" if se and fit["n_runs"] == 1 else ""
        values.append(f"{owner} {name} {p['value']:.3g}{se}")
    lower_bound = (
        " (*one path: SE a lower bound)" if fit["n_runs"] == 1 and values else ""
    )
    return (
        f"{', '.join(values)}{lower_bound}; score {fit['objective_start']:.2f} -> "
        f"{fit['objective_optimum']:.2f} (sum over {len(fit['kinds'])} kinds of "
        "the mean CRPS scaled by its value at the start)"
    )


def simulate_line(stats: dict) -> str:
    """Runout and where boulder A's measured speed and energy fall at x = 610 m
    (a runout percentile that uses rocks which left the profile is a lower bound,
    "≥"; a measured value beyond every simulated rock has no percentile)."""
    runout = stats["runout_x_m"]
    bound = runout.get("lower_bound", {})

    def at(key: str) -> str:
        return ("≥ " if bound.get(key) else "") + f"{runout[key]:.0f} m"

    text = f"runout p50 {at('p50')}, p95 {at('p95')}"
    if bound.get("p95"):
        left = stats["runout_censored"]["fraction"]
        text += f" (end of profile; {100 * left:.0f} % of rocks left it)"
    for point in stats["measured"]:
        for key, label, scale, unit in (
            ("speed_mps", "speed", 1, "m/s"),
            ("ke_j", "KE", 1e-3, "kJ"),
        ):
            if key in point:
                m = point[key]
                where = (
                    f"{m['beyond']} all {m['n']:,} simulated rocks"
                    if m.get("beyond")
                    else f"at the {m['percentile']:.0f}th percentile"
                )
                text += (
                    f"; boulder A's {m['measured'] * scale:g} {unit} {label} at "
                    f"x = {point['x_m']:g} m is {where}"
                )
    return text


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out/demo"))
