"""The compiled core: one rock's flight, impacts, sliding and stopping (numba).

:func:`run_rock` follows one rock from its start until it stops, leaves the profile or
reaches ``max_impacts``; :func:`run_rocks` runs many in parallel (``prange`` over
rocks; every random number is a function of the rock's key, so results do not depend
on threads). :mod:`fieldkit.model.reference` runs the same source in the Python
interpreter.

Arguments come in named bundles (namedtuples, built in one place,
:func:`fieldkit.model.simulate.kernel_inputs`): the rock's start (:class:`Rock`,
:class:`Rocks`), the model (:class:`KernelModel`: :class:`Profile`, the material
table with columns :data:`MATERIAL_COLUMNS`, :class:`Trees`, :class:`Effects`,
:class:`Core`), the sampled outputs (:class:`Probe`, :class:`Probes`; analysis
columns :data:`ANALYSIS_COLUMNS`), the impact rows (:class:`Record`,
:class:`Records`; columns :data:`RECORD_COLUMNS`) and the outcomes
(:class:`Outcomes`). A rock's life is three stages, :func:`fly`, :func:`impact` and
:func:`slide`, looped by a short driver; :func:`restitution` and
:func:`passive_normal_speed` are the impact laws every kernel shares.

Flight (exact, lumped mass): the centre follows ``x = x0 + vx t``,
``z = z0 + vz t - g t^2 / 2``. The signed height above the line of segment j,
``d(t) = A t^2 + B t + C``, is a quadratic; contact is its smallest root ``t >= 0``
at which ``d`` is *decreasing* (the centre meets the line from above) and ``x(t)``
lies on the segment. This excludes the root at ``t = 0`` after a rebound or a launch
(where ``d`` grows) without any time epsilon. ``x`` is monotonic in ``t``, so
segments are met in x order: the scan starts at the current segment and steps in the
direction of travel; the first segment with a contact is the contact. Roots use the
cancellation-free form ``q = -(B + sign(B) sqrt(B^2 - 4AC))/2``, ``t = q/A, C/q``.
With ``air_drag`` the flight is a chain of parabolic substeps (constant acceleration
each), handled by the same contact test.

Impact in local axes of the segment dip psi (T down-slope, N outward; §2):
``vin < 0``, ``vit``; ``vfn = -e_n vin``, ``vft = e_t vit`` with per-impact draws
``N(mean, sd)`` clipped at 0, modified by the active effects. A rebound whose normal
speed is below ``slide_vn_mps`` (or that points into the real segment) starts the
sliding/rolling phase with the tangential velocity on the segment.

Sliding (eq. 7.3): along segment j with dip psi and friction angle phi (drawn at
each segment entry), acceleration ``g (sin psi - sign(u) cos psi tan phi)``, exact
``v^2 = v0^2 + 2 a s``. A rock coming to rest stays if ``|tan psi| <= tan phi`` and
restarts down-slope otherwise. At a convex break it launches into flight with its
velocity; at a concave break it continues with the velocity projected on the new
segment (the normal component is lost). Spin while sliding is rolling, ``-u/r``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from fieldkit.model.effects import (
    affine_rebound,
    air_drag,
    angle_dependent_restitution,
    mass_loss,
    rotation_friction,
    slope_roughness,
    tree_impacts,
    velocity_scaled_restitution,
)
from fieldkit.model.effects.registry import EFFECTS, LAYOUT
from fieldkit.model.random_streams import (
    SLOT_E_N,
    SLOT_E_T,
    SLOT_FRICTION,
    SLOT_ROUGHNESS,
    SLOT_TREE,
    normal,
    uniform,
)
from fieldkit.model.results import (
    EXITED_DOWNSLOPE,
    EXITED_UPSLOPE,
    MAX_IMPACTS,
    STOPPED,
)

G = 9.81
#: Smallest increase of the dip [deg] at a vertex that launches a sliding rock (a
#: convex break): far below any surveyed break, far above the rounding of collinear
#: vertices (found by the 3-D kernel's comparison, issue 21).
CONVEX_BREAK_DEG = 1e-6
INF = math.inf
#: Columns of a recorded impact row (``R_*`` name each column's index).
RECORD_COLUMNS = (
    "t_s",
    "x_m",
    "z_m",
    "slope_deg",
    "vi_x_mps",
    "vi_z_mps",
    "vf_x_mps",
    "vf_z_mps",
    "mass_kg",
    "radius_m",
    "gyration_m",
    "omega_i_radps",
    "omega_f_radps",
    "material_index",
    "tree_strike",
)
N_RECORD = len(RECORD_COLUMNS)
R_T = RECORD_COLUMNS.index("t_s")
R_X = RECORD_COLUMNS.index("x_m")
R_Z = RECORD_COLUMNS.index("z_m")
R_SLOPE = RECORD_COLUMNS.index("slope_deg")
R_VI_X = RECORD_COLUMNS.index("vi_x_mps")
R_VI_Z = RECORD_COLUMNS.index("vi_z_mps")
R_VF_X = RECORD_COLUMNS.index("vf_x_mps")
R_VF_Z = RECORD_COLUMNS.index("vf_z_mps")
R_MASS = RECORD_COLUMNS.index("mass_kg")
R_RADIUS = RECORD_COLUMNS.index("radius_m")
R_GYRATION = RECORD_COLUMNS.index("gyration_m")
R_OMEGA_I = RECORD_COLUMNS.index("omega_i_radps")
R_OMEGA_F = RECORD_COLUMNS.index("omega_f_radps")
R_MATERIAL = RECORD_COLUMNS.index("material_index")
R_TREE = RECORD_COLUMNS.index("tree_strike")
#: Columns of an analysis-point record (``A_*`` name each column's index): crossed
#: flag (1.0), speed [m/s], translational / rotational / total kinetic energy [J],
#: centre height above the ground [m].
ANALYSIS_COLUMNS = ("crossed", "speed_mps", "ke_j", "re_j", "total_j", "height_m")
N_ANALYSIS = len(ANALYSIS_COLUMNS)
A_CROSSED = ANALYSIS_COLUMNS.index("crossed")
A_SPEED = ANALYSIS_COLUMNS.index("speed_mps")
A_KE = ANALYSIS_COLUMNS.index("ke_j")
A_RE = ANALYSIS_COLUMNS.index("re_j")
A_TOTAL = ANALYSIS_COLUMNS.index("total_j")
A_HEIGHT = ANALYSIS_COLUMNS.index("height_m")
#: Columns of the material table (one row per material; ``M_*`` name the indices).
MATERIAL_COLUMNS = (
    "e_n",
    "e_t",
    "friction_deg",
    "e_n_sd",
    "e_t_sd",
    "friction_deg_sd",
    "roughness_m",
    "roughness_deg_sd",
)
M_EN = MATERIAL_COLUMNS.index("e_n")
M_ET = MATERIAL_COLUMNS.index("e_t")
M_PHI = MATERIAL_COLUMNS.index("friction_deg")
M_EN_SD = MATERIAL_COLUMNS.index("e_n_sd")
M_ET_SD = MATERIAL_COLUMNS.index("e_t_sd")
M_PHI_SD = MATERIAL_COLUMNS.index("friction_deg_sd")
M_ROUGH = MATERIAL_COLUMNS.index("roughness_m")
M_ROUGH_SD = MATERIAL_COLUMNS.index("roughness_deg_sd")
#: Slide steps (segment passes) after which a rock is stopped as MAX_IMPACTS.
MAX_SLIDE_STEPS = 100000

# Flag indices (registry order) and parameter indices (registry layout).
_NAMES = [spec.name for spec in EFFECTS]
F_ADR = _NAMES.index("angle_dependent_restitution")
F_VSR = _NAMES.index("velocity_scaled_restitution")
F_ROT = _NAMES.index("rotation_friction")
F_ROUGH = _NAMES.index("slope_roughness")
F_MASS = _NAMES.index("mass_loss")
F_TREE = _NAMES.index("tree_impacts")
F_DRAG = _NAMES.index("air_drag")
F_AFF = _NAMES.index("affine_rebound")
P_ADR_B = LAYOUT["angle_dependent_restitution.b"]
P_ADR_REF = LAYOUT["angle_dependent_restitution.theta_ref_deg"]
P_ADR_A = LAYOUT["angle_dependent_restitution.a"]
P_VSR_K = LAYOUT["velocity_scaled_restitution.k_mps"]
P_ROT_MU = LAYOUT["rotation_friction.friction"]
P_ROT_C = LAYOUT["rotation_friction.coupling"]
P_ROUGH = LAYOUT["slope_roughness.scale"]
P_MASS_RATE = LAYOUT["mass_loss.rate_per_m"]
P_MASS_EXP = LAYOUT["mass_loss.impact_exponent"]
P_TREE_P = LAYOUT["tree_impacts.hit_probability"]
P_TREE_C = LAYOUT["tree_impacts.energy_factor"]
P_TREE_EXP = LAYOUT["tree_impacts.energy_exponent"]
P_DRAG_CD = LAYOUT["air_drag.cd"]
P_DRAG_RHO = LAYOUT["air_drag.air_density_kg_m3"]
P_AFF_BN = LAYOUT["affine_rebound.b_n_mps"]
P_AFF_BT = LAYOUT["affine_rebound.b_t_mps"]


# ---------------------------------------------------------------- named bundles
# The kernel's arguments, grouped so that no two neighbours of one type can be
# swapped silently. numba compiles namedtuples (of arrays and scalars, nested) with
# ``cache=True`` and inside ``prange``; fieldkit.model.simulate builds them.
class Rock(NamedTuple):
    """One rock's start (scalars): random key, position, velocity, spin, body."""

    key: np.uint64
    x_m: float
    z_m: float
    vx_mps: float
    vz_mps: float
    omega_radps: float
    mass_kg: float
    radius_m: float
    gyration_m: float


