"""What a held-out test of release/deposit runs can show (issue 21, item 3).

A 3-D model is scored in plan against the **climatology** -- the calibration runs'
release-to-deposit vectors added to each held-out release
(:func:`fieldkit.fit.plan_scores.plan_climatology`). The climatology's fair score
is an *unbiased* estimate of the score of the distribution its vectors are drawn
from (:mod:`fieldkit.fit.plan_scores`, fair scores). So where the deposit vector of
a run does not depend on anything a model knows about the run (its release point,
its block), the climatology scores, on average, exactly as well as the true
distribution: **no model can beat it in expectation**, however good. A model beats
it only by the *per-run information* the runs carry, and a test of N held-out runs
can show that only when the information is large against the run-to-run scatter of
the score difference.

Two ways to measure how much there is, before reading a verdict:

* :func:`virtual_campaigns` -- the model as the truth. Each virtual campaign draws
  one "observed" deposit per run from the model itself (from the run's release with
  its block, censored as the model is), builds the climatology from its calibration
  runs and scores the model -- a perfect forecast of that world -- against it on its
  held-out runs. The share of campaigns in which the perfect forecast beats the
  climatology by >= 2 paired SEs is the test's **power** in a world where the model
  is right: what the model itself says its per-run skill is worth on this split.
* :func:`group_climatology_skill` -- the data's own ceiling for a per-run
  covariate (the block): the climatology of the held-out run's own group against
  the pooled one, by repeated k-fold over all runs. Both are fair scores of
  empirical distributions, so the mean difference estimates, without bias, what
  knowing a run's group is worth -- the most any forecast using the group can gain.

Each gives a :class:`SkillTest` per score: the mean per-run advantage of the better
informed forecast, the SD of the per-run differences and from them the held-out
runs a test would need (:meth:`SkillTest.runs_needed`).

Random streams: virtual observations use ``default_rng([seed, VIRTUAL_STREAM, r])``,
a tag no fit or held-out scoring uses; the perfect forecast's ensembles are the
held-out ones (``[seed, HOLDOUT_STREAM, r]``), independent of the observations.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import norm

from fieldkit.errors import ArgumentError
from fieldkit.fit.plan_fit import HOLDOUT_STREAM, PlanRun, plan_ensembles
from fieldkit.fit.plan_scores import (
    _pair_distance_sum,
    fair_crps,
    release_deposit_distance_m,
    repeated_kfold,
)
from fieldkit.fit.tracked_extent import Extent, censored_climatology
from fieldkit.model.model3d import Model3D

#: Stream tag of the virtual observations (``default_rng([seed, VIRTUAL_STREAM,
#: r])``): no fit (``[seed, r]``) or held-out scoring (``[seed, HOLDOUT_STREAM,
#: r]``) uses it.
VIRTUAL_STREAM = 130_363
#: The verdict's threshold: a forecast beats another by >= this many paired SEs.
N_SE = 2.0
#: Power at which :meth:`SkillTest.runs_needed` is quoted.
POWER = 0.8


@dataclass(frozen=True)
class SkillTest:
    """Repeated tests of an informed forecast A against the climatology B on one
    score (lower is better; differences A - B).

    Attributes
    ----------
    score
        The score's name.
    differences, ses
        (tests,) mean over runs of A - B and its paired SE over runs, per test
        (a virtual campaign; a repeat of the k-fold).
    per_run_mean, per_run_sd
        Mean and SD (ddof 1) of the per-run differences pooled over tests: the
        advantage per run and the scatter a test's SE is made of.
    mean_se
        The SE of ``per_run_mean``: over independent tests (virtual campaigns),
        the SD of their differences / sqrt(tests); over repeats of a k-fold of the
        same runs, the SD over runs of the repeat-averaged differences /
        sqrt(runs).
    n_runs
        Held-out runs per test.
    """

    score: str
    differences: np.ndarray
    ses: np.ndarray
    per_run_mean: float
    per_run_sd: float
    mean_se: float
    n_runs: int

    def pass_rate(self, n_se: float = N_SE) -> float:
        """Share of tests in which A beats B by >= ``n_se`` paired SEs."""
        ok = np.isfinite(self.ses)
        return float(np.mean(self.passes(n_se)[ok])) if ok.any() else math.nan

    def passes(self, n_se: float = N_SE) -> np.ndarray:
        """Per test, whether A beats B by >= ``n_se`` paired SEs."""
        return np.isfinite(self.ses) & (self.differences <= -n_se * self.ses)

    def runs_needed(self, n_se: float = N_SE, power: float = POWER) -> float:
        """Held-out runs for A to beat B by ``n_se`` paired SEs in a share ``power``
        of tests (:func:`runs_needed`)."""
        return runs_needed(self.per_run_mean, self.per_run_sd, n_se, power)

    def power_at(self, n_runs: int, n_se: float = N_SE) -> float:
        """Probability that A beats B by >= ``n_se`` paired SEs on ``n_runs``
        held-out runs (normal approximation from the per-run mean and SD)."""
        if not (math.isfinite(self.per_run_mean) and self.per_run_sd > 0):
            return math.nan
        z = -self.per_run_mean * math.sqrt(n_runs) / self.per_run_sd
        return float(norm.cdf(z - n_se))

    def to_dict(self) -> dict:
        return {
            "score": self.score,
            "tests": int(self.differences.size),
            "n_runs": self.n_runs,
            "mean_difference_m": float(np.mean(self.differences)),
            "sd_of_test_difference_m": float(np.std(self.differences, ddof=1))
            if self.differences.size > 1
            else math.nan,
            "mean_se_m": float(np.nanmean(self.ses)),
            "per_run_mean_m": self.per_run_mean,
            "per_run_sd_m": self.per_run_sd,
            "per_run_mean_se_m": self.mean_se,
            "pass_rate_2se": self.pass_rate(),
            "runs_needed_80pct": self.runs_needed(),
        }


def runs_needed(
    per_run_mean: float, per_run_sd: float, n_se: float = N_SE, power: float = POWER
) -> float:
    """Held-out runs for a forecast with a per-run advantage ``per_run_mean`` (< 0:
    better) and per-run SD ``per_run_sd`` of the difference to beat the other by
    ``n_se`` paired SEs in a share ``power`` of tests (normal approximation:
    ``-mean sqrt(n) / sd >= n_se + z_power``); ``inf`` without an advantage.

    Examples
    --------
    >>> round(runs_needed(-1.0, 4.0), 1)  # (2 + 0.8416)^2 * 16
    129.2
    >>> runs_needed(0.5, 4.0)
    inf
    """
    if not (math.isfinite(per_run_mean) and math.isfinite(per_run_sd)):
        return math.nan
    if per_run_mean >= 0.0:
        return math.inf
    return float(((n_se + norm.ppf(power)) * per_run_sd / -per_run_mean) ** 2)


def _skill(score: str, diffs: np.ndarray, *, same_runs: bool) -> SkillTest:
    """:class:`SkillTest` from per-test, per-run differences (tests, runs);
    ``same_runs``: the tests are repeats over the same runs (a k-fold), not
    independent campaigns."""
    d = np.asarray(diffs, float)
    tests, n = d.shape
    se = d.std(axis=1, ddof=1) / math.sqrt(n) if n > 1 else np.full(tests, np.nan)
    flat = d.ravel()
    if same_runs:
        mean_se = float(d.mean(axis=0).std(ddof=1) / math.sqrt(n))
    else:
        mean_se = float(d.mean(axis=1).std(ddof=1) / math.sqrt(tests))
    return SkillTest(
        score=score,
        differences=d.mean(axis=1),
        ses=se,
        per_run_mean=float(flat.mean()),
        per_run_sd=float(flat.std(ddof=1)) if flat.size > 1 else math.nan,
        mean_se=mean_se,
        n_runs=n,
    )


@dataclass(frozen=True)
class Attainable:
    """The outcome of repeated tests of an informed forecast against the
    climatology on both scores (:func:`virtual_campaigns`,
    :func:`group_climatology_skill`)."""

    what: str
    energy: SkillTest
    distance: SkillTest
    split_runs: int
    notes: list[str] = field(default_factory=list)

    @property
    def tests(self) -> int:
        """Tests (virtual campaigns, or repeats of the k-fold)."""
        return int(self.energy.differences.size)

    @property
    def both_pass_rate(self) -> float:
        """Share of tests passing on both scores at once."""
        return float(np.mean(self.energy.passes() & self.distance.passes()))

    @property
    def measured(self) -> bool:
        """Whether the tests are of the split's size (virtual campaigns): then the
        pass rates are measured, else (k-fold over all runs) the power on the
        split is the normal approximation :meth:`SkillTest.power_at`."""
        return self.energy.n_runs == self.split_runs

    def power(self, test: SkillTest) -> float:
        """Share of tests of :attr:`split_runs` held-out runs that pass."""
        return test.pass_rate() if self.measured else test.power_at(self.split_runs)

    def lines(self) -> list[str]:
        out = [
            f"{self.what} ({self.tests} "
            + ("virtual campaigns" if self.measured else "repeats")
            + f" of {self.energy.n_runs} held-out runs):"
        ]
        how = "measured" if self.measured else "normal approximation"
        for t, name in ((self.energy, "energy score"),
                        (self.distance, "distance CRPS")):  # fmt: skip
            need = t.runs_needed()
            out.append(
                f"  {name}: {t.per_run_mean:+.2f} +- {t.mean_se:.2f} m per run (SD "
                f"{t.per_run_sd:.2f} m); beats the climatology by >= 2 paired SEs on "
                f"{self.split_runs} held-out runs with probability "
                f"{100 * self.power(t):.0f} % ({how}); held-out runs for 80 %: "
                + ("none suffice (no advantage)" if math.isinf(need) else f"{need:.0f}")
            )
        if self.measured:
            out.append(
                f"  both scores at once: {100 * self.both_pass_rate:.1f} % of campaigns"
            )
        return out + [f"  note: {n}" for n in self.notes]

    def to_dict(self) -> dict:
        return {
            "what": self.what,
            "tests": self.tests,
            "energy": self.energy.to_dict(),
            "distance": self.distance.to_dict(),
            "split_runs": self.split_runs,
            "power_on_split_energy": self.power(self.energy),
            "power_on_split_distance": self.power(self.distance),
            "both_pass_rate_2se": self.both_pass_rate if self.measured else None,
            "notes": list(self.notes),
        }


def _fair_energy_vs_points(
    ens: np.ndarray, spread: float, obs: np.ndarray
) -> np.ndarray:
    """Fair energy score of one fixed ensemble (m, 2) at many observations (k, 2),
    its spread term ``spread`` computed once."""
    d = np.sqrt(((ens[None, :, :] - obs[:, None, :]) ** 2).sum(axis=2))
    return d.mean(axis=1) - spread


def _fair_energy_rows(ens: np.ndarray, obs: np.ndarray) -> np.ndarray:
    """Fair energy score of ensembles (k, m, 2) at observations (k, 2), row-wise."""
    m = ens.shape[1]
    to_obs = np.sqrt(((ens - obs[:, None, :]) ** 2).sum(axis=2)).mean(axis=1)
    pair = np.sqrt(((ens[:, :, None, :] - ens[:, None, :, :]) ** 2).sum(axis=3))
    return to_obs - pair.sum(axis=(1, 2)) / (2.0 * m * (m - 1))


def virtual_campaigns(
    truth: Model3D,
    calibration: Sequence[PlanRun],
    holdout: Sequence[PlanRun],
    *,
    campaigns: int = 200,
    holdout_rocks: int = 200,
    seed: int = 0,
    extent: Extent | None = None,
    progress: Callable[[str], None] | None = None,
) -> Attainable:
    """The power of the held-out test in a world where ``truth`` is right.

    Campaign ``c`` observes one deposit per run -- rock ``c`` of the run simulated
    with ``default_rng([seed, VIRTUAL_STREAM, r])``, r the run's position in
    ``calibration + holdout`` -- builds the climatology from its calibration runs
    (censored at ``extent`` as the observations are, when given) and scores
    ``truth``'s held-out ensembles (``holdout_rocks`` per run,
    ``default_rng([seed, HOLDOUT_STREAM, r])``, the same for every campaign) against
    it on its held-out runs, by the fair energy score and the fair distance CRPS.

    Parameters
    ----------
    truth
        The model taken as the truth (a calibrated model; clipped to the tracked
        extent when the observations were, so its rocks are censored as theirs).
    calibration, holdout
        The split's runs (releases, blocks; their observed deposits are not used).
    campaigns
        Virtual campaigns, >= 2.
    holdout_rocks
        Members of the perfect forecast's ensembles, >= 2.
    seed
        Seed of the virtual observations and the forecast's streams.
    extent
        The tracked extent the climatology is censored at (None: not censored).
    progress
        Called with one line per stage.

    Returns
    -------
    Attainable
    """
    say = progress or (lambda line: None)
    if not (isinstance(campaigns, int | np.integer) and campaigns >= 2):
        raise ArgumentError(f"campaigns must be >= 2 (got {campaigns})",
                            source="campaigns")  # fmt: skip
    if not (isinstance(holdout_rocks, int | np.integer) and holdout_rocks >= 2):
        raise ArgumentError(f"holdout_rocks must be >= 2 (got {holdout_rocks})",
                            source="holdout_rocks")  # fmt: skip
    if len(calibration) < 2 or len(holdout) < 2:
        raise ArgumentError(
            f"needs >= 2 calibration and >= 2 held-out runs (got {len(calibration)}, "
            f"{len(holdout)})",
            source="runs",
        )
    runs = [*calibration, *holdout]
    n_cal = len(calibration)
    say(f"virtual campaigns: {campaigns} observations per run from the model")
    observed = plan_ensembles(
        truth, runs, int(campaigns), seed, stream=VIRTUAL_STREAM
    ).deposits_xy
    forecast = plan_ensembles(
        truth, holdout, int(holdout_rocks), seed, stream=HOLDOUT_STREAM
    ).deposits_xy
    rel = np.array([r.release_xy for r in runs], float)
    cal_rel, hold_rel = rel[:n_cal], rel[n_cal:]
    obs = np.stack(observed)  # (runs, campaigns, 2)
    hold_obs = obs[n_cal:]  # (holdout, campaigns, 2)
    # the perfect forecast: fixed ensembles, scored at every campaign's observation
    es_truth = np.empty((campaigns, len(holdout)))
    crps_truth = np.empty_like(es_truth)
    for i, (ens, r) in enumerate(zip(forecast, hold_rel, strict=True)):
        ens = ens[np.all(np.isfinite(ens), axis=1)]
        m = ens.shape[0]
        spread = _pair_distance_sum(ens) / (2.0 * m * (m - 1))
        es_truth[:, i] = _fair_energy_vs_points(ens, spread, hold_obs[i])
        dist = release_deposit_distance_m(r, ens)
        crps_truth[:, i] = fair_crps(
            np.broadcast_to(dist, (campaigns, m)),
            release_deposit_distance_m(r, hold_obs[i]),
        )
    es_clim = np.empty_like(es_truth)
    crps_clim = np.empty_like(es_truth)
    say("scoring the perfect forecast against each campaign's climatology")
    for c in range(campaigns):
        clim = censored_climatology(cal_rel, obs[:n_cal, c], hold_rel, extent)[0]
        y = hold_obs[:, c]
        es_clim[c] = _fair_energy_rows(clim, y)
        crps_clim[c] = fair_crps(
            release_deposit_distance_m(hold_rel[:, None, :], clim),
            release_deposit_distance_m(hold_rel, y),
        )
    notes = [
        f"virtual observations: one rock per run and campaign from the model "
        f"(streams [{seed}, {VIRTUAL_STREAM}, run]); the perfect forecast: "
        f"{holdout_rocks} rocks per held-out run (streams [{seed}, {HOLDOUT_STREAM}, "
        "run]), the same ensembles in every campaign",
        "climatology: each campaign's calibration runs' release-to-deposit vectors"
        + (f", censored at {extent.describe()}" if extent is not None else ""),
    ]
    return Attainable(
        what="a perfect forecast (the model as the truth) against the climatology",
        energy=_skill("energy_fair_m", es_truth - es_clim, same_runs=False),
        distance=_skill(
            "distance_crps_fair_m", crps_truth - crps_clim, same_runs=False
        ),
        split_runs=len(holdout),
        notes=notes,
    )


def group_climatology_skill(
    release_xy: np.ndarray,
    deposit_xy: np.ndarray,
    groups: Sequence,
    *,
    k: int = 5,
    repeats: int = 20,
    seed: int = 21,
    extent: Extent | None = None,
    split_runs: int = 18,
    label: str = "group",
) -> Attainable:
    """What knowing a run's group (its block) is worth: the climatology of the
    held-out run's own group against the pooled climatology, by repeated k-fold
    over all runs (stratified by group; :func:`repeated_kfold`).

    Each repeat holds every run out once; a test is a repeat (its per-run
    differences over all runs). The per-run advantage, pooled over repeats, is an
    unbiased estimate of what the group is worth to a perfect forecast (module
    docstring); its SE over runs is :attr:`SkillTest.per_run_sd` / sqrt(runs).

    Parameters
    ----------
    release_xy, deposit_xy
        (n, 2) the runs (duplicates removed).
    groups
        (n,) each run's group label.
    k, repeats, seed
        The k-fold (:func:`fieldkit.fit.plan_scores.repeated_kfold`).
    extent
        The tracked extent both climatologies are censored at (None: not).
    split_runs
        The held-out size of the split whose power is quoted
        (:meth:`SkillTest.power_at`).
    label
        What a group is, for the report (e.g. ``"block"``).

    Raises
    ------
    ArgumentError
        A group with fewer than ``k`` runs (a fold could leave it no calibration
        run).
    """
    rel = np.asarray(release_xy, float)[:, :2]
    dep = np.asarray(deposit_xy, float)[:, :2]
    g = np.asarray(groups)
    labels, counts = np.unique(g, return_counts=True)
    small = [str(lab) for lab, c in zip(labels, counts, strict=True) if c < k]
    if small:
        raise ArgumentError(
            f"group(s) {', '.join(small)} have fewer than k = {k} runs", source="groups"
        )
    n = len(rel)
    diff = np.zeros((repeats, n, 2))
    for f in repeated_kfold(n, k=k, repeats=repeats, seed=seed, groups=list(g)):
        cal, hold = f.calibration, f.holdout
        pooled = censored_climatology(rel[cal], dep[cal], rel[hold], extent)[0]
        y = dep[hold]
        dist_obs = release_deposit_distance_m(rel[hold], y)
        es_p = _fair_energy_rows(pooled, y)
        crps_p = fair_crps(release_deposit_distance_m(rel[hold][:, None, :], pooled),
                           dist_obs)  # fmt: skip
        for j, i in enumerate(hold):
            own = cal[g[cal] == g[i]]
            ens = censored_climatology(rel[own], dep[own], rel[[i]], extent)[0]
            diff[f.repeat, i, 0] = _fair_energy_rows(ens, y[[j]])[0] - es_p[j]
            diff[f.repeat, i, 1] = (
                fair_crps(release_deposit_distance_m(rel[i], ens[0]), dist_obs[j])
                - crps_p[j]
            )
    # a test is a repeat: every run held out once
    energy = _skill("energy_fair_m", diff[:, :, 0], same_runs=True)
    distance = _skill("distance_crps_fair_m", diff[:, :, 1], same_runs=True)
    notes = [
        f"repeated {k}-fold over {n} runs ({repeats} repeats, stratified by {label}, "
        f"seed {seed}); {label}s: "
        + ", ".join(f"{lab} ({c})" for lab, c in zip(labels, counts, strict=True)),
    ]
    return Attainable(
        what=f"the climatology of the run's own {label} against the pooled one",
        energy=energy,
        distance=distance,
        split_runs=int(split_runs),
        notes=notes,
    )
