"""Warm the simulator's compile cache: ``make`` runs :func:`main` at install.

The kernel (:mod:`fieldkit.model.kernel`) is compiled by numba with ``cache=True``:
the first run on a machine compiles it (tens of seconds) and writes the machine code
to ``__pycache__`` beside the source (numba keys it by the source file's path,
modification time and size, and by the CPU); every later process loads it in well
under a second. :func:`fieldkit.model.kernel.kernel_ready` says whether a run will
have to compile; :func:`fieldkit.model.simulate.warm_kernel` compiles (or loads) it
on a one-rock model, so a simulation's own time never includes compiling.

A fresh clone (new paths, new modification times) compiles once, at its install
(``python -c "from fieldkit.model.compile_cache import main; main()"``) or on its
first run; moving a clone keeps its cache.
"""

from __future__ import annotations

import fieldkit.model.kernel as kernel
from fieldkit.model.simulate import warm_kernel


def main() -> None:
    """Compile the kernel or load it from the cache, and print which and how long."""
    if not kernel.kernel_ready():
        print("compiling the simulator, first run only ...", flush=True)
    seconds = warm_kernel()
    what = "compiled" if kernel.compiled_now() else "loaded from the cache"
    print(f"simulator {what} in {seconds:.1f} s ({kernel.run_rocks.stats.cache_path})")
