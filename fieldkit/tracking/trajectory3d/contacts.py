"""Where two consecutive flights meet: an impact on the ground, or a misfit.

With g fixed the difference of two fitted flights is linear in time (the gravity
terms cancel), so the time they come closest is closed form (:func:`meet_time`);
there the incoming and outgoing velocities are the two fits' velocities, and the
contact point the mean of their positions.

**No contact without the ground.** A join is an impact only when

* the flights meet: closest approach within ``tolerance_m``, between the last
  sample of the first and the first sample of the second (one sampling interval
  either side);
* the centre there is within ``radius_m + tolerance_m`` of the local ground plane
  (:mod:`.surface`) and not more than ``tolerance_m`` below it;
* it arrives into the ground and leaves out of it (``vin < 0``, ``vfn > 0``:
  ``e_n < 0`` is never an impact).

Otherwise the join is a :class:`Contact` of kind ``misfit`` with the reason in
words (a flight split in mid-air is not ballistic there: air drag, a spin-induced
lift, or a wrong time base). Two flights that do not meet but end and start on the
ground with at least :data:`RESOLVED_GAP_SAMPLES` samples between them are a
*resolved* contact (the block was on the ground for several samples): its
duration is the time between the two flights' end and start samples, the impact
velocity the first flight's at its end, the rebound the second's at its start.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from fieldkit.model.terrain import Terrain
from fieldkit.physics.constants import G
from fieldkit.tracking.trajectory3d.flights import (
    FALSE_ALARM,
    MIN_FLIGHT_SAMPLES,
    MIN_NOISE_SD_M,
    Flight3D,
    fit_flight,
)
from fieldkit.tracking.trajectory3d.surface import LocalPlane, local_plane

#: Samples at each end of a flight left out of the fit that places the join.
BOUNDARY_SAMPLES = 3
#: Passes of the boundary re-assignment at each join.
REFINE_PASSES = 3
#: Samples between two flights from which a contact's duration counts as resolved.
RESOLVED_GAP_SAMPLES = 2
#: A segment whose ballistic arc (g T^2 / 8) rises more than this many noise SDs
#: is a flight, never a ground phase (:func:`on_the_ground`).
GROUND_ARC_SDS = 2.0
#: Samples at each side of a contact whose median spin is the spin before / after.
SPIN_SAMPLES = 3


@dataclass(frozen=True)
class Contact:
    """A join between flight ``flight`` and ``flight + 1`` (numbered from 1).

    ``kind`` is ``impact`` or ``misfit`` (then ``reason`` says why, and the
    velocities may be NaN).
    """

    flight: int
    kind: str
    reason: str
    t_s: float
    point_m: np.ndarray
    vi_mps: np.ndarray
    vf_mps: np.ndarray
    plane: LocalPlane | None
    height_m: float
    miss_m: float
    duration_s: float
    omega_i_radps: float
    omega_f_radps: float
    vi_sd_mps: float = float("nan")
    vf_sd_mps: float = float("nan")
    omega_vector_i_radps: np.ndarray | None = None
    omega_vector_f_radps: np.ndarray | None = None


def on_the_ground(
    t_s: np.ndarray,
    xyz_m: np.ndarray,
    f: Flight3D,
    terrain: Terrain,
    *,
    radius_m: float,
    tolerance_m: float,
    footprint_m: float,
    sigma_m: float,
) -> bool:
    """Whether the samples of ``f`` never leave the ground: their centre stays
    within ``radius_m + tolerance_m`` of the ground plane under them at a height
    above it that is constant within the noise (chi-square at
    :data:`~.flights.FALSE_ALARM`), and a ballistic arc of their duration would
    rise no more than :data:`GROUND_ARC_SDS` noise SDs (``g T^2 / 8``), so the
    two cannot be told apart. A block resting, sliding or rolling for a few
    samples can also pass for a slow ballistic flight (g t^2/2 is 1.5 cm in 55 ms);
    it is a contact, not a flight between two impacts."""
    sigma = max(float(sigma_m), MIN_NOISE_SD_M)
    duration = float(t_s[f.end - 1] - t_s[f.start])
    if G * duration**2 / 8.0 > GROUND_ARC_SDS * sigma:
        return False  # a ballistic arc this long rises measurably: a flight
    q = np.asarray(xyz_m)[f.start : f.end]
    mid = np.median(q, axis=0)
    plane = local_plane(terrain, mid[0], mid[1], footprint_m)
    if plane is None:
        return False
    h = np.array([plane.distance(p, mid[0], mid[1]) for p in q])
    if h.max() > radius_m + tolerance_m:
        return False
    ss = float(np.sum((h - h.mean()) ** 2)) / (sigma * sigma)
    return ss <= chi2.isf(FALSE_ALARM, len(h) - 1)


def meet_time(a: Flight3D, b: Flight3D) -> float:
    """Time at which two fitted flights come closest (g cancels: linear difference;
    with air drag, searched between the first's last sample and the second's
    first, widened by their gap either side)."""
    if a.drag_per_m > 0 or b.drag_per_m > 0:
        gap = max(b.t_ref_s - a.t_last_s, 1e-3)
        lo, hi = a.t_last_s - gap, b.t_ref_s + gap
        for _ in range(3):
            ts = np.linspace(lo, hi, 41)
            d = a.position(ts) - b.position(ts)
            i = int(np.argmin(np.einsum("ij,ij->i", d, d)))
            step = ts[1] - ts[0]
            lo, hi = ts[max(i - 1, 0)], ts[min(i + 1, 40)]
            if step < 1e-6:
                break
        return float(ts[i])
    # p(t) = p0 + v0 (t - tr) - g (t - tr)^2/2 z = c + lin t - g t^2/2 z: the
    # difference of two flights is c_a - c_b + (lin_a - lin_b) t
    c_a = a.p0_m - a.v0_mps * a.t_ref_s - 0.5 * G * a.t_ref_s**2 * _Z
    c_b = b.p0_m - b.v0_mps * b.t_ref_s - 0.5 * G * b.t_ref_s**2 * _Z
    lin_a = a.v0_mps + G * a.t_ref_s * _Z
    lin_b = b.v0_mps + G * b.t_ref_s * _Z
    d0 = c_a - c_b
    dv = lin_a - lin_b
    den = float(dv @ dv)
    return float(-(d0 @ dv) / den) if den > 0 else float("nan")


_Z = np.array([0.0, 0.0, 1.0])


def _fits(t, p, idx, fl, sigma, bound) -> bool:
    e = p[idx] - fl.position(t[idx])
    return float(e @ e) / (sigma * sigma) <= bound


def refine_joins(
    t_s: np.ndarray,
    xyz_m: np.ndarray,
    ranges: list[tuple[int, int]],
    sigma_m: float,
    drag_per_m: float = 0.0,
) -> list[tuple[int, int]]:
    """Move the samples around each join to the flight on their side of the time
    the two flights meet (fitted without :data:`BOUNDARY_SAMPLES` at the join),
    keeping only samples that fit it; the others lie between the flights."""
    t = np.asarray(t_s, float)
    p = np.asarray(xyz_m, float)
    sigma = max(float(sigma_m), MIN_NOISE_SD_M)
    bound = chi2.isf(FALSE_ALARM, 3)
    m, k = MIN_FLIGHT_SAMPLES, BOUNDARY_SAMPLES
    out = list(ranges)
    for j in range(len(out) - 1):
        for _ in range(REFINE_PASSES):
            (a0, a1), (b0, b1) = out[j], out[j + 1]
            fa = fit_flight(t, p, a0, max(a0 + m, a1 - k) if a1 - a0 > m else a1,
                            drag_per_m=drag_per_m)  # fmt: skip
            fb = fit_flight(t, p, min(b1 - m, b0 + k) if b1 - b0 > m else b0, b1,
                            drag_per_m=drag_per_m)  # fmt: skip
            ts = meet_time(fa, fb)
            if not np.isfinite(ts):
                break
            ea = fa.end
            while ea < b1 and t[ea] < ts and _fits(t, p, ea, fa, sigma, bound):
                ea += 1
            while ea > a0 + m and t[ea - 1] > ts:
                ea -= 1
            sb = fb.start
            while sb - 1 >= ea and t[sb - 1] > ts and _fits(t, p, sb - 1, fb, sigma,
                                                             bound):  # fmt: skip
                sb -= 1
            while sb < b1 - m and t[sb] < ts:
                sb += 1
            new = [(a0, ea), (sb, b1)]
            if new == out[j : j + 2]:
                break
            out[j : j + 2] = new
    return out


def _reach(f: Flight3D, plane: LocalPlane, at: np.ndarray, h_m: float,
           near_s: float) -> float:  # fmt: skip
    """The time nearest ``near_s`` at which flight ``f`` is ``h_m`` above ``plane``
    (the plane's point under ``at``); NaN if never."""
    n = plane.normal
    ground = np.array([at[0], at[1], plane.z_m])
    if f.drag_per_m > 0:
        span = max(abs(near_s - f.t_ref_s), abs(near_s - f.t_last_s), 0.05)
        ts = np.linspace(near_s - span, near_s + span, 801)
        h = (f.position(ts) - ground) @ n - h_m
        cross = np.flatnonzero(np.sign(h[:-1]) != np.sign(h[1:]))
        if cross.size == 0:
            return float("nan")
        tc = ts[cross] - h[cross] * (ts[cross + 1] - ts[cross]) / (
            h[cross + 1] - h[cross]
        )
        return float(tc[np.argmin(np.abs(tc - near_s))])
    tr = f.t_ref_s
    # (p0 + v0 tau - g tau^2/2 z - ground) . n = h
    qa = -0.5 * G * n[2]
    qb = float(f.v0_mps @ n)
    qc = float((f.p0_m - ground) @ n) - h_m
    roots = np.roots([qa, qb, qc]) if qa != 0 else np.array([-qc / qb])
    roots = roots[np.isreal(roots)].real + tr
    if roots.size == 0:
        return float("nan")
    return float(roots[np.argmin(np.abs(roots - near_s))])


def _spin_vector(omega, idx) -> np.ndarray | None:
    if omega is None:
        return None
    return np.array([_spin(omega[:, c], idx) for c in range(3)])


def _spin(omega, idx) -> float:
    if omega is None:
        return float("nan")
    v = omega[idx]
    v = v[np.isfinite(v)]
    return float(np.median(v)) if v.size else float("nan")


def classify_join(
    j: int,
    t_s: np.ndarray,
    a: Flight3D,
    b: Flight3D,
    terrain: Terrain,
    *,
    radius_m: float,
    tolerance_m: float,
    footprint_m: float,
    omega: np.ndarray | None,
    xyz_m: np.ndarray | None = None,
    omega_vector: np.ndarray | None = None,
) -> Contact:
    """The join of flights ``a`` and ``b`` (flight numbers ``j``, ``j + 1``)."""
    t = np.asarray(t_s, float)
    dt = float(np.median(np.diff(t)))
    ts = meet_time(a, b)
    t_end, t_start = t[a.end - 1], t[b.start]
    before = np.arange(max(a.start, a.end - SPIN_SAMPLES), a.end)
    after = np.arange(b.start, min(b.end, b.start + SPIN_SAMPLES))
    spin_i = _spin(omega, before)
    spin_f = _spin(omega, after)
    meets = np.isfinite(ts) and t_end - dt <= ts <= t_start + dt
    miss = float(np.linalg.norm(a.position(ts) - b.position(ts))) if meets else np.inf
    meets = meets and miss <= tolerance_m
    gap = b.start - a.end
    if meets:
        t_c = ts
        point = 0.5 * (a.position(ts) + b.position(ts))
        vi, vf = a.velocity(ts), b.velocity(ts)
        duration = float("nan")
    else:
        t_c = t_end
        point = a.position(t_end)
        vi, vf = a.velocity(t_end), b.velocity(t_start)
        duration = float(t_start - t_end)

    def done(kind, reason, plane=None, height=float("nan")):
        return Contact(j, kind, reason, float(t_c), point, vi, vf, plane, height,
                       miss, duration if kind == "impact" else float("nan"),
                       spin_i, spin_f, a.v_sd_mps, b.v_sd_mps,
                       _spin_vector(omega_vector, before),
                       _spin_vector(omega_vector, after))  # fmt: skip

    plane = local_plane(terrain, point[0], point[1], footprint_m)
    if plane is None:
        return done("misfit", f"flights {j} and {j + 1} join off the DEM's surface")
    height = plane.distance(point, point[0], point[1])
    reach = radius_m + tolerance_m
    if not meets and gap >= RESOLVED_GAP_SAMPLES and xyz_m is not None:
        # on the ground for several samples: where the flights reach the height the
        # block kept between them, against the plane under those samples
        mid = np.median(np.asarray(xyz_m)[a.end : b.start], axis=0)
        under = local_plane(terrain, mid[0], mid[1], footprint_m)
        if under is not None:
            h_c = float(np.median([under.distance(q, mid[0], mid[1])
                                   for q in np.asarray(xyz_m)[a.end : b.start]]))
            t_in = _reach(a, under, mid, h_c, t_end)
            t_out = _reach(b, under, mid, h_c, t_start)
            if np.isfinite(t_in) and np.isfinite(t_out) and t_out > t_in:
                t_c, duration = t_in, float(t_out - t_in)
                point = a.position(t_in)
                vi, vf = a.velocity(t_in), b.velocity(t_out)
                plane = local_plane(terrain, point[0], point[1], footprint_m)
                if plane is None:
                    return done("misfit", f"flights {j} and {j + 1} join off the "
                                "DEM's surface")  # fmt: skip
                height = plane.distance(point, point[0], point[1])
    if not meets:
        end_h = height
        start_p = b.position(t_start)
        start_plane = local_plane(terrain, start_p[0], start_p[1], footprint_m)
        start_h = (
            start_plane.distance(start_p, start_p[0], start_p[1])
            if start_plane is not None
            else np.inf
        )
        if gap >= RESOLVED_GAP_SAMPLES and end_h <= reach and start_h <= reach:
            pass  # a contact resolved by the sampling: checked as an impact below
        else:
            why = (
                f"flights {j} and {j + 1} do not meet (closest {miss:.3f} m apart"
                f" at t = {ts:.3f} s)"
                if np.isfinite(miss)
                else f"flights {j} and {j + 1} do not meet between their samples"
            )
            return done("misfit", f"{why}: a flight is not ballistic there "
                        "(try air_drag) or a contact was not sampled", plane,
                        height)  # fmt: skip
    if height > reach:
        return done(
            "misfit",
            f"flights {j} and {j + 1} meet {height:.2f} m above the ground at t = "
            f"{t_c:.3f} s (more than radius + tolerance {reach:.2f} m): a mid-air "
            "split, not an impact -- the flight is not ballistic there (try "
            "air_drag)",
            plane,
            height,
        )
    if height < -tolerance_m:
        return done(
            "misfit",
            f"flights {j} and {j + 1} meet {-height:.2f} m below the DEM's surface "
            f"at t = {t_c:.3f} s (more than the tolerance {tolerance_m:.2f} m): the "
            "DEM or the trajectory's coordinates are off there",
            plane,
            height,
        )
    n = plane.normal
    vin, vfn = float(vi @ n), float(vf @ n)
    if not vin < 0:
        return done("misfit", f"at t = {t_c:.3f} s the block arrives out of the "
                    f"ground (vin {vin:+.2f} m/s): not an impact", plane,
                    height)  # fmt: skip
    if not vfn > 0:
        return done("misfit", f"at t = {t_c:.3f} s the rebound points into the "
                    f"ground (vfn {vfn:+.2f} m/s, e_n < 0): not an impact", plane,
                    height)  # fmt: skip
    return done("impact", "", plane, height)
