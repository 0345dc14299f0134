"""An accurate flight with quadratic air drag, and its sensitivities, for fitting.

The physics is :mod:`fieldkit.model.effects.air_drag`'s (``a = g - k |v| v`` with
``k = rho C_d pi r^2 / (2 m)`` from
:func:`~fieldkit.model.effects.air_drag.drag_factor`),
but integrated by classical fourth-order Runge-Kutta with steps of at most
``max_step_s`` (the kernel's second-order substeps are built for finding contacts, not
for matching millimetre-accurate video positions). With ``k = 0`` every RK4 step is
exact (the acceleration is constant), so the flight is the parabola to rounding.

Beside the positions, :func:`flight_path` integrates the variational equations: the
derivatives of ``x(t)``, ``z(t)`` with respect to the initial velocity ``(vx0, vz0)``
and to ``k``. The derivatives with respect to the initial position are 1 (a
translation), so a flight is fitted by Gauss-Newton in four parameters
(:func:`fit_flights`) and ``k`` by Newton on the profiled sum of squares
(:func:`fit_drag`).

:func:`fit_drag` is the one fit of quadratic drag to tracked flights: `fieldkit
track` fits one flight with it (:mod:`fieldkit.tracking.flights.free_flight`) and
`fieldkit diagnose` fits one ``k`` shared by a track's flights
(:mod:`fieldkit.diagnose.flights`), both over the same range of ``k``
(:data:`MAX_K_PER_M`), so the drag `track` finds is the drag `diagnose` scores.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

#: Longest RK4 step [s]: drag changes the velocity on a time scale 1/(k|v|) of tens
#: of seconds for rocks, so 5 ms leaves the truncation error far below a micrometre.
MAX_STEP_S = 0.005
#: Largest drag factor fitted [1/m]: a ping-pong ball (2.7 g, r 20 mm, cd 0.5) has
#: 0.28 / m; ten times that is drag no tracked body has. A bound on ``k``, not on
#: ``cd``: the registry's ``cd`` range is that of a rough rock, while a tracked body
#: (a light ball) can show ``k`` far beyond what ``cd <= 3`` gives for its mass.
MAX_K_PER_M = 3.0
#: Newton iterations on ``k`` and Gauss-Newton iterations per flight and ``k``.
_OUTER, _INNER = 30, 8
#: Size of the state: x, z, vx, vz and d(x, z, vx, vz)/d(vx0, vz0, k).
_N = 16


@njit(cache=True)
def _derivative(y, k, g, out):
    """``dy/dt`` of the state and its sensitivities (layout in :func:`_initial`)."""
    vx, vz = y[2], y[3]
    s = math.sqrt(vx * vx + vz * vz)
    out[0] = vx
    out[1] = vz
    out[2] = -k * s * vx
    out[3] = -g - k * s * vz
    if s > 0.0:
        a00 = -k * (s + vx * vx / s)
        a01 = -k * vx * vz / s
        a11 = -k * (s + vz * vz / s)
    else:
        a00 = a01 = a11 = 0.0
    for j in range(3):  # parameter j: vx0, vz0, k
        px, pz, qx, qz = 4 + j, 7 + j, 10 + j, 13 + j
        out[px] = y[qx]
        out[pz] = y[qz]
        out[qx] = a00 * y[qx] + a01 * y[qz]
        out[qz] = a01 * y[qx] + a11 * y[qz]
    out[12] += -s * vx
    out[15] += -s * vz


@njit(cache=True)
def _rk4(y, h, k, g, k1, k2, k3, k4, tmp):
    """One classical RK4 step of length ``h`` (``y`` updated in place)."""
    n = y.size
    _derivative(y, k, g, k1)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * h * k1[i]
    _derivative(tmp, k, g, k2)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * h * k2[i]
    _derivative(tmp, k, g, k3)
    for i in range(n):
        tmp[i] = y[i] + h * k3[i]
    _derivative(tmp, k, g, k4)
    for i in range(n):
        y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@njit(cache=True)
def _initial(x0, z0, vx0, vz0):
    y = np.zeros(_N)
    y[0], y[1], y[2], y[3] = x0, z0, vx0, vz0
    y[10] = 1.0  # dvx/dvx0
    y[14] = 1.0  # dvz/dvz0
    return y


@njit(cache=True)
def flight_path(t_s, x0, z0, vx0, vz0, k, g, max_step_s):
    """Positions at the (increasing) times ``t_s`` of a flight in state ``x0..vz0``
    at ``t_s[0]``, and their derivatives.

    Returns
    -------
    x, z : ndarray (n,)
        Centre positions [m].
    jac : ndarray (n, 2, 3)
        ``d(x, z)/d(vx0, vz0, k)`` at each time.
    vel : ndarray (n, 2)
        Velocity [m/s] at each time.
    """
    n = t_s.size
    x = np.empty(n)
    z = np.empty(n)
    jac = np.empty((n, 2, 3))
    vel = np.empty((n, 2))
    y = _initial(x0, z0, vx0, vz0)
    w = np.empty((5, _N))
    k1, k2, k3, k4, tmp = w[0], w[1], w[2], w[3], w[4]
    for i in range(n):
        if i > 0:
            dt = t_s[i] - t_s[i - 1]
            steps = max(1, int(math.ceil(dt / max_step_s)))
            h = dt / steps
            for _ in range(steps):
                _rk4(y, h, k, g, k1, k2, k3, k4, tmp)
        x[i], z[i] = y[0], y[1]
        vel[i, 0], vel[i, 1] = y[2], y[3]
        for j in range(3):
            jac[i, 0, j] = y[4 + j]
            jac[i, 1, j] = y[7 + j]
    return x, z, jac, vel


@njit(cache=True)
def step_state(state, h, k, g):
    """``(x, z, vx, vz)`` after one RK4 step of ``h`` seconds (no sensitivities)."""
    y = _initial(state[0], state[1], state[2], state[3])
    w = np.empty((5, _N))
    k1, k2, k3, k4, tmp = w[0], w[1], w[2], w[3], w[4]
    _rk4(y, h, k, g, k1, k2, k3, k4, tmp)
    return y[:4].copy()


@njit(cache=True)
def _ballistic(t, x, z, g):
    """Closed-form least squares of the g-fixed parabola: ``(x0, z0, vx0, vz0)``
    at ``t[0]``."""
    tau = t - t[0]
    a = np.empty((tau.size, 2))
    a[:, 0] = 1.0
    a[:, 1] = tau
    ata = a.T @ a
    cx = np.linalg.solve(ata, a.T @ x)
    cz = np.linalg.solve(ata, a.T @ (z + 0.5 * g * tau * tau))
    return np.array([cx[0], cz[0], cx[1], cz[1]])


@njit(cache=True)
def _fit_one(t, x, z, k, g, max_step_s, p, iterations):
    """Gauss-Newton for one flight's ``(x0, z0, vx0, vz0)`` at fixed ``k``.

    ``p`` is the start (updated in place). Returns ``(sse, r.j_k, |j_k perp|^2)``
    with the residual ``r = obs - model`` and ``j_k perp`` the derivative in ``k``
    with the part the four flight parameters absorb projected out.
    """
    n = t.size
    jm = np.zeros((2 * n, 5))
    r = np.empty(2 * n)
    for it in range(iterations + 1):
        xm, zm, jac, _ = flight_path(t, p[0], p[1], p[2], p[3], k, g, max_step_s)
        for i in range(n):
            r[i] = x[i] - xm[i]
            r[n + i] = z[i] - zm[i]
            jm[i, 0] = 1.0
            jm[n + i, 1] = 1.0
            for j in range(3):
                jm[i, 2 + j] = jac[i, 0, j]
                jm[n + i, 2 + j] = jac[i, 1, j]
        j4 = np.ascontiguousarray(jm[:, :4])
        normal = j4.T @ j4
        step = np.linalg.solve(normal, j4.T @ r)
        if it == iterations:
            break
        for j in range(4):
            p[j] += step[j]
        small = abs(step[0]) + abs(step[1]) < 1e-12 * (1.0 + abs(p[0]) + abs(p[1]))
        if small and abs(step[2]) + abs(step[3]) < 1e-12 * (1.0 + abs(p[2])):
            break
    jk = jm[:, 4].copy()
    coef = np.linalg.solve(normal, j4.T @ jk)
    perp = jk - j4 @ coef
    return float(r @ r), float(r @ jk), float(perp @ perp)


@njit(cache=True)
def fit_flights(t, x, z, start, k, g, max_step_s, params, iterations):
    """Fit every flight (samples ``start[i]:start[i+1]``) at a fixed drag factor ``k``.

    ``params`` (n_flights, 4) holds starting values and receives the fits (a row of
    NaN starts from the closed-form parabola). Returns per flight
    ``(sse, r.j_k, |j_k perp|^2)`` as three arrays.
    """
    nf = start.size - 1
    sse = np.empty(nf)
    grad = np.empty(nf)
    info = np.empty(nf)
    for f in range(nf):
        a, b = start[f], start[f + 1]
        p = params[f]
        if not np.isfinite(p[0]):
            p[:] = _ballistic(t[a:b], x[a:b], z[a:b], g)
        sse[f], grad[f], info[f] = _fit_one(
            t[a:b], x[a:b], z[a:b], k, g, max_step_s, p, iterations
        )
    return sse, grad, info


@njit(cache=True)
def residuals(t, x, z, start, k, g, max_step_s, params):
    """Per-sample residuals ``(obs - model)`` ``(n, 2)`` and model speeds ``(n,)``."""
    out = np.empty((t.size, 2))
    speed = np.empty(t.size)
    for f in range(start.size - 1):
        a, b = start[f], start[f + 1]
        p = params[f]
        xm, zm, _, vel = flight_path(t[a:b], p[0], p[1], p[2], p[3], k, g, max_step_s)
        for i in range(b - a):
            out[a + i, 0] = x[a + i] - xm[i]
            out[a + i, 1] = z[a + i] - zm[i]
            speed[a + i] = math.sqrt(vel[i, 0] ** 2 + vel[i, 1] ** 2)
    return out, speed


@dataclass
class DragFit:
    """Flights fitted with one drag factor (:func:`fit_drag`).

    Attributes
    ----------
    k_per_m
        The drag factor ``k`` [1/m] (given or fitted).
    params
        ``(n_flights, 4)``: ``x0, z0, vx0, vz0`` at each flight's first sample.
    sse_m2
        Sum of the squared x and z residuals of all flights [m^2].
    info
        ``sum |j_k perp|^2``: the curvature of ``sse / 2`` in ``k`` profiled over
        the flights' states (``sigma^2 / info`` is the variance of ``k``).
    """

    k_per_m: float
    params: np.ndarray
    sse_m2: float
    info: float


def _fit_at(t, x, z, start, k, g, params):
    sse, grad, info = fit_flights(t, x, z, start, k, g, MAX_STEP_S, params, _INNER)
    return float(sse.sum()), float(grad.sum()), float(info.sum())


def fit_drag(
    t_s: np.ndarray,
    x_m: np.ndarray,
    z_m: np.ndarray,
    start: np.ndarray,
    g_mps2: float,
    *,
    k_per_m: float | None = None,
    k_max_per_m: float = MAX_K_PER_M,
) -> DragFit:
    """Flights with quadratic drag: one ``k`` shared by all, each its own state.

    ``k`` in ``[0, k_max_per_m]`` is found by projected Newton on ``sse / 2``
    profiled over the flights' initial positions and velocities (the model is nearly
    linear in ``k``: a few steps), a step that does not lower the sum of squares
    halved; each flight's state by Gauss-Newton (:func:`fit_flights`) from the
    parabola, then from the previous ``k``'s fit.

    Parameters
    ----------
    t_s, x_m, z_m
        Samples of all flights, concatenated; flight ``i`` is
        ``start[i]:start[i + 1]`` (times increasing within it).
    start
        Flight boundaries (``int64``, ``n_flights + 1`` values).
    g_mps2
        Gravity [m/s^2].
    k_per_m
        A fixed drag factor (only the states are fitted), or None to fit it.
    k_max_per_m
        Upper bound of the fitted ``k``.

    Returns
    -------
    DragFit

    Examples
    --------
    >>> t = np.arange(0.0, 0.4, 1 / 500)
    >>> x, z, _, _ = flight_path(t, 0.0, 0.5, 3.0, 1.0, 0.35, 9.81, MAX_STEP_S)
    >>> fit = fit_drag(t, x, z, np.array([0, t.size]), 9.81)
    >>> round(fit.k_per_m, 6), fit.sse_m2 < 1e-20
    (0.35, True)
    """
    t, x, z = (np.ascontiguousarray(a, dtype=float) for a in (t_s, x_m, z_m))
    start = np.ascontiguousarray(start, dtype=np.int64)
    params = np.full((start.size - 1, 4), np.nan)
    k = 0.0 if k_per_m is None else float(k_per_m)
    sse, grad, info = _fit_at(t, x, z, start, k, g_mps2, params)
    if k_per_m is None and np.isfinite(sse):
        for _ in range(_OUTER):
            step = grad / info if info > 0 else 0.0
            trial_k = min(max(k + step, 0.0), k_max_per_m)
            if trial_k == k:
                break
            trial_p = params.copy()
            trial = _fit_at(t, x, z, start, trial_k, g_mps2, trial_p)
            while not trial[0] <= sse and abs(trial_k - k) > 1e-9 * k_max_per_m:
                trial_k = 0.5 * (trial_k + k)
                trial_p = params.copy()
                trial = _fit_at(t, x, z, start, trial_k, g_mps2, trial_p)
            if not trial[0] <= sse:
                break
            done = abs(trial_k - k) <= 1e-7 * max(trial_k, 1e-12)
            k, params = trial_k, trial_p
            sse, grad, info = trial
            if done:
                break
    return DragFit(k, params, sse, info)