class Rocks(NamedTuple):
    """Many rocks' starts: the fields of :class:`Rock` as 1-D arrays (one per rock)."""

    key: np.ndarray
    x_m: np.ndarray
    z_m: np.ndarray
    vx_mps: np.ndarray
    vz_mps: np.ndarray
    omega_radps: np.ndarray
    mass_kg: np.ndarray
    radius_m: np.ndarray
    gyration_m: np.ndarray


class Profile(NamedTuple):
    """The slope: vertices ``x_m, z_m`` and per segment its slope dz/dx, the cosine,
    sine and degrees of its dip ``psi = -atan(dz/dx)`` and its material index."""

    x_m: np.ndarray
    z_m: np.ndarray
    slope: np.ndarray
    cos_psi: np.ndarray
    sin_psi: np.ndarray
    psi_deg: np.ndarray
    material: np.ndarray


class Trees(NamedTuple):
    """Trees along the profile, sorted by ``x_m`` (empty arrays for none)."""

    x_m: np.ndarray
    diameter_m: np.ndarray
    height_m: np.ndarray


class Effects(NamedTuple):
    """Effect switches ``flags`` (registry order, 1 = on) and the flat parameter
    array ``par`` (registry :data:`~fieldkit.model.effects.registry.LAYOUT`)."""

    flags: np.ndarray
    par: np.ndarray


class Core(NamedTuple):
    """The model file's ``core`` settings (floats)."""

    slide_vn_mps: float
    stop_speed_mps: float
    max_impacts: float
    drag_dt_s: float


class KernelModel(NamedTuple):
    """Everything about the model the kernel reads; ``materials`` is the material
    table (one row per material, columns :data:`MATERIAL_COLUMNS`)."""

    profile: Profile
    materials: np.ndarray
    trees: Trees
    effects: Effects
    core: Core


class Probe(NamedTuple):
    """One rock's sampled outputs, written in place: ``values`` (analysis points x
    :data:`ANALYSIS_COLUMNS`, NaN on entry) at ``x_m``; the bounce-height envelope
    ``env`` (bins of ``env_dx_m`` from ``env_x0_m``, NaN on entry; zero bins for
    none)."""

    x_m: np.ndarray
    values: np.ndarray
    env_x0_m: float
    env_dx_m: float
    env: np.ndarray


class Probes(NamedTuple):
    """:class:`Probe` of many rocks: ``values`` (rocks, points, N_ANALYSIS), ``env``
    (rocks, bins)."""

    x_m: np.ndarray
    values: np.ndarray
    env_x0_m: float
    env_dx_m: float
    env: np.ndarray


