"""Hard synthetic clips: one failure mode of real footage each, with exact truth.

The clips of :mod:`render` are clean high-speed footage. These add what real clips
have and the clean ones lack (issue 31): a cast shadow, a dark ball on a darker ground,
long exposures with bounces inside the blurred frames, a rolling shutter, lens
distortion (and a checkerboard clip to calibrate it), a hand-held camera, phone-like
compression at 30/120/240 frames/s, a tumbling block instead of a ball, dust puffs at
the impacts, a 1000 frames/s free fall of a small ball beside a tape measure, a
tennis ball bouncing on a table (contact far shorter than a frame), and most of these
together (``hard_all``).

Camera model (one for every clip; the plain clips of :mod:`render` are its special
case). The scene is the vertical world plane ``y = 0`` (x right, z up). A pinhole
camera with focal length ``focal_px`` looks at it along +y from the distance
``focal_px * scale_m_per_px``, placed so that world (0, 0) is imaged at
``(origin_u_px, origin_v_px)`` and ``scale_m_per_px`` holds at the plane; its
principal point is the image centre ``((W - 1)/2, (H - 1)/2)`` (pixel centres at
integer u, v). Normalised coordinates are distorted by the radial model of OpenCV
(``k1, k2``; p1 = p2 = k3 = 0). A hand-held camera adds a time-dependent translation
``(cam_x, cam_y, cam_z)`` [m] and rotation (yaw about the image's v axis, pitch about
its u axis, roll about the optical axis) [rad]: a slow drift (three sinusoids per
axis at 0.15-0.8 Hz, random phases) plus shake (three at 5-12 Hz). With a rolling
shutter row ``v`` is exposed around ``t_frame + v * line_time_s``. Exposure: the
frame's light is integrated over ``exposure_s`` centred on the row's time with
``exposure_samples`` equally spaced sub-samples.

Image formation: every output pixel (4x4 super-samples for the body) is traced back
through the camera model at its own time to the world plane, where the scene is
defined: a static world texture (noise octaves, shapes, the plate or table, scale
crosses or a tape measure), a soft cast shadow on the plate (multiplies the ground:
darker, same chroma), the body (disc with marker, or a rectangle), dust particles
(Gaussian blobs of grey-brown, over the body). Sensor noise and the codec follow.
The background under the moving body is the frame's (exposure-averaged) background.

Run through ``render.py``: ``python video/render.py --out DIR hard_shadow``.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import cv2
import numpy as np

HERE = Path(__file__).resolve().parent


def _base():
    """The sibling ``render.py`` (plain clips, motion, JSON helpers)."""
    name = "fieldkit_video_render_base"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, HERE / "render.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


base = _base()
G = base.G


# ----------------------------------------------------------------------------- camera
@dataclass
class HardCamera:
    """Camera of a hard clip (see the module docstring for the model)."""

    width: int = 640
    height: int = 360
    scale_m_per_px: float = 0.002  # at the world plane, on the optical axis
    origin_u_px: float = 40.0  # nominal image position of world (0, 0)
    origin_v_px: float = 330.0
    focal_px: float = 800.0
    k1: float = 0.0
    k2: float = 0.0
    capture_fps: float = 240.0
    container_fps: float = 240.0
    exposure_s: float = 1.0 / 2000.0
    exposure_samples: int = 0  # 0: chosen from the body's speed (<= 1.5 px a sample)
    line_time_s: float = 0.0  # rolling shutter: row v is read at t + v * line_time_s
    drift_m: float = 0.0  # hand-held: sd of the slow translation drift per axis
    drift_rad: float = 0.0  # sd of the slow rotation drift per axis
    shake_m: float = 0.0  # sd of the 5-12 Hz translation shake per axis
    shake_rad: float = 0.0  # sd of the 5-12 Hz rotation shake per axis
    noise_sd: float = 2.5
    codec: str = "MJPG"
    extension: str = ".avi"
    jpeg_quality: int = 90

    @property
    def distance_m(self) -> float:
        return self.focal_px * self.scale_m_per_px

    @property
    def principal_px(self) -> tuple[float, float]:
        return (self.width - 1) / 2.0, (self.height - 1) / 2.0

    @property
    def centre_m(self) -> tuple[float, float]:
        """World (x, z) of the nominal camera centre (its foot on the plane)."""
        cx, cy = self.principal_px
        s = self.scale_m_per_px
        return (cx - self.origin_u_px) * s, (self.origin_v_px - cy) * s

    def matrix(self) -> np.ndarray:
        cx, cy = self.principal_px
        return np.array([[self.focal_px, 0, cx], [0, self.focal_px, cy], [0, 0, 1.0]])

    def distortion(self) -> np.ndarray:
        """OpenCV's ``distCoeffs`` (k1, k2, p1, p2, k3)."""
        return np.array([self.k1, self.k2, 0.0, 0.0, 0.0])

    @property
    def moves(self) -> bool:
        return any((self.drift_m, self.drift_rad, self.shake_m, self.shake_rad))


@dataclass
class Shake:
    """Hand-held camera motion: per axis, sums of sinusoids (drift + shake)."""

    freq_hz: np.ndarray  # (6, 6): axis (x, y, z, yaw, pitch, roll) x component
    amp: np.ndarray  # (6, 6)
    phase: np.ndarray  # (6, 6)

    @classmethod
    def draw(cls, camera: HardCamera, rng: np.random.Generator) -> Shake:
        freq = np.concatenate(
            [rng.uniform(0.15, 0.8, (6, 3)), rng.uniform(5.0, 12.0, (6, 3))], axis=1
        )
        sd = np.array(
            [
                [camera.drift_m] * 3 + [camera.drift_rad] * 3,
                [camera.shake_m] * 3 + [camera.shake_rad] * 3,
            ]
        ).T
        weights = rng.uniform(0.5, 1.0, (6, 6))
        # three sinusoids of amplitudes a_k have sd sqrt(sum a_k^2 / 2)
        amp = np.zeros((6, 6))
        for part in (slice(0, 3), slice(3, 6)):
            w = weights[:, part]
            amp[:, part] = w / np.sqrt(0.5 * (w * w).sum(1))[:, None]
        amp *= np.repeat(sd, 3, axis=1)
        return cls(freq, amp, rng.uniform(0, 2 * np.pi, (6, 6)))

    @classmethod
    def still(cls) -> Shake:
        zero = np.zeros((6, 6))
        return cls(zero, zero, zero)

    def pose(self, t) -> np.ndarray:
        """``(6, *t.shape)``: cam_x, cam_y, cam_z [m], yaw, pitch, roll [rad]."""
        t = np.asarray(t, float)
        arg = 2 * np.pi * self.freq_hz[:, :, None] * t.ravel()[None, None, :]
        arg += self.phase[:, :, None]
        out = (self.amp[:, :, None] * np.sin(arg)).sum(axis=1)
        return out.reshape((6, *t.shape))


def _rotation(yaw, pitch, roll):
    """Entries ``m[i][j]`` (arrays) of R = Rz(roll) Ry(yaw) Rx(pitch)."""
    cy_, sy_ = np.cos(yaw), np.sin(yaw)
    cp, sp = np.cos(pitch), np.sin(pitch)
    cr, sr = np.cos(roll), np.sin(roll)
    # Rx(pitch)
    rx = [[1, 0, 0], [0, cp, -sp], [0, sp, cp]]
    ry = [[cy_, 0, sy_], [0, 1, 0], [-sy_, 0, cy_]]
    rz = [[cr, -sr, 0], [sr, cr, 0], [0, 0, 1]]

    def mul(a, b):
        return [
            [sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)]
            for i in range(3)
        ]

    return mul(rz, mul(ry, rx))


def distort(camera: HardCamera, xn, yn):
    r2 = xn * xn + yn * yn
    f = 1.0 + camera.k1 * r2 + camera.k2 * r2 * r2
    return xn * f, yn * f


def undistort(camera: HardCamera, xd, yd, iterations: int = 6):
    """Normalised undistorted coordinates of distorted ones.

    Newton's method on the radius: ``r (1 + k1 r^2 + k2 r^4) = r_d`` from ``r = r_d``
    (converged to rounding within 6 steps for the lenses here).
    """
    xd, yd = np.asarray(xd, float), np.asarray(yd, float)
    if camera.k1 == 0 and camera.k2 == 0:
        return xd.copy(), yd.copy()
    k1, k2 = camera.k1, camera.k2
    rd = np.hypot(xd, yd)
    r = rd.copy()
    for _ in range(iterations):
        r2 = r * r
        g = r * (1.0 + k1 * r2 + k2 * r2 * r2) - rd
        r = r - g / (1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2)
    scale = np.divide(r, rd, out=np.ones_like(rd), where=rd > 0)
    return xd * scale, yd * scale


