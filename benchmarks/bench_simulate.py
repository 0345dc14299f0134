"""Impacts/s, rocks/s and peak memory of `fieldkit simulate`'s kernel vs its reference.

Profile: 100 segments, a concave slope from z = 300 m down to 0 over x = 0-600 m with
seeded noise in the vertex heights (so the segment dips vary), three materials by
chainage (rock < 150 m, talus < 400 m, soil beyond), every material with per-impact SDs
(e_n, e_t 0.04, friction 2 deg, roughness 4 deg). Cases: 10,000 and 100,000 rocks, the
base model and every registered effect switched on (non-neutral parameters; trees for
``tree_impacts``), 2 numba threads, after a warm-up compile.

Each timed case runs in its own subprocess, so its peak RSS (``VmHWM``) is clean;
the figure printed is the peak during the run minus the RSS just before it (after
imports and warm-up), plus tracemalloc's peak of Python/numpy allocations in a separate
untimed repeat. In the same run, ``fieldkit.model.reference`` (the one-rock-at-a-time
pure-Python simulator of the same physics and random numbers) simulates 200 rocks; its
rate is compared with the kernel's and its results with the kernel's for the same seed
(max abs difference, should be 0). A memory check runs 100,000 rocks without impacts and
with impacts streamed through ``on_impact_chunk`` (discarded): peak memory must not grow
with the number of impacts.

Targets (issue 9): base model >= 1,500,000 impacts/s, every effect on >= 500,000
impacts/s on this 2-core machine; printed, not asserted.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

SEED = 9
THREADS = 2
REFERENCE_ROCKS = 200
ROCK_COUNTS = (10_000, 100_000)
TARGET_IMPACTS_PER_S = {"base": 1_500_000, "all": 500_000}
STREAM_CHUNK_ROCKS = 5000


# --------------------------------------------------------------------------- model
def profile_dict(segments: int = 100) -> dict:
    """The benchmark profile (deterministic: seeded noise)."""
    rng = np.random.default_rng(SEED)
    x = np.linspace(0.0, 600.0, segments + 1)
    z = 300.0 * (1.0 - x / 600.0) ** 1.6  # concave: steep at the top, flat below
    z[1:-1] += rng.normal(0.0, 0.6, segments - 1)  # dips vary by a few deg
    material = np.where(
        x[1:] <= 150.0, "rock", np.where(x[1:] <= 400.0, "talus", "soil")
    )
    return {
        "x_m": [round(float(v), 3) for v in x],
        "z_m": [round(float(v), 3) for v in z],
        "material": [str(m) for m in material],
    }


def materials_dict() -> dict:
    sd = {"e_n_sd": 0.04, "e_t_sd": 0.04, "friction_deg_sd": 2.0}
    return {
        "rock": {"e_n": 0.45, "e_t": 0.85, "friction_deg": 30.0, **sd,
                 "roughness_m": 0.1, "roughness_deg_sd": 4.0},
        "talus": {"e_n": 0.35, "e_t": 0.80, "friction_deg": 35.0, **sd,
                  "roughness_m": 0.2, "roughness_deg_sd": 4.0},
        "soil": {"e_n": 0.30, "e_t": 0.70, "friction_deg": 38.0, **sd,
                 "roughness_m": 0.05, "roughness_deg_sd": 4.0},
    }  # fmt: skip


def active_value(parameter) -> float:
    """A non-neutral value for ``parameter``: its default, or a step off neutral."""
    default = float(parameter.default)
    neutral = getattr(parameter, "neutral", None)
    if neutral is None or default != float(neutral):
        return default
    upper, lower = float(parameter.upper), float(parameter.lower)
    if np.isfinite(upper) and upper > default:
        return default + 0.25 * (upper - default)
    if np.isfinite(lower) and lower < default:
        return default - 0.25 * (default - lower)
    return default + 1.0


def all_effects() -> dict:
    """Every registered effect with non-neutral parameters (from the registry)."""
    registry = importlib.import_module("fieldkit.model.effects.registry")
    return {
        spec.name: {p.name: active_value(p) for p in spec.parameters}
        for spec in registry.EFFECTS
    }


def model_data(case: str) -> dict:
    data = {
        "profile": profile_dict(),
        "materials": materials_dict(),
        "effects": {},
        "body": {"mass_kg": 1000.0, "radius_m": 0.45, "gyration_m": 0.28},
        "seeder": {"x_m": 2.0, "z_m": 302.0, "vx_mps": 2.0, "vz_mps": 0.0,
                   "vx_sd_mps": 0.5, "vz_sd_mps": 0.5, "mass_sd_kg": 100.0},
    }  # fmt: skip
    if case == "all":
        data["effects"] = all_effects()
        rng = np.random.default_rng(SEED + 1)
        n = 80
        data["trees"] = {
            "x_m": np.round(np.sort(rng.uniform(300.0, 590.0, n)), 2).tolist(),
            "diameter_m": np.round(rng.uniform(0.15, 0.4, n), 3).tolist(),
            "height_m": np.round(rng.uniform(8.0, 20.0, n), 1).tolist(),
        }
    return data


def build_model(case: str):
    from fieldkit.model.model_file import model_from_dict

    return model_from_dict(model_data(case), source=f"benchmark ({case})")


# --------------------------------------------------------------------------- child
def _status_kib(field: str) -> int:
    """A ``/proc/self/status`` memory field [KiB] (Linux)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(f"{field}:"):
            return int(line.split()[1])
    return 0


