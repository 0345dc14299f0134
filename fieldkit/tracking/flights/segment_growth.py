"""Growing a ballistic segment sample by sample (region growing for flight finding).

A seed of a few samples is extended to the right, then to the left, one sample at a
time, while the next sample agrees with the current least-squares fit of the free-g
ballistic model (x linear, z quadratic in time) within a chi-square test on its
prediction variance ``sigma^2 (1 + f' (A'A)^-1 f)``. One isolated bad sample (a
mis-detection) is skipped when the two samples after it agree again; two rejections
in a row end the segment. The normal equations are updated incrementally and rebuilt
around the current centre whenever the samples outgrow twice their span, so they stay
well conditioned.

The model is the free-g parabola of
:func:`fieldkit.tracking.flights.ballistic_fit.fit_free_g`, but the algorithm is not a
refit: growing a flight of n samples tests about n candidates, and refitting for each
would cost O(n^2) per flight. Here each added sample updates the power sums in O(1)
and each test solves a 2x2 and a 3x3 system (prediction variance included). The
parameters are never reported; the flights found are fitted by
:func:`~fieldkit.tracking.flights.ballistic_fit.fit_flight`.
"""

from __future__ import annotations

import numpy as np

#: Chi-square (2 d.o.f.) bound for a sample to join a flight (p ~ 4e-6 for pure noise).
CHI2_JOIN = 25.0


class _Grower:
    """Incremental least squares of x = a + b tau, z = c + d tau + e tau^2.

    Sums of powers of ``tau = (t - t0) / span`` are accumulated; when the samples
    outgrow twice the current span the sums are rebuilt around the new centre so
    the 3x3 normal equations stay well conditioned.
    """

    def __init__(self, t: np.ndarray, x: np.ndarray, z: np.ndarray, members: list[int]):
        self.t, self.x, self.z = t, x, z
        self.members = list(members)
        self._rebuild()

    def _rebuild(self) -> None:
        tm = self.t[self.members]
        self.t0 = 0.5 * (tm.min() + tm.max())
        self.span = max(0.5 * (tm.max() - tm.min()), 1e-12)
        tau = (tm - self.t0) / self.span
        p = tau[:, None] ** np.arange(5)[None, :]
        self.s = p.sum(axis=0)
        self.sx = (self.x[self.members][:, None] * p[:, :2]).sum(axis=0)
        self.sz = (self.z[self.members][:, None] * p[:, :3]).sum(axis=0)

    def _tau(self, i: int) -> float:
        return (self.t[i] - self.t0) / self.span

    def add(self, i: int) -> None:
        self.members.append(i)
        tau = self._tau(i)
        if abs(tau) > 2.0:
            self._rebuild()
            return
        p = tau ** np.arange(5)
        self.s += p
        self.sx += self.x[i] * p[:2]
        self.sz += self.z[i] * p[:3]

    def chi2(self, i: int, sigma: float) -> float:
        """Prediction chi-square of sample ``i`` against the current fit."""
        s = self.s
        mx = np.array([[s[0], s[1]], [s[1], s[2]]])
        mz = np.array([[s[0], s[1], s[2]], [s[1], s[2], s[3]], [s[2], s[3], s[4]]])
        try:
            ix = np.linalg.inv(mx)
            iz = np.linalg.inv(mz)
        except np.linalg.LinAlgError:
            return np.inf
        tau = self._tau(i)
        fx = np.array([1.0, tau])
        fz = np.array([1.0, tau, tau * tau])
        rx = self.x[i] - fx @ (ix @ self.sx)
        rz = self.z[i] - fz @ (iz @ self.sz)
        vx = sigma**2 * (1.0 + fx @ ix @ fx)
        vz = sigma**2 * (1.0 + fz @ iz @ fz)
        return float(rx * rx / vx + rz * rz / vz)


def grow_segment(
    t, x, z, lo: int, hi: int, free: np.ndarray, sigma: float, exclude=()
) -> tuple[int, int, list[int]]:
    """Grow the inclusive range ``[lo, hi]`` over samples with ``free`` true.

    Parameters
    ----------
    t, x, z
        Sample times [s] and positions [m] (valid samples only).
    lo, hi
        The seed range (inclusive positions).
    free
        Samples not yet taken by another segment.
    sigma
        Position noise per coordinate [m].
    exclude
        Positions inside ``[lo, hi]`` already known to be outliers.

    Returns
    -------
    lo, hi, outliers
        The grown range and the positions of skipped outliers inside it.
    """
    outliers: list[int] = list(exclude)
    g = _Grower(t, x, z, [i for i in range(lo, hi + 1) if i not in set(exclude)])
    n = len(t)
    for step in (1, -1):
        edge = hi if step == 1 else lo
        while True:
            j = edge + step
            if j < 0 or j >= n or not free[j]:
                break
            if g.chi2(j, sigma) <= CHI2_JOIN:
                g.add(j)
                edge = j
                continue
            # one outlier tolerated if the next two samples agree
            k1, k2 = j + step, j + 2 * step
            if (
                0 <= k2 < n
                and free[k1]
                and free[k2]
                and g.chi2(k1, sigma) <= CHI2_JOIN
                and g.chi2(k2, sigma) <= CHI2_JOIN
            ):
                outliers.append(j)
                g.add(k1)
                edge = k1
                continue
            break
        if step == 1:
            hi = edge
        else:
            lo = edge
    return lo, hi, outliers
