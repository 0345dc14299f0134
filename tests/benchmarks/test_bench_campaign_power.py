"""The virtual-campaign power benchmark runs, prints its table, and counts honestly."""

from __future__ import annotations

import doctest
import importlib.util
import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_campaign_power.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_campaign_power", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_campaign_power"] = module
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop("bench_campaign_power", None)


def test_classify_counts_only_gains_above_the_oracle_threshold(bench):
    failures, _ = doctest.testmod(bench, verbose=False)
    assert failures == 0


def test_seed_streams_are_apart(bench):
    """The threshold's null campaigns are never the ones the false rate is
    measured on, and a cell's seeds do not depend on the other cells of a run."""
    key = bench.Design(1, 20, True).key
    threshold = bench.seeds(18, bench.STREAM_THRESHOLD, key, 3)
    null = bench.seeds(18, bench.STREAM_NULL, (*key, 0), 3)
    draws = {
        tuple(np.random.default_rng(s).integers(0, 2**62, 4)) for s in threshold + null
    }
    assert len(draws) == 6
    again = bench.seeds(18, bench.STREAM_NULL, (*key, 0), 3)
    assert [s.entropy for s in again] == [s.entropy for s in null]
    assert [s.spawn_key for s in again] == [s.spawn_key for s in null]


@pytest.mark.slow
def test_short_mode_prints_the_table(bench, capsys, tmp_path):
    """A tiny setting of the short mode, in one process: every row of the table,
    the end-to-end line, the key rows and the timing are printed, and --out holds
    the same markdown."""
    out = tmp_path / "power.md"
    code = bench.main(
        [
            "--paths", "1", "--scars", "20", "--campaigns", "1",
            "--threshold-campaigns", "2", "--e2e", "1", "--e2e-null", "2",
            "--time-null", "2", "--time-power", "1", "--size-rocks", "2",
            "--workers", "1", "--out", str(out),
        ]
    )  # fmt: skip
    assert code == 0
    text = capsys.readouterr().out
    assert bench.HEAD in text
    rows = [line for line in text.splitlines() if line.startswith("| 1×20 trees |")]
    assert [row.split("|")[2].strip() for row in rows] == [t[0] for t in bench.TRUTHS]
    for row in rows:
        assert row.split("|")[4].strip() == "1"  # N
    assert re.search(r"false findings with its own null: \d of 1 ", text)
    assert "| 1 × 20 | as boulder A |" in text
    timed = r"diagnose_surveyed\(null_size=2, power_size=1, .*\*\*\d+ s\*\*"
    assert re.search(timed, text)
    assert "load average" in text
    assert out.read_text().strip() == text.strip()
    assert "1×20 trees: the true law's own gain, eq. 7.1 K=7: median" in text
    # every campaign's screen kept: 2 threshold nulls + 5 cells of 1
    dumped = [json.loads(line) for line in out.with_suffix(".jsonl").open()]
    assert len(dumped) == 7
    assert sum(d["kind"] == "threshold" for d in dumped) == 2
    candidates = set(bench.boulder_a().candidates)
    assert all(set(d["gains"]) == candidates for d in dumped)


def test_effect_size_is_zero_without_effect_and_grows_with_it(bench):
    """A is the part of the effect constant e_n, e_t cannot absorb: none without an
    effect, more for the stronger law (K = 7 vs 14 m/s on the same impacts)."""
    world = bench.boulder_a()
    assert bench.effect_size(world, {}, 3, 18, 1) < 1e-12
    k7 = {"velocity_scaled_restitution": {"k_mps": 7.0}}
    strong = bench.effect_size(world, k7, 3, 18, 1)
    # the same impacts (simulated with K = 7): the weaker law departs less at each
    weak = bench.effect_size(
        world, {"velocity_scaled_restitution": {"k_mps": 14.0}}, 3, 18, 1,
        simulated_with=k7,
    )  # fmt: skip
    assert 0 < weak < strong
