"""Held-out error, the gain of one model over another, and its standard error.

The score of a model is the weighted root-mean-square of its *held-out* residuals
(each datum predicted by the model fitted without the datum's fold):

    cv_rmse = sqrt( sum w r^2 / sum w ),   w = 1/sd^2 normalised,

which is plain RMSE when all weights are equal and keeps the data's units (m/s for
rebound velocities). The gain of a candidate over a reference is

    improvement = 1 - cv_rmse(candidate) / cv_rmse(reference)

and its standard error is the delete-one-group jackknife over the independent
groups (paths or blocks, :mod:`fieldkit.diagnose.groups`) with the held-out
predictions fixed: for each group g the ratio is recomputed without g's sums,
``se^2 = (G-1)/G sum (I_(-g) - mean I)^2`` (Efron & Tibshirani 1993, ch. 11).
Keeping the predictions fixed leaves out the refit's own variability; the rule of
:func:`meaningful` is calibrated by simulation against that (``make bench``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class HeldOut:
    """Per-group sums of a model's held-out weighted squared residuals."""

    sse: np.ndarray  # sum w r^2 per group
    weight: np.ndarray  # sum w per group

    @property
    def rmse(self) -> float:
        """The weighted held-out RMSE over all groups."""
        return math.sqrt(float(self.sse.sum()) / float(self.weight.sum()))


def held_out(
    residual: np.ndarray, weight: np.ndarray, group: np.ndarray, n_groups: int
) -> HeldOut:
    """Group sums of ``weight * residual**2``; NaN residuals are left out.

    ``residual`` and ``weight`` may be ``(n, k)`` (k data per row); ``group`` is
    the group of each row.

    Examples
    --------
    >>> h = held_out(np.array([1.0, 2.0, 3.0]), np.ones(3), np.array([0, 0, 1]), 2)
    >>> h.sse.tolist(), round(h.rmse, 4)
    ([5.0, 9.0], 2.1602)
    """
    r = np.asarray(residual, float)
    w = np.broadcast_to(np.asarray(weight, float), r.shape)
    ok = np.isfinite(r) & np.isfinite(w)
    g = np.broadcast_to(np.asarray(group).reshape((-1,) + (1,) * (r.ndim - 1)), r.shape)
    sse = np.bincount(g[ok], weights=(w * r * r)[ok], minlength=n_groups)
    weight_sum = np.bincount(g[ok], weights=w[ok], minlength=n_groups)
    return HeldOut(sse=sse, weight=weight_sum)


def improvement(reference: HeldOut, candidate: HeldOut) -> tuple[float, float]:
    """``(1 - rmse_c / rmse_ref, jackknife standard error)`` over groups.

    Examples
    --------
    >>> ref = HeldOut(np.array([4.0, 4.0, 4.0]), np.ones(3))
    >>> gain, se = improvement(ref, HeldOut(np.array([1.0, 1.0, 1.0]), np.ones(3)))
    >>> round(gain, 6), round(se, 6)
    (0.5, 0.0)
    """
    gain = 1.0 - math.sqrt(candidate.sse.sum() / reference.sse.sum())
    left_out = 1.0 - np.sqrt(_without(candidate.sse) / _without(reference.sse))
    return gain, _jackknife_se(left_out)


def weighted_rmse(residual: np.ndarray, weight: np.ndarray) -> float:
    """``sqrt(sum w r^2 / sum w)`` over the finite residuals (NaN when none).

    Examples
    --------
    >>> weighted_rmse(np.array([1.0, np.nan, 3.0]), np.array([1.0, 1.0, 3.0]))
    2.6457513110645907
    """
    ok = np.isfinite(residual)
    if not ok.any():
        return math.nan
    w = np.broadcast_to(weight, residual.shape)[ok]
    return math.sqrt(float(np.sum(w * residual[ok] ** 2) / np.sum(w)))


def _without(per_group: np.ndarray) -> np.ndarray:
    """Total of ``per_group`` with each group left out in turn."""
    return per_group.sum() - per_group


def _jackknife_se(left_out: np.ndarray) -> float:
    """Delete-one jackknife SE from the leave-one-group-out statistics."""
    n = left_out.size
    if n < 3 or not np.all(np.isfinite(left_out)):
        return math.inf
    return float(math.sqrt((n - 1) / n * ((left_out - left_out.mean()) ** 2).sum()))


#: A gain is meaningful when it exceeds this many standard errors: z = 2 keeps
#: effect-free tables under 5 % false findings (0 of 30 at 100 impacts; z = 1
#: found an effect in 23 %: ``benchmarks/bench_diagnose_power.py``).
DEFAULT_Z = 2.0
#: The z of the conditional gains that decide confounding (B given A, A given B):
#: z = 1 keeps the power of z = 2 recommendations at A/sigma = 0.5 (92 % vs 70 % for
#: an angle law at 100 impacts) and still reports truly confounded tables (100 %).
CONFOUND_Z = 1.0
#: ... and this fraction of the reference's held-out error (a 1 % gain is not worth
#: a parameter, however small its standard error).
MIN_GAIN = 0.01


def meaningful(
    gain: float, se: float, *, z: float = DEFAULT_Z, min_gain: float = MIN_GAIN
) -> bool:
    """Whether a held-out gain exceeds ``z`` standard errors and ``min_gain``."""
    return gain > min_gain and math.isfinite(se) and gain > z * se


def recommendation_rule(z: float = DEFAULT_Z, min_gain: float = MIN_GAIN) -> str:
    """The rule of :func:`meaningful` in words: a candidate is recommended when ...
    (the report, ``--help`` and the README state it in these words). The gain is
    ``1 - cv_rmse(candidate) / cv_rmse(reference)``.

    Examples
    --------
    >>> recommendation_rule(min_gain=0.0)
    'it lowers the held-out error by more than 2 standard errors of that gain'
    >>> recommendation_rule(z=1.0).split(" error by ")[1]
    'more than 1 % and by more than 1 standard error of that gain'
    """
    floor = f"more than {min_gain * 100:g} % and by " if min_gain > 0 else ""
    errors = "standard error" if z == 1 else "standard errors"
    return (
        f"it lowers the held-out error by {floor}more than {z:g} {errors} of that gain"
    )
