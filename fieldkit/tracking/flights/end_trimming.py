"""Trimming the ends of a flight: samples that belong to the contact, not the flight.

Region growing (:mod:`fieldkit.tracking.flights.segment_growth`) accepts a sample when
it is consistent with the flight so far; near a contact a few samples pass that should
not: one or two just after a small impact (low frame rates), or the tail of a soft
contact whose force has faded below the noise (a net letting go). Each function here
takes a flight's sample positions and returns them without such end samples.
The parabolas are those of :mod:`fieldkit.tracking.flights.ballistic_fit`.
"""

from __future__ import annotations

import numpy as np

from fieldkit.tracking.flights.ballistic_fit import fit_fixed_g, fit_free_g


def trim_ends(t, x, z, rows: np.ndarray, sigma: float) -> np.ndarray:
    """Drop end samples further than 3.5 sigma from the flight's own free-g fit."""
    while len(rows) >= 6:
        off = fit_free_g(t[rows], x[rows], z[rows]).residual_m
        limit = 3.5 * sigma * np.sqrt(2.0)
        if off[0] > limit:
            rows = rows[1:]
        elif off[-1] > limit:
            rows = rows[:-1]
        else:
            break
    return rows


def trim_kinked_ends(
    t, x, z, rows: np.ndarray, sigma: float, g: float, kmax: int = 3
) -> np.ndarray:
    """Drop the last (first) k <= 3 samples when the flight without them misses one.

    A small impact seen at a low frame rate bends the fit enough that the one or two
    samples after it pass one at a time; predicted from the rest of the flight (g
    fixed at the track's own value) the furthest of them stands out.

    The bound is 3.5 (2-D) standard deviations of the position noise: the track's
    ``sigma``, or the scatter of this flight's own samples about their fit when that
    is smaller. ``sigma`` has a floor (a few hundredths of a pixel, for errors
    correlated over frames) that keeps good samples in a growing flight, but on a
    clean video it can be three times the real scatter, and a sample just after an
    impact that lies off the flight by several times its noise then stays in it
    (``bounce_short``: the frame 0.26 ms after impact 3, 0.24 mm off a flight whose
    samples scatter by 0.03 mm, biased its fitted g by 0.008 m/s^2).
    """
    for _ in range(2 * kmax):
        cut = None
        for at_start in (False, True):
            for k in range(1, kmax + 1):
                if len(rows) - k < 3 * kmax + 3:
                    break
                keep = rows[k:] if at_start else rows[:-k]
                out = rows[:k] if at_start else rows[-k:]
                fit = fit_fixed_g(t[keep], x[keep], z[keep], g)
                own = np.sqrt(fit.sse_m2 / max(2 * len(keep) - 4, 1))
                limit = 3.5 * np.sqrt(2.0) * min(sigma, max(own, 1e-3 * sigma))
                px, pz = fit.position(t[out])
                if np.hypot(x[out] - px, z[out] - pz).max() > limit:
                    cut = (at_start, k)
                    break
            if cut:
                break
        if cut is None:
            return rows
        rows = rows[cut[1] :] if cut[0] else rows[: -cut[1]]
    return rows


def trim_biased_ends(
    t, x, z, rows: np.ndarray, sigma: float, g: float, run: int = 6
) -> np.ndarray:
    """Drop end samples while the last ``run`` residuals are biased.

    With gravity fixed at the track's own ``g``, the residuals of a clean flight
    average to zero over any ``run`` samples (standard error ``sigma / sqrt(run)``);
    the tail of a soft contact (a net letting go) pulls them off systematically.
    """
    limit = 3.5 * sigma / np.sqrt(run)
    for _ in range(len(rows)):
        if len(rows) < 3 * run:
            break
        fit = fit_fixed_g(t[rows], x[rows], z[rows], g)
        rx, rz = fit.residual_x_m, fit.residual_z_m
        head = max(abs(rx[:run].mean()), abs(rz[:run].mean()))
        tail = max(abs(rx[-run:].mean()), abs(rz[-run:].mean()))
        if max(head, tail) <= limit:
            break
        rows = rows[1:] if head > tail else rows[:-1]
    return rows


def stable_end(
    t, x, z, rows: np.ndarray, sigma: float, g: float, at_start: bool
) -> np.ndarray:
    """Drop the samples of a flight still pulled by a fading contact force.

    Next to an extended contact the force fades below what single samples reveal
    (a net letting go), yet biases the flight's velocity at the contact. The flight
    is refitted (g fixed) without its first k samples on the contact side, k = 0, 1,
    ... up to 40 %; the velocity at the contact-side boundary drifts while
    contaminated samples are dropped and then stays put. The smallest k whose
    velocity agrees with every later one within 3 standard errors is kept.
    """
    n = len(rows)
    kmax = int(0.4 * n)
    if kmax < 2:
        return rows
    t_b = t[rows[0]] if at_start else t[rows[-1]]
    v, se = [], []
    for k in range(kmax + 1):
        r = rows[k:] if at_start else rows[: n - k]
        fit = fit_fixed_g(t[r], x[r], z[r], g, t_ref_s=t_b)
        v.append((fit.vx_mps, fit.vz_mps))
        se.append(sigma * np.sqrt(fit.unit_covariance()[1, 1]))
    v = np.array(v)
    se = np.array(se)
    for k in range(kmax + 1):
        later = slice(k + 1, kmax + 1)
        if np.all(np.abs(v[later] - v[k]).max(axis=1) <= 3.0 * se[later]):
            return rows[k:] if at_start else rows[: n - k]
    return rows
