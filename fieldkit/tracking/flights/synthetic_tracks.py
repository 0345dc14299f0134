"""Synthetic tracks with known truth: a ball bouncing on a tilted plane, a net capture.

Used by the tests (recover the truth within stated tolerances) and by examples. Both
generators return the sampled :class:`~fieldkit.track.Track` together with the
exact truth, so analysis can be checked against numbers it never saw.

* :func:`bouncing_ball` — exact parabolas between instantaneous impacts on the plane
  ``z = -x tan(psi)`` (psi positive descending toward +x, docs/architecture.md §2). At
  each impact ``v_fN = -e_n v_iN``, ``v_fT = e_t v_iT`` and the spin follows from the
  angular-momentum balance about the contact point of a rigid sphere,
  ``omega_f = omega_i + r (v_fT - v_iT) / k^2`` (the friction impulse that changes
  ``v_T`` also spins the body; thesis ch. 4).
* :func:`net_capture` — a ball that meets an inclined net modelled as a linear
  spring-damper acting along the net normal (``F = k d + c d'``, never pulling),
  integrated with a fine fixed step; the truth includes the energy the damper
  dissipated, ``int c d'^2 dt``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from fieldkit.model import drag_flight
from fieldkit.model.effects import air_drag
from fieldkit.physics.constants import G
from fieldkit.physics.local_axes import to_local, to_section
from fieldkit.track import Track


@dataclass
class SyntheticTrack:
    """A sampled track and its truth (one row per impact or contact)."""

    track: Track
    truth: pd.DataFrame


def bouncing_ball(
    *,
    fps: float = 1205.0,
    fps_reported: float | None = None,
    duration_s: float = 0.6,
    start_xz_m: tuple[float, float] = (0.0, 0.25),
    start_velocity_mps: tuple[float, float] = (2.0, 0.0),
    surface_angle_deg: float = 10.0,
    radius_m: float = 0.0375,
    gyration_m: float | None = None,
    e_n: float = 0.6,
    e_t: float = 0.8,
    omega0_radps: float = 0.0,
    noise_m: float = 0.0,
    angle_noise_rad: float = 0.0,
    max_impacts: int = 20,
    rng: np.random.Generator | None = None,
    cd: float = 0.0,
    mass_kg: float = 0.14,
    air_density_kg_m3: float = 1.225,
) -> SyntheticTrack:
    """A sphere bouncing down the plane ``z = -x tan(psi)`` sampled at ``fps``.

    With ``cd > 0`` the flights carry quadratic air drag ``a = g - k |v| v``,
    ``k = rho cd pi r^2 / (2 m)`` (:mod:`fieldkit.model.effects.air_drag`),
    integrated by :func:`fieldkit.model.drag_flight.flight_path` (RK4, exact to
    rounding for the parabola); each landing is found by bisection to 1e-12 s.

    Parameters
    ----------
    fps
        True capture rate [1/s]; samples are at ``k / fps``.
    fps_reported
        Rate used to compute the track's time column (default ``fps``); a different
        value imitates a user giving the wrong capture rate ``fps``.
    start_xz_m, start_velocity_mps
        Centre position [m] and velocity [m/s] at t = 0 (must be above the plane).
    surface_angle_deg
        Plane dip psi [deg].
    radius_m, gyration_m
        Sphere radius and radius of gyration (default solid sphere ``sqrt(2/5) r``).
    e_n, e_t
        Coefficients of restitution applied at every impact.
    omega0_radps
        Initial spin [rad/s] (negative = clockwise = rolling toward +x).
    noise_m, angle_noise_rad
        Standard deviation of Gaussian noise added to x, z and to the marker angle.
    rng
        Random generator for the noise (required when noise is non-zero).
    cd, mass_kg, air_density_kg_m3
        Drag coefficient (0: exact parabolas), body mass [kg] and air density
        [kg/m^3] of the drag factor ``k``.

    Returns
    -------
    SyntheticTrack
        ``truth`` has one row per impact: ``t_s``, ``x_m``, ``z_m``, ``vi_x_mps``,
        ``vi_z_mps``, ``vf_x_mps``, ``vf_z_mps``, ``omega_i_radps``, ``omega_f_radps``.
    """
    k = gyration_m if gyration_m is not None else np.sqrt(0.4) * radius_m
    psi = surface_angle_deg
    n_hat = np.array([np.sin(np.radians(psi)), np.cos(np.radians(psi))])
    p = np.array(start_xz_m, float)
    v = np.array(start_velocity_mps, float)
    omega, angle, t = float(omega0_radps), 0.0, 0.0
    pieces = []  # (t_start, p, v, angle, omega)
    truth = []
    k_drag = float(air_drag.drag_factor(cd, air_density_kg_m3, radius_m, mass_kg))
    while t < duration_s and len(truth) < max_impacts:
        pieces.append((t, p.copy(), v.copy(), angle, omega))
        dt_hit = _time_to_plane(p, v, n_hat, radius_m, k_drag, duration_s - t)
        if dt_hit is None or dt_hit < 1e-9 or t + dt_hit >= duration_s:
            break
        t += dt_hit
        p, v = _flight_state(p, v, dt_hit, k_drag)
        angle += omega * dt_hit
        vit, vin = to_local(v[0], v[1], psi)
        vft, vfn = e_t * vit, -e_n * vin
        omega_f = omega + radius_m * (vft - vit) / k**2
        vfx, vfz = to_section(vft, vfn, psi)
        truth.append(
            dict(
                t_s=t,
                x_m=p[0],
                z_m=p[1],
                vi_x_mps=v[0],
                vi_z_mps=v[1],
                vf_x_mps=float(vfx),
                vf_z_mps=float(vfz),
                omega_i_radps=omega,
                omega_f_radps=omega_f,
            )
        )
        v = np.array([float(vfx), float(vfz)])
        omega = omega_f
    if len(pieces) == len(truth):  # stopped at max_impacts: end at the last impact
        duration_s = truth[-1]["t_s"]
    frames = np.arange(int(np.floor(duration_s * fps)) + 1)
    times = frames / fps
    starts = np.array([pc[0] for pc in pieces])
    which = np.searchsorted(starts, times, side="right") - 1
    x = np.empty_like(times)
    z = np.empty_like(times)
    ang = np.empty_like(times)
    for j, (t0, p0, v0, a0, w0) in enumerate(pieces):
        sel = which == j
        tau = times[sel] - t0
        if k_drag > 0 and sel.any():
            tt = np.concatenate([[0.0], tau])
            xs, zs, _, _ = drag_flight.flight_path(
                tt, p0[0], p0[1], v0[0], v0[1], k_drag, G, drag_flight.MAX_STEP_S
            )
            x[sel], z[sel] = xs[1:], zs[1:]
        else:
            x[sel] = p0[0] + v0[0] * tau
            z[sel] = p0[1] + v0[1] * tau - 0.5 * G * tau**2
        ang[sel] = a0 + w0 * tau
    if noise_m or angle_noise_rad:
        if rng is None:
            raise ValueError("noise needs an explicit numpy Generator")
        x = x + rng.normal(0.0, noise_m, x.shape)
        z = z + rng.normal(0.0, noise_m, z.shape)
        ang = ang + rng.normal(0.0, angle_noise_rad, ang.shape)
    t_col = frames / (fps_reported or fps)
    frame = pd.DataFrame(
        {
            "frame": frames,
            "t_s": t_col,
            "x_m": x,
            "z_m": z,
            "angle_rad": ang,
            "omega_radps": np.gradient(ang, t_col),
        }
    )
    return SyntheticTrack(
        Track(
            frame,
            source="synthetic bouncing ball",
            fps=fps_reported or fps,
            meta={
                "truth_fps": fps,
                "radius_m": radius_m,
                "gyration_m": k,
                "mass_kg": mass_kg,
                "cd": cd,
                "k_per_m": k_drag,
            },
        ),
        pd.DataFrame(truth),
    )


def _flight_state(p, v, dt, k_drag):
    """Centre and velocity after ``dt`` seconds of free flight (drag factor ``k``)."""
    if k_drag <= 0:
        return p + v * dt + np.array([0.0, -0.5 * G * dt**2]), v + np.array(
            [0.0, -G * dt]
        )
    xs, zs, _, vel = drag_flight.flight_path(
        np.array([0.0, dt]), p[0], p[1], v[0], v[1], k_drag, G, drag_flight.MAX_STEP_S
    )
    return np.array([xs[1], zs[1]]), vel[1].copy()


def _time_to_plane(p, v, n_hat, radius_m, k_drag, horizon_s):
    """Time until the centre is ``radius_m`` above the plane through the origin
    with normal ``n_hat`` (None when not within ``horizon_s``)."""
    g_n = G * n_hat[1]
    d0 = p @ n_hat - radius_m
    vn = v @ n_hat
    if k_drag <= 0:
        return float((vn + np.sqrt(vn * vn + 2.0 * g_n * d0)) / g_n)

    def gap(dt):
        q, _ = _flight_state(p, v, dt, k_drag)
        return float(q @ n_hat - radius_m)

    step, t = 1e-3, 0.0
    while t < horizon_s + step:
        if gap(t + step) < 0.0:
            lo, hi = t, t + step
            while hi - lo > 1e-12:
                mid = 0.5 * (lo + hi)
                lo, hi = (lo, mid) if gap(mid) < 0.0 else (mid, hi)
            return hi
        t += step
    return None


def net_capture(
    *,
    fps: float = 1205.0,
    duration_s: float = 0.16,
    start_xz_m: tuple[float, float] = (0.0, 0.3),
    start_velocity_mps: tuple[float, float] = (12.0, -2.0),
    net_point_xz_m: tuple[float, float] = (0.6, 0.0),
    net_normal_deg: float = 150.0,
    radius_m: float = 0.0375,
    mass_kg: float = 0.14,
    stiffness_npm: float = 550.0,
    damping_nspm: float = 4.0,
    noise_m: float = 0.0,
    rng: np.random.Generator | None = None,
    step_s: float = 1e-5,
) -> SyntheticTrack:
    """A ball caught and redirected by a spring-damper net (thesis §8.5 model tests).

    The net is the line through ``net_point_xz_m`` with outward unit normal at
    ``net_normal_deg`` (counter-clockwise from +x; 150° faces the incoming ball and
    up). Penetration ``d = r - (p - p_net).n``; while ``d > 0`` the net pushes with
    ``max(0, k d + c d')`` along ``n``; the contact ends when that force first returns
    to zero (the damped net cannot follow the ball out). Gravity acts throughout.

    Returns
    -------
    SyntheticTrack
        ``truth`` has one row: contact start/end times and positions, velocities at
        both, ``ke_i_j``, ``ke_f_j`` and ``damper_j`` (energy dissipated by the
        damper, ``int c d'^2 dt``), and ``v_min_mps``.
    """
    n_hat = np.array(
        [np.cos(np.radians(net_normal_deg)), np.sin(np.radians(net_normal_deg))]
    )
    p_net = np.array(net_point_xz_m, float)
    state = np.array([*start_xz_m, *start_velocity_mps], float)

    def accel(s: np.ndarray) -> tuple[np.ndarray, float, float]:
        d = radius_m - (s[:2] - p_net) @ n_hat
        acc = np.array([0.0, -G])
        if d <= 0:
            return acc, 0.0, 0.0
        d_dot = -(s[2:] @ n_hat)
        force = max(0.0, stiffness_npm * d + damping_nspm * d_dot)
        return acc + force / mass_kg * n_hat, d, d_dot

    n_steps = int(round(duration_s / step_s))
    sample_every = 1.0 / fps
    times, xs, zs = [], [], []
    next_sample = 0.0
    t = 0.0
    in_contact = False
    damper = 0.0
    speeds = []
    truth: dict[str, float] = {}
    for _ in range(n_steps + 1):
        if t >= next_sample - 1e-12:
            times.append(t)
            xs.append(state[0])
            zs.append(state[1])
            next_sample += sample_every
        a1, d, d_dot = accel(state)
        pushing = d > 0 and stiffness_npm * d + damping_nspm * d_dot > 0
        if pushing and not in_contact and "t_end_s" not in truth:
            in_contact = True
            truth.update(
                t_start_s=t,
                x_start_m=state[0],
                z_start_m=state[1],
                vi_x_mps=state[2],
                vi_z_mps=state[3],
            )
        elif in_contact and not pushing:
            in_contact = False
            truth.update(
                t_end_s=t,
                x_end_m=state[0],
                z_end_m=state[1],
                vf_x_mps=state[2],
                vf_z_mps=state[3],
                spring_j=0.5 * stiffness_npm * max(d, 0.0) ** 2,
            )
        if in_contact:
            damper += damping_nspm * d_dot**2 * step_s
            speeds.append(np.hypot(state[2], state[3]))
        # RK4
        k1 = np.concatenate([state[2:], a1])
        s2 = state + 0.5 * step_s * k1
        k2 = np.concatenate([s2[2:], accel(s2)[0]])
        s3 = state + 0.5 * step_s * k2
        k3 = np.concatenate([s3[2:], accel(s3)[0]])
        s4 = state + step_s * k3
        k4 = np.concatenate([s4[2:], accel(s4)[0]])
        state = state + step_s / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        t += step_s
    x, z = np.array(xs), np.array(zs)
    if noise_m:
        if rng is None:
            raise ValueError("noise needs an explicit numpy Generator")
        x = x + rng.normal(0.0, noise_m, x.shape)
        z = z + rng.normal(0.0, noise_m, z.shape)
    truth["ke_i_j"] = 0.5 * mass_kg * (truth["vi_x_mps"] ** 2 + truth["vi_z_mps"] ** 2)
    truth["ke_f_j"] = 0.5 * mass_kg * (truth["vf_x_mps"] ** 2 + truth["vf_z_mps"] ** 2)
    truth["damper_j"] = damper
    truth["v_min_mps"] = float(min(speeds))
    frame = pd.DataFrame(
        {
            "frame": np.arange(len(times)),
            "t_s": np.arange(len(times)) / fps,
            "x_m": x,
            "z_m": z,
        }
    )
    return SyntheticTrack(
        Track(
            frame,
            source="synthetic net capture",
            fps=fps,
            meta={"radius_m": radius_m, "mass_kg": mass_kg},
        ),
        pd.DataFrame([truth]),
    )
