"""Synthetic ImpactTables: the simulator's impacts with hidden effects and noise.

The pattern of SimPEG's ``SyntheticData``: the clean values are kept beside the
noisy ones, so a recovery test can compare a fit with the truth.

* Hidden effects are added to (or override the parameters of) the model's own.
* One path per rock (``path_id`` = rock number), ``paths`` rocks.
* Noise on the rebound (relative, isotropic, ``noise_fraction`` F): each section
  component of ``vf`` gets independent ``N(0, (F |vf|)^2)`` noise, so the local
  components ``vfn``, ``vft`` carry the same SD ``F |vf|`` (a rotation keeps an
  isotropic Gaussian); ``omega_f`` gets ``N(0, (F |vf| / r)^2)`` (the same relative
  error on the rolling-equivalent spin, never zero for a moving rock).
* Noise on the impact (``impact_noise_fraction`` F_i, default 0: exact), the same
  model, independent of the rebound's: ``vi_x``, ``vi_z`` each ``N(0, (F_i |vi|)^2)``
  and ``omega_i`` ``N(0, (F_i |vi| / r)^2)``. A survey measures both velocities with
  error; the fit and the diagnosis take it into account when the table carries
  ``vin_sd_mps``, ``vit_sd_mps`` (:func:`fieldkit.fit.impact_fit.impact_problem`);
  without that, noise on ``vi`` dilutes the regression (flattens the rebound
  against the impact speed) and biases ``e_n`` by about ``F_i^2 |vi|^2 / vin^2``.
* Clean values are kept in ``vf_x_mps_true``, ``vf_z_mps_true``, ``vfn_mps_true``,
  ``vft_mps_true``, ``omega_f_radps_true`` and, with impact noise,
  ``vi_x_mps_true``, ``vi_z_mps_true``, ``vin_mps_true``, ``vit_mps_true``,
  ``omega_i_radps_true``; the noise SDs in ``vfn_sd_mps``, ``vft_sd_mps``,
  ``omega_f_sd_radps`` (when F > 0 or F_i > 0; zero when F = 0) and ``vin_sd_mps``,
  ``vit_sd_mps``, ``omega_i_sd_radps`` (when F_i > 0). The impact and rebound
  errors are independent, so no ``vin_vfn_corr``/``vit_vft_corr`` is written.

The random numbers come from one ``numpy.random.Generator`` in this order: the
simulation's, then the rebound noise (a ``(3, n)`` standard normal block: ``vf_x``,
``vf_z``, ``omega_f``), then -- only when F_i > 0 -- the impact noise (another
``(3, n)`` block: ``vi_x``, ``vi_z``, ``omega_i``). A seed reproduces the table
exactly, and with F_i = 0 a seed gives the same table as before impact noise existed.
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
#: ... and of the impact columns, when the impact velocity is noisy.
TRUE_IMPACT_COLUMNS = ("vi_x_mps", "vi_z_mps", "vin_mps", "vit_mps", "omega_i_radps")


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


def check_noise(noise_fraction: float, impact_noise_fraction: float = 0.0) -> None:
    """Refuse a relative noise outside [0, 1] (named by its argument)."""
    for name, value in (
        ("noise_fraction", noise_fraction),
        ("impact_noise_fraction", impact_noise_fraction),
    ):
        if not (np.isfinite(value) and 0.0 <= value <= 1.0):
            raise ArgumentError(f"{name} must be in [0, 1] (got {value})", source=name)


def synthetic_table(
    model: Model,
    *,
    effects: dict[str, dict[str, float]],
    noise_fraction: float,
    paths: int,
    rng: np.random.Generator,
    impact_noise_fraction: float = 0.0,
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
    check_noise(noise_fraction, impact_noise_fraction)
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
    radius = frame["radius_m"].to_numpy(float)
    vf = np.hypot(frame["vf_x_mps"].to_numpy(float), frame["vf_z_mps"].to_numpy(float))
    sd_v = noise_fraction * vf
    sd_w = sd_v / radius
    n = len(frame)
    noise = rng.standard_normal((3, n))
    frame["vf_x_mps"] = frame["vf_x_mps"].to_numpy(float) + sd_v * noise[0]
    frame["vf_z_mps"] = frame["vf_z_mps"].to_numpy(float) + sd_v * noise[1]
    frame["omega_f_radps"] = frame["omega_f_radps"].to_numpy(float) + sd_w * noise[2]
    if noise_fraction > 0.0 or impact_noise_fraction > 0.0:
        frame["vfn_sd_mps"] = sd_v
        frame["vft_sd_mps"] = sd_v
        frame["omega_f_sd_radps"] = sd_w
    if impact_noise_fraction > 0.0:
        for name in TRUE_IMPACT_COLUMNS:
            frame[f"{name}_true"] = frame[name].to_numpy(float)
        vi = np.hypot(
            frame["vi_x_mps"].to_numpy(float), frame["vi_z_mps"].to_numpy(float)
        )
        sd_i = impact_noise_fraction * vi
        noise = rng.standard_normal((3, n))
        frame["vi_x_mps"] = frame["vi_x_mps"].to_numpy(float) + sd_i * noise[0]
        frame["vi_z_mps"] = frame["vi_z_mps"].to_numpy(float) + sd_i * noise[1]
        frame["omega_i_radps"] = (
            frame["omega_i_radps"].to_numpy(float) + sd_i / radius * noise[2]
        )
        frame["vin_sd_mps"] = sd_i
        frame["vit_sd_mps"] = sd_i
        frame["omega_i_sd_radps"] = sd_i / radius
    return ImpactTable(frame, source="synthetic").derive()
