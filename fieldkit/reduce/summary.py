"""The short printed summary of a reduction (what an engineer checks first).

Restitution coefficients by slope material (mean, standard deviation, count; the way
thesis Table 2-7 and Figs. 5.7-5.8 report them), how each flight was fixed (tree,
given, assumed), the energy budget (kinetic energy lost on impacts against energy
gained in flights, and the potential energy released), how many rows carry each
quality flag (``qa_flags``), the position error the ``*_sd`` columns come from and how
many impacts have an ``e_n`` known to better than :data:`E_N_SD_MEANINGFUL`, and a
warning when the default chord slope moves ``e_n`` by more than that error does.

The impact-mechanics share of the measured loss (thesis §6.3) is a median over the
impacts that lost kinetic energy. It is printed only when it means something
(:func:`theory_verdict`): at least :data:`THEORY_MIN_IMPACTS` such impacts, kinetic
energy gained at no more than :data:`THEORY_MAX_GAINED_SHARE` of the impacts, and the
share outside 0-100 % at no more than :data:`THEORY_MAX_OUTSIDE_SHARE` of them;
otherwise the summary says which condition failed instead of giving a number.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fieldkit.impact_table import QA_FLAGS, ImpactTable
from fieldkit.physics.energy import potential_energy
from fieldkit.reduce.uncertainty import Propagated

#: Fewest impacts with a measured loss for a median share to mean anything.
THEORY_MIN_IMPACTS = 5
#: Largest share of impacts that may have *gained* kinetic energy: beyond it the
#: measured "losses" are dominated by survey error or spin turned into translation.
THEORY_MAX_GAINED_SHARE = 0.25
#: Largest share of the losing impacts whose theory share lies outside 0-100 % (the
#: theory predicts a gain, e.g. e_n > 1, or more than the whole loss): beyond it the
#: velocities do not support the comparison and the median of the rest is cherry-picked.
THEORY_MAX_OUTSIDE_SHARE = 0.25
#: ``e_n_sd`` below which an impact's ``e_n`` is counted as meaningful: e_n spans
#: about 0.1-0.9 on natural slopes (thesis Table 2-7), so a value known to better
#: than 0.1 places the impact in that range; one known to 0.3 does not.
E_N_SD_MEANINGFUL = 0.1


@dataclass(frozen=True)
class MaterialStats:
    """e_n and e_t statistics for one slope material."""

    material: str
    n: int
    e_n_mean: float
    e_n_sd: float
    e_t_mean: float
    e_t_sd: float


@dataclass(frozen=True)
class ReductionSummary:
    """Numbers behind the printed summary (energies in J)."""

    path_ids: tuple[str, ...]
    n_points: int
    n_impacts: int
    flight_sources: dict[str, int]
    by_material: tuple[MaterialStats, ...]
    impact_ke_change_j: float
    flight_ke_gain_j: float
    potential_released_j: float
    rotational_change_j: float
    #: Median over impacts that lost energy of ``theory_loss_fraction`` (thesis §6.3).
    theory_fraction_median: float = float("nan")
    theory_fraction_n: int = 0
    #: The spin entering the theory was estimated (omega = v/r, eq. 3.17), not measured.
    theory_spin_estimated: bool = False
    #: Quartiles of those fractions.
    theory_fraction_quartiles: tuple[float, float] = (float("nan"), float("nan"))
    #: Why the median means nothing here (None: it is printed).
    theory_not_meaningful: str | None = None
    #: Rows carrying each quality flag, in the order of ``QA_FLAGS`` (then others).
    flag_counts: dict[str, int] = field(default_factory=dict)
    #: Impacts whose slope is the chord from the previous point and have e_n.
    chord_impacts: int = 0
    #: Of those, how many move by more than e_n_sd with the chord to the next point.
    slope_sensitive: int = 0
    slope_shift_median: float = float("nan")
    e_n_sd_median: float = float("nan")
    #: Impacts with a finite ``e_n_sd``, and of those how many are below
    #: :data:`E_N_SD_MEANINGFUL`.
    e_n_sd_count: int = 0
    e_n_meaningful: int = 0
    #: How the ``*_sd`` columns were obtained (None: not propagated).
    uncertainty: str | None = None
    #: Flights with no ballistic solution: ``(launch point, reason)`` in path order
    #: (``flight_unsolved``).
    unsolved_flights: tuple[tuple[str, str], ...] = ()
    #: Flights the path has (points less one, per path).
    n_flights: int = 0


#: Unsolved flights named one by one in the summary's warning.
N_UNSOLVED_NAMED = 3


def _sd(values: np.ndarray) -> float:
    return float(np.std(values, ddof=1)) if len(values) > 1 else float("nan")


def theory_verdict(
    fractions: np.ndarray, dke_j: np.ndarray, impacts: int
) -> str | None:
    """Why a median of ``theory_loss_fraction`` would mean nothing, or None.

    ``fractions`` are those of the impacts that lost kinetic energy (finite);
    ``dke_j`` the measured change at every impact; ``impacts`` how many impacts.

    Examples
    --------
    >>> theory_verdict(np.array([0.2, 0.25, 0.3]), np.array([-1.0] * 3), 3)
    'only 3 impacts lost kinetic energy and have a theory value (a median needs 5)'
    >>> theory_verdict(np.full(6, 0.2), np.array([-1.0] * 6), 6) is None
    True
    """
    gained = int(np.sum(dke_j > 0))
    if impacts and gained > THEORY_MAX_GAINED_SHARE * impacts:
        return (
            f"kinetic energy was gained at {gained} of {impacts} impacts (more than "
            f"{THEORY_MAX_GAINED_SHARE:.0%}): survey error or spin turned into "
            "translation dominates the measured losses"
        )
    n = len(fractions)
    if n < THEORY_MIN_IMPACTS:
        return (
            f"only {n} impact{'' if n == 1 else 's'} lost kinetic energy and "
            f"{'has' if n == 1 else 'have'} a theory value (a median needs "
            f"{THEORY_MIN_IMPACTS})"
        )
    outside = int(np.sum((fractions < 0) | (fractions > 1)))
    if outside > THEORY_MAX_OUTSIDE_SHARE * n:
        return (
            f"at {outside} of the {n} impacts that lost kinetic energy the theory "
            f"share lies outside 0-100 % (from {100 * fractions.min():.0f} % to "
            f"{100 * fractions.max():.0f} %): the theory predicts a gain (e_n > 1) or "
            "more than the whole loss there, so these velocities do not support the "
            "comparison"
        )
    return None


def summarize(
    table: ImpactTable, uncertainty: Propagated | None = None
) -> ReductionSummary:
    """Statistics of a reduced table.

    ``impact_ke_change_j`` sums ``dke_j`` over impacts (negative = lost);
    ``flight_ke_gain_j`` sums ``flight_dke_j``; ``potential_released_j`` is
    ``m g (z_first - z_last)`` per path. ``uncertainty`` (from
    :func:`fieldkit.reduce.pipeline.reduce_path`) says how the ``*_sd`` columns were
    obtained.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> frame = pd.DataFrame({"path_id": "A", "point": ["1", "2"], "x_m": [0.0, 1.0],
    ...     "z_m": [0.0, -1.0], "slope_deg": [0.0, 45.0], "vi_x_mps": [np.nan, 3.0],
    ...     "vi_z_mps": [np.nan, -4.0], "vf_x_mps": [3.0, 2.0], "vf_z_mps": [0.0, 1.0]})
    >>> s = summarize(ImpactTable(frame).derive())
    >>> s.n_impacts, s.by_material[0].material
    (1, 'unknown')
    """
    f = table.frame
    impacts = f[
        np.isfinite(f["e_n"].to_numpy(float)) | np.isfinite(f["e_t"].to_numpy(float))
    ]
    material = impacts["material"].astype("string").fillna("unknown")
    stats = []
    for name in dict.fromkeys(material.tolist()):
        part = impacts[material == name]
        en = part["e_n"].to_numpy(float)
        et = part["e_t"].to_numpy(float)
        en, et = en[np.isfinite(en)], et[np.isfinite(et)]
        stats.append(
            MaterialStats(
                str(name),
                len(part),
                float(np.mean(en)),
                _sd(en),
                float(np.mean(et)),
                _sd(et),
            )
        )
    sources = f["theta0_source"].dropna().value_counts()
    unsolved: tuple[tuple[str, str], ...] = ()
    if "flight_unsolved" in f:
        rows = f[f["flight_unsolved"].notna()]
        unsolved = tuple(
            (str(p), str(r))
            for p, r in zip(rows["point"], rows["flight_unsolved"], strict=True)
        )
    flight_sources = {str(k): int(v) for k, v in sources.items()}
    if unsolved:
        flight_sources["unsolved"] = len(unsolved)
    potential = 0.0
    for _, path in f.groupby("path_id", sort=False):
        m = path["mass_kg"].to_numpy(float)[0]
        z = path["z_m"].to_numpy(float)
        potential += float(potential_energy(m, z[0] - z[-1]))
    re_change = np.nansum(f["re_f_j"].to_numpy(float) - f["re_i_j"].to_numpy(float))
    fraction = np.array([], dtype=float)
    dke = impacts["dke_j"].to_numpy(float)
    verdict = None
    if "theory_loss_fraction" in impacts:
        theory = impacts["theory_loss_fraction"].to_numpy(float)
        fraction = theory[(dke < 0) & np.isfinite(theory)]
        if np.isfinite(theory).any():
            verdict = theory_verdict(fraction, dke[np.isfinite(dke)], len(impacts))
    flags = _flag_counts(f)
    chord = np.zeros(len(impacts), dtype=bool)
    if "slope_source" in impacts:
        chord = impacts["slope_source"].eq("chord").fillna(False).to_numpy(bool)
    chord &= np.isfinite(impacts["e_n"].to_numpy(float))
    shift = sd = np.array([], dtype=float)
    if "e_n_next_chord" in impacts:
        shift = np.abs(impacts["e_n_next_chord"] - impacts["e_n"]).to_numpy(float)
        shift = shift[chord & np.isfinite(shift)]
    all_sd = np.array([], dtype=float)
    if "e_n_sd" in impacts:
        sd = impacts["e_n_sd"].to_numpy(float)[chord]
        sd = sd[np.isfinite(sd)]
        all_sd = impacts["e_n_sd"].to_numpy(float)
        all_sd = all_sd[np.isfinite(all_sd) & np.isfinite(impacts["e_n"])]
    return ReductionSummary(
        path_ids=tuple(str(p) for p in table.paths()),
        n_points=len(f),
        n_impacts=len(impacts),
        flight_sources=flight_sources,
        by_material=tuple(stats),
        impact_ke_change_j=float(np.nansum(f["dke_j"].to_numpy(float))),
        flight_ke_gain_j=float(np.nansum(f["flight_dke_j"].to_numpy(float)))
        if "flight_dke_j" in f
        else float("nan"),
        potential_released_j=float(potential),
        rotational_change_j=float(re_change),
        theory_fraction_median=float(np.median(fraction)) if len(fraction) else np.nan,
        theory_fraction_n=len(fraction),
        theory_spin_estimated=bool(
            "omega_source" in f and f["omega_source"].eq("estimated").any()
        ),
        theory_fraction_quartiles=(
            (float(np.percentile(fraction, 25)), float(np.percentile(fraction, 75)))
            if len(fraction)
            else (np.nan, np.nan)
        ),
        theory_not_meaningful=verdict,
        flag_counts=flags,
        chord_impacts=int(chord.sum()),
        slope_sensitive=int(
            impacts["qa_flags"].str.contains("slope_sensitive").fillna(False).sum()
        ),
        slope_shift_median=float(np.median(shift)) if len(shift) else np.nan,
        e_n_sd_median=float(np.median(sd)) if len(sd) else np.nan,
        e_n_sd_count=len(all_sd),
        e_n_meaningful=int(np.sum(all_sd < E_N_SD_MEANINGFUL)),
        uncertainty=None if uncertainty is None else uncertainty.describe(),
        unsolved_flights=unsolved,
        n_flights=len(f) - f["path_id"].nunique(),
    )


def _flag_counts(frame) -> dict[str, int]:
    """Rows carrying each flag of ``qa_flags``: QA_FLAGS order, then others."""
    counts: dict[str, int] = {}
    for text in frame["qa_flags"].dropna():
        for name in str(text).split(";"):
            if name:
                counts[name] = counts.get(name, 0) + 1
    order = [name for name in QA_FLAGS if name in counts]
    order += sorted(name for name in counts if name not in QA_FLAGS)
    return {name: counts[name] for name in order}


def format_summary(summary: ReductionSummary) -> str:
    """The summary as a few aligned lines of text (energies in kJ)."""
    lines = [
        f"path {', '.join(summary.path_ids)}: {summary.n_points} points, "
        f"{summary.n_impacts} impacts; flights fixed by "
        + ", ".join(f"{k} {v}" for k, v in sorted(summary.flight_sources.items())),
        f"{'material':<12} {'n':>3}  {'e_n mean':>8} {'sd':>5}  "
        f"{'e_t mean':>8} {'sd':>5}",
    ]
    for s in summary.by_material:
        lines.append(
            f"{s.material:<12} {s.n:>3}  {s.e_n_mean:8.2f} {s.e_n_sd:5.2f}  "
            f"{s.e_t_mean:8.2f} {s.e_t_sd:5.2f}"
        )
    if np.isfinite(summary.potential_released_j) and summary.potential_released_j:
        change = summary.impact_ke_change_j / 1e3
        verb = "lost on impacts" if change <= 0 else "GAINED on impacts"
        lines += [
            f"energy: {verb} {abs(change):,.0f} kJ, "
            f"gained in flights {summary.flight_ke_gain_j / 1e3:,.0f} kJ, "
            f"potential released {summary.potential_released_j / 1e3:,.0f} kJ",
        ]
    else:
        lines.append("energy: no mass given (`mass_kg` or `shape`), energies left out")
    if summary.theory_not_meaningful is not None:
        lines.append(
            "impact mechanics against the measured KE loss (thesis §6.3): no median "
            f"given, {summary.theory_not_meaningful}; see theory_loss_fraction per "
            "impact"
        )
    elif summary.theory_fraction_n:
        q1, q3 = summary.theory_fraction_quartiles
        lines.append(
            "impact mechanics explains a median "
            f"{100 * summary.theory_fraction_median:.0f} % (quartiles "
            f"{100 * q1:.0f}-{100 * q3:.0f} %) of the measured KE loss, median over "
            f"the {summary.theory_fraction_n} of {summary.n_impacts} impacts that "
            "lost kinetic energy and have a theory value (thesis §6.3 finds ~20-30 %; "
            "see theory_loss_fraction)"
        )
        if summary.theory_spin_estimated:
            lines.append(
                "  (spin estimated as v/r: a rolling body slips little, so friction "
                "loss is a lower bound)"
            )
    if summary.uncertainty is not None:
        median = (
            f"; median e_n_sd {summary.e_n_sd_median:.2f}"
            if np.isfinite(summary.e_n_sd_median)
            else ""
        )
        lines.append(f"uncertainty: {summary.uncertainty}{median}")
        if summary.e_n_sd_count:
            lines.append(
                f"  e_n is known to better than {E_N_SD_MEANINGFUL:g} (e_n_sd) at "
                f"{summary.e_n_meaningful} of {summary.e_n_sd_count} impacts; "
                "weigh the others by their e_n_sd"
            )
    if summary.flag_counts:
        lines.append(
            "quality flags (qa_flags; meanings in fieldkit.impact_table.QA_FLAGS): "
            + ", ".join(f"{k} {v}" for k, v in summary.flag_counts.items())
        )
    if summary.unsolved_flights:
        lines.append(unsolved_warning(summary))
    if summary.slope_sensitive:
        lines.append(
            f"warning: at {summary.slope_sensitive} of {summary.chord_impacts} impacts "
            "whose slope is the chord from the previous point, the chord to the next "
            "point moves e_n by more than its standard uncertainty e_n_sd (median "
            f"|change| {summary.slope_shift_median:.2f}, median e_n_sd "
            f"{summary.e_n_sd_median:.2f}): there e_n rests on the slope assumed more "
            "than on the survey; survey the ground slope at the impacts (a slope_deg "
            "column) to settle it"
        )
    return "\n".join(lines)


def unsolved_warning(summary: ReductionSummary) -> str:
    """One ``warning:`` line: how many flights were left unsolved, the first few
    launch points, the first reason, and what that means for fit and diagnose."""
    unsolved = summary.unsolved_flights
    k = len(unsolved)
    points = ", ".join(point for point, _ in unsolved[:N_UNSOLVED_NAMED])
    if k > N_UNSOLVED_NAMED:
        points += f" and {k - N_UNSOLVED_NAMED} more"
    return (
        f"warning: {k} of {summary.n_flights} flights {'has' if k == 1 else 'have'} no "
        f"ballistic solution and {'was' if k == 1 else 'were'} left unsolved "
        f"(leaving point{'' if k == 1 else 's'} {points}; "
        f"{'the' if k == 1 else 'first'} reason: {unsolved[0][1]}): the rebound at "
        "the launch point and the impact at the arrival point are unknown "
        "(flight_unsolved column), so those rows are not impacts for fit and "
        "diagnose"
    )