def _camera_frame(camera: HardCamera, shake: Shake, t_s):
    """Camera centre (world x, y, z) and rotation entries at times ``t_s``."""
    t_s = np.asarray(t_s, float)
    xc, zc = camera.centre_m
    if not camera.moves:
        one, zero = np.ones_like(t_s), np.zeros_like(t_s)
        m = [[one, zero, zero], [zero, one, zero], [zero, zero, one]]
        return (xc + zero, -camera.distance_m + zero, zc + zero), m
    pose = shake.pose(t_s)
    cam = (xc + pose[0], -camera.distance_m + pose[1], zc + pose[2])
    return cam, _rotation(pose[3], pose[4], pose[5])


def project(camera: HardCamera, shake: Shake, x_m, z_m, t_s, *, ideal=False):
    """World (x, z) on the plane at time ``t_s`` -> pixel (u, v).

    ``ideal``: without lens distortion (the pinhole image).
    """
    cam, m = _camera_frame(camera, shake, t_s)
    px, pz = np.asarray(x_m, float) - cam[0], np.asarray(z_m, float) - cam[2]
    q = (px, -pz, 0.0 - cam[1])  # camera axes of the nominal camera: right, down, fwd
    c = [m[i][0] * q[0] + m[i][1] * q[1] + m[i][2] * q[2] for i in range(3)]
    xn, yn = c[0] / c[2], c[1] / c[2]
    if not ideal:
        xn, yn = distort(camera, xn, yn)
    cx, cy = camera.principal_px
    return camera.focal_px * xn + cx, camera.focal_px * yn + cy


def back_project(camera: HardCamera, shake: Shake, xn, yn, t_s):
    """Undistorted normalised coordinates seen at time ``t_s`` -> world (x, z)."""
    cam, m = _camera_frame(camera, shake, t_s)
    xn, yn = np.asarray(xn, float), np.asarray(yn, float)
    q = [m[0][i] * xn + m[1][i] * yn + m[2][i] for i in range(3)]  # R^T (xn, yn, 1)
    d = (q[0], q[2], -q[1])  # nominal camera axes -> world (x, y, z)
    lam = -cam[1] / d[1]
    return cam[0] + lam * d[0], cam[2] + lam * d[2]


def pixel_to_world(camera: HardCamera, shake: Shake, u, v, t_s):
    """Pixel (u, v) at time ``t_s`` -> world (x, z) on the plane."""
    cx, cy = camera.principal_px
    xn, yn = undistort(
        camera,
        (np.asarray(u, float) - cx) / camera.focal_px,
        (np.asarray(v, float) - cy) / camera.focal_px,
    )
    return back_project(camera, shake, xn, yn, t_s)


# ----------------------------------------------------------------------------- bodies
@dataclass
class Block:
    """A rectangular block (the body is not always a ball)."""

    length_m: float = 0.12
    width_m: float = 0.07
    mass_kg: float = 1.2
    colour_bgr: tuple = (95, 125, 160)
    marker_bgr: tuple = (60, 80, 105)  # a darker face band (its orientation shows)

    @property
    def inertia_kgm2(self) -> float:
        return self.mass_kg * (self.length_m**2 + self.width_m**2) / 12.0

    @property
    def extent_m(self) -> float:
        return 0.5 * math.hypot(self.length_m, self.width_m)


@dataclass
class BlockScene:
    surface_deg: float = 8.0
    plate_point_m: tuple = (0.0, 0.10)
    start_m: tuple = (0.05, 0.55)
    start_velocity_mps: tuple = (0.7, 0.6)
    start_angle_rad: float = 0.4
    start_omega_radps: float = 9.0
    e_n: float = 0.6  # at the contact corner, along the plate normal; frictionless
    duration_s: float = 1.0


def block_corners(block: Block, angle):
    a, b = block.length_m / 2, block.width_m / 2
    q = np.array([[a, b], [-a, b], [-a, -b], [a, -b]])
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([q[:, 0] * c - q[:, 1] * s, q[:, 0] * s + q[:, 1] * c], axis=1)


def block_motion(scene: BlockScene, block: Block, times: np.ndarray):
    """Exact state of a tumbling block with frictionless corner impacts.

    Flights: parabola + constant spin. An impact happens when a corner reaches the
    plate moving into it (located by bisection to 1e-13 s); the normal impulse
    ``J = -(1 + e_n) v_cn / (1/m + (r x n)^2 / I)`` at the corner (``r`` from the
    centroid, ``v_cn`` the corner's normal velocity) sets ``v += J n / m`` and
    ``omega += J (r x n) / I``. Returns (states [x, z, vx, vz, angle, omega], impacts).
    """
    key = repr((scene, block))
    if key not in _BLOCK_CACHE:
        _BLOCK_CACHE[key] = _block_segments(scene, block)
    seg, impacts = _BLOCK_CACHE[key]
    starts = np.array([s[0] for s in seg])
    idx = np.searchsorted(starts, times, side="right") - 1
    states = np.zeros((*np.shape(times), 6))
    for k, s in enumerate(seg):
        sel = idx == k
        dt = np.asarray(times)[sel] - s[0]
        states[sel, 0] = s[1][0] + s[2][0] * dt
        states[sel, 1] = s[1][1] + s[2][1] * dt - 0.5 * G * dt * dt
        states[sel, 2] = s[2][0]
        states[sel, 3] = s[2][1] - G * dt
        states[sel, 4] = s[3] + s[4] * dt
        states[sel, 5] = s[4]
    return states, [dict(imp) for imp in impacts]


_BLOCK_CACHE: dict = {}


def _block_segments(scene: BlockScene, block: Block):
    """Flight segments (t0, position, velocity, angle, omega) and the impacts."""
    tangent, normal = base._plate_axes(scene.surface_deg)
    p0 = np.array(scene.plate_point_m)
    m, inertia = block.mass_kg, block.inertia_kgm2
    seg = [
        (
            0.0,
            np.array(scene.start_m, float),
            np.array(scene.start_velocity_mps, float),
            scene.start_angle_rad,
            scene.start_omega_radps,
        )
    ]

    def at(s, dt):
        t0, p, v, a, w = s
        return (
            p + v * dt + 0.5 * np.array([0, -G]) * dt * dt,
            v + np.array([0, -G]) * dt,
            a + w * dt,
            w,
        )

    def gaps(s, dt):
        p, _, a, _ = at(s, dt)
        return (p + block_corners(block, a) - p0) @ normal

    impacts = []
    h = 2e-4
    while True:
        s = seg[-1]
        dt, hit = 0.0, None
        while s[0] + dt < scene.duration_s:
            g0, g1 = gaps(s, dt), gaps(s, dt + h)
            j = int(np.argmin(g1))
            if g1[j] < 0 <= g0[j]:
                lo, hi = dt, dt + h
                while hi - lo > 1e-13:
                    mid = 0.5 * (lo + hi)
                    lo, hi = (lo, mid) if gaps(s, mid)[j] < 0 else (mid, hi)
                hit = (lo, j)
                break
            dt += h
        if hit is None:
            break
        dt, j = hit
        p, v, a, w = at(s, dt)
        r = block_corners(block, a)[j]
        rxn = r[0] * normal[1] - r[1] * normal[0]
        v_c = v + w * np.array([-r[1], r[0]])
        vcn = float(v_c @ normal)
        if vcn >= 0:  # grazing: no impulse needed
            seg.append((s[0] + dt + 1e-9, *at(s, dt + 1e-9)))
            continue
        jn = -(1 + scene.e_n) * vcn / (1 / m + rxn * rxn / inertia)
        vf, wf = v + jn * normal / m, w + jn * rxn / inertia
        vcf = vf + wf * np.array([-r[1], r[0]])
        contact = p + r
        impacts.append(
            base._rounded(
                dict(
                    index=len(impacts) + 1,
                    t_s=s[0] + dt,
                    x_m=p[0],
                    z_m=p[1],
                    contact_x_m=contact[0],
                    contact_z_m=contact[1],
                    corner=j,
                    vi_x_mps=v[0],
                    vi_z_mps=v[1],
                    vf_x_mps=vf[0],
                    vf_z_mps=vf[1],
                    vin_mps=float(v @ normal),
                    vit_mps=float(v @ tangent),
                    vfn_mps=float(vf @ normal),
                    vft_mps=float(vf @ tangent),
                    corner_vin_mps=vcn,
                    corner_vfn_mps=float(vcf @ normal),
                    e_n=-float(vcf @ normal) / vcn,
                    omega_i_radps=w,
                    omega_f_radps=wf,
                    impulse_ns=jn * m,
                )
            )
        )
        seg.append((s[0] + dt, p.copy(), vf, a, wf))
        if len(impacts) > 40:
            raise ValueError("block scene: more than 40 impacts; shorten it")
    return seg, impacts


