"""Synthetic impact tables with known hidden effects, for the diagnosis tests.

Every table here has a known truth: the smoke model's materials (``e_n``, ``e_t``
of rock, talus, soil) with their SDs zeroed, rocks started with scattered
velocities and masses, and chosen hidden effects at sizes a practising engineer
would call realistic: ``angle_dependent_restitution.b = 1.03`` (thesis eq. 5.4),
``velocity_scaled_restitution.k_mps = 9.144`` (RocFall's K = 30 ft/s, thesis
eq. 7.1) and ``rotation_friction`` at its defaults (friction 0.5, coupling 1).
Noise is relative on the rebound velocity (:func:`synthetic_table`).

Imported by the tests of this folder (pytest puts the folder on ``sys.path``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.diagnose.impacts import base_model
from fieldkit.fit.impact_model import impact_inputs, predict_arrays
from fieldkit.fit.synthetic import synthetic_table
from fieldkit.impact_table import ImpactTable
from fieldkit.model.model_file import Model, model_from_dict
from fieldkit.physics.local_axes import to_section

SMOKE = Path(__file__).parents[1] / "model" / "data" / "smoke.json"

ANGLE = "angle_dependent_restitution"
VELOCITY = "velocity_scaled_restitution"
ROTATION = "rotation_friction"
#: Realistic hidden-effect sizes (see the module docstring).
HIDDEN = {
    ANGLE: {"b": 1.03},
    VELOCITY: {"k_mps": 9.144},
    ROTATION: {},
}
#: The hidden truth of every fitted parameter (materials of smoke.json; effects
#: above, rotation_friction at its registry defaults).
TRUTH = {
    "materials.rock.e_n": 0.6,
    "materials.rock.e_t": 0.9,
    "materials.talus.e_n": 0.5,
    "materials.talus.e_t": 0.85,
    "materials.soil.e_n": 0.3,
    "materials.soil.e_t": 0.7,
    f"{ANGLE}.b": 1.03,
    f"{VELOCITY}.k_mps": 9.144,
    f"{ROTATION}.friction": 0.5,
    f"{ROTATION}.coupling": 1.0,
}


def smoke_model(*, one_material: str | None = None) -> Model:
    """The smoke model without effects, material SDs zero, scattered seeder.

    ``one_material`` makes every profile segment that material.
    """
    data = json.loads(SMOKE.read_text())
    for m in data["materials"].values():
        m["e_n_sd"] = 0.0
        m["e_t_sd"] = 0.0
    data["effects"] = {}
    data["seeder"].update(vx_sd_mps=2.0, vz_sd_mps=1.0, mass_sd_kg=150.0)
    if one_material is not None:
        n = len(data["profile"]["material"])
        data["profile"]["material"] = [one_material] * n
    return model_from_dict(data, source="smoke.json")


def hidden_table(
    effects: tuple[str, ...],
    *,
    noise: float,
    paths: int,
    seed: int,
    impacts: int | None = None,
) -> ImpactTable:
    """A synthetic table with ``effects`` hidden at their realistic sizes.

    ``impacts`` keeps only the first that many rows (whole paths, then part of
    the last one).
    """
    table = synthetic_table(
        smoke_model(),
        effects={e: dict(HIDDEN[e]) for e in effects},
        noise_fraction=noise,
        paths=paths,
        rng=np.random.default_rng(seed),
    )
    if impacts is not None:
        assert len(table) >= impacts, (len(table), impacts)
        table = ImpactTable(table.frame.iloc[:impacts], source="synthetic")
    return table


def narrow_speed_table(
    rng: np.random.Generator,
    *,
    speed: tuple[float, float] = (10.0, 10.2),
    theta_deg: tuple[float, float] = (20.0, 45.0),
    paths: int = 20,
    per_path: int = 10,
    slope_deg: float = 35.0,
    noise: float = 0.05,
    b: float = 1.03,
) -> ImpactTable:
    """Impacts built by hand, all at nearly the same speed, angle law hidden.

    One material (``rock``: e_n 0.6, e_t 0.9), ``e_n`` scaled by
    ``(theta_i / 30)^-b``; impact speeds uniform in ``speed`` and angles to the
    ground uniform in ``theta_deg``, so the normal speed ``|v| sin(theta_i)`` rises
    with the angle alone. Spins are not given (estimated as rolling), so
    rotation_friction is not a candidate. Relative noise ``noise |vf|`` on each
    section component of the rebound, with its SD in ``vfn_sd_mps``,
    ``vft_sd_mps``.
    """
    n = paths * per_path
    v = rng.uniform(*speed, n)
    theta = np.radians(rng.uniform(*theta_deg, n))
    vx, vz = to_section(v * np.cos(theta), -v * np.sin(theta), slope_deg)
    frame = pd.DataFrame(
        {
            "path_id": np.repeat([f"P{i}" for i in range(paths)], per_path),
            "point": np.tile([str(j) for j in range(per_path)], paths),
            "x_m": np.arange(n, dtype=float),
            "z_m": -0.7 * np.arange(n, dtype=float),
            "slope_deg": slope_deg,
            "material": "rock",
            "mass_kg": 500.0,
            "radius_m": 0.36,
            "gyration_m": 0.295,
            "vi_x_mps": vx,
            "vi_z_mps": vz,
            "vf_x_mps": vx,  # placeholders until the rebound is computed
            "vf_z_mps": vz,
        }
    )
    table = ImpactTable(frame).derive()
    clean = predict_arrays(
        impact_inputs(table, base_model(table)),
        np.array([0.6]),
        np.array([0.9]),
        {ANGLE: {"b": b, "theta_ref_deg": 30.0, "a": 0.0}},
    )
    fx, fz = to_section(clean[:, 1], clean[:, 0], slope_deg)
    sd = noise * np.hypot(fx, fz)
    e = rng.standard_normal((2, n))
    frame["vf_x_mps"] = fx + sd * e[0]
    frame["vf_z_mps"] = fz + sd * e[1]
    frame["vfn_sd_mps"] = sd
    frame["vft_sd_mps"] = sd
    return ImpactTable(frame, source="narrow speeds").derive()


def chainage_trend_table(
    rng: np.random.Generator,
    *,
    amplitude: float = 0.3,
    paths: int = 40,
    noise: float = 0.05,
) -> ImpactTable:
    """No effect of the vocabulary: clean ``vfn`` scaled by a trend in ``x_m``.

    The smoke model with every segment ``talus`` (so a per-material ``e_n`` cannot
    absorb the trend), simulated without noise; each clean ``vfn`` is multiplied
    by ``1 + amplitude (x_m - 45) / 45`` (the profile runs 0-90 m), then the
    rebound gets the relative noise of :func:`synthetic_table` (``noise |vf|``
    per section component, ``noise |vf| / r`` on the spin) with its SD columns.
    """
    clean = synthetic_table(
        smoke_model(one_material="talus"),
        effects={},
        noise_fraction=0.0,
        paths=paths,
        rng=rng,
    )
    f = clean.frame.copy()
    x = f["x_m"].to_numpy(float)
    vfn = f["vfn_mps_true"].to_numpy(float) * (1.0 + amplitude * (x - 45.0) / 45.0)
    vx, vz = to_section(
        f["vft_mps_true"].to_numpy(float), vfn, f["slope_deg"].to_numpy(float)
    )
    sd = noise * np.hypot(vx, vz)
    r = f["radius_m"].to_numpy(float)
    e = rng.standard_normal((3, len(f)))
    f["vf_x_mps"] = vx + sd * e[0]
    f["vf_z_mps"] = vz + sd * e[1]
    f["omega_f_radps"] = f["omega_f_radps_true"].to_numpy(float) + sd / r * e[2]
    f["vfn_sd_mps"] = sd
    f["vft_sd_mps"] = sd
    f["omega_f_sd_radps"] = sd / r
    return ImpactTable(f, source="chainage trend").derive()
