"""Suspect observations: impacts the reduction flags, flights on an assumed θ0.

Two groups of observed values are suspect (issue 20):

``flagged``
    an impact whose ``qa_flags`` (:data:`fieldkit.impact_table.QA_FLAGS`) carry one
    of :data:`SUSPECT_FLAGS`: the rock left it with more kinetic energy than it
    arrived with, or with more tangential speed. Rounding cannot do that; a survey
    error in one of the two flights that meet at the impact can. In an impact fit
    the datum is the impact's own rebound (the row); in a path fit the values that
    rest on the two flights it joins -- the flight arriving at it (its impact speed
    ``vi_mps`` and the previous point's flight height) and the flight leaving it
    (its flight height ``hmax_normal_m`` and the next point's ``vi_mps``) -- since
    the flag does not tell which flight is wrong.
``assumed_theta0``
    a flight whose launch angle was assumed (``theta0_source == "assumed"`` on its
    launch row: :mod:`fieldkit.reduce.flights`; the first flight from the source
    is the least-speed launch, also assumed), not fixed by a tree strike, a video
    or a given angle. The flight leaving point ``j`` gives ``j``'s normal flight
    height and the impact speed at ``j + 1``; an impact's rebound (impact fit)
    rests on the flight arriving at it and the one leaving it, so it is suspect
    when either is assumed. Impact spacings and runouts are surveyed positions and
    rest on no θ0.

A :class:`SuspectPolicy` says, per group, what a fit does with them
(:class:`Treatment`): keep them (the default), exclude them, or weight them by
``w`` in (0, 1) -- their terms count ``w`` times in the objective (a least-squares
residual's variance divided by ``w``, a CRPS term multiplied by it). A value in
both groups takes both factors.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.impact_table import (
    SUSPECT_FLAGS,
    flag_codes,
    flight_value_markers,
    impact_markers,
)

__all__ = [
    "GROUPS",
    "SUSPECT_FLAGS",
    "SuspectCount",
    "SuspectPolicy",
    "Treatment",
    "count",
    "flag_codes",
    "flight_value_markers",
    "impact_markers",
    "parse_treatment",
    "policy_lines",
]

#: Groups of suspect values -> words.
GROUPS: dict[str, str] = {
    "flagged": "flagged " + " or ".join(SUSPECT_FLAGS),
    "assumed_theta0": "resting on an assumed launch angle θ0",
}


@dataclass(frozen=True)
class Treatment:
    """What a fit does with one group: weight 1 keeps, 0 excludes, else weights.

    Examples
    --------
    >>> Treatment().words, Treatment(0.0).words, Treatment(0.25).words
    ('kept', 'excluded', 'weighted 0.25')
    """

    weight: float = 1.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.weight <= 1.0:
            raise ArgumentError(
                f"a weight must lie in [0, 1] (got {self.weight:g})", source="weight"
            )

    @property
    def keep(self) -> bool:
        """Whether the group is kept as it is."""
        return self.weight == 1.0

    @property
    def exclude(self) -> bool:
        """Whether the group is left out."""
        return self.weight == 0.0

    @property
    def words(self) -> str:
        """``kept``, ``excluded`` or ``weighted w``."""
        if self.keep:
            return "kept"
        return "excluded" if self.exclude else f"weighted {self.weight:g}"

    @property
    def option(self) -> str:
        """The value as given on the command line: keep, exclude or the weight."""
        if self.keep:
            return "keep"
        return "exclude" if self.exclude else f"{self.weight:g}"


KEEP = Treatment(1.0)
EXCLUDE = Treatment(0.0)


def parse_treatment(text: str, argument: str) -> Treatment:
    """``keep``, ``exclude`` or a weight ``w`` in (0, 1) -> :class:`Treatment`.

    Raises
    ------
    ArgumentError
        Anything else, naming ``argument``.

    Examples
    --------
    >>> parse_treatment("exclude", "flagged").words
    'excluded'
    >>> parse_treatment("0.3", "flagged").weight
    0.3
    >>> try:
    ...     parse_treatment("1.5", "flagged")
    ... except ArgumentError as exc:
    ...     print(exc.message)
    expected keep, exclude or a weight in (0, 1) (got '1.5')
    """
    word = str(text).strip().lower()
    if word == "keep":
        return KEEP
    if word == "exclude":
        return EXCLUDE
    try:
        w = float(word)
    except ValueError:
        w = math.nan
    if not 0.0 < w < 1.0:
        raise ArgumentError(
            f"expected keep, exclude or a weight in (0, 1) (got {text!r})",
            source=argument,
        )
    return Treatment(w)


@dataclass(frozen=True)
class SuspectPolicy:
    """Per group (:data:`GROUPS`) what a fit does with its values."""

    flagged: Treatment = KEEP
    assumed_theta0: Treatment = KEEP

    @property
    def is_default(self) -> bool:
        """Whether every group is kept (the fit is the one without a policy)."""
        return self.flagged.keep and self.assumed_theta0.keep

    def treatment(self, group: str) -> Treatment:
        """The treatment of ``group``."""
        return getattr(self, group)

    def factors(self, flags: np.ndarray, assumed: np.ndarray) -> np.ndarray:
        """Weight factor of each value from its markers (``flags`` a bit code over
        :data:`SUSPECT_FLAGS`, ``assumed`` bool): 1 kept, 0 excluded."""
        out = np.ones(np.shape(flags))
        out[np.asarray(flags) > 0] *= self.flagged.weight
        out[np.asarray(assumed, bool)] *= self.assumed_theta0.weight
        return out

    def to_dict(self) -> dict[str, str]:
        """``{"flagged": "keep", "assumed_theta0": "0.5"}``."""
        return {g: self.treatment(g).option for g in GROUPS}


@dataclass
class SuspectCount:
    """How many values of one kind are suspect and what the policy did with them."""

    values: int = 0
    flagged: int = 0
    by_flag: dict[str, int] = field(default_factory=dict)
    assumed_theta0: int = 0
    excluded: int = 0
    weighted: int = 0
    #: Names of the flagged impacts (an impact fit's rows), where known.
    points: list[str] = field(default_factory=list)
    #: Of the excluded values, how many carry each flag.
    excluded_by_flag: dict[str, int] = field(default_factory=dict)

    def add(self, other: SuspectCount) -> None:
        """Add ``other``'s counts to these."""
        self.values += other.values
        self.flagged += other.flagged
        self.assumed_theta0 += other.assumed_theta0
        self.excluded += other.excluded
        self.weighted += other.weighted
        self.points += other.points
        for k, v in other.by_flag.items():
            self.by_flag[k] = self.by_flag.get(k, 0) + v
        for k, v in other.excluded_by_flag.items():
            self.excluded_by_flag[k] = self.excluded_by_flag.get(k, 0) + v

    def to_dict(self) -> dict:
        """JSON-ready counts."""
        return {
            "values": self.values,
            "flagged": self.flagged,
            "by_flag": dict(self.by_flag),
            "assumed_theta0": self.assumed_theta0,
            "excluded": self.excluded,
            "weighted": self.weighted,
            "kept": self.values - self.excluded - self.weighted,
            "flagged_points": list(self.points),
            "excluded_by_flag": dict(self.excluded_by_flag),
        }


