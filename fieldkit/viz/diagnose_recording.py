"""A rerun recording of a diagnosis: the error falling, step by step.

Timeline ``step`` (0 = baseline, k = after the k-th accepted effect):

* ``diagnose/cv_rmse`` — the held-out error at each step (a falling line, its
  series named in words, :mod:`fieldkit.diagnose.labels`);
* ``diagnose/candidates/<effect>`` — each candidate's held-out error at the
  steps where it was ranked (series named by the effect in words);
* ``residuals/<feature>/<component>`` — held-out residuals against each feature
  as 2-D points, so scrubbing the timeline shows the structure disappear;
* ``report`` — the Markdown report as a text document.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import rerun as rr

from fieldkit.diagnose import labels
from fieldkit.diagnose.diagnosis import Diagnosis
from fieldkit.outputs import OutputSet, write_file
from fieldkit.viz.rerun_log import open_recording

_COLOURS = ((31, 119, 180), (255, 127, 14), (44, 160, 44))


def _residual_points(rec, features, residual, components) -> None:
    for name, values in features.items():
        if values.dtype == object:
            labels = sorted(set(values) - {""})
            x = np.array([labels.index(v) if v in labels else np.nan for v in values])
        else:
            x = values.astype(float)
        for j, comp in enumerate(components):
            r = residual[:, j]
            ok = np.isfinite(r) & np.isfinite(x)
            rec.log(
                f"residuals/{name}/{comp}",
                rr.Points2D(
                    np.column_stack([x[ok], r[ok]]), radii=0.5,
                    colors=_COLOURS[j % 3],
                ),
            )  # fmt: skip


def write_diagnosis_recording(
    path: str | os.PathLike[str],
    diagnosis: Diagnosis,
    report: str,
    *,
    outputs: OutputSet | None = None,
) -> Path:
    """Write the recording (into ``outputs`` when given, else at once)."""
    arrays = diagnosis.arrays
    features = arrays.get("features", {})
    components = tuple(arrays.get("components", ("vfn", "vft", "omega_f")))
    stages = [arrays.get("baseline")] + list(arrays.get("steps", []))

    def record(tmp: Path) -> None:
        rec = open_recording(tmp, "diagnosis")
        try:
            rec.log("report", rr.TextDocument(report, media_type="text/markdown"),
                    static=True)  # fmt: skip
            errors = [diagnosis.baseline.cv_rmse] + [s.cv_rmse for s in diagnosis.steps]
            ranked = [diagnosis.candidates] + [
                s.candidates for s in diagnosis.steps[1:]
            ]
            # the plots' series in words (the entity paths keep the JSON names)
            metric = rr.SeriesLines(names=labels.metric(diagnosis.metric))
            rec.log("diagnose/cv_rmse", metric, static=True)
            for name in sorted({c.effect for r in ranked for c in r}):
                series = rr.SeriesLines(names=labels.effect(name))
                rec.log(f"diagnose/candidates/{name}", series, static=True)
            for k, error in enumerate(errors):
                rec.set_time("step", sequence=k)
                rec.log("diagnose/cv_rmse", rr.Scalars(error))
                if k < len(ranked):
                    for c in ranked[k]:
                        rec.log(
                            f"diagnose/candidates/{c.effect}", rr.Scalars(c.cv_rmse)
                        )
                if k < len(stages) and stages[k] is not None:
                    _residual_points(rec, features, stages[k], components)
        finally:
            rec.disconnect()

    return write_file(path, record, outputs)
