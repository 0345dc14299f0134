"""The options every command that runs units through the Dask engine shares
(:mod:`fieldkit.parallel.engine`): where they run, memory, time-out, retries."""

from __future__ import annotations

from typing import Annotated

import typer

from fieldkit.parallel.engine import EngineSpec, parse_memory

#: Library argument names of the engine -> flags.
ENGINE_FLAGS = {
    "workers": "--workers",
    "scheduler": "--scheduler",
    "memory_per_worker": "--worker-memory",
    "timeout_s": "--timeout",
    "retries": "--retries",
}

Workers = Annotated[
    int | None,
    typer.Option(
        "--workers",
        help="Local Dask worker processes (one thread each); 0 = run in this process. "
        "Default: one per core, or this process for a tiny job.",
        rich_help_panel="Where it runs",
    ),
]
Scheduler = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        help="Address of a running Dask scheduler (tcp://host:8786) to send the work "
        "to; default: DASK_SCHEDULER_ADDRESS / Dask's config if set, else local.",
        rich_help_panel="Where it runs",
    ),
]
WorkerMemory = Annotated[
    str | None,
    typer.Option(
        "--worker-memory",
        help="Memory limit of each local worker, e.g. 2GiB (default: the machine's "
        "memory / workers).",
        rich_help_panel="Where it runs",
    ),
]
Timeout = Annotated[
    float,
    typer.Option(
        "--timeout",
        help="Seconds to wait for the scheduler to answer and for its first worker.",
        rich_help_panel="Where it runs",
    ),
]
Retries = Annotated[
    int,
    typer.Option(
        "--retries",
        help="Times a failed unit (a worker lost, out of memory) is run again "
        "before the command fails.",
        rich_help_panel="Where it runs",
    ),
]


def engine_spec(
    workers: int | None,
    scheduler: str | None,
    worker_memory: str | None,
    timeout: float,
    retries: int,
) -> EngineSpec:
    """The checked :class:`EngineSpec` of the options."""
    memory = parse_memory(worker_memory) if worker_memory is not None else None
    return EngineSpec(
        workers=workers,
        scheduler=scheduler,
        memory_per_worker=memory,
        timeout_s=timeout,
        retries=retries,
    ).check()
