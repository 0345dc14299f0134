"""Impact-level prediction: each measured impact's rebound under a model's laws.

Given an ImpactTable's measured impacts (local ``vin_mps``, ``vit_mps`` on the
table's ``slope_deg``, ``omega_i_radps`` where known, ``radius_m``, ``gyration_m``,
``material``) and a :class:`~fieldkit.model.model_file.Model`, predict each impact's
``vfn``, ``vft`` and ``omega_f`` with the model's material *means* (no random draws)
and its active impact-stage effects. The physics is the simulator's own:
:func:`fieldkit.model.kernel.restitution`, the one function the kernel's impact stage
calls, looped over the rows in compiled code. ``slope_roughness`` acts through the
slope the kernel recorded (``slope_deg``), so it needs nothing here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from fieldkit.errors import InputFileError
from fieldkit.impact_table import ImpactTable
from fieldkit.model import kernel
from fieldkit.model.effects import registry
from fieldkit.model.model_file import Model

#: Columns the prediction reads (``omega_i_radps`` optional: NaN = rolling, -vit/r).
INPUT_COLUMNS = ("vin_mps", "vit_mps", "radius_m", "gyration_m", "material")


@dataclass(frozen=True)
class ImpactInputs:
    """The measured impact state, as arrays (one entry per impact)."""

    vin_mps: np.ndarray
    vit_mps: np.ndarray
    omega_i_radps: np.ndarray
    radius_m: np.ndarray
    gyration_m: np.ndarray
    material_index: np.ndarray
    material_names: tuple[str, ...]


def impact_inputs(table: ImpactTable, model: Model) -> ImpactInputs:
    """The prediction inputs of ``table`` (derived columns) against ``model``.

    Raises
    ------
    InputFileError
        A required column is missing or empty, or a material of the table is not
        in the model (named).
    """
    frame = table.frame
    problem = table.unusable_columns(INPUT_COLUMNS)
    if problem:
        raise InputFileError(
            f"{problem}: needed to predict impacts", source=table.source
        )
    names = tuple(model.materials)
    labels = frame["material"].astype("string")
    unknown = sorted(set(labels.dropna()) - set(names))
    if unknown or labels.isna().any():
        what = ", ".join(unknown) if unknown else "(empty)"
        raise InputFileError(
            f"material(s) {what} not in the model (model has {', '.join(names)})",
            source=table.source,
            where="material",
        )
    index = np.array([names.index(m) for m in labels], np.int64)
    radius = table.column("radius_m")
    omega = table.column("omega_i_radps")
    vit = table.column("vit_mps")
    omega = np.where(np.isfinite(omega), omega, -vit / radius)
    return ImpactInputs(
        vin_mps=table.column("vin_mps"),
        vit_mps=vit,
        omega_i_radps=omega,
        radius_m=radius,
        gyration_m=table.column("gyration_m"),
        material_index=index,
        material_names=names,
    )


@njit(cache=True)
def predict_rows(vin, vit, omega, r, kg, mi, e_n, e_t, flags, par):
    """``(n, 3)`` ``vfn, vft, omega_f`` of each row (compiled loop over
    :func:`fieldkit.model.kernel.restitution`; ``mi`` indexes ``e_n``, ``e_t``)."""
    n = vin.size
    out = np.empty((n, 3))
    for i in range(n):
        m = mi[i]
        out[i, 0], out[i, 1], out[i, 2] = kernel.restitution(
            vin[i], vit[i], e_n[m], e_n[m], e_t[m], omega[i], r[i], kg[i], flags, par
        )
    return out


def predict_arrays(
    inputs: ImpactInputs,
    e_n: np.ndarray,
    e_t: np.ndarray,
    effects: dict[str, dict[str, float]],
) -> np.ndarray:
    """``(n, 3)`` array of predicted ``vfn, vft, omega_f`` for per-material means.

    ``e_n``, ``e_t`` are indexed like ``inputs.material_names``; ``effects`` maps
    active effect -> parameter values (as in a model file).
    """
    flags, par = registry.kernel_arrays(effects)
    return predict_rows(
        inputs.vin_mps,
        inputs.vit_mps,
        inputs.omega_i_radps,
        inputs.radius_m,
        inputs.gyration_m,
        inputs.material_index,
        np.ascontiguousarray(e_n, float),
        np.ascontiguousarray(e_t, float),
        flags,
        par,
    )


def predict_impacts(table: ImpactTable, model: Model) -> dict[str, np.ndarray]:
    """Predicted ``vfn_mps``, ``vft_mps``, ``omega_f_radps`` of each row of ``table``.

    Examples
    --------
    >>> import pandas as pd
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 50], "z_m": [30, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.5, "e_t": 0.8,
    ...   "friction_deg": 25}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 31}})
    >>> t = ImpactTable(pd.DataFrame({"path_id": ["A"], "point": ["1"], "x_m": [0.0],
    ...   "z_m": [0.0], "slope_deg": [0.0], "vi_x_mps": [3.0], "vi_z_mps": [-4.0],
    ...   "vf_x_mps": [3.0], "vf_z_mps": [2.0], "material": ["rock"],
    ...   "radius_m": [0.2], "gyration_m": [0.1]})).derive()
    >>> {k: round(float(v[0]), 6) for k, v in predict_impacts(t, m).items()}
    {'vfn_mps': 2.0, 'vft_mps': 2.4, 'omega_f_radps': -12.0}
    """
    inputs = impact_inputs(table, model)
    mats = [model.materials[n] for n in inputs.material_names]
    out = predict_arrays(
        inputs,
        np.array([m.e_n for m in mats]),
        np.array([m.e_t for m in mats]),
        model.effects,
    )
    return {"vfn_mps": out[:, 0], "vft_mps": out[:, 1], "omega_f_radps": out[:, 2]}
