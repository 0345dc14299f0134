"""Held-out validation of a path-level calibration (issue 11, item 4).

On the held-out runs, the predicted runout ensembles of three models are scored
against what was observed (:func:`fieldkit.fit.holdout.holdout_scores`): the
calibrated model, the uncalibrated starting model, and the *climatology* — the
empirical distribution of the calibration runs' observed runouts, the forecast a
calibrated model must at least match. The same common random numbers serve the
calibrated and the starting model, so their difference is the parameters' alone.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from fieldkit.fit.holdout import climatology, holdout_scores
from fieldkit.fit.path_fit import PathObjective
from fieldkit.fit.path_runs import PathRun

#: The three forecasts compared on the held-out runs, in report order.
FORECASTS = ("calibrated", "uncalibrated", "climatology")
#: A simulated runout within this distance of the section's end [m]: the rock left
#: the section, and its runout is censored (at least that far).
END_TOLERANCE_M = 0.5
#: A simulated runout shorter than this [m]: the rock stopped at its release.
RELEASE_STOP_M = 5.0
#: Share of a run's rocks above which censoring or stops at the release are listed
#: (and marked in the figure): the tail a 90 % central interval leaves out on each
#: side, so the interval's end is then the section's end or the release.
LISTED_SHARE = 0.05


def left_share(runouts: np.ndarray, section_end_m: float) -> float:
    """Share of ``runouts`` [m] at the section's end (the rocks left the section)."""
    return float(np.mean(np.asarray(runouts, float) >= section_end_m - END_TOLERANCE_M))


def stopped_share(runouts: np.ndarray) -> float:
    """Share of ``runouts`` [m] shorter than :data:`RELEASE_STOP_M`."""
    return float(np.mean(np.asarray(runouts, float) < RELEASE_STOP_M))


def censoring(validation: dict) -> dict:
    """Per simulated forecast, the held-out runs where more than
    :data:`LISTED_SHARE` of the rocks left the section (``left_section``: runouts
    censored at the section's end) or stopped within :data:`RELEASE_STOP_M` of the
    release (``stopped_at_release``), each as ``{path_id: share}``.
    """
    out = {}
    ends = validation["section_end_m"]
    for name in ("calibrated", "uncalibrated"):
        left, stopped = {}, {}
        for pid, e, end in zip(validation["path_ids"], validation["ensembles"][name],
                               ends, strict=True):  # fmt: skip
            e = np.asarray(e, float)
            share = left_share(e, end)
            if share > LISTED_SHARE:
                left[pid] = share
            share = stopped_share(e)
            if share > LISTED_SHARE:
                stopped[pid] = share
        out[name] = {"left_section": left, "stopped_at_release": stopped}
    return out


def validate(
    holdout: Sequence[PathRun],
    calibration: Sequence[PathRun],
    fitted: dict[str, float],
    *,
    rocks: int,
    seed: int,
) -> dict:
    """Scores of the three forecasts on ``holdout`` (``fitted``: calibrated values).

    Returns ``{"forecasts": {name: scores}, "ensembles": {name: [arrays]},
    "observed": array, "path_ids": [...], "section_end_m": [...]}`` (the last
    chainage of each run's section from its release: a rock simulated that far left
    the section, its runout censored); each ``scores`` as
    :func:`holdout_scores` with the climatology as reference (``crps_skill``), plus
    ``mean_error_m`` = mean predicted - mean observed runout.
    """
    names = list(fitted)
    objective = PathObjective(holdout, names, rocks, seed)
    observed = objective.observed
    cal_observed = np.array([r.observed_runout_m for r in calibration], float)
    ensembles = {
        "calibrated": objective.ensembles(fitted),
        "uncalibrated": objective.ensembles({}),
        "climatology": climatology(cal_observed, len(observed)),
    }
    reference = ensembles["climatology"]
    forecasts = {}
    for name in FORECASTS:
        scores = holdout_scores(ensembles[name], observed, reference=reference)
        scores["mean_error_m"] = scores["mean_predicted"] - scores["mean_observed"]
        forecasts[name] = scores
    return {
        "forecasts": forecasts,
        "ensembles": ensembles,
        "observed": observed,
        "path_ids": [r.path_id for r in objective.runs],
        "section_end_m": [
            float(r.model.profile.x_m[-1] - r.model.seeder.x_m) for r in objective.runs
        ],
    }
