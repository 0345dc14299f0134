"""r.stone's own law along a section: a 2-D port of its point-block kernel.

fieldkit's emulation of r.stone (:func:`fieldkit.export.rstone.emulated_model`)
for the translation error and the behaviour search. r.stone (OSGeo grass-addons
``src/raster/r.stone``, vendored in ``tools/r.stone``) moves a point block over
the triangles between DEM cell centres. Along a section whose vertices are the
cell centres (chainage ``x``, ground ``z``), each segment is one of those planes
seen in section, and this module ports, from ``points.c`` (``TrackPoints``,
``Parab``, ``Bounce``, ``Roll``), ``stone.c`` (``GetRandVElas``, ``GetRandHElas``,
``GetRandFrict``, ``NewPlane``) and ``fixed_parameters.c``:

* the launch: from the ground at the release point, horizontally at
  ``start_vel`` towards the lower neighbour (``TrackPoints``: the steepest of
  the eight);
* flight: a parabola under gravity ``G = 9.805 m/s²`` (``stone.h``) to its first
  meeting with the ground, segment by segment (exact: r.stone steps its 5 m
  flight steps but lands at the exact intersection with the current plane);
* a landing: a *roll* when the landing lies less than ``DIST_FLY_ROLL = 3 m``
  from the last bounce point (the release point before the first) **and** the
  speed is below ``VEL_FLY_ROLL = 5 m/s``; otherwise a bounce (``Bounce``): a cell
  with nrest 0 stops the rock ("water"); the normal velocity component is
  multiplied by ``-nrest``, the tangential by ``trest``, both drawn per bounce
  from Gaussians of SD ``2 range / 100`` about the cell's ``nrest/100``,
  ``trest/100`` and clipped to [0, 1]; a rock slower than ``stop_vel`` after a
  bounce stops. A bounce that leaves no normal velocity (a draw of 0) is
  followed by a further bounce at once (``Parab``'s "bounce forced"), without
  the roll test and without moving the last bounce point (:data:`MAX_FORCED`
  such bounces in a row end the track there: r.stone would repeat them
  forever with a trest draw of 1, or hop on its 0.1 mm rounding);
* rolling (``Roll``): the velocity projected onto the plane (its normal
  component lost), the point onto the plane; acceleration ``g`` along the plane
  minus ``g sin(beta)`` against the motion, ``tan(beta)`` the cell's friction
  drawn (Gaussian SD ``2 range / 100``, clipped to [0, 1]) each time the rock
  enters a cell and afresh at every new roll phase; time steps of
  ``ROLL_INT_TAB / |v|`` (5 m), the first of length 0, shortened to
  ``|v| / (g sin beta)`` when the friction alone would stop the rock within it
  ("stop between two steps"); a stop when the speed falls below ``stop_vel``.
  When a step ends beyond the segment, the next segment is the one under that
  point (``NewPlane``): if the point lies more than 0.01 m above its line (a
  convex break) the rock flies again from there with its rolling velocity,
  otherwise it rolls on, projected onto the new line. 100 000 roll points
  without a flight end the track where it was last written (``Track
  overflow``);
* the grid's end: a rock whose point leaves the section ends there (r.stone's
  ``NewPlane`` out of bounds).

Not ported: the 3-D geometry of the triangles (a section sees one plane per
segment; r.stone's two triangles per cell and the lateral components of
velocity and gravity in them), the lateral spread of the launch angle
(``ang_stoch_range``; fieldkit's exports write 0), the 5 m flight steps between
which r.stone decides that a flight left its triangle (the exact parabola
instead), the rounding of positions to 0.1 mm and of elevations to mm, and the
output sampling (r.stone marks its grids at path points 5 m apart). The mass is
fieldkit's (r.stone ignores it): energy ``m v² / 2``, no rotation.

Randomness comes only from the ``numpy.random.Generator`` given: one 64-bit key
per rock, and counter-based normals (:mod:`fieldkit.model.random_streams`),
counter the bounce or friction-draw number, so a seed reproduces a run exactly
and runs with different values share their draws (common random numbers).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from fieldkit.errors import ArgumentError
from fieldkit.model.random_streams import normal
from fieldkit.model.results import (
    EXITED_DOWNSLOPE,
    EXITED_UPSLOPE,
    STOPPED,
    AnalysisPoint,
)

#: r.stone's gravity [m/s²] (``stone.h`` G).
G_MPS2 = 9.805

#: A bounce shorter than this [m] and slower than :data:`ROLL_SPEED_MPS` rolls
#: (``fixed_parameters.c`` DIST_FLY_ROLL).
ROLL_DISTANCE_M = 3.0

#: See :data:`ROLL_DISTANCE_M` (``fixed_parameters.c`` VEL_FLY_ROLL) [m/s].
ROLL_SPEED_MPS = 5.0

#: r.stone's roll step [m] (``fixed_parameters.c`` ROLL_INT_TAB).
ROLL_STEP_M = 5.0

#: A point this far above the next plane after a roll step flies [m] (``Roll``).
FLY_HEIGHT_M = 0.01

#: Roll points without a flight before r.stone gives up (PATH_ARRAY_SIZE).
MAX_PATH = 100000

#: Forced bounces in a row (no normal velocity left) after which the port ends
#: the track where it is: with a trest draw of 1 the speed never falls, and
#: r.stone would bounce in place forever (or hop on its 0.1 mm rounding).
MAX_FORCED = 1000

#: Random-stream slots: nrest and trest per bounce, friction per cell entered.
SLOT_NREST, SLOT_TREST, SLOT_FRICTION = 0, 1, 2


@njit(cache=True)
def _segment(x, px):
    """Segment index under ``px``: -1 before the first vertex, -2 past the last."""
    n = x.size
    if px < x[0]:
        return -1
    if px > x[n - 1]:
        return -2
    j = np.searchsorted(x, px, side="right") - 1
    if j > n - 2:
        j = n - 2
    return j


@njit(cache=True)
def _cell(x, px):
    """The vertex nearest ``px`` (whose cell and values are the point's)."""
    n = x.size
    j = np.searchsorted(x, px, side="right") - 1
    if j < 0:
        return 0
    if j >= n - 1:
        return n - 1
    if px - x[j] > x[j + 1] - px:
        return j + 1
    return j


@njit(cache=True)
def _ground(x, z, px):
    j = _segment(x, px)
    if j == -1:
        return z[0]
    if j == -2:
        return z[x.size - 1]
    return z[j] + (z[j + 1] - z[j]) / (x[j + 1] - x[j]) * (px - x[j])


@njit(cache=True)
def _clip01(v):
    if v < 0.0:
        return 0.0
    if v > 1.0:
        return 1.0
    return v


@njit(cache=True)
def _flight(x, z, g, px, pz, vx, vz, j):
    """The first meeting of the parabola from ``(px, pz)`` with the ground.

    Returns ``(kind, t, j)``: kind 0 landing on segment ``j`` at time ``t``, 1 a
    landing at ``t = 0`` (no velocity away from the plane: a forced bounce), 2
    the rock leaves the section at time ``t`` (``j`` -1 upslope, -2 downslope).
    """
    n = x.size
    step = 1 if vx > 0 else -1
    first = True
    while True:
        s = (z[j + 1] - z[j]) / (x[j + 1] - x[j])
        w = vz - s * vx
        h0 = pz - (z[j] + s * (px - x[j]))
        disc = w * w + 2.0 * g * h0
        if disc < 0.0:  # Parab: sq < 0, the point taken as on the plane
            disc = w * w
            h0 = 0.0
        t_land = (w + math.sqrt(disc)) / g
        if first and t_land <= 1e-9 * (1.0 + abs(w) / g):
            return 1, 0.0, j
        first = False
        if vx == 0.0:
            return 0, t_land, j
        edge = x[j + 1] if step > 0 else x[j]
        t_exit = (edge - px) / vx
        if t_land <= t_exit:
            return 0, t_land, j
        j += step
        if j < 0:
            return 2, t_exit, -1
        if j > n - 2:
            return 2, t_exit, -2


@njit(cache=True)
def _cross_flight(x, z, g, at, crossed, speed, height, r, px, pz, vx, vz, t_end):
    """Record the first crossings of the analysis points during a flight."""
    if vx == 0.0:
        return
    x_end = px + vx * t_end
    lo, hi = min(px, x_end), max(px, x_end)
    for k in range(at.size):
        a = at[k]
        if crossed[r, k] or a < lo or a > hi:
            continue
        t = (a - px) / vx
        vzt = vz - g * t
        crossed[r, k] = True
        speed[r, k] = math.sqrt(vx * vx + vzt * vzt)
        height[r, k] = pz + vz * t - 0.5 * g * t * t - _ground(x, z, a)


@njit(cache=True)
def _cross_roll(x, z, at, crossed, speed, height, r, x0, z0, tx, tz, d0, u, acc, dt):
    """Record first crossings during one roll step along the line through
    ``(x0, z0)`` with unit tangent ``(tx, tz)``, from coordinate ``d0``."""
    xa = x0 + d0 * tx
    xb = x0 + (d0 + u * dt + 0.5 * acc * dt * dt) * tx
    lo, hi = min(xa, xb), max(xa, xb)
    for k in range(at.size):
        a = at[k]
        if crossed[r, k] or a < lo or a > hi or tx == 0.0:
            continue
        c = d0 - (a - x0) / tx
        if abs(acc) < 1e-12:
            t = -c / u if u != 0.0 else 0.0
        else:
            disc = u * u - 2.0 * acc * c
            disc = disc if disc > 0.0 else 0.0
            r1 = (-u - math.sqrt(disc)) / acc
            r2 = (-u + math.sqrt(disc)) / acc
            t = dt
            if 0.0 <= r1 <= dt:
                t = r1
            if 0.0 <= r2 <= dt and r2 < t:
                t = r2
        d = (a - x0) / tx
        crossed[r, k] = True
        speed[r, k] = abs(u + acc * t)
        height[r, k] = z0 + d * tz - _ground(x, z, a)


@njit(cache=True)
def run_law(
    x, z, cells, nrest, trest, frict, sd, start_vel, stop_vel, release_x, keys, at, g
):
    """r.stone's law for each rock (module docstring).

    Parameters
    ----------
    x, z
        Vertices of the section [m], x increasing.
    cells
        Per vertex: the id of the DEM cell it lies in (a friction draw per cell
        entered).
    nrest, trest
        Per vertex (cell): restitution in whole percent as r.stone reads them.
    frict
        Per vertex: friction ``tan(beta)`` as r.stone reads it (thousandths).
    sd
        Gaussian SDs ``2 range / 100`` of nrest, trest, friction (3 values).
    start_vel, stop_vel
        r.stone's start and stop speeds [m/s].
    release_x
        Chainage of the release point [m] (on the ground).
    keys
        One uint64 random key per rock.
    at
        Analysis chainages [m].
    g
        Gravity [m/s²].

    Returns
    -------
    runout, state, bounces, crossed, speed, height
    """
    rocks = keys.size
    na = at.size
    n = x.size
    runout = np.empty(rocks)
    state = np.zeros(rocks, np.int64)
    bounces = np.zeros(rocks, np.int64)
    crossed = np.zeros((rocks, na), np.bool_)
    speed = np.full((rocks, na), np.nan)
    height = np.full((rocks, na), np.nan)
    vmin2 = stop_vel * stop_vel
    for r in range(rocks):
        key = keys[r]
        nb = 0
        nf = 0
        px = release_x
        j = _segment(x, px)
        if j < 0:
            runout[r] = x[0] if j == -1 else x[n - 1]
            state[r] = EXITED_UPSLOPE if j == -1 else EXITED_DOWNSLOPE
            continue
        pz = _ground(x, z, px)
        # towards the lower neighbour (TrackPoints: the steepest descent)
        k = _cell(x, px)
        left = z[k] - z[k - 1] if k > 0 else -np.inf
        right = z[k] - z[k + 1] if k < n - 1 else -np.inf
        vdir = 1.0 if right >= left else -1.0
        if vdir < 0.0 and px == x[j] and j > 0:
            j -= 1
        vx = vdir * start_vel
        vz = 0.0
        lbx, lbz = px, pz
        xw = px
        fly = True
        npath = 0
        forced = 0
        while True:
            if fly:
                kind, t, jj = _flight(x, z, g, px, pz, vx, vz, j)
                forced = forced + 1 if kind == 1 else 0
                if forced > MAX_FORCED:
                    state[r] = STOPPED
                    runout[r] = px
                    break
                _cross_flight(x, z, g, at, crossed, speed, height, r, px, pz, vx,
                              vz, t)  # fmt: skip
                if kind == 2:
                    state[r] = EXITED_UPSLOPE if jj == -1 else EXITED_DOWNSLOPE
                    runout[r] = x[0] if jj == -1 else x[n - 1]
                    break
                j = jj
                px = px + vx * t
                vz = vz - g * t
                s = (z[j + 1] - z[j]) / (x[j + 1] - x[j])
                pz = z[j] + s * (px - x[j])
                if kind == 0:
                    xw = px
                    d2 = (px - lbx) ** 2 + (pz - lbz) ** 2
                    v2 = vx * vx + vz * vz
                    if (
                        d2 < ROLL_DISTANCE_M * ROLL_DISTANCE_M
                        and v2 < ROLL_SPEED_MPS * ROLL_SPEED_MPS
                    ):
                        fly = False
                        npath = 0
                        continue
                # Bounce
                c = _cell(x, px)
                if nrest[c] == 0:
                    state[r] = STOPPED
                    runout[r] = px
                    break
                v_el = _clip01(nrest[c] / 100.0 + sd[0] * normal(key, nb, SLOT_NREST))
                h_el = _clip01(trest[c] / 100.0 + sd[1] * normal(key, nb, SLOT_TREST))
                nb += 1
                bounces[r] += 1
                norm = math.sqrt(1.0 + s * s)
                tx, tz = 1.0 / norm, s / norm
                vn = -vx * tz + vz * tx
                vt = vx * tx + vz * tz
                vn *= -v_el
                vt *= h_el
                vx = vt * tx - vn * tz
                vz = vt * tz + vn * tx
                if vx * vx + vz * vz < vmin2:
                    state[r] = STOPPED
                    runout[r] = px
                    break
                if kind == 0:
                    lbx, lbz = px, pz
                npath = 0
                continue
            # Roll on segment j from (px, pz) with velocity (vx, vz)
            s = (z[j + 1] - z[j]) / (x[j + 1] - x[j])
            norm = math.sqrt(1.0 + s * s)
            tx, tz = 1.0 / norm, s / norm
            d = (px - x[j]) * tx + (pz - z[j]) * tz
            u = vx * tx + vz * tz
            gt = -g * tz
            lcell = -1
            f = 0.0
            t = 0.0
            ended = False
            while True:
                cx = x[j] + d * tx
                c = _cell(x, cx)
                if cells[c] != lcell:
                    fc = _clip01(frict[c] + sd[2] * normal(key, nf, SLOT_FRICTION))
                    nf += 1
                    f = math.sin(math.atan(fc)) * g
                    lcell = cells[c]
                dirn = 0.0
                if u > 0.0:
                    dirn = 1.0
                elif u < 0.0:
                    dirn = -1.0
                vs = abs(u)
                if vs < f * t:
                    t = vs / f
                acc = gt - dirn * f
                _cross_roll(x, z, at, crossed, speed, height, r, x[j], z[j], tx, tz,
                            d, u, acc, t)  # fmt: skip
                d = d + u * t + 0.5 * acc * t * t
                u = u + acc * t
                npath += 1
                px = x[j] + d * tx
                pz = z[j] + d * tz
                if npath >= MAX_PATH:  # Track overflow: the path is not written
                    state[r] = STOPPED
                    runout[r] = xw
                    ended = True
                    break
                vs = abs(u)
                if vs < stop_vel or vs == 0.0:
                    state[r] = STOPPED
                    runout[r] = px
                    ended = True
                    break
                t = ROLL_STEP_M / vs
                if px < x[j] or px > x[j + 1]:
                    break
            if ended:
                break
            vx, vz = u * tx, u * tz
            jn = _segment(x, px)
            if jn < 0:
                state[r] = EXITED_UPSLOPE if jn == -1 else EXITED_DOWNSLOPE
                runout[r] = x[0] if jn == -1 else x[n - 1]
                break
            j = jn
            sn = (z[j + 1] - z[j]) / (x[j + 1] - x[j])
            above = ((pz - z[j]) - sn * (px - x[j])) / math.sqrt(1.0 + sn * sn)
            if above > FLY_HEIGHT_M:
                xw = px
                fly = True
                npath = 0
    return runout, state, bounces, crossed, speed, height


@dataclass
class LawResult:
    """A run of :class:`RstoneLaw`: the fields of a
    :class:`~fieldkit.model.results.SimulationResult` the translation error reads.

    Attributes
    ----------
    rocks
        Rocks run.
    runout_x_m
        (rocks,) chainage where each rock stopped or left the section [m].
    state
        (rocks,) :data:`~fieldkit.model.results.STOPPED`, ``EXITED_DOWNSLOPE`` or
        ``EXITED_UPSLOPE``.
    impacts_per_rock
        (rocks,) bounces of each rock.
    analysis
        One :class:`~fieldkit.model.results.AnalysisPoint` per analysis chainage
        (no rotation: ``re_j`` 0, ``total_j`` the translational energy).
    """

    rocks: int
    runout_x_m: np.ndarray
    state: np.ndarray
    impacts_per_rock: np.ndarray
    analysis: list[AnalysisPoint] = field(default_factory=list)


@dataclass(frozen=True)
class RstoneLaw:
    """r.stone's law with the values written, along a section (module docstring).

    Attributes
    ----------
    x_m, z_m
        The section's vertices, the cell centres along it [m] (x increasing).
    nrest_pct, trest_pct
        Per vertex (cell): nrest and trest as written, whole percent.
    friction_tan
        Per vertex: ``tan(beta)`` as r.stone reads it (thousandths).
    vrest_stoch_range, hrest_stoch_range, frict_stoch_range
        r.stone's spread ranges (Gaussian SD ``2 range / 100``).
    start_vel_mps, stop_vel_mps
        r.stone's ``start_vel`` and ``stop_vel``.
    release_x_m
        Where the rocks start, on the ground [m].
    mass_kg
        The rock's mass for energies (r.stone itself has none).
    cell_id
        Per vertex, the DEM cell it lies in (None: every vertex a cell centre,
        its own cell). A point takes the values of its nearest vertex and draws
        a new friction when that vertex's cell differs from the last one's.
    """

    x_m: np.ndarray
    z_m: np.ndarray
    nrest_pct: np.ndarray
    trest_pct: np.ndarray
    friction_tan: np.ndarray
    vrest_stoch_range: int
    hrest_stoch_range: int
    frict_stoch_range: int
    start_vel_mps: float
    stop_vel_mps: float
    release_x_m: float
    mass_kg: float
    cell_id: np.ndarray | None = None

    def __post_init__(self) -> None:
        x = np.asarray(self.x_m, float)
        if x.ndim != 1 or x.size < 2 or not np.all(np.diff(x) > 0):
            raise ArgumentError(
                "x_m must hold at least 2 increasing chainages", source="x_m"
            )
        for name in ("z_m", "nrest_pct", "trest_pct", "friction_tan", "cell_id"):
            if name == "cell_id" and self.cell_id is None:
                continue
            if np.shape(getattr(self, name)) != x.shape:
                raise ArgumentError(
                    f"{name} must have one value per vertex ({x.size})", source=name
                )

    @property
    def start_x_m(self) -> float:
        """Where the rocks start [m] (see ``translation.Emulation``)."""
        return float(self.release_x_m)

    @property
    def end_x_m(self) -> float:
        """The section's lower end [m]."""
        return float(np.asarray(self.x_m, float)[-1])

    def simulate(
        self,
        rocks: int,
        rng: np.random.Generator,
        analysis_x_m=(),
    ) -> LawResult:
        """Run ``rocks`` rocks with the random numbers of ``rng`` (one key per
        rock, drawn as :func:`fieldkit.model.simulate.simulate` draws them)."""
        keys = rng.integers(0, 2**63, size=int(rocks), dtype=np.uint64)
        at = np.asarray(list(analysis_x_m), float)
        sd = np.array(
            [
                2.0 * self.vrest_stoch_range / 100.0,
                2.0 * self.hrest_stoch_range / 100.0,
                2.0 * self.frict_stoch_range / 100.0,
            ]
        )
        x = np.ascontiguousarray(self.x_m, float)
        cells = (
            np.arange(x.size, dtype=np.int64)
            if self.cell_id is None
            else np.ascontiguousarray(self.cell_id, np.int64)
        )
        runout, state, bounces, crossed, speed, height = run_law(
            x,
            np.ascontiguousarray(self.z_m, float),
            cells,
            np.ascontiguousarray(self.nrest_pct, np.int64),
            np.ascontiguousarray(self.trest_pct, np.int64),
            np.ascontiguousarray(self.friction_tan, float),
            sd,
            float(self.start_vel_mps),
            float(self.stop_vel_mps),
            float(self.release_x_m),
            keys,
            at,
            G_MPS2,
        )
        points = []
        for k, a in enumerate(at):
            ke = 0.5 * self.mass_kg * speed[:, k] ** 2
            points.append(
                AnalysisPoint(
                    x_m=float(a),
                    crossed=crossed[:, k].copy(),
                    speed_mps=speed[:, k].copy(),
                    ke_j=ke,
                    re_j=np.where(crossed[:, k], 0.0, np.nan),
                    total_j=ke.copy(),
                    height_m=height[:, k].copy(),
                )
            )
        return LawResult(int(rocks), runout, state, bounces, points)
