"""The constant e_n, e_t a model's impact laws realise, for targets without the laws.

Some simulators take one restitution pair per material and nothing else (r.stone,
Rockyfor3D's soil types): a calibrated model whose e_n is scaled by the impact
velocity (eq. 7.1), depends on the impact angle (eq. 5.4) or couples rotation into
the tangential rebound cannot be written as it is -- the velocity-scaled
colluvium e_n of Tornado Mountain is above 1, which such a target refuses, though
the rebounds it produces are not. :func:`lumped_equivalent` writes instead the
constant pair a least-squares fit of fieldkit's own base model would give on the
calibrated model's simulated impacts of each material,

.. math:: e_n = \\frac{\\sum v_{fN} |v_{iN}|}{\\sum v_{iN}^2}, \\qquad
          e_t = \\frac{\\sum v_{fT} v_{iT}}{\\sum v_{iT}^2},

(the unweighted ``fieldkit fit`` of a constant-e_n, e_t model), and says so.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

import numpy as np

from fieldkit.model.effects import registry
from fieldkit.model.model_file import Model
from fieldkit.model.simulate import simulate

#: Impact-stage effects that change the restitution pair of an impact (effect
#: metadata, :attr:`~fieldkit.model.effects.spec.EffectSpec.changes_rebound`).
RESTITUTION_LAWS = tuple(s.name for s in registry.EFFECTS if s.changes_rebound)


def not_a_law(name: str, target: str) -> str:
    """Why ``target`` cannot take effect ``name`` when the effect is the diagnosis's
    statistical alternative (:attr:`EffectSpec.kind <fieldkit.model.effects.spec.
    EffectSpec.kind>` ``"alternative"``); ``""`` for a physical law.

    Examples
    --------
    >>> not_a_law("affine_rebound", "CRSP")[:40]
    'affine_rebound is a statistical alternat'
    >>> not_a_law("air_drag", "CRSP")
    ''
    """
    spec = registry.effect(name)
    if spec.is_law:
        return ""
    return (
        f"{name} is a statistical alternative ({spec.physics}), not a physical "
        f"law: {target} has no such law; a model that needs it is not described "
        "by any law a target program has"
    )


#: Rocks simulated, and the seed, for the realised pair.
ROCKS, SEED = 400, 0


def lumped_equivalent(
    model: Model,
    target: str,
    laws: Iterable[str] = RESTITUTION_LAWS,
    *,
    rocks: int = ROCKS,
    seed: int = SEED,
) -> tuple[Model, list[str]]:
    """``model`` without the active ``laws``, each material's e_n, e_t replaced by
    the constant pair its simulated impacts realise (module docstring).

    Returns
    -------
    model, lines
        The lumped model (``model`` itself when no law is active) and one line per
        material for the export's mismatches.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 60, 120], "z_m": [60, 20, 0],
    ...   "material": "talus"}, "materials": {"talus": {"e_n": 1.2, "e_t": 0.8,
    ...   "friction_deg": 30}}, "effects": {"velocity_scaled_restitution":
    ...   {"k_mps": 9.144}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 70}})
    >>> lumped, lines = lumped_equivalent(m, "r.stone", rocks=50)
    >>> sorted(lumped.effects), lumped.materials["talus"].e_n < 1.0
    ([], True)
    """
    active = [law for law in laws if law in model.effects]
    if not active:
        return model, []
    result = simulate(model, rocks, np.random.default_rng(seed), record_impacts=True)
    frame = result.impact_table.frame
    materials = dict(model.materials)
    lines = []
    alternatives = "".join(
        f"; {w}" for w in (not_a_law(a, target) for a in active) if w
    )
    for name, material in model.materials.items():
        rows = frame[frame["material"] == name]
        vin = rows["vin_mps"].to_numpy(float)
        vit = rows["vit_mps"].to_numpy(float)
        vfn = rows["vfn_mps"].to_numpy(float)
        vft = rows["vft_mps"].to_numpy(float)
        ok = np.isfinite(vin) & np.isfinite(vit) & np.isfinite(vfn) & np.isfinite(vft)
        if ok.sum() < 2:
            lines.append(
                f"{name}: no simulated impact on it ({rocks} rocks): e_n "
                f"{material.e_n:.4g}, e_t {material.e_t:.4g} written without "
                f"{', '.join(active)}, which {target} cannot represent"
            )
            continue
        e_n = float(np.sum(vfn[ok] * np.abs(vin[ok])) / np.sum(vin[ok] ** 2))
        e_t = float(np.sum(vft[ok] * vit[ok]) / np.sum(vit[ok] ** 2))
        materials[name] = replace(material, e_n=e_n, e_t=e_t)
        lines.append(
            f"{name}: {target} has no {', '.join(active)}: e_n {material.e_n:.4g}, "
            f"e_t {material.e_t:.4g} with them are written as the constant pair "
            f"they realise, e_n {e_n:.3f}, e_t {e_t:.3f} (least squares over the "
            f"{int(ok.sum())} impacts on {name} of {rocks} simulated rocks, seed "
            f"{seed}); the target's rebounds no longer vary with impact speed or "
            "angle as the calibrated ones do" + alternatives
        )
    effects = {k: v for k, v in model.effects.items() if k not in active}
    return replace(model, materials=materials, effects=effects), lines
