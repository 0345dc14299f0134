"""Synthetic ImpactTables: the simulator's impacts with hidden effects and noise.

The pattern of SimPEG's ``SyntheticData``: the clean values are kept beside the
noisy ones, so a recovery test can compare a fit with the truth.

* Hidden effects are added to (or override the parameters of) the model's own.
* One path per rock (``path_id`` = rock number), ``paths`` rocks.
* Noise model (relative, isotropic, on the *restitution* velocity only): each
  section component of ``vf`` gets independent ``N(0, (F |vf|)^2)`` noise, so the
  local components ``vfn``, ``vft`` carry the same SD ``F |vf|`` (a rotation keeps an
  isotropic Gaussian); ``omega_f`` gets ``N(0, (F |vf| / r)^2)`` (the same relative
  error on the rolling-equivalent spin, never zero for a moving rock). The impact
  velocity ``vi`` and ``omega_i`` are left exact: the fit treats them as known
  inputs (no errors-in-variables model), and noise there would bias ``e_n`` by
  about ``F^2 |vi|^2 / vin^2``.
* Clean values are kept in ``vf_x_mps_true``, ``vf_z_mps_true``, ``vfn_mps_true``,
  ``vft_mps_true``, ``omega_f_radps_true``; the noise SDs in ``vfn_sd_mps``,
  ``vft_sd_mps``, ``omega_f_sd_radps`` (omitted when ``F = 0``).

The random numbers come from one ``numpy.random.Generator``: the simulation's
first, then the noise, so a seed reproduces the table exactly.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.impact_table import ImpactTable
from fieldkit.model.effects import registry
from fieldkit.model.model_file import Model, model_from_dict, model_to_dict
from fieldkit.model.simulate import simulate

#: Most rocks in one synthetic table. Each rock makes up to the simulator's impact
#: cap (500) rows and a row holds about 2.6 kB in memory while the table is built
#: (2,000 rocks of the Table 7-1 model: 305k impacts, 1.2 GB); 5,000 rocks is
#: about 3 GB, and a fit recovers its parameters from a few hundred.
MAX_PATHS = 5_000

#: Clean copies kept next to the noisy columns.
TRUE_COLUMNS = ("vf_x_mps", "vf_z_mps", "vfn_mps", "vft_mps", "omega_f_radps")


def with_effects(model: Model, effects: dict[str, dict[str, float]]) -> Model:
    """``model`` with ``effects`` switched on (validated; parameters override)."""
    data = model_to_dict(model)
    for name, values in effects.items():
        merged = {**data["effects"].get(name, {}), **values}
        data["effects"][name] = registry.validate(name, merged, source="effects")
    out = model_from_dict(data, source=model.source)
    return replace(out, provenance=dict(model.provenance))


def check_paths(paths: int) -> None:
    """Refuse a number of rocks outside 1 .. :data:`MAX_PATHS` (memory, see there)."""
    if not (isinstance(paths, int | np.integer) and 1 <= paths <= MAX_PATHS):
        raise ArgumentError(
            f"paths must be from 1 to {MAX_PATHS:,} (got {paths}): each rock adds up "
            "to 500 impact rows of about 2.6 kB in memory",
            source="paths",
        )


def synthetic_table(
    model: Model,
    *,
    effects: dict[str, dict[str, float]],
    noise_fraction: float,
    paths: int,
    rng: np.random.Generator,
) -> ImpactTable:
    """An ImpactTable of ``paths`` simulated rocks with hidden ``effects`` and noise.

    See the module docstring for the noise model and the extra columns.

    Examples
    --------
    >>> from fieldkit.model.model_file import read_model
    >>> m = read_model("tests/model/data/smoke.json")
    >>> t = synthetic_table(m, effects={}, noise_fraction=0.05, paths=3,
    ...                     rng=np.random.default_rng(0))
    >>> t.paths()
    ['0', '1', '2']
    """
    if not (np.isfinite(noise_fraction) and 0.0 <= noise_fraction <= 1.0):
        raise ArgumentError(
            f"noise_fraction must be in [0, 1] (got {noise_fraction})",
            source="noise_fraction",
        )
    check_paths(paths)
    hidden = with_effects(model, effects)
    table = simulate(hidden, int(paths), rng, record_impacts=True).impact_table
    if table is None or len(table) == 0:
        raise ArgumentError(
            "the simulated rocks made no impacts (nothing to tabulate)", source="paths"
        )
    frame = table.frame.copy()
    for name in TRUE_COLUMNS:
        frame[f"{name}_true"] = frame[name].to_numpy(float)
    vf = np.hypot(frame["vf_x_mps"].to_numpy(float), frame["vf_z_mps"].to_numpy(float))
    sd_v = noise_fraction * vf
    sd_w = sd_v / frame["radius_m"].to_numpy(float)
    n = len(frame)
    noise = rng.standard_normal((3, n))
    frame["vf_x_mps"] = frame["vf_x_mps"].to_numpy(float) + sd_v * noise[0]
    frame["vf_z_mps"] = frame["vf_z_mps"].to_numpy(float) + sd_v * noise[1]
    frame["omega_f_radps"] = frame["omega_f_radps"].to_numpy(float) + sd_w * noise[2]
    if noise_fraction > 0.0:
        frame["vfn_sd_mps"] = sd_v
        frame["vft_sd_mps"] = sd_v
        frame["omega_f_sd_radps"] = sd_w
    return ImpactTable(frame, source="synthetic").derive()