def rss_now_kib() -> int:
    """Current resident set size [KiB]."""
    return _status_kib("VmRSS")


def rss_peak_kib() -> int:
    """Peak resident set size of this process [KiB] (``VmHWM``). Not ``ru_maxrss``:
    Linux carries that high-water mark across fork and exec, so a child of a big
    parent (``make bench`` runs the impact-writing benchmark first) reports the
    parent's peak."""
    return _status_kib("VmHWM")


def set_threads() -> int:
    try:
        import numba
    except ImportError:
        return 1
    numba.set_num_threads(min(THREADS, numba.config.NUMBA_NUM_THREADS))
    return numba.get_num_threads()


def run_case(case: str, rocks: int, impacts: str) -> dict:
    """One timed case (run in a fresh process): rates and memory as a dict."""
    from fieldkit.model import simulate

    threads = set_threads()
    model = build_model(case)
    simulate(model, 50, np.random.default_rng(0))  # warm-up (compile / load cache)
    streamed = [0]

    def discard(chunk) -> None:
        streamed[0] += len(chunk)

    kwargs = {}
    if impacts == "streamed":
        kwargs = {
            "record_impacts": True,
            "on_impact_chunk": discard,
            "impact_chunk_rocks": STREAM_CHUNK_ROCKS,
        }
    before = rss_now_kib()
    start = time.perf_counter()
    result = simulate(model, rocks, np.random.default_rng(SEED), **kwargs)
    wall = time.perf_counter() - start
    peak = rss_peak_kib()
    tracemalloc.start()
    simulate(model, rocks, np.random.default_rng(SEED), **kwargs)
    _, py_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return {
        "case": case,
        "rocks": rocks,
        "impacts_mode": impacts,
        "threads": threads,
        "impacts": int(result.impacts),
        "streamed_rows": streamed[0] // 2,  # counted in both runs
        "kernel_s": float(result.wall_s),
        "wall_s": wall,
        "rss_before_mib": before / 1024,
        "rss_peak_delta_mib": max(0, peak - before) / 1024,
        "py_peak_mib": py_peak / 2**20,
    }


def run_reference(case: str) -> dict:
    """Reference vs kernel on the same REFERENCE_ROCKS rocks and seed.

    :func:`fieldkit.model.reference.simulate_reference` follows one rock at a time
    through the kernel's own per-rock code run by the Python interpreter, drawing the
    same random numbers; every impact row and every rock's outcome must agree.
    """
    from fieldkit.model import simulate
    from fieldkit.model.kernel import RECORD_COLUMNS
    from fieldkit.model.reference import simulate_reference

    set_threads()
    model = build_model(case)
    simulate(model, 50, np.random.default_rng(0))  # warm-up
    kernel = simulate(
        model, REFERENCE_ROCKS, np.random.default_rng(SEED), record_impacts=True
    )
    start = time.perf_counter()
    ref = simulate_reference(model, REFERENCE_ROCKS, np.random.default_rng(SEED))
    wall = time.perf_counter() - start
    impacts = sum(len(r.impacts) for r in ref)
    frame = kernel.impact_table.frame
    worst = float(np.max(np.abs(kernel.runout_x_m - [r.runout_x_m for r in ref])))
    same_states = bool(np.array_equal(kernel.state, [r.state for r in ref]))
    for rock, r in enumerate(ref):
        rows = frame[frame["path_id"] == str(rock)]
        if len(rows) != len(r.impacts):
            return {
                "case": case,
                "rocks": REFERENCE_ROCKS,
                "impacts": impacts,
                "wall_s": wall,
                "max_abs_difference": float("inf"),
                "impacts_equal": False,
                "states_equal": same_states,
            }
        for name in ("x_m", "z_m", "vi_x_mps", "vi_z_mps", "vf_x_mps", "vf_z_mps"):
            got = rows[name].to_numpy(float)
            want = r.impacts[:, RECORD_COLUMNS.index(name)]
            if len(got):
                worst = max(worst, float(np.max(np.abs(got - want))))
    return {
        "case": case,
        "function": "fieldkit.model.reference.simulate_reference",
        "rocks": REFERENCE_ROCKS,
        "impacts": impacts,
        "wall_s": wall,
        "max_abs_difference": worst,
        "impacts_equal": impacts == int(kernel.impacts),
        "states_equal": same_states,
    }


