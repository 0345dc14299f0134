"""`fieldkit fit` options for suspect data (issue 20): ``--flagged``,
``--assumed-theta0`` and ``--no-leave-out``, and what the fit says about them.

Glue only: the policy and the leave-out refits are :mod:`fieldkit.fit.suspect`
and :mod:`fieldkit.fit.leave_out`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
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


def suspect_markdown(lines: Sequence[str]) -> str:
    """The report's section on suspect data."""
    return "\n## Suspect data\n\n```\n" + "\n".join(lines) + "\n```\n"