class Record(NamedTuple):
    """Impact rows (columns :data:`RECORD_COLUMNS`): one rock's impact ``i`` goes to
    ``rows[start + i]`` when ``on``."""

    rows: np.ndarray
    start: int
    on: bool


class Records(NamedTuple):
    """:class:`Record` of many rocks: rock ``i`` writes from ``rows[offsets[i]]``."""

    rows: np.ndarray
    offsets: np.ndarray
    on: bool


class Outcomes(NamedTuple):
    """Per-rock results of :func:`run_rocks`, written in place."""

    impacts: np.ndarray
    state: np.ndarray
    runout_x_m: np.ndarray


@njit(cache=True)
def descending_root(a, b, c):
    """First ``t >= 0`` with ``a t^2 + b t + c = 0``, ``2 a t + b < 0``; else inf."""
    if a == 0.0:
        if b < 0.0:
            t = -c / b
            return t if t >= 0.0 else INF
        return INF
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return INF
    sq = math.sqrt(disc)
    q = -0.5 * (b + sq) if b >= 0.0 else -0.5 * (b - sq)
    best = INF
    r1 = q / a
    if r1 >= 0.0 and 2.0 * a * r1 + b < 0.0:
        best = r1
    if q != 0.0:
        r2 = c / q
        if r2 >= 0.0 and 2.0 * a * r2 + b < 0.0 and r2 < best:
            best = r2
    return best


@njit(cache=True)
def time_to_x(x0, vx, ax, xb):
    """First ``t >= 0`` with ``x0 + vx t + ax t^2 / 2 = xb``; inf if never."""
    if ax == 0.0:
        if vx == 0.0:
            return INF
        t = (xb - x0) / vx
        return t if t >= 0.0 else INF
    a = 0.5 * ax
    c = x0 - xb
    disc = vx * vx - 4.0 * a * c
    if disc < 0.0:
        return INF
    sq = math.sqrt(disc)
    q = -0.5 * (vx + sq) if vx >= 0.0 else -0.5 * (vx - sq)
    best = INF
    r1 = q / a
    if r1 >= 0.0:
        best = r1
    if q != 0.0:
        r2 = c / q
        if 0.0 <= r2 < best:
            best = r2
    return best


@njit(cache=True)
def segment_at(px, x):
    """Segment index under ``x`` (clipped to the profile)."""
    j = np.searchsorted(px, x, side="right") - 1
    if j < 0:
        return 0
    if j > px.size - 2:
        return px.size - 2
    return j


@njit(cache=True)
def ground_z(px, pz, sl, x):
    """Ground elevation at ``x``."""
    j = segment_at(px, x)
    return pz[j] + sl[j] * (x - px[j])


@njit(cache=True)
def piece_contact(px, pz, sl, j, x0, z0, vx, vz, ax, az, tmax):
    """First contact of a constant-acceleration piece lasting at most ``tmax``.

    Returns ``(segment, t)``: ``segment >= 0`` a contact; ``-1`` none within
    ``tmax``; ``-2`` / ``-3`` the centre leaves the profile at its lower / upper end
    at time ``t``.
    """
    nseg = px.size - 1
    step = 1 if vx > 0.0 else (-1 if vx < 0.0 else 0)
    jj = j
    while True:
        s = sl[jj]
        b = vz - s * vx
        c = z0 - pz[jj] - s * (x0 - px[jj])
        if jj == j and c <= 0.0 and b <= 0.0:
            return jj, 0.0  # on (or by rounding below) the line, moving into it
        t = descending_root(0.5 * (az - s * ax), b, c)
        if t <= tmax:
            xt = x0 + vx * t + 0.5 * ax * t * t
            tol = 1e-9 * (1.0 + abs(xt))
            if px[jj] - tol <= xt <= px[jj + 1] + tol:
                return jj, t
        if step == 0:
            return -1, tmax
        boundary = px[jj + 1] if step > 0 else px[jj]
        tb = time_to_x(x0, vx, ax, boundary)
        if tb > tmax:
            return -1, tmax
        jj += step
        if jj >= nseg:
            return -2, tb
        if jj < 0:
            return -3, tb


@njit(cache=True)
def _env_put(env, env0, envdx, xq, h, edge):
    nb = env.size
    b = int(math.floor((xq - env0) / envdx))
    if 0 <= b < nb and not (env[b] >= h):
        env[b] = h
    if edge and 0 <= b - 1 < nb and not (env[b - 1] >= h):
        env[b - 1] = h


