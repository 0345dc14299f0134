"""Ballistic fit of one flight of a track: free gravity first, then fixed gravity.

Between contacts the centre of mass of a body moves on a parabola (thesis eq. 3.1-3.5,
drag neglected)::

    x(t) = x0 + vx * tau
    z(t) = z0 + vz * tau - g * tau**2 / 2,        tau = t - t_ref

:func:`fit_flight` fits this model twice by linear least squares:

1. with ``g`` **free**: the fitted ``g`` and its standard error check the time base
   and the length scale of the video. A wrong capture rate scales the apparent gravity
   by ``(fps_used / fps_true)**2``; a wrong scale scales it linearly.
2. with ``g`` **fixed** at 9.81 m/s^2: the velocities reported for impacts come from
   this fit (one parameter fewer, smaller errors).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from fieldkit.physics.constants import G

#: Relative difference between fitted and true gravity above which a warning is due.
GRAVITY_WARNING_FRACTION = 0.05


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
    t_ref_s
        Reference time of the parameters [s].
    x0_m, z0_m, vx_mps, vz_mps
        Position [m] and velocity [m/s] at ``t_ref_s`` (fixed-g fit).
    vx_se_mps, vz_se_mps
        Standard errors of the velocity components [m/s]; constant along the flight.
    g_mps2, g_se_mps2
        Fitted gravity and its standard error (free-g fit) [m/s^2].
    g_fixed_mps2
        Gravity used for the fixed fit [m/s^2].
    rms_m
        Root-mean-square distance of the samples from the fixed-g parabola [m].
    rms_free_m
        Root-mean-square distance of the samples from the free-g parabola [m].
    residual_m
        Distance of each sample from the fixed-g parabola [m].
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

    def gravity_warning(self) -> str | None:
        """A warning when the fitted g is > 5 % from 9.81 and the difference is real.

        The difference must exceed both 5 % and three standard errors, so a short,
        noisy flight does not raise a false alarm. The message gives the capture rate
        that would make g right (``fps * sqrt(9.81 / g)``) in case the scale is right.
        """
        rel = self.g_relative_error
        if not np.isfinite(rel) or abs(rel) <= GRAVITY_WARNING_FRACTION:
            return None
        if abs(self.g_mps2 - G) <= 3.0 * self.g_se_mps2:
            return None
        factor = np.sqrt(G / self.g_mps2) if self.g_mps2 > 0 else float("nan")
        return (
            f"flight {self.index} (t = {self.t_start_s:.4f}-{self.t_end_s:.4f} s): "
            f"fitted g = {self.g_mps2:.2f} +/- {self.g_se_mps2:.2f} m/s^2 is "
            f"{100 * rel:+.1f} % "
            f"from 9.81; check the capture rate (`fps`; times {factor:.4g} would fit) "
            "or the length scale"
        )


def fit_flight(
    t_s: ArrayLike,
    x_m: ArrayLike,
    z_m: ArrayLike,
    *,
    index: int = 0,
    rows: ArrayLike | None = None,
    g_fixed_mps2: float = G,
) -> FlightFit:
    """Fit a ballistic parabola to one flight, with g free and with g fixed.

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
    t_ref = float(t.mean())
    tau = t - t_ref
    one = np.ones_like(tau)

    # x = x0 + vx tau (same design in both fits)
    ax = np.column_stack([one, tau])
    cx, ssx = _lstsq(ax, x)
    # free g: z = z0 + vz tau - g tau^2 / 2
    az = np.column_stack([one, tau, -0.5 * tau**2])
    cz, ssz = _lstsq(az, z)
    dof_free = max(2 * n - 5, 1)
    sigma2_free = (ssx + ssz) / dof_free
    cov_z = sigma2_free * np.linalg.inv(az.T @ az)
    g_free, g_se = float(cz[2]), float(np.sqrt(max(cov_z[2, 2], 0.0)))

    # fixed g: z + g tau^2 / 2 = z0 + vz tau
    cz_fixed, ssz_fixed = _lstsq(ax, z + 0.5 * g_fixed_mps2 * tau**2)
    dof_fixed = max(2 * n - 4, 1)
    sigma2 = (ssx + ssz_fixed) / dof_fixed
    cov_lin = sigma2 * np.linalg.inv(ax.T @ ax)
    v_se = float(np.sqrt(max(cov_lin[1, 1], 0.0)))

    fit = FlightFit(
        index=index,
        rows=np.arange(n) if rows is None else np.asarray(rows, int),
        t_start_s=float(t.min()),
        t_end_s=float(t.max()),
        t_ref_s=t_ref,
        x0_m=float(cx[0]),
        z0_m=float(cz_fixed[0]),
        vx_mps=float(cx[1]),
        vz_mps=float(cz_fixed[1]),
        vx_se_mps=v_se,
        vz_se_mps=v_se,
        g_mps2=g_free,
        g_se_mps2=g_se,
        g_fixed_mps2=float(g_fixed_mps2),
        rms_m=0.0,
        rms_free_m=float(np.sqrt((ssx + ssz) / n)),
        residual_m=np.empty(0),
    )
    px, pz = fit.position(t)
    fit.residual_m = np.hypot(x - px, z - pz)
    fit.rms_m = float(np.sqrt(np.mean(fit.residual_m**2)))
    return fit


def _lstsq(design: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, float]:
    coef, *_ = np.linalg.lstsq(design, values, rcond=None)
    resid = values - design @ coef
    return coef, float(resid @ resid)
