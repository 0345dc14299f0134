"""`fieldkit fit` options for suspect data (issue 20): ``--flagged``,
``--assumed-theta0`` and ``--no-leave-out``, and what the fit says about them.

Glue only: the policy and the leave-out refits are :mod:`fieldkit.fit.suspect`
and :mod:`fieldkit.fit.leave_out`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Annotated

import typer

from fieldkit.cli.common import with_flags

#: Option names -> flags (merged into ``fieldkit fit``'s FLAGS).
SUSPECT_FLAGS = {
    "flagged": "--flagged",
    "assumed_theta0": "--assumed-theta0",
    "leave_out": "--no-leave-out",
}

FlaggedOpt = Annotated[
    str,
    typer.Option(
        "--flagged",
        help="Impacts the reduction flags energy_gained or e_t_above_1 (a path "
        "fit: the flight heights and speeds of the two flights each joins): "
        "'keep' (default), 'exclude' or a weight in (0, 1).",
    ),
]
AssumedOpt = Annotated[
    str,
    typer.Option(
        "--assumed-theta0",
        help="Flights on an assumed launch angle θ0 (theta0_source 'assumed'; an "
        "impact fit: impacts either of whose flights is): 'keep' (default), "
        "'exclude' or a weight in (0, 1).",
    ),
]
LeaveOutOpt = Annotated[
    bool,
    typer.Option(
        "--leave-out/--no-leave-out",
        help="Refit without the flagged impacts and without the assumed-θ0 "
        "flights and report how the parameters move (default on; a path fit "
        "costs about two more searches).",
    ),
]


def suspect_policy(flagged: str, assumed_theta0: str):
    """The :class:`~fieldkit.fit.suspect.SuspectPolicy` of the two options
    (one-line errors naming the option)."""
    from fieldkit.fit.suspect import SuspectPolicy, parse_treatment

    return SuspectPolicy(
        flagged=parse_treatment(flagged, "flagged"),
        assumed_theta0=parse_treatment(assumed_theta0, "assumed_theta0"),
    )


def suspect_record(policy, counts: Mapping, leave_outs: Sequence, lines) -> dict:
    """The fit's JSON ``suspect`` entry."""
    return {
        "policy": policy.to_dict(),
        "counts": {k: c.to_dict() for k, c in counts.items()},
        "statement": list(lines),
        "leave_out": [lo.to_dict() for lo in leave_outs],
    }


def suspect_lines(
    policy, counts: Mapping, what: str, leave_outs: Sequence | None, *, how: str
) -> list[str]:
    """What the fit did with suspect data, then the leave-out table (flags named);
    ``leave_outs`` None: skipped by ``--no-leave-out``."""
    from fieldkit.fit.leave_out import leave_out_lines
    from fieldkit.fit.suspect import policy_lines

    flags = dict(SUSPECT_FLAGS)
    if not counts:
        lines = [
            "suspect data: the observations carry no quality flags or launch "
            "angles (runs from release and deposit points): nothing to weight or "
            "leave out"
        ]
        return lines
    lines = [
        f"suspect data: {with_flags(line, flags)}"
        for line in policy_lines(policy, counts, what, flights=what != "impacts")
    ]
    if leave_outs is None:
        lines.append("leave-out refits skipped (--no-leave-out)")
        return lines
    lines.append(
        f"leave-out refits ({how}; value (shift from the full fit, in its standard "
        "errors); --no-leave-out skips them):"
    )
    return lines + leave_out_lines(leave_outs)


#: Suspect flags and groups in words (report.md).
FLAG_WORDS = {"energy_gained": "kinetic energy gained", "e_t_above_1": "e_T > 1"}
GROUP_WORDS = {
    "flagged": ("the flights of impacts flagged", "--flagged"),
    "assumed_theta0": ("flights on an assumed launch angle θ0", "--assumed-theta0"),
}


def suspect_markdown(
    record: dict, kind_words: Mapping[str, str], parameter_words: Callable[[str], str]
) -> str:
    """The report's section on suspect data (:func:`suspect_record`), in words:
    kinds by ``kind_words``, parameters by ``parameter_words(name)``."""

    def kinds(counts: dict) -> str:
        return "; ".join(f"{kind_words.get(k, k)}: {n}" for k, n in counts.items() if n)

    lines = ["", "## Suspect data", ""]
    counts = record["counts"]
    if not counts:
        return "\n".join(lines + [
            "The observations carry no quality flags or launch angles: nothing to "
            "weight or leave out.", "",
        ])  # fmt: skip
    for group, (words, flag) in GROUP_WORDS.items():
        per = {k: c[group] for k, c in counts.items()}
        option = record["policy"][group]
        done = {"keep": "kept", "exclude": "excluded"}.get(option, f"weighted {option}")
        extra = ""
        if group == "flagged":
            by = {f: sum(c["by_flag"].get(f, 0) for c in counts.values())
                  for f in FLAG_WORDS}  # fmt: skip
            extra = " (" + ", ".join(f"{FLAG_WORDS[f]}: {n}" for f, n in by.items())
            points = [p for c in counts.values() for p in c["flagged_points"]]
            extra += f"; points {', '.join(points)})" if points else ")"
        impacts = "impacts" in counts
        what = "impacts" if impacts else "observed values"
        per_kind = "" if impacts or not any(per.values()) else f" ({kinds(per)})"
        lines.append(
            f"* {sum(per.values())} {what}{per_kind} "
            f"{'flagged' if impacts and group == 'flagged' else 'rest on ' + words}"
            f"{extra}: "
            f"{done} ({flag} {option})."
        )
    leave = record["leave_out"]
    if not leave:
        return "\n".join(lines + ["", "No leave-out refits (--no-leave-out).", ""])
    lines += [
        "",
        "Leave-out refits: the fit repeated without each group (a search from the "
        "calibrated values); in brackets the shift from the full fit and, where it "
        "has one, in its standard errors.",
        "",
        "| parameter | full fit | " + " | ".join(v["variant"] for v in leave) + " |",
        "|---" * (2 + len(leave)) + "|",
    ]
    for j, p in enumerate(leave[0]["parameters"]):
        cells = []
        for v in leave:
            q = v["parameters"][j]
            if not v["refitted"]:
                cells.append("not refitted")
            elif q["name"] in v["held"]:
                cells.append(f"{q['refitted']:.4g} (held)")
            else:
                z = q["shift_in_stderr"]
                se = f", {z + 0.0:+.1f} SE" if z is not None else ""
                cells.append(f"{q['refitted']:.4g} ({q['shift'] + 0.0:+.3g}{se})")
        lines.append(
            f"| {parameter_words(p['name'])} | {p['full']:.4g} | "
            + " | ".join(cells) + " |"
        )  # fmt: skip
    lines.append("")
    for v in leave:
        dropped = kinds(v["dropped"]) if "impacts" not in v["dropped"] else ""
        text = f"* {v['variant']}: dropped {sum(v['dropped'].values())}"
        text += f" ({dropped})" if dropped else ""
        if v["note"]:
            text += f"; {v['note']}"
        if v["reason"]:
            text += f"; not refitted: {v['reason']}"
        lines.append(text + ".")
    return "\n".join(lines) + "\n"
