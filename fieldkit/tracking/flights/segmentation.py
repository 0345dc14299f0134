"""Split a track into ballistic flights and the contacts between them, from the data.

No contact times are given: a sample belongs to a flight when it lies on the same
parabola as its neighbours (constant acceleration, ``x`` linear in time), and a contact
is wherever the motion is not free flight (a bounce: a jump in velocity; a net or a
rolling phase: a sustained non-ballistic acceleration).

Method (region growing from the cleanest seeds):

1. **Noise.** A quadratic is fitted to ``x(t)`` and ``z(t)`` in every window of
   ``window`` consecutive samples; the median residual RMS is the position noise
   ``sigma`` (robust because contacts are a minority of the windows). A 4x longer
   window may raise it by up to half (errors correlated over frames), and a floor
   (``noise_floor_m``, 0.05 px for video) applies.
2. **Growth.** Seeds are windows in increasing order of residual; each grows sample by
   sample while the next sample agrees with the current free-g ballistic fit
   (:func:`fieldkit.tracking.flights.segment_growth.grow_segment`).
3. **Validation.** Every flight's free-g fit gives ``g`` and its standard error.
   The track's gravity ``g_common`` is their inverse-variance weighted median. A
   segment is a flight only if it falls (``g > 3 SE``), fits its parabola to the
   noise (RMS <= 2x), its ``g`` is determined (SE < 25 % of ``g_common``) and
   consistent with ``g_common`` (within 4 SE + 5 %). This rejects pieces of a net
   contact or a rolling phase that look ballistic over a few frames, and runs of
   bounces merged into one. Because the test is against the track's own ``g``,
   flights are still found when the capture rate is wrong (their common ``g`` is
   then wrong, which :mod:`flight_fit` warns about).
4. **Extension and trimming.** Accepted flights grow again into samples freed by
   rejected segments; end samples off the fit are trimmed; next to an extended
   contact, samples are dropped while the contact-side velocity still drifts.
5. **No contact without an event.** A flight bent by air drag stops the parabola
   in mid-air; :func:`merge_free_flights` grows it on as a dragged flight and joins
   consecutive flights that one free flight (parabola or quadratic drag, chosen by
   BIC, :mod:`fieldkit.tracking.flights.free_flight`) explains. Such flights are
   reported as misfits ("flight 3 is not ballistic: try air_drag"), not impacts.

Everything between two consecutive flights is a :class:`ContactSpan`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fieldkit.physics.constants import G
from fieldkit.tracking.flights.ballistic_fit import fit_flight
from fieldkit.tracking.flights.end_trimming import (
    stable_end,
    trim_biased_ends,
    trim_ends,
    trim_kinked_ends,
)
from fieldkit.tracking.flights.free_flight import (
    JoinTest,
    classify_join,
    drag_fit,
    extend_flight,
    flight_residuals,
    prefers_drag,
)
from fieldkit.tracking.flights.segment_growth import CHI2_JOIN, grow_segment

#: Largest relative distance of the track's apparent g from 9.81 for the
#: free-flight tests to use 9.81 (beyond it the capture rate or scale is off).
G_TRUSTED_FRACTION = 0.2
#: Samples of the shortest noise window (a quadratic: 2 degrees of freedom left per
#: coordinate) and the median residual RMS of such windows over Gaussian noise of
#: sd 1 (``sqrt(median(chi2_4) / 4)`` = ``sqrt(3.357 / 4)``).
SHORT_WINDOW = 5
SHORT_MEDIAN = 0.916
#: A contact with at least this many samples off both flights is extended (a net, a
#: rolling phase) rather than an impact.
EXTENDED_CONTACT_SAMPLES = 5


@dataclass(frozen=True)
class ContactSpan:
    """The samples between two consecutive flights.

    Attributes
    ----------
    before, after
        Indices of the flights before and after the contact.
    rows
        Track positions of the samples in contact (may be empty for an impact
        shorter than a frame interval).
    t_last_before_s, t_first_after_s
        Time of the last sample of the flight before and the first of the flight after.
    """

    before: int
    after: int
    rows: np.ndarray
    t_last_before_s: float
    t_first_after_s: float

    @property
    def gap_s(self) -> float:
        """Time from the last flight sample before to the first after [s]."""
        return self.t_first_after_s - self.t_last_before_s


@dataclass(frozen=True)
class FlightMisfit:
    """A flight the parabola split in mid-air and one dragged flight explains.

    Attributes
    ----------
    flight
        Index of the flight in the segmentation.
    t_start_s, t_end_s
        Its first and last sample times [s].
    split_at_s
        Where the parabolas had split it [s] (joins that are not contacts).
    k_per_m
        Drag factor ``k`` of ``a = g - k |v| v`` fitted to the flight [1/m].
    """

    flight: int
    t_start_s: float
    t_end_s: float
    split_at_s: tuple[float, ...]
    k_per_m: float

    def message(self, label: str | None = None) -> str:
        """``flight 3 is not ballistic: try air_drag`` with the evidence."""
        where = ", ".join(f"{t:.4f}" for t in self.split_at_s)
        return (
            f"{label or f'flight {self.flight}'} (t = {self.t_start_s:.4f}-"
            f"{self.t_end_s:.4f} s) is not ballistic: try air_drag. A parabola "
            f"stopped fitting it in mid-air at t = {where} s, where one flight with "
            f"quadratic drag (k = {self.k_per_m:.4g} 1/m) explains the samples better "
            "(BIC); no impact is reported there"
        )


@dataclass
class Segmentation:
    """Flights found in a track.

    Attributes
    ----------
    flights
        For each flight (in time order) the track positions of its samples.
    contacts
        The spans between consecutive flights.
    noise_m
        Estimated position noise per coordinate [m].
    g_common_mps2
        The track's apparent gravity (weighted median of the flights) [m/s^2].
    frame_interval_s
        Median time between samples [s].
    misfits
        Flights that only a dragged flight explains (:func:`merge_free_flights`).
    drift_joins
        Joins that one flight seen through a slow detection drift explains (no
        contact there): ``(last_before, first_after, drift_m)``, the track positions
        of the samples on either side and the drift's size [m].
    """

    flights: list[np.ndarray]
    contacts: list[ContactSpan]
    noise_m: float
    g_common_mps2: float
    frame_interval_s: float
    misfits: list[FlightMisfit] = field(default_factory=list)
    drift_joins: list[tuple[int, int, float]] = field(default_factory=list)


def estimate_noise(
    t: np.ndarray, x: np.ndarray, z: np.ndarray, window: int
) -> np.ndarray:
    """Residual RMS of a local quadratic in each window of ``window`` samples [m].

    Returns one value per window start (``len(t) - window + 1`` values).
    """
    n = len(t)
    if n < window:
        return np.empty(0)
    idx = np.arange(window)[None, :] + np.arange(n - window + 1)[:, None]
    tau = t[idx] - t[idx].mean(axis=1, keepdims=True)
    scale = np.abs(tau).max(axis=1, keepdims=True)
    scale[scale == 0] = 1.0
    tau = tau / scale
    design = np.stack([np.ones_like(tau), tau, tau**2], axis=2)  # (m, w, 3)
    pinv = np.linalg.pinv(design)  # (m, 3, w)
    out = np.zeros(len(idx))
    for values in (x[idx], z[idx]):
        coef = np.einsum("mkw,mw->mk", pinv, values)
        resid = values - np.einsum("mwk,mk->mw", design, coef)
        out += (resid**2).sum(axis=1)
    return np.sqrt(out / (2 * (window - 3)))


def find_flights(
    t_s: np.ndarray,
    x_m: np.ndarray,
    z_m: np.ndarray,
    *,
    window: int = 9,
    min_samples: int = 8,
    noise_floor_m: float = 0.0,
    drift_limit_m: float = 0.0,
) -> Segmentation:
    """Find the ballistic flights of a track (see the module docstring for the method).

    Parameters
    ----------
    t_s, x_m, z_m
        Sample times [s] (increasing) and centre positions [m]; NaN positions are
        ignored (never part of a flight).
    window
        Samples per local window for the noise estimate and the seeds.
    min_samples
        Fewest samples a flight may have.
    noise_floor_m
        Smallest position noise assumed [m]. Detection errors are correlated over
        several frames (slowly changing background under the rim, compression), so
        the sample-to-sample scatter understates them; a floor of a few hundredths of
        a pixel keeps good samples in their flights.
    drift_limit_m
        Largest slow detection drift [m] that may explain two flights as one
        (:func:`fieldkit.tracking.flights.free_flight.classify_join`); 0: none.

    Returns
    -------
    Segmentation
        ``flights`` hold positions into the input arrays.

    Examples
    --------
    >>> t = np.arange(200) / 1000.0
    >>> tc = 0.1
    >>> x = 2.0 * t
    >>> z = np.where(t < tc, 0.6 - 4.905 * t**2 - 0.05,
    ...              -0.05 + 0.5 * 0.981 * (t - tc) - 4.905 * (t - tc) ** 2)
    >>> seg = find_flights(t, x, z)
    >>> len(seg.flights), len(seg.contacts)
    (2, 1)
    """
    t_all = np.asarray(t_s, float)
    x_all = np.asarray(x_m, float)
    z_all = np.asarray(z_m, float)
    valid = np.flatnonzero(np.isfinite(t_all) & np.isfinite(x_all) & np.isfinite(z_all))
    t, x, z = t_all[valid], x_all[valid], z_all[valid]
    n = len(t)
    dt = float(np.median(np.diff(t))) if n > 1 else float("nan")
    window = max(5, min(window, n))
    empty = Segmentation([], [], float("nan"), float("nan"), dt)
    if n < max(min_samples, window):
        return empty

    local = estimate_noise(t, x, z, window)
    extent = max(np.ptp(x), np.ptp(z), 1e-9)
    # a 4x longer window also sees errors correlated over a few frames; it may
    # straddle impacts when flights are short in samples, so it can at most raise
    # the estimate by half
    local_sigma = float(np.median(local)) * 1.05
    # flights of few samples (a bounce every ~12 frames at 30 fps): most windows
    # straddle a bounce and their median is the bounces, not the noise; the
    # shortest windows (5 samples) straddle fewer. Their median residual RMS
    # (2 x 2 degrees of freedom) is 0.92 sigma for Gaussian noise.
    # Errors correlated over a few frames (a rolling shutter) still show in the
    # cleanest tenth of the long windows: the estimate does not go below those.
    short = estimate_noise(t, x, z, SHORT_WINDOW)
    if len(short) and np.median(short) / SHORT_MEDIAN < 0.5 * local_sigma:
        clean = float(np.quantile(local, 0.1)) * 1.05
        local_sigma = max(float(np.median(short)) / SHORT_MEDIAN, clean)
    long = estimate_noise(t, x, z, min(4 * window - 3, n))
    long_sigma = min(float(np.median(long)), 1.5 * local_sigma) if len(long) else 0.0
    sigma = max(local_sigma, long_sigma, noise_floor_m, 1e-9 * extent)

    free = np.ones(n, bool)
    segments: list[tuple[int, int, list[int]]] = []
    # then shorter seeds where no window of `window` samples fits: a flight of a
    # few frames next to a mis-detected one (30 fps, a blurred bounce)
    seeds = [(local, window)]
    if window > min_samples - 1 >= 5:
        seeds.append((estimate_noise(t, x, z, min_samples - 1), min_samples - 1))
    for scores, width in seeds:
        for start in np.argsort(scores, kind="stable"):
            if scores[start] > 3.0 * sigma:
                break
            stop = start + width - 1
            if not free[start : stop + 1].all():
                continue
            lo, hi, outl = grow_segment(t, x, z, start, stop, free, sigma)
            free[lo : hi + 1] = False
            segments.append((lo, hi, outl))

    fits = []
    for lo, hi, outl in segments:
        rows = np.setdiff1d(np.arange(lo, hi + 1), outl)
        fits.append(
            fit_flight(t[rows], x[rows], z[rows]) if len(rows) >= min_samples else None
        )
    g_common = _common_gravity(
        [f for f in fits if f is not None and f.g_mps2 > 3.0 * f.g_se_mps2]
    )

    accepted: list[tuple[int, int, list[int]]] = []
    free = np.ones(n, bool)
    for (lo, hi, outl), fit in zip(segments, fits, strict=True):
        if fit is None or not _is_flight(fit, g_common, sigma):
            continue
        accepted.append((lo, hi, outl))
        free[lo : hi + 1] = False
    # let accepted flights take back samples held by rejected segments
    extended = []
    for lo, hi, outl in sorted(accepted):
        free[lo : hi + 1] = True
        lo2, hi2, outl2 = grow_segment(t, x, z, lo, hi, free, sigma, exclude=outl)
        free[lo2 : hi2 + 1] = False
        extended.append((lo2, hi2, sorted(set(outl) | set(outl2))))
    extended.sort()

    flights: list[np.ndarray] = []
    for lo, hi, outl in extended:
        rows = np.setdiff1d(np.arange(lo, hi + 1), outl)
        rows = trim_ends(t, x, z, rows, sigma)
        if np.isfinite(g_common):
            rows = trim_kinked_ends(t, x, z, rows, sigma, g_common)
            rows = trim_biased_ends(t, x, z, rows, sigma, g_common)
        if len(rows) >= min_samples:
            flights.append(rows)

    g_fix = g_common if np.isfinite(g_common) else 9.81
    # the free-flight tests use the true g: the pieces' own g is biased by drag
    # (a few %); far from it the capture rate or scale is wrong, and the track's g
    # stands in (the gravity check warns)
    g_free = G if abs(g_fix / G - 1.0) < G_TRUSTED_FRACTION else g_fix
    drift_joins: list[tuple[int, int, float]] = []
    flights, misfits = merge_free_flights(
        t, x, z, flights, g_free, sigma, drift_limit_m=drift_limit_m,
        drift_joins=drift_joins,
    )  # fmt: skip
    for k in range(len(flights) - 1):
        if flights[k + 1][0] - flights[k][-1] - 1 >= EXTENDED_CONTACT_SAMPLES:
            flights[k] = stable_end(t, x, z, flights[k], sigma, g_fix, at_start=False)
            flights[k + 1] = stable_end(t, x, z, flights[k + 1], sigma, g_fix, True)
    contacts = []
    for k in range(len(flights) - 1):
        a, b = flights[k], flights[k + 1]
        inside = np.arange(a[-1] + 1, b[0])
        contacts.append(
            ContactSpan(
                before=k,
                after=k + 1,
                rows=valid[inside],
                t_last_before_s=float(t[a[-1]]),
                t_first_after_s=float(t[b[0]]),
            )
        )
    return Segmentation(
        flights=[valid[r] for r in flights],
        contacts=contacts,
        noise_m=sigma,
        g_common_mps2=g_common,
        frame_interval_s=dt,
        misfits=misfits,
        drift_joins=[(int(valid[a]), int(valid[b]), d) for a, b, d in drift_joins],
    )


def merge_free_flights(
    t: np.ndarray,
    x: np.ndarray,
    z: np.ndarray,
    flights: list[np.ndarray],
    g_mps2: float,
    sigma: float,
    *,
    drift_limit_m: float = 0.0,
    drift_joins: list[tuple[int, int, float]] | None = None,
) -> tuple[list[np.ndarray], list[FlightMisfit]]:
    """Join consecutive flights that one free flight explains (no contact between).

    First each flight is grown on as a dragged flight
    (:func:`fieldkit.tracking.flights.free_flight.extend_flight`) over the samples
    beside it, kept when that adds at least :data:`EXTENDED_CONTACT_SAMPLES` and
    the grown flight prefers drag (BIC). Each
    join is tested by :func:`fieldkit.tracking.flights.free_flight.classify_join`
    (two parabolas against one parabola or one dragged flight, by BIC). When a free
    flight wins, the two become one flight, with the samples between them that lie
    on it (chi-square of :data:`~.segment_growth.CHI2_JOIN`), and the test is
    repeated with the next flight. A flight grown or joined as a dragged flight is
    returned as a :class:`FlightMisfit` (indices into the returned flights).
    A join one flight explains only through a slow detection drift of at most
    ``drift_limit_m`` is joined too and appended to ``drift_joins`` as
    ``(last sample before, first after, drift [m])``.
    """
    flights = [np.asarray(r) for r in flights]
    joined: list[list[tuple[float, JoinTest | float]]] = [[] for _ in flights]
    for i, rows in enumerate(flights):
        # where drag bent a flight, the parabola stopped growing in mid-air: the
        # dragged flight grows on; it is kept when it explains at least
        # EXTENDED_CONTACT_SAMPLES more samples (a parabola's own end, trimmed
        # at an impact, is left alone)
        k = drag_fit(t[rows], x[rows], z[rows], g_mps2)[0]
        if k <= 0:
            continue
        lo = flights[i - 1][-1] + 1 if i > 0 else 0
        hi = flights[i + 1][0] - 1 if i + 1 < len(flights) else len(t) - 1
        grown = extend_flight(
            t, x, z, rows, lo, hi, k, g_mps2=g_mps2, sigma_m=sigma,
            chi2_join=CHI2_JOIN,
        )  # fmt: skip
        if grown.size - rows.size < EXTENDED_CONTACT_SAMPLES:
            continue
        k = prefers_drag(t[grown], x[grown], z[grown], g_mps2=g_mps2, sigma_m=sigma)
        if k <= 0:
            continue
        ends = [rows[0]] if grown[0] < rows[0] else []
        ends += [rows[-1]] if grown[-1] > rows[-1] else []
        joined[i] = [(float(t[e]), k) for e in ends]
        flights[i] = grown
    i = 0
    while i < len(flights) - 1:
        a, b = flights[i], flights[i + 1]
        test = classify_join(
            (t[a], x[a], z[a]), (t[b], x[b], z[b]), g_mps2=g_mps2, sigma_m=sigma,
            drift_limit_m=drift_limit_m,
        )  # fmt: skip
        if test.model == "contact":
            i += 1
            continue
        if test.model == "drift" and drift_joins is not None:
            drift_joins.append((int(a[-1]), int(b[0]), test.drift_m))
        rows = np.concatenate([a, b])
        gap = np.arange(a[-1] + 1, b[0])
        if gap.size:
            k = test.k_per_m if test.model == "air_drag" else 0.0
            res = flight_residuals(
                t[rows], x[rows], z[rows], k, g_mps2,
                np.column_stack([t[gap], x[gap], z[gap]]),
            )  # fmt: skip
            fits = (res**2).sum(axis=1) <= CHI2_JOIN * sigma**2
            rows = np.concatenate([rows, gap[fits]])
        flights[i] = np.sort(rows)
        t_join = 0.5 * (float(t[a[-1]]) + float(t[b[0]]))
        joined[i] = joined[i] + [(t_join, test)] + joined[i + 1]
        del flights[i + 1], joined[i + 1]
    misfits = []
    for i, joins in enumerate(joined):
        r = flights[i]
        # a float is the k of a flight the dragged flight grew past its parabola
        dragged = any(isinstance(j, float) or j.model == "air_drag" for _, j in joins)
        k = drag_fit(t[r], x[r], z[r], g_mps2)[0] if dragged else 0.0
        if k > 0:
            misfits.append(
                FlightMisfit(
                    flight=i,
                    t_start_s=float(t[r[0]]),
                    t_end_s=float(t[r[-1]]),
                    split_at_s=tuple(sorted(tj for tj, _ in joins)),
                    k_per_m=k,
                )
            )
    return flights, misfits


def _common_gravity(fits) -> float:
    good = [f for f in fits if np.isfinite(f.g_se_mps2) and f.g_se_mps2 > 0]
    if not good:
        return float("nan")
    g = np.array([f.g_mps2 for f in good])
    w = np.array([1.0 / f.g_se_mps2**2 for f in good])
    order = np.argsort(g)
    cum = np.cumsum(w[order])
    return float(g[order][np.searchsorted(cum, 0.5 * cum[-1])])


def _is_flight(fit, g_common: float, sigma: float) -> bool:
    # a flight falls (g > 0) and fits its parabola to the noise: a run of bounces
    # merged into one "flight" fails both or the latter
    if fit.g_mps2 <= 3.0 * fit.g_se_mps2 or fit.rms_free_m > 2.0 * np.sqrt(2.0) * sigma:
        return False
    if not np.isfinite(g_common):
        return True
    scale = abs(g_common)
    if not fit.g_se_mps2 < 0.25 * scale:
        return False
    return abs(fit.g_mps2 - g_common) <= 4.0 * fit.g_se_mps2 + 0.05 * scale
