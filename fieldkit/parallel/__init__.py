"""Running independent units of work past one process: the Dask engine
(:mod:`fieldkit.parallel.engine`). Stages hand it picklable units and a pure
function; it never imports a stage."""