# ----------------------------------------------------------------------------- layers
@dataclass
class Shadow:
    """A soft cast shadow on the plate from a directional light.

    The light travels along ``light_deg`` below the horizontal toward +x. The shadow
    centre is where the ray through the body's centre meets the plate line, drawn on
    the plate's visible top face ``face_offset_r`` radii below that line (a ground seen
    obliquely); an ellipse of ``along_r`` x ``across_r`` radii, its penumbra
    ``soft_r`` radii + ``soft_per_m`` per metre of height. The ground is multiplied by
    ``1 - strength * coverage`` (darker, same chroma). At contact it touches the body.
    """

    light_deg: float = 55.0
    strength: float = 0.65
    along_r: float = 1.4
    across_r: float = 0.6
    face_offset_r: float = 0.45
    soft_r: float = 0.08
    soft_per_m: float = 0.02


@dataclass
class Dust:
    """A dust puff at each impact: ``particles`` Gaussian blobs thrown from the contact.

    Each particle leaves the contact point at ``speed_mps`` x U(0.3, 1) in a direction
    within 80 deg of the plate normal, slowed exponentially (``stop_s``), its size
    growing from ``size_m`` by ``grow_mps``, its opacity ``opacity`` x U(0.5, 1)
    decaying with ``fade_s``; colour ``colour_bgr``. Drawn over the body.
    """

    particles: int = 50
    speed_mps: float = 2.0
    stop_s: float = 0.06
    size_m: float = 0.008
    grow_mps: float = 0.25
    opacity: float = 0.4
    fade_s: float = 0.15
    colour_bgr: tuple = (150, 170, 185)


@dataclass
class World:
    """The static world texture's look (a mean, contrast and blue cast)."""

    mean: float = 95.0
    contrast: float = 1.0
    blue: float = 10.0
    plate_level: float = 60.0
    shapes: int = 14
    tape_x_m: float | None = None  # a vertical tape measure at this x (free fall)
    tape_z_m: tuple = (0.0, 0.5)


@dataclass
class Clip:
    """One hard clip: camera, body, motion scene and layers."""

    description: str
    camera: HardCamera
    scene: object
    body: object = field(default_factory=base.Ball)
    frames: int = 240
    shadow: Shadow | None = None
    dust: Dust | None = None
    world: World = field(default_factory=World)
    surface: str = "plate"
    conditions: tuple = ()
    colour_hint: str = "orange ball with a dark spot"
    t0_s: float = 0.0  # the clip starts this long after the scene's start


# ----------------------------------------------------------------------------- motion
def motion(clip: Clip, times: np.ndarray):
    """(states, impacts) of the clip's body at ``times`` (clip time)."""
    t = np.asarray(times, float) + clip.t0_s
    if isinstance(clip.body, Block):
        states, impacts = block_motion(clip.scene, clip.body, t.ravel())
    else:
        states, impacts = base.bounce_motion(clip.scene, clip.body, t.ravel())
    impacts = [dict(imp, t_s=imp["t_s"] - clip.t0_s) for imp in impacts]
    return states.reshape((*t.shape, 6)), impacts


def body_extent_m(body) -> float:
    return body.extent_m if isinstance(body, Block) else body.radius_m


