"""Render the synthetic high-speed clips in ``video/`` deterministically.

Two scenes (the bounce also with quadratic air drag: ``bounce_drag``, and with the
strong drag of a light ball: ``bounce_drag_strong``), filmed "at"
1205 frames/s (thesis §8.5) and stored as MJPG ``.avi``
with a 30 frames/s playback rate, as high-speed cameras do:

``bounce``
    A 75 mm, 140 g rubber ball (thesis §8.5.2) with a dark marker spot, launched with
    top-spin, bouncing on a plate tilted at ``surface_deg`` (descending toward +x).
    Flights are exact parabolas (g = 9.81, no drag). Each impact is instantaneous, with
    a prescribed normal coefficient ``e_n`` and a rough-sphere Coulomb friction model:
    the tangential impulse brings the contact point to rolling if friction allows
    (``mu * (1 + e_n) * |vin| >= |v_slip| / (1 + r^2/k^2)``), otherwise it slides with
    impulse ``mu * (1 + e_n) * |vin|``. Velocities and spin jump exactly at the impact.
``net``
    The same ball caught and redirected by an inclined net: a spring-damper acting
    along the net's normal while the ball presses into it (stiffness ``net_stiffness``,
    damping ``net_damping``), with Coulomb friction along the net acting on slip and
    spin. Integrated with RK4 on 40 sub-steps per frame; the truth records the velocity
    at every frame of the contact, its duration and the energies (eq. 8.1 efficiency).

Image formation: a seeded static texture (blurred noise + shapes + the plate or net
anchors + two scale crosses), the ball anti-aliased by 8x8 super-sampling at its exact
sub-pixel centre, Gaussian sensor noise, MJPG compression. Pixel centres sit at integer
(u, v) (OpenCV convention); ``u`` right, ``v`` down; world ``x`` right, ``z`` up.

Beside each clip ``NAME.avi`` the script writes ``NAME.calibration.json`` (two scale
points + their distance, and >= 4 homography points), ``NAME.truth.json`` (scene,
impacts / contact) and ``NAME.truth.csv`` (true state at every frame).

Usage::

    python video/render.py               # both clips into video/
    python video/render.py --out /tmp/v bounce_drag_short   # the dragged ball
    python video/render.py --out /tmp/v --frames 300 bounce
    python video/render.py --out /tmp/v hard_shadow     # a hard clip (video/hard.py)
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import cv2
import numpy as np

G = 9.81
HERE = Path(__file__).resolve().parent


@dataclass
class Camera:
    """Image geometry: a level camera, ``scale_m_per_px`` metres per pixel."""

    width: int = 800
    height: int = 480
    scale_m_per_px: float = 0.002
    origin_u_px: float = 40.0  # image position of world (0, 0)
    origin_v_px: float = 440.0
    capture_fps: float = 1205.0
    playback_fps: float = 30.0
    noise_sd: float = 2.5  # grey levels
    exposure_s: float = 1.0 / 2410.0  # shutter open half the frame interval
    flicker: float = 0.0  # relative amplitude of lighting flicker (mains lamps)
    flicker_hz: float = 100.0
    jpeg_quality: int = 90

    def to_image(self, x_m, z_m):
        """World (x right, z up) [m] -> image (u right, v down) [px]."""
        u = self.origin_u_px + np.asarray(x_m) / self.scale_m_per_px
        v = self.origin_v_px - np.asarray(z_m) / self.scale_m_per_px
        return u, v


@dataclass
class Ball:
    radius_m: float = 0.0375
    mass_kg: float = 0.14
    marker_offset: float = 0.55  # marker spot centre, fraction of the radius
    marker_radius: float = 0.24  # spot radius (stripe half-width), fraction of r
    marker: str = "spot"  # "spot" off the centre, or "stripe" through the centre
    colour_bgr: tuple = (70, 175, 240)
    marker_bgr: tuple = (60, 30, 20)

    @property
    def gyration_m(self) -> float:
        return math.sqrt(0.4) * self.radius_m  # solid sphere


@dataclass
class BounceScene:
    surface_deg: float = 15.0  # plate dip, descending toward +x
    plate_point_m: tuple = (0.0, 0.40)  # a point on the plate surface
    plate_end_x_m: float = 1.40  # the plate ends here: the ball flies off its edge
    start_m: tuple = (-0.07, 0.62)  # enters partly outside the left edge
    start_velocity_mps: tuple = (1.6, 0.3)
    start_omega_radps: float = 30.0  # back-spin: the first impact reverses it
    start_angle_rad: float = 0.3
    e_n: tuple = (0.7, 0.65, 0.6, 0.55, 0.5)  # prescribed, impact by impact
    friction: float = 0.3  # Coulomb coefficient at the contact
    duration_s: float = 0.95
    drag_cd: float = 0.0  # quadratic air drag a = -k |v| v, k = rho cd pi r^2 / (2 m)
    air_density_kg_m3: float = 1.225


@dataclass
class NetScene:
    net_top_m: tuple = (0.85, 0.86)  # anchors of the straight, unloaded net (it
    net_bottom_m: tuple = (1.05, 0.12)  # overhangs: the ball is redirected down it)
    start_m: tuple = (-0.02, 0.70)
    start_velocity_mps: tuple = (4.0, -0.3)
    start_omega_radps: float = 0.0
    start_angle_rad: float = 1.0
    net_stiffness: float = 420.0  # N/m along the net normal
    net_damping: float = 2.2  # N s/m
    friction: float = 0.4
    duration_s: float = 0.40


# ----------------------------------------------------------------------------- motion
def _plate_axes(surface_deg: float):
    psi = math.radians(surface_deg)
    tangent = np.array([math.cos(psi), -math.sin(psi)])
    normal = np.array([math.sin(psi), math.cos(psi)])
    return tangent, normal


def _impact(v, omega, surface_deg, e_n, mu, ball: Ball):
    """Instantaneous rough-sphere impact: vf, omega_f and the local components."""
    tangent, normal = _plate_axes(surface_deg)
    vin, vit = float(v @ normal), float(v @ tangent)
    r, k = ball.radius_m, ball.gyration_m
    jn = (1.0 + e_n) * abs(vin)  # normal impulse / m
    slip = vit + r * omega
    j_roll = slip / (1.0 + r * r / (k * k))
    jt = j_roll if mu * jn >= abs(j_roll) else math.copysign(mu * jn, slip)
    vfn, vft = -e_n * vin, vit - jt
    omega_f = omega - jt * r / (k * k)
    vf = vft * tangent + vfn * normal
    return (
        vf,
        omega_f,
        dict(vin=vin, vit=vit, vfn=vfn, vft=vft, rolling=bool(jt == j_roll)),
    )


def drag_factor(scene: BounceScene, ball: Ball) -> float:
    """``k = rho cd pi r^2 / (2 m)`` [1/m] of the scene's air drag."""
    return (
        scene.air_density_kg_m3 * scene.drag_cd * math.pi * ball.radius_m**2
        / (2.0 * ball.mass_kg)
    )  # fmt: skip


