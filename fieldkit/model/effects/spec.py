"""Typed metadata of an effect: :class:`Parameter` and :class:`EffectSpec`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

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
    #: Why an impact fit holds it at the model's value ("" when a table can fit it).
    held: str = ""


#: Export targets whose handling of every law an effect declares
#: (:attr:`EffectSpec.exports`): the lumped-mass programs fieldkit writes files for.
EXPORT_TARGETS = ("CRSP", "RocFall", "RAMMS", "Rockyfor3D", "r.stone")
#: Impact quantities (:attr:`EffectSpec.writes`) that make up the rebound: normal
#: (``e_n``, ``vfn_mps``), tangential and spin.
NORMAL_REBOUND = ("e_n", "vfn_mps")
REBOUND = (*NORMAL_REBOUND, "vft_mps", "omega_f_radps")


@dataclass(frozen=True)
class Export:
    """How one target program takes an effect: ``mapped`` (to what, ``how``) or
    not (``how`` says why)."""

    mapped: bool
    how: str


#: What an effect is: ``"law"``, a physical law with its reference (thesis or
#: literature); ``"alternative"``, a statistical alternative the diagnosis compares
#: the laws with (no target program has it: an export says so).
KINDS = ("law", "alternative")


#: How r.stone takes a law that changes the rebound pair: its only impact law is a
#: constant pair per cell, so the pair is fitted to the model's own impacts.
RSTONE_FOLDED = Export(
    True,
    "r.stone's only impact law is a constant nrest/trest pair per cell "
    "(Bounce, points.c): the rebounds this law makes are folded into the "
    "in-range pair fitted to the calibrated model's own impacts, which no "
    "longer varies as the law makes it",
)


@dataclass(frozen=True)
class EffectSpec:
    """Declared metadata of one effect.

    Besides the physics, the metadata say what the rest of fieldkit does with the
    effect: ``kind`` (:data:`KINDS`), ``changes_rebound`` (it changes the
    restitution pair of an impact, so a target with one constant pair per
    material writes the pair it realises, :mod:`fieldkit.export.lumped`; which
    part of the rebound is in ``writes``, :attr:`changes_normal_rebound`),
    ``not_from_impacts`` (why an ImpactTable cannot inform it; empty when it can,
    which makes it a candidate of the diagnosis), ``exports`` (how each of
    :data:`EXPORT_TARGETS` takes it, read by the exporters; empty for the
    statistical alternative, which no target has) and, per parameter,
    :attr:`Parameter.held` (why an impact fit holds it).
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
    exports: Mapping[str, Export] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"{self.name}: kind {self.kind!r} not in {KINDS}")

    @property
    def changes_normal_rebound(self) -> bool:
        """True when it changes the normal rebound (writes ``e_n`` or ``vfn_mps``):
        a target whose normal law differs cannot take it."""
        return self.changes_rebound and any(w in NORMAL_REBOUND for w in self.writes)

    def export(self, target: str) -> Export | None:
        """How ``target`` takes the effect; None when it is not declared."""
        return self.exports.get(target)

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