@njit(cache=True)
def _sweep_flight(x0, z0, vx, vz, ax, az, t1, px, pz, sl, m, kg, w, ana_x, ana, env0,
                  envdx, env, trace, ntr):  # fmt: skip
    """Analysis-point crossings, envelope and trace of one flight piece ``[0, t1]``."""
    x1 = x0 + vx * t1 + 0.5 * ax * t1 * t1
    lo, hi = min(x0, x1), max(x0, x1)
    for a in range(ana_x.size):
        xa = ana_x[a]
        if ana[a, A_CROSSED] == 1.0 or xa < lo or xa > hi or vx == 0.0:
            continue
        ta = time_to_x(x0, vx, ax, xa)
        if ta > t1:
            continue
        za = z0 + vz * ta + 0.5 * az * ta * ta
        vxa = vx + ax * ta
        vza = vz + az * ta
        v2 = vxa * vxa + vza * vza
        ke = 0.5 * m * v2
        re = 0.5 * m * kg * kg * w * w
        ana[a, A_CROSSED] = 1.0
        ana[a, A_SPEED] = math.sqrt(v2)
        ana[a, A_KE] = ke
        ana[a, A_RE] = re
        ana[a, A_TOTAL] = ke + re
        ana[a, A_HEIGHT] = za - ground_z(px, pz, sl, xa)
    if env.size > 0 and vx != 0.0:
        # h(x) = z(x) - ground(x) is concave on each segment: its maximum over a bin
        # is at a bin edge, a vertex, a piece end or the stationary point.
        for xq in (x0, x1):
            tq = time_to_x(x0, vx, ax, xq) if xq != x0 else 0.0
            if tq == INF:
                tq = t1
            zq = z0 + vz * tq + 0.5 * az * tq * tq
            _env_put(env, env0, envdx, xq, zq - ground_z(px, pz, sl, xq), False)
        b0 = int(math.ceil((lo - env0) / envdx))
        b1 = int(math.floor((hi - env0) / envdx))
        for b in range(max(b0, 0), min(b1, env.size) + 1):
            xq = env0 + b * envdx
            tq = time_to_x(x0, vx, ax, xq)
            if tq <= t1:
                zq = z0 + vz * tq + 0.5 * az * tq * tq
                _env_put(env, env0, envdx, xq, zq - ground_z(px, pz, sl, xq), True)
        ja = segment_at(px, lo)
        jb = segment_at(px, hi)
        for jj in range(ja, jb + 1):
            if jj > ja:
                xq = px[jj]
                tq = time_to_x(x0, vx, ax, xq)
                if tq <= t1:
                    zq = z0 + vz * tq + 0.5 * az * tq * tq
                    _env_put(env, env0, envdx, xq, zq - pz[jj], False)
            if ax == 0.0:
                xs = x0 + (vz - sl[jj] * vx) * vx / (-az)
                if lo <= xs <= hi and px[jj] <= xs <= px[jj + 1]:
                    ts = (xs - x0) / vx
                    zq = z0 + vz * ts + 0.5 * az * ts * ts
                    _env_put(env, env0, envdx, xs, zq - ground_z(px, pz, sl, xs), False)
    cap = trace.shape[0]
    if cap > 0:
        samples = 8 if ax == 0.0 else 1
        for i in range(samples):
            if ntr < cap:
                tq = t1 * i / samples
                trace[ntr, 0] = x0 + vx * tq + 0.5 * ax * tq * tq
                trace[ntr, 1] = z0 + vz * tq + 0.5 * az * tq * tq
                ntr += 1
    return ntr


@njit(cache=True)
def _sweep_slide(xa, xb, sp, ad, cpsi, m, r, kg, px, pz, sl, ana_x, ana, env0, envdx,
                 env, trace, ntr):  # fmt: skip
    """Analysis crossings, envelope (height 0) and trace of a slide from xa to xb."""
    lo, hi = min(xa, xb), max(xa, xb)
    for a in range(ana_x.size):
        xq = ana_x[a]
        if ana[a, A_CROSSED] == 1.0 or xq < lo or xq > hi:
            continue
        v2 = sp * sp + 2.0 * ad * abs(xq - xa) / cpsi
        v = math.sqrt(v2) if v2 > 0.0 else 0.0
        ke = 0.5 * m * v * v
        re = 0.5 * m * kg * kg * (v / r) ** 2
        ana[a, A_CROSSED] = 1.0
        ana[a, A_SPEED] = v
        ana[a, A_KE] = ke
        ana[a, A_RE] = re
        ana[a, A_TOTAL] = ke + re
        ana[a, A_HEIGHT] = 0.0
    if env.size > 0:
        b0 = int(math.floor((lo - env0) / envdx))
        b1 = int(math.floor((hi - env0) / envdx))
        for b in range(max(b0, 0), min(b1, env.size - 1) + 1):
            if not (env[b] >= 0.0):
                env[b] = 0.0
    if trace.shape[0] > ntr:
        trace[ntr, 0] = xa
        trace[ntr, 1] = ground_z(px, pz, sl, xa)
        ntr += 1
    return ntr


@njit(cache=True)
def _tree_struck(tx, xa, xb, key, n, p):
    """Index of the first tree strictly past ``xa`` up to ``xb`` that is struck, or -1.

    Used for rocks sliding or rolling on the ground (always below the tree top).
    """
    lo, hi = min(xa, xb), max(xa, xb)
    i0 = np.searchsorted(tx, lo, side="right")
    i1 = np.searchsorted(tx, hi, side="right")
    forward = xb > xa
    for k in range(i1 - i0):
        ii = i0 + k if forward else i1 - 1 - k
        if tx[ii] == xa:
            continue
        if uniform(key, n, SLOT_TREE + ii) < p:
            return ii
    return -1


@njit(cache=True)
def _friction_tan(mat, mi, key, n, entry):
    phi = mat[mi, M_PHI]
    if mat[mi, M_PHI_SD] > 0.0:
        phi = max(0.0, phi + mat[mi, M_PHI_SD] * normal(key, n, SLOT_FRICTION + entry))
    return math.tan(math.radians(min(phi, 89.9)))


@njit(cache=True, inline="always")
def drawn_restitution(e_n, e_n_sd, e_t, e_t_sd, key, n):
    """This impact's ``(e_n, e_t)``: the material's means with their scatter drawn
    on the impact's own slots (clipped at 0); shared by the 2-D and 3-D kernels."""
    if e_n_sd > 0.0:
        e_n = max(0.0, e_n + e_n_sd * normal(key, n, SLOT_E_N))
    if e_t_sd > 0.0:
        e_t = max(0.0, e_t + e_t_sd * normal(key, n, SLOT_E_T))
    return e_n, e_t


@njit(cache=True)
def restitution(vin, vit, e_n, e_n_mean, e_t, omega_i, r, kg, flags, par):
    """``(vfn, vft, omega_f)`` of one impact in local axes: the impact stage's laws.

    ``vfn = -e_n vin``, ``vft = e_t vit`` (eqs. 4.6, 4.7; spin after impact rolling,
    ``-vft/r``, eq. 7.5), modified by the active impact-stage effects in ``flags`` /
    ``par``: angle-dependent ``e_n`` (eq. 5.4), velocity-scaled ``vfn`` (eq. 7.1),
    rotation friction (eqs. 4.20-4.22), then the affine rebound's intercepts (the
    diagnosis's statistical alternative; the spin stays rolling, ``-vft/r``, unless
    rotation friction sets it). ``e_n``, ``e_t`` are this impact's draws,
    ``e_n_mean`` the material mean. ``vin >= 0`` (moving away from the ground) keeps
    the tangential velocity and stops the normal one. :func:`run_rock` and
    :mod:`fieldkit.fit.impact_model` both call this one function.
    """
    if vin >= 0.0:
        return 0.0, vit, -vit / r
    if flags[F_ADR] == 1:
        theta_i = math.degrees(math.atan2(-vin, abs(vit)))
        e_n = angle_dependent_restitution.normal_restitution(
            e_n, e_n_mean, theta_i, par[P_ADR_B], par[P_ADR_REF], par[P_ADR_A]
        )
    vfn = -e_n * vin
    if flags[F_VSR] == 1:
        vfn *= velocity_scaled_restitution.normal_speed_factor(vin, par[P_VSR_K])
    if flags[F_ROT] == 1:
        vft, w = rotation_friction.impact(
            vit, vin, e_t, e_n, omega_i, r, kg, par[P_ROT_MU], par[P_ROT_C]
        )
    else:
        vft = e_t * vit
        w = -vft / r
    if flags[F_AFF] == 1:
        vfn, vft = affine_rebound.rebound(vfn, vft, vit, par[P_AFF_BN], par[P_AFF_BT])
        if flags[F_ROT] != 1:
            w = -vft / r
    return vfn, vft, w