def _drag_rk4(state, h, k):
    """One RK4 step of ``(x, z, vx, vz, angle, omega)`` under g and quadratic drag."""

    def deriv(s):
        speed = math.hypot(s[2], s[3])
        return np.array(
            [s[2], s[3], -k * speed * s[2], -G - k * speed * s[3], s[5], 0.0]
        )

    k1 = deriv(state)
    k2 = deriv(state + 0.5 * h * k1)
    k3 = deriv(state + 0.5 * h * k2)
    k4 = deriv(state + h * k3)
    return state + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


def drag_bounce_motion(
    scene: BounceScene, ball: Ball, times: np.ndarray, substeps: int = 40
):
    """State at ``times`` of the bounce scene with quadratic air drag in flight.

    RK4 with ``substeps`` steps per frame; an impact inside a step is located by
    bisection to 1e-13 s and applied there (the same instantaneous rough-sphere
    impact as :func:`bounce_motion`). Returns (states, impacts).
    """
    _, normal = _plate_axes(scene.surface_deg)
    p0 = np.array(scene.plate_point_m)
    k = drag_factor(scene, ball)
    state = np.array(
        [*scene.start_m, *scene.start_velocity_mps, scene.start_angle_rad,
         scene.start_omega_radps], float,
    )  # fmt: skip

    def gap(s):
        return float((s[:2] - p0) @ normal) - ball.radius_m

    def on_plate(s):
        return (s[:2] - ball.radius_m * normal)[0] <= scene.plate_end_x_m

    states = np.zeros((len(times), 6))
    impacts = []
    h = (times[1] - times[0]) / substeps
    for i, t_frame in enumerate(times):
        states[i] = state
        for step in range(substeps):
            new = _drag_rk4(state, h, k)
            if gap(new) < 0.0 and gap(state) >= 0.0 and on_plate(new):
                if len(impacts) == len(scene.e_n):
                    raise ValueError("bounce scene: more impacts than e_n values")
                lo, hi = 0.0, h
                while hi - lo > 1e-13:
                    mid = 0.5 * (lo + hi)
                    below = gap(_drag_rk4(state, mid, k)) < 0
                    lo, hi = (lo, mid) if below else (mid, hi)
                hit = _drag_rk4(state, lo, k)
                vel_i, omega = hit[2:4].copy(), hit[5]
                e_n = scene.e_n[len(impacts)]
                vel, omega_f, local = _impact(
                    vel_i, omega, scene.surface_deg, e_n, scene.friction, ball
                )
                pos = hit[:2]
                impacts.append(
                    dict(
                        index=len(impacts) + 1,
                        t_s=t_frame + step * h + lo,
                        x_m=pos[0],
                        z_m=pos[1],
                        contact_x_m=float((pos - ball.radius_m * normal)[0]),
                        contact_z_m=float((pos - ball.radius_m * normal)[1]),
                        vi_x_mps=vel_i[0],
                        vi_z_mps=vel_i[1],
                        vf_x_mps=vel[0],
                        vf_z_mps=vel[1],
                        vin_mps=local["vin"],
                        vit_mps=local["vit"],
                        vfn_mps=local["vfn"],
                        vft_mps=local["vft"],
                        e_n=-local["vfn"] / local["vin"],
                        e_t=local["vft"] / local["vit"],
                        omega_i_radps=omega,
                        omega_f_radps=omega_f,
                        ends_rolling=local["rolling"],
                        vi_mps=float(np.hypot(*vel_i)),
                        vf_mps=float(np.hypot(*vel)),
                    )
                )
                hit[2:4], hit[5] = vel, omega_f
                new = _drag_rk4(hit, h - lo, k)
            state = new
    return states, [{k_: _plain(v) for k_, v in imp.items()} for imp in impacts]


