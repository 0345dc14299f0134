"""Least-squares ballistic parabolas, and the fit of one flight of a track.

Between contacts the centre of mass of a body moves on a parabola (thesis eq. 3.1-3.5,
drag neglected)::

    x(t) = x0 + vx * tau
    z(t) = z0 + vz * tau - g * tau**2 / 2,        tau = t - t_ref

This module holds the one implementation of its linear least-squares fit, used by
every stage of :mod:`fieldkit.tracking.flights`:

* :func:`fit_fixed_g` -- ``g`` given: ``x`` and ``z + g tau^2 / 2`` are straight lines
  in ``tau``;
* :func:`fit_free_g` -- ``g`` fitted too (a third column ``-tau^2 / 2`` for ``z``).

:func:`fit_flight` fits one flight both ways:

1. with ``g`` **free**: the fitted ``g`` and its standard error check the time base
   and the length scale of the video. A wrong capture rate scales the apparent gravity
   by ``(fps_used / fps_true)**2``; a wrong scale scales it linearly.
2. with ``g`` **fixed** at 9.81 m/s^2: the velocities reported for impacts come from
   this fit (one parameter fewer, smaller errors).

Region growing (:mod:`fieldkit.tracking.flights.segment_growth`) solves the free-g
model through incrementally updated normal equations instead; see its docstring.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics.constants import G

#: Standard errors between fitted and true gravity beyond which a flight's gravity
#: is reported as off (a difference the fit's own noise does not explain).
GRAVITY_WARNING_SIGMAS = 3.0

#: Bounds of the lag-1 autocorrelation used to inflate standard errors
#: (:func:`ar1_inflation`): negative estimates are taken as 0 (no deflation), and
#: 0.95 caps the factor at about 6.2.
AR1_RHO_BOUNDS = (0.0, 0.95)


@dataclass(frozen=True)
class Parabola:
    """A ballistic parabola fitted by least squares (:func:`fit_fixed_g`,
    :func:`fit_free_g`).

    Attributes
    ----------
    t_ref_s
        Reference time of the parameters [s].
    x0_m, z0_m, vx_mps, vz_mps
        Position [m] and velocity [m/s] at ``t_ref_s``.
    g_mps2
        Gravity [m/s^2]: the given value (fixed fit) or the fitted one (free fit).
    residual_x_m, residual_z_m
        Residuals of the samples in x and z [m] (for the fixed fit, those of the
        straight line fitted to ``z + g tau^2 / 2``: the same values).
    design
        The design matrix of the ``z`` fit, columns ``1, tau`` (fixed) or
        ``1, tau, -tau^2 / 2`` (free); the ``x`` fit uses its first two columns.
    """

    t_ref_s: float
    x0_m: float
    z0_m: float
    vx_mps: float
    vz_mps: float
    g_mps2: float
    residual_x_m: np.ndarray = field(repr=False)
    residual_z_m: np.ndarray = field(repr=False)
    design: np.ndarray = field(repr=False)

    @property
    def residual_m(self) -> np.ndarray:
        """Distance of each sample from the parabola [m]."""
        return np.hypot(self.residual_x_m, self.residual_z_m)

    @property
    def sse_m2(self) -> float:
        """Sum of the squared residuals of x and z [m^2]."""
        rx, rz = self.residual_x_m, self.residual_z_m
        return float(rx @ rx) + float(rz @ rz)

    def unit_covariance(self) -> np.ndarray:
        """``(A'A)^-1`` of the z design: covariance of ``(z0, vz[, g])`` per unit
        noise variance (multiply by ``sigma^2``); ``[1, 1]`` also serves ``vx``."""
        return np.linalg.inv(self.design.T @ self.design)

    def position(self, t_s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Centre position ``(x, z)`` [m] on the parabola at time(s) ``t_s``."""
        tau = np.asarray(t_s, float) - self.t_ref_s
        x = self.x0_m + self.vx_mps * tau
        z = self.z0_m + self.vz_mps * tau - 0.5 * self.g_mps2 * tau**2
        return x, z


def fit_fixed_g(
    t_s: ArrayLike,
    x_m: ArrayLike,
    z_m: ArrayLike,
    g_mps2: float = G,
    *,
    t_ref_s: float | None = None,
) -> Parabola:
    """Least-squares parabola with gravity fixed at ``g_mps2``.

    Parameters
    ----------
    t_s, x_m, z_m
        Sample times [s] and centre positions [m] (at least 2 samples).
    g_mps2
        Gravity [m/s^2].
    t_ref_s
        Reference time of the fitted position and velocity (default: mean of
        ``t_s``, where they are least correlated).

    Returns
    -------
    Parabola

    Examples
    --------
    >>> t = np.linspace(0.0, 0.2, 20)
    >>> p = fit_fixed_g(t, 1.0 + 3.0 * t, 2.0 + t - 0.5 * 9.81 * t**2, t_ref_s=0.0)
    >>> [round(v, 9) for v in (p.x0_m, p.z0_m, p.vx_mps, p.vz_mps)]
    [1.0, 2.0, 3.0, 1.0]
    """
    t, x, z = (np.asarray(a, float) for a in (t_s, x_m, z_m))
    t_ref = float(t.mean()) if t_ref_s is None else float(t_ref_s)
    tau = t - t_ref
    design = np.column_stack([np.ones_like(tau), tau])
    cx, rx = _lstsq(design, x)
    cz, rz = _lstsq(design, z + 0.5 * g_mps2 * tau**2)
    return _parabola(t_ref, cx, cz, float(g_mps2), rx, rz, design)


def fit_free_g(
    t_s: ArrayLike,
    x_m: ArrayLike,
    z_m: ArrayLike,
    *,
    t_ref_s: float | None = None,
) -> Parabola:
    """Least-squares parabola with gravity fitted (x linear, z quadratic in time).

    Parameters
    ----------
    t_s, x_m, z_m
        Sample times [s] and centre positions [m] (at least 3 samples).
    t_ref_s
        Reference time of the fitted position and velocity (default: mean of
        ``t_s``).

    Returns
    -------
    Parabola
        ``g_mps2`` is the fitted gravity.

    Examples
    --------
    >>> t = np.linspace(0.0, 0.2, 20)
    >>> round(fit_free_g(t, 3.0 * t, 2.0 + t - 0.5 * 9.5 * t**2).g_mps2, 9)
    9.5
    """
    t, x, z = (np.asarray(a, float) for a in (t_s, x_m, z_m))
    t_ref = float(t.mean()) if t_ref_s is None else float(t_ref_s)
    tau = t - t_ref
    one = np.ones_like(tau)
    cx, rx = _lstsq(np.column_stack([one, tau]), x)
    design = np.column_stack([one, tau, -0.5 * tau**2])
    cz, rz = _lstsq(design, z)
    return _parabola(t_ref, cx, cz, float(cz[2]), rx, rz, design)


@dataclass
class FlightFit:
    """A fitted ballistic flight.

    Velocities and positions are those of the fixed-gravity fit (``g_fixed_mps2``);
    ``g_mps2`` and ``g_se_mps2`` come from the free-gravity fit of the same samples.

    Attributes
    ----------
    index
        Flight number along the track (0, 1, ...).
    rows
        Positions (``iloc``) in the track frame of the samples used in the fit.
    t_start_s, t_end_s
        Times of the first and last sample [s].
    t_ref_s
        Reference time of the parameters [s].
    x0_m, z0_m, vx_mps, vz_mps
        Position [m] and velocity [m/s] at ``t_ref_s`` (fixed-g fit).
    vx_se_mps, vz_se_mps
        Standard errors of the velocity components [m/s]; constant along the flight.
    g_mps2, g_se_mps2
        Fitted gravity and its standard error (free-g fit) [m/s^2]. The standard
        error allows for residuals correlated from frame to frame (the
        least-squares value times the AR(1) factor of :func:`ar1_inflation`) and,
        in quadrature, for a slow detection error (``g_systematic_mps2``).
    g_fixed_mps2
        Gravity used for the fixed fit [m/s^2].
    rms_m
        Root-mean-square distance of the samples from the fixed-g parabola [m].
    rms_free_m
        Root-mean-square distance of the samples from the free-g parabola [m].
    residual_m
        Distance of each sample from the fixed-g parabola [m].
    covariance
        Covariance of ``(position, velocity)`` at ``t_ref_s`` of either component,
        ``x`` or ``z`` (the two are independent and share the design) [m^2, m^2/s,
        m^2/s^2]: ``sigma^2 (A'A)^-1`` of the fixed-g fit, with the noise variance
        ``sigma^2`` estimated from its residuals (``2n - 4`` degrees of freedom).
    residual_rho
        Lag-1 autocorrelation of the free-g fit's residuals, clipped to
        :data:`AR1_RHO_BOUNDS` (the one that inflates ``g_se_mps2``).
    g_systematic_mps2
        Part of ``g_se_mps2`` from a slowly varying detection error of size ``b``
        (``systematic_m`` of :func:`fit_flight`): ``8 b / T^2`` [m/s^2]; 0 when none
        is given.
    g_calibration_rel_sd
        Relative standard uncertainty of g from the stated calibration, shared by
        every flight of a clip: ``sqrt(s_L^2 + (2 s_f)^2)`` for a length scale known
        to the relative SD ``s_L`` and a capture rate to ``s_f`` (g scales with the
        length and with the square of the rate; :func:`calibration_rel_sd`). Not in
        ``g_se_mps2`` (which compares flights of one clip); in :attr:`g_check_se_mps2`,
        the standard error of the test against 9.81. 0 when none is stated.
    """

    index: int
    rows: np.ndarray
    t_start_s: float
    t_end_s: float
    t_ref_s: float
    x0_m: float
    z0_m: float
    vx_mps: float
    vz_mps: float
    vx_se_mps: float
    vz_se_mps: float
    g_mps2: float
    g_se_mps2: float
    g_fixed_mps2: float
    rms_m: float
    rms_free_m: float
    residual_m: np.ndarray = field(repr=False)
    covariance: np.ndarray = field(
        default_factory=lambda: np.full((2, 2), np.nan), repr=False
    )
    residual_rho: float = float("nan")
    g_systematic_mps2: float = 0.0
    g_calibration_rel_sd: float = 0.0

    @property
    def n_samples(self) -> int:
        """Number of samples in the fit."""
        return len(self.rows)

    @property
    def duration_s(self) -> float:
        """Time between the first and last sample [s]."""
        return self.t_end_s - self.t_start_s

    @property
    def g_relative_error(self) -> float:
        """``(g_fitted - 9.81) / 9.81``."""
        return (self.g_mps2 - G) / G

    @property
    def g_check_se_mps2(self) -> float:
        """Standard error of the fitted g against 9.81 [m/s^2]: the fit's
        ``g_se_mps2`` and, in quadrature, the stated calibration's
        ``g_calibration_rel_sd * g``."""
        return float(np.hypot(self.g_se_mps2, self.g_calibration_rel_sd * self.g_mps2))

    @property
    def g_sigmas(self) -> float:
        """``(g_fitted - 9.81) / g_check_se``: standard errors from 9.81, after the
        stated scale and rate uncertainty (NaN when the standard error is unknown
        or zero)."""
        se = self.g_check_se_mps2
        if not (np.isfinite(se) and se > 0):
            return float("nan")
        return (self.g_mps2 - G) / se

    def gravity_summary(self) -> str:
        """One line: the flight's time span and fitted g with its standard error.

        Examples
        --------
        ``flight 3 (t = 0.5012-0.6910 s, 229 samples): g = 9.58 +/- 0.04 m/s^2,
        -2.3 %, -5.7 SE from 9.81``
        """
        sigmas = self.g_sigmas
        off = f", {sigmas:+.1f} SE" if np.isfinite(sigmas) else ""
        return (
            f"flight {self.index} (t = {self.t_start_s:.4f}-{self.t_end_s:.4f} s, "
            f"{self.n_samples} samples): g = {self.g_text()} m/s^2, "
            f"{100 * self.g_relative_error:+.2f} %{off} from 9.81"
        )

    def g_text(self) -> str:
        """``g +/- SE`` with the standard error (of the check against 9.81,
        :attr:`g_check_se_mps2`) to two significant digits (at least two decimals):
        ``9.58 +/- 0.04``, ``9.8093 +/- 0.0012``."""
        se = self.g_check_se_mps2
        digits = 2
        if np.isfinite(se) and se > 0:
            digits = int(min(max(2, 1 - np.floor(np.log10(se))), 4))
        return f"{self.g_mps2:.{digits}f} +/- {se:.{digits}f}"

    def position(self, t_s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Centre position ``(x, z)`` [m] on the fitted parabola at time(s) ``t_s``."""
        tau = np.asarray(t_s, float) - self.t_ref_s
        x = self.x0_m + self.vx_mps * tau
        z = self.z0_m + self.vz_mps * tau - 0.5 * self.g_fixed_mps2 * tau**2
        return x, z

    def velocity(self, t_s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Velocity ``(vx, vz)`` [m/s] on the fitted parabola at time(s) ``t_s``."""
        tau = np.asarray(t_s, float) - self.t_ref_s
        vx = np.full_like(tau, self.vx_mps)
        vz = self.vz_mps - self.g_fixed_mps2 * tau
        return vx, vz

    def speed(self, t_s: ArrayLike) -> np.ndarray:
        """Speed [m/s] on the fitted parabola at time(s) ``t_s``."""
        return np.hypot(*self.velocity(t_s))

    def gravity_warning(self) -> str | None:
        """A warning naming the flight when its fitted g is more than
        :data:`GRAVITY_WARNING_SIGMAS` standard errors from 9.81.

        A difference the fit's noise does not explain points at the capture rate,
        the length scale, or a flight disturbed by something else (a contact inside
        it, drag). The message gives the capture rate that would make g right
        (``fps * sqrt(9.81 / g)``) in case the scale is right.
        """
        sigmas = self.g_sigmas
        if not np.isfinite(sigmas) or abs(sigmas) <= GRAVITY_WARNING_SIGMAS:
            return None
        factor = np.sqrt(G / self.g_mps2) if self.g_mps2 > 0 else float("nan")
        return (
            f"flight {self.index} (t = {self.t_start_s:.4f}-{self.t_end_s:.4f} s): "
            f"fitted g = {self.g_text()} m/s^2 is "
            f"{100 * self.g_relative_error:+.1f} % ({sigmas:+.1f} standard errors) "
            f"from 9.81; check the capture rate (`fps`; times {factor:.4g} would fit) "
            "or the length scale"
        )


def calibration_rel_sd(scale_rel_sd: float = 0.0, fps_rel_sd: float = 0.0) -> float:
    """Relative standard uncertainty of a fitted g from the calibration's.

    A length scale too large by the fraction ``e_L`` makes g too large by ``e_L``;
    a capture rate too large by ``e_f`` makes every time too short and g too large
    by ``(1 + e_f)^2 - 1 ~ 2 e_f`` (module docstring). Independent, they add in
    quadrature.

    Parameters
    ----------
    scale_rel_sd
        Relative standard uncertainty of the length scale (metres per pixel) [-].
    fps_rel_sd
        Relative standard uncertainty of the capture rate [-].

    Returns
    -------
    float
        ``sqrt(scale_rel_sd^2 + (2 fps_rel_sd)^2)`` [-].

    Examples
    --------
    >>> round(calibration_rel_sd(0.03, 0.02), 6)
    0.05
    """
    for name, value in (("scale_rel_sd", scale_rel_sd), ("fps_rel_sd", fps_rel_sd)):
        if not (np.isfinite(value) and value >= 0):
            raise ValueError(f"{name} must be >= 0 (got {value!r})")
    return float(np.hypot(scale_rel_sd, 2.0 * fps_rel_sd))


def ar1_inflation(*residuals: np.ndarray) -> tuple[float, float]:
    """Lag-1 autocorrelation of fit residuals and the standard-error factor it implies.

    Least-squares standard errors assume independent residuals. Detection errors of
    a video track are correlated from frame to frame (the same background under the
    rim, compression blocks), which makes those standard errors too small. Modelling
    the errors as a first-order autoregressive process with lag-1 correlation
    ``rho``, the variance of a least-squares estimate from many samples is inflated
    by ``(1 + rho) / (1 - rho)`` (the AR(1) variance inflation factor; Bence 1995,
    *Analysis of short time series: correcting for autocorrelation*, Ecology 76(2),
    628-639; Zieba 2010, Metrol. Meas. Syst. 17(1), 3-16), so the standard error by
    its square root.

    Parameters
    ----------
    *residuals
        Residual series in sample order (e.g. those of ``x`` and ``z``); ``rho`` is
        pooled over them: ``sum(r[i] r[i+1]) / sum(r[i]^2)``.

    Returns
    -------
    rho, factor
        ``rho`` clipped to :data:`AR1_RHO_BOUNDS` and
        ``sqrt((1 + rho) / (1 - rho))`` (1 when there are too few residuals).

    Examples
    --------
    >>> r = np.array([1.0, 1.0, 1.0, -1.0, -1.0, -1.0])
    >>> rho, factor = ar1_inflation(r)
    >>> round(rho, 3), round(factor, 3)
    (0.5, 1.732)
    """
    lagged = sum(float(r[:-1] @ r[1:]) for r in residuals if len(r) > 1)
    power = sum(float(r @ r) for r in residuals if len(r) > 1)
    rho = lagged / power if power > 0 else 0.0
    rho = float(np.clip(rho, *AR1_RHO_BOUNDS))
    return rho, float(np.sqrt((1.0 + rho) / (1.0 - rho)))


def fit_flight(
    t_s: ArrayLike,
    x_m: ArrayLike,
    z_m: ArrayLike,
    *,
    index: int = 0,
    rows: ArrayLike | None = None,
    g_fixed_mps2: float = G,
    systematic_m: float = 0.0,
) -> FlightFit:
    """Fit a ballistic parabola to one flight, with g free and with g fixed.

    The standard error of the fitted g has two parts, added in quadrature:

    * **noise**: the least-squares value from the free fit's residuals, inflated by
      the AR(1) factor of :func:`ar1_inflation` (errors correlated frame to frame);
    * **slow detection error** (``systematic_m`` > 0): an error of that size that
      changes slowly along the flight (compression blocks of an MJPG video, the
      background under the rim) cannot be told from the parabola's curvature: a
      difference ``b`` between the flight's ends and its middle changes g by
      ``8 b / T^2`` (``T`` the flight's duration). Residuals cannot show it.
      On the rendered ``bounce_short`` clip (MJPG, quality 90) the four flights
      need slow errors of 0.014-0.027 px to explain their g; rendered losslessly
      (FFV1) the same flights fit 9.81 within 1.3 noise standard errors.

    Parameters
    ----------
    t_s, x_m, z_m
        Sample times [s] and centre positions [m] of the flight (at least 4 samples).
    index
        Flight number stored in the result.
    rows
        Positions of the samples in the track frame (default ``0..n-1``).
    g_fixed_mps2
        Gravity for the fixed fit whose velocities are reported [m/s^2].
    systematic_m
        Size of a slowly varying detection error [m] (a video track: its noise
        floor, :func:`fieldkit.tracking.flights.pipeline.noise_floor`); 0 for none.

    Returns
    -------
    FlightFit

    Examples
    --------
    >>> t = np.linspace(0.0, 0.2, 50)
    >>> f = fit_flight(t, 1.0 + 3.0 * t, 2.0 + 1.0 * t - 0.5 * 9.81 * t**2)
    >>> round(f.g_mps2, 6), round(float(f.velocity(0.2)[1][()]), 6)
    (9.81, -0.962)
    """
    t = np.asarray(t_s, float)
    x = np.asarray(x_m, float)
    z = np.asarray(z_m, float)
    n = len(t)
    if n < 4:
        raise ValueError("a flight fit needs at least 4 samples")
    free = fit_free_g(t, x, z)
    fixed = fit_fixed_g(t, x, z, g_fixed_mps2, t_ref_s=free.t_ref_s)
    sigma2_free = free.sse_m2 / max(2 * n - 5, 1)
    # residuals correlated frame to frame: the independent-error variance of g is
    # too small by the AR(1) factor estimated from the free fit's own residuals
    rho, inflation = ar1_inflation(free.residual_x_m, free.residual_z_m)
    g_var = sigma2_free * free.unit_covariance()[2, 2] * inflation**2
    duration = float(t.max() - t.min())
    g_systematic = 0.0
    if systematic_m > 0 and duration > 0:
        g_systematic = 8.0 * systematic_m / duration**2
    sigma2 = fixed.sse_m2 / max(2 * n - 4, 1)
    covariance = sigma2 * fixed.unit_covariance()
    v_se = float(np.sqrt(max(covariance[1, 1], 0.0)))

    fit = FlightFit(
        index=index,
        rows=np.arange(n) if rows is None else np.asarray(rows, int),
        t_start_s=float(t.min()),
        t_end_s=float(t.max()),
        t_ref_s=fixed.t_ref_s,
        x0_m=fixed.x0_m,
        z0_m=fixed.z0_m,
        vx_mps=fixed.vx_mps,
        vz_mps=fixed.vz_mps,
        vx_se_mps=v_se,
        vz_se_mps=v_se,
        g_mps2=free.g_mps2,
        g_se_mps2=float(np.sqrt(max(g_var, 0.0) + g_systematic**2)),
        g_fixed_mps2=float(g_fixed_mps2),
        rms_m=0.0,
        rms_free_m=float(np.sqrt(free.sse_m2 / n)),
        residual_m=np.empty(0),
        covariance=covariance,
        residual_rho=rho,
        g_systematic_mps2=g_systematic,
    )
    px, pz = fit.position(t)
    fit.residual_m = np.hypot(x - px, z - pz)
    fit.rms_m = float(np.sqrt(np.mean(fit.residual_m**2)))
    return fit


def _parabola(t_ref, cx, cz, g, rx, rz, design) -> Parabola:
    return Parabola(
        t_ref_s=t_ref,
        x0_m=float(cx[0]),
        z0_m=float(cz[0]),
        vx_mps=float(cx[1]),
        vz_mps=float(cz[1]),
        g_mps2=g,
        residual_x_m=rx,
        residual_z_m=rz,
        design=design,
    )


def _lstsq(design: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares coefficients of ``design @ coef = values`` and the residuals."""
    coef, *_ = np.linalg.lstsq(design, values, rcond=None)
    return coef, values - design @ coef