def child(argv: list[str]) -> None:
    if argv[0] == "--reference":
        print(json.dumps(run_reference(argv[1])))
    else:
        print(json.dumps(run_case(argv[1], int(argv[2]), argv[3])))


# --------------------------------------------------------------------------- parent
def spawn(*args: str) -> dict | None:
    done = subprocess.run(
        [sys.executable, __file__, *args], capture_output=True, text=True
    )
    if done.returncode != 0:
        tail = done.stderr.strip().splitlines()[-1:] or ["(no message)"]
        print(f"  {' '.join(args)}: failed: {tail[0]}")
        return None
    return json.loads(done.stdout.strip().splitlines()[-1])


def load() -> str:
    one, five, _ = os.getloadavg()
    return (
        f"load average {one:.2f} (1 min), {five:.2f} (5 min) on {os.cpu_count()} CPUs"
    )


def main() -> None:
    try:
        importlib.import_module("fieldkit.model.simulate")
    except ImportError as error:
        print(
            "fieldkit.model.simulate is not available "
            f"({error}); nothing to benchmark yet"
        )
        return
    print(load())
    print(
        "profile: 100 segments, 3 materials, per-impact SDs; "
        f"{THREADS} threads; each case in a fresh process after a warm-up"
    )
    rates = {}
    header = (
        f"{'case':5s} {'rocks':>8s} {'impacts':>10s} {'impacts/s':>11s} "
        f"{'rocks/s':>9s} {'kernel s':>8s} {'wall s':>7s} {'RSS+ MiB':>8s} "
        f"{'py MiB':>7s}"
    )
    print(header)
    for case in ("base", "all"):
        for rocks in ROCK_COUNTS:
            row = spawn("--case", case, str(rocks), "none")
            if row is None:
                continue
            rate = row["impacts"] / row["kernel_s"]
            rates[case] = rate  # the largest run counts
            print(
                f"{case:5s} {rocks:8d} {row['impacts']:10d} {rate:11,.0f} "
                f"{rocks / row['kernel_s']:9,.0f} {row['kernel_s']:8.2f} "
                f"{row['wall_s']:7.2f} {row['rss_peak_delta_mib']:8.1f} "
                f"{row['py_peak_mib']:7.1f}"
            )
    print(
        "RSS+ = peak RSS during the run minus RSS before it (VmHWM, fresh "
        "process); py = tracemalloc peak (Python + numpy) in an untimed repeat"
    )

    print("\nreference (one rock at a time, same physics and random numbers):")
    for case in ("base", "all"):
        ref = spawn("--reference", case)
        if ref is None:
            continue
        ref_rate = ref["impacts"] / ref["wall_s"]
        line = (
            f"  {case:5s} {ref['function']}: {ref['rocks']} rocks, {ref['impacts']} "
            f"impacts, {ref_rate:,.0f} impacts/s; max abs difference vs kernel "
            f"{ref['max_abs_difference']:.3g} (impact counts equal: "
            f"{ref['impacts_equal']})"
        )
        if case in rates:
            line += f"; kernel/reference {rates[case] / ref_rate:,.0f}x"
        print(line)

    print("\ntargets (largest run, kernel time):")
    for case, target in TARGET_IMPACTS_PER_S.items():
        if case in rates:
            met = "met" if rates[case] >= target else "NOT met"
            print(f"  {case:5s} {rates[case]:,.0f} impacts/s vs >= {target:,} -> {met}")

    print(f"\nmemory check, {ROCK_COUNTS[-1]:,} rocks, base model:")
    for mode in ("none", "streamed"):
        row = spawn("--case", "base", str(ROCK_COUNTS[-1]), mode)
        if row is None:
            continue
        what = (
            "no impacts recorded"
            if mode == "none"
            else f"{row['streamed_rows']:,} impact rows streamed in chunks of "
            f"{STREAM_CHUNK_ROCKS} rocks"
        )
        print(
            f"  {what}: RSS+ {row['rss_peak_delta_mib']:.1f} MiB, py peak "
            f"{row['py_peak_mib']:.1f} MiB"
        )
    print(load())


if __name__ == "__main__":
    if len(sys.argv) > 1:
        child(sys.argv[1:])
    else:
        main()
