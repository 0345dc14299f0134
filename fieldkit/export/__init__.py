"""Export: a calibrated model file -> the input files of other rockfall simulators.

One module per target (:mod:`.rocfall`, :mod:`.crsp`, :mod:`.rockyfor3d`,
:mod:`.ramms`, :mod:`.rstone`, :mod:`.json_model`), each a pure function from a
:class:`~fieldkit.model.model_file.Model` (and, for grid targets, a
:class:`~fieldkit.export.site.ExportSite`) to an :class:`~fieldkit.export.result.
Export`: the target's files as text, and what was mapped to what, what could not be
mapped and why, the units converted and the residual mismatch where a class had to
be chosen -- the README written beside the files. :mod:`.targets` lists them;
:mod:`.rocfall_import` reads RocFall text back into a model. Writing files is the
command line's (:mod:`fieldkit.cli.export`).
"""