@njit(cache=True)
def passive_normal_speed(vin, vit, w_i, vfn, vft, w_f, kg):
    """The rebound normal speed ``vfn``, lowered so an impact gains no energy.

    An impact on the ground is passive: the rock's kinetic energy after it,
    translational + rotational (``v^2 + k^2 w^2`` per unit mass, ``I = m k^2``), is
    at most the energy before (thesis ch. 6: energy is lost at every impact).
    ``kg`` is the gyration radius when spin is part of the dynamics
    (``rotation_friction`` with coupling > 0), 0 when the spin is only the rolling
    bookkeeping
    ``-vft/r`` of the base model (then the rule is ``|v_f| <= |v_i|``). A
    normal coefficient above 1 is legal (thesis ch. 5: shallow impacts, where the
    tangential loss pays for it), so ``vfn`` is left alone whenever the energy
    balance allows it; otherwise it is lowered to the largest value that gains
    nothing (0 when the tangential rebound alone already holds all the energy).

    Without this a material drawn around ``e_n = 1`` (RocFall's Table 7-1
    colluvium) bounces in place for ever once its tangential speed is gone: a
    normal speed multiplied by ``N(1, sd)`` draws random-walks *up* as often as down
    (a 3750 kg block bouncing 20 m high on level ground after 400 impacts).

    Examples
    --------
    >>> passive_normal_speed(-2.0, 0.0, 0.0, 2.2, 0.0, 0.0, 0.3)  # e_n 1.1, no spin
    2.0
    >>> passive_normal_speed(-2.0, 10.0, 0.0, 2.4, 6.0, 0.0, 0.3)  # shallow: kept
    2.4
    """
    before = vin * vin + vit * vit + kg * kg * w_i * w_i
    after_t = vft * vft + kg * kg * w_f * w_f
    if vfn * vfn + after_t <= before:
        return vfn
    room = before - after_t
    return math.sqrt(room) if room > 0.0 else 0.0


@njit(cache=True)
def _flight_tree(key, n, x, z, vx, vz, ax, az, tc, px, pz, sl, tx, th, p_hit):
    """The first tree the flight piece ``[0, tc)`` passes below its top and strikes
    (one draw per tree passed): ``(index, time)``, index -1 for none."""
    x_end = x + vx * tc + 0.5 * ax * tc * tc
    lo, hi = min(x, x_end), max(x, x_end)
    i0 = np.searchsorted(tx, lo, side="right")
    i1 = np.searchsorted(tx, hi, side="right")
    tt = 0.0
    ii = i0 if vx > 0.0 else i1 - 1
    for _ in range(i1 - i0):
        tt = time_to_x(x, vx, ax, tx[ii])
        if tt < tc:
            zt = z + vz * tt + 0.5 * az * tt * tt
            above = zt - ground_z(px, pz, sl, tx[ii])
            if 0.0 < above < th[ii] and uniform(key, n, SLOT_TREE + ii) < p_hit:
                return ii, tt
        ii += 1 if vx > 0.0 else -1
    return -1, tt


@njit(cache=True, inline="always")
def fly(key, n, x, z, vx, vz, w, m, r, kg, t, j, tree_hit, px, pz, sl, tx, td, th,
        flags, par, drag_dt, ana_x, ana, env0, envdx, env, trace, ntr):  # fmt: skip
    """The flight stage: from ``(x, z)`` with ``(vx, vz)`` over segment ``j`` until
    the centre meets the profile or leaves it.

    Exact parabolas (chains of constant-acceleration substeps with ``air_drag``);
    trees passed below their top are struck with their probability
    (``tree_impacts``). Returns ``(x, z, vx, vz, t, j, tree_hit, ntr, state,
    exit_x)``: ``state`` -1 on a contact with segment ``j`` (``z`` then exactly on
    its line), else ``EXITED_*`` with ``exit_x`` the profile end left.
    """
    drag = flags[F_DRAG] == 1 and par[P_DRAG_CD] > 0.0
    trees = flags[F_TREE] == 1 and tx.size > 0 and par[P_TREE_P] > 0.0
    nseg = px.size - 1
    state = -1
    exit_x = x
    while True:
        if drag:
            k = air_drag.drag_factor(par[P_DRAG_CD], par[P_DRAG_RHO], r, m)
            tmax = air_drag.substep_s(vx, vz, k, drag_dt)
            ax, az = air_drag.substep_acceleration(vx, vz, k, G, tmax)
        else:
            ax, az, tmax = 0.0, -G, INF
        jc, tc = piece_contact(px, pz, sl, j, x, z, vx, vz, ax, az, tmax)
        if trees and vx != 0.0:
            struck, tt = _flight_tree(
                key, n, x, z, vx, vz, ax, az, tc, px, pz, sl, tx, th, par[P_TREE_P]
            )
            if struck >= 0:
                ntr = _sweep_flight(
                    x, z, vx, vz, ax, az, tt, px, pz, sl, m, kg, w, ana_x, ana, env0,
                    envdx, env, trace, ntr,
                )  # fmt: skip
                z = z + vz * tt + 0.5 * az * tt * tt
                x = tx[struck]
                vx = vx + ax * tt
                vz = vz + az * tt
                t += tt
                v = math.sqrt(vx * vx + vz * vz)
                v_new = tree_impacts.speed_after_strike(
                    v, m, td[struck], par[P_TREE_C], par[P_TREE_EXP]
                )
                scale = v_new / v if v > 0.0 else 0.0
                vx *= scale
                vz *= scale
                tree_hit = 1.0
                j = segment_at(px, x)
                continue
        ntr = _sweep_flight(
            x, z, vx, vz, ax, az, tc, px, pz, sl, m, kg, w, ana_x, ana, env0, envdx,
            env, trace, ntr,
        )  # fmt: skip
        x = x + vx * tc + 0.5 * ax * tc * tc
        z = z + vz * tc + 0.5 * az * tc * tc
        vx = vx + ax * tc
        vz = vz + az * tc
        t += tc
        if jc >= 0:
            j = jc
            z = pz[j] + sl[j] * (x - px[j])  # exactly on the line
            break
        if jc == -2:
            state = EXITED_DOWNSLOPE
            exit_x = px[nseg]
            break
        if jc == -3:
            state = EXITED_UPSLOPE
            exit_x = px[0]
            break
        j = segment_at(px, x)
    return x, z, vx, vz, t, j, tree_hit, ntr, state, exit_x


