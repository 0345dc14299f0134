"""The forward model: a fast 2-D lumped-mass Monte Carlo rock-fall simulator (ch. 7).

A slope profile (a polyline with a material per segment), a seeder, exact ballistic
flight and first contact, the impact in local N/T axes with the active laws, the
sliding/rolling phase (eq. 7.3) and stopping; physical effects are small units in
:mod:`fieldkit.model.effects`, switched on in the model file.
"""

from fieldkit.model.cache_guard import guard

guard()  # before any compiled function is loaded from numba's cache

from fieldkit.model.model_file import (  # noqa: E402
    Model,
    model_from_dict,
    read_model,
    write_model,
)
from fieldkit.model.results import SimulationResult  # noqa: E402
from fieldkit.model.simulate import simulate  # noqa: E402

__all__ = [
    "Model",
    "SimulationResult",
    "model_from_dict",
    "read_model",
    "simulate",
    "write_model",
]