def bounce_motion(scene: BounceScene, ball: Ball, times: np.ndarray):
    """Exact piecewise-ballistic state at ``times``; returns (states, impacts).

    A scene with air drag (``drag_cd > 0``) is integrated by
    :func:`drag_bounce_motion`.
    """
    if scene.drag_cd > 0:
        return drag_bounce_motion(scene, ball, times)
    tangent, normal = _plate_axes(scene.surface_deg)
    p0 = np.array(scene.plate_point_m)
    pos = np.array(scene.start_m, float)
    vel = np.array(scene.start_velocity_mps, float)
    omega, angle, t0 = scene.start_omega_radps, scene.start_angle_rad, 0.0
    gvec = np.array([0.0, -G])
    segments, impacts = [], []
    for i in range(len(scene.e_n) + 1):
        segments.append((t0, pos.copy(), vel.copy(), omega, angle))
        # distance to plate d(t) = d0 + vN t - g cos(psi) t^2 / 2 = r
        d0, vn, an = (
            float((pos - p0) @ normal),
            float(vel @ normal),
            float(gvec @ normal),
        )
        a, b, c = 0.5 * an, vn, d0 - ball.radius_m
        roots = np.roots([a, b, c])
        roots = np.sort(roots[np.isreal(roots)].real)
        dt = roots[roots > 1e-9][0]
        contact_x = (pos + vel * dt + 0.5 * gvec * dt * dt - ball.radius_m * normal)[0]
        if t0 + dt > scene.duration_s or contact_x > scene.plate_end_x_m:
            break
        if i == len(scene.e_n):
            raise ValueError("bounce scene: more impacts than e_n values; add some")
        pos = pos + vel * dt + 0.5 * gvec * dt * dt
        vel_i = vel + gvec * dt
        angle = angle + omega * dt
        t0 = t0 + dt
        vel, omega_f, local = _impact(
            vel_i, omega, scene.surface_deg, scene.e_n[i], scene.friction, ball
        )
        impacts.append(
            dict(
                index=i + 1,
                t_s=t0,
                x_m=pos[0],
                z_m=pos[1],
                contact_x_m=float((pos - ball.radius_m * normal)[0]),
                contact_z_m=float((pos - ball.radius_m * normal)[1]),
                vi_x_mps=vel_i[0],
                vi_z_mps=vel_i[1],
                vf_x_mps=vel[0],
                vf_z_mps=vel[1],
                vin_mps=local["vin"],
                vit_mps=local["vit"],
                vfn_mps=local["vfn"],
                vft_mps=local["vft"],
                e_n=-local["vfn"] / local["vin"],
                e_t=local["vft"] / local["vit"],
                omega_i_radps=omega,
                omega_f_radps=omega_f,
                ends_rolling=local["rolling"],
                vi_mps=float(np.hypot(*vel_i)),
                vf_mps=float(np.hypot(*vel)),
            )
        )
        omega = omega_f
    starts = np.array([s[0] for s in segments])
    seg = np.searchsorted(starts, times, side="right") - 1
    states = np.zeros((len(times), 6))  # x, z, vx, vz, angle, omega
    for j, (ts, p, v, w, ang) in enumerate(segments):
        sel = seg == j
        dt = times[sel] - ts
        states[sel, 0] = p[0] + v[0] * dt
        states[sel, 1] = p[1] + v[1] * dt - 0.5 * G * dt * dt
        states[sel, 2] = v[0]
        states[sel, 3] = v[1] - G * dt
        states[sel, 4] = ang + w * dt
        states[sel, 5] = w
    return states, [{k: _plain(v) for k, v in imp.items()} for imp in impacts]


def _net_axes(scene: NetScene):
    top, bottom = np.array(scene.net_top_m), np.array(scene.net_bottom_m)
    along = (bottom - top) / np.linalg.norm(bottom - top)  # down the net
    normal = np.array([-along[1], along[0]])
    if normal[0] > 0:  # face the incoming ball (from -x)
        normal = -normal
    return top, along, normal


