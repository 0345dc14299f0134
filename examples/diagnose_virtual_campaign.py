"""Walk-through: a virtual field campaign with a hidden effect, from raw files to
the diagnosis, with the survey and the reduction in the loop (issue 18).

1. **Rocks with a hidden law, surveyed as a geologist would.** ``fieldkit synth
   --survey`` simulates rocks down Tornado Mountain (boulder A's section, Table
   7-1's RocFall inputs) with RocFall's velocity scaling hidden (eq. 7.1, K = 7
   m/s), and writes what a field crew would bring back: scars only where an impact
   marks the ground (5 kJ), neighbouring scars merged (2 m), 0.5 m GNSS error on
   every point, tree strikes with 0.25 m height error, and no launch angle -- plus
   the truth beside them.
2. **Reduced like the thesis.** ``fieldkit reduce --campaign`` solves every
   flight with the assumed launch angle 32.6 deg where no tree fixes it.
3. **Diagnosed with its null.** ``fieldkit diagnose`` simulates effect-free
   campaigns under the fitted baseline on each path's own profile, surveys and
   reduces them the same way, and recommends a law only when its held-out gain
   beats theirs (the 95 % quantile).
4. **Campaign size.** The same is done for 1, 3 (and with ``--full`` 10) surveyed
   paths; the script says at which size the hidden law starts being found. One
   campaign per size is an anecdote: the rates over many campaigns are in
   ``benchmarks/bench_campaign_power.py`` (``make bench-diagnose``) and the
   README's table.

Run:  python examples/diagnose_virtual_campaign.py [OUT_DIR] [--quick | --full]
(OUT_DIR default ``out/diagnose_virtual_campaign``; about a minute on 2 cores;
``--quick``: the 1-path campaign only, about half that (the fast test suite's run);
``--full``: 10 paths too, null 99 and power 40 per diagnosis, about half an hour.)
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
HIDDEN = "velocity_scaled_restitution"
TRUE_K_MPS = 7.0  # the test size (RocFall's default is 9.144 m/s)
SEED = 11


def fieldkit(*args: str) -> str:
    """Run a fieldkit command as a user would; echo it and the end of its output."""
    print("$ fieldkit " + " ".join(args), flush=True)
    done = subprocess.run(
        [sys.executable, "-m", "fieldkit", *args],
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        sys.exit(done.stderr.strip())
    lines = done.stdout.strip().splitlines()
    print("\n".join(lines[-6:]), flush=True)
    return done.stdout


def campaign(out: Path, paths: int, null: int, power: int) -> dict:
    """Survey ``paths`` rocks, reduce them, diagnose them; the diagnosis JSON."""
    folder = out / f"campaign_{paths:02d}"
    fieldkit(
        "synth", str(MODEL), "--survey", "--paths", str(paths), "--seed",
        str(SEED + paths), "--effects", f"{HIDDEN}=k_mps={TRUE_K_MPS}",
        "--tree-spacing", "15", "-o", str(folder),
    )  # fmt: skip
    table = out / f"campaign_{paths:02d}.csv"
    fieldkit("reduce", "--campaign", str(folder), "-o", str(table))
    diagnosis = out / f"diagnosis_{paths:02d}.json"
    fieldkit(
        "diagnose", str(table), "--seed", "1", "--null", str(null), "--power",
        str(power), "--no-sensitivity", "--json", str(diagnosis),
        "--report", str(out / f"diagnosis_{paths:02d}"),
    )  # fmt: skip
    return json.loads(diagnosis.read_text(encoding="utf-8"))


def main(out: Path, full: bool, quick: bool = False) -> None:
    sizes = (1, 3, 10) if full else (1,) if quick else (1, 3)
    null, power = (99, 40) if full else (19, 0)
    found_at = None
    rows = []
    for paths in sizes:
        d = campaign(out, paths, null, power)
        n = d["null"]
        impacts = d["n_rows"]
        threshold = (
            f"{n['threshold']:+.1%}" if n["threshold"] is not None else "not available"
        )
        best = max(d["candidates"], key=lambda c: c["improvement"])
        rows.append(
            f"{paths:>2} path(s), {impacts} rows: recommended "
            f"{d['recommended'] or 'nothing'}; best {best['effect']} gain "
            f"{best['improvement']:+.1%} ± {best['improvement_se']:.1%}, null "
            f"threshold {threshold} ({n['size']} campaigns), p = "
            f"{n['p_value']:.2f}"
        )
        if d["recommended"] == HIDDEN and found_at is None:
            found_at = paths
        if d["recommended"] and d["recommended"] != HIDDEN:
            rows.append(f"   a wrong finding: {d['recommended']} (truth {HIDDEN})")
    print(f"\nhidden: {HIDDEN} at K = {TRUE_K_MPS:g} m/s; one campaign per size:")
    for row in rows:
        print("  " + row)
    if found_at is None:
        print(
            f"the hidden law is not found with up to {sizes[-1]} surveyed paths "
            "in these campaigns"
        )
    else:
        print(f"the hidden law is first found with {found_at} surveyed path(s)")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    main(
        Path(args[0]) if args else Path("out/diagnose_virtual_campaign"),
        full="--full" in sys.argv[1:],
        quick="--quick" in sys.argv[1:],
    )
