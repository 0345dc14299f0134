"""Trimming the ends of a flight: samples that belong to the contact, not the flight.

Region growing (:mod:`fieldkit.tracking.flights.segment_growth`) accepts a sample when
it is consistent with the flight so far; near a contact a few samples pass that should
not: one or two just after a small impact (low frame rates), or the tail of a soft
contact whose force has faded below the noise (a net letting go). Each function here
takes a flight's sample positions and returns them without such end samples.
"""

from __future__ import annotations

import numpy as np


def trim_ends(t, x, z, rows: np.ndarray, sigma: float) -> np.ndarray:
    """Drop end samples further than 3.5 sigma from the flight's own free-g fit."""
    while len(rows) >= 6:
        fit = fit_flight_free(t[rows], x[rows], z[rows])
        limit = 3.5 * sigma * np.sqrt(2.0)
        if fit[0] > limit:
            rows = rows[1:]
        elif fit[-1] > limit:
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
    """
    limit = 3.5 * sigma * np.sqrt(2.0)
    for _ in range(2 * kmax):
        cut = None
        for at_start in (False, True):
            for k in range(1, kmax + 1):
                if len(rows) - k < 3 * kmax + 3:
                    break
                keep = rows[k:] if at_start else rows[:-k]
                out = rows[:k] if at_start else rows[-k:]
                tau = t[keep] - t[keep].mean()
                design = np.column_stack([np.ones_like(tau), tau])
                zc = z[keep] + 0.5 * g * tau**2
                cx = np.linalg.lstsq(design, x[keep], rcond=None)[0]
                cz = np.linalg.lstsq(design, zc, rcond=None)[0]
                tau_out = t[out] - t[keep].mean()
                px = cx[0] + cx[1] * tau_out
                pz = cz[0] + cz[1] * tau_out - 0.5 * g * tau_out**2
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
        tau = t[rows] - t[rows].mean()
        design = np.column_stack([np.ones_like(tau), tau])
        zc = z[rows] + 0.5 * g * tau**2
        rx = x[rows] - design @ np.linalg.lstsq(design, x[rows], rcond=None)[0]
        rz = zc - design @ np.linalg.lstsq(design, zc, rcond=None)[0]
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
        tau = t[r] - t_b
        design = np.column_stack([np.ones_like(tau), tau])
        zc = z[r] + 0.5 * g * tau**2
        cx = np.linalg.lstsq(design, x[r], rcond=None)[0]
        cz = np.linalg.lstsq(design, zc, rcond=None)[0]
        cov = np.linalg.inv(design.T @ design)
        v.append((cx[1], cz[1]))
        se.append(sigma * np.sqrt(cov[1, 1]))
    v = np.array(v)
    se = np.array(se)
    for k in range(kmax + 1):
        later = slice(k + 1, kmax + 1)
        if np.all(np.abs(v[later] - v[k]).max(axis=1) <= 3.0 * se[later]):
            return rows[k:] if at_start else rows[: n - k]
    return rows


def fit_flight_free(t: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Distance of each sample from the free-g ballistic least-squares fit [m]."""
    tau = t - t.mean()
    one = np.ones_like(tau)
    ax = np.column_stack([one, tau])
    az = np.column_stack([one, tau, tau**2])
    rx = x - ax @ np.linalg.lstsq(ax, x, rcond=None)[0]
    rz = z - az @ np.linalg.lstsq(az, z, rcond=None)[0]
    return np.hypot(rx, rz)