def _net_derivative(state, scene: NetScene, ball: Ball):
    top, along, normal = _net_axes(scene)
    x, z, vx, vz, _, w = state
    pos, vel = np.array([x, z]), np.array([vx, vz])
    pen = ball.radius_m - float((pos - top) @ normal)
    force = np.array([0.0, -G * ball.mass_kg])
    torque = 0.0
    if pen > 0:
        vn = float(vel @ normal)
        fn = max(0.0, scene.net_stiffness * pen - scene.net_damping * vn)
        # contact point at pos - r n; slip = its velocity along the net
        lever = -ball.radius_m * normal
        cross_la = lever[0] * along[1] - lever[1] * along[0]
        slip = float(vel @ along) + w * (-(lever[1]) * along[0] + lever[0] * along[1])
        ft = -scene.friction * fn * math.tanh(slip / 0.02)
        force = force + fn * normal + ft * along
        torque = cross_la * ft
    inertia = ball.mass_kg * ball.gyration_m**2
    return np.array(
        [vx, vz, force[0] / ball.mass_kg, force[1] / ball.mass_kg, w, torque / inertia]
    ), pen > 0


def net_motion(scene: NetScene, ball: Ball, times: np.ndarray, substeps: int = 40):
    """RK4-integrated state at uniformly spaced ``times``: (states, contact)."""
    state = np.array(
        [
            *scene.start_m,
            *scene.start_velocity_mps,
            scene.start_angle_rad,
            scene.start_omega_radps,
        ],
        float,
    )
    dt = (times[1] - times[0]) / substeps
    states, in_contact = np.zeros((len(times), 6)), np.zeros(len(times), bool)
    t_on = t_off = None
    for i in range(len(times)):
        states[i] = state
        in_contact[i] = _net_derivative(state, scene, ball)[1]
        for step in range(substeps):
            k1, c1 = _net_derivative(state, scene, ball)
            k2, _ = _net_derivative(state + 0.5 * dt * k1, scene, ball)
            k3, _ = _net_derivative(state + 0.5 * dt * k2, scene, ball)
            k4, _ = _net_derivative(state + dt * k3, scene, ball)
            new = state + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            c_new = _net_derivative(new, scene, ball)[1]
            t_here = times[i] + (step + 1) * dt
            if c_new and not c1 and t_on is None:
                t_on, s_on = t_here, new.copy()
            if c1 and not c_new and t_on is not None and t_off is None:
                t_off, s_off = t_here, new.copy()
            state = new
    if t_on is None or t_off is None:
        raise RuntimeError("net scene: the ball does not complete a contact; adjust it")
    m, inertia = ball.mass_kg, ball.mass_kg * ball.gyration_m**2

    def energies(s):
        ke, re = 0.5 * m * (s[2] ** 2 + s[3] ** 2), 0.5 * inertia * s[5] ** 2
        return ke, re

    ke_i, re_i = energies(s_on)
    ke_f, re_f = energies(s_off)
    sel = in_contact
    speed = np.hypot(states[:, 2], states[:, 3])
    contact = dict(
        t_start_s=t_on,
        t_end_s=t_off,
        duration_s=t_off - t_on,
        frames=int(sel.sum()),
        first_frame=int(np.flatnonzero(sel)[0]),
        last_frame=int(np.flatnonzero(sel)[-1]),
        vi_x_mps=s_on[2],
        vi_z_mps=s_on[3],
        vf_x_mps=s_off[2],
        vf_z_mps=s_off[3],
        vi_mps=float(np.hypot(s_on[2], s_on[3])),
        vf_mps=float(np.hypot(s_off[2], s_off[3])),
        v_min_mps=float(speed[sel].min()),
        omega_i_radps=s_on[5],
        omega_f_radps=s_off[5],
        ke_i_j=ke_i,
        re_i_j=re_i,
        ke_f_j=ke_f,
        re_f_j=re_f,
        efficiency_percent=100.0 * (ke_f + re_f) / (ke_i + re_i),  # thesis eq. 8.1
        absorbed_j=(ke_i + re_i) - (ke_f + re_f),
    )
    return states, in_contact, {k: _plain(v) for k, v in contact.items()}


def _plain(value):
    if isinstance(value, np.generic):
        return value.item()
    return value


#: Significant digits of every float in the JSON files. The last bits of a float can
#: differ between machines (numpy picks SIMD code paths by CPU), so full ``repr`` digits
#: would make ``make video`` write different bytes elsewhere; 12 digits are far below
#: any tolerance and reproduce byte for byte (the truth CSV keeps 10).
JSON_DIGITS = 12


def _rounded(value):
    """``value`` with every float rounded to :data:`JSON_DIGITS` significant digits."""
    value = _plain(value)
    if isinstance(value, float):
        return float(f"{value:.{JSON_DIGITS}g}") if math.isfinite(value) else value
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_rounded(v) for v in value]
    return value


