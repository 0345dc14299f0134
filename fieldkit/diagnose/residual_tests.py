"""Do the residuals depend on a feature? A test, not eyeballing.

For every feature the table carries (impact angle, normal, tangential and total
impact speed, measured spin, chainage, material, tree strike, body size) and every
residual component (``vfn``, ``vft``, ``omega_f``), the standardised held-out
residuals are tested for dependence:

* continuous features: Spearman's rank correlation (monotone trends) and a
  Kruskal-Wallis test across quintile bins (trends that turn, e.g. a U shape);
  the smaller p-value, doubled (Bonferroni over the two);
* categorical features (material, tree strike): Kruskal-Wallis across the
  categories that hold at least :data:`MIN_PER_GROUP` residuals.

All p-values of one residual set are corrected together by Holm's step-down
method (family-wise error :data:`ALPHA`), so a table without structure is reported
as such in about 1 - ALPHA of cases. Impacts of one rock are treated as
independent here (the cross-validation is not), which makes the tests somewhat
liberal on real surveys with few paths; the report says so.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from fieldkit.diagnose.diagnosis import Dependence

#: Family-wise error rate of the dependence tests.
ALPHA = 0.01
#: Least residuals per category (or bin) for a group to enter a test.
MIN_PER_GROUP = 5
#: Quantile bins of the Kruskal-Wallis test on a continuous feature.
BINS = 5
#: Residual components, in the order of the (n, 3) residual arrays.
COMPONENTS = ("vfn", "vft", "omega_f")


def impact_features(frame: pd.DataFrame, spin_measured: np.ndarray) -> dict:
    """Feature name -> values (float array, or object array for categories).

    Only features the table carries and that vary are returned.
    """
    out: dict[str, np.ndarray] = {}

    def num(name: str, values=None) -> None:
        if values is None:
            if name not in frame:
                return
            values = pd.to_numeric(frame[name], errors="coerce").to_numpy(float)
        v = np.asarray(values, float)
        finite = v[np.isfinite(v)]
        if finite.size >= 2 * MIN_PER_GROUP and np.ptp(finite) > 0:
            out[name] = v

    num("theta_i_deg")
    if "vin_mps" in frame:
        num("vin_mps", np.abs(frame["vin_mps"].to_numpy(float)))
    num("vit_mps")
    num("vi_mps")
    if "omega_i_radps" in frame:
        spin = frame["omega_i_radps"].to_numpy(float).copy()
        spin[~spin_measured] = np.nan
        num("omega_i_radps", spin)
    num("x_m")
    num("radius_m")
    num("mass_kg")
    for name in ("material", "tree_strike"):
        if name in frame:
            labels = frame[name].astype("string").fillna("").to_numpy(object)
            if len(set(labels) - {""}) >= 2:
                out[name] = labels
    return out


def why_untested(values: np.ndarray) -> str:
    """Why a feature of :func:`impact_features` entered no test (in words).

    Examples
    --------
    >>> why_untested(np.array(["rock", "rock", "till"] + ["colluvium"] * 9, object))
    'the test needs two categories of at least 5 impacts (colluvium 9, rock 2, till 1)'
    """
    if values.dtype == object:
        names = sorted(set(values) - {""})
        counts = ", ".join(f"{c} {int((values == c).sum())}" for c in names)
        return (
            f"the test needs two categories of at least {MIN_PER_GROUP} impacts "
            f"({counts})"
        )
    return f"fewer than {2 * MIN_PER_GROUP} impacts with a value and a residual"


def dependence_tests(
    residuals: np.ndarray, features: dict[str, np.ndarray]
) -> list[Dependence]:
    """Holm-corrected tests of each residual column against each feature.

    ``residuals`` is ``(n, k)`` standardised residuals (NaN = no datum), columns
    named by :data:`COMPONENTS`.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> x = rng.uniform(0, 1, 200)
    >>> r = np.column_stack([x + rng.normal(0, 0.3, 200), rng.normal(size=200)])
    >>> [(d.feature, d.component) for d in dependence_tests(r, {"x": x})
    ...  if d.significant]
    [('x', 'vfn')]
    """
    results: list[Dependence] = []
    for j in range(residuals.shape[1]):
        r = residuals[:, j]
        for name, values in features.items():
            test = _test(r, values)
            if test is not None:
                stat, p, method = test
                results.append(
                    Dependence(name, COMPONENTS[j], stat, p, False, p_method=method)
                )
    return _holm(results)


#: What the p-value of a continuous feature's test is.
COMBINED_P = (
    "continuous features: the smaller of the Spearman and the binned "
    "Kruskal-Wallis p, doubled (Bonferroni over the two)"
)


def _test(r: np.ndarray, values: np.ndarray) -> tuple[str, float, str] | None:
    if values.dtype == object:
        ok = np.isfinite(r) & (values != "")
        groups = [r[ok & (values == g)] for g in sorted(set(values[ok]))]
        groups = [g for g in groups if g.size >= MIN_PER_GROUP]
        if len(groups) < 2:
            return None
        h, p = stats.kruskal(*groups)
        return (
            f"Kruskal-Wallis H = {h:.3g} over {len(groups)} groups",
            float(p),
            "categories: Kruskal-Wallis across the groups",
        )
    ok = np.isfinite(r) & np.isfinite(values)
    if ok.sum() < 2 * MIN_PER_GROUP or np.ptp(values[ok]) == 0:
        return None
    rho, p_rho = stats.spearmanr(values[ok], r[ok])
    edges = np.unique(np.quantile(values[ok], np.linspace(0, 1, BINS + 1)))
    bins = np.clip(np.searchsorted(edges, values[ok], side="right") - 1, 0, None)
    groups = [r[ok][bins == b] for b in np.unique(bins)]
    groups = [g for g in groups if g.size >= MIN_PER_GROUP]
    p_kw = float(stats.kruskal(*groups).pvalue) if len(groups) >= 2 else 1.0
    p = min(1.0, 2.0 * min(float(p_rho), p_kw))
    return (
        f"Spearman rho = {rho:+.2f}; Spearman p = {float(p_rho):.2g}; "
        f"Kruskal-Wallis over {len(groups)} quantile bins p = {p_kw:.2g}",
        p,
        COMBINED_P,
    )


def holm(p_values, alpha: float = ALPHA) -> np.ndarray:
    """Holm's step-down: which of ``p_values`` are significant at family-wise
    ``alpha`` (the k-th smallest needs ``p <= alpha / (m - k)``, and every smaller
    one before it).

    Examples
    --------
    >>> holm([0.001, 0.04, 0.02], alpha=0.05).tolist()
    [True, True, True]
    >>> holm([0.001, 0.04, 0.03], alpha=0.05).tolist()
    [True, False, False]
    """
    p = np.asarray(p_values, float)
    order = np.argsort(p, kind="stable")
    passed = p[order] <= alpha / (p.size - np.arange(p.size))
    out = np.zeros(p.size, bool)
    out[order] = np.logical_and.accumulate(passed)
    return out


def holm_adjusted(p_values) -> np.ndarray:
    """Holm-adjusted p-values: the k-th smallest times ``m - k`` (k from 0), made
    non-decreasing and capped at 1. A test is significant at family-wise ``alpha``
    exactly when its adjusted p is at most ``alpha`` (the decision :func:`holm`
    makes; these are what a report prints).

    Examples
    --------
    >>> holm_adjusted([0.001, 0.04, 0.03]).round(3).tolist()
    [0.003, 0.06, 0.06]
    """
    p = np.asarray(p_values, float)
    order = np.argsort(p, kind="stable")
    scaled = p[order] * (p.size - np.arange(p.size))
    out = np.empty(p.size)
    out[order] = np.minimum(np.maximum.accumulate(scaled), 1.0)
    return out


def mark_holm(results: list[Dependence], alpha: float) -> list[Dependence]:
    """Set each test's significance (Holm's step-down at ``alpha``), its adjusted p
    and the level, in place; returns ``results``."""
    p = [d.p_value for d in results]
    for d, flag, adjusted in zip(
        results, holm(p, alpha), holm_adjusted(p), strict=True
    ):
        d.significant = bool(flag)
        d.p_holm = float(adjusted)
        d.alpha = alpha
    return results


def _holm(results: list[Dependence]) -> list[Dependence]:
    """Mark significance by Holm's step-down at :data:`ALPHA`."""
    return mark_holm(results, ALPHA)


def describe(dependences: list[Dependence]) -> list[str]:
    """One sentence per significant dependence, strongest first."""
    hits = sorted((d for d in dependences if d.significant), key=lambda d: d.p_value)
    return [
        f"{d.component} residuals depend on {d.feature} ({d.statistic}; "
        f"raw p = {d.p_value:.2g}, Holm-adjusted p = {d.p_holm:.2g} <= {d.alpha:g})"
        for d in hits
    ]
