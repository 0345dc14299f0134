"""Contact phases on nets: velocity, impulse and energy while a body is in the net.

Thesis §8.5 (model tests at 1205 fps): a ball "rolls" down an inclined net for tens of
frames; its speed falls from ``V_i`` to a minimum and rises a little as it rebounds
(Fig. 8.14); the impulse absorbed, ``m (V_i - V(t))``, grows steadily during contact
(Fig. 8.15); the energy efficiency of the fence is the share of the impact energy the
body keeps (eq. 8.1)::

    E_e = E_f / E_i,     E = 1/2 m v^2 + 1/2 I omega^2

For an extended contact between two fitted flights, :func:`analyse_net_contact`
returns these as time series (speed by local quadratic differentiation of the tracked
centre; the end points come from the flight fits) and summary numbers. Eq. 8.1 itself
is :func:`fieldkit.physics.fences.energy_efficiency`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from fieldkit.physics.constants import G
from fieldkit.physics.fences import energy_efficiency
from fieldkit.track import Track
from fieldkit.tracking.flights.ballistic_fit import FlightFit


@dataclass
class NetContact:
    """One extended contact of a body with a net (or any deforming surface).

    Attributes
    ----------
    index
        Contact number along the track.
    before, after
        Flights before and after the contact.
    t_start_s, t_end_s, duration_s
        Contact start and end [s] where the net force sets in and fades out
        (:func:`contact_onset`; by default the last sample of the flight before and
        the first of the flight after), and the duration; ``n_frames`` frames apart.
        This is the contact of the *force*: a damped net stops pushing while the body
        is still inside its undeformed plane (the force ``k d + c d'`` reaches zero
        with ``d > 0``), and from then on the track is ballistic, so a contact defined
        by penetration cannot be seen in it. On the rendered ``video/net`` clip the
        force acts for frames 292.97-355.60 and the ball leaves the net's plane at
        frame 361.9; the end found is 0.4 frame after the force's end, the start 1.3
        frames after its onset.
    t_s, speed_mps, vx_mps, vz_mps
        Time series through the contact [s], [m/s] (first and last value from the flight
        fits).
    impulse_absorbed_fraction
        ``1 - V(t)/V_i``: the speed deficit, the thesis' "impulse absorbed"
        ``m (V_i - V(t))`` per ``m V_i`` (Fig. 8.15) [-]. A difference of speeds, not
        the impulse vector: see :attr:`net_impulse_fraction`.
    net_impulse_ns
        Magnitude of the impulse the net has applied so far, gravity removed,
        ``m |v(t) - v_i - g (t - t_i)|`` [N s]; NaN without mass.
    vi_mps, vf_mps, v_min_mps, t_min_s
        Speed at contact start, end, the minimum and when it occurs (from start) [s].
    energy_i_j, energy_f_j, absorbed_j
        Total (translational + rotational) energy before and after, and their
        difference [J]; NaN without mass.
    efficiency
        Eq. 8.1, ``E_f / E_i`` [-] (per unit mass when no mass is given), over the
        force contact (``video/net``: 71.34 % against 71.44 % at the true ends of the
        force, 72.95 % at the end of penetration, after 5 ballistic frames).
    rotation_included
        Whether the energies include the rotational energy (gyration and the spin
        before and after known); without it they are translational only.
    """

    index: int
    before: int
    after: int
    t_start_s: float
    t_end_s: float
    n_frames: int
    t_s: np.ndarray = field(repr=False)
    vx_mps: np.ndarray = field(repr=False)
    vz_mps: np.ndarray = field(repr=False)
    speed_mps: np.ndarray = field(repr=False)
    impulse_absorbed_fraction: np.ndarray = field(repr=False)
    net_impulse_ns: np.ndarray = field(repr=False)
    vi_mps: float = float("nan")
    vf_mps: float = float("nan")
    v_min_mps: float = float("nan")
    t_min_s: float = float("nan")
    energy_i_j: float = float("nan")
    energy_f_j: float = float("nan")
    absorbed_j: float = float("nan")
    efficiency: float = float("nan")
    rotation_included: bool = False

    @property
    def duration_s(self) -> float:
        return self.t_end_s - self.t_start_s

    @property
    def net_impulse_fraction(self) -> np.ndarray:
        """Magnitude of the impulse the net has applied so far, gravity removed, per
        impact momentum: ``|v(t) - v_i - g (t - t_i)| / V_i`` [-] (``net_impulse_ns``
        divided by ``m V_i``, known without the mass)."""
        dvx = self.vx_mps - self.vx_mps[0]
        dvz = self.vz_mps - self.vz_mps[0] + G * (self.t_s - self.t_s[0])
        return np.hypot(dvx, dvz) / self.vi_mps

    def summary(self) -> str:
        """One line for the console: times, speeds and the energy efficiency (eq. 8.1),
        saying what the energies include."""
        notes = [
            f"absorbed {self.absorbed_j:.3g} J"
            if np.isfinite(self.absorbed_j)
            else "per unit mass (no mass given)",
            "translational + rotational energy"
            if self.rotation_included
            else "translational energy only (no spin or gyration)",
        ]
        return (
            f"net contact {self.index}: t {self.t_start_s:.4f}-{self.t_end_s:.4f} s "
            f"({1e3 * self.duration_s:.1f} ms), V_i {self.vi_mps:.3f} -> V_min "
            f"{self.v_min_mps:.3f} -> V_f {self.vf_mps:.3f} m/s; energy efficiency "
            f"E_f/E_i (eq. 8.1) {100 * self.efficiency:.1f} %; {'; '.join(notes)}"
        )

    def to_frame(self) -> pd.DataFrame:
        """The contact time series (time from contact start)."""
        return pd.DataFrame(
            {
                "contact": self.index,
                "t_s": self.t_s,
                "t_from_start_s": self.t_s - self.t_start_s,
                "vx_mps": self.vx_mps,
                "vz_mps": self.vz_mps,
                "speed_mps": self.speed_mps,
                "impulse_absorbed_fraction": self.impulse_absorbed_fraction,
                "net_impulse_ns": self.net_impulse_ns,
            }
        )


def contact_onset(
    track: Track, flight: FlightFit, rows: np.ndarray, *, forward: bool = True
) -> float:
    """When a fading or growing contact force starts (or stops) acting [s].

    The per-sample test that ends a flight notices a soft contact only once the
    deviation from the parabola exceeds the noise, several frames after the force
    began (a net's force grows from zero). Here the deviation of the samples from
    the flight's parabola, projected on its final direction, is fitted with the onset
    law ``s(t) = a max(0, t - t0)^p`` (p = 2: force jumps to a finite value, a damper;
    p = 3: force grows linearly, a spring), searching ``t0`` on a fine grid; zero-mean
    noise before the onset, a power law after. With ``forward=False`` the same is
    done backward in time from the flight after the contact (its start).

    Parameters
    ----------
    track
        The track.
    flight
        The flight before (``forward``) or after the contact.
    rows
        Track positions of the contact samples.

    Returns
    -------
    float
        The onset time ``t0`` [s] (the flight's boundary when the fit fails).
    """
    edge = flight.rows[-10:] if forward else flight.rows[:10]
    use = np.concatenate([edge, rows]) if forward else np.concatenate([rows, edge])
    t = track.t[use]
    px, pz = flight.position(t)
    dev = np.column_stack([track.x[use] - px, track.z[use] - pz])
    ok = np.isfinite(dev).all(axis=1)
    t, dev = t[ok], dev[ok]
    boundary = flight.t_end_s if forward else flight.t_start_s
    if len(t) < 8:
        return boundary
    order = np.argsort(t) if forward else np.argsort(-t)
    t, dev = t[order], dev[order]
    size = np.hypot(dev[:, 0], dev[:, 1])
    # fit up to where the deviation is 100x its level along the flight (tuned on
    # spring-damper captures: within a frame of the true start and end)
    level = max(float(np.median(size[: len(edge)])), 1e-12)
    stop = (
        int(np.argmax(size > 100.0 * level)) if (size > 100.0 * level).any() else len(t)
    )
    stop = max(stop, len(edge) + 3)
    t, dev, size = t[:stop], dev[:stop], size[:stop]
    direction = dev[-3:].mean(axis=0)
    norm = np.hypot(*direction)
    if norm == 0:
        return boundary
    s = dev @ (direction / norm)
    tau = (t - t[0]) if forward else (t[0] - t)
    dt = float(np.median(np.diff(tau)))
    best = (np.inf, boundary)
    for tau0 in np.arange(0.0, tau[-2], dt / 10.0):
        for p in (2.0, 3.0):
            basis = np.clip(tau - tau0, 0.0, None) ** p
            norm2 = basis @ basis
            if norm2 == 0:
                continue
            a = (basis @ s) / norm2
            sse = float(np.sum((s - a * basis) ** 2))
            if a > 0 and sse < best[0]:
                best = (sse, float(t[0] + tau0) if forward else float(t[0] - tau0))
    return best[1]


def local_velocity(t: np.ndarray, p: np.ndarray, half_window: int = 4) -> np.ndarray:
    """Derivative of ``p(t)``: local quadratic over ``2 h + 1`` samples (clipped)."""
    n = len(t)
    out = np.full(n, np.nan)
    for i in range(n):
        lo, hi = max(0, i - half_window), min(n, i + half_window + 1)
        if hi - lo < 3:
            continue
        tau = t[lo:hi] - t[i]
        coef = np.polyfit(tau, p[lo:hi], 2)
        out[i] = coef[1]
    return out


def analyse_net_contact(
    track: Track,
    rows: np.ndarray,
    before: FlightFit,
    after: FlightFit,
    *,
    index: int = 0,
    mass_kg: float | None = None,
    gyration_m: float | None = None,
    omega_i_radps: float = float("nan"),
    omega_f_radps: float = float("nan"),
    t_start_s: float | None = None,
    t_end_s: float | None = None,
) -> NetContact:
    """Velocity, impulse and energy through one extended contact.

    Parameters
    ----------
    track
        The track (positions in metres, times in seconds).
    rows
        Track positions of the samples in contact (between the two flights).
    before, after
        The fitted flights before and after the contact.
    mass_kg, gyration_m
        Body mass and radius of gyration; rotational energy counts only when both the
        gyration and the spins are known.
    omega_i_radps, omega_f_radps
        Spin before and after the contact [rad/s].
    t_start_s, t_end_s
        Contact start and end [s] (:func:`contact_onset`); default the last sample of
        the flight before and the first of the flight after.
    """
    t_start = before.t_end_s if t_start_s is None else t_start_s
    t_end = after.t_start_s if t_end_s is None else t_end_s
    use = np.unique(
        np.concatenate([before.rows[-15:], np.asarray(rows, int), after.rows[:15]])
    )
    t = track.t[use]
    vx = local_velocity(t, track.x[use])
    vz = local_velocity(t, track.z[use])
    inside = (t > t_start) & (t < t_end)
    vi = np.array([float(v) for v in before.velocity(t_start)])
    vf = np.array([float(v) for v in after.velocity(t_end)])
    ts = np.concatenate([[t_start], t[inside], [t_end]])
    vxs = np.concatenate([[vi[0]], vx[inside], [vf[0]]])
    vzs = np.concatenate([[vi[1]], vz[inside], [vf[1]]])
    speed = np.hypot(vxs, vzs)
    vi_s, vf_s = float(speed[0]), float(speed[-1])
    j = int(np.nanargmin(speed))
    m = mass_kg if mass_kg is not None else np.nan
    net_dvx = vxs - vi[0]
    net_dvz = vzs - vi[1] + G * (ts - t_start)
    spin_known = (
        gyration_m is not None
        and np.isfinite(omega_i_radps)
        and np.isfinite(omega_f_radps)
    )
    k2 = gyration_m**2 if spin_known else 0.0
    e_i_per_kg = 0.5 * vi_s**2 + (0.5 * k2 * omega_i_radps**2 if spin_known else 0.0)
    e_f_per_kg = 0.5 * vf_s**2 + (0.5 * k2 * omega_f_radps**2 if spin_known else 0.0)
    return NetContact(
        index=index,
        before=before.index,
        after=after.index,
        t_start_s=float(t_start),
        t_end_s=float(t_end),
        n_frames=int(round((t_end - t_start) / np.median(np.diff(t))))
        if len(t) > 1
        else 0,
        t_s=ts,
        vx_mps=vxs,
        vz_mps=vzs,
        speed_mps=speed,
        impulse_absorbed_fraction=1.0 - speed / vi_s,
        net_impulse_ns=m * np.hypot(net_dvx, net_dvz),
        vi_mps=vi_s,
        vf_mps=vf_s,
        v_min_mps=float(speed[j]),
        t_min_s=float(ts[j] - t_start),
        energy_i_j=m * e_i_per_kg,
        energy_f_j=m * e_f_per_kg,
        absorbed_j=m * (e_i_per_kg - e_f_per_kg),
        efficiency=float(energy_efficiency(e_i_per_kg, e_f_per_kg)),
        rotation_included=spin_known,
    )
