"""Physical effects of the forward model (docs/architecture.md §5 names).

Each effect is one module with its metadata ``SPEC`` (an
:class:`~fieldkit.model.effects.registry.EffectSpec`) and the compiled physics hook(s)
the kernel calls; :mod:`fieldkit.model.effects.registry` lists them all.
"""