def _write_json(path: Path, data: dict) -> None:
    path.write_text(json.dumps(_rounded(data), indent=1))


# ----------------------------------------------------------------------------- images
def background(camera: Camera, rng: np.random.Generator, scene) -> np.ndarray:
    """Static textured background with the plate (or net anchors) and scale crosses."""
    h, w = camera.height, camera.width
    img = np.zeros((h, w), np.float32)
    for sigma, amp in ((1.0, 14.0), (4.0, 20.0), (16.0, 30.0)):
        layer = cv2.GaussianBlur(
            rng.standard_normal((h, w)).astype(np.float32), (0, 0), sigma
        )
        img += amp * layer / (layer.std() + 1e-9)
    img += 95.0
    bgr = np.repeat(img[:, :, None], 3, axis=2)
    bgr[:, :, 0] += 10.0
    for _ in range(14):  # distracting static shapes (none ball-sized and bright)
        colour = tuple(float(c) for c in rng.uniform(40, 150, 3))
        cx, cy = int(rng.integers(0, w)), int(rng.integers(0, h))
        if rng.random() < 0.5:
            cv2.rectangle(
                bgr,
                (cx, cy),
                (cx + int(rng.integers(10, 70)), cy + int(rng.integers(5, 40))),
                colour,
                -1,
                cv2.LINE_AA,
            )
        else:
            cv2.circle(bgr, (cx, cy), int(rng.integers(4, 12)), colour, -1, cv2.LINE_AA)
    if isinstance(scene, BounceScene):
        tangent, normal = _plate_axes(scene.surface_deg)
        p0 = np.array(scene.plate_point_m)
        a = p0 - 2.0 * tangent
        b = p0 + (scene.plate_end_x_m - p0[0]) / tangent[0] * tangent
        ua, va = camera.to_image(*a)
        ub, vb = camera.to_image(*b)
        poly = np.array([[ua, va], [ub, vb], [ub, va + 2000], [ua, va + 2000]])
        plate = np.zeros((h, w), np.uint8)
        cv2.fillPoly(plate, [np.round(poly * 16).astype(np.int32)], 255, cv2.LINE_AA, 4)
        alpha = (plate.astype(np.float32) / 255.0)[:, :, None]
        plate_tex = 60.0 + 0.4 * (bgr - 95.0)
        bgr = bgr * (1 - alpha) + plate_tex * alpha
    else:
        for p in (scene.net_top_m, scene.net_bottom_m):
            u, v = camera.to_image(*p)
            cv2.circle(
                bgr, (int(round(u)), int(round(v))), 5, (30, 30, 30), -1, cv2.LINE_AA
            )
    for u, v in _scale_points(camera):
        cv2.line(bgr, (int(u) - 8, int(v)), (int(u) + 8, int(v)), (250, 250, 250), 1)
        cv2.line(bgr, (int(u), int(v) - 8), (int(u), int(v) + 8), (250, 250, 250), 1)
    return bgr


def _scale_points(camera: Camera):
    return (
        [(100.0, 30.0), (700.0, 30.0)]
        if camera.width >= 760
        else [(20.0, 20.0), (camera.width - 20.0, 20.0)]
    )


