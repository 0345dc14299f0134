"""The registry of effects: typed metadata, parameter layout, lookup by name.

An effect declares its name, the stage it acts in (``impact``, ``flight`` or
``slide``), its physics in one line, its parameters (default, bounds, units, the
*neutral* value that reproduces the base model exactly) and its thesis reference.
Model files switch effects on by name; parameters are namespaced
``effect.parameter`` (``angle_dependent_restitution.b``). The kernel receives the
active flags and one flat parameter array laid out by :func:`parameter_layout`.
"""

from __future__ import annotations

import math

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.model.effects import (
    affine_rebound,
    air_drag,
    angle_dependent_restitution,
    mass_loss,
    rotation_friction,
    slope_roughness,
    tree_impacts,
    velocity_scaled_restitution,
)
from fieldkit.model.effects.spec import EXPORT_TARGETS, EffectSpec, Parameter

__all__ = ["EFFECTS", "BY_NAME", "EffectSpec", "Parameter", "effect", "describe"]


#: Every effect, in contract order (this order fixes the kernel's flag layout).
EFFECTS: tuple[EffectSpec, ...] = (
    angle_dependent_restitution.SPEC,
    velocity_scaled_restitution.SPEC,
    rotation_friction.SPEC,
    slope_roughness.SPEC,
    mass_loss.SPEC,
    tree_impacts.SPEC,
    air_drag.SPEC,
    affine_rebound.SPEC,
)
BY_NAME: dict[str, EffectSpec] = {spec.name: spec for spec in EFFECTS}
#: :attr:`EffectSpec.kind` in words (``fieldkit effects NAME``).
KIND_WORDS = {
    "law": "a physical law",
    "alternative": "a statistical alternative, not a physical law: no export "
    "target has it",
}


def effect(name: str) -> EffectSpec:
    """The effect called ``name``.

    Raises
    ------
    ArgumentError
        Unknown name; the message lists the known ones.

    Examples
    --------
    >>> effect("air_drag").stage
    'flight'
    """
    try:
        return BY_NAME[name]
    except KeyError:
        raise ArgumentError(
            f"unknown effect {name!r} (known: {', '.join(BY_NAME)})", source="effects"
        ) from None


def parameter_layout() -> dict[str, int]:
    """Namespaced parameter name -> index in the kernel's flat parameter array."""
    layout: dict[str, int] = {}
    for spec in EFFECTS:
        for p in spec.parameters:
            layout[f"{spec.name}.{p.name}"] = len(layout)
    return layout


LAYOUT: dict[str, int] = parameter_layout()


def kernel_arrays(active: dict[str, dict[str, float]]) -> tuple[np.ndarray, np.ndarray]:
    """``(flags, params)`` for the kernel from active effect -> parameter values.

    ``flags[i]`` is 1 where ``EFFECTS[i]`` is on; ``params`` follows :data:`LAYOUT`,
    inactive effects filled with their neutral values.
    """
    flags = np.zeros(len(EFFECTS), np.int64)
    params = np.zeros(len(LAYOUT), np.float64)
    for i, spec in enumerate(EFFECTS):
        values = spec.neutral()
        if spec.name in active:
            flags[i] = 1
            values.update(active[spec.name])
        for name, value in values.items():
            params[LAYOUT[f"{spec.name}.{name}"]] = value
    return flags, params


def validate(
    name: str, values: dict[str, object], *, source: str = "effects"
) -> dict[str, float]:
    """Full parameter dict (defaults filled) for effect ``name``; one-line errors.

    Errors name ``source`` (the model file) and the field ``effects.<name>.<param>``,
    with the bounds.
    """
    spec = effect(name)
    out = spec.defaults()
    for key, value in values.items():
        where = f"effects.{name}.{key}"
        known = [p.name for p in spec.parameters]
        if key not in known:
            raise ArgumentError(
                f"unknown parameter (known: {', '.join(known) or 'none'})",
                source=source,
                where=where,
            )
        p = spec.parameter(key)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ArgumentError(
                f"must be a number (got {value!r})", source=source, where=where
            )
        try:
            number = float(value)
        except OverflowError:  # an integer beyond the float range
            number = math.inf
        if not math.isfinite(number):
            raise ArgumentError(
                f"must be a finite number (got {number})", source=source, where=where
            )
        if not p.lower <= number <= p.upper:
            raise ArgumentError(
                f"must be in [{p.lower:g}, {p.upper:g}] {p.units} (got {number:g})",
                source=source,
                where=where,
            )
        out[key] = number
    return out


def describe(name: str) -> str:
    """Human-readable description of one effect (for ``fieldkit effects NAME``)."""
    spec = effect(name)
    lines = [
        f"{spec.name} ({spec.stage} stage): {spec.summary}",
        f"  physics:   {spec.physics}",
        f"  reference: {spec.reference}",
        f"  kind:      {KIND_WORDS[spec.kind]}",
        "  parameters:",
    ]
    for p in spec.parameters:
        neutral = "none" if p.neutral is None else f"{p.neutral:g}"
        lines.append(
            f"    {spec.name}.{p.name} [{p.units}] default {p.default:g}, bounds "
            f"[{p.lower:g}, {p.upper:g}], neutral {neutral}: {p.description}"
        )
        if p.held:
            lines.append(f"      held by an impact fit: {p.held}")
    if spec.reads or spec.writes:
        lines.append(
            f"  reads: {', '.join(spec.reads) or '-'}; writes: "
            f"{', '.join(spec.writes) or '-'}"
        )
    lines.append(
        "  from an ImpactTable: "
        + (f"no: {spec.not_from_impacts}" if spec.not_from_impacts else "yes")
    )
    for target in EXPORT_TARGETS:
        rule = spec.export(target)
        if rule is None:
            text = f"not mapped: {spec.name} is not a physical law"
        else:
            text = f"{'mapped' if rule.mapped else 'not mapped'}: {rule.how}"
        lines.append(f"  export to {target}: {text}")
    return "\n".join(lines)
