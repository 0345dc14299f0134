"""The short printed summary of a reduction (what an engineer checks first).

Restitution coefficients by slope material (mean, standard deviation, count; the way
thesis Table 2-7 and Figs. 5.7-5.8 report them), how each flight was fixed (tree,
given, assumed), and the energy budget: kinetic energy lost on impacts against energy
gained in flights, and the potential energy released.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fieldkit.impact_table import ImpactTable
from fieldkit.physics.energy import potential_energy


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


def _sd(values: np.ndarray) -> float:
    return float(np.std(values, ddof=1)) if len(values) > 1 else float("nan")


def summarize(table: ImpactTable) -> ReductionSummary:
    """Statistics of a reduced table.

    ``impact_ke_change_j`` sums ``dke_j`` over impacts (negative = lost);
    ``flight_ke_gain_j`` sums ``flight_dke_j``; ``potential_released_j`` is
    ``m g (z_first - z_last)`` per path.

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
    potential = 0.0
    for _, path in f.groupby("path_id", sort=False):
        m = path["mass_kg"].to_numpy(float)[0]
        z = path["z_m"].to_numpy(float)
        potential += float(potential_energy(m, z[0] - z[-1]))
    re_change = np.nansum(f["re_f_j"].to_numpy(float) - f["re_i_j"].to_numpy(float))
    fraction = np.array([], dtype=float)
    if "theory_loss_fraction" in f:
        lost = f["dke_j"].to_numpy(float) < 0
        fraction = f["theory_loss_fraction"].to_numpy(float)[lost]
        fraction = fraction[np.isfinite(fraction)]
    return ReductionSummary(
        path_ids=tuple(str(p) for p in table.paths()),
        n_points=len(f),
        n_impacts=len(impacts),
        flight_sources={str(k): int(v) for k, v in sources.items()},
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
    )


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
    if summary.theory_fraction_n:
        lines.append(
            "impact mechanics explains a median "
            f"{100 * summary.theory_fraction_median:.0f} % of the measured KE loss "
            f"({summary.theory_fraction_n} impacts; thesis §6.3 finds ~20-30 %; "
            "see theory_loss_fraction)"
        )
        if summary.theory_spin_estimated:
            lines.append(
                "  (spin estimated as v/r: a rolling body slips little, so friction "
                "loss is a lower bound)"
            )
    return "\n".join(lines)
