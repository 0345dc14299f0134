"""One engine for independent units of work: in this process, on a local Dask
cluster, or on any running Dask scheduler.

A *unit* is one picklable argument to a pure function -- a corridor station, a tile
of release cells, one fit on one split and seed, one virtual campaign. Every unit
carries its own seed (or its own rocks' keys), so what a unit returns does not
depend on where or beside what it ran: a run gives the same numbers in this
process, on 1 local worker or on 200 remote ones.

Where the units run (:class:`EngineSpec`):

* ``workers=0``: in this process, in order (what a tiny job gets by default, and
  what the tests compare against);
* ``scheduler`` an address (``tcp://host:8786``), or Dask's own configuration
  (``DASK_SCHEDULER_ADDRESS`` / ``scheduler-address``): that cluster, whatever
  started it (``dask scheduler`` + ``dask worker``, dask-jobqueue on SLURM or PBS,
  Kubernetes, a cloud service);
* otherwise a :class:`distributed.LocalCluster` of ``workers`` processes (default:
  one per core) of one thread each, each with a memory limit (default: the
  machine's memory shared equally; Dask pauses a worker at 80 % of its limit and
  restarts it at 95 %, and the unit it held is run again).

Failures: a unit that raises :class:`~fieldkit.errors.FieldkitError` is bad input
and ends the run at once with that one line. Any other failure (a worker killed,
out of memory, a lost connection) is reported through ``notify`` and the unit run
again, up to ``retries`` times; a unit that still fails ends the run with
:class:`UnitFailedError` naming it -- a unit is never dropped.

Examples
--------
>>> with Engine(EngineSpec(workers=0)) as engine:
...     engine.map(abs, [-1, 2, -3], label="number")
[1, 2, 3]
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from fieldkit.errors import ArgumentError, FieldkitError

#: Most local workers one run starts.
MAX_WORKERS = 512
#: Smallest memory limit per worker [bytes] (a worker imports numpy, numba, pandas).
MIN_WORKER_MEMORY = 256 * 2**20
#: Longest wait for a scheduler or its first worker [s].
MAX_TIMEOUT_S = 3600.0
#: Most retries of a failing unit.
MAX_RETRIES = 10


class UnitFailedError(FieldkitError):
    """A unit that failed on every attempt (named, with its last error)."""


@dataclass(frozen=True)
class EngineSpec:
    """Where and how the units run (module docstring).

    Attributes
    ----------
    workers
        Local worker processes: None = one per core (or this process for a tiny
        job), 0 = this process.
    scheduler
        Address of a running Dask scheduler; None = Dask's configuration
        (``scheduler-address``) if set, else local.
    memory_per_worker
        A local worker's memory limit [bytes]; None = the machine's memory / workers.
    timeout_s
        Longest wait for the scheduler to answer and for its first worker [s].
    retries
        Times a failing unit is run again before the run fails.
    """

    workers: int | None = None
    scheduler: str | None = None
    memory_per_worker: int | None = None
    timeout_s: float = 10.0
    retries: int = 2

    def check(self) -> EngineSpec:
        """Refuse settings that cannot work (one-line :class:`ArgumentError`)."""
        if self.workers is not None and not 0 <= self.workers <= MAX_WORKERS:
            raise ArgumentError(
                f"workers must be from 0 (this process) to {MAX_WORKERS} "
                f"(got {self.workers})",
                source="workers",
            )
        if self.scheduler is not None and self.workers:
            raise ArgumentError(
                "give either `workers` (a local cluster) or `scheduler` (a running "
                "one), not both",
                source="scheduler",
            )
        if self.scheduler is not None and not str(self.scheduler).strip():
            raise ArgumentError("scheduler must be an address", source="scheduler")
        if self.memory_per_worker is not None and (
            self.memory_per_worker < MIN_WORKER_MEMORY
        ):
            raise ArgumentError(
                f"memory_per_worker must be at least {MIN_WORKER_MEMORY // 2**20} MiB "
                f"(got {self.memory_per_worker / 2**20:.0f} MiB)",
                source="memory_per_worker",
            )
        if not 0 < self.timeout_s <= MAX_TIMEOUT_S:
            raise ArgumentError(
                f"timeout_s must be > 0 and <= {MAX_TIMEOUT_S:g} s "
                f"(got {self.timeout_s:g})",
                source="timeout_s",
            )
        if not 0 <= self.retries <= MAX_RETRIES:
            raise ArgumentError(
                f"retries must be from 0 to {MAX_RETRIES} (got {self.retries})",
                source="retries",
            )
        return self


def parse_memory(text: str) -> int:
    """``"4GiB"``, ``"1.5 GB"``, ``"800MB"`` -> bytes (Dask's own parser).

    Examples
    --------
    >>> parse_memory("2GiB")
    2147483648
    """
    from dask.utils import parse_bytes

    try:
        value = int(parse_bytes(str(text).strip()))
    except (ValueError, TypeError, KeyError, AttributeError):
        raise ArgumentError(
            f"'{text}' is not a size (e.g. 4GiB, 1.5GB, 800MB)",
            source="memory_per_worker",
        ) from None
    return value


def machine_memory() -> int:
    """The memory this machine lets a process tree use [bytes] (cgroup limits
    included, as Dask reads it)."""
    from distributed.system import MEMORY_LIMIT

    return int(MEMORY_LIMIT)


def configured_scheduler() -> str | None:
    """Dask's configured scheduler address (``DASK_SCHEDULER_ADDRESS`` or
    ``scheduler-address`` in a Dask config file), or None."""
    import dask

    address = dask.config.get("scheduler-address", None)
    return str(address) if address else None


def _gib(n: float) -> str:
    return f"{n / 2**30:.1f} GiB"


def _run_unit(fn: Callable[..., Any], unit: Any, threads: int, shared: Any = None,
              with_shared: bool = False) -> Any:  # fmt: skip
    """Run one unit on a worker with ``threads`` compute threads (numba's and the
    BLAS pools): a worker process of one thread must not start a thread per core."""
    from threadpoolctl import threadpool_limits

    try:
        import numba

        numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))
    except ImportError:  # pragma: no cover - numba is a dependency
        pass
    with threadpool_limits(threads):
        return fn(shared, unit) if with_shared else fn(unit)


def _worker_version() -> str:
    from fieldkit._version import __version__

    return __version__


class Engine:
    """Runs units where :class:`EngineSpec` says (module docstring).

    Parameters
    ----------
    spec
        Where the units run.
    notify
        Called with one line for every event a user should see: where the units
        run, a unit retried.

    Notes
    -----
    Use as a context manager; the cluster (or the connection) is made at the first
    :meth:`map` that needs it and closed on exit.
    """

    def __init__(
        self,
        spec: EngineSpec | None = None,
        *,
        notify: Callable[[str], None] | None = None,
    ) -> None:
        self.spec = (spec or EngineSpec()).check()
        self.notify = notify or (lambda text: None)
        self._client = None
        self._cluster = None
        self.where = "this process"
        self.workers = 0
        self.threads_per_worker = 1
        self.memory_per_worker: int | None = None
        self.retried: list[str] = []
        self._said_local = False

    # -- lifetime -----------------------------------------------------------------
    def __enter__(self) -> Engine:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Close the connection and any local cluster."""
        client, cluster = self._client, self._cluster
        self._client = self._cluster = None
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()

    def remote(self, tiny: bool = False) -> bool:
        """Whether :meth:`map` sends units to Dask workers (``tiny``: the job is
        small enough that, left to the default, it runs in this process)."""
        spec = self.spec
        if spec.scheduler is not None or (
            spec.workers is None and configured_scheduler()
        ):
            return True
        if spec.workers == 0:
            return False
        return not (spec.workers is None and tiny)

    def start(self, tiny: bool = False) -> None:
        """Start the cluster or connect to the scheduler now, if :meth:`map` would
        (so a scheduler that does not answer fails before any work)."""
        if self.remote(tiny):
            self._connect()

    def _connect(self) -> None:
        if self._client is not None:
            return
        from distributed import Client, LocalCluster

        spec = self.spec
        address = spec.scheduler or (
            configured_scheduler() if spec.workers is None else None
        )
        for name in ("distributed", "distributed.worker", "distributed.nanny",
                     "distributed.scheduler", "distributed.core"):  # fmt: skip
            logging.getLogger(name).setLevel(logging.CRITICAL)
        if address is not None:
            try:
                client = Client(address, timeout=f"{spec.timeout_s}s")
            except (OSError, TimeoutError, ValueError) as exc:
                why = str(exc).split("\n")[0]
                raise ArgumentError(
                    f"the Dask scheduler at {address} did not answer within "
                    f"{spec.timeout_s:g} s ({why})",
                    source="scheduler",
                ) from None
            self._client = client
            try:
                client.wait_for_workers(1, timeout=spec.timeout_s)
            except (OSError, TimeoutError) as exc:
                self.close()
                raise ArgumentError(
                    f"the Dask scheduler at {address} has no workers (waited "
                    f"{spec.timeout_s:g} s: {type(exc).__name__})",
                    source="scheduler",
                ) from None
            try:
                versions = set(client.run(_worker_version).values())
            except Exception as exc:  # noqa: BLE001 - any worker-side import failure
                self.close()
                raise ArgumentError(
                    f"the workers of the Dask scheduler at {address} cannot run "
                    f"fieldkit ({type(exc).__name__}: {exc}); install this fieldkit "
                    "in the workers' environment",
                    source="scheduler",
                ) from None
            mine = _worker_version()
            if versions != {mine}:
                self.close()
                raise ArgumentError(
                    f"the workers of the Dask scheduler at {address} run fieldkit "
                    f"{', '.join(sorted(versions))}, this is {mine}: results would "
                    "not be this version's",
                    source="scheduler",
                )
            info = client.scheduler_info()["workers"].values()
            self.workers = len(info)
            threads = sorted({int(w.get("nthreads", 1)) for w in info})
            self.threads_per_worker = threads[0]  # the fewest any worker has
            limits = [int(w.get("memory_limit") or 0) for w in info]
            self.memory_per_worker = min(limits) if all(limits) else None
            memory = (
                f"memory limit {_gib(self.memory_per_worker)} per worker (the "
                "cluster's)"
                if self.memory_per_worker
                else "no memory limit set on the workers (the cluster's choice)"
            )
            self.where = (
                f"Dask scheduler {address}: {self.workers} workers x "
                f"{'/'.join(map(str, threads))} threads, {memory}"
            )
            self.notify(f"running on the {self.where}")
            return
        workers = spec.workers or os.cpu_count() or 1
        memory = spec.memory_per_worker or machine_memory() // workers
        source = "given" if spec.memory_per_worker else "the machine's memory / workers"
        import dask

        # a unit whose worker died comes straight back to map() (KilledWorker), to
        # be reported and run again there, not re-run silently by the scheduler
        with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
            self._cluster = self._local_cluster(LocalCluster, workers, memory)
        self._client = Client(self._cluster)
        self.workers, self.threads_per_worker = workers, 1
        self.memory_per_worker = memory
        self.where = (
            f"local Dask cluster: {workers} worker process{'es' if workers > 1 else ''}"
            f" x 1 thread, memory limit {_gib(memory)} each ({source}; a worker past "
            "95 % of it is restarted and its unit run again)"
        )
        self.notify(f"running on a {self.where}")

    @staticmethod
    def _local_cluster(factory, workers: int, memory: int):
        return factory(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            memory_limit=memory,
            dashboard_address=":0",  # any free port: never a clash with another
            # cluster on this machine (a warning otherwise)
            silence_logs=logging.CRITICAL,
        )

    # -- work ---------------------------------------------------------------------
    def map(
        self,
        fn: Callable[[Any], Any],
        units: Sequence[Any],
        *,
        label: str = "unit",
        names: Sequence[str] | None = None,
        progress: Callable[[int, int], None] | None = None,
        tiny: bool = False,
        shared: Any = None,
    ) -> list[Any]:
        """``[fn(u) for u in units]``, the units run where the spec says.

        Parameters
        ----------
        fn
            A pure module-level function (pickled by reference).
        units
            Its arguments, one per unit (picklable).
        label, names
            How a unit is named in a report: ``names[i]`` or ``"<label> i"``.
        progress
            Called with (units done, units) as units finish.
        tiny
            The job is small: left to the default, run it in this process.
        shared
            One large input every unit reads (a DEM model): sent to each worker
            once, and ``fn(shared, unit)`` called instead of ``fn(unit)``.

        Returns
        -------
        list
            The results in the order of ``units``.

        Raises
        ------
        FieldkitError
            A unit's bad input (at once).
        UnitFailedError
            A unit that failed ``1 + retries`` times.
        """
        units = list(units)
        total = len(units)
        name = (lambda i: names[i]) if names is not None else (lambda i: f"{label} {i}")
        with_shared = shared is not None
        if not self.remote(tiny):
            if self.where == "this process" and not self._said_local:
                self._said_local = True
                self.notify(
                    "running in this process"
                    + (" (a tiny job)" if tiny and self.spec.workers is None else "")
                )
            out = []
            for i, unit in enumerate(units):
                call = (lambda u: fn(shared, u)) if with_shared else fn
                out.append(self._attempts_here(call, unit, name(i)))
                if progress is not None:
                    progress(i + 1, total)
            return out
        self._connect()
        from distributed import as_completed

        client = self._client
        threads = self.threads_per_worker
        if with_shared:
            shared = client.scatter(shared, broadcast=True, hash=False)

        def submit(unit):
            return client.submit(_run_unit, fn, unit, threads, shared, with_shared,
                                 pure=False)  # fmt: skip

        before = set(client.scheduler_info()["workers"])
        futures = {}
        for i, unit in enumerate(units):
            futures[submit(unit)] = (i, 0)
        results: list[Any] = [None] * total
        done = 0
        pending = as_completed(list(futures))
        for fut in pending:
            i, attempt = futures.pop(fut)
            if fut.status == "finished":
                results[i] = fut.result()
                done += 1
                if progress is not None:
                    progress(done, total)
                continue
            try:
                exc = fut.exception()
            except Exception as lost:  # noqa: BLE001 - a cancelled / lost future
                exc = lost
            if isinstance(exc, FieldkitError):
                self._cancel(futures)
                raise exc
            self._failed(name(i), attempt, exc, futures)
            again = submit(units[i])
            futures[again] = (i, attempt + 1)
            pending.add(again)
        gone = before - set(client.scheduler_info()["workers"])
        if gone:
            line = (
                f"{len(gone)} worker(s) left during the run "
                f"({', '.join(sorted(gone))}); their units were run again (results "
                "unchanged: a seed per unit)"
            )
            self.retried.append(line)
            self.notify(line)
        return results

    def _cancel(self, futures: dict) -> None:
        if futures and self._client is not None:
            self._client.cancel(list(futures))

    def _failed(
        self, unit: str, attempt: int, exc: BaseException, futures=None
    ) -> None:
        if type(exc).__name__ == "KilledWorker":
            last = getattr(exc, "last_worker", None)
            where = getattr(last, "address", None) or "a worker"
            why = f"its worker died: {where}"
        else:
            why = f"{type(exc).__name__}: {' '.join(str(exc).split())}"[:300]
        if attempt >= self.spec.retries:
            if futures:
                self._cancel(futures)
            raise UnitFailedError(
                f"{unit} failed {attempt + 1} time{'s' if attempt else ''} on "
                f"{self.where.split(':')[0]}: {why}"
            ) from None
        line = (
            f"{unit} failed ({why}); running it again "
            f"({attempt + 1} of {self.spec.retries})"
        )
        self.retried.append(line)
        self.notify(line)

    def _attempts_here(self, fn, unit, unit_name: str):
        attempt = 0
        while True:
            try:
                return fn(unit)
            except FieldkitError:
                raise
            except (KeyboardInterrupt, SystemExit):
                raise
            except Exception as exc:  # noqa: BLE001 - retried, then reported
                self._failed(unit_name, attempt, exc)
                attempt += 1

    def describe(self) -> dict:
        """Where the units ran, for a JSON summary."""
        return {
            "where": self.where,
            "workers": self.workers,
            "threads_per_worker": self.threads_per_worker,
            "memory_per_worker_bytes": self.memory_per_worker,
            "retried": list(self.retried),
        }
