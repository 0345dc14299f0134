"""The result of a diagnosis and its JSON form (docs/architecture.md §4).

One :class:`Diagnosis` for impact tables and for video tracks; only the metric
differs (``cv_rmse_mps`` for rebound velocities, ``cv_rmse_m`` for the positions
of a track's flights). The keys the contract fixes (``metric``, ``baseline``,
``candidates``, ``recommended``, ``steps``, ``confounded``, ``after``) come first;
the rest (``rule``, ``groups``, ``skipped``, ``dependence``, ...) say how the
numbers were made and what they mean.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


@dataclass
class ModelScore:
    """A model (its effects on top of the base) scored by its held-out error."""

    effects: list[str]
    cv_rmse: float
    params: dict[str, float]
    params_sd: dict[str, float] = field(default_factory=dict)
    fit_rmse: float = math.nan  # in-sample weighted RMSE of the fit on all data

    def to_json(self, metric: str) -> dict:
        """The contract's ``{"effects", metric, "params"}`` (+ ``params_sd``)."""
        return {
            "effects": list(self.effects),
            metric: _num(self.cv_rmse),
            "params": {k: _num(v) for k, v in self.params.items()},
            "params_sd": {k: _num(v) for k, v in self.params_sd.items()},
            "fit_rmse": _num(self.fit_rmse),
        }


@dataclass
class Candidate:
    """One candidate effect added to the current model, scored on held-out data."""

    effect: str
    cv_rmse: float
    improvement: float
    improvement_se: float
    meaningful: bool
    params: dict[str, float] = field(default_factory=dict)
    params_sd: dict[str, float] = field(default_factory=dict)

    def to_json(self, metric: str) -> dict:
        """The contract's candidate entry (+ ``meaningful``, ``params_sd``)."""
        return {
            "effect": self.effect,
            metric: _num(self.cv_rmse),
            "improvement": _num(self.improvement),
            "improvement_se": _num(self.improvement_se),
            "meaningful": bool(self.meaningful),
            "params": {k: _num(v) for k, v in self.params.items()},
            "params_sd": {k: _num(v) for k, v in self.params_sd.items()},
        }


@dataclass
class Step:
    """One stepwise addition: the ranked candidates and the one accepted."""

    added: str
    cv_rmse_before: float
    cv_rmse: float
    candidates: list[Candidate]

    def to_json(self, metric: str) -> dict:
        """The contract's step entry (+ the error before the step)."""
        return {
            "added": self.added,
            metric: _num(self.cv_rmse),
            f"{metric}_before": _num(self.cv_rmse_before),
            "candidates": [c.to_json(metric) for c in self.candidates],
        }


@dataclass
class Dependence:
    """A test of whether residuals depend on one feature."""

    feature: str
    component: str  # which residual (vfn, vft, omega_f, position, ...)
    statistic: str  # what was computed, e.g. "spearman rho = -0.41"
    p_value: float  # raw: this test alone, before the family-wise correction
    significant: bool  # after the family-wise correction
    #: What ``p_value`` is, in words (which test, how two were combined).
    p_method: str = ""
    #: ``p_value`` adjusted by Holm's method over the tests of one residual set.
    p_holm: float = math.nan
    #: Family-wise level: significant when ``p_holm <= alpha``.
    alpha: float = math.nan

    def to_json(self) -> dict:
        """Plain dict."""
        return {
            "feature": self.feature,
            "component": self.component,
            "statistic": self.statistic,
            "p_value": _num(self.p_value),
            "significant": bool(self.significant),
            "p_method": self.p_method,
            "p_holm": _num(self.p_holm),
            "alpha": _num(self.alpha),
        }


@dataclass
class Diagnosis:
    """Everything a diagnosis found; :meth:`to_json` is the ``--json`` file."""

    metric: str
    baseline: ModelScore
    candidates: list[Candidate]
    recommended: str | None
    steps: list[Step]
    confounded: list[list[str]]
    after: ModelScore
    rule: str
    groups: str
    stopped: str
    skipped: dict[str, str] = field(default_factory=dict)
    advice: list[str] = field(default_factory=list)
    dependence_before: list[Dependence] = field(default_factory=list)
    dependence_after: list[Dependence] = field(default_factory=list)
    unexplained: list[str] = field(default_factory=list)
    worst: list[dict] = field(default_factory=list)
    per_material: dict[str, dict[str, float]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    n_data: int = 0
    n_rows: int = 0
    #: ``n_rows`` in words, as the printed summary and the report say it ("48
    #: impacts (of 50 rows; not impacts: row 1, a release point; ...)"); not in
    #: the JSON (empty: "``n_rows`` rows").
    size: str = ""
    #: The null of a surveyed table (:mod:`fieldkit.diagnose.survey_loop`): size,
    #: quantile, threshold, the null campaigns' gains; None when none was run.
    null: dict | None = None
    #: Per candidate, the share of campaigns with it switched on at its fitted size
    #: in which the diagnosis finds it (None when no null was run).
    power: dict | None = None
    #: Arrays for figures and recordings (not in the JSON): ``features``,
    #: ``baseline``/``after``/``steps`` held-out residuals, ``weight``, ``path_id``,
    #: ``dependence`` (tests of the baseline and of each step), ``after_model``,
    #: ``rankings`` (the candidates ranked in every round, the last, unaccepted
    #: one included).
    arrays: dict = field(default_factory=dict, repr=False)
    #: The verdict under each variant of the table's reduction (assumed launch
    #: angle +- 10 deg, materials grouped; :mod:`fieldkit.diagnose.sensitivity`).
    sensitivity: list = field(default_factory=list)

    @property
    def accepted(self) -> list[str]:
        """Every accepted effect, in the order accepted (``recommended`` is the
        first)."""
        return [s.added for s in self.steps]

    def to_json(self) -> dict:
        """The ``diagnose --json`` document (contract keys first)."""
        m = self.metric
        return {
            "metric": m,
            "baseline": self.baseline.to_json(m),
            "candidates": [c.to_json(m) for c in self.candidates],
            "recommended": self.recommended,
            "steps": [s.to_json(m) for s in self.steps],
            "confounded": [list(p) for p in self.confounded],
            "after": self.after.to_json(m),
            "accepted": self.accepted,
            "rule": self.rule,
            "groups": self.groups,
            "stopped": self.stopped,
            "skipped": dict(self.skipped),
            "advice": list(self.advice),
            "dependence": {
                "before": [d.to_json() for d in self.dependence_before],
                "after": [d.to_json() for d in self.dependence_after],
            },
            "unexplained": list(self.unexplained),
            "worst": list(self.worst),
            "per_material": {
                k: {kk: _num(vv) for kk, vv in v.items()}
                for k, v in self.per_material.items()
            },
            "null": self.null,
            "power": self.power,
            "n_rows": self.n_rows,
            "n_data": self.n_data,
            "notes": list(self.notes),
            "sensitivity": [v.to_json() for v in self.sensitivity],
        }
