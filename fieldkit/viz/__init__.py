"""Figures a rockfall engineer recognises (PNG, matplotlib Agg) and rerun recordings.

One module per kind of figure; every function takes data and returns a matplotlib Figure
or writes a PNG through :func:`fieldkit.viz.figure_files.save_png`.
"""
