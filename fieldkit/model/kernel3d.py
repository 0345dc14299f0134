"""The compiled 3-D core: one rock's flight, impacts and sliding on a DEM (numba).

The ground is the bilinear surface between DEM cell centres
(:mod:`fieldkit.model.terrain`); the rock is a lumped mass (its centre meets the
surface), as in 2-D (:mod:`fieldkit.model.kernel`), whose impact laws it shares.

Flight (exact contact): the centre follows ``p(t) = p0 + v0 t - (0, 0, g t^2/2)``
(no air drag in 3-D yet). Over one bilinear patch (the square between four centres)
the surface along the path is a quadratic in ``t`` (``x``, ``y`` are linear in
``t`` and the surface is bilinear), so the height above it ``d(t)`` is a quadratic:
the contact is its descending root (the root at which ``d`` decreases:
:func:`fieldkit.model.kernel.descending_root`) lying in the time the path spends
over the patch. Patches are walked in the order the path's plan projection crosses
them (a grid traversal), so the first contact found is the first contact: no step
size and no bisection, the contact is exact to rounding. A path crossing into a
patch beside nodata or off the grid leaves the DEM there (state ``EXITED``).

Impact in local axes: ``N`` the surface normal at the contact (``slope_roughness``:
tilted by two independent angles ``N(0, sd)``, in the plane of incidence and across
it, ``sd`` as in 2-D; the mirror draw, then no tilt, when the tilted surface faces
away from the rock), ``T`` the direction of the tangential velocity (in the plane of
incidence; ``vit = |v_t| >= 0``). The 2-D :func:`~fieldkit.model.kernel.restitution`
and :func:`~fieldkit.model.kernel.passive_normal_speed` give the rebound's normal and
tangential speeds and spin; the rebound is ``vfn N + vft T``, so the lateral
direction of the tangential velocity is kept. Spin is a scalar about the axis
across the direction of travel (the lumped-mass bookkeeping of 2-D: rolling
``-v/r``); it is carried from impact to impact whatever the change of direction.

Sliding/rolling (eq. 7.3 in 3-D): on the surface under gravity projected on the
tangent plane and Coulomb friction ``g n_z tan(phi)`` opposite the velocity
(``tan phi`` drawn per DEM cell entered, as 2-D draws it per segment), stepped
with the exact constant-acceleration update over steps of at most
:data:`SLIDE_STEP_CELLS` cells (and half the sampling distance), each ended at the
next patch edge it reaches (the surface's slope jumps there, as at a 2-D vertex;
the step ends :data:`EDGE_NUDGE` cell past it). After each step the rock is put
back on the surface and its velocity projected on the new tangent plane (the normal
component is lost, as at a 2-D concave break). The rock flies (the 2-D convex
break) at an edge where its velocity points away from the new tangent plane fast
enough to rise more than :data:`LAUNCH_GAP_M` off it, or when a free (ballistic)
step inside a patch would end more than :data:`LAUNCH_GAP_M` above the surface. A
rock slower than ``stop_speed_mps`` stays if ``|g_t| <= g n_z tan(phi)`` (the 2-D
rest test) and otherwise restarts down the fall line -- unless that step from rest
ends where the ground rises along it (the fall lines meet within one step: a notch,
where it stays, as in 2-D); friction bringing it to rest within a step ends the step
there. On a patch edge or a centre the slope is that of the patch the velocity
points into (the mean of the patches there along an axis it has no component on). A
rock that crosses into a groove (a patch edge with the ground rising on both sides)
with too little speed across it to climb the far flank by one slide step follows the
groove's line (gravity along it, friction from gravity across it: the 2-D law on
that line) until the groove opens -- without this it would zigzag across the edge in
ever shorter steps. On an inclined plane and along a groove the scheme is exact; on
a profile extruded along y it follows the 2-D kernel's exact slide
(tests/model/test_kernel3d.py).

Trees (``tree_impacts``, thesis §6.6): a stem stands at ``(x, y)`` with trunk
diameter ``d`` and a top ``height`` above the ground at the stem. The rock strikes
it where its centre enters the vertical cylinder of radius ``d/2 + r`` about the
stem below the top -- through the side, or through the top while over the disc
(:func:`stem_struck`). In flight the plan projection is a straight line (no drag)
and the height a parabola in time, so the entry is a root of two quadratics, exact
like the contact; a slide step is short and is taken along its chord, the speed at
the strike from ``v^2`` linear along the step (exact on a plane). At the strike the
trunk takes the 2-D law's energy
(:func:`fieldkit.model.effects.tree_impacts.speed_after_strike`, capped at the
kinetic energy), the direction of travel and the spin are kept, and the rock flies
or slides on from there; the stem just struck is passed through (as 2-D passes
the tree), and can be struck again only after the rock has left its disc. The
strike is geometric and certain: ``hit_probability`` must be 1 in 3-D
(:func:`fieldkit.model.simulate3d.tree_hit_probability` says why). Stems are
binned into the DEM's cells (:func:`stems_of`) and only the cells within
``max(d)/2 + r`` of a piece's plan segment are searched, so a rock far from the
trees pays for the empty cells around it, not for the number of trees. The next
impact row is flagged ``tree_strike``.

Impact rows (:data:`IMPACT_COLUMNS`, written when recording): the contact, the
local-axes speeds, N and T in DEM axes, the body, the tree-strike flag, and the time
since the release (each flight's contact and strike times are exact; a slide adds
the duration of its steps, exact on a plane, and a strike within a step the time to
it with the speed linear in time along the chord).
:func:`fieldkit.model.results3d.impact_table3d` makes them an ImpactTable.

Randomness: every draw is ``f(key, impact number, slot)``
(:mod:`fieldkit.model.random_streams`, the 2-D slots; the tilt across the plane of
incidence uses :data:`SLOT_ROUGHNESS_LATERAL`), so threads and chunks do not change
results; tree strikes draw nothing. ``mass_loss`` uses the plan distance from the
release point (2-D: the horizontal distance). Not yet in 3-D: ``air_drag``
(:data:`NOT_IN_3D`; :func:`fieldkit.model.simulate3d.simulate3d` refuses it).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, prange

from fieldkit.model.effects import mass_loss, slope_roughness, tree_impacts
from fieldkit.model.effects.registry import EFFECTS, LAYOUT
from fieldkit.model.kernel import (
    MATERIAL_COLUMNS,
    descending_root,
    drawn_restitution,
    passive_normal_speed,
    restitution,
    time_to_x,
)
from fieldkit.model.random_streams import (
    SLOT_FRICTION,
    SLOT_ROUGHNESS,
    normal,
)
from fieldkit.model.results import EXITED_DOWNSLOPE, MAX_IMPACTS, STOPPED
from fieldkit.model.terrain import surface_at

G = 9.81
INF = math.inf
#: A rock that left the DEM (or reached nodata): the 2-D "exited" code.
EXITED = EXITED_DOWNSLOPE
#: Effects the 3-D kernel does not apply yet (a model enabling one is refused).
NOT_IN_3D = ("air_drag",)
#: Normal draw slot of the roughness tilt across the plane of incidence (uniforms
#: 6 and 7 of an impact; the 2-D slots use 0-5, 200+ and 2000+).
SLOT_ROUGHNESS_LATERAL = 3
#: Longest slide step, in DEM cells travelled.
SLIDE_STEP_CELLS = 0.1
#: A free step ending this far above the surface launches a sliding rock [m].
LAUNCH_GAP_M = 1e-4
#: A slide step ending on a patch edge ends this fraction of a cell past it.
EDGE_NUDGE = 1e-9
#: Slide steps after which a rock is stopped as capped.
MAX_SLIDE_STEPS = 1_000_000

_NAMES = [spec.name for spec in EFFECTS]
F_ROUGH = _NAMES.index("slope_roughness")
F_ROT = _NAMES.index("rotation_friction")
F_MASS = _NAMES.index("mass_loss")
F_TREE = _NAMES.index("tree_impacts")
P_TREE_C = LAYOUT["tree_impacts.energy_factor"]
P_TREE_EXP = LAYOUT["tree_impacts.energy_exponent"]
P_MASS_RATE = LAYOUT["mass_loss.rate_per_m"]
P_MASS_EXP = LAYOUT["mass_loss.impact_exponent"]
P_ROUGH = LAYOUT["slope_roughness.scale"]
P_ROT_C = LAYOUT["rotation_friction.coupling"]
#: Material table columns (as the 2-D kernel's).
# the 2-D kernel's material table, column for column
M_EN, M_ET, M_PHI, M_EN_SD, M_ET_SD, M_PHI_SD, M_ROUGH, M_ROUGH_SD = range(
    len(MATERIAL_COLUMNS)
)

#: The ground: the terrain grid (:data:`fieldkit.model.terrain.Grid` fields) and the
#: material index of every cell (int64, the grid's shape).
Ground = namedtuple("Ground", ("z", "xc0", "yc0", "cell", "mat_index"))
#: Run settings: slide_vn, stop speed, max impacts, sampling distance, slide step.
Settings = namedtuple(
    "Settings", ("slide_vn", "stop_v", "max_impacts", "sample_m", "step_m")
)
#: Tree stems binned into the DEM's cells (:func:`stems_of`): stem ``x``, ``y``
#: [m], trunk ``diameter`` [m], ``top_z`` (the ground at the stem plus the tree's
#: height) [m], sorted by cell; the stems of cell ``row * nx + col`` are
#: ``cell_start[cell] .. cell_start[cell + 1]``; ``max_half`` the largest d/2 [m].
Stems = namedtuple("Stems", ("x", "y", "diameter", "top_z", "cell_start", "max_half"))
#: Sampled path buffers (flat, one entry per sample).
Path = namedtuple(
    "Path", ("x_m", "y_m", "z_m", "speed_mps", "ke_j", "re_j", "height_m")
)
PATH_FIELDS = Path._fields
#: Columns of a recorded impact row (``R_*`` name each column's index): the rock,
#: the time since its release, the contact (DEM coordinates), the material index,
#: the local-axes speeds, spin before and after, the unit normal N the impact used
#: (tilted by roughness) and the unit tangent T (in the plane of incidence, along
#: the incoming tangential velocity), all in DEM axes, the body at the impact (after
#: mass loss) and whether a tree was struck since the previous impact (1.0).
IMPACT_COLUMNS = (
    "rock",
    "t_s",
    "x_m",
    "y_m",
    "z_m",
    "material_index",
    "vin_mps",
    "vit_mps",
    "vfn_mps",
    "vft_mps",
    "omega_i_radps",
    "omega_f_radps",
    "normal_x",
    "normal_y",
    "normal_z",
    "tangent_x",
    "tangent_y",
    "tangent_z",
    "mass_kg",
    "radius_m",
    "gyration_m",
    "tree_strike",
)
N_IMPACT = len(IMPACT_COLUMNS)
R_ROCK = IMPACT_COLUMNS.index("rock")
R_T = IMPACT_COLUMNS.index("t_s")
R_X = IMPACT_COLUMNS.index("x_m")
R_Y = IMPACT_COLUMNS.index("y_m")
R_Z = IMPACT_COLUMNS.index("z_m")
R_MATERIAL = IMPACT_COLUMNS.index("material_index")
R_VIN = IMPACT_COLUMNS.index("vin_mps")
R_VIT = IMPACT_COLUMNS.index("vit_mps")
R_VFN = IMPACT_COLUMNS.index("vfn_mps")
R_VFT = IMPACT_COLUMNS.index("vft_mps")
R_OMEGA_I = IMPACT_COLUMNS.index("omega_i_radps")
R_OMEGA_F = IMPACT_COLUMNS.index("omega_f_radps")
R_NX = IMPACT_COLUMNS.index("normal_x")
R_NY = IMPACT_COLUMNS.index("normal_y")
R_NZ = IMPACT_COLUMNS.index("normal_z")
R_TX = IMPACT_COLUMNS.index("tangent_x")
R_TY = IMPACT_COLUMNS.index("tangent_y")
R_TZ = IMPACT_COLUMNS.index("tangent_z")
R_MASS = IMPACT_COLUMNS.index("mass_kg")
R_RADIUS = IMPACT_COLUMNS.index("radius_m")
R_GYRATION = IMPACT_COLUMNS.index("gyration_m")
R_TREE = IMPACT_COLUMNS.index("tree_strike")


@njit(cache=True)
def _cell_material(gr, x, y):
    ny, nx = gr.z.shape
    col = min(max(int(math.floor((x - gr.xc0) / gr.cell + 0.5)), 0), nx - 1)
    row = min(max(int(math.floor((y - gr.yc0) / gr.cell + 0.5)), 0), ny - 1)
    return gr.mat_index[row, col], row * nx + col


@njit(cache=True)
def _unit_normal(gx, gy):
    inv = 1.0 / math.sqrt(gx * gx + gy * gy + 1.0)
    return -gx * inv, -gy * inv, inv


@njit(cache=True)
def flight_contact(gr, x, y, z, vx, vy, vz):
    """First contact of the free flight from ``(x, y, z)`` with velocity ``v``.

    Returns ``(t, hit)``: ``hit`` True = contact at ``t``; False = the path's plan
    projection leaves the surface (grid edge or nodata) at ``t``.
    """
    ny, nx = gr.z.shape
    cell = gr.cell
    fx = (x - gr.xc0) / cell
    fy = (y - gr.yc0) / cell
    if not (0.0 <= fx <= nx - 1.0 and 0.0 <= fy <= ny - 1.0):
        return 0.0, False
    # the patch the path is over just after t = 0 (on an edge: the one ahead)
    i = int(fx)
    j = int(fy)
    if vx < 0.0 and fx == i:
        i -= 1
    if vy < 0.0 and fy == j:
        j -= 1
    i = min(max(i, 0), nx - 2)
    j = min(max(j, 0), ny - 2)
    au = vx / cell
    av = vy / cell
    t0 = 0.0
    first = True
    while True:
        z00 = gr.z[j, i]
        z10 = gr.z[j, i + 1]
        z01 = gr.z[j + 1, i]
        z11 = gr.z[j + 1, i + 1]
        if z00 != z00 or z10 != z10 or z01 != z01 or z11 != z11:
            return t0, False
        if vx > 0.0:
            tx = (i + 1 - fx) / au
        elif vx < 0.0:
            tx = (i - fx) / au
        else:
            tx = INF
        if vy > 0.0:
            ty = (j + 1 - fy) / av
        elif vy < 0.0:
            ty = (j - fy) / av
        else:
            ty = INF
        t1 = min(tx, ty)
        # d(t) = z(t) - h(t), h bilinear in u = u0 + au t, v = v0 + av t
        u0 = fx - i
        v0 = fy - j
        a = z10 - z00
        b = z01 - z00
        c = z11 - z10 - z01 + z00
        h0 = z00 + a * u0 + b * v0 + c * u0 * v0
        h1 = a * au + b * av + c * (u0 * av + v0 * au)
        h2 = c * au * av
        qa = -0.5 * G - h2
        qb = vz - h1
        qc = z - h0
        if first and qc <= 0.0 and qb <= 0.0:
            return 0.0, True  # on (or by rounding below) the surface, moving in
        if not first and (qa * t0 + qb) * t0 + qc < 0.0:
            return t0, True  # below the surface on entering (a root lost to rounding)
        first = False
        tc = descending_root(qa, qb, qc)
        tol = 1e-12 * (1.0 + t1) if t1 < INF else 0.0
        if t0 - 1e-12 * (1.0 + t0) <= tc <= t1 + tol:
            return max(tc, t0), True
        if t1 == INF:
            return t0, False  # cannot happen with gravity; guards the loops
        t0 = t1
        if tx <= ty:
            i += 1 if vx > 0.0 else -1
            if i < 0 or i > nx - 2:
                return t0, False
        else:
            j += 1 if vy > 0.0 else -1
            if j < 0 or j > ny - 2:
                return t0, False


@njit(cache=True)
def _emit(path, k, on, x, y, z, speed, m, re, hgt):
    if on:
        path.x_m[k] = x
        path.y_m[k] = y
        path.z_m[k] = z
        path.speed_mps[k] = speed
        path.ke_j[k] = 0.5 * m * speed * speed
        path.re_j[k] = re
        path.height_m[k] = hgt
    return k + 1


@njit(cache=True)
def _enter_cell(gr, mat, key, n, x, y, cell_id, entry, tanphi):
    """``(cell_id, entry, tanphi)`` after a slide step ends at ``(x, y)``: a new
    DEM cell draws a new friction (:func:`_friction_tan`, entry number + 1)."""
    mi1, cell1 = _cell_material(gr, x, y)
    if cell1 != cell_id:
        return cell1, entry + 1, _friction_tan(mat, mi1, key, n, entry + 1)
    return cell_id, entry, tanphi


@njit(cache=True)
def _friction_tan(mat, mi, key, n, entry):
    phi = mat[mi, M_PHI]
    if mat[mi, M_PHI_SD] > 0.0:
        slot = SLOT_FRICTION + entry % 500_000
        phi = max(0.0, phi + mat[mi, M_PHI_SD] * normal(key, n, slot))
    return math.tan(math.radians(min(phi, 89.9)))


@njit(cache=True)
def _fly(gr, path, k, on, x, y, z, vx, vy, vz, t1, sample_m, m, re):
    """The flight over ``[0, t1]``: its samples, then ``(k, x, y, z, vz)`` at ``t1``
    (the parabola; ``vx, vy`` do not change)."""
    k = _sample_flight(gr, path, k, on, x, y, z, vx, vy, vz, t1, sample_m, m, re)
    return (
        k,
        x + vx * t1,
        y + vy * t1,
        z + vz * t1 - 0.5 * G * t1 * t1,
        vz - G * t1,
    )


@njit(cache=True)
def _sample_flight(gr, path, k, on, x, y, z, vx, vy, vz, t1, sample_m, m, re):
    """Samples of the flight over ``[0, t1)``: at most ``sample_m`` travelled apart."""
    q = math.sqrt(2.0 * G * sample_m)
    t = 0.0
    while t < t1:
        cz = vz - G * t
        sp = math.sqrt(vx * vx + vy * vy + cz * cz)
        px = x + vx * t
        py = y + vy * t
        pz = z + vz * t - 0.5 * G * t * t
        k = _emit(path, k, on, px, py, pz, sp, m, re, pz - surface_at(gr, px, py)[0])
        t += sample_m / (sp + q)  # travels at most sample_m (module docstring)
    return k


@njit(cache=True)
def _stem_entry(stems, k, x, y, z, ux, uy, bz, az, s_end, r):
    """When the piece ``p(s) = (x + ux s, y + uy s, z + bz s + az s^2)``,
    ``0 <= s <= s_end``, enters stem ``k``'s cylinder (radius ``d/2 + r`` about
    the stem, up to its top); inf if it does not. Entering through the side needs
    the centre below the top there, through the top a descent inside the disc; a
    piece that starts inside the cylinder does not enter it."""
    big_r = 0.5 * stems.diameter[k] + r
    dx = x - stems.x[k]
    dy = y - stems.y[k]
    a = ux * ux + uy * uy
    b = 2.0 * (dx * ux + dy * uy)
    c = dx * dx + dy * dy - big_r * big_r
    disc = b * b - 4.0 * a * c
    if not (a > 0.0 and disc > 0.0):
        return INF  # no plan motion, or passing by (a graze is no strike)
    sq = math.sqrt(disc)
    q = -0.5 * (b + sq) if b >= 0.0 else -0.5 * (b - sq)
    ta = min(q / a, c / q)
    tb = max(q / a, c / q)
    if tb < 0.0 or ta > s_end:
        return INF
    top = stems.top_z[k]
    t0 = max(ta, 0.0)
    if z + (bz + az * t0) * t0 < top:
        # below the top where the piece is first inside the disc: the side, unless
        # it starts inside (then it is in the cylinder already)
        return ta if ta >= 0.0 else INF
    td = descending_root(az, bz, z - top)  # through the top, inside the disc
    return td if t0 <= td <= min(tb, s_end) else INF


@njit(cache=True)
def stem_struck(gr, stems, skip, x, y, z, ux, uy, bz, az, s_end, r):
    """The first stem the piece of :func:`_stem_entry` enters, ``(index, s)``
    (index -1: none), ``skip`` (a stem just struck, or -1) aside.

    Only the DEM cells within ``max_half + r`` of the piece's plan segment are
    searched (stems are binned by cell), so the cost does not grow with the stems
    far from the rock.
    """
    ny, nx = gr.z.shape
    cell = gr.cell
    x0 = gr.xc0 - 0.5 * cell
    y0 = gr.yc0 - 0.5 * cell
    margin = stems.max_half + r
    xe = x + ux * s_end
    ye = y + uy * s_end
    j0 = max(int(math.floor((min(y, ye) - margin - y0) / cell)), 0)
    j1 = min(int(math.floor((max(y, ye) + margin - y0) / cell)), ny - 1)
    best = INF
    found = -1
    for j in range(j0, j1 + 1):
        lo = y0 + j * cell - margin  # the row's band, widened by the margin
        hi = lo + cell + 2.0 * margin
        if uy != 0.0:
            sa = (lo - y) / uy
            sb = (hi - y) / uy
            sa, sb = max(min(sa, sb), 0.0), min(max(sa, sb), s_end)
            if sa > sb:
                continue
            xa = x + ux * sa
            xb = x + ux * sb
        else:
            xa, xb = x, xe
        i0 = max(int(math.floor((min(xa, xb) - margin - x0) / cell)), 0)
        i1 = min(int(math.floor((max(xa, xb) + margin - x0) / cell)), nx - 1)
        for i in range(i0, i1 + 1):
            c = j * nx + i
            for k in range(stems.cell_start[c], stems.cell_start[c + 1]):
                if k == skip:
                    continue
                s = _stem_entry(stems, k, x, y, z, ux, uy, bz, az, s_end, r)
                if s < best:
                    best, found = s, k
    return found, best


@njit(cache=True)
def _left_stem(stems, skip, x, y, r):
    """``skip``, or -1 once the rock is clear of that stem's disc (so a stem just
    struck is not struck again on the way through, but can be on a later pass)."""
    if skip < 0:
        return skip
    big_r = (0.5 * stems.diameter[skip] + r) * (1.0 + 1e-6)
    dx = x - stems.x[skip]
    dy = y - stems.y[skip]
    return skip if dx * dx + dy * dy <= big_r * big_r else -1


@njit(cache=True, inline="always")
def _local_axes(vx, vy, vz, nx, ny, nz):
    """``(vin, vit, tx, ty, tz)``: the velocity's normal component on the unit
    normal ``n``, its tangential speed and the unit tangent T along it (in the plane
    of incidence); T is the bare tangential velocity when ``vit`` is not positive."""
    vin = vx * nx + vy * ny + vz * nz
    tx = vx - vin * nx
    ty = vy - vin * ny
    tz = vz - vin * nz
    vit = math.sqrt(tx * tx + ty * ty + tz * tz)
    if vit > 0.0:
        return vin, vit, tx / vit, ty / vit, tz / vit
    return vin, vit, tx, ty, tz


@njit(cache=True)
def impact(gr, mat, flags, par, key, n, x, y, vx, vy, vz, w, r, kg):
    """One impact at ``(x, y)`` on the surface; returns the rebound and its axes.

    Returns ``(vfx, vfy, vfz, w_f, vin, vit, vfn, vft, nx, ny, nz, tx, ty, tz,
    mi)``: rebound velocity and spin, the local-axes speeds, the normal used
    (tilted by roughness), the unit tangent T and the material index.
    """
    h, gx, gy = surface_at(gr, x, y)
    nx, ny, nz = _unit_normal(gx, gy)
    mi, _ = _cell_material(gr, x, y)
    e_n, e_t = drawn_restitution(
        mat[mi, M_EN], mat[mi, M_EN_SD], mat[mi, M_ET], mat[mi, M_ET_SD], key, n
    )
    vin, vit, tx, ty, tz = _local_axes(vx, vy, vz, nx, ny, nz)
    if not vit > 0.0:
        # normal incidence: T down the fall line (or along x on level ground)
        tx, ty, tz = nx * nz, ny * nz, nz * nz - 1.0
        tn = math.sqrt(tx * tx + ty * ty + tz * tz)
        if tn > 1e-12:
            tx, ty, tz = tx / tn, ty / tn, tz / tn
        else:
            tx, ty, tz = 1.0, 0.0, 0.0
    if flags[F_ROUGH] == 1:
        sd = slope_roughness.dip_sd_rad(
            mat[mi, M_ROUGH], mat[mi, M_ROUGH_SD], r, par[P_ROUGH]
        )
        if sd > 0.0:
            d1 = sd * normal(key, n, SLOT_ROUGHNESS)
            d2 = sd * normal(key, n, SLOT_ROUGHNESS_LATERAL)
            # L = N x T: across the plane of incidence
            lx = ny * tz - nz * ty
            ly = nz * tx - nx * tz
            lz = nx * ty - ny * tx
            for trial in range(3):
                sgn = 1.0 if trial == 0 else (-1.0 if trial == 1 else 0.0)
                a1 = math.tan(sgn * d1)
                a2 = math.tan(sgn * d2)
                mx = nx + a1 * tx + a2 * lx
                my = ny + a1 * ty + a2 * ly
                mz = nz + a1 * tz + a2 * lz
                mn = math.sqrt(mx * mx + my * my + mz * mz)
                mx, my, mz = mx / mn, my / mn, mz / mn
                if vx * mx + vy * my + vz * mz < 0.0 or trial == 2:
                    nx, ny, nz = mx, my, mz
                    break
            vin, vit, tx, ty, tz = _local_axes(vx, vy, vz, nx, ny, nz)
    vfn, vft, w_f = restitution(vin, vit, e_n, mat[mi, M_EN], e_t, w, r, kg, flags, par)
    k_spin = kg if flags[F_ROT] == 1 and par[P_ROT_C] > 0.0 else 0.0
    vfn = passive_normal_speed(vin, vit, w, vfn, vft, w_f, k_spin)
    vfx = vft * tx + vfn * nx
    vfy = vft * ty + vfn * ny
    vfz = vft * tz + vfn * nz
    return vfx, vfy, vfz, w_f, vin, vit, vfn, vft, nx, ny, nz, tx, ty, tz, mi


@njit(cache=True)
def _strike(gr, stems, ks, par, path, k, on, x, y, z, vx, vy, vz, m, re):
    """A strike on stem ``ks`` at ``(x, y, z)``: the trunk takes its energy
    (:func:`fieldkit.model.effects.tree_impacts.speed_after_strike`, capped at the
    kinetic energy), the direction is kept. Emits the samples just before and just
    after; returns ``(k, vx, vy, vz)``."""
    sp = math.sqrt(vx * vx + vy * vy + vz * vz)
    hgt = z - surface_at(gr, x, y)[0]
    k = _emit(path, k, on, x, y, z, sp, m, re, hgt)
    v_new = tree_impacts.speed_after_strike(
        sp, m, stems.diameter[ks], par[P_TREE_C], par[P_TREE_EXP]
    )
    scale = v_new / sp if sp > 0.0 else 0.0
    vx, vy, vz = vx * scale, vy * scale, vz * scale
    k = _emit(path, k, on, x, y, z, v_new, m, re, hgt)
    return k, vx, vy, vz


@njit(cache=True)
def run_rock(
    key, x, y, z, vx, vy, vz, w, m, r, kg, gr, mat, flags, par, st, stems,
    path, path_start, path_on, rec, rec_start, rec_on, rock,
):  # fmt: skip
    """Follow one rock; returns ``(impacts, state, x, y, z, samples, strikes)``.

    ``gr`` is a :data:`Ground`, ``mat`` the material table (columns ``M_*``),
    ``flags`` / ``par`` the effects (registry layout), ``st`` the :data:`Settings`,
    ``stems`` the trees (:data:`Stems`; struck with ``tree_impacts`` on);
    ``strikes`` counts the tree strikes.
    Path samples are written from ``path_start`` when ``path_on`` (else only
    counted), impact rows into ``rec[rec_start + i]`` when ``rec_on``.
    """
    max_imp = st.max_impacts
    kr = kg * kg
    m0, r0, k0, x_rel, y_rel = m, r, kg, x, y
    losing = flags[F_MASS] == 1
    trees = flags[F_TREE] == 1 and stems.x.size > 0
    strikes = 0
    struck = 0.0  # a tree struck since the last impact
    skip = -1  # the stem just struck
    t = 0.0  # time since the release [s]
    n = 0
    k = path_start
    state = -1
    h, gx, gy = surface_at(gr, x, y)
    if h != h:
        k = _emit(path, k, path_on, x, y, z, 0.0, m, 0.0, math.nan)
        return 0, EXITED, x, y, z, k - path_start, 0
    nx, ny, nz = _unit_normal(gx, gy)
    flying = z > h or vx * nx + vy * ny + vz * nz > 0.0
    if not flying:
        z = h
        vn = vx * nx + vy * ny + vz * nz
        vx, vy, vz = vx - vn * nx, vy - vn * ny, vz - vn * nz
    k = _emit(
        path, k, path_on, x, y, z, math.sqrt(vx * vx + vy * vy + vz * vz), m,
        0.5 * m * kr * w * w, z - h,
    )  # fmt: skip
    while state < 0:
        if flying:
            tc, hit = flight_contact(gr, x, y, z, vx, vy, vz)
            if trees:
                skip = _left_stem(stems, skip, x, y, r)
                ks, ts = stem_struck(
                    gr, stems, skip, x, y, z, vx, vy, vz, -0.5 * G, tc, r
                )
                if ks >= 0:
                    re = 0.5 * m * kr * w * w
                    k, x, y, z, vz = _fly(
                        gr, path, k, path_on, x, y, z, vx, vy, vz, ts, st.sample_m,
                        m, re,
                    )  # fmt: skip
                    t += ts
                    k, vx, vy, vz = _strike(
                        gr, stems, ks, par, path, k, path_on, x, y, z, vx, vy, vz, m,
                        re,
                    )  # fmt: skip
                    strikes += 1
                    struck = 1.0
                    skip = ks
                    continue
            k, x, y, z, vz = _fly(
                gr, path, k, path_on, x, y, z, vx, vy, vz, tc, st.sample_m, m,
                0.5 * m * kr * w * w,
            )  # fmt: skip
            t += tc
            if not hit:
                state = EXITED
                break
            h = surface_at(gr, x, y)[0]
            if h == h:
                z = h  # exactly on the surface
            if n >= max_imp:
                state = MAX_IMPACTS
                break
            n += 1
            sp = math.sqrt(vx * vx + vy * vy + vz * vz)
            k = _emit(path, k, path_on, x, y, z, sp, m, 0.5 * m * kr * w * w, 0.0)
            if losing:  # eqs. 6.15-6.16 with the plan distance from the release
                ratio = mass_loss.volume_ratio(
                    math.hypot(x - x_rel, y - y_rel), n, par[P_MASS_RATE],
                    par[P_MASS_EXP],
                )  # fmt: skip
                cube = ratio ** (1.0 / 3.0)
                m, r, kg = m0 * ratio, r0 * cube, k0 * cube
                kr = kg * kg
            w_i = w
            vfx, vfy, vfz, w, vin, vit, vfn, vft, nnx, nny, nnz, tx, ty, tz, mi = (
                impact(gr, mat, flags, par, key, n, x, y, vx, vy, vz, w, r, kg)
            )
            if rec_on:
                row = rec_start + n - 1
                rec[row, R_ROCK] = rock
                rec[row, R_T] = t
                rec[row, R_X] = x
                rec[row, R_Y] = y
                rec[row, R_Z] = z
                rec[row, R_MATERIAL] = mi
                rec[row, R_VIN] = vin
                rec[row, R_VIT] = vit
                rec[row, R_VFN] = vfn
                rec[row, R_VFT] = vft
                rec[row, R_OMEGA_I] = w_i
                rec[row, R_OMEGA_F] = w
                rec[row, R_NX] = nnx
                rec[row, R_NY] = nny
                rec[row, R_NZ] = nnz
                rec[row, R_TX] = tx
                rec[row, R_TY] = ty
                rec[row, R_TZ] = tz
                rec[row, R_MASS] = m
                rec[row, R_RADIUS] = r
                rec[row, R_GYRATION] = kg
                rec[row, R_TREE] = struck
            struck = 0.0
            h, gx, gy = surface_at(gr, x, y)
            nx, ny, nz = _unit_normal(gx, gy)
            vn_real = vfx * nx + vfy * ny + vfz * nz
            if vfn < st.slide_vn or vn_real <= 0.0:
                flying = False
                vx = vfx - vn_real * nx
                vy = vfy - vn_real * ny
                vz = vfz - vn_real * nz
            else:
                vx, vy, vz = vfx, vfy, vfz
        else:
            state, x, y, z, vx, vy, vz, w, k, hits, skip, t = _slide(
                gr, mat, key, n, x, y, z, vx, vy, vz, w, m, r, kr, st,
                path, k, path_on, stems, par, trees, skip, t,
            )  # fmt: skip
            if hits > 0:
                strikes += hits
                struck = 1.0
            if state < 0:
                flying = True
    sp = math.sqrt(vx * vx + vy * vy + vz * vz) if state != STOPPED else 0.0
    hh = surface_at(gr, x, y)[0]
    k = _emit(path, k, path_on, x, y, z, sp, m, 0.5 * m * kr * w * w, z - hh)
    return n, state, x, y, z, k - path_start, strikes


@njit(cache=True)
def _is_groove(gr, x, y, groove):
    """Whether the patch edge through ``(x, y)`` (``groove`` 1: ``y`` const, 2:
    ``x`` const) is a groove: the ground rises away from it on both sides."""
    e = EDGE_NUDGE * gr.cell
    if groove == 1:
        return surface_at(gr, x, y - e)[2] < 0.0 < surface_at(gr, x, y + e)[2]
    return surface_at(gr, x - e, y)[1] < 0.0 < surface_at(gr, x + e, y)[1]


@njit(cache=True)
def _edge_gradient(gr, x, y, vx, vy, gx, gy):
    """The gradient a sliding rock at ``(x, y)`` feels. On a patch edge or a centre
    (where the slope jumps) it is that of the patch the velocity points into, and
    the mean over the patches meeting there along the axis the velocity has no
    component on (a rock at rest on a cell centre does not take the north-east
    patch's fall line; one running along a crest stays on it)."""
    fx = (x - gr.xc0) / gr.cell
    fy = (y - gr.yc0) / gr.cell
    on_x = fx == math.floor(fx)
    on_y = fy == math.floor(fy)
    if not (on_x or on_y):
        return gx, gy
    e = EDGE_NUDGE * gr.cell
    sx = 0.0
    sy = 0.0
    count = 0
    for corner in range(4):  # (repeated offsets keep equal weights)
        dx = 0.0
        if on_x:
            dx = math.copysign(e, vx) if vx != 0.0 else (e if corner & 1 else -e)
        dy = 0.0
        if on_y:
            dy = math.copysign(e, vy) if vy != 0.0 else (e if corner & 2 else -e)
        h, ax, ay = surface_at(gr, x + dx, y + dy)
        if h == h:
            sx += ax
            sy += ay
            count += 1
    if count == 0:
        return gx, gy
    return sx / count, sy / count


@njit(cache=True)
def _line_direction(gx, gy, groove):
    """Unit direction of a groove line (towards +x or +y) from the surface slope."""
    sl = gx if groove == 1 else gy
    inv = 1.0 / math.sqrt(1.0 + sl * sl)
    if groove == 1:
        return inv, 0.0, sl * inv
    return 0.0, inv, sl * inv


@njit(cache=True)
def _slide(gr, mat, key, n, x, y, z, vx, vy, vz, w, m, r, kr, st, path, k, on,
           stems, par, trees, skip, t):  # fmt: skip
    """Slide/roll on the surface until the rock stops, leaves the DEM or launches.

    Returns ``(state, x, y, z, vx, vy, vz, w, samples, strikes, skip, t)``;
    ``state`` -1 = launched (flying from the returned point, above the surface).
    With ``trees``, a step whose chord enters a stem's cylinder ends there with a
    strike (the speed there from ``v^2`` linear along the step, exact on a plane);
    ``skip`` is the stem just struck (:func:`_left_stem`). ``t``: the time [s] at
    the returned point (``t`` at the start plus the steps taken; to a strike within
    a step, ``2 d / (v_0 + v_s)`` over the chord's distance ``d`` to it, exact for
    constant acceleration along a line).
    """
    hits = 0
    mi, cell_id = _cell_material(gr, x, y)
    entry = 0
    tanphi = _friction_tan(mat, mi, key, n, entry)
    walked = 0.0
    half = 0.5 * st.sample_m
    groove = 0  # 1: in a groove along a patch edge y = const, 2: along x = const
    fy = (y - gr.yc0) / gr.cell
    fx = (x - gr.xc0) / gr.cell
    if fy == math.floor(fy) and _is_groove(gr, x, y, 1):
        groove = 1
    elif fx == math.floor(fx) and _is_groove(gr, x, y, 2):
        groove = 2
    if groove != 0:  # starting in a groove: the velocity along its line
        h, gx, gy = surface_at(gr, x, y)
        dx, dy, dz = _line_direction(gx, gy, groove)
        u = vx * dx + vy * dy + vz * dz
        vx, vy, vz = u * dx, u * dy, u * dz
    for _ in range(MAX_SLIDE_STEPS):
        h, gx, gy = surface_at(gr, x, y)
        if groove == 0:
            gx, gy = _edge_gradient(gr, x, y, vx, vy, gx, gy)
        if groove == 0:
            nx, ny, nz = _unit_normal(gx, gy)
            # gravity on the tangent plane: (0, 0, -g) + g nz n
            gtx = G * nz * nx
            gty = G * nz * ny
            gtz = -G + G * nz * nz
            fric = G * nz * tanphi
        else:
            # on the groove's line, direction d: gravity along it, (g . d) d, and
            # friction from gravity across it, g cos(dip of the line)
            dx, dy, dz = _line_direction(gx, gy, groove)
            gtx = -G * dz * dx
            gty = -G * dz * dy
            gtz = -G * dz * dz
            fric = G * math.sqrt(1.0 - dz * dz) * tanphi
        gt = math.sqrt(gtx * gtx + gty * gty + gtz * gtz)
        sp = math.sqrt(vx * vx + vy * vy + vz * vz)
        restart = False
        if sp < st.stop_v or sp == 0.0:
            if gt <= fric:
                return STOPPED, x, y, z, 0.0, 0.0, 0.0, 0.0, k, hits, skip, t
            vx = vy = vz = 0.0
            sp = 0.0
            s = 1.0 - fric / gt
            ax, ay, az = gtx * s, gty * s, gtz * s
            restart = True
        else:
            ax = gtx - fric * vx / sp
            ay = gty - fric * vy / sp
            az = gtz - fric * vz / sp
        acc = math.sqrt(ax * ax + ay * ay + az * az)
        dt = st.step_m / (sp + math.sqrt(2.0 * st.step_m * acc) + 1e-300)
        av = ax * vx + ay * vy + az * vz
        rest = False
        if sp > 0.0 and av < 0.0:
            ts = -sp * sp / av  # the speed along the travel reaches 0
            if ts <= dt:
                dt = ts
                rest = True
        # end the step at the next patch edge (where the surface's slope jumps), as
        # 2-D ends a slide step at the next vertex
        edge = 0
        edge_at = 0.0
        fx = (x - gr.xc0) / gr.cell
        ix = math.floor(fx)
        for e in (ix if fx > ix else ix - 1, ix + 1):
            tb = time_to_x(x, vx, ax, gr.xc0 + e * gr.cell)
            if tb < dt:
                dt, edge, edge_at, rest = tb, 1, e - fx, False
        fy = (y - gr.yc0) / gr.cell
        iy = math.floor(fy)
        for e in (iy if fy > iy else iy - 1, iy + 1):
            tb = time_to_x(y, vy, ay, gr.yc0 + e * gr.cell)
            if tb < dt:
                dt, edge, edge_at, rest = tb, 2, e - fy, False
        # a free step: does the surface fall away faster than the rock?
        bx = x + vx * dt
        by = y + vy * dt
        bz = z + vz * dt - 0.5 * G * dt * dt
        hb = surface_at(gr, bx, by)[0]
        if hb != hb:
            return EXITED, x, y, z, vx, vy, vz, w, k, hits, skip, t
        if bz > hb + LAUNCH_GAP_M:
            k = _emit(path, k, on, x, y, z, sp, m, 0.5 * m * kr * w * w, 0.0)
            return -1, bx, by, bz, vx, vy, vz - G * dt, w, k, hits, skip, t + dt
        x1 = x + vx * dt + 0.5 * ax * dt * dt
        y1 = y + vy * dt + 0.5 * ay * dt * dt
        if edge == 1:  # just past the edge, in the patch ahead
            x1 = x + (edge_at + math.copysign(EDGE_NUDGE, edge_at)) * gr.cell
        elif edge == 2:
            y1 = y + (edge_at + math.copysign(EDGE_NUDGE, edge_at)) * gr.cell
        h1, gx1, gy1 = surface_at(gr, x1, y1)
        if h1 != h1:
            return EXITED, x, y, z, vx, vy, vz, w, k, hits, skip, t
        if restart and (x1 - x) * gx1 + (y1 - y) * gy1 > 0.0:
            # a step from rest ends where the ground rises along it: the fall lines
            # meet within one step (a notch), where the rock stays
            return STOPPED, x, y, z, 0.0, 0.0, 0.0, 0.0, k, hits, skip, t
        if trees:
            skip = _left_stem(stems, skip, x, y, r)
            ks, s1 = stem_struck(
                gr, stems, skip, x, y, z, x1 - x, y1 - y, h1 - z, 0.0, 1.0, r
            )
            if ks >= 0:
                ex, ey, ez = vx + ax * dt, vy + ay * dt, vz + az * dt
                if rest:
                    ex, ey, ez = x1 - x, y1 - y, h1 - z  # (only the direction)
                    v2 = (1.0 - s1) * sp * sp
                else:
                    v2 = sp * sp + s1 * (ex * ex + ey * ey + ez * ez - sp * sp)
                xs = x + s1 * (x1 - x)
                ys = y + s1 * (y1 - y)
                hs, gxs, gys = surface_at(gr, xs, ys)
                # the time to the strike: speed linear in time along the chord
                d_s = s1 * math.sqrt((x1 - x) ** 2 + (y1 - y) ** 2 + (h1 - z) ** 2)
                v_s = math.sqrt(v2) if v2 > 0.0 else 0.0
                t += 2.0 * d_s / (sp + v_s) if sp + v_s > 0.0 else 0.0
                if groove == 0:  # along the tangent plane there
                    n1x, n1y, n1z = _unit_normal(gxs, gys)
                    en = ex * n1x + ey * n1y + ez * n1z
                    ex, ey, ez = ex - en * n1x, ey - en * n1y, ez - en * n1z
                norm = math.sqrt(ex * ex + ey * ey + ez * ez)
                vs = math.sqrt(v2) if v2 > 0.0 else 0.0
                scale = vs / norm if norm > 0.0 else 0.0
                re = 0.5 * m * kr * w * w
                k, vx, vy, vz = _strike(
                    gr, stems, ks, par, path, k, on, xs, ys, hs, ex * scale,
                    ey * scale, ez * scale, m, re,
                )  # fmt: skip
                hits += 1
                skip = ks
                x, y, z = xs, ys, hs
                sp = math.sqrt(vx * vx + vy * vy + vz * vz)
                w = -sp / r
                walked = 0.0
                cell_id, entry, tanphi = _enter_cell(
                    gr, mat, key, n, x, y, cell_id, entry, tanphi
                )
                continue
        walked += math.sqrt((x1 - x) ** 2 + (y1 - y) ** 2 + (h1 - z) ** 2)
        if rest:
            vx = vy = vz = 0.0
        else:
            vx += ax * dt
            vy += ay * dt
            vz += az * dt
            if groove == 0:
                gx1, gy1 = _edge_gradient(gr, x1, y1, vx, vy, gx1, gy1)
                n1x, n1y, n1z = _unit_normal(gx1, gy1)
            else:  # the normal of the line's vertical plane
                dx, dy, dz = _line_direction(gx1, gy1, groove)
                hor = math.sqrt(1.0 - dz * dz)
                n1x, n1y, n1z = -dz * dx / hor, -dz * dy / hor, hor
            vn = vx * n1x + vy * n1y + vz * n1z
            if edge != 0 and vn > 0.0 and vn * vn > 2.0 * G * n1z * LAUNCH_GAP_M:
                # a convex edge: the rock leaves the surface (the 2-D convex break)
                # when its free flight would rise above LAUNCH_GAP_M off the plane
                k = _emit(path, k, on, x, y, z, sp, m, 0.5 * m * kr * w * w, 0.0)
                return -1, x1, y1, h1, vx, vy, vz, w, k, hits, skip, t + dt
            if groove == 0:
                vx -= vn * n1x
                vy -= vn * n1y
                vz -= vn * n1z
                if edge != 0 and _is_groove(gr, x1, y1, 3 - edge):
                    # crossed into a groove: an excursion up the far flank shorter
                    # than a slide step is below the step's resolution (and would
                    # zigzag across the edge for ever): follow the groove
                    across = vy if edge == 2 else vx
                    a_across = G * n1z * abs(n1y if edge == 2 else n1x)
                    if across * across < 2.0 * a_across * st.step_m:
                        groove = 3 - edge
                        if edge == 2:
                            y1 = y + edge_at * gr.cell  # on the edge
                        else:
                            x1 = x + edge_at * gr.cell
                        h1, gx1, gy1 = surface_at(gr, x1, y1)
            if groove != 0:
                dx, dy, dz = _line_direction(gx1, gy1, groove)
                u = vx * dx + vy * dy + vz * dz
                vx, vy, vz = u * dx, u * dy, u * dz
        x, y, z = x1, y1, h1
        t += dt
        if groove != 0 and not _is_groove(gr, x, y, groove):
            groove = 0  # the groove opens: back on the surface
        sp = math.sqrt(vx * vx + vy * vy + vz * vz)
        w = -sp / r
        if walked >= half:
            k = _emit(path, k, on, x, y, z, sp, m, 0.5 * m * kr * w * w, 0.0)
            walked = 0.0
        cell_id, entry, tanphi = _enter_cell(
            gr, mat, key, n, x, y, cell_id, entry, tanphi
        )
    return MAX_IMPACTS, x, y, z, vx, vy, vz, w, k, hits, skip, t


@njit(cache=True, parallel=True)
def run_rocks(
    keys, x, y, z, vx, vy, vz, w, m, r, kg, gr, mat, flags, par, st, stems,
    path, path_offsets, path_on, rec, rec_offsets, rec_on, first_rock,
    impacts, states, deposit, samples, strikes,
):  # fmt: skip
    """:func:`run_rock` over all rocks in parallel; outputs written in place."""
    for i in prange(keys.size):
        n, s, xf, yf, zf, ns, nt = run_rock(
            keys[i], x[i], y[i], z[i], vx[i], vy[i], vz[i], w[i], m[i], r[i], kg[i],
            gr, mat, flags, par, st, stems, path, path_offsets[i], path_on,
            rec, rec_offsets[i], rec_on, first_rock + i,
        )  # fmt: skip
        strikes[i] = nt
        impacts[i] = n
        states[i] = s
        deposit[i, 0] = xf
        deposit[i, 1] = yf
        deposit[i, 2] = zf
        samples[i] = ns


def stems_of(x_m, y_m, diameter_m, height_m, terrain) -> Stems:
    """The trees as the kernel takes them (:data:`Stems`), binned into the DEM's
    cells; a stem off the DEM's surface (outside the cell centres or beside nodata)
    is left out: no rock can reach it.

    Parameters
    ----------
    x_m, y_m, diameter_m, height_m
        Stem positions, trunk diameters and tree heights [m] (equal lengths).
    terrain
        The :class:`fieldkit.model.terrain.Terrain` the rocks run on.

    Examples
    --------
    >>> from fieldkit.model.terrain import Terrain
    >>> t = Terrain(0.0, 0.0, 1.0, np.zeros((3, 3)))
    >>> s = stems_of([1.2, 0.7, 9.0], [1.5, 0.6, 1.0], [0.3, 0.2, 0.3],
    ...              [20.0, 15.0, 20.0], t)
    >>> s.x.tolist(), s.cell_start.tolist(), s.max_half
    ([0.7, 1.2], [0, 1, 1, 1, 1, 2, 2, 2, 2, 2], 0.15)
    """
    x = np.asarray(x_m, float)
    y = np.asarray(y_m, float)
    d = np.asarray(diameter_m, float)
    ground = terrain.heights(x, y)
    keep = np.isfinite(ground)
    x, y, d = x[keep], y[keep], d[keep]
    top = ground[keep] + np.asarray(height_m, float)[keep]
    ny, nx = terrain.shape
    row, col = terrain.cell_index(x, y)
    cell = row * nx + col
    order = np.argsort(cell, kind="stable")
    start = np.searchsorted(cell[order], np.arange(ny * nx + 1)).astype(np.int64)
    return Stems(
        np.ascontiguousarray(x[order]),
        np.ascontiguousarray(y[order]),
        np.ascontiguousarray(d[order]),
        np.ascontiguousarray(top[order]),
        start,
        float(0.5 * d.max()) if d.size else 0.0,
    )


def no_stems(terrain) -> Stems:
    """No trees (a model without any)."""
    return stems_of([], [], [], [], terrain)


def empty_path() -> Path:
    """Path buffers of no samples (for a counting run)."""
    return Path(*(np.zeros(0) for _ in PATH_FIELDS))
