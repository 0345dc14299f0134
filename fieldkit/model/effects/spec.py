"""Typed metadata of an effect: :class:`Parameter` and :class:`EffectSpec`."""

from __future__ import annotations

from dataclasses import dataclass

from fieldkit.errors import ArgumentError


@dataclass(frozen=True)
class Parameter:
    """One effect parameter: default, closed bounds, unit and the neutral value."""

    name: str
    default: float
    lower: float
    upper: float
    units: str
    description: str
    neutral: float | None  # value that makes the effect a no-op (None: no such value)


@dataclass(frozen=True)
class EffectSpec:
    """Declared metadata of one effect."""

    name: str
    stage: str  # "impact" | "flight" | "slide"
    summary: str
    physics: str
    parameters: tuple[Parameter, ...]
    reference: str
    reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()

    def parameter(self, name: str) -> Parameter:
        """The parameter called ``name``; ArgumentError listing the known ones."""
        for p in self.parameters:
            if p.name == name:
                return p
        known = ", ".join(p.name for p in self.parameters)
        raise ArgumentError(
            f"unknown parameter {self.name}.{name} (known: {known})", source="effects"
        )

    def defaults(self) -> dict[str, float]:
        """Parameter name -> default."""
        return {p.name: p.default for p in self.parameters}

    def neutral(self) -> dict[str, float]:
        """Parameters that reproduce the base model (defaults where no neutral)."""
        return {
            p.name: p.default if p.neutral is None else p.neutral
            for p in self.parameters
        }
