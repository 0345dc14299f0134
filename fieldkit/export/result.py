"""What an export produces: the target's files and the account of the translation.

The simulators fieldkit exports to do not share one physics, so every export says
what it did: each fieldkit quantity and the target field it went to
(:class:`Mapped`), what could not be mapped and why, the unit conversions, and the
residual mismatch where a category or class had to be chosen. :meth:`Export.readme`
writes that account as the ``README.md`` beside the files.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Mapped:
    """One fieldkit quantity and where it went in the target.

    Attributes
    ----------
    fieldkit
        The quantity and its value, e.g. ``"materials.talus.e_n = 0.42 ± 0.03"``.
    target
        The target's field, e.g. ``"talus material: Rn (normal, mean 0.42, sd 0.04)"``.
    note
        How (a formula, a convention), or "".
    """

    fieldkit: str
    target: str
    note: str = ""


@dataclass
class Export:
    """A target's files (relative path -> text or bytes) and the translation account.

    ``translation`` holds the README lines (markdown) of the translation error --
    the calibrated model against fieldkit's emulation of the exported values under
    the target's own law; ``sources`` the documents each of the target's rules
    comes from (repository + path, or page title), one per line; ``unconfirmed``
    what those sources leave open, listed once.

    Examples
    --------
    >>> e = Export("demo", "Demo simulator", {"a.txt": "1\\n"},
    ...            mapped=[Mapped("materials.rock.e_n = 0.5", "Rn 0.5")],
    ...            unmapped=[("air_drag", "no drag in Demo")],
    ...            units=["lengths in feet (1 ft = 0.3048 m)"])
    >>> text = e.readme("model.json")
    >>> "| materials.rock.e_n = 0.5 | Rn 0.5 |" in text, "air_drag" in text
    (True, True)
    """

    target: str
    title: str
    files: dict[str, str | bytes]
    mapped: list[Mapped] = field(default_factory=list)
    unmapped: list[tuple[str, str]] = field(default_factory=list)
    units: list[str] = field(default_factory=list)
    mismatches: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    how_to_use: str = ""
    translation: list[str] = field(default_factory=list)
    sources: list[str] = field(default_factory=list)
    unconfirmed: list[str] = field(default_factory=list)

    def readme(self, model_source: str) -> str:
        """The ``README.md`` written beside the files."""
        lines = [
            f"# {self.title}: inputs from fieldkit",
            "",
            f"Exported by `fieldkit export --to {self.target}` from `{model_source}`.",
            "",
            "## Files",
            "",
        ]
        lines += [f"* `{name}`" for name in sorted(self.files)]
        if self.how_to_use:
            lines += ["", "## How to use them", "", self.how_to_use.strip()]
        lines += ["", "## What was mapped to what", ""]
        if self.mapped:
            lines += ["| fieldkit | target | how |", "|---|---|---|"]
            lines += [
                f"| {m.fieldkit} | {m.target} | {m.note} |".replace("|  |", "| |")
                for m in self.mapped
            ]
        else:
            lines.append("Nothing.")
        lines += ["", "## What could not be mapped, and why", ""]
        lines += [f"* **{what}**: {why}" for what, why in self.unmapped] or [
            "Everything in the model was mapped."
        ]
        lines += ["", "## Units", ""]
        lines += [f"* {u}" for u in self.units] or ["* SI throughout (m, kg, s)."]
        lines += ["", "## Residual mismatch where a class or category was chosen", ""]
        lines += [f"* {m}" for m in self.mismatches] or [
            "* None: every value was written as calibrated."
        ]
        if self.translation:
            lines += [
                "",
                "## Translation error: calibrated model vs the target's law",
                "",
            ]
            lines += self.translation
        if self.sources:
            lines += ["", "## Sources of the target's rules", ""]
            lines += [f"* {s}" for s in self.sources]
        if self.unconfirmed:
            lines += ["", "## Unconfirmed", ""]
            lines += [f"* {u}" for u in self.unconfirmed]
        if self.notes:
            lines += ["", "## Notes", ""]
            lines += [f"* {n}" for n in self.notes]
        return "\n".join(lines) + "\n"
