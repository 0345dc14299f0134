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

from fieldkit.fit.suspect import SuspectCount

#: |correlation| above which a pair of parameters is flagged as not identifiable.
CORRELATION_LIMIT = 0.98
#: A standard error above this times max(|value|, 1e-3) is "huge".
HUGE_SE_RATIO = 1.0
#: Relative distance to a bound under which a value is "at the bound".
BOUND_TOLERANCE = 1e-6
#: Standard deviations of the reduced chi-square (sqrt(2 / dof) for a correct model
#: and correct standard uncertainties) beyond which it is called far from 1.
REDCHI_SIGMAS = 3.0
#: The optimiser's stopping messages (scipy's least_squares) in words.
STOP_WORDS = {
    "`ftol` termination condition is satisfied.":
        "the sum of squares stopped changing (relative change below 1e-8)",
    "`xtol` termination condition is satisfied.":
        "the parameters stopped changing (relative change below 1e-8)",
    "`gtol` termination condition is satisfied.":
        "the gradient vanished (below 1e-8)",
    "Both `ftol` and `xtol` termination conditions are satisfied.":
        "the sum of squares and the parameters stopped changing",
}  # fmt: skip
#: Column names in the weighting description -> words.
WEIGHT_WORDS = {
    "unit weights (the table has no *_sd columns)":
        "unit weights (the table gives no standard uncertainties)",
    "1/sd from the table's": "1 / the standard uncertainty the table gives for",
    "vfn_sd_mps": "the normal rebound velocity (m/s)",
    "vft_sd_mps": "the tangential rebound velocity (m/s)",
    "omega_f_sd_radps": "the rebound spin (rad/s)",
    "vin_sd_mps": "the normal impact velocity (m/s)",
    "vit_sd_mps": "the tangential impact velocity (m/s)",
    "omega_i_sd_radps": "the impact spin (rad/s)",
    "e_n_sd |vin|": "(SD of e_n) × normal impact speed",
    "e_t_sd |vit|": "(SD of e_t) × tangential impact speed",
    "e_n_sd": "SD of e_n",
    "e_t_sd": "SD of e_t",
    "sd(vfn)": "the normal rebound velocity's",
    "sd(vft)": "the tangential's",
    "1/sd with": "1 / standard uncertainty, with",
    "(no omega_f_sd_radps)": "(the table gives no standard uncertainty for them)",
    "r omega_f": "r·ω_f",
}  # fmt: skip


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
    #: Profile-likelihood intervals (:func:`fieldkit.fit.impact_profile.
    #: profile_intervals`; None: not made).
    profile: dict | None = None
    #: Suspect impacts and what the fit did with them (fieldkit.fit.suspect).
    suspect: SuspectCount | None = None

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

    def stop_words(self) -> str:
        """Why the optimiser stopped, in words."""
        return STOP_WORDS.get(self.message, self.message)

    def weighting_words(self) -> str:
        """How the data were weighted, in words (column names replaced).

        Examples
        --------
        >>> r = FitResult([], *[np.zeros(0)] * 6, 0, 0, 0, 0, 1, 0, 1, True, "",
        ...               "1/sd from the table's vfn_sd_mps, vft_sd_mps")
        >>> r.weighting_words()
        '1 / the standard uncertainty the table gives for the normal rebound velocity \
(m/s), the tangential rebound velocity (m/s)'
        """
        text = self.weighting
        for name, words in WEIGHT_WORDS.items():
            text = text.replace(name, words)
        return text

    def verdict(self) -> str:
        """What the reduced chi-square says: a sentence.

        With weights 1/sd it is about 1 (within ``sqrt(2 / dof)``) when the model
        explains the impacts within their standard uncertainties; far above 1 the
        model misses physics the impacts show or the standard uncertainties are too
        small; far below, they are too large. With unit weights it is the mean
        squared residual and says nothing about the fit's adequacy.
        """
        dof = self.ndata - self.nparams
        if self.weighting.startswith("unit weights"):
            return (
                f"reduced chi2 {self.redchi:.4g} (m/s)² is the mean squared residual "
                "of unit weights: no verdict on the model without the table's "
                "standard uncertainties"
            )
        if dof < 1 or not math.isfinite(self.redchi):
            return f"reduced chi2 {self.redchi:.4g}: too few data for a verdict"
        spread = math.sqrt(2.0 / dof)
        expected = f"1 ± {spread:.2g} expected for {dof} degrees of freedom"
        if self.redchi > 1.0 + REDCHI_SIGMAS * spread:
            return (
                f"reduced chi2 {self.redchi:.4g} is far above 1 ({expected}): the "
                "model misses physics the impacts show, or the table's standard "
                "uncertainties are too small; the standard errors are scaled up by "
                f"√{self.redchi:.3g} = {math.sqrt(self.redchi):.2g} to cover it. "
                "`fieldkit diagnose` ranks the effects that may be missing"
            )
        if self.redchi < 1.0 - REDCHI_SIGMAS * spread:
            return (
                f"reduced chi2 {self.redchi:.4g} is far below 1 ({expected}): the "
                "table's standard uncertainties are larger than the scatter of the "
                "impacts about the model"
            )
        return (
            f"reduced chi2 {self.redchi:.4g} is about 1 ({expected}): the model "
            "explains the impacts within their standard uncertainties"
        )

    def report(self) -> str:
        """Plain-text report: statistics, then one line per parameter with flags."""
        lines = [
            f"fit: {'converged' if self.success else 'FAILED'} ({self.stop_words()})",
            f"data {self.ndata} from {self.n_impacts} impacts, parameters "
            f"{self.nparams}; chi2 {self.chi2:.6g}, reduced chi2 {self.redchi:.4g}, "
            f"AIC {self.aic:.6g}, BIC {self.bic:.6g}",
            self.verdict(),
            f"weights: {self.weighting_words()}",
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
        lines.extend(self.profile_lines())
        lines.extend(f"note: {n}" for n in self.notes)
        return "\n".join(lines)

    def profile_lines(self) -> list[str]:
        """The profile-likelihood intervals beside the Jacobian's (none without)."""
        prof = self.profile
        if not prof:
            return []
        lines = []
        if prof.get("one_path"):
            lines.append(prof["one_path"])
        lines.append(
            "90 % intervals: profile likelihood (each parameter fixed, the others "
            f"refitted; Δchi2 / reduced chi2 <= F(1, {prof['dof']}) = "
            f"{_fmt(prof['threshold'])}) beside the Jacobian's value ± "
            f"{_fmt(prof['t_quantile'])} SE ({prof['evaluations']} refits, "
            f"{prof['wall_s']:.2f} s)"
        )
        width = max(len(n) for n in self.names)
        for q, lower, upper in zip(prof["parameters"], self.lower, self.upper,
                                   strict=True):  # fmt: skip
            lo, hi = q["interval90"]
            jlo, jhi = q["jacobian90"]
            marks = [
                f"open: the {side} bound is still inside" if math.isfinite(b)
                else f"open: not closed within {prof['max_half_widths']:g} Jacobian "
                f"half-widths {'above' if side == 'upper' else 'below'}"
                for side, o, b in zip(("lower", "upper"), q["open"], (lower, upper),
                                      strict=True)
                if o
            ]  # fmt: skip
            asym = q["asymmetry"]
            lines.append(
                f"  {q['name']:<{width}}  profile {_fmt(lo)} to {_fmt(hi)}; Jacobian "
                f"{_fmt(jlo)} to {_fmt(jhi)}"
                + (f"; upper/lower half-width {asym:.2f}" if asym is not None else "")
                + (f" [{'; '.join(marks)}]" if marks else "")
            )
        return lines

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
            "profile": self.profile,
        }


def _fmt(x: float | None) -> str:
    """``x`` to 4 significant digits, ``none`` for a missing value."""
    return "none" if x is None else f"{x:.4g}"
