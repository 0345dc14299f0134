"""Synthetic video tracks: a rock bouncing down a plane, with or without air drag.

The flights follow the simulator's drag physics (``a = g - k |v| v``, ``k`` from
:func:`fieldkit.model.effects.air_drag.drag_factor`), integrated accurately by
:mod:`fieldkit.model.drag_flight`. Each flight starts where the previous one landed
on the plane ``z = z0 - (x - x0) tan(psi)`` (the centre meets the ground line, as in
the lumped-mass model) with a *prescribed* launch speed and angle above the plane:
the rebound is given rather than modelled, so every flight has the length a test
wants. Samples are taken at ``k / fps``; Gaussian noise of ``noise_m`` is added to x
and z; the clean positions are kept in ``x_m_true``, ``z_m_true`` and the flight of
each sample in ``flight_true``.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from fieldkit.errors import ArgumentError
from fieldkit.model import drag_flight
from fieldkit.model.effects import air_drag
from fieldkit.physics.constants import G
from fieldkit.track import Track

#: RK4 step while looking for the landing [s] (then refined by bisection).
_LANDING_STEP_S = 1e-3

#: Half-width of the uniform spread of each flight's launch angle [deg].
LAUNCH_JITTER_DEG = 5.0

#: Most flights in one synthetic track (a filmed sequence has a handful).
MAX_FLIGHTS = 1_000

#: Fastest capture rate [1/s]: the top of high-speed video at useful resolution.
MAX_FPS = 100_000.0

#: Fastest launch speed [m/s]: free fall from 500 m reaches 99 m/s; rockfall
#: rebounds are tens of m/s.
MAX_LAUNCH_SPEED_MPS = 100.0

#: Largest position noise SD [m]: beyond a metre a video track measures nothing.
MAX_NOISE_M = 1.0

#: Longest track [s]: ten minutes of video (a filmed rockfall lasts seconds); the
#: flights are integrated in 1 ms steps, so this also bounds the work.
MAX_TRACK_S = 600.0

#: Most samples in one track (8 flights of 1 s at 200 frames/s are 1,600): a
#: million samples is about 70 MB of CSV.
MAX_TRACK_SAMPLES = 1_000_000


def check_track_options(
    *,
    flights: int,
    launch_speed_mps: float,
    launch_angle_deg: float,
    fps: float,
    noise_m: float,
) -> None:
    """Refuse options of a synthetic track outside their physical range.

    ``flights`` 1 .. :data:`MAX_FLIGHTS`, launch speed in (0,
    :data:`MAX_LAUNCH_SPEED_MPS`] m/s, mean launch angle above the plane within
    (0, 90) deg by :data:`LAUNCH_JITTER_DEG` (the angle each flight is drawn from),
    ``fps`` in (0, :data:`MAX_FPS`], ``noise_m`` in [0, :data:`MAX_NOISE_M`] m.
    """
    checks = (
        ("flights", flights, 1 <= flights <= MAX_FLIGHTS, f"from 1 to {MAX_FLIGHTS:,}"),
        ("launch_speed_mps", launch_speed_mps,
         0 < launch_speed_mps <= MAX_LAUNCH_SPEED_MPS,
         f"in (0, {MAX_LAUNCH_SPEED_MPS:g}] m/s (free fall from 500 m reaches 99 m/s)"),
        ("launch_angle_deg", launch_angle_deg,
         LAUNCH_JITTER_DEG < launch_angle_deg < 90 - LAUNCH_JITTER_DEG,
         f"in ({LAUNCH_JITTER_DEG:g}, {90 - LAUNCH_JITTER_DEG:g}) deg: each flight's "
         f"angle is drawn within +-{LAUNCH_JITTER_DEG:g} deg and must stay above the "
         "plane and ahead, down-slope"),
        ("fps", fps, 0 < fps <= MAX_FPS,
         f"in (0, {MAX_FPS:,.0f}] frames/s (high-speed video)"),
        ("noise_m", noise_m, 0 <= noise_m <= MAX_NOISE_M,
         f"in [0, {MAX_NOISE_M:g}] m (a noisier track measures nothing)"),
    )  # fmt: skip
    for name, value, ok, bound in checks:
        if not (math.isfinite(value) and ok):
            got = value if isinstance(value, int) else f"{value:g}"
            raise ArgumentError(f"{name} must be {bound} (got {got})", source=name)


def _landing(state: np.ndarray, k: float, tan_psi: float, x0: float, z0: float):
    """Time of flight and landing state of a flight leaving the plane at ``state``."""

    def height(s: np.ndarray) -> float:
        return s[1] - (z0 - (s[0] - x0) * tan_psi)

    t = 0.0
    for _ in range(int(60.0 / _LANDING_STEP_S)):
        nxt = drag_flight.step_state(state, _LANDING_STEP_S, k, G)
        if height(nxt) < 0.0 and t > 0.0:
            lo, hi = 0.0, _LANDING_STEP_S
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if height(drag_flight.step_state(state, mid, k, G)) < 0.0:
                    hi = mid
                else:
                    lo = mid
            return t + hi, drag_flight.step_state(state, hi, k, G)
        state, t = nxt, t + _LANDING_STEP_S
    raise ArgumentError("a flight does not land within 60 s", source="launch_angle_deg")


def synthetic_track(
    *,
    radius_m: float,
    mass_kg: float,
    cd: float,
    launch_speed_mps: np.ndarray,
    launch_angle_deg: np.ndarray,
    surface_angle_deg: float,
    fps: float,
    noise_m: float,
    rng: np.random.Generator,
    air_density_kg_m3: float = 1.225,
    start_xz_m: tuple[float, float] = (0.0, 0.0),
) -> Track:
    """A track of ``len(launch_speed_mps)`` flights down a plane, sampled at ``fps``.

    Parameters
    ----------
    radius_m, mass_kg
        The body (drag factor ``k = rho cd pi r^2 / (2 m)``).
    cd, air_density_kg_m3
        ``air_drag`` parameters; ``cd = 0`` gives exact parabolas.
    launch_speed_mps, launch_angle_deg
        Per flight: launch speed [m/s] > 0 and angle above the plane [deg] in
        (0, 90), measured from the down-slope direction (the direction of travel).
    surface_angle_deg
        Dip of the plane psi [deg], positive descending toward +x.
    fps
        Capture rate [1/s].
    noise_m
        SD of the Gaussian noise on x and z [m].
    rng
        Random generator for the noise.
    start_xz_m
        Where the first flight leaves the plane.

    Returns
    -------
    Track
        Columns of a track file plus ``x_m_true``, ``z_m_true``, ``flight_true``
        and the body (``body_radius_m``, ``body_mass_kg``);
        ``meta`` holds the truth (``cd``, ``k_per_m``, flight times; without drag
        a flight lasts ``2 v sin(angle) / (g cos psi)``, 0.609 s below).

    Examples
    --------
    >>> tr = synthetic_track(radius_m=0.2, mass_kg=88.8, cd=0.0,
    ...     launch_speed_mps=np.full(3, 10.0), launch_angle_deg=np.full(3, 15.0),
    ...     surface_angle_deg=30.0, fps=100, noise_m=0.0,
    ...     rng=np.random.default_rng(0))
    >>> sorted(set(tr.frame["flight_true"])), round(tr.meta["flight_s"][0], 3)
    ([0, 1, 2], 0.609)
    """
    speeds = np.atleast_1d(np.asarray(launch_speed_mps, float))
    angles = np.atleast_1d(np.asarray(launch_angle_deg, float))
    if speeds.shape != angles.shape or speeds.size == 0:
        raise ArgumentError(
            "launch_speed_mps and launch_angle_deg need one value per flight",
            source="launch_speed_mps",
        )
    if not (np.all(speeds > 0) and np.all((angles > 0) & (angles < 90))):
        # above 90 deg a flight leaves the plane backwards, up-slope: x must
        # increase in the direction of travel (ARCHITECTURE §2)
        raise ArgumentError(
            "launch speeds must be > 0 and angles above the plane in (0, 90) deg "
            "(ahead, down-slope)",
            source="launch_speed_mps",
        )
    if not fps > 0 or not noise_m >= 0 or not cd >= 0:
        raise ArgumentError("fps must be > 0, noise_m and cd >= 0", source="fps")
    k = float(air_drag.drag_factor(cd, air_density_kg_m3, radius_m, mass_kg))
    tan_psi = math.tan(math.radians(surface_angle_deg))
    x0, z0 = start_xz_m
    starts, states, durations = [], [], []
    t, pos = 0.0, np.array(start_xz_m, float)
    for i, (speed, angle) in enumerate(zip(speeds, angles, strict=True)):
        if t > MAX_TRACK_S or t * fps >= MAX_TRACK_SAMPLES:  # before more work
            raise ArgumentError(
                f"the first {i} of {len(speeds)} flights already last {t:.1f} s, "
                f"{math.floor(t * fps) + 1:,} samples at fps {fps:g}: a track holds "
                f"at most {MAX_TRACK_S:g} s and {MAX_TRACK_SAMPLES:,} samples (fewer "
                "flights, a lower fps or slower launches)",
                source="fps" if t <= MAX_TRACK_S else "flights",
            )
        theta = math.radians(angle - surface_angle_deg)
        state = np.array(
            [pos[0], pos[1], speed * math.cos(theta), speed * math.sin(theta)]
        )
        duration, end = _landing(state, k, tan_psi, x0, z0)
        starts.append(t)
        states.append(state)
        durations.append(duration)
        t += duration
        pos = end[:2]
    samples = math.floor(t * fps) + 1
    if t > MAX_TRACK_S or samples > MAX_TRACK_SAMPLES:
        raise ArgumentError(
            f"{len(speeds)} flights lasting {t:.1f} s at fps {fps:g} would make "
            f"{samples:,} samples: a track holds at most {MAX_TRACK_S:g} s and "
            f"{MAX_TRACK_SAMPLES:,} samples (fewer flights, a lower fps or slower "
            "launches)",
            source="fps" if t <= MAX_TRACK_S else "flights",
        )
    times = np.arange(0, samples) / fps
    x_true, z_true = np.empty(times.size), np.empty(times.size)
    flight = np.searchsorted(np.array(starts), times, side="right") - 1
    for i, (s, st) in enumerate(zip(starts, states, strict=True)):
        rows = np.flatnonzero(flight == i)
        if rows.size == 0:
            continue
        tt = np.concatenate([[s], times[rows]])
        xs, zs, _, _ = drag_flight.flight_path(
            tt, st[0], st[1], st[2], st[3], k, G, drag_flight.MAX_STEP_S
        )
        x_true[rows], z_true[rows] = xs[1:], zs[1:]
    noise = rng.normal(0.0, noise_m, (times.size, 2)) if noise_m > 0 else 0.0
    frame = pd.DataFrame(
        {
            "frame": np.arange(times.size),
            "t_s": times,
            "x_m": x_true + (noise[:, 0] if noise_m > 0 else 0.0),
            "z_m": z_true + (noise[:, 1] if noise_m > 0 else 0.0),
            "angle_rad": np.nan,
            "omega_radps": np.nan,
            "x_m_true": x_true,
            "z_m_true": z_true,
            "flight_true": flight,
            # the body, so `fieldkit diagnose` reads it (as from `fieldkit track`)
            "body_radius_m": radius_m,
            "body_mass_kg": mass_kg,
        }
    )
    meta = {
        "cd": cd,
        "k_per_m": k,
        "radius_m": radius_m,
        "mass_kg": mass_kg,
        "noise_m": noise_m,
        "flight_start_s": starts,
        "flight_s": durations,
    }
    return Track(frame, source="synthetic", fps=fps, meta=meta)
