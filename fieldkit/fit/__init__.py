"""Fitting model parameters to measured impacts (docs/architecture.md §4)."""
