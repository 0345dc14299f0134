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


#: What an effect is: ``"law"``, a physical law with its reference (thesis or
#: literature); ``"alternative"``, a statistical alternative the diagnosis compares
#: the laws with (no target program has it: an export says so).
KINDS = ("law", "alternative")


@dataclass(frozen=True)
class EffectSpec:
    """Declared metadata of one effect.

    Besides the physics, the metadata say what the rest of fieldkit does with the
    effect: ``kind`` (:data:`KINDS`), ``changes_rebound`` (it changes the
    restitution pair of an impact, so a target with one constant pair per
    material writes the pair it realises, :mod:`fieldkit.export.lumped`) and
    ``not_from_impacts`` (why an ImpactTable cannot inform it; empty when it can,
    which makes it a candidate of the diagnosis).
    """

    name: str
    stage: str  # "impact" | "flight" | "slide"
    summary: str
    physics: str
    parameters: tuple[Parameter, ...]
    reference: str
    reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()
    kind: str = "law"
    changes_rebound: bool = False
    not_from_impacts: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"{self.name}: kind {self.kind!r} not in {KINDS}")

    @property
    def is_law(self) -> bool:
        """True for a physical law, False for the statistical alternative."""
        return self.kind == "law"

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