def count(
    policy: SuspectPolicy, flags: np.ndarray, assumed: np.ndarray
) -> SuspectCount:
    """The :class:`SuspectCount` of values with these markers under ``policy``.

    Examples
    --------
    >>> c = count(SuspectPolicy(flagged=EXCLUDE), np.array([0, 1, 3, 0]),
    ...           np.array([False, True, False, True]))
    >>> c.to_dict()["by_flag"], c.excluded, c.assumed_theta0
    ({'energy_gained': 2, 'e_t_above_1': 1}, 2, 2)
    """
    flags = np.asarray(flags, np.int64)
    assumed = np.asarray(assumed, bool)
    factor = policy.factors(flags, assumed)
    return SuspectCount(
        values=int(flags.size),
        flagged=int(np.sum(flags > 0)),
        by_flag={
            name: int(np.sum(flags >> bit & 1))
            for bit, name in enumerate(SUSPECT_FLAGS)
        },
        assumed_theta0=int(np.sum(assumed)),
        excluded=int(np.sum(factor == 0.0)),
        weighted=int(np.sum((factor > 0.0) & (factor < 1.0))),
        excluded_by_flag={
            name: int(np.sum((flags >> bit & 1).astype(bool) & (factor == 0.0)))
            for bit, name in enumerate(SUSPECT_FLAGS)
        },
    )


def policy_lines(
    policy: SuspectPolicy,
    counts: Mapping[str, SuspectCount],
    what: str,
    *,
    flights: bool = True,
    arguments: bool = True,
) -> list[str]:
    """One line per group: how many ``what`` (e.g. "impacts", "observed values")
    are suspect and what the fit did with them (argument names in backticks).
    ``flights``: the values rest on the flights of flagged impacts (a path fit),
    not on the impacts themselves (an impact fit). ``arguments``: end each line
    with the argument and its value (for the command line, which names the flag).

    Examples
    --------
    >>> c = {"flight_height_m": SuspectCount(48, 8, {"energy_gained": 6,
    ...      "e_t_above_1": 6}, 33), "speed_mps": SuspectCount(49, 8,
    ...      {"energy_gained": 6, "e_t_above_1": 6}, 34)}
    >>> policy_lines(SuspectPolicy(), c, "observed values")[0]
    'flagged: 16 observed values (flight_height_m 8, speed_mps 8) rest on the \
flights of impacts flagged energy_gained or e_t_above_1 (energy_gained 12, \
e_t_above_1 12): kept (`flagged` keep)'
    >>> c = {"impacts": SuspectCount(48, 4, {"energy_gained": 3, "e_t_above_1": 3},
    ...      43, points=["22", "27", "32", "42"])}
    >>> policy_lines(SuspectPolicy(assumed_theta0=EXCLUDE), c, "impacts",
    ...              flights=False)[1]
    'assumed θ0: 43 impacts rest on an assumed launch angle (of the flight \
arriving or leaving): excluded (`assumed_theta0` exclude)'
    """
    lines = []
    several = len(counts) > 1
    for group in GROUPS:
        n = sum(getattr(c, group) for c in counts.values())
        per = ", ".join(
            f"{k} {getattr(c, group)}" for k, c in counts.items() if getattr(c, group)
        )
        where = f" ({per})" if per and several else ""
        t = policy.treatment(group)
        if group == "flagged":
            by = ", ".join(
                f"{name} {sum(c.by_flag.get(name, 0) for c in counts.values())}"
                for name in SUSPECT_FLAGS
            )
            points = [p for c in counts.values() for p in c.points]
            named = f", points {', '.join(points)}" if points else ""
            head = (
                f"flagged: {n} {what}{where} rest on the flights of impacts flagged "
                f"{' or '.join(SUSPECT_FLAGS)} ({by})"
                if flights
                else f"flagged: {n} {what} flagged ({by}{named})"
            )
        else:
            head = f"assumed θ0: {n} {what}{where} rest on an assumed launch angle"
            if not flights:
                head += " (of the flight arriving or leaving)"
        tail = f" (`{group}` {t.option})" if arguments else ""
        lines.append(f"{head}: {t.words}{tail}")
    return lines