def draw_ball(
    frame: np.ndarray,
    camera: Camera,
    ball: Ball,
    x_m,
    z_m,
    angle_rad,
    supersample: int = 8,
    motion: tuple[float, float, float] | None = None,
) -> None:
    """Composite the anti-aliased ball (with marker) into ``frame`` (uint8 BGR).

    ``motion = (vx_mps, vz_mps, omega_radps)`` adds exposure blur: the ball is
    averaged over ``camera.exposure_s`` centred on the frame time (5 time samples),
    so the blurred image is centred on the true position at the frame time.
    """
    uc, vc = camera.to_image(x_m, z_m)
    r = ball.radius_m / camera.scale_m_per_px
    steps = [0.0]
    if motion is not None and camera.exposure_s > 0:
        steps = list(np.linspace(-0.5, 0.5, 5) * camera.exposure_s)
        reach = (
            np.hypot(motion[0], motion[1]) * camera.exposure_s / camera.scale_m_per_px
        )
    else:
        reach = 0.0
    u0, u1 = int(math.floor(uc - r - 2 - reach)), int(math.ceil(uc + r + 2 + reach))
    v0, v1 = int(math.floor(vc - r - 2 - reach)), int(math.ceil(vc + r + 2 + reach))
    u0c, u1c = max(u0, 0), min(u1, camera.width - 1)
    v0c, v1c = max(v0, 0), min(v1, camera.height - 1)
    if u0c > u1c or v0c > v1c:
        return
    s = supersample
    offs = (np.arange(s) + 0.5) / s - 0.5
    us = (np.arange(u0c, u1c + 1)[:, None] + offs[None, :]).ravel()[None, :]
    vs = (np.arange(v0c, v1c + 1)[:, None] + offs[None, :]).ravel()[:, None]
    hh, ww = v1c - v0c + 1, u1c - u0c + 1

    def block_mean(mask):
        return mask.reshape(hh, s, ww, s).mean(axis=(1, 3)).astype(np.float32)

    cover = np.zeros((hh, ww), np.float32)
    mcover = np.zeros((hh, ww), np.float32)
    for dt in steps:
        if motion is not None and dt != 0.0:
            ut, vt = camera.to_image(x_m + motion[0] * dt, z_m + motion[1] * dt)
            at = angle_rad + motion[2] * dt
        else:
            ut, vt, at = uc, vc, angle_rad
        du, dv = us - ut, vs - vt
        inside = du * du + dv * dv <= r * r
        # marker in world orientation: angle counter-clockwise from +x, z up (v down)
        if ball.marker == "stripe":  # band through the centre along the angle
            across = -du * math.sin(at) - dv * math.cos(at)
            mrk = np.abs(across) <= ball.marker_radius * r
        else:
            mu_ = ball.marker_offset * r * math.cos(at)
            mv_ = -ball.marker_offset * r * math.sin(at)
            mrk = (du - mu_) ** 2 + (dv - mv_) ** 2 <= (ball.marker_radius * r) ** 2
        cover += block_mean(inside)
        mcover += block_mean(mrk & inside)
    cover /= len(steps)
    mcover /= len(steps)
    patch = frame[v0c : v1c + 1, u0c : u1c + 1]
    body = np.array(ball.colour_bgr, np.float32)
    mark = np.array(ball.marker_bgr, np.float32)
    colour = (
        body[None, None, :] * (cover - mcover)[:, :, None] + mark * mcover[:, :, None]
    )
    mixed = patch.astype(np.float32) * (1.0 - cover[:, :, None]) + colour
    patch[:] = np.clip(mixed + 0.5, 0, 255).astype(frame.dtype)


def draw_net(frame, camera: Camera, scene: NetScene, ball: Ball, x_m, z_m) -> None:
    """Thin net strands from the anchors, deflected around the ball in contact."""
    top, along, normal = _net_axes(scene)
    pos = np.array([x_m, z_m])
    pen = ball.radius_m - float((pos - top) @ normal)
    pts = [np.array(scene.net_top_m)]
    if pen > 0:
        pts.append(pos - ball.radius_m * normal)
    pts.append(np.array(scene.net_bottom_m))
    uv = np.array([camera.to_image(*p) for p in pts])
    cv2.polylines(
        frame,
        [np.round(uv * 16).astype(np.int32)],
        False,
        (45, 45, 45),
        1,
        cv2.LINE_AA,
        4,
    )


def write_clip(
    path: Path,
    camera: Camera,
    ball: Ball,
    background_bgr: np.ndarray,
    poses: np.ndarray,
    rng: np.random.Generator,
    *,
    codec: str = "MJPG",
    draw=None,
    motion: np.ndarray | None = None,
) -> Path:
    """Write one video: ``poses[i] = (x_m, z_m, angle_rad)`` per frame (NaN: no ball).

    ``motion[i] = (vx_mps, vz_mps, omega_radps)`` adds exposure blur (see draw_ball).

    ``background_bgr`` is uint8; ``draw(frame, i)`` may add scene details (a net)
    before the ball is composited. Sensor noise: windows at random offsets into one
    seeded noise field, applied with saturating uint8 add/subtract (grey noise).
    """
    writer = cv2.VideoWriter(
        str(path),
        cv2.VideoWriter.fourcc(*codec),
        camera.playback_fps,
        (camera.width, camera.height),
    )
    if not writer.isOpened():
        raise RuntimeError(f"cannot open a {codec} writer for {path}")
    writer.set(cv2.VIDEOWRITER_PROP_QUALITY, camera.jpeg_quality)
    pad = 64
    field = camera.noise_sd * rng.standard_normal(
        (camera.height + pad, camera.width + pad), np.float32
    )
    field = np.repeat(np.round(field)[:, :, None], 3, axis=2)
    noise_up = np.clip(field, 0, 255).astype(np.uint8)
    noise_down = np.clip(-field, 0, 255).astype(np.uint8)
    for i, (x, z, angle) in enumerate(np.asarray(poses, float)):
        frame = background_bgr.copy()
        if draw is not None:
            draw(frame, i)
        if np.isfinite(x) and np.isfinite(z):
            blur = None if motion is None else tuple(float(m) for m in motion[i])
            draw_ball(frame, camera, ball, x, z, angle, motion=blur)
        if camera.flicker:
            t = i / camera.capture_fps
            gain = 1.0 + camera.flicker * math.sin(2 * math.pi * camera.flicker_hz * t)
            frame = cv2.convertScaleAbs(frame, alpha=gain)
        dv, du = (int(k) for k in rng.integers(0, pad, 2))
        window = (slice(dv, dv + camera.height), slice(du, du + camera.width))
        cv2.add(frame, noise_up[window], dst=frame)
        cv2.subtract(frame, noise_down[window], dst=frame)
        writer.write(frame)
    writer.release()
    return Path(path)


