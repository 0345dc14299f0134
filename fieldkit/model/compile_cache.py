"""Compile the simulator kernel once: is it cached, and warm the cache.

The kernel (:mod:`fieldkit.model.kernel`) is compiled by numba with ``cache=True``:
the first run on a machine compiles it (tens of seconds) and writes the machine code
to ``__pycache__`` beside the source (numba keys it by the source file's path,
modification time and size, and by the CPU); every later process loads it in well
under a second. :func:`kernel_ready` says whether a run will have to compile,
:func:`warm` compiles (or loads) it on a one-rock model, so a simulation's own time
never includes compiling. :func:`main` warms the cache and says what it did
(``make`` runs it at install: ``python -c "from fieldkit.model.compile_cache import
main; main()"``).

A fresh clone (new paths, new modification times) compiles once, on its first run or
at its install; moving a clone keeps its cache.
"""

from __future__ import annotations

import time

import numpy as np

import fieldkit.model.kernel as kernel

#: The compiled entry points a simulation calls from Python.
_ENTRY_POINTS = ("run_rocks", "run_rock")

#: A one-segment model that exercises every argument type of the kernel.
_TINY_MODEL = {
    "profile": {"x_m": [0.0, 10.0], "z_m": [5.0, 0.0], "material": "rock"},
    "materials": {"rock": {"e_n": 0.3, "e_t": 0.8, "friction_deg": 30.0}},
    "body": {"mass_kg": 100.0, "radius_m": 0.2},
    "seeder": {"x_m": 0.5, "z_m": 6.0},
}


def _cached_on_disk(dispatcher) -> bool:
    """Whether numba's cache holds machine code of ``dispatcher`` for this CPU.

    Reads numba's cache index (private API, numba 0.5x-0.6x); any surprise counts
    as "not cached", so the worst case is a needless "compiling" note.
    """
    try:
        index = dispatcher._cache._cache_file._load_index()
        magic = dispatcher.targetctx.codegen().magic_tuple()
        return any(key[1] == magic for key in index)
    except Exception:  # noqa: BLE001 -- numba internals moved: say "not cached"
        return False


def kernel_ready() -> bool:
    """True when a simulation will not compile: the kernel is loaded in this
    process or its machine code for this CPU is in the cache.

    Examples
    --------
    >>> isinstance(kernel_ready(), bool)
    True
    """
    for name in _ENTRY_POINTS:
        dispatcher = getattr(kernel, name)
        if not dispatcher.signatures and not _cached_on_disk(dispatcher):
            return False
    return True


def kernel_loaded() -> bool:
    """True when this process already holds the compiled kernel (no load, no
    compile before the next call)."""
    return all(getattr(kernel, name).signatures for name in _ENTRY_POINTS)


def compiled_now() -> int:
    """Entry-point signatures compiled (not loaded from the cache) in this process."""
    return sum(
        sum(getattr(kernel, name).stats.cache_misses.values()) for name in _ENTRY_POINTS
    )


def warm() -> float:
    """Compile the kernel (or load it from the cache); returns the seconds it took.

    Runs one rock of a one-segment model with an analysis point, an envelope,
    recorded impacts and a trajectory: every kernel signature a simulation uses.
    """
    from fieldkit.model.model_file import model_from_dict
    from fieldkit.model.simulate import simulate

    tic = time.perf_counter()
    simulate(
        model_from_dict(_TINY_MODEL),
        1,
        np.random.default_rng(0),
        analysis_x_m=[5.0],
        trajectories=1,
        record_impacts=True,
        envelope_dx_m=1.0,
        compile_first=False,
    )
    return time.perf_counter() - tic


def main() -> None:
    """Warm the cache (compile or load the kernel) and print what it did."""
    ready = kernel_ready()
    if not ready:
        print("compiling the simulator, first run only ...", flush=True)
    seconds = warm()
    what = "compiled" if compiled_now() else "loaded from the cache"
    print(f"simulator {what} in {seconds:.1f} s ({kernel.run_rocks.stats.cache_path})")
