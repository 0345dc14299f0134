"""Predicted runout intervals against observed runouts, one row per held-out run."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fieldkit.fit.path_validation import (
    LISTED_SHARE,
    RELEASE_STOP_M,
    left_share,
    stopped_share,
)
from fieldkit.outputs import OutputSet
from fieldkit.viz.figure_files import save_png

_STYLE = {"calibrated": ("C0", 0.12), "uncalibrated": ("C7", -0.12)}
_NAMES = {"calibrated": "calibrated", "uncalibrated": "starting (uncalibrated)"}


def holdout_figure(validation: dict) -> Figure:
    """50 % (thick) and 90 % (thin) central intervals and median of the calibrated
    and uncalibrated forecasts per held-out run; observed runout as a black dot;
    the climatology's 5-95 % band shaded. Where more than
    :data:`~fieldkit.fit.path_validation.LISTED_SHARE` of a run's rocks left the
    section (the bar ends at the section's end: those runouts are only lower
    bounds), an arrow at the bar's end with that share; where more than that
    stopped within :data:`~fieldkit.fit.path_validation.RELEASE_STOP_M` of the
    release (the bar starts there), a cross at its start with their share."""
    ids = validation["path_ids"]
    observed = validation["observed"]
    ends = validation.get("section_end_m", [np.inf] * len(ids))
    n = len(ids)
    fig = Figure(figsize=(8.0, 0.35 * n + 3.6), layout="constrained")
    ax = fig.add_subplot()
    clim = validation["ensembles"]["climatology"][0]
    lo, hi = np.percentile(clim, [5, 95])
    ax.axvspan(lo, hi, color="0.9", label="5-95 % of the calibration runs'\nobserved "
               "runouts (climatology)")  # fmt: skip
    y = np.arange(n)
    censored = stopped = False
    for name, (colour, dy) in _STYLE.items():
        for i, e in enumerate(validation["ensembles"][name]):
            q = np.percentile(e, [5, 25, 50, 75, 95])
            ax.plot([q[0], q[4]], [y[i] + dy] * 2, c=colour, lw=1)
            ax.plot([q[1], q[3]], [y[i] + dy] * 2, c=colour, lw=4,
                    label=f"{_NAMES[name]} model" if i == 0 else None)  # fmt: skip
            ax.plot(q[2], y[i] + dy, "|", c="k", ms=8)
            share = left_share(e, ends[i])
            if share > LISTED_SHARE:
                censored = True
                ax.plot(q[4], y[i] + dy, ">", c=colour, ms=7, mec="k", mew=0.6)
                ax.annotate(f"{share:.0%}", (q[4], y[i] + dy), xytext=(-6, -9),
                            textcoords="offset points", fontsize=7,
                            ha="right")  # fmt: skip
            share = stopped_share(e)
            if share > LISTED_SHARE:
                stopped = True
                ax.plot(q[0], y[i] + dy, "X", c=colour, ms=7, mec="k", mew=0.6)
                ax.annotate(f"{share:.0%}", (q[0], y[i] + dy), xytext=(6, -9),
                            textcoords="offset points", fontsize=7)  # fmt: skip
    ax.plot(observed, y, "o", c="k", ms=5, label="observed runout")
    # what the thick and thin bars and the ticks are (one legend entry each)
    ax.plot([], [], c="0.3", lw=4, label="50 % of simulated runouts (thick)")
    ax.plot([], [], c="0.3", lw=1, label="90 % of simulated runouts (thin)")
    ax.plot([], [], "|", c="k", ms=8, label="median simulated runout")
    if censored:
        ax.plot([], [], ">", c="0.6", mec="k", mew=0.6, ms=7,
                label="bar reaches the section's end: share of rocks\nthat left "
                "the section (runout at least this)")  # fmt: skip
    if stopped:
        ax.plot([], [], "X", c="0.6", mec="k", mew=0.6, ms=7,
                label=f"bar starts at the release: share of rocks\nthat "
                f"stopped within {RELEASE_STOP_M:g} m of it")  # fmt: skip
    ax.set_yticks(y, ids)
    ax.invert_yaxis()
    ax.set_xlabel("runout along the section from the release (m)")
    ax.set_ylabel("held-out run")
    s = validation["forecasts"]
    ax.set_title(
        "held-out runs: mean CRPS "
        + ", ".join(f"{k} {s[k]['mean_crps']:.1f} m" for k in s)
    )
    ax.grid(True, axis="x", alpha=0.3)
    fig.legend(loc="outside lower center", ncol=2, fontsize=8)
    return fig


def write_holdout_figure(
    path: str | os.PathLike[str], validation: dict, *, outputs: OutputSet | None = None
) -> Path:
    """Write :func:`holdout_figure` as PNG (through ``outputs`` when given)."""
    return save_png(holdout_figure(validation), path, outputs=outputs)
