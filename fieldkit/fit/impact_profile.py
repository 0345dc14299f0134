"""Profile-likelihood intervals of an impact fit, beside the Jacobian's.

The Jacobian standard error is the curvature of the sum of squares at the optimum:
exact for a model linear in its parameters, a local approximation otherwise (a
velocity scale ``K`` in ``e_n / (1 + (v/K)^2)``, whose effect fades as ``K`` grows,
is bounded far more tightly below than above). The profile does not linearise: for
a value :math:`v` of parameter :math:`j` the others are refitted by the same
weighted least squares (:meth:`~fieldkit.fit.impact_fit.ImpactProblem.solve`, the
fit's own weights), giving :math:`\\chi^2_j(v)`, and :math:`v` is in the 90 %
interval when

.. math:: \\frac{\\chi^2_j(v) - \\chi^2_{min}}{s^2} \\le F_{0.90}(1, n - p)
          = t_{0.95, n-p}^2, \\qquad s^2 = \\chi^2_{min} / (n - p),

the F-based threshold (Venzon & Moolgavkar 1988; Bates & Watts 1988, §6.1): the
errors' scale is estimated by the reduced chi-square :math:`s^2` (as the Jacobian's
standard errors are scaled by it), so the likelihood-ratio's :math:`\\chi^2_1`
quantile 2.706 becomes that of :math:`F(1, n-p)`, which tends to it for many data.
The Jacobian interval it is compared with is ``value ± t SE`` with the same
:math:`t`: on a linear problem the two agree exactly.

Each end is bracketed by steps of 1, 2, 4, ... Jacobian half-widths outward and
found by Brent's method (:data:`END_XTOL` of the half-width); an end that does not
reach the threshold within the bound (or :data:`MAX_HALF_WIDTHS` half-widths when
the bound is infinite) is the bound (or that limit), marked open.

References
----------
Bates, D. M., Watts, D. G. (1988). Nonlinear Regression Analysis and Its
Applications. Wiley.
Venzon, D. J., Moolgavkar, S. H. (1988). A method for computing
profile-likelihood-based confidence intervals. Appl. Stat. 37(1), 87-94.
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.optimize import brentq
from scipy.stats import t as student_t

#: Relative tolerance (of the Jacobian half-width) of each profile end.
END_XTOL = 1e-3
#: Farthest an end is looked for, in Jacobian half-widths, when the bound is
#: infinite.
MAX_HALF_WIDTHS = 64.0


def profile_intervals(problem, model, names: list[str], values: np.ndarray,
                      stderr: np.ndarray, chi2: float, dof: int) -> dict:  # fmt: skip
    """Profile-likelihood 90 % intervals of ``names`` (module docstring).

    Parameters
    ----------
    problem
        The fit's :class:`~fieldkit.fit.impact_fit.ImpactProblem` (its weights).
    model
        The base model (parameters not in ``names`` at its values).
    names, values, stderr
        The fitted parameters, their values and Jacobian standard errors.
    chi2, dof
        The minimum sum of squares and its residual degrees of freedom.

    Returns
    -------
    dict
        JSON-ready: ``threshold``, ``method``, ``evaluations``, ``wall_s`` and per
        parameter ``interval90``, ``jacobian90``, ``open`` (each end: not reached
        within the bound / limit), ``asymmetry`` (upper over lower half-width) and
        the ``curve`` (value, scaled excess) of the refits.
    """
    t0 = time.perf_counter()
    p = len(names)
    tq = float(student_t.ppf(0.95, dof)) if dof >= 1 else math.nan
    threshold = tq * tq
    scale = chi2 / dof if dof >= 1 and chi2 > 0 else math.nan
    bounds = problem.bounds(model, names)
    count = [0]
    out = []
    for j, name in enumerate(names):
        rest = [k for k in range(p) if k != j]
        others = [names[k] for k in rest]
        curve: dict[float, float] = {float(values[j]): 0.0}

        def excess(v: float, j=j, rest=rest, others=others, curve=curve) -> float:
            fixed = model.with_parameters(
                {**dict(zip(names, map(float, values), strict=True)), names[j]: v}
            )
            start = np.clip(values[rest], bounds[rest, 0], bounds[rest, 1])
            fit = problem.solve(fixed, others, start=start)
            count[0] += 1
            r = np.asarray(fit.fun, float)
            curve[float(v)] = (float(r @ r) - chi2) / scale
            return curve[float(v)] - threshold

        half = tq * stderr[j]
        if not (math.isfinite(half) and half > 0):
            half = 0.1 * max(abs(float(values[j])), 0.1)
        ends, open_ = [], []
        for sign, bound in ((-1.0, bounds[j, 0]), (1.0, bounds[j, 1])):
            inside = float(values[j])
            limit = (
                bound
                if math.isfinite(bound)
                else inside + sign * (MAX_HALF_WIDTHS * half)
            )
            end, reached, k = float(limit), False, 1.0
            while math.isfinite(scale):
                v = inside + sign * k * half
                if sign * (v - limit) >= 0:
                    v = float(limit)
                if excess(v) > 0:
                    end = brentq(excess, inside, v, xtol=END_XTOL * half)
                    reached = True
                    break
                if v == limit:
                    break
                inside, k = v, 2.0 * k
            ends.append(float(end) if math.isfinite(scale) else math.nan)
            open_.append(not reached)
        lo, hi = ends
        jac = [float(values[j] - tq * stderr[j]), float(values[j] + tq * stderr[j])]
        below, above = float(values[j]) - lo, hi - float(values[j])
        grid = sorted(curve)
        out.append({
            "name": name,
            "value": float(values[j]),
            "interval90": [_num(lo), _num(hi)],
            "jacobian90": [_num(jac[0]), _num(jac[1])],
            "open": open_,
            "asymmetry": _num(above / below) if below > 0 else None,
            "curve": {"value": grid, "excess": [_num(curve[v]) for v in grid]},
        })  # fmt: skip
    return {
        "method": (
            "profile likelihood: each parameter fixed, the others refitted by the "
            "same weighted least squares; in the 90 % interval while "
            "(chi2 - chi2_min) / reduced chi2 <= F(0.90; 1, n - p) = t(0.95, n - p)^2"
        ),
        "threshold": _num(threshold),
        "t_quantile": _num(tq),
        "dof": int(dof),
        "max_half_widths": MAX_HALF_WIDTHS,
        "evaluations": count[0],
        "wall_s": time.perf_counter() - t0,
        "parameters": out,
    }


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None
