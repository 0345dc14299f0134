"""SIGTERM (a timeout, a cancelled CI job, ``docker stop``) ends a command as Ctrl-C
does: a streamed output's temporary file and the folders made for it are removed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
TABLE_7_1 = REPO / "surveys" / "tornado_mountain" / "model_rocfall_table_7_1.json"


def _temporaries(folder: Path) -> list[Path]:
    return list(folder.glob(".fk-*")) if folder.is_dir() else []


@pytest.mark.parametrize(
    "signum, streamed_bytes",
    [
        (signal.SIGTERM, 0),
        (signal.SIGHUP, 0),
        (signal.SIGINT, 0),
        # tens of MB streamed first (after the numba compile on a cold cache)
        pytest.param(signal.SIGTERM, 10_000_000, marks=pytest.mark.slow),
    ],
)
def test_a_terminated_streamed_simulation_leaves_nothing(
    tmp_path, signum, streamed_bytes
):
    (tmp_path / "mine.txt").write_text("keep")
    folder = tmp_path / "new" / "deeper"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), *sys.path])}
    process = subprocess.Popen(
        [sys.executable, "-m", "fieldkit", "simulate", str(TABLE_7_1),
         "--rocks", "200000", "--seed", "1", "--impacts", str(folder / "big.csv")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
    )  # fmt: skip
    try:
        # the temporary file is made before the simulation starts; whether it has
        # impacts yet or not (the numba compile comes first on a cold cache), what
        # must be removed is the same: it and the folders made for it
        deadline = time.monotonic() + 180
        while time.monotonic() < deadline and process.poll() is None:
            temporaries = _temporaries(folder)
            if temporaries and temporaries[0].stat().st_size >= streamed_bytes:
                break
            time.sleep(0.02)
        assert process.poll() is None, "the simulation ended before it was signalled"
        assert _temporaries(folder), "no streamed temporary file to clean up"
        process.send_signal(signum)
        _, stderr = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 128 + signum
    lines = [line for line in stderr.splitlines() if line.startswith("error")]
    how = "interrupted" if signum == signal.SIGINT else "terminated"
    assert lines == [
        f"error: {how} by {signal.Signals(signum).name}; unfinished outputs "
        "were removed"
    ], stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.txt"]
    assert (tmp_path / "mine.txt").read_text() == "keep"
