"""The corridor benchmark runs (its --quick setting) and finds the tables of this
process, 1 and 2 local workers identical."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_bench_corridor_quick():
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_corridor.py"), "--quick"],
        capture_output=True, text=True, timeout=600, cwd=ROOT,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("tables identical on all three: True") == 2, done.stdout
    assert "parallel efficiency" in done.stdout