def body_outline(body, x, z, angle, n: int = 64):
    """World outline points (n, 2) of the body at one pose."""
    if isinstance(body, Block):
        a, b = body.length_m / 2, body.width_m / 2
        s = np.linspace(-1, 1, n // 4, endpoint=False)
        q = np.concatenate(
            [
                np.c_[a + 0 * s, b * s],
                np.c_[-a * s, b + 0 * s],
                np.c_[-a + 0 * s, -b * s],
                np.c_[a * s, -b + 0 * s],
            ]
        )
        c, sn = math.cos(angle), math.sin(angle)
        return np.c_[x + q[:, 0] * c - q[:, 1] * sn, z + q[:, 0] * sn + q[:, 1] * c]
    phi = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[x + body.radius_m * np.cos(phi), z + body.radius_m * np.sin(phi)]


def body_cover(body, px, pz, x, z, angle):
    """(inside, marker) boolean masks of world points (px, pz) for a body pose."""
    dx, dz = px - x, pz - z
    if isinstance(body, Block):
        c, s = np.cos(angle), np.sin(angle)
        along, across = dx * c + dz * s, -dx * s + dz * c
        inside = (np.abs(along) <= body.length_m / 2) & (
            np.abs(across) <= body.width_m / 2
        )
        marker = inside & (along > 0.3 * body.length_m)
        return inside, marker
    r = body.radius_m
    inside = dx * dx + dz * dz <= r * r
    if body.marker == "none":
        return inside, np.zeros_like(inside)
    mx = body.marker_offset * r * np.cos(angle)
    mz = body.marker_offset * r * np.sin(angle)
    marker = inside & ((dx - mx) ** 2 + (dz - mz) ** 2 <= (body.marker_radius * r) ** 2)
    return inside, marker


def shadow_factor(clip: Clip, px, pz, x, z):
    """Multiplier (<= 1) of the ground at world points for a body centre (x, z)."""
    sh = clip.shadow
    tangent, normal = base._plate_axes(clip.scene.surface_deg)
    p0 = np.array(clip.scene.plate_point_m)
    lg = math.radians(sh.light_deg)
    d = np.array([math.cos(lg), -math.sin(lg)])
    r = body_extent_m(clip.body)
    height = (x - p0[0]) * normal[0] + (z - p0[1]) * normal[1]
    lam = height / -(d @ normal)
    fx = x + lam * d[0] - sh.face_offset_r * r * normal[0]
    fz = z + lam * d[1] - sh.face_offset_r * r * normal[1]
    rel_x, rel_z = px - fx, pz - fz
    a = (rel_x * tangent[0] + rel_z * tangent[1]) / (sh.along_r * r)
    b = (rel_x * normal[0] + rel_z * normal[1]) / (sh.across_r * r)
    rho = np.sqrt(a * a + b * b)
    soft = (sh.soft_r * r + sh.soft_per_m * np.maximum(height - r, 0.0)) / (
        sh.across_r * r
    )
    cover = 1.0 / (1.0 + np.exp(np.clip((rho - 1.0) / soft, -50, 50)))
    below = (px - p0[0]) * normal[0] + (pz - p0[1]) * normal[1] <= 0.0
    return 1.0 - sh.strength * cover * below


def dust_particles(clip: Clip, impacts, rng: np.random.Generator):
    """Per impact, per particle: (t0, x0, z0, vx, vz, opacity) arrays."""
    du = clip.dust
    tangent, normal = base._plate_axes(clip.scene.surface_deg)
    rows = []
    for imp in impacts:
        ang = rng.uniform(-np.radians(80), np.radians(80), du.particles)
        speed = du.speed_mps * rng.uniform(0.3, 1.0, du.particles)
        dirs = np.outer(np.cos(ang), normal) + np.outer(np.sin(ang), tangent)
        opac = du.opacity * rng.uniform(0.5, 1.0, du.particles)
        for k in range(du.particles):
            rows.append(
                (
                    imp["t_s"],
                    imp["contact_x_m"],
                    imp["contact_z_m"],
                    speed[k] * dirs[k, 0],
                    speed[k] * dirs[k, 1],
                    opac[k],
                )
            )
    return np.array(rows, float).reshape(-1, 6)


def dust_state(clip: Clip, particles: np.ndarray, t: float):
    """Live particles at time ``t``: (x, z, size, opacity) arrays."""
    du = clip.dust
    age = t - particles[:, 0]
    live = (age >= 0) & (age < 6 * du.fade_s)
    p, age = particles[live], age[live]
    reach = du.stop_s * (1 - np.exp(-age / du.stop_s))
    x = p[:, 1] + p[:, 3] * reach
    z = p[:, 2] + p[:, 4] * reach
    return x, z, du.size_m + du.grow_mps * age, p[:, 5] * np.exp(-age / du.fade_s)


# ----------------------------------------------------------------------------- world
def scale_points_m(clip: Clip):
    """World positions of the two scale marks (crosses, or tape ticks)."""
    cam, w = clip.camera, clip.world
    s = cam.scale_m_per_px
    if w.tape_x_m is not None:
        return [(w.tape_x_m, w.tape_z_m[0] + 0.05), (w.tape_x_m, w.tape_z_m[1] - 0.05)]
    z = (cam.origin_v_px - 24) * s
    return [
        ((40 - cam.origin_u_px) * s, z),
        ((cam.width - 40 - cam.origin_u_px) * s, z),
    ]


def world_texture(clip: Clip, rng: np.random.Generator, margin: int):
    """The static world plane as a canvas: nominal pixel grid + ``margin`` around."""
    cam, look = clip.camera, clip.world
    h, w = cam.height + 2 * margin, cam.width + 2 * margin
    s = cam.scale_m_per_px
    ou, ov = cam.origin_u_px + margin, cam.origin_v_px + margin

    def to_canvas(x, z):
        return ou + np.asarray(x) / s, ov - np.asarray(z) / s

    img = np.zeros((h, w), np.float32)
    for sigma, amp in ((1.0, 14.0), (4.0, 20.0), (16.0, 30.0)):
        layer = cv2.GaussianBlur(
            rng.standard_normal((h, w)).astype(np.float32), (0, 0), sigma
        )
        img += look.contrast * amp * layer / (layer.std() + 1e-9)
    img += look.mean
    bgr = np.repeat(img[:, :, None], 3, axis=2)
    bgr[:, :, 0] += look.blue
    lo, hi = look.mean - 55 * look.contrast, look.mean + 55 * look.contrast
    for _ in range(look.shapes):  # static distractors (none ball-sized and bright)
        colour = tuple(float(c) for c in rng.uniform(max(lo, 0), hi, 3))
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
    scene = clip.scene
    tangent, normal = base._plate_axes(scene.surface_deg)
    p0 = np.array(scene.plate_point_m)
    end_x = getattr(scene, "plate_end_x_m", 1e3)
    a = p0 - 50.0 * tangent
    b = p0 + min((end_x - p0[0]) / tangent[0], 50.0) * tangent
    (ua, va), (ub, vb) = to_canvas(*a), to_canvas(*b)
    poly = np.array([[ua, va], [ub, vb], [ub, vb + 4000], [ua, va + 4000]])
    plate = np.zeros((h, w), np.uint8)
    cv2.fillPoly(plate, [np.round(poly * 16).astype(np.int32)], 255, cv2.LINE_AA, 4)
    alpha = (plate.astype(np.float32) / 255.0)[:, :, None]
    plate_tex = look.plate_level + 0.4 * (bgr - look.mean)
    bgr = bgr * (1 - alpha) + plate_tex * alpha
    bgr = np.clip(np.round(bgr), 0, 255).astype(np.uint8)
    if look.tape_x_m is not None:
        _draw_tape(bgr, clip, to_canvas)
    else:
        for x, z in scale_points_m(clip):
            u, v = to_canvas(x, z)
            cv2.line(
                bgr, (int(u) - 8, int(v)), (int(u) + 8, int(v)), (250, 250, 250), 1
            )
            cv2.line(
                bgr, (int(u), int(v) - 8), (int(u), int(v) + 8), (250, 250, 250), 1
            )
    return bgr.astype(np.float32)


def _draw_tape(bgr, clip: Clip, to_canvas) -> None:
    """A yellow tape measure: ticks every cm, longer every 5 and 10 cm."""
    look, s = clip.world, clip.camera.scale_m_per_px
    z0, z1 = look.tape_z_m
    half = 0.0125
    (u0, v0), (u1, v1) = (
        to_canvas(look.tape_x_m - half, z1),
        to_canvas(look.tape_x_m + half, z0),
    )
    cv2.rectangle(
        bgr,
        (int(round(u0)), int(round(v0))),
        (int(round(u1)), int(round(v1))),
        (40, 200, 235),
        -1,
    )
    for k in range(int(round((z1 - z0) * 100)) + 1):
        z = z0 + 0.01 * k
        length = 0.4 if k % 10 == 0 else (0.3 if k % 5 == 0 else 0.18)
        ua, v = to_canvas(look.tape_x_m - half, z)
        ub = ua + length * 2 * half / s
        vv = int(round(float(v) * 16))
        cv2.line(
            bgr,
            (int(round(float(ua) * 16)), vv),
            (int(round(float(ub) * 16)), vv),
            (20, 20, 20),
            1,
            cv2.LINE_AA,
            4,
        )
        if k % 10 == 0:
            cv2.putText(
                bgr,
                str(k),
                (int(ub) + 1, int(v) + 4),
                cv2.FONT_HERSHEY_PLAIN,
                0.7,
                (20, 20, 20),
                1,
                cv2.LINE_AA,
            )


# ----------------------------------------------------------------------------- frames
class Renderer:
    """Traces each frame's pixels through the camera model (see module docstring)."""

    SUPER = 4

    def __init__(self, clip: Clip, rng: np.random.Generator):
        self.clip, cam = clip, clip.camera
        self.shake = Shake.draw(cam, rng) if cam.moves else Shake.still()
        self.margin = 200
        self.canvas = world_texture(clip, rng, self.margin)
        cx, cy = cam.principal_px
        vv, uu = np.mgrid[0 : cam.height, 0 : cam.width].astype(float)
        self.xn, self.yn = undistort(
            cam, (uu - cx) / cam.focal_px, (vv - cy) / cam.focal_px
        )
        self.rows = np.arange(cam.height, dtype=float)
        self.static = not cam.moves and cam.k1 == 0 and cam.k2 == 0
        self._bg_static = None

    # time offsets of the exposure sub-samples for one frame
    def offsets(self, states_at) -> np.ndarray:
        cam = self.clip.camera
        n = cam.exposure_samples
        if n <= 0:
            speed = float(np.max(np.hypot(states_at[..., 2], states_at[..., 3])))
            span = speed * cam.exposure_s
            n = int(np.clip(math.ceil(span / cam.scale_m_per_px / 1.5), 1, 64))
        if n == 1:
            return np.zeros(1)
        return (np.arange(n) + 0.5) / n * cam.exposure_s - 0.5 * cam.exposure_s

    def canvas_maps(self, x, z):
        cam, s = self.clip.camera, self.clip.camera.scale_m_per_px
        mu = cam.origin_u_px + self.margin + x / s
        mv = cam.origin_v_px + self.margin - z / s
        return mu.astype(np.float32), mv.astype(np.float32)

    def background(self, t_frame: float, taus: np.ndarray) -> np.ndarray:
        cam = self.clip.camera
        if self.static:
            if self._bg_static is None:
                m = self.margin
                self._bg_static = self.canvas[m : m + cam.height, m : m + cam.width]
            return self._bg_static.copy()
        n_bg = min(len(taus), 4) if cam.moves else 1
        picks = taus[np.round(np.linspace(0, len(taus) - 1, n_bg)).astype(int)]
        if not cam.moves:
            picks = np.zeros(1)
        acc = np.zeros((cam.height, cam.width, 3), np.float32)
        for tau in picks:
            t_rows = t_frame + tau + self.rows * cam.line_time_s
            x, z = back_project(cam, self.shake, self.xn, self.yn, t_rows[:, None])
            mu, mv = self.canvas_maps(x, z)
            acc += cv2.remap(
                self.canvas, mu, mv, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT
            )
        return acc / len(picks)

    def _box(self, pts, times, pad):
        cam = self.clip.camera
        u, v = project(cam, self.shake, pts[:, 0], pts[:, 1], times)
        u0 = int(max(math.floor(u.min() - pad), 0))
        u1 = int(min(math.ceil(u.max() + pad), cam.width - 1))
        v0 = int(max(math.floor(v.min() - pad), 0))
        v1 = int(min(math.ceil(v.max() + pad), cam.height - 1))
        return v0, v1, u0, u1

    def boxes(self, t_frame, taus, dust_now):
        """Pixel boxes (v0, v1, u0, u1) of the body and of body + shadow + dust."""
        clip, cam = self.clip, self.clip.camera
        read = cam.height * cam.line_time_s
        ts = (t_frame + taus[:, None] + np.linspace(0, read, 4)[None, :]).ravel()
        st, _ = motion(clip, ts)
        ext = body_extent_m(clip.body) * 1.15
        pts = [
            np.c_[st[:, 0] + dx * ext, st[:, 1] + dz * ext]
            for dx in (-1, 1)
            for dz in (-1, 1)
        ]
        pad = 4 + 2 * abs(cam.k1) * cam.width * ext / cam.scale_m_per_px / cam.focal_px
        body_box = self._box(np.concatenate(pts), np.tile(ts, 4), pad)
        times = [ts] * 4
        if clip.shadow is not None:
            sh = clip.shadow
            tangent, normal = base._plate_axes(clip.scene.surface_deg)
            p0 = np.array(clip.scene.plate_point_m)
            lg = math.radians(sh.light_deg)
            d = np.array([math.cos(lg), -math.sin(lg)])
            height = (st[:, :2] - p0) @ normal
            lam = height / -(d @ normal)
            r = body_extent_m(clip.body)
            centre = st[:, :2] + lam[:, None] * d - sh.face_offset_r * r * normal
            reach = sh.along_r * r + 4 * (sh.soft_r * r + sh.soft_per_m * height)
            for dx in (-1, 1):
                for dz in (-1, 1):
                    pts.append(centre + np.c_[dx * reach, dz * reach])
                    times.append(ts)
        if dust_now is not None and len(dust_now[0]):
            x, z, size, _ = dust_now
            for dx in (-1, 1):
                for dz in (-1, 1):
                    pts.append(np.c_[x + dx * 3 * size, z + dz * 3 * size])
                    times.append(np.full(len(x), t_frame))
        layer_box = self._box(np.concatenate(pts), np.concatenate(times), pad)
        return body_box, layer_box

    def frame(self, i: int, particles) -> np.ndarray:
        clip, cam = self.clip, self.clip.camera
        t_frame = i / cam.capture_fps
        read = cam.height * cam.line_time_s
        probe, _ = motion(
            clip,
            t_frame
            + np.linspace(-0.5, 0.5, 5) * cam.exposure_s
            + np.linspace(0, read, 5),
        )
        taus = self.offsets(probe)
        bg = self.background(t_frame, taus)
        dust_now = None
        if clip.dust is not None:
            dust_now = dust_state(clip, particles, t_frame)
        (b0, b1, c0, c1), (v0, v1, u0, u1) = self.boxes(t_frame, taus, dust_now)
        v0, v1, u0, u1 = min(v0, b0), max(v1, b1), min(u0, c0), max(u1, c1)
        if v0 > v1 or u0 > u1:
            return bg
        s, cx, cy = self.SUPER, *cam.principal_px
        offs = (np.arange(s) + 0.5) / s - 0.5
        rows = np.arange(v0, v1 + 1, dtype=float)
        has_body = b0 <= b1 and c0 <= c1
        if has_body:
            brows = np.arange(b0, b1 + 1, dtype=float)
            bcols = np.arange(c0, c1 + 1, dtype=float)
            bh, bw = len(brows), len(bcols)
            us = (bcols[:, None] + offs[None, :]).ravel()[None, :]
            vs = (brows[:, None] + offs[None, :]).ravel()[:, None]
            xs, ys = undistort(cam, (us - cx) / cam.focal_px, (vs - cy) / cam.focal_px)
            row_of_sub = np.repeat(brows, s)[:, None]
            inner = (slice(b0 - v0, b1 - v0 + 1), slice(c0 - u0, c1 - u0 + 1))
        xp, yp = self.xn[v0 : v1 + 1, u0 : u1 + 1], self.yn[v0 : v1 + 1, u0 : u1 + 1]
        patch_bg = bg[v0 : v1 + 1, u0 : u1 + 1]
        body = np.array(clip.body.colour_bgr, np.float32)
        mark = np.array(clip.body.marker_bgr, np.float32)
        acc = np.zeros_like(patch_bg)
        for tau in taus:
            t_pix = t_frame + tau + rows[:, None] * cam.line_time_s
            col = patch_bg.copy()
            wx = wz = None
            if clip.shadow is not None or dust_now is not None:
                wx, wz = back_project(cam, self.shake, xp, yp, t_pix)
            if clip.shadow is not None:
                st_rows, _ = motion(clip, t_pix[:, 0])
                fac = shadow_factor(clip, wx, wz, st_rows[:, 0:1], st_rows[:, 1:2])
                col *= fac[:, :, None].astype(np.float32)
            if has_body:
                st_b, _ = motion(clip, t_frame + tau + brows * cam.line_time_s)
                t_sub = t_frame + tau + row_of_sub * cam.line_time_s
                sx, sz = back_project(cam, self.shake, xs, ys, t_sub)
                st_sub = np.repeat(st_b, s, axis=0)
                inside, marker = body_cover(
                    clip.body, sx, sz, st_sub[:, 0:1], st_sub[:, 1:2], st_sub[:, 4:5]
                )
                cover = inside.reshape(bh, s, bw, s).mean(axis=(1, 3))[:, :, None]
                mcov = marker.reshape(bh, s, bw, s).mean(axis=(1, 3))[:, :, None]
                cover, mcov = cover.astype(np.float32), mcov.astype(np.float32)
                col[inner] = (
                    col[inner] * (1 - cover) + body * (cover - mcov) + mark * mcov
                )
            if dust_now is not None and len(dust_now[0]):
                x, z, size, opac = dust_state(clip, particles, t_frame + tau)
                dcol = np.array(clip.dust.colour_bgr, np.float32)
                for k in range(len(x)):
                    g = opac[k] * np.exp(
                        -((wx - x[k]) ** 2 + (wz - z[k]) ** 2) / (2 * size[k] ** 2)
                    )
                    g = g.astype(np.float32)[:, :, None]
                    col = col * (1 - g) + dcol * g
            acc += col
        out = bg
        out[v0 : v1 + 1, u0 : u1 + 1] = acc / len(taus)
        return out


def write_hard_video(path: Path, clip: Clip, rng: np.random.Generator, particles):
    """Render and encode every frame; returns the exposure sample counts."""
    cam = clip.camera
    renderer = Renderer(clip, rng)
    writer = cv2.VideoWriter(
        str(path),
        cv2.VideoWriter.fourcc(*cam.codec),
        cam.container_fps,
        (cam.width, cam.height),
    )
    if not writer.isOpened():
        raise RuntimeError(f"cannot open a {cam.codec} writer for {path}")
    if cam.codec == "MJPG":
        writer.set(cv2.VIDEOWRITER_PROP_QUALITY, cam.jpeg_quality)
    pad = 64
    noise = cam.noise_sd * rng.standard_normal(
        (cam.height + pad, cam.width + pad), np.float32
    )
    noise = np.repeat(noise[:, :, None], 3, axis=2)
    for i in range(clip.frames):
        img = renderer.frame(i, particles)
        dv, du = (int(k) for k in rng.integers(0, pad, 2))
        img = img + noise[dv : dv + cam.height, du : du + cam.width]
        writer.write(np.clip(np.round(img), 0, 255).astype(np.uint8))
    writer.release()
    return renderer


# ----------------------------------------------------------------------------- clips
def _ball_scene(**kw) -> base.BounceScene:
    """A bounce scene; ``e_n`` is padded with its last value to 16 impacts."""
    e_n = tuple(kw.pop("e_n"))
    e_n = e_n + (e_n[-1],) * (16 - len(e_n))
    return base.BounceScene(
        **{**dict(start_omega_radps=0.0, friction=0.3), **kw, "e_n": e_n}
    )


def _clips() -> dict:
    clips = {}
    clips["hard_shadow"] = Clip(
        "a soft cast shadow on the plate (light 55 deg from the upper left) that "
        "follows the ball up to ~0.5 m from it and merges with it at each contact",
        HardCamera(capture_fps=240, container_fps=240),
        _ball_scene(
            surface_deg=4.0,
            plate_point_m=(0.0, 0.08),
            plate_end_x_m=5.0,
            start_m=(0.05, 0.55),
            start_velocity_mps=(0.8, 0.4),
            e_n=(0.75, 0.7, 0.65, 0.6, 0.55),
            duration_s=1.3,
        ),
        frames=288,
        shadow=Shadow(),
        world=World(plate_level=150.0),  # a light floor: the shadow shows
        conditions=("shadow", "shadow_merges_at_contact"),
    )
    dark = base.Ball(
        radius_m=0.010, mass_kg=0.01, colour_bgr=(36, 35, 34), marker_bgr=(24, 24, 24)
    )
    clips["hard_dark"] = Clip(
        "a dark 20 mm ball (grey ~35) bouncing on a darker low-contrast textured "
        "ground (mean ~24), strong low-light sensor noise",
        HardCamera(
            scale_m_per_px=0.0005,
            origin_u_px=30.0,
            origin_v_px=330.0,
            focal_px=1600.0,
            capture_fps=240,
            container_fps=30,
            noise_sd=3.0,
        ),
        _ball_scene(
            surface_deg=3.0,
            plate_point_m=(0.0, 0.01),
            plate_end_x_m=5.0,
            start_m=(0.02, 0.12),
            start_velocity_mps=(0.2, 0.2),
            e_n=(0.8, 0.78, 0.76, 0.74),
            duration_s=0.9,
        ),
        body=dark,
        frames=200,
        world=World(mean=24.0, contrast=0.22, blue=2.0, plate_level=17.0, shapes=6),
        conditions=("dark_ball", "low_contrast", "low_light_noise"),
        colour_hint="dark grey ball (~35/255) on a darker ground",
    )
    clips["hard_blur"] = Clip(
        "30 frames/s with the shutter open 3/4 of the frame interval: a fast 0.12 m "
        "ball leaves 30-40 px streaks; both floor bounces fall inside exposures, so "
        "their frames show a bent streak",
        HardCamera(
            scale_m_per_px=0.004,
            origin_u_px=30.0,
            origin_v_px=340.0,
            focal_px=600.0,
            capture_fps=30,
            container_fps=30,
            exposure_s=0.025,
            noise_sd=2.0,
        ),
        _ball_scene(
            surface_deg=0.0,
            plate_point_m=(0.0, 0.04),
            plate_end_x_m=50.0,
            start_m=(0.08, 1.05),
            start_velocity_mps=(1.45, 0.0),
            e_n=(0.8, 0.75, 0.7),
            duration_s=2.0,
        ),
        body=base.Ball(radius_m=0.06, mass_kg=0.4),
        frames=48,
        t0_s=0.0,
        surface="floor",
        conditions=("motion_blur", "bounce_inside_blurred_frame", "low_fps"),
    )
    clips["hard_rolling"] = Clip(
        "a phone-like rolling shutter: 30 frames/s, rows read over 30 ms (83 us a "
        "row), short exposure; the fast ball is sheared and displaced row by row",
        HardCamera(
            capture_fps=30,
            container_fps=30,
            exposure_s=1 / 2000,
            line_time_s=0.030 / 360,
        ),
        _ball_scene(
            surface_deg=5.0,
            plate_point_m=(0.0, 0.06),
            plate_end_x_m=5.0,
            start_m=(0.02, 0.55),
            start_velocity_mps=(0.5, 1.2),
            e_n=(0.8, 0.75, 0.7),
            duration_s=1.8,
        ),
        frames=50,
        conditions=("rolling_shutter",),
    )
    clips["hard_lens"] = Clip(
        "a wide-angle lens with barrel distortion (k1 = -0.28, k2 = 0.09 at a 420 px "
        "focal length): straight plate and paths bend near the edges",
        _lens_camera(),
        _ball_scene(
            surface_deg=10.0,
            plate_point_m=(0.0, 0.10),
            plate_end_x_m=5.0,
            start_m=(-0.02, 0.55),
            start_velocity_mps=(1.1, 0.5),
            e_n=(0.75, 0.7, 0.65, 0.6),
            duration_s=1.2,
        ),
        frames=240,
        conditions=("lens_distortion",),
    )
    clips["hard_handheld"] = Clip(
        "a hand-held phone at 120 frames/s: slow drift (8 mm, 0.8 deg sd per axis) "
        "plus 5-12 Hz shake (1.5 mm, 0.12 deg): the whole background moves",
        HardCamera(
            capture_fps=120,
            container_fps=120,
            exposure_s=1 / 1000,
            drift_m=0.008,
            drift_rad=math.radians(0.8),
            shake_m=0.0015,
            shake_rad=math.radians(0.12),
        ),
        _ball_scene(
            surface_deg=4.0,
            plate_point_m=(0.0, 0.10),
            plate_end_x_m=5.0,
            start_m=(0.05, 0.55),
            start_velocity_mps=(0.5, 0.4),
            e_n=(0.8, 0.78, 0.76, 0.74),
            duration_s=1.6,
        ),
        frames=180,
        conditions=("handheld", "camera_motion"),
    )
    for fps, frames in ((240, 240), (120, 150), (30, 45)):
        name = "hard_h264" if fps == 240 else f"hard_h264_{fps}"
        clips[name] = Clip(
            f"phone-like capture at {fps} frames/s stored at {fps} frames/s in an "
            "MPEG-4 Part 2 (mp4v) .mp4 at OpenCV's default bit rate (no H.264 "
            "encoder in opencv-python-headless here)",
            HardCamera(
                capture_fps=fps,
                container_fps=fps,
                exposure_s=min(1 / 1000, 0.5 / fps),
                codec="mp4v",
                extension=".mp4",
            ),
            _ball_scene(
                surface_deg=8.0,
                plate_point_m=(0.0, 0.10),
                plate_end_x_m=5.0,
                start_m=(0.05, 0.55),
                start_velocity_mps=(1.05 * fps / frames, 0.3),
                e_n=(0.8, 0.78, 0.76, 0.74),
                duration_s=frames / fps + 0.1,
            ),
            frames=frames,
            conditions=("compression_mp4v", f"phone_{fps}fps"),
        )
    clips["hard_block"] = Clip(
        "a tumbling 120 x 70 mm block (not a ball) with a darker end band, bouncing on "
        "its corners (frictionless corner impacts, e_n 0.6 at the corner)",
        HardCamera(capture_fps=240, container_fps=240),
        BlockScene(),
        body=Block(),
        frames=240,
        conditions=("block", "irregular_silhouette", "tumbling"),
        colour_hint="brown-grey rectangular block with a darker end",
    )
    clips["hard_dust"] = Clip(
        "a dust puff at each impact: 50 grey-brown particles thrown from the contact "
        "point, growing and fading over ~0.4 s, drawn over the ball",
        HardCamera(capture_fps=240, container_fps=240),
        _ball_scene(
            surface_deg=4.0,
            plate_point_m=(0.0, 0.10),
            plate_end_x_m=5.0,
            start_m=(0.05, 0.55),
            start_velocity_mps=(0.6, 0.4),
            e_n=(0.75, 0.7, 0.65, 0.6),
            duration_s=1.3,
        ),
        frames=288,
        dust=Dust(),
        conditions=("dust",),
    )
    small = base.Ball(
        radius_m=0.008, mass_kg=0.005, marker="none", colour_bgr=(225, 225, 230)
    )
    clips["hard_freefall"] = Clip(
        "a 16 mm white ball (radius 5.3 px) falling freely from rest beside a tape "
        "measure, 1000 frames/s stored at 30 frames/s: no contact",
        HardCamera(
            width=480,
            height=360,
            scale_m_per_px=0.0015,
            origin_u_px=60.0,
            origin_v_px=345.0,
            focal_px=1200.0,
            capture_fps=1000,
            container_fps=30,
            exposure_s=1 / 4000,
        ),
        base.BounceScene(
            surface_deg=0.0,
            plate_point_m=(0.0, -10.0),
            plate_end_x_m=1e3,
            start_m=(0.30, 0.49),
            start_velocity_mps=(0.0, 0.0),
            start_omega_radps=0.0,
            e_n=(),
            duration_s=0.4,
        ),
        body=small,
        frames=300,
        world=World(mean=80.0, tape_x_m=0.10, tape_z_m=(0.0, 0.50)),
        surface="none",
        conditions=("free_fall", "small_ball", "1000fps", "no_contact"),
        colour_hint="small white ball",
    )
    tennis = base.Ball(
        radius_m=0.0335,
        mass_kg=0.057,
        marker="stripe",
        marker_radius=0.12,
        colour_bgr=(40, 230, 205),
        marker_bgr=(215, 235, 235),
    )
    clips["hard_table"] = Clip(
        "a tennis ball bouncing on a level table at 120 frames/s (instantaneous "
        "contacts; a real one lasts ~5 ms, under the 8.3 ms frame), its shadow on the "
        "table top",
        HardCamera(
            scale_m_per_px=0.0025,
            origin_u_px=20.0,
            origin_v_px=300.0,
            capture_fps=120,
            container_fps=120,
            exposure_s=1 / 500,
        ),
        _ball_scene(
            surface_deg=0.0,
            plate_point_m=(0.0, 0.0),
            plate_end_x_m=50.0,
            start_m=(0.05, 0.68),
            start_velocity_mps=(0.55, 0.0),
            e_n=(0.75, 0.75, 0.75, 0.75, 0.75, 0.75),
            duration_s=2.1,
        ),
        body=tennis,
        frames=240,
        shadow=Shadow(light_deg=65.0, strength=0.5),
        world=World(mean=105.0, plate_level=120.0),
        surface="table",
        conditions=("table_bounce", "sub_frame_contact", "shadow"),
        colour_hint="optic yellow tennis ball with a white seam",
    )
    clips["hard_all"] = Clip(
        "shadow + motion blur (exposure 3/4 of the frame) + hand-held camera + mp4v "
        "compression + dust, at 120 frames/s",
        HardCamera(
            capture_fps=120,
            container_fps=120,
            exposure_s=0.75 / 120,
            drift_m=0.006,
            drift_rad=math.radians(0.6),
            shake_m=0.001,
            shake_rad=math.radians(0.1),
            codec="mp4v",
            extension=".mp4",
        ),
        _ball_scene(
            surface_deg=5.0,
            plate_point_m=(0.0, 0.08),
            plate_end_x_m=5.0,
            start_m=(0.05, 0.55),
            start_velocity_mps=(1.2, 0.6),
            e_n=(0.75, 0.7, 0.65, 0.6),
            duration_s=1.1,
        ),
        frames=120,
        shadow=Shadow(),
        world=World(plate_level=150.0),  # a light floor: the shadow shows
        dust=Dust(),
        conditions=("shadow", "motion_blur", "handheld", "compression_mp4v", "dust"),
    )
    return clips


def _lens_camera() -> HardCamera:
    return HardCamera(
        focal_px=420.0, k1=-0.28, k2=0.09, capture_fps=240, container_fps=240
    )


CLIPS = _clips()
#: the checkerboard calibration clip seen through ``hard_lens``'s camera
CHECKER = "hard_lens_checker"
NAMES = (*CLIPS, CHECKER)


# ----------------------------------------------------------------------------- truth
def _impact_frames(t_s: float, fps: float) -> tuple[int, int]:
    """The two frames bracketing an instantaneous contact at ``t_s``."""
    first = int(math.floor(t_s * fps))
    return first, first + 1


def render_hard(
    name: str, out_dir: Path, *, seed: int = 20131, frames=None, video: bool = True
) -> dict:
    """Render hard clip ``name`` with its truth, calibration and labels files.

    ``video=False`` writes the same files without the video (its size and bit rate
    are then None in the truth).
    """
    if name == CHECKER:
        return render_checker(out_dir, seed=seed)
    clip = CLIPS[name]
    if frames is not None:
        clip = replace(clip, frames=frames)
    cam = clip.camera
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    n = clip.frames
    times = np.arange(n) / cam.capture_fps
    states, impacts = motion(clip, times)
    impacts = [imp for imp in impacts if 0 <= imp["t_s"] <= times[-1]]
    particles = (
        dust_particles(clip, impacts, np.random.default_rng(seed + 1))
        if clip.dust is not None
        else None
    )
    path = out_dir / f"{name}{cam.extension}"
    if video:
        shake = write_hard_video(path, clip, rng, particles).shake
    else:  # the renderer's first draw from ``rng``
        shake = Shake.draw(cam, rng) if cam.moves else Shake.still()
    u, v = project(cam, shake, states[:, 0], states[:, 1], times)
    ui, vi = project(cam, shake, states[:, 0], states[:, 1], times, ideal=True)
    # rolling shutter: the ball's centre as read (the row's time solves t = t_f + v*L)
    t_rs = times.copy()
    for _ in range(30):
        st_rs, _ = motion(clip, t_rs)
        _, v_rs = project(cam, shake, st_rs[:, 0], st_rs[:, 1], t_rs)
        t_rs = times + v_rs * cam.line_time_s
    st_rs, _ = motion(clip, t_rs)
    u_rs, v_rs = project(cam, shake, st_rs[:, 0], st_rs[:, 1], t_rs)
    pose = shake.pose(times)
    visible = (u >= 0) & (u <= cam.width - 1) & (v >= 0) & (v <= cam.height - 1)
    header = (
        "frame,t_s,x_m,z_m,vx_mps,vz_mps,angle_rad,omega_radps,u_px,v_px,visible,"
        "in_contact,u_ideal_px,v_ideal_px,t_rs_s,u_rs_px,v_rs_px,cam_x_m,cam_y_m,"
        "cam_z_m,cam_yaw_rad,cam_pitch_rad,cam_roll_rad"
    )
    rows = np.column_stack(
        [
            np.arange(n),
            times,
            states,
            u,
            v,
            visible,
            np.zeros(n),
            ui,
            vi,
            t_rs,
            u_rs,
            v_rs,
            pose.T,
        ]
    )
    np.savetxt(
        out_dir / f"{name}.truth.csv",
        rows,
        delimiter=",",
        header=header,
        comments="",
        fmt=["%d"] + ["%.10g"] * 9 + ["%d", "%d"] + ["%.10g"] * 11,
    )
    scale_m = scale_points_m(clip)
    scale_px = [[float(a) for a in project(cam, shake, x, z, 0.0)] for x, z in scale_m]
    length = math.dist(*scale_m)
    # homography points of frame 0 (exact for a still, undistorted camera)
    marks = [
        (40, cam.height - 40),
        (cam.width - 40, cam.height - 40),
        (cam.width - 40, 40),
        (40, 40),
        (cam.width // 2, cam.height // 2),
    ]
    hpoints = []
    for mu, mv in marks:
        x, z = pixel_to_world(cam, shake, float(mu), float(mv), 0.0)
        hpoints.append(dict(u_px=float(mu), v_px=float(mv), x_m=float(x), z_m=float(z)))
    base._write_json(out_dir / f"{name}.homography.json", {"points": hpoints})
    base._write_json(
        out_dir / f"{name}.calibration.json",
        dict(
            video=path.name,
            capture_fps=cam.capture_fps,
            playback_fps=cam.container_fps,
            scale_points_px=[*scale_px[0], *scale_px[1]],
            scale_length_m=length,
            homography_file=f"{name}.homography.json",
            note="frame 0's camera; the homography is exact only for a still camera "
            "without lens distortion (see the truth's camera_model)",
        ),
    )
    contacts = []
    for imp in impacts:
        f0, f1 = _impact_frames(imp["t_s"], cam.capture_fps)
        contacts.append(
            dict(
                first_frame=f0,
                last_frame=min(f1, n - 1),
                kind="impact",
                surface=clip.surface,
                sub_frame=True,
                t_s=imp["t_s"],
            )
        )
    flights = []
    bounds = [-np.inf] + [imp["t_s"] for imp in impacts] + [np.inf]
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        sel = np.flatnonzero((times > a) & (times < b) & visible)
        if len(sel):
            flights.append(
                dict(first_frame=int(sel[0]), last_frame=int(sel[-1]), free=True)
            )
    first = int(np.flatnonzero(visible)[0])
    outline = body_outline(clip.body, *states[first, [0, 1, 4]])
    ou, ov = project(cam, shake, outline[:, 0], outline[:, 1], times[first])
    box = [float(ou.min()), float(ov.min()), float(np.ptp(ou)), float(np.ptp(ov))]
    size_bytes = path.stat().st_size if video else None
    bitrate = size_bytes * 8 / (n / cam.container_fps) if video else None
    body = clip.body
    if isinstance(body, Block):
        body_truth = dict(
            asdict(body),
            kind="block",
            inertia_kgm2=body.inertia_kgm2,
            extent_m=body.extent_m,
        )
        radius = body.extent_m
        description = "rectangular block, centroid tracked"
    else:
        body_truth = dict(asdict(body), kind="ball", gyration_m=body.gyration_m)
        radius = body.radius_m
        description = "ball"
    truth = dict(
        clip=path.name,
        frames=n,
        description=clip.description,
        conditions=list(clip.conditions),
        camera=asdict(cam),
        camera_model=dict(
            matrix=cam.matrix().tolist(),
            distortion=cam.distortion().tolist(),
            distance_m=cam.distance_m,
            centre_m=list(cam.centre_m),
            principal_px=list(cam.principal_px),
            shake=dict(
                freq_hz=shake.freq_hz.tolist(),
                amp=shake.amp.tolist(),
                phase_rad=shake.phase.tolist(),
            ),
            rolling_readout_s=cam.height * cam.line_time_s,
            exposure_samples_note="0: per frame, ceil(speed * exposure / 1.5 px)",
        ),
        capture_fps=cam.capture_fps,
        container_fps=cam.container_fps,
        video_bytes=size_bytes,
        video_bit_rate_bps=bitrate,
        ball=body_truth,
        scene=type(clip.scene).__name__,
        scene_parameters=asdict(clip.scene),
        shadow=None if clip.shadow is None else asdict(clip.shadow),
        dust=None if clip.dust is None else asdict(clip.dust),
        dust_particles=None if particles is None else particles.tolist(),
        world=asdict(clip.world),
        time_offset_s=clip.t0_s,
        impacts=impacts,
        contact=None,
        contacts=contacts,
        flights=flights,
        scale_points_m=[list(p) for p in scale_m],
        scale_point_origin_m=list(scale_m[0]),
    )
    base._write_json(out_dir / f"{name}.truth.json", truth)
    labels = dict(
        clip=name,
        file=path.name,
        frames=n,
        container_fps=cam.container_fps,
        capture_fps=cam.capture_fps,
        capture_fps_sd=0,
        capture_fps_how="rendered",
        size_px=[cam.width, cam.height],
        scale=dict(
            points_px=scale_px,
            length_m=length,
            length_sd_m=0,
            how="rendered scale marks, imaged in frame 0",
        ),
        body=dict(
            description=description,
            radius_m=radius,
            radius_sd_m=0,
            colour_hint=clip.colour_hint,
            first_box_px=box,
            first_box_frame=first,
        ),
        contacts=[
            {
                k: c[k]
                for k in ("first_frame", "last_frame", "kind", "surface", "sub_frame")
            }
            for c in contacts
        ],
        flights=flights,
        conditions=list(clip.conditions),
        label_uncertainty_frames=0,
        notes=clip.description + ". Rendered by video/hard.py; exact truth in "
        f"{name}.truth.json/.csv. A contact is instantaneous: first/last_frame are the "
        "two frames bracketing its time.",
    )
    base._write_json(out_dir / f"{name}.labels.json", labels)
    return base._rounded(truth)


# ----------------------------------------------------------------------------- checker
CHECKER_SHAPE = (9, 6)  # inner corners (columns, rows)
CHECKER_SQUARE_M = 0.03


def checker_poses(rng: np.random.Generator, views: int = 16):
    """Board poses (rotation vector, translation) in front of the lens camera."""
    poses = []
    for k in range(views):
        rx, ry = rng.uniform(-0.45, 0.45, 2)
        rz = rng.uniform(-0.3, 0.3)
        dist = rng.uniform(0.30, 0.42)
        # board centre spread over the image (normalised offsets up to ~0.45)
        ox, oy = rng.uniform(-0.38, 0.38), rng.uniform(-0.22, 0.22)
        if k == 0:
            rx = ry = rz = ox = oy = 0.0
        poses.append((np.array([rx, ry, rz]), np.array([ox * dist, oy * dist, dist])))
    return poses


def render_checker(out_dir: Path, *, seed: int = 20131, views: int = 16) -> dict:
    """The calibration clip: a checkerboard in ``views`` poses through hard_lens."""
    cam = _lens_camera()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed + 7)
    poses = checker_poses(rng, views)
    nx, ny = CHECKER_SHAPE
    sq = CHECKER_SQUARE_M
    # board plane coordinates: origin at the board centre, corners on a grid
    obj = np.zeros((nx * ny, 3))
    obj[:, :2] = np.mgrid[0:nx, 0:ny].T.reshape(-1, 2) * sq
    obj[:, 0] -= (nx - 1) * sq / 2
    obj[:, 1] -= (ny - 1) * sq / 2
    cx, cy = cam.principal_px
    s = 3
    offs = (np.arange(s) + 0.5) / s - 0.5
    us = (np.arange(cam.width)[:, None] + offs[None, :]).ravel()[None, :]
    vs = (np.arange(cam.height)[:, None] + offs[None, :]).ravel()[:, None]
    xn, yn = undistort(cam, (us - cx) / cam.focal_px, (vs - cy) / cam.focal_px)
    xn, yn = np.broadcast_arrays(xn, yn)
    path = out_dir / f"{CHECKER}.avi"
    writer = cv2.VideoWriter(
        str(path), cv2.VideoWriter.fourcc(*"MJPG"), 30.0, (cam.width, cam.height)
    )
    writer.set(cv2.VIDEOWRITER_PROP_QUALITY, 95)
    corners = []
    # the board's outline (sampled densely: its edges bulge) to box the work in
    edge = np.linspace(-1, 1, 41)
    hx, hy = (nx + 3) * sq / 2, (ny + 3) * sq / 2
    outline = np.concatenate(
        [
            np.c_[hx * edge, -hy + 0 * edge],
            np.c_[hx * edge, hy + 0 * edge],
            np.c_[-hx + 0 * edge, hy * edge],
            np.c_[hx + 0 * edge, hy * edge],
        ]
    )
    outline = np.c_[outline, np.zeros(len(outline))]
    for rvec, tvec in poses:
        rot, _ = cv2.Rodrigues(rvec)
        box, _ = cv2.projectPoints(outline, rvec, tvec, cam.matrix(), cam.distortion())
        box = box.reshape(-1, 2)
        c0 = int(np.clip(np.floor(box[:, 0].min()) - 3, 0, cam.width - 1))
        c1 = int(np.clip(np.ceil(box[:, 0].max()) + 3, 0, cam.width - 1))
        r0 = int(np.clip(np.floor(box[:, 1].min()) - 3, 0, cam.height - 1))
        r1 = int(np.clip(np.ceil(box[:, 1].max()) + 3, 0, cam.height - 1))
        bx_n = xn[r0 * s : (r1 + 1) * s, c0 * s : (c1 + 1) * s]
        by_n = yn[r0 * s : (r1 + 1) * s, c0 * s : (c1 + 1) * s]
        # ray (xn, yn, 1) meets the board plane n.(X - t) = 0, n = R e3
        nrm = rot[:, 2]
        lam = (nrm @ tvec) / (nrm[0] * bx_n + nrm[1] * by_n + nrm[2])
        # board coordinates R^T (lam (xn, yn, 1) - t)
        bx = lam * (rot[0, 0] * bx_n + rot[1, 0] * by_n + rot[2, 0]) - rot[:, 0] @ tvec
        by = lam * (rot[0, 1] * bx_n + rot[1, 1] * by_n + rot[2, 1]) - rot[:, 1] @ tvec
        i = np.floor((bx + nx * sq / 2) / sq + 0.5)
        j = np.floor((by + ny * sq / 2) / sq + 0.5)
        on_board = (np.abs(bx) < (nx + 1) * sq / 2) & (np.abs(by) < (ny + 1) * sq / 2)
        white = ((i + j) % 2 == 0) | ~on_board
        border = (np.abs(bx) < hx) & (np.abs(by) < hy)
        level = np.where(white, 215.0, 30.0)
        level = np.where(border, level, 120.0)
        grey = np.full((cam.height, cam.width), 120.0)
        grey[r0 : r1 + 1, c0 : c1 + 1] = level.reshape(
            r1 - r0 + 1, s, c1 - c0 + 1, s
        ).mean(axis=(1, 3))
        grey = grey + 2.0 * rng.standard_normal(grey.shape)
        img = np.repeat(
            np.clip(np.round(grey), 0, 255).astype(np.uint8)[:, :, None], 3, 2
        )
        writer.write(img)
        img_pts, _ = cv2.projectPoints(obj, rvec, tvec, cam.matrix(), cam.distortion())
        corners.append(img_pts.reshape(-1, 2).tolist())
    writer.release()
    truth = dict(
        clip=path.name,
        frames=views,
        description="checkerboard calibration views through hard_lens's camera",
        camera=asdict(cam),
        camera_matrix=cam.matrix().tolist(),
        distortion=cam.distortion().tolist(),
        pattern_size=list(CHECKER_SHAPE),
        square_m=sq,
        object_points_m=obj.tolist(),
        views=[
            dict(rvec=r.tolist(), tvec=t.tolist(), corners_px=c)
            for (r, t), c in zip(poses, corners, strict=True)
        ],
        note="corner order: OpenCV's (columns fastest); the board's origin is its "
        "centre; the first view faces the camera squarely",
    )
    base._write_json(out_dir / f"{CHECKER}.truth.json", truth)
    return base._rounded(truth)


def clip_files(name: str, out_dir: Path) -> list[Path]:
    out_dir = Path(out_dir)
    if name == CHECKER:
        return [out_dir / f"{CHECKER}.avi", out_dir / f"{CHECKER}.truth.json"]
    ext = CLIPS[name].camera.extension
    return [out_dir / f"{name}{ext}"] + [
        out_dir / f"{name}.{k}"
        for k in (
            "truth.csv",
            "homography.json",
            "calibration.json",
            "truth.json",
            "labels.json",
        )
    ]
