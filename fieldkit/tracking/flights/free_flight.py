"""Is a join between two flights a contact, or one free flight the parabola missed?

The segmentation grows flights with a parabola
(:mod:`fieldkit.tracking.flights.segment_growth`): on a flight bent by air drag the
growth stops in mid-air and the next piece starts there, and every such join would
become a "contact". A contact must be an event no free flight explains, so each join
between consecutive flights ``a`` and ``b`` is tested on the samples of ``a`` and
``b`` (the same data for every model) with three models:

* **contact** -- ``a`` and ``b`` each a parabola (8 parameters: position and
  velocity of each), or each a dragged flight with one ``k`` for both (9
  parameters), whichever has the lower BIC: where drag bends the flights, two
  parabolas misfit the long flight before a bounce so badly that one dragged flight
  through the bounce beat them (on a k = 0.35 1/m clip, 18 frames after the first
  impact joined the flight before it, and the k of that flight came out 12 % high);
* **ballistic** -- one parabola through both (4 parameters);
* **air_drag** -- one flight with quadratic drag ``a = g - k |v| v``, the law of
  :mod:`fieldkit.model.effects.air_drag`, integrated by
  :mod:`fieldkit.model.drag_flight`, ``k >= 0`` fitted (5 parameters).

All three use g = 9.81 m/s^2, not the track's apparent g: drag biases the free-g
fits of the pieces (a falling piece looks lighter), and with that g a dragged flight
fits worse than two parabolas (on a cd 3 ball 5 of 5 tracks kept mid-air "contacts").
The data choose by the Bayesian information criterion of Gaussian errors,
``BIC = n ln(SSE / n) + p ln n`` with ``n`` the number of coordinates (two per
sample) and ``SSE / n`` floored at ``sigma^2``, the segmentation's noise (with its
floor for detection errors correlated over frames): a model that improves on another
only below the noise is not chosen, since BIC's white-noise likelihood would count
correlated detection errors as evidence (on the plain ``bounce_short`` clip a
``(sigma / 10)^2`` floor made one flight "need" drag, k = 0.007 1/m). The join
is a contact only when the contact model has the lowest BIC; otherwise the two flights
are one free flight, and when that flight needs drag the track reports it as a model
misfit of the parabola ("flight 3 is not ballistic: try air_drag"), never as an
impact.

Before the joins are tested, every flight is also grown on with its own dragged
flight (:func:`extend_flight`, ``k`` from :func:`drag_fit`) over the samples the
parabola left beside it: a flight whose samples were partly taken by rejected
pieces gets them back. The segmentation keeps the growth only when it adds at least
``EXTENDED_CONTACT_SAMPLES`` samples and the grown flight prefers drag to the
parabola (:func:`prefers_drag`, BIC): a ballistic flight's ends, trimmed at an impact,
stay as they were (on 1 mm noise, growing them let a small impact's samples into
the flight).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fieldkit.model import drag_flight


@dataclass(frozen=True)
class JoinTest:
    """The models of one join, by BIC (lower is better).

    Attributes
    ----------
    bic_contact, bic_ballistic, bic_drag
        BIC of two free flights (the better of two parabolas and two dragged
        flights with one ``k``), one parabola and one dragged flight.
    k_per_m
        The drag factor of the dragged flight [1/m].
    rms_drag_m
        RMS residual per coordinate of the dragged flight [m].
    bic_drift
        BIC of one parabola seen through a slowly drifting detection error
        (:func:`drift_fit`); infinite when no drift is allowed or the drift it
        needs exceeds the limit.
    drift_m
        Size of that drift [m] (0 when not fitted).
    """

    bic_contact: float
    bic_ballistic: float
    bic_drag: float
    k_per_m: float
    rms_drag_m: float
    bic_drift: float = math.inf
    drift_m: float = 0.0

    @property
    def model(self) -> str:
        """``contact``, ``ballistic``, ``air_drag`` or ``drift`` (one parabola with a
        slow detection drift): the model the data choose."""
        best = min(self.bic_contact, self.bic_ballistic, self.bic_drag, self.bic_drift)
        if best == self.bic_contact:
            return "contact"
        if best == self.bic_ballistic:
            return "ballistic"
        return "air_drag" if best == self.bic_drag else "drift"


def _bic(sse: float, n: int, p: int, floor: float) -> float:
    return n * math.log(max(sse / n, floor)) + p * math.log(n)


def _flight_sse(t, x, z, k: float, g: float) -> float:
    return _flight_fit(t, x, z, k, g).sse_m2


def _flight_fit(t, x, z, k: float, g: float) -> drag_flight.DragFit:
    """One flight fitted at drag factor ``k`` (its state ``(x0, z0, vx0, vz0)`` at
    ``t[0]`` in ``params[0]``)."""
    return drag_flight.fit_drag(t, x, z, np.array([0, t.size]), g, k_per_m=k)


def flight_residuals(t, x, z, k: float, g: float, t_eval) -> np.ndarray:
    """Residuals ``(m, 2)`` at the samples ``t_eval`` (inside the span of ``t``) of
    the flight with drag factor ``k`` fitted to ``(t, x, z)``; ``t_eval`` come with
    their positions as ``(t, x, z)`` columns of a ``(m, 3)`` array."""
    state = _flight_fit(t, x, z, k, g).params[0]
    te = np.asarray(t_eval, float)
    order = np.argsort(te[:, 0])
    times = np.concatenate([[t[0]], te[order, 0]])
    xs, zs, _, _ = drag_flight.flight_path(
        times, state[0], state[1], state[2], state[3], k, g, drag_flight.MAX_STEP_S
    )
    out = np.empty((te.shape[0], 2))
    out[order, 0] = te[order, 1] - xs[1:]
    out[order, 1] = te[order, 2] - zs[1:]
    return out


def drag_fit(t, x, z, g: float) -> tuple[float, float]:
    """Quadratic-drag flight fitted to samples: ``(k [1/m], sse [m^2])``.

    :func:`fieldkit.model.drag_flight.fit_drag` on the one flight (``k`` in
    ``[0, MAX_K_PER_M]`` profiled over the initial position and velocity), the fit
    :func:`fieldkit.diagnose.flights.diagnose_flights` makes with one ``k`` over
    many flights.
    """
    fit = drag_flight.fit_drag(t, x, z, np.array([0, t.size]), g)
    return fit.k_per_m, fit.sse_m2


def prefers_drag(t, x, z, *, g_mps2: float, sigma_m: float) -> float:
    """Drag factor ``k`` [1/m] when one flight's samples choose quadratic drag over
    the parabola (BIC), else 0.

    The variance floor is ``(sigma_m / 10)^2``, not the ``sigma_m^2`` of
    :func:`classify_join`: a flight only just long enough to show drag bends from
    its parabola by less than the noise (``bounce_drag_short``'s second flight),
    and this test is only asked about a flight a dragged flight has already grown
    by :data:`~.segmentation.EXTENDED_CONTACT_SAMPLES` samples past where its
    parabola stopped.
    """
    n = 2 * t.size
    floor = (0.1 * sigma_m) ** 2
    sse_one = _flight_sse(t, x, z, 0.0, g_mps2)
    k, sse_drag = drag_fit(t, x, z, g_mps2)
    better = _bic(sse_drag, n, 5, floor) < _bic(sse_one, n, 4, floor)
    return k if better and k > 0 else 0.0


def extend_flight(
    t, x, z, rows: np.ndarray, lo: int, hi: int, k: float, *, g_mps2: float,
    sigma_m: float, chi2_join: float, block: int = 8,
) -> np.ndarray:  # fmt: skip
    """Grow a dragged flight's rows over the positions ``lo..hi`` next to its ends.

    The flight (drag factor ``k`` fixed) is refitted after each block of samples;
    the next samples join while their residual's chi-square (2 d.o.f., noise
    ``sigma_m``) stays within ``chi2_join``; the first that does not ends the growth
    on that side.
    """
    rows = np.asarray(rows)
    for forward in (True, False):
        while True:
            edge = rows[-1] if forward else rows[0]
            cand = (
                np.arange(edge + 1, min(edge + block, hi) + 1)
                if forward
                else np.arange(edge - 1, max(edge - block, lo) - 1, -1)
            )
            if cand.size == 0:
                break
            res = flight_residuals(
                t[rows], x[rows], z[rows], k, g_mps2,
                np.column_stack([t[cand], x[cand], z[cand]]),
            )  # fmt: skip
            ok = (res**2).sum(axis=1) <= chi2_join * sigma_m**2
            run = int(np.argmin(ok)) if not ok.all() else cand.size
            if run == 0:
                break
            rows = np.sort(np.concatenate([rows, cand[:run]]))
            if run < cand.size:
                break
    return rows


#: Parameters of the drift model beyond the parabola: ``tau^2, tau^3, tau^4`` in x
#: and in z (a drift linear in time is the parabola's own velocity).
DRIFT_PARAMETERS = 6


def drift_fit(t, x, z, g: float) -> tuple[float, float]:
    """One fixed-g parabola plus a slow detection drift: ``(sse [m^2], drift [m])``.

    The drift is a polynomial in time added to the centre, ``tau^2 .. tau^4`` in x
    and z (lower orders are the parabola's own position and velocity; in z the
    quadratic term is also a drift of the apparent g, bounded by the drift's size).
    Its size is the largest distance, over the samples, of the fitted drift from
    its own best straight line (what the parabola cannot take up). A contact's kink
    is not smooth: a quartic leaves it in the residuals.

    Examples
    --------
    >>> t = np.linspace(0.0, 0.3, 301)
    >>> drift = 5e-4 * (t / 0.3) ** 3
    >>> sse, size = drift_fit(t, 2.0 * t, 1.0 - 4.905 * t**2 + drift, 9.81)
    >>> sse < 1e-20, round(size * 1e3, 3)
    (True, 0.149)
    """
    t = np.asarray(t, float)
    half = max(0.5 * float(np.ptp(t)), 1e-12)
    s = (t - 0.5 * (t.max() + t.min())) / half
    ones = np.ones_like(s)
    ax = np.column_stack([ones, s, s**2, s**3, s**4])
    az = ax
    zg = np.asarray(z, float) + 0.5 * g * (s * half) ** 2
    cx, *_ = np.linalg.lstsq(ax, np.asarray(x, float), rcond=None)
    cz, *_ = np.linalg.lstsq(az, zg, rcond=None)
    rx = np.asarray(x, float) - ax @ cx
    rz = zg - az @ cz
    sse = float(rx @ rx + rz @ rz)
    line = np.column_stack([ones, s])
    size = 0.0
    for drift in (ax[:, 2:] @ cx[2:], az[:, 2:] @ cz[2:]):
        c, *_ = np.linalg.lstsq(line, drift, rcond=None)
        size = max(size, float(np.abs(drift - line @ c).max()))
    return sse, size


def classify_join(
    a: tuple[np.ndarray, np.ndarray, np.ndarray],
    b: tuple[np.ndarray, np.ndarray, np.ndarray],
    *,
    g_mps2: float,
    sigma_m: float,
    drift_limit_m: float = 0.0,
) -> JoinTest:
    """Contact, one parabola or one dragged flight for the samples ``a`` then ``b``.

    Parameters
    ----------
    a, b
        ``(t_s, x_m, z_m)`` of the flight before and after the join (times
        increasing, all of ``a`` before ``b``).
    g_mps2
        The track's gravity [m/s^2].
    sigma_m
        Position noise per coordinate [m] (the BIC's variance floor is its square).
    drift_limit_m
        Largest slow detection drift [m] allowed to explain the two flights as one
        (:func:`drift_fit`; a fourth model, ``drift``, when > 0): a drifting centre
        must not split a free flight into "contacts".

    Examples
    --------
    >>> t = np.arange(0, 0.4, 0.002)
    >>> x, z = 3.0 * t, 2.0 * t - 4.905 * t**2
    >>> j = classify_join((t[:100], x[:100], z[:100]), (t[100:], x[100:], z[100:]),
    ...                   g_mps2=9.81, sigma_m=1e-4)
    >>> j.model
    'ballistic'
    """
    t = np.concatenate([a[0], b[0]])
    x = np.concatenate([a[1], b[1]])
    z = np.concatenate([a[2], b[2]])
    n = 2 * t.size
    floor = sigma_m**2
    sse_two = _flight_sse(*a, 0.0, g_mps2) + _flight_sse(*b, 0.0, g_mps2)
    # two dragged flights with one k: a bounce between flights that drag bends
    start = np.array([0, a[0].size, t.size])
    sse_two_drag = drag_flight.fit_drag(t, x, z, start, g_mps2).sse_m2
    sse_one = _flight_sse(t, x, z, 0.0, g_mps2)
    k, sse_drag = drag_fit(t, x, z, g_mps2)
    bic_drift, drift = math.inf, 0.0
    if drift_limit_m > 0 and t.size > 4 + DRIFT_PARAMETERS:
        sse_drift, drift = drift_fit(t, x, z, g_mps2)
        if drift <= drift_limit_m:
            bic_drift = _bic(sse_drift, n, 4 + DRIFT_PARAMETERS, floor)
    return JoinTest(
        bic_contact=min(_bic(sse_two, n, 8, floor), _bic(sse_two_drag, n, 9, floor)),
        bic_ballistic=_bic(sse_one, n, 4, floor),
        bic_drag=_bic(sse_drag, n, 5, floor),
        k_per_m=k,
        rms_drag_m=math.sqrt(sse_drag / n),
        bic_drift=bic_drift,
        drift_m=drift,
    )


#: RMS residual per coordinate, in noise standard deviations, within which one
#: flight with a slow drift explains samples (:func:`explained_by_drift`).
DRIFT_RMS_SIGMAS = 2.0


def explained_by_drift(
    t, x, z, *, g_mps2: float, sigma_m: float, drift_limit_m: float
) -> float | None:
    """Size of the slow detection drift [m] through which one free flight explains
    the samples to the noise, or None.

    One fixed-g parabola plus a drift (:func:`drift_fit`) of at most
    ``drift_limit_m`` must leave an RMS residual per coordinate within
    :data:`DRIFT_RMS_SIGMAS` noise standard deviations. Used on joins the physics of
    a contact has already refused (no impulse, energy gained, an apex) and on
    extended "contacts" to ask whether the samples are one flight after all; a
    contact's kink leaves residuals far above the noise.

    Examples
    --------
    >>> t = np.linspace(0.0, 0.3, 301)
    >>> z = 1.0 - 4.905 * t**2 + 5e-4 * np.sin(5 * t / 0.3)
    >>> round(explained_by_drift(t, 2 * t, z, g_mps2=9.81, sigma_m=5e-5,
    ...                          drift_limit_m=2e-3) * 1e3, 2)
    0.59
    >>> bounce = np.where(t < 0.15, z, 2 * z[150] - z)  # a kink at t = 0.15 s
    >>> explained_by_drift(t, 2 * t, bounce, g_mps2=9.81, sigma_m=5e-5,
    ...                    drift_limit_m=2e-3) is None
    True
    """
    t = np.asarray(t, float)
    if t.size <= 4 + DRIFT_PARAMETERS or not sigma_m > 0:
        return None
    sse, size = drift_fit(t, x, z, g_mps2)
    rms = math.sqrt(sse / (2 * t.size))
    if size <= drift_limit_m and rms <= DRIFT_RMS_SIGMAS * sigma_m:
        return size
    return None