@njit(cache=True, inline="always")
def impact(key, n, x, z, vx, vz, w, t, j, m, r, kg, x0, m0, r0, k0, tree_hit, cpsi,
           spsi, psid, smat, mat, flags, par, slide_vn, rec, rec_start,
           rec_on):  # fmt: skip
    """The impact stage: impact number ``n`` of the rock at ``(x, z)`` on segment
    ``j`` with incoming ``(vx, vz)`` and spin ``w``.

    Draws ``e_n, e_t`` of the segment's material, applies ``mass_loss`` (from the
    rock's release ``x0`` and start mass, radius, gyration ``m0, r0, k0``) and
    ``slope_roughness`` (a random tilt of the dip), the rebound laws
    (:func:`restitution`, :func:`passive_normal_speed`) and writes the impact row.
    Returns ``(vx, vz, w, m, r, kg, flying, u)``: the rebound velocity when the
    rock flies on; when it starts sliding (rebound normal speed below
    ``slide_vn_mps`` or into the segment) ``flying`` False, the incoming ``(vx,
    vz)`` and ``u`` the velocity along the segment.
    """
    mi = smat[j]
    e_n, e_t = drawn_restitution(
        mat[mi, M_EN], mat[mi, M_EN_SD], mat[mi, M_ET], mat[mi, M_ET_SD], key, n
    )
    if flags[F_MASS] == 1:
        ratio = mass_loss.volume_ratio(x - x0, n, par[P_MASS_RATE], par[P_MASS_EXP])
        cube = ratio ** (1.0 / 3.0)
        m, r, kg = m0 * ratio, r0 * cube, k0 * cube
    c = cpsi[j]
    s = spsi[j]
    psi = psid[j]
    vit = vx * c - vz * s
    vin = vx * s + vz * c
    if flags[F_ROUGH] == 1:
        sd = slope_roughness.dip_sd_rad(
            mat[mi, M_ROUGH], mat[mi, M_ROUGH_SD], r, par[P_ROUGH]
        )
        if sd > 0.0:
            delta = sd * normal(key, n, SLOT_ROUGHNESS)
            for trial in range(3):
                d = delta if trial == 0 else (-delta if trial == 1 else 0.0)
                rad = math.radians(psid[j]) + d
                c2 = math.cos(rad)
                s2 = math.sin(rad)
                if vx * s2 + vz * c2 < 0.0 or trial == 2:
                    # the dip as the ImpactTable keeps it, in (-180, 180]
                    # (a steep face tilted further reads as an overhang)
                    psi = math.degrees(math.atan2(s2, c2))
                    if psi <= -180.0:
                        psi += 360.0
                    c, s = c2, s2
                    break
            vit = vx * c - vz * s
            vin = vx * s + vz * c
    w_i = w
    vfn, vft, w = restitution(vin, vit, e_n, mat[mi, M_EN], e_t, w, r, kg, flags, par)
    # spin is carried energy only where rotation_friction couples it
    k_spin = kg if flags[F_ROT] == 1 and par[P_ROT_C] > 0.0 else 0.0
    vfn = passive_normal_speed(vin, vit, w_i, vfn, vft, w, k_spin)
    vfx = vft * c + vfn * s
    vfz = -vft * s + vfn * c
    if rec_on:
        row = rec_start + n - 1
        rec[row, R_T] = t
        rec[row, R_X] = x
        rec[row, R_Z] = z
        rec[row, R_SLOPE] = psi
        rec[row, R_VI_X] = vx
        rec[row, R_VI_Z] = vz
        rec[row, R_VF_X] = vfx
        rec[row, R_VF_Z] = vfz
        rec[row, R_MASS] = m
        rec[row, R_RADIUS] = r
        rec[row, R_GYRATION] = kg
        rec[row, R_OMEGA_I] = w_i
        rec[row, R_OMEGA_F] = w
        rec[row, R_MATERIAL] = mi
        rec[row, R_TREE] = tree_hit
    vn_real = vfx * spsi[j] + vfz * cpsi[j]
    if vfn < slide_vn or vn_real <= 0.0:
        u = vfx * cpsi[j] - vfz * spsi[j]
        return vx, vz, w, m, r, kg, False, u
    return vfx, vfz, w, m, r, kg, True, 0.0