def _short_bounce_camera() -> Camera:
    return Camera(width=480, height=320, origin_u_px=30.0, origin_v_px=300.0)


def _short_bounce_scene() -> BounceScene:
    return BounceScene(
        plate_point_m=(0.0, 0.30),
        plate_end_x_m=0.85,
        start_m=(-0.06, 0.40),  # centre on the left border: half the ball visible
        start_velocity_mps=(1.4, 0.0),
        e_n=(0.75, 0.7, 0.65, 0.6),
        duration_s=0.45,
    )


def _drag_bounce_scene() -> BounceScene:
    return BounceScene(
        surface_deg=18.0,
        plate_point_m=(0.0, 0.40),
        plate_end_x_m=1.15,
        start_m=(-0.07, 0.55),
        start_velocity_mps=(2.0, 0.0),
        start_omega_radps=0.0,
        e_n=(0.7, 0.65, 0.6),
        duration_s=0.8,
        drag_cd=2.5,
    )


def _short_drag_bounce_scene() -> BounceScene:
    return BounceScene(
        surface_deg=18.0,
        plate_point_m=(0.0, 0.30),
        plate_end_x_m=0.66,
        start_m=(-0.06, 0.40),
        start_velocity_mps=(1.6, 0.0),
        start_omega_radps=0.0,
        e_n=(0.7, 0.65, 0.6),
        duration_s=0.55,
        drag_cd=2.5,
    )


def _strong_drag_bounce_scene() -> BounceScene:
    # cd 18.1: k = 0.35 1/m for the bundled 75 mm, 140 g ball, the drag of a light
    # ball; launched upward so that the flights are long enough to bend
    return BounceScene(
        surface_deg=18.0,
        plate_point_m=(0.0, 0.40),
        plate_end_x_m=1.40,
        start_m=(-0.07, 0.55),
        start_velocity_mps=(2.0, 1.0),
        start_omega_radps=0.0,
        e_n=(0.7, 0.65, 0.6),
        duration_s=0.9,
        drag_cd=18.1,
    )


#: clip name -> (camera factory, scene factory). ``bounce_short`` (480x320, 542
#: frames, 3 impacts) is the reduced clip the fast tests render.
PRESETS = {
    "bounce": (Camera, BounceScene),
    "net": (Camera, NetScene),
    "bounce_short": (_short_bounce_camera, _short_bounce_scene),
    "bounce_drag": (Camera, _drag_bounce_scene),
    "bounce_drag_short": (_short_bounce_camera, _short_drag_bounce_scene),
    "bounce_drag_strong": (Camera, _strong_drag_bounce_scene),
}


