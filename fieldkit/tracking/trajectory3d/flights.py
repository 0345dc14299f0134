"""Ballistic flights in 3-D samples: the sampling noise, segmentation and fits.

In free flight without drag the centre follows ``p(t) = p0 + v0 tau - (0, 0, g
tau^2 / 2)`` (``tau = t - t_ref``, g = 9.81 m/s^2 fixed): with the known gravity
term added back, every coordinate is a straight line in time, fitted by least
squares. Air drag is not modelled (the flights are ballistic; a flight that is not
shows as a mid-air split, :mod:`.contacts`).

**Noise.** The sampling noise SD is estimated from the data (:func:`noise_sd`): the
second divided difference of three consecutive samples of a ballistic flight is
``(0, 0, -g)`` exactly, whatever the velocity, so its scatter is the noise's
(``6 sigma^2 / dt^4`` for equal intervals); the median absolute deviation keeps the
few triples that straddle a contact from counting.

**Segmentation** (:func:`segment_flights`): a flight starts at the first window of
:data:`MIN_FLIGHT_SAMPLES` samples that is ballistic (chi-square of its residuals
within :data:`FALSE_ALARM`), and grows sample by sample while each new sample lies
within the prediction's chi-square (3 dof) bound; two samples in a row beyond it end
the flight (one is an outlier, skipped). The boundary samples are then re-assigned
at each join by the time the two fitted flights meet (:mod:`.contacts`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.stats import chi2

from fieldkit.physics.constants import G

#: Fewest samples a flight is fitted to.
MIN_FLIGHT_SAMPLES = 6
#: Probability that a ballistic sample (or window) is taken for a break.
FALSE_ALARM = 1e-4
#: Smallest noise SD used [m] (exact samples would make every bound zero).
MIN_NOISE_SD_M = 1e-4
_UP = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class Flight3D:
    """A ballistic flight fitted to samples ``start .. end - 1``.

    Attributes
    ----------
    start, end
        Sample index range (end exclusive).
    t_ref_s
        Reference time of the fit [s] (its first sample).
    p0_m, v0_mps
        Fitted position and velocity at ``t_ref_s`` (3-vectors).
    rms_m
        Root-mean-square 3-D residual of the fit [m].
    v_sd_mps
        Standard uncertainty of each velocity component from the sampling noise
        (``sigma / sqrt(sum (tau - mean tau)^2)``: the slope of a straight-line
        fit; the same at every time, g being fixed) [m/s]; NaN when no noise SD
        was given to :func:`fit_flight`.
    """

    start: int
    end: int
    t_ref_s: float
    p0_m: np.ndarray
    v0_mps: np.ndarray
    rms_m: float
    v_sd_mps: float = float("nan")
    drag_per_m: float = 0.0
    t_last_s: float = float("nan")

    @property
    def samples(self) -> int:
        return self.end - self.start

    def position(self, t_s):
        """Fitted centre position at ``t_s`` (a time or an array of times) [m]."""
        tau = np.asarray(t_s, float) - self.t_ref_s
        if self.drag_per_m > 0:
            d, _ = drag_path(self.v0_mps, self.drag_per_m, np.atleast_1d(tau))
            return self.p0_m + (d[0] if np.ndim(tau) == 0 else d)
        tau = tau[..., None] if np.ndim(tau) else tau
        return self.p0_m + self.v0_mps * tau - 0.5 * G * tau * tau * _UP

    def velocity(self, t_s: float) -> np.ndarray:
        """Fitted velocity at ``t_s`` [m/s]."""
        if self.drag_per_m > 0:
            _, v = drag_path(self.v0_mps, self.drag_per_m, [t_s - self.t_ref_s])
            return v[0]
        return self.v0_mps - G * (t_s - self.t_ref_s) * _UP


#: Longest integration step of a flight with air drag [s].
DRAG_STEP_S = 1e-3
#: Fixed-point passes of a fit with air drag (the drag path of the last v0).
DRAG_FIT_PASSES = 4


@njit(cache=True)
def _acc(v, k, out):
    speed = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    out[0] = -k * speed * v[0]
    out[1] = -k * speed * v[1]
    out[2] = -G - k * speed * v[2]


@njit(cache=True)
def _rk4_drag(v0, k, h, n):
    """Positions and velocities after 0..n RK4 steps of ``h`` from the origin."""
    ps = np.zeros((n + 1, 3))
    vs = np.zeros((n + 1, 3))
    v = v0.copy()
    pos = np.zeros(3)
    vs[0] = v
    a1 = np.empty(3)
    a2 = np.empty(3)
    a3 = np.empty(3)
    a4 = np.empty(3)
    w = np.empty(3)
    for i in range(n):
        _acc(v, k, a1)
        w[:] = v + 0.5 * h * a1
        _acc(w, k, a2)
        w[:] = v + 0.5 * h * a2
        _acc(w, k, a3)
        w[:] = v + h * a3
        _acc(w, k, a4)
        pos = pos + h * (v + h / 6.0 * (a1 + a2 + a3))
        v = v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        ps[i + 1] = pos
        vs[i + 1] = v
    return ps, vs


def drag_path(v0_mps, drag_per_m: float, tau_s) -> tuple[np.ndarray, np.ndarray]:
    """Displacement and velocity at times ``tau_s`` (from 0, either sign) of a
    flight leaving the origin at ``v0_mps`` under g and quadratic air drag
    ``dv/dt = -g z - k |v| v`` (``k = rho C_d A / (2 m)`` [1/m]); RK4 with steps of
    at most :data:`DRAG_STEP_S`, linear between steps.

    Examples
    --------
    >>> d, v = drag_path(np.array([3.0, 0, 4]), 0.0, [0.5])
    >>> [round(float(x), 6) for x in d[0]], [round(float(x), 6) for x in v[0]]
    ([1.5, 0.0, 0.77375], [3.0, 0.0, -0.905])
    """
    tau = np.asarray(tau_s, float)
    disp = np.zeros((tau.size, 3))
    vel = np.zeros((tau.size, 3))
    v0 = np.asarray(v0_mps, float)
    k = float(drag_per_m)

    for sign in (1.0, -1.0):
        sel = tau >= 0 if sign > 0 else tau < 0
        if not sel.any():
            continue
        span = float(np.abs(tau[sel]).max())
        n = max(int(np.ceil(span / DRAG_STEP_S)), 1)
        h = sign * span / n
        ps, vs = _rk4_drag(v0, k, h, n)
        grid = np.abs(h) * np.arange(n + 1)
        at = np.abs(tau[sel])
        for c in range(3):
            disp[sel, c] = np.interp(at, grid, ps[:, c])
            vel[sel, c] = np.interp(at, grid, vs[:, c])
    return disp, vel


def noise_sd(t_s: np.ndarray, xyz_m: np.ndarray) -> float:
    """Sampling noise SD per coordinate [m], from second divided differences.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(400) / 200.0
    >>> p = np.c_[3 * t, -t, 5 + 4 * t - 4.905 * t**2] + rng.normal(0, 0.02, (400, 3))
    >>> abs(noise_sd(t, p) - 0.02) < 0.003
    True
    """
    t = np.asarray(t_s, float)
    p = np.asarray(xyz_m, float)
    d1 = np.diff(p, axis=0) / np.diff(t)[:, None]
    acc = 2.0 * np.diff(d1, axis=0) / (t[2:] - t[:-2])[:, None]
    acc[:, 2] += G
    dt = np.median(np.diff(t))
    mad = np.median(np.abs(acc - np.median(acc, axis=0)))
    return float(1.4826 * mad * dt * dt / np.sqrt(6.0))


def fit_flight(
    t_s: np.ndarray,
    xyz_m: np.ndarray,
    start: int,
    end: int,
    sigma_m: float | None = None,
    drag_per_m: float = 0.0,
) -> Flight3D:
    """Least-squares ballistic fit (g fixed) to samples ``start .. end - 1``
    (``sigma_m``: the noise SD per coordinate, for :attr:`Flight3D.v_sd_mps`).

    With ``drag_per_m`` > 0 the flight has quadratic air drag of that known
    parameter: the drag's part of the path (:func:`drag_path` less the ballistic
    one) for the last estimate of ``v0`` is taken off the samples and the straight
    lines refitted, :data:`DRAG_FIT_PASSES` times."""
    t = t_s[start:end]
    tau = t - t[0]
    q0 = xyz_m[start:end].copy()
    q0[:, 2] += 0.5 * G * tau * tau
    a = np.c_[np.ones_like(tau), tau]
    q = q0
    coef, *_ = np.linalg.lstsq(a, q, rcond=None)
    for _ in range(DRAG_FIT_PASSES if drag_per_m > 0 else 0):
        d, _v = drag_path(coef[1], drag_per_m, tau)
        extra = d - (coef[1] * tau[:, None] - 0.5 * G * (tau * tau)[:, None] * _UP)
        q = q0 - extra
        coef, *_ = np.linalg.lstsq(a, q, rcond=None)
    res = q - a @ coef
    return Flight3D(
        start,
        end,
        float(t[0]),
        coef[0].copy(),
        coef[1].copy(),
        float(np.sqrt(np.mean(np.sum(res * res, axis=1)))),
        _slope_sd(tau, sigma_m),
        float(drag_per_m),
        float(t[-1]),
    )


def _slope_sd(tau: np.ndarray, sigma_m: float | None) -> float:
    if sigma_m is None:
        return float("nan")
    spread = float(np.sum((tau - tau.mean()) ** 2))
    return float(max(sigma_m, MIN_NOISE_SD_M) / np.sqrt(spread))


class _Growing:
    """Running sums of a straight-line fit of q = p + g tau^2/2 z against tau."""

    def __init__(self, t_ref: float) -> None:
        self.t_ref = t_ref
        self.n = 0
        self.st = self.stt = 0.0
        self.sq = np.zeros(3)
        self.stq = np.zeros(3)

    def add(self, t: float, p: np.ndarray) -> None:
        tau = t - self.t_ref
        q = p + 0.5 * G * tau * tau * _UP
        self.n += 1
        self.st += tau
        self.stt += tau * tau
        self.sq += q
        self.stq += tau * q

    def chi2(self, t: float, p: np.ndarray, sigma: float) -> float:
        """Squared prediction residual of a new sample over its variance."""
        n = self.n
        tbar = self.st / n
        stt = self.stt - n * tbar * tbar
        slope = (self.stq - tbar * self.sq) / stt
        qbar = self.sq / n
        tau = t - self.t_ref
        pred = qbar + slope * (tau - tbar)
        q = p + 0.5 * G * tau * tau * _UP
        var = sigma * sigma * (1.0 + 1.0 / n + (tau - tbar) ** 2 / stt)
        e = q - pred
        return float(e @ e / var)


def _grow_with_drag(t, p, i, m, sigma, k, bound) -> int:
    """End (exclusive) of the flight with drag starting at sample ``i``."""
    n = len(t)
    fitted_to = i + m
    fl = fit_flight(t, p, i, fitted_to, drag_per_m=k)

    def chi(j: int) -> float:
        tau = t[i:fitted_to] - t[i]
        tbar = tau.mean()
        stt = float(np.sum((tau - tbar) ** 2))
        var = sigma * sigma * (1 + 1 / tau.size + (t[j] - t[i] - tbar) ** 2 / stt)
        e = p[j] - fl.position(t[j])
        return float(e @ e / var)

    j = end = i + m
    while j < n:
        if chi(j) <= bound:
            j += 1
            end = j
            if end - i >= 1.25 * (fitted_to - i):
                fitted_to = end
                fl = fit_flight(t, p, i, fitted_to, drag_per_m=k)
            continue
        if j + 1 < n and chi(j + 1) <= bound:
            j += 1
            continue
        break
    return end


def _window_ballistic(t, p, i, m, sigma, drag_per_m=0.0) -> bool:
    f = fit_flight(t, p, i, i + m, drag_per_m=drag_per_m)
    ss = f.rms_m**2 * m / (sigma * sigma)
    return ss <= chi2.isf(FALSE_ALARM, 3 * (m - 2))


def segment_flights(
    t_s: np.ndarray, xyz_m: np.ndarray, sigma_m: float, drag_per_m: float = 0.0
) -> list[tuple[int, int]]:
    """Sample ranges ``(start, end)`` of the ballistic flights, in time order.

    Samples in no range lie between flights (at a contact, or outliers). With
    ``drag_per_m`` > 0 the flights have that quadratic air drag: each new sample
    is predicted by the drag fit of the flight so far (refitted each time the
    flight has grown by a quarter).
    """
    t = np.asarray(t_s, float)
    p = np.asarray(xyz_m, float)
    n = len(t)
    m = MIN_FLIGHT_SAMPLES
    sigma = max(float(sigma_m), MIN_NOISE_SD_M)
    bound = chi2.isf(FALSE_ALARM, 3)
    out: list[tuple[int, int]] = []
    i = 0
    while i + m <= n:
        if not _window_ballistic(t, p, i, m, sigma, drag_per_m):
            i += 1
            continue
        if drag_per_m > 0:
            end = _grow_with_drag(t, p, i, m, sigma, drag_per_m, bound)
            out.append((i, end))
            i = end
            continue
        grow = _Growing(t[i])
        for k in range(i, i + m):
            grow.add(t[k], p[k])
        j = i + m
        end = j
        while j < n:
            if grow.chi2(t[j], p[j], sigma) <= bound:
                grow.add(t[j], p[j])
                j += 1
                end = j
                continue
            if j + 1 < n and grow.chi2(t[j + 1], p[j + 1], sigma) <= bound:
                j += 1  # one outlier: skipped, the flight goes on
                continue
            break
        out.append((i, end))
        i = end
    return out