@njit(cache=True, inline="always")
def slide(key, n, x, u, t, j, m, r, kg, px, pz, sl, cpsi, spsi, psid, smat, mat, tx,
          td, flags, par, stop_v, ana_x, ana, env0, envdx, env, trace,
          ntr):  # fmt: skip
    """The slide stage (eq. 7.3): sliding / rolling from ``x`` on segment ``j`` with
    velocity ``u`` along it after impact ``n``, segment by segment (a friction draw
    at each entry), until the rock stops, leaves the profile, launches at a convex
    break or takes :data:`MAX_SLIDE_STEPS` steps; trees on the way are struck with
    their probability.

    Returns ``(x, t, j, ntr, state, tree_hit, z, vx, vz, w)``: ``state`` -1 for a
    launch, then ``z, vx, vz, w`` the take-off height, velocity and spin (zeros
    otherwise); ``tree_hit`` 1.0 when a tree was struck.
    """
    trees = flags[F_TREE] == 1 and tx.size > 0 and par[P_TREE_P] > 0.0
    nseg = px.size - 1
    state = -1
    entry = 0
    tanphi = _friction_tan(mat, smat[j], key, n, entry)
    tree_hit = 0.0
    z = vx = vz = w = 0.0
    for _ in range(MAX_SLIDE_STEPS):
        c = cpsi[j]
        s = spsi[j]
        if u > 0.0:
            dirn = 1.0
        elif u < 0.0:
            dirn = -1.0
        else:
            if abs(s) <= c * tanphi:
                state = STOPPED
                break
            dirn = 1.0 if s > 0.0 else -1.0
        sp = abs(u)
        ad = dirn * G * s - G * c * tanphi  # acceleration along travel
        length = ((px[j + 1] - x) if dirn > 0.0 else (x - px[j])) / c
        if sp == 0.0 and length <= 1e-12:
            state = STOPPED  # at rest in a notch
            break
        v2 = sp * sp + 2.0 * ad * length
        if trees:
            reach = length if v2 > 0.0 else sp * sp / (-2.0 * ad)
            ii = _tree_struck(tx, x, x + dirn * reach * c, key, n, par[P_TREE_P])
            if ii >= 0:
                d = abs(tx[ii] - x) / c
                vt2 = sp * sp + 2.0 * ad * d
                vt = math.sqrt(vt2) if vt2 > 0.0 else 0.0
                ntr = _sweep_slide(
                    x, tx[ii], sp, ad, c, m, r, kg, px, pz, sl, ana_x, ana, env0,
                    envdx, env, trace, ntr,
                )  # fmt: skip
                t += (vt - sp) / ad if ad != 0.0 else d / sp
                x = tx[ii]
                vt = tree_impacts.speed_after_strike(
                    vt, m, td[ii], par[P_TREE_C], par[P_TREE_EXP]
                )
                u = dirn * vt
                tree_hit = 1.0
                continue
        if v2 <= 0.0:
            dist = sp * sp / (-2.0 * ad)
            x_new = x + dirn * dist * c
            ntr = _sweep_slide(
                x, x_new, sp, ad, c, m, r, kg, px, pz, sl, ana_x, ana, env0, envdx,
                env, trace, ntr,
            )  # fmt: skip
            t += sp / (-ad)
            x = x_new
            u = 0.0
            continue
        ve = math.sqrt(v2)
        x_new = px[j + 1] if dirn > 0.0 else px[j]
        ntr = _sweep_slide(
            x, x_new, sp, ad, c, m, r, kg, px, pz, sl, ana_x, ana, env0, envdx, env,
            trace, ntr,
        )  # fmt: skip
        t += (ve - sp) / ad if ad != 0.0 else length / sp
        x = x_new
        jn = j + (1 if dirn > 0.0 else -1)
        if jn >= nseg:
            state = EXITED_DOWNSLOPE
            break
        if jn < 0:
            state = EXITED_UPSLOPE
            break
        u_end = dirn * ve
        # A convex break needs the dip to grow by more than rounding: collinear
        # vertices (a DEM section's, 1e-13 deg apart) would launch the rock and land
        # it again at every vertex, losing speed to e_t each time.
        if dirn > 0.0:
            convex = psid[jn] > psid[j] + CONVEX_BREAK_DEG
        else:
            convex = psid[jn] < psid[j] - CONVEX_BREAK_DEG
        if convex:
            vx = u_end * c
            vz = -u_end * s
            w = -u_end / r
            j = jn
            z = pz[j] + sl[j] * (x - px[j])
            break
        u = u_end * (c * cpsi[jn] + s * spsi[jn])  # projection on segment jn
        if abs(u) < stop_v:
            u = 0.0
        j = jn
        entry += 1
        tanphi = _friction_tan(mat, smat[j], key, n, entry)
    else:
        state = MAX_IMPACTS
    if state >= 0:
        if trace.shape[0] > ntr:
            trace[ntr, 0] = x
            trace[ntr, 1] = ground_z(px, pz, sl, x)
            ntr += 1
    else:
        # the spin of the launch: rolling at the speed of the last segment entry
        w = -u / r if u != 0.0 else w
    return x, t, j, ntr, state, tree_hit, z, vx, vz, w


@njit(cache=True, _nrt=False)
def _drive(key, x, z, vx, vz, w, m, r, kg, px, pz, sl, cpsi, spsi, psid, smat, mat, tx,
           td, th, flags, par, slide_vn, stop_v, max_imp, drag_dt, ana_x, ana, env0,
           envdx, env, rec, rec_start, rec_on, trace):  # fmt: skip
    """The stage loop of :func:`run_rock` on the bundles' fields (called from
    :func:`run_rock` and :func:`_run_rocks` only).

    Speed: the stages are inlined (``inline="always"``: a call passing some forty
    arrays per impact costs more than the impact) and this loop is compiled
    without reference counting (``_nrt=False``: it allocates nothing, and numba
    would otherwise count a reference to every array handed to an inlined stage,
    at every impact). Calls keep fewer than 30 positional arguments: beyond that
    CPython passes ``*args``, which numba's inliner refuses.
    """
    x0, m0, r0, k0 = x, m, r, kg
    max_imp = int(max_imp)
    n = 0
    t = 0.0
    ntr = 0
    tree_hit = 0.0
    state = -1
    runout = x
    j = segment_at(px, x)
    flying = True
    u = 0.0
    while state < 0:
        if flying:
            x, z, vx, vz, t, j, tree_hit, ntr, state, exit_x = fly(
                key, n, x, z, vx, vz, w, m, r, kg, t, j, tree_hit, px, pz, sl, tx, td,
                th, flags, par, drag_dt, ana_x, ana, env0, envdx, env, trace, ntr,
            )  # fmt: skip
            if state >= 0:
                runout = exit_x
                break
            if n >= max_imp:
                state = MAX_IMPACTS
                runout = x
                break
            n += 1
            vx, vz, w, m, r, kg, flying, u = impact(
                key, n, x, z, vx, vz, w, t, j, m, r, kg, x0, m0, r0, k0, tree_hit, cpsi,
                spsi, psid, smat, mat, flags, par, slide_vn, rec, rec_start, rec_on,
            )  # fmt: skip
            tree_hit = 0.0
            if trace.shape[0] > ntr:
                trace[ntr, 0] = x
                trace[ntr, 1] = z
                ntr += 1
        else:
            x, t, j, ntr, state, hit, z_l, vx_l, vz_l, w_l = slide(
                key, n, x, u, t, j, m, r, kg, px, pz, sl, cpsi, spsi, psid, smat,
                mat, tx, td, flags, par, stop_v, ana_x, ana, env0, envdx, env,
                trace, ntr,
            )  # fmt: skip
            if hit == 1.0:
                tree_hit = 1.0
            if state >= 0:
                runout = x
            else:
                z, vx, vz, w = z_l, vx_l, vz_l, w_l
                flying = True
    if state != STOPPED and trace.shape[0] > ntr:
        trace[ntr, 0] = x if state == MAX_IMPACTS else runout
        trace[ntr, 1] = z
        ntr += 1
    return n, state, runout, ntr


