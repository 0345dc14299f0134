"""The Dask engine: the same results in this process and on a 2-worker local
cluster, units retried and reported (never dropped), bad input at once, a silent
scheduler refused within its time-out."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from fieldkit.errors import ArgumentError, FieldkitError
from fieldkit.parallel.engine import Engine, EngineSpec, UnitFailedError, parse_memory


def square(x: int) -> int:
    return x * x


def add_shared(shared: dict, x: int) -> int:
    return shared["offset"] + x


def fail_first_time(args: tuple[str, int]) -> int:
    """Fails the first time it sees unit ``i`` (a marker file per unit): a worker
    that crashed once."""
    folder, i = args
    mark = Path(folder) / f"seen-{i}"
    if not mark.exists():
        mark.write_text("x")
        raise RuntimeError(f"lost worker on unit {i}")
    return i


def always_fails(i: int) -> int:
    raise RuntimeError("disk full")


def unit_one_fails(i: int) -> int:
    if i == 1:
        raise RuntimeError("disk full")
    return i


def bad_input(i: int) -> int:
    if i == 2:
        raise ArgumentError("spacing_m must be > 0 (got 0)", source="spacing_m")
    return i


@pytest.fixture(scope="module")
def two_workers():
    with Engine(EngineSpec(workers=2, retries=1)) as engine:
        yield engine


def test_in_process_keeps_order_and_reports_progress():
    seen = []
    with Engine(EngineSpec(workers=0)) as engine:
        out = engine.map(square, range(5), progress=lambda d, n: seen.append((d, n)))
    assert out == [0, 1, 4, 9, 16]
    assert seen[-1] == (5, 5) and len(seen) == 5
    assert engine.describe()["where"] == "this process"


def test_tiny_job_runs_here_by_default_and_a_big_one_does_not():
    engine = Engine(EngineSpec())
    assert not engine.remote(tiny=True)
    assert engine.remote(tiny=False)
    assert not Engine(EngineSpec(workers=0)).remote(tiny=False)


def test_two_workers_give_the_in_process_results(two_workers):
    units = list(range(23))
    assert two_workers.map(square, units) == [u * u for u in units]
    assert two_workers.workers == 2 and two_workers.threads_per_worker == 1
    assert "2 worker processes x 1 thread, memory limit" in two_workers.where
    assert two_workers.memory_per_worker > 0
    assert two_workers.map(add_shared, [1, 2], shared={"offset": 10}) == [11, 12]


def test_a_failed_unit_is_retried_and_reported_on_workers(two_workers, tmp_path):
    lines = []
    two_workers.notify = lines.append
    try:
        out = two_workers.map(fail_first_time, [(str(tmp_path), i) for i in range(4)],
                              label="tile")  # fmt: skip
    finally:
        two_workers.notify = lambda text: None
    assert out == [0, 1, 2, 3]  # none dropped
    retried = [ln for ln in lines if "running it again (1 of 1)" in ln]
    assert len(retried) == 4
    assert "tile 0 failed (RuntimeError: lost worker on unit 0)" in "\n".join(retried)


def test_a_unit_failing_every_time_ends_the_run_naming_it(two_workers):
    with pytest.raises(UnitFailedError, match=r"station 1 failed 2 times .*disk full"):
        two_workers.map(unit_one_fails, [0, 1, 2], names=["station 0", "station 1",
                                                          "station 2"])


def test_bad_input_in_a_unit_is_raised_at_once_not_retried(two_workers):
    with pytest.raises(ArgumentError, match="spacing_m must be > 0"):
        two_workers.map(bad_input, range(4))
    with Engine(EngineSpec(workers=0, retries=3)) as engine:
        with pytest.raises(FieldkitError, match="spacing_m"):
            engine.map(bad_input, range(4))
        assert engine.retried == []


def test_in_process_retries_too(tmp_path):
    lines = []
    with Engine(EngineSpec(workers=0, retries=1), notify=lines.append) as engine:
        assert engine.map(fail_first_time, [(str(tmp_path), 7)]) == [7]
        with pytest.raises(UnitFailedError, match="unit 0 failed 2 times"):
            engine.map(always_fails, [0])
    assert any("unit 0 failed (RuntimeError: lost worker on unit 7)" in ln
               for ln in lines)  # fmt: skip


def test_a_scheduler_that_does_not_answer_times_out_in_one_line():
    tic = time.perf_counter()
    with pytest.raises(ArgumentError) as err:
        with Engine(EngineSpec(scheduler="tcp://127.0.0.1:9", timeout_s=1.0)) as engine:
            engine.map(square, [1])
    assert time.perf_counter() - tic < 20
    text = str(err.value)
    assert "\n" not in text
    assert "the Dask scheduler at tcp://127.0.0.1:9 did not answer within 1 s" in text


@pytest.mark.parametrize(
    ("spec", "words"),
    [
        (EngineSpec(workers=-1), "workers must be from 0"),
        (EngineSpec(workers=2, scheduler="tcp://x:1"), "not both"),
        (EngineSpec(timeout_s=0), "timeout_s must be > 0"),
        (EngineSpec(retries=-1), "retries must be from 0"),
        (EngineSpec(memory_per_worker=1000), "at least 256 MiB"),
    ],
)
def test_settings_that_cannot_work_are_refused(spec, words):
    with pytest.raises(ArgumentError, match=words):
        spec.check()


def test_memory_sizes():
    assert parse_memory("1.5 GiB") == int(1.5 * 2**30)
    with pytest.raises(ArgumentError, match="not a size"):
        parse_memory("lots")


def slow_pid(i: int) -> tuple[int, int]:
    import os

    time.sleep(0.4)
    return i, os.getpid()


def test_a_killed_worker_is_reported_and_its_units_run_again():
    """kill -9 of a worker mid-run: its unit comes back (KilledWorker), is reported
    and run again; every unit's result is there, in order."""
    import os
    import signal
    import threading

    lines: list[str] = []
    with Engine(EngineSpec(workers=2), notify=lines.append) as engine:
        engine.start()
        victim = sorted(engine._client.run(os.getpid).values())[0]
        threading.Timer(1.0, os.kill, (victim, signal.SIGKILL)).start()
        out = engine.map(slow_pid, range(8), label="tile")
    assert [o[0] for o in out] == list(range(8))
    text = "\n".join(lines)
    assert "failed (its worker died: tcp://" in text and "running it again" in text
    assert "1 worker(s) left during the run" in text
