"""Walk-through: find a missing physical effect, add it, watch the error fall.

The loop of issue 10 on data where the truth is known:

1. **Measurements with a hidden effect.** ``fieldkit synth`` simulates 25 rocks
   down Tornado Mountain with the thesis's RocFall inputs (Table 7-1) and, hidden,
   the thesis's own angle-dependent restitution (eq. 5.4, exponent b = 1.03),
   then adds 5 % measurement noise to the rebound velocities. The table looks
   like a reduced survey: impacts, rebounds, e_n, e_t.
2. **The baseline fails, and the report shows where.** ``fieldkit diagnose``
   fits the constant e_n, e_t of the base model (what RocFall and CRSP users
   start from) and scores it on held-out paths; its residuals depend on the
   impact angle (a test, printed).
3. **The diagnosis names the effect** — angle_dependent_restitution, ranked
   first with its held-out gain and the gain's standard error — and recovers
   b within its uncertainty.
4. **Add it; the error falls.** The calibrated model (``-o``) carries the
   effect; the held-out error before and after is printed.

Run:  python examples/diagnose_hidden_effect.py [OUT_DIR]
(OUT_DIR default ``out/diagnose_hidden_effect``; the report is OUT_DIR/report.md.)
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

MODEL = (
    Path(__file__).resolve().parents[1]
    / "surveys"
    / "tornado_mountain"
    / "model_rocfall_table_7_1.json"
)
TRUE_B = 1.03  # thesis eq. 5.4


def fieldkit(*args: str) -> str:
    """Run a fieldkit command as a user would; echo it and its output."""
    print("$ fieldkit " + " ".join(args), flush=True)
    done = subprocess.run(
        [sys.executable, "-m", "fieldkit", *args],
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        sys.exit(done.stderr.strip())
    print(done.stdout, flush=True)
    return done.stdout


def main(out: Path) -> None:
    table = out / "tornado_hidden.csv"
    fieldkit(
        "synth", str(MODEL), "--paths", "25", "--seed", "7", "--noise", "0.05",
        "--effects", f"angle_dependent_restitution=b={TRUE_B}", "-o", str(table),
    )  # fmt: skip
    fieldkit(
        "diagnose", str(table), "--model", str(MODEL), "--seed", "1",
        "--json", str(out / "diagnosis.json"), "--report", str(out / "report"),
        "--rrd", str(out / "diagnosis.rrd"), "-o", str(out / "calibrated.json"),
    )  # fmt: skip
    d = json.loads((out / "diagnosis.json").read_text())
    base, after = d["baseline"]["cv_rmse_mps"], d["after"]["cv_rmse_mps"]
    hits = [
        x["feature"] for x in d["dependence"]["before"]
        if x["significant"] and x["component"] == "vfn"
    ]  # fmt: skip
    print(f"baseline residuals (vfn) depend on: {', '.join(hits) or 'nothing'}")
    top = d["candidates"][0]
    print(
        f"ranked first: {top['effect']}, held-out gain {top['improvement']:.1%} "
        f"± {top['improvement_se']:.1%}"
    )
    print(f"recommended: {d['recommended']}")
    b = d["after"]["params"]["angle_dependent_restitution.b"]
    b_sd = d["after"]["params_sd"]["angle_dependent_restitution.b"]
    print(
        f"fitted b = {b:.3f} ± {b_sd:.3f} (hidden truth {TRUE_B}; "
        f"{abs(b - TRUE_B) / b_sd:.1f} SE away)"
    )
    print(
        f"held-out error {base:.3f} -> {after:.3f} m/s "
        f"({1 - after / base:.0%} lower) with {', '.join(d['after']['effects'])}"
    )
    print(f"report: {out / 'report' / 'report.md'}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out/diagnose_hidden_effect"))
