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
(:func:`fit_flights`) and ``k`` by Newton on the profiled sum of squares.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Longest RK4 step [s]: drag changes the velocity on a time scale 1/(k|v|) of tens
#: of seconds for rocks, so 5 ms leaves the truncation error far below a micrometre.
MAX_STEP_S = 0.005
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
