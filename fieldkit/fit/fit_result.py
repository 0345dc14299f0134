"""The result of a fit, in lmfit's vocabulary, and its plain-text report.

Values, standard errors from the Jacobian (``(J^T W J)^-1`` scaled by the reduced
chi-square, lmfit's ``scale_covar=True``), correlation matrix, ``chi2``, ``redchi``,
``aic = n ln(chi2/n) + 2 p``, ``bic = n ln(chi2/n) + p ln n`` (lmfit's definitions),
the number of data ``n`` and of parameters ``p``, and the optimiser's success flag
and message. :meth:`FitResult.report` flags parameters at a bound, not identifiable
(standard error not finite or larger than :data:`HUGE_SE_RATIO` times the value's
size, or ``|corr| >`` :data:`CORRELATION_LIMIT` with another parameter) or unchanged
from the start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: |correlation| above which a pair of parameters is flagged as not identifiable.
CORRELATION_LIMIT = 0.98
#: A standard error above this times max(|value|, 1e-3) is "huge".
HUGE_SE_RATIO = 1.0
#: Relative distance to a bound under which a value is "at the bound".
BOUND_TOLERANCE = 1e-6


@dataclass
class FitResult:
    """Fitted parameters and their statistics (see the module docstring)."""

    names: list[str]
    values: np.ndarray
    stderr: np.ndarray
    start: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    correlation: np.ndarray
    chi2: float
    redchi: float
    aic: float
    bic: float
    ndata: int
    nparams: int
    n_impacts: int
    success: bool
    message: str
    weighting: str
    notes: list[str] = field(default_factory=list)
    residuals: np.ndarray | None = None  # weighted, in data order
    residual_kind: np.ndarray | None = None  # "vfn", "vft", "omega_f" per datum
    residual_row: np.ndarray | None = None  # table row of each datum

    def value(self, name: str) -> float:
        """The fitted value of ``name``."""
        return float(self.values[self.names.index(name)])

    def error(self, name: str) -> float:
        """The standard error of ``name``."""
        return float(self.stderr[self.names.index(name)])

    def at_bound(self) -> np.ndarray:
        """Whether each value sits on its lower or upper bound."""
        scale = BOUND_TOLERANCE * (1.0 + np.abs(self.values))
        return (np.abs(self.values - self.lower) <= scale) | (
            np.abs(self.values - self.upper) <= scale
        )

    def unchanged(self) -> np.ndarray:
        """Whether each value is still its starting value."""
        return np.abs(self.values - self.start) <= 1e-8 * (1.0 + np.abs(self.start))

    def not_identifiable(self) -> list[str]:
        """Why each parameter is not identifiable ('' where it is)."""
        out = []
        for i, se in enumerate(self.stderr):
            reasons = []
            if not math.isfinite(se) or se > HUGE_SE_RATIO * max(
                abs(self.values[i]), 1e-3
            ):
                reasons.append(f"standard error {se:.3g}")
            for j in range(len(self.names)):
                c = self.correlation[i, j]
                if j != i and math.isfinite(c) and abs(c) > CORRELATION_LIMIT:
                    reasons.append(f"corr {c:+.3f} with {self.names[j]}")
            out.append("; ".join(reasons))
        return out

    def flags(self) -> list[list[str]]:
        """Each parameter's flags: at bound, not identifiable, unchanged."""
        bound, same, why = self.at_bound(), self.unchanged(), self.not_identifiable()
        out = []
        for i in range(len(self.names)):
            f = []
            if bound[i]:
                f.append("at bound")
            if why[i]:
                f.append(f"not identifiable ({why[i]})")
            if same[i]:
                f.append("unchanged from the start")
            out.append(f)
        return out

    def report(self) -> str:
        """Plain-text report: statistics, then one line per parameter with flags."""
        lines = [
            f"fit: {'converged' if self.success else 'FAILED'} ({self.message})",
            f"data {self.ndata} from {self.n_impacts} impacts, parameters "
            f"{self.nparams}; chi2 {self.chi2:.6g}, reduced chi2 {self.redchi:.4g}, "
            f"AIC {self.aic:.6g}, BIC {self.bic:.6g}",
            f"weights: {self.weighting}",
            "standard errors: from the Jacobian, (J^T W J)^-1 scaled by the reduced "
            "chi2",
        ]
        width = max(len(n) for n in self.names)
        for name, v, se, s0, f in zip(
            self.names, self.values, self.stderr, self.start, self.flags(), strict=True
        ):
            flag = f"  [{'; '.join(f)}]" if f else ""
            lines.append(
                f"  {name:<{width}}  {v:.6g} ± {se:.2g}  (start {s0:.6g}){flag}"
            )
        lines.extend(f"note: {n}" for n in self.notes)
        return "\n".join(lines)

    def provenance(self, table: str) -> dict:
        """The ``provenance["fit"]`` entry of the calibrated model file."""
        bound = self.at_bound()

        def num(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        return {
            "table": table,
            "n_impacts": self.n_impacts,
            "n_data": self.ndata,
            "weighting": self.weighting,
            "parameters": {
                name: {
                    "value": float(v),
                    "stderr": num(se),
                    "at_bound": bool(b),
                }
                for name, v, se, b in zip(
                    self.names, self.values, self.stderr, bound, strict=True
                )
            },
            "correlation": {
                "names": list(self.names),
                "matrix": [[num(c) for c in row] for row in self.correlation],
            },
            "chi2": num(self.chi2),
            "redchi": num(self.redchi),
            "aic": num(self.aic),
            "bic": num(self.bic),
            "success": bool(self.success),
            "message": self.message,
        }
