"""The corridor table: one row per station, what a barrier designer reads.

Per station: the rocks behind its numbers, how many crossed the alignment there
(``passing``) and that as a fraction of the rocks released (with its binomial SE),
and at each crossing rock's first crossing the p95 and p99 of the kinetic energy
(translational plus rotational, kJ) and of the bounce height (the centre above the
ground, m), each with its Monte Carlo SE (:mod:`fieldkit.model.statistics`:
order-statistic intervals, no distribution assumed), and the largest energy.
A percentile of fewer than :data:`MIN_FOR_PERCENTILE` crossing rocks is left empty:
it would be one of the largest few values, not a percentile.

``etag027_class_p99`` is the smallest ETAG 027 / EAD 340059-00-0106 barrier energy
class whose maximum energy level (MEL) covers the p99 energy -- a first screening
of the barrier line, before the partial factors of a design code (UNI 11211-4,
ONR 24810) are applied to the design energy; 8 means more than 4,500 kJ.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from fieldkit.model.statistics import fraction_se, percentile_se

#: ETAG 027 energy classes: class -> maximum energy level MEL [kJ] (class 8: > 4500).
ETAG027_MEL_KJ = {0: 100, 1: 250, 2: 500, 3: 1000, 4: 1500, 5: 2000, 6: 3000, 7: 4500}
#: Fewest crossing rocks for a p95/p99 (else the cells are empty).
MIN_FOR_PERCENTILE = 20
#: Columns of the corridor table, in order.
COLUMNS = (
    "station", "chainage_m", "x_m", "y_m", "rocks", "passing", "passing_fraction",
    "passing_fraction_se", "energy_p95_kj", "energy_p95_se_kj", "energy_p99_kj",
    "energy_p99_se_kj", "energy_max_kj", "height_p95_m", "height_p95_se_m",
    "height_p99_m", "height_p99_se_m", "etag027_class_p99",
)  # fmt: skip


def etag027_class(energy_kj: float) -> int | None:
    """The smallest ETAG 027 class whose MEL covers ``energy_kj`` (None for NaN).

    Examples
    --------
    >>> etag027_class(80.0), etag027_class(250.0), etag027_class(6000.0)
    (0, 1, 8)
    """
    if not math.isfinite(energy_kj):
        return None
    for cls, mel in ETAG027_MEL_KJ.items():
        if energy_kj <= mel:
            return cls
    return 8


def station_numbers(
    rocks: int, energy_j: np.ndarray, height_m: np.ndarray
) -> dict[str, float]:
    """The statistics of one station (module docstring) from the first-crossing
    energies [J] and bounce heights [m] of its crossing rocks, of ``rocks``.

    Examples
    --------
    >>> d = station_numbers(100, np.full(25, 2000.0), np.full(25, 1.0))
    >>> d["passing"], d["passing_fraction"], d["energy_p99_kj"], d["etag027_class_p99"]
    (25, 0.25, 2.0, 0)
    """
    energy = np.asarray(energy_j, float)
    height = np.asarray(height_m, float)
    passing = int(energy.size)
    fraction, fraction_err = fraction_se(passing, rocks)
    out: dict[str, float] = {
        "rocks": int(rocks),
        "passing": passing,
        "passing_fraction": fraction,
        "passing_fraction_se": fraction_err,
    }
    enough = passing >= MIN_FOR_PERCENTILE
    for q in (95, 99):
        e, e_se = percentile_se(energy, q) if enough else (math.nan, math.nan)
        h, h_se = percentile_se(height, q) if enough else (math.nan, math.nan)
        out[f"energy_p{q}_kj"] = e / 1e3
        out[f"energy_p{q}_se_kj"] = e_se / 1e3
        out[f"height_p{q}_m"] = h
        out[f"height_p{q}_se_m"] = h_se
    out["energy_max_kj"] = float(energy.max()) / 1e3 if passing else math.nan
    cls = etag027_class(out["energy_p99_kj"])
    out["etag027_class_p99"] = cls if cls is not None else pd.NA
    return out


def corridor_frame(
    stations, rows: list[dict], extra: dict | None = None
) -> pd.DataFrame:
    """The corridor table: ``rows`` (one :func:`station_numbers` dict per station)
    beside the stations' chainage and position; ``extra`` adds columns (name ->
    one value per station) after the table's own."""
    frame = pd.DataFrame(rows)
    frame.insert(0, "y_m", stations.xy_m[:, 1])
    frame.insert(0, "x_m", stations.xy_m[:, 0])
    frame.insert(0, "chainage_m", stations.chainage_m)
    frame.insert(0, "station", np.arange(len(stations)))
    frame = frame[list(COLUMNS)]
    frame["etag027_class_p99"] = frame["etag027_class_p99"].astype("Int64")
    for name, values in (extra or {}).items():
        frame[name] = values
    return frame