def render(
    name: str,
    out_dir: Path,
    *,
    frames: int | None = None,
    camera: Camera | None = None,
    ball: Ball | None = None,
    scene=None,
    seed: int = 20130,
    codec: str = "MJPG",
    extension: str = ".avi",
) -> dict:
    """Render one clip plus its calibration and truth files; returns the truth dict."""
    preset_camera, preset_scene = PRESETS.get(name, (Camera, None))
    camera = camera or preset_camera()
    scene = scene or (preset_scene() if preset_scene else None)
    ball = ball or Ball()
    if scene is None:
        scene = BounceScene() if name.startswith("bounce") else NetScene()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    n = frames or int(round(scene.duration_s * camera.capture_fps))
    times = np.arange(n) / camera.capture_fps
    if isinstance(scene, BounceScene):
        states, impacts = bounce_motion(scene, ball, times)
        in_contact, contact = np.zeros(n, bool), None
    else:
        states, in_contact, contact = net_motion(scene, ball, times)
        impacts = []
    bg = np.clip(background(camera, rng, scene) + 0.5, 0, 255).astype(np.uint8)
    path = out_dir / f"{name}{extension}"
    us, vs = camera.to_image(states[:, 0], states[:, 1])
    draw = None
    if isinstance(scene, NetScene):

        def draw(frame, i):
            draw_net(frame, camera, scene, ball, states[i, 0], states[i, 1])

    poses, motion = states[:, [0, 1, 4]], states[:, [2, 3, 5]]
    write_clip(
        path, camera, ball, bg, poses, rng, codec=codec, draw=draw, motion=motion
    )
    visible = (
        (us + ball.radius_m / camera.scale_m_per_px > 0)
        & (us - ball.radius_m / camera.scale_m_per_px < camera.width - 1)
        & (vs + ball.radius_m / camera.scale_m_per_px > 0)
        & (vs - ball.radius_m / camera.scale_m_per_px < camera.height - 1)
    )
    header = (
        "frame,t_s,x_m,z_m,vx_mps,vz_mps,angle_rad,omega_radps,u_px,v_px,"
        "visible,in_contact"
    )
    rows = np.column_stack([np.arange(n), times, states, us, vs, visible, in_contact])
    np.savetxt(
        out_dir / f"{name}.truth.csv",
        rows,
        delimiter=",",
        header=header,
        comments="",
        fmt=["%d"] + ["%.10g"] * 9 + ["%d", "%d"],
    )
    scale_pts = _scale_points(camera)
    calib = dict(
        video=path.name,
        capture_fps=camera.capture_fps,
        playback_fps=camera.playback_fps,
        scale_points_px=[*scale_pts[0], *scale_pts[1]],
        scale_length_m=(scale_pts[1][0] - scale_pts[0][0]) * camera.scale_m_per_px,
        homography_file=f"{name}.homography.json",
        note="--scale-points puts the world origin at the first scale point; the "
        "homography file uses the scene's world frame (origin at the truth's (0, 0)).",
    )
    # five reference marks inside the frame (corners of a 40 px inset and the centre)
    w, h, sc = camera.width, camera.height, camera.scale_m_per_px
    marks = [(40, h - 40), (w - 40, h - 40), (w - 40, 40), (40, 40), (w // 2, h // 2)]
    hpoints = [
        dict(
            u_px=float(u),
            v_px=float(v),
            x_m=round((u - camera.origin_u_px) * sc, 9),
            z_m=round((camera.origin_v_px - v) * sc, 9),
        )
        for u, v in marks
    ]
    _write_json(out_dir / f"{name}.homography.json", {"points": hpoints})
    _write_json(out_dir / f"{name}.calibration.json", calib)
    u_first = scale_pts[0]
    truth = dict(
        clip=path.name,
        frames=n,
        camera=asdict(camera),
        ball=dict(asdict(ball), gyration_m=ball.gyration_m),
        scene=type(scene).__name__,
        scene_parameters=_scene_parameters(scene),
        impacts=impacts,
        contact=contact,
        scale_point_origin_m=[
            float((u_first[0] - camera.origin_u_px) * camera.scale_m_per_px),
            float((camera.origin_v_px - u_first[1]) * camera.scale_m_per_px),
        ],
    )
    truth = _rounded(truth)
    _write_json(out_dir / f"{name}.truth.json", truth)
    return truth


def _scene_parameters(scene) -> dict:
    """The scene's parameters for the truth file; a bounce without drag leaves the
    drag fields out, so the committed ``bounce`` files stay byte for byte."""
    params = asdict(scene)
    if isinstance(scene, BounceScene) and scene.drag_cd == 0:
        params.pop("drag_cd")
        params.pop("air_density_kg_m3")
    return params


def clip_files(name: str, out_dir: Path, extension: str = ".avi") -> list[Path]:
    """The files :func:`render` writes for clip ``name``, in the order written."""
    out_dir = Path(out_dir)
    return [
        out_dir / f"{name}{extension}",
        out_dir / f"{name}.truth.csv",
        out_dir / f"{name}.homography.json",
        out_dir / f"{name}.calibration.json",
        out_dir / f"{name}.truth.json",
    ]


def _hard():
    """The hard clips' module (``video/hard.py``, which builds on this one)."""
    import importlib.util
    import sys

    name = "fieldkit_video_render_hard"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, HERE / "hard.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "clips",
        nargs="*",
        help=f"clips to render: {', '.join(sorted(PRESETS))}, the hard clips of "
        "video/hard.py (hard_shadow, ..., or 'hard' for all) (default: bounce net)",
    )
    parser.add_argument("--out", type=Path, default=HERE)
    parser.add_argument("--frames", type=int, default=None)
    args = parser.parse_args(argv)
    args.clips = args.clips or ["bounce", "net"]
    if "hard" in args.clips:  # every hard clip
        args.clips = [c for c in args.clips if c != "hard"] + list(_hard().NAMES)
    hard_names = [c for c in args.clips if c.startswith("hard_")]
    unknown = sorted(set(args.clips) - set(PRESETS) - set(hard_names))
    unknown += sorted(set(hard_names) - set(_hard().NAMES)) if hard_names else []
    if unknown:
        parser.error(f"unknown clip(s) {', '.join(unknown)}")
    for name in hard_names:
        hard = _hard()
        truth = hard.render_hard(name, args.out, frames=args.frames)
        print(
            f"{args.out / truth['clip']}: {truth['frames']} frames, "
            f"{len(truth.get('impacts', []))} impacts"
        )
        for path in hard.clip_files(name, args.out):
            print(f"wrote {path}")
    for name in [c for c in args.clips if c not in hard_names]:
        truth = render(name, args.out, frames=args.frames)
        print(
            f"{args.out / truth['clip']}: {truth['frames']} frames, "
            f"{len(truth['impacts'])} impacts, contact={truth['contact'] is not None}"
        )
        for path in clip_files(name, args.out):
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
