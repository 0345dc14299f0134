"""Synthetic observed runs with known parameters (tests and the calibration check).

A synthetic *site* is a set of runs, each on its own analytic section: a steep
upper slope (``upper_deg``, length drawn per run) onto a 200 m runout zone
(``lower_deg``), one material ``talus`` with slope roughness switched on. Each run
releases one block a drawn height above the ground 0.5 m down the upper slope; its
"observed" runout is one rock of the *true* model simulated with the site's
Generator (so never with the fit's common random numbers).
"""

from __future__ import annotations

import math

import numpy as np

from fieldkit.fit.path_runs import PathRun
from fieldkit.model.model_file import Model, model_from_dict
from fieldkit.model.simulate import simulate

#: The material of the synthetic sites before any fitted value is set.
BASE_MATERIAL: dict[str, float] = {
    "e_n": 0.3,
    "e_t": 0.8,
    "friction_deg": 30.0,
    "e_n_sd": 0.05,
    "e_t_sd": 0.05,
    "roughness_deg_sd": 4.0,
}


def section_model(
    upper_length_m: float,
    drop_m: float,
    *,
    upper_deg: float = 50.0,
    lower_deg: float = 12.0,
    lower_length_m: float = 200.0,
    material: dict[str, float] | None = None,
) -> Model:
    """Model of one synthetic run (module docstring); chainage 0 at the top.

    Examples
    --------
    >>> m = section_model(40.0, 5.0)
    >>> [round(float(v), 1) for v in m.profile.x_m]
    [0.0, 40.0, 240.0]
    """
    z2 = lower_length_m * math.tan(math.radians(lower_deg))
    z1 = upper_length_m * math.tan(math.radians(upper_deg))
    x0 = 0.5
    ground0 = z1 + z2 - x0 * math.tan(math.radians(upper_deg))
    return model_from_dict(
        {
            "profile": {
                "x_m": [0.0, upper_length_m, upper_length_m + lower_length_m],
                "z_m": [z1 + z2, z2, 0.0],
                "material": "talus",
            },
            "materials": {"talus": dict(material or BASE_MATERIAL)},
            "effects": {"slope_roughness": {"scale": 1.0}},
            "body": {"mass_kg": 500.0, "radius_m": 0.4},
            "seeder": {"x_m": x0, "z_m": ground0 + drop_m},
        },
        source="synthetic",
    )


def synthetic_site(
    true_values: dict[str, float],
    runs: int,
    rng: np.random.Generator,
    *,
    upper_length_m: tuple[float, float] = (25.0, 70.0),
    drop_m: tuple[float, float] = (2.0, 8.0),
) -> list[PathRun]:
    """``runs`` synthetic runs whose observed runout comes from the model with
    ``true_values`` (namespaced, e.g. ``materials.talus.friction_deg``) set; the
    returned runs carry the *base* model (:data:`BASE_MATERIAL`), as a fit would.

    Examples
    --------
    >>> site = synthetic_site({}, 3, np.random.default_rng(1))
    >>> len(site), all(r.observed_runout_m > 0 for r in site)
    (3, True)
    """
    out = []
    for i in range(runs):
        length = rng.uniform(*upper_length_m)
        drop = rng.uniform(*drop_m)
        base = section_model(length, drop)
        truth = base.with_parameters(true_values) if true_values else base
        observed = float(simulate(truth, 1, rng).runout_x_m[0])
        out.append(
            PathRun(
                path_id=f"run{i:02d}",
                model=base,
                # the runout as simulated_runouts measures it: from the release
                # (the seeder's chainage), not from the profile's first vertex
                observed_runout_m=observed - float(base.seeder.x_m),
                group="synthetic",
            )
        )
    return out