@njit(cache=True)
def run_rock(rock, model, probe, record, trace):
    """Follow one rock; returns ``(impacts, state, runout_x_m, trace_points)``.

    The driver of the three stages :func:`fly`, :func:`impact` and :func:`slide`.
    ``rock`` a :class:`Rock`, ``model`` a :class:`KernelModel`; outputs written in
    place: ``probe`` (:class:`Probe`), ``record`` (:class:`Record`, impact rows when
    ``record.on``) and ``trace`` (x, z points; zero rows for none).
    """
    prof, trees, effects, core = model.profile, model.trees, model.effects, model.core
    return _drive(
        rock.key, rock.x_m, rock.z_m, rock.vx_mps, rock.vz_mps, rock.omega_radps,
        rock.mass_kg, rock.radius_m, rock.gyration_m, prof.x_m, prof.z_m, prof.slope,
        prof.cos_psi, prof.sin_psi, prof.psi_deg, prof.material, model.materials,
        trees.x_m, trees.diameter_m, trees.height_m, effects.flags, effects.par,
        core.slide_vn_mps, core.stop_speed_mps, core.max_impacts, core.drag_dt_s,
        probe.x_m, probe.values, probe.env_x0_m, probe.env_dx_m, probe.env,
        record.rows, record.start, record.on, trace,
    )  # fmt: skip


@njit(cache=True)
def run_rocks(rocks, model, probes, records, out):
    """:func:`run_rock` over all ``rocks`` (:class:`Rocks`) in parallel; outputs
    written in place (``probes`` :class:`Probes`, ``records`` :class:`Records`,
    ``out`` :class:`Outcomes`)."""
    prof, trees, effects, core = model.profile, model.trees, model.effects, model.core
    _run_rocks(
        rocks.key, rocks.x_m, rocks.z_m, rocks.vx_mps, rocks.vz_mps,
        rocks.omega_radps, rocks.mass_kg, rocks.radius_m, rocks.gyration_m,
        prof.x_m, prof.z_m, prof.slope, prof.cos_psi, prof.sin_psi, prof.psi_deg,
        prof.material, model.materials, trees.x_m, trees.diameter_m, trees.height_m,
        effects.flags, effects.par, core.slide_vn_mps, core.stop_speed_mps,
        core.max_impacts, core.drag_dt_s, probes.x_m, probes.values,
        probes.env_x0_m, probes.env_dx_m, probes.env, records.rows, records.offsets,
        records.on, out.impacts, out.state, out.runout_x_m,
    )  # fmt: skip


@njit(cache=True, parallel=True)
def _run_rocks(key, x, z, vx, vz, w, m, r, kg, px, pz, sl, cpsi, spsi, psid, smat,
               mat, tx, td, th, flags, par, slide_vn, stop_v, max_imp, drag_dt, ana_x,
               ana, env0, envdx, env, rows, offsets, rec_on, impacts, states,
               runout):  # fmt: skip
    """The ``prange`` loop of :func:`run_rocks` on the bundles' fields (numba's
    ``prange`` cannot hand a tuple holding arrays to its worker function)."""
    no_trace = np.zeros((0, 2))
    for i in prange(key.size):
        n, st, ro, _ = _drive(
            key[i], x[i], z[i], vx[i], vz[i], w[i], m[i], r[i], kg[i], px, pz, sl,
            cpsi, spsi, psid, smat, mat, tx, td, th, flags, par, slide_vn, stop_v,
            max_imp, drag_dt, ana_x, ana[i], env0, envdx, env[i], rows, offsets[i],
            rec_on, no_trace,
        )  # fmt: skip
        impacts[i] = n
        states[i] = st
        runout[i] = ro


# ---------------------------------------------------------------- compile cache
#: The compiled entry points a simulation calls from Python.
ENTRY_POINTS = ("run_rocks", "run_rock")


def _cached_on_disk(dispatcher) -> bool:
    """Whether numba's cache holds machine code of ``dispatcher`` for this CPU.

    Reads numba's cache index (private API, numba 0.5x-0.6x); any surprise counts
    as "not cached", so the worst case is a needless "compiling" note.
    """
    try:
        index = dispatcher._cache._cache_file._load_index()
        magic = dispatcher.targetctx.codegen().magic_tuple()
        return any(key[1] == magic for key in index)
    except Exception:  # noqa: BLE001 -- numba internals moved: say "not cached"
        return False


def kernel_ready() -> bool:
    """True when a simulation will not compile: the kernel is loaded in this
    process or its machine code for this CPU is in numba's cache (``__pycache__``
    beside this file, keyed by its path, modification time and size).

    Examples
    --------
    >>> isinstance(kernel_ready(), bool)
    True
    """
    for name in ENTRY_POINTS:
        dispatcher = globals()[name]
        if not dispatcher.signatures and not _cached_on_disk(dispatcher):
            return False
    return True


def kernel_loaded() -> bool:
    """True when this process already holds the compiled kernel."""
    return all(globals()[name].signatures for name in ENTRY_POINTS)


def compiled_now() -> int:
    """Entry-point signatures compiled (not loaded from the cache) in this process."""
    return sum(
        sum(globals()[name].stats.cache_misses.values()) for name in ENTRY_POINTS
    )
