"""Weighted least squares of a model's impact laws on an ImpactTable.

The data are each impact's measured rebound in local axes, ``vfn_mps`` and
``vft_mps``, and ``omega_f_radps`` where it is measured (finite and
``omega_source`` not ``estimated``/``none``); the prediction is
:func:`fieldkit.fit.impact_model.predict_arrays` (the simulator's impact stage with
material means). Residuals ``(observed - predicted) / sd`` are minimised by
``scipy.optimize.least_squares`` (``trf``, bounds, 3-point Jacobian).

Weights (the first that the table allows, stated in the result):

1. ``vfn_sd_mps``, ``vft_sd_mps`` (and ``omega_f_sd_radps`` for spins): the SDs of
   the rebound components themselves (written by ``fieldkit synth``);
2. ``e_n_sd``, ``e_t_sd``: ``sd(vfn) = e_n_sd |vin|``, ``sd(vft) = e_t_sd |vit|``
   (the table's restitution uncertainty carried to the rebound speed with the
   impact velocity as exact; ``vi_sd_mps`` is already inside ``e_n_sd`` and is not
   used again). Spins then need ``omega_f_sd_radps``, else they are left out;
3. unit weights: residuals in m/s, spins as the surface speed ``r omega`` in m/s.

Errors in the impact velocities (:func:`errors_in_variables`): when the table
carries ``vin_sd_mps`` and ``vit_sd_mps`` beside ``vfn_sd_mps``, ``vft_sd_mps``, the
impact velocity is a measurement too, and taking it as exact flattens the rebound
against it (regression dilution). Two corrections, both stated in the notes:

* **regression calibration** (Carroll et al. 2006, *Measurement Error in Nonlinear
  Models*, ch. 4): the inputs ``vin``, ``vit``, ``omega_i`` (with
  ``omega_i_sd_radps``) are replaced by their best estimate given the observation,
  ``E[v | v_obs] = mu + K (v_obs - mu)``, ``K = Sigma_true (Sigma_true + D)^-1``
  (one input alone: ``lambda = var_true / (var_true + sd^2)``), ``D`` the
  material's mean error variances, ``mu`` and ``Sigma_true = cov(v_obs) - D`` by
  the method of moments per material (eigenvalues floored at
  :data:`CALIBRATION_FLOOR` of the observed variance). Jointly, because an
  impact's spin and tangential speed are nearly tied (rolling) and calibrating
  each alone would break the tie; with the material's mean ``D`` (the best linear
  predictor), not each row's, because a row's SD grows with its own speed: a
  per-row ``lambda`` shrinks the fastest impacts hardest and leaves a bias a
  speed or spin law fits (measured: 8 false findings in 20 effect-free tables of
  1,000 impacts against 0 in 8). Where ``vin_vfn_corr`` (``vit_vft_corr``)
  says the rebound's error shares the impact's (an arrival and a rebound
  computed from the same surveyed point), the rebound is corrected by the part of
  its error the input's error predicts, ``c' V^-1 (v_obs - mu)`` with ``c = corr
  sd_in sd_out`` and ``V = Sigma_true + D_row`` (the row's own error variances);
* **effective variance** (Orear 1982, Am. J. Phys. 50, 912): each residual's
  variance is ``sd_out^2 + g' P g + 2 g' q``: the rebound's own error (less the
  part the correction removed) plus the calibrated inputs' remaining error, the
  covariance ``P = (I - K) Sigma_true`` of ``x - x_cal`` (at the material's mean
  ``D``, like ``K``: weights that shrink with a row's own ``D`` weight by its true
  speed), carried through the model's local gradient ``g = df/dv`` (central
  differences of the prediction at the model's values, recomputed once at the
  fitted values by :func:`fit_impacts`), plus twice their covariance ``q``. One
  input with ``K = 1`` (no calibration): Orear's ``sd_out^2 + g^2 sd_in^2 - 2 g
  cov``.

Without ``vin_sd_mps``/``vit_sd_mps`` nothing of this applies and the impact
velocities are exact inputs.

Free parameters: ``materials.<m>.e_n`` and ``materials.<m>.e_t`` of every material
the table's impacts touch, and every parameter of the active impact-stage effects
except those an impact table cannot determine (:data:`HELD`, stated in the notes):
flight and slide effects leave no mark on a single impact, and ``slope_roughness``
acts through the slope the table already records. Bounds come from the material
validation (:data:`fieldkit.model.materials.MATERIAL_FIELDS`) and the effect
registry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import least_squares
from threadpoolctl import threadpool_limits

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.fit.fit_result import FitResult
from fieldkit.fit.impact_model import (
    ImpactInputs,
    impact_inputs,
    predict_arrays,
    predict_rows,
)
from fieldkit.fit.impact_profile import profile_intervals
from fieldkit.fit.suspect import (
    GROUPS,
    SuspectCount,
    SuspectPolicy,
    count,
    impact_markers,
    policy_lines,
)
from fieldkit.impact_table import ImpactTable, flight_sides, path_point_kinds
from fieldkit.model.effects import registry
from fieldkit.model.materials import MATERIAL_FIELDS
from fieldkit.model.model_file import Model

#: Effect parameters held at the model's value, with the reason (stated in notes):
#: the parameters' metadata (:attr:`fieldkit.model.effects.spec.Parameter.held`).
HELD: dict[str, str] = {
    f"{spec.name}.{p.name}": p.held
    for spec in registry.EFFECTS
    for p in spec.parameters
    if p.held
}
#: Fewest impacts an impact fit takes per fitted material, and fewest residual
#: degrees of freedom (data - parameters). Below them the standard errors are not
#: worth the name: one impact determines its material's e_n and e_t exactly from
#: its vfn and vft (zero residuals, nothing of its own to measure the scatter;
#: two overdetermine them), and the errors' pooled scale sqrt(chi2 / dof) is itself
#: uncertain by about 1 / sqrt(2 dof) -- 71 % at 1 degree of freedom, 41 % at 3
#: (where the 95 % t multiplier is 3.2 against 12.7 at 1). Two per material keeps
#: the README's boulder A fit (rock: 2 impacts). A path fit likewise refuses a
#: path of one impact.
MIN_IMPACTS_PER_MATERIAL = 2
MIN_RESIDUAL_DOF = 3

#: The regression calibration's floor on a material's true-value variance of an
#: input, as a fraction of its observed variance: below it the method of moments
#: says the spread is nearly all error, which a handful of impacts cannot tell
#: reliably, and shrinking every impact to the mean would leave nothing to fit.
CALIBRATION_FLOOR = 0.1
#: Inputs measured with error: (ImpactInputs field, table value column, sd column,
#: rebound output it shares an error with (index in vfn, vft, omega_f) and the
#: correlation column of the two errors).
INPUT_ERRORS = (
    ("vin_mps", "vin_mps", "vin_sd_mps", 0, "vin_vfn_corr"),
    ("vit_mps", "vit_mps", "vit_sd_mps", 1, "vit_vft_corr"),
    ("omega_i_radps", "omega_i_radps", "omega_i_sd_radps", None, None),
)

#: A fit constrained to realised e_n <= c (``max_realised_e_n``): one residual per
#: impact, P times its predicted e_n beyond ``c - REALISED_MARGIN``, added to the
#: weighted residuals and solved for P = each of :data:`REALISED_PENALTIES` in turn
#: from the last solution (one large P at once leaves the search stuck: chi2 609
#: against 506 on boulder A); the margin holds the excess the last P leaves
#: (~1e-6) below c. chi2, the standard errors and AIC/BIC are of the data
#: residuals alone.
REALISED_PENALTIES = (1e2, 1e3, 1e4, 1e5)
REALISED_MARGIN = 1e-4

#: Primary columns every fitted row needs finite.
FINITE_COLUMNS = ("vi_x_mps", "vi_z_mps", "vf_x_mps", "vf_z_mps", "slope_deg")
_NOT_MEASURED_SPIN = ("estimated", "none")


def _rows(mask: np.ndarray) -> str:
    rows = np.flatnonzero(mask) + 1
    shown = ", ".join(str(r) for r in rows[:5])
    return (
        f"row {shown}"
        if rows.size == 1
        else f"rows {shown}" + (f" and {rows.size - 5} more" if rows.size > 5 else "")
    )


def no_flight_rows(table: ImpactTable) -> np.ndarray:
    """Rows with no arriving or no leaving flight (both components of ``vi`` or of
    ``vf`` empty): a reduced path's release and stop points, not impacts."""
    arrives, leaves = flight_sides(table.frame)
    return ~(arrives & leaves)


def check_table(
    table: ImpactTable, model: Model, skip: np.ndarray | None = None
) -> None:
    """Columns present and finite for a fit; one-line InputFileError otherwise.

    ``skip`` marks rows left out of the fit (not checked).
    """
    frame = table.frame
    keep = np.ones(len(frame), bool) if skip is None else ~skip
    needed = ["material", "radius_m"]
    if "rotation_friction" in model.effects:
        needed.append("gyration_m")
    problem = table.unusable_columns((*needed, *FINITE_COLUMNS))
    if problem:
        raise InputFileError(f"{problem} (needed to fit impacts)", source=table.source)
    for name in (*FINITE_COLUMNS, *needed[1:]):
        bad = ~np.isfinite(table.column(name)) & keep
        if bad.any():
            raise InputFileError(
                f"{name} is not a finite number", source=table.source, where=_rows(bad)
            )
    empty = frame["material"].isna().to_numpy() & keep
    if empty.any():
        raise InputFileError(
            "material is empty", source=table.source, where=_rows(empty)
        )


def free_parameters(model: Model, materials: list[str]) -> tuple[list[str], list[str]]:
    """``(free parameter names, notes)`` for a table touching ``materials``."""
    names = []
    for m in materials:
        names += [f"materials.{m}.e_n", f"materials.{m}.e_t"]
    notes = []
    for effect, values in model.effects.items():
        spec = registry.effect(effect)
        for key in values:
            name = f"{effect}.{key}"
            if spec.stage != "impact":
                notes.append(
                    f"{name} held: a {spec.stage}-stage effect leaves no "
                    "mark on a single impact"
                )
            elif name in HELD:
                notes.append(f"{name} held: {HELD[name]}")
            else:
                names.append(name)
    unused = [m for m in model.materials if m not in materials]
    if unused:
        notes.append(f"material(s) {', '.join(unused)} not in the table: unchanged")
    return names, notes


def _bounds(model: Model, name: str) -> tuple[float, float]:
    parts = name.split(".")
    if parts[0] == "materials":
        lower, upper, _, _ = MATERIAL_FIELDS[parts[2]]
        return lower, upper
    p = registry.effect(parts[0]).parameter(parts[1])
    return p.lower, p.upper


def _weights(table: ImpactTable, inputs: ImpactInputs) -> tuple[np.ndarray, str]:
    """``(sd array (n, 3), description)``; NaN sd = datum left out."""
    frame = table.frame
    n = len(frame)
    sd = np.full((n, 3), np.nan)
    spin = table.column("omega_f_radps")
    if "omega_source" in frame:
        src = frame["omega_source"].astype("string").fillna("")
        spin = np.where(src.isin(_NOT_MEASURED_SPIN).to_numpy(), np.nan, spin)
    has_spin = np.isfinite(spin)
    if "vfn_sd_mps" in frame and "vft_sd_mps" in frame:
        sd[:, 0] = table.column("vfn_sd_mps")
        sd[:, 1] = table.column("vft_sd_mps")
        text = "1/sd from the table's vfn_sd_mps, vft_sd_mps"
        spin_sd = "omega_f_sd_radps" in frame
    elif "e_n_sd" in frame and "e_t_sd" in frame and frame["e_n_sd"].notna().all():
        sd[:, 0] = table.column("e_n_sd") * np.abs(inputs.vin_mps)
        sd[:, 1] = table.column("e_t_sd") * np.abs(inputs.vit_mps)
        text = (
            "1/sd with sd(vfn) = e_n_sd |vin|, sd(vft) = e_t_sd |vit| from the "
            "table's e_n_sd, e_t_sd"
        )
        spin_sd = "omega_f_sd_radps" in frame
    else:
        sd[:, 0] = 1.0
        sd[:, 1] = 1.0
        sd[has_spin, 2] = 1.0 / inputs.radius_m[has_spin]
        return sd, (
            "unit weights (the table has no *_sd columns): residuals in m/s, spins "
            "as r omega_f in m/s"
        )
    if spin_sd:
        sd[has_spin, 2] = table.column("omega_f_sd_radps")[has_spin]
        text += ", omega_f_sd_radps"
    elif has_spin.any():
        text += "; measured spins left out (no omega_f_sd_radps)"
    known = np.isfinite(sd[:, :2])
    # a rebound measured exactly is allowed when the impact carries the error
    exact_ok = _has_input_errors(table) and text.startswith("1/sd from")
    positive = sd[:, :2] >= 0 if exact_ok else sd[:, :2] > 0
    bad = (known & ~positive).any(axis=1) | np.isinf(sd[:, :2]).any(axis=1)
    if bad.any():
        raise InputFileError(
            "standard uncertainty is not a positive number",
            source=table.source,
            where=_rows(bad),
        )
    # An empty sd beside a measured rebound: the reduction could not estimate it
    # (its flight had no ballistic solution in most survey-error draws): the datum
    # is too fragile to weigh, so it is left out, and said so.
    fragile = ~known.all(axis=1) & np.isfinite(inputs.vin_mps)
    if fragile.any():
        sd[fragile, :2] = np.nan
        text += (
            f"; {int(fragile.sum())} impact(s) left out whose sd is empty (their "
            "flights have no ballistic solution in most survey-error draws: "
            f"{_rows(fragile)})"
        )
    return sd, text


def _has_input_errors(table: ImpactTable) -> bool:
    """Whether ``table`` gives the impact velocity's standard uncertainty."""
    return {"vin_sd_mps", "vit_sd_mps"} <= set(table.frame)


@dataclass(frozen=True)
class InputErrors:
    """The regression calibration of a problem's inputs (see the module docstring).

    Per row, over the inputs ``vin``, ``vit``, ``omega_i`` (:data:`INPUT_ERRORS`)
    and the rebounds ``vfn``, ``vft``, ``omega_f``: ``sigma`` ``(n, 3, 3)`` the
    material's true-input covariance, ``gain`` ``(n, 3, 3)`` its ``K``,
    ``error_var`` ``(n, 3)`` its mean input error variances ``D``, ``shared``
    ``(n, 3, 3)`` [input, rebound] the errors' covariance at those variances
    (``corr sqrt(D) sd_out``), ``sd_out`` ``(n, 3)`` the rebound's own SD.
    ``mean`` ``(n, 3)`` is the material mean ``mu`` and ``recolour`` ``(n, 3, 3)``
    the material's ``Sigma_true^1/2 V^-1/2``, which maps observed deviations
    ``x_obs - mu`` to deviations of the true inputs' covariance with the observed
    distribution's shape (what :mod:`fieldkit.diagnose.table_null` draws its
    truth from).
    """

    sigma: np.ndarray
    gain: np.ndarray
    error_var: np.ndarray
    shared: np.ndarray
    sd_out: np.ndarray
    mean: np.ndarray
    recolour: np.ndarray

    def effective_sd(self, inputs: ImpactInputs, predict) -> np.ndarray:
        """``(n, 3)`` effective SD of each residual, ``g`` the gradient of
        ``predict(inputs) -> (n, 3)`` over the inputs (central differences).

        The residual ``y_obs - a' (x_obs - mu) - f(x_cal)`` is, to first order,
        ``u' (x - mu) + e_y - w' e`` with ``u = (I - K)' g - a``, ``w = a + K' g``,
        ``a = V^-1 c``: its variance ``u' Sigma u + sd_out^2 + w' D w - 2 w' c``
        (``c = 0``: ``sd_out^2 + g' (I - K) Sigma g``).
        """
        n = self.sd_out.shape[0]
        grad = np.zeros((n, 3, 3))  # [row, input, output]
        for j, (fname, *_) in enumerate(INPUT_ERRORS):
            if not np.any(self.error_var[:, j] > 0):
                continue
            x = getattr(inputs, fname)
            h = 1e-4 * np.maximum(1.0, np.abs(x))
            up = predict(replace(inputs, **{fname: x + h}))
            down = predict(replace(inputs, **{fname: x - h}))
            grad[:, j, :] = (up - down) / (2 * h)[:, None]
        grad[~np.isfinite(grad)] = 0.0
        d = np.einsum("rj,jk->rjk", self.error_var, np.eye(3))
        v_inv = np.linalg.inv(self.sigma + d)
        a = v_inv @ self.shared  # [row, input, rebound]
        k_t = self.gain.transpose(0, 2, 1)
        u = (np.eye(3)[None] - k_t) @ grad - a
        w = a + k_t @ grad
        var = (
            np.einsum("rjk,rjl,rlk->rk", u, self.sigma, u)
            + self.sd_out**2
            + np.einsum("rjk,rj,rjk->rk", w, self.error_var, w)
            - 2 * np.einsum("rjk,rjk->rk", w, self.shared)
        )
        return np.sqrt(np.maximum(var, 0.0))


@dataclass
class ImpactProblem:
    """A table's impact data against a model, ready to fit on any subset of rows.

    Built once by :func:`impact_problem`; :meth:`solve` fits chosen parameters on
    chosen rows (what cross-validation needs) and :meth:`predict` evaluates the
    laws anywhere. ``observed``, ``sd`` and ``use`` are ``(n, 3)`` arrays over the
    data kinds ``vfn``, ``vft``, ``omega_f`` (NaN sd = datum left out).
    """

    table: ImpactTable
    model: Model
    inputs: ImpactInputs
    observed: np.ndarray
    sd: np.ndarray
    use: np.ndarray
    weighting: str
    materials: list[str]
    rows: np.ndarray  # the table row (0-based) of each problem row
    notes: list[str] = field(default_factory=list)
    errors: InputErrors | None = None  # inputs measured with error (calibrated)
    #: Per row the factor its terms count with in the objective (the suspect-data
    #: policy, :mod:`fieldkit.fit.suspect`: residual / sd times its square root);
    #: None: all 1.
    row_weight: np.ndarray | None = None
    #: The suspect impacts (flagged, on an assumed θ0) and what the policy did.
    suspect: SuspectCount | None = None
    suspect_policy: SuspectPolicy = field(default_factory=SuspectPolicy)

    def reweighted(
        self,
        model: Model,
        names: list[str] | None = None,
        theta: np.ndarray | None = None,
    ) -> ImpactProblem:
        """This problem with the effective variances' derivatives taken at
        ``model`` with ``names`` set to ``theta`` (itself when its inputs are
        exact)."""
        if self.errors is None:
            return self
        e_n, e_t, effects = self.unpack(
            model, names or [], np.zeros(0) if theta is None else theta
        )
        sd = self.errors.effective_sd(
            self.inputs, lambda i: predict_arrays(i, e_n, e_t, effects)
        )
        sd = np.where(np.isfinite(self.sd), sd, np.nan)
        return replace(self, sd=sd, use=self.use & (sd > 0))

    def unpack(
        self, model: Model, names: list[str], theta: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, dict[str, dict[str, float]]]:
        """``(e_n, e_t, effects)`` of ``model`` with ``names`` set to ``theta``."""
        index = {m: i for i, m in enumerate(self.inputs.material_names)}
        e_n = np.array([model.materials[m].e_n for m in self.inputs.material_names])
        e_t = np.array([model.materials[m].e_t for m in self.inputs.material_names])
        effects = {k: dict(v) for k, v in model.effects.items()}
        for name, value in zip(names, theta, strict=True):
            parts = name.split(".")
            if parts[0] == "materials":
                target = e_n if parts[2] == "e_n" else e_t
                target[index[parts[1]]] = value
            else:
                effects[parts[0]][parts[1]] = float(value)
        return e_n, e_t, effects

    def predict(
        self,
        model: Model,
        names: list[str] | None = None,
        theta: np.ndarray | None = None,
    ) -> np.ndarray:
        """``(n, 3)`` predicted ``vfn, vft, omega_f`` of every row."""
        names = names or []
        theta = np.zeros(0) if theta is None else theta
        return predict_arrays(self.inputs, *self.unpack(model, names, theta))

    def start(self, model: Model, names: list[str]) -> tuple[np.ndarray, list[str]]:
        """Starting values (clipped into bounds) and notes on substituted ones."""
        notes = []
        start = np.array([model.parameters()[n] for n in names], float)
        bounds = self.bounds(model, names)
        for i, name in enumerate(names):
            if not math.isfinite(start[i]):
                effect, key = name.split(".")[:2]
                default = registry.effect(effect).parameter(key).default
                start[i] = default
                notes.append(
                    f"{name} starts at its default {default:g} "
                    "(the model's value is not finite)"
                )
        return np.clip(start, bounds[:, 0], bounds[:, 1]), notes

    @staticmethod
    def bounds(model: Model, names: list[str]) -> np.ndarray:
        """``(p, 2)`` lower and upper bounds of ``names``."""
        return np.array([_bounds(model, n) for n in names], float).reshape(-1, 2)

    def solve(
        self,
        model: Model,
        names: list[str],
        rows: np.ndarray | None = None,
        start: np.ndarray | None = None,
        max_realised_e_n: float | None = None,
    ):
        """``scipy.optimize.least_squares`` result of ``names`` fitted on ``rows``.

        ``rows`` is a boolean mask or index array (all rows when None); the
        residuals are ``(observed - predicted) / sd`` of the used data, followed,
        with ``max_realised_e_n``, by one penalty residual per impact
        (:func:`realised_penalty`, :data:`REALISED_PENALTIES` in turn).
        """
        rows = np.ones(len(self.observed), bool) if rows is None else rows
        mask = np.zeros(len(self.observed), bool)
        mask[rows] = True
        use = self.use & mask[:, None]
        inputs = self.inputs
        sub = ImpactInputs(
            *(getattr(inputs, f)[mask] for f in _ARRAY_FIELDS),
            material_names=inputs.material_names,
        )
        observed, sd = self.observed[mask], self.sd[mask]
        if self.row_weight is not None:
            sd = sd / np.sqrt(self.row_weight[mask])[:, None]
        keep = use[mask]
        if start is None:
            start, _ = self.start(model, names)
        bounds = self.bounds(model, names)

        limit = None
        if max_realised_e_n is not None:
            # the table's own impact velocities (not their regression
            # calibration): what the plausibility report applies the law to
            own = impact_inputs(self.table, model)
            limit = (
                max_realised_e_n,
                ImpactInputs(
                    *(getattr(own, f)[mask] for f in _ARRAY_FIELDS),
                    material_names=own.material_names,
                ),
            )
        residuals = _Residuals(self, model, names, sub, observed, sd, keep, limit)

        if not names:
            return _NoFit(residuals(np.zeros(0)))
        # The Jacobian is tall and thin (data x a few parameters): threaded BLAS
        # only adds contention (10x slower on a loaded 2-core machine, measured).
        with threadpool_limits(limits=1, user_api="blas"):
            for penalty in REALISED_PENALTIES if limit is not None else [None]:
                residuals.penalty = penalty
                fit = least_squares(
                    residuals,
                    start,
                    bounds=(bounds[:, 0], bounds[:, 1]),
                    method="trf",
                    jac="3-point",
                    x_scale="jac",
                )
                start = fit.x
            return fit


class _Residuals:
    """``theta -> (observed - predicted) / sd`` with the parameter plumbing done once.

    Each name maps to one slot: a material's ``e_n`` or ``e_t`` or an entry of the
    kernel's flat effect-parameter array (the registry layout), so a call only
    writes ``theta`` into copies of three arrays and runs the compiled predictor.
    """

    def __init__(
        self, problem, model, names, inputs, observed, sd, keep, limit=None
    ) -> None:
        self.limit = limit
        self.penalty = REALISED_PENALTIES[-1]
        e_n, e_t, effects = problem.unpack(model, [], np.zeros(0))
        self.flags, self.par = registry.kernel_arrays(effects)
        self.e_n, self.e_t = e_n, e_t
        index = {m: i for i, m in enumerate(problem.inputs.material_names)}
        self.slots = []
        for name in names:
            parts = name.split(".")
            if parts[0] == "materials":
                self.slots.append((parts[2], index[parts[1]]))
            else:
                self.slots.append(("par", registry.LAYOUT[name]))
        self.inputs = inputs
        self.observed, self.sd, self.keep = observed, sd, keep

    def __call__(self, theta: np.ndarray) -> np.ndarray:
        e_n, e_t, par = self.e_n.copy(), self.e_t.copy(), self.par.copy()
        target = {"e_n": e_n, "e_t": e_t, "par": par}
        for (kind, i), value in zip(self.slots, theta, strict=True):
            target[kind][i] = value
        i = self.inputs
        pred = predict_rows(
            i.vin_mps, i.vit_mps, i.omega_i_radps, i.radius_m, i.gyration_m,
            i.material_index, e_n, e_t, self.flags, par,
        )  # fmt: skip
        out = ((self.observed - pred) / self.sd)[self.keep]
        if self.limit is None:
            return out
        limit, i = self.limit
        if i is not self.inputs:
            pred = predict_rows(
                i.vin_mps, i.vit_mps, i.omega_i_radps, i.radius_m, i.gyration_m,
                i.material_index, e_n, e_t, self.flags, par,
            )  # fmt: skip
        return np.concatenate(
            [out, realised_penalty(pred[:, 0], i.vin_mps, limit, self.penalty)]
        )


def check_realised_limit(value: float | None) -> None:
    """Refuse a realised-e_n limit that is not a positive finite number.

    Raises
    ------
    ArgumentError
        Naming ``max_realised_e_n``.
    """
    if value is not None and not (math.isfinite(value) and value > 0):
        raise ArgumentError(
            f"the realised e_n limit must be a positive number (got {value:g})",
            source="max_realised_e_n",
        )


def realised_penalty(
    vfn: np.ndarray, vin: np.ndarray, limit: float, penalty: float
) -> np.ndarray:
    """Penalty residuals of a fit constrained to realised ``e_n <= limit``:
    ``penalty x max(-vfn/vin - (limit - REALISED_MARGIN), 0)`` per impact (0
    where the velocity is not into the ground).

    Examples
    --------
    >>> realised_penalty(np.array([1.2, 0.5]), np.array([-1.0, -1.0]), 1.0, 100.0)
    array([20.01,  0.  ])
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        e_n = np.where(vin < 0, vfn / -vin, 0.0)
    excess = np.nan_to_num(e_n) - (limit - REALISED_MARGIN)
    return penalty * np.maximum(excess, 0.0)


_ARRAY_FIELDS = (
    "vin_mps",
    "vit_mps",
    "omega_i_radps",
    "radius_m",
    "gyration_m",
    "material_index",
)


@dataclass
class _NoFit:
    """``least_squares``-like result when nothing is free."""

    fun: np.ndarray
    x: np.ndarray = field(default_factory=lambda: np.zeros(0))
    jac: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    success: bool = True
    message: str = "no free parameters"


def _sqrtm(a: np.ndarray) -> np.ndarray:
    """Symmetric square root of a symmetric positive definite matrix."""
    values, vectors = np.linalg.eigh((a + a.T) / 2)
    return (vectors * np.sqrt(np.maximum(values, 0.0))) @ vectors.T


def _true_covariance(x: np.ndarray, error_var: np.ndarray) -> tuple[np.ndarray, bool]:
    """Method-of-moments covariance of the true inputs of one material,
    ``cov(x_obs) - diag(mean sd^2)``, its correlation-scaled eigenvalues floored
    at :data:`CALIBRATION_FLOOR`; ``(Sigma_true, floored)``."""
    s_obs = np.atleast_2d(np.cov(x, rowvar=False)) if len(x) > 1 else np.zeros((3, 3))
    scale = np.sqrt(np.diag(s_obs))
    scale = np.where(scale > 0, scale, 1.0)
    r = (s_obs - np.diag(error_var.mean(axis=0))) / np.outer(scale, scale)
    values, vectors = np.linalg.eigh((r + r.T) / 2)
    floored = bool(np.any(values < CALIBRATION_FLOOR))
    r = (vectors * np.maximum(values, CALIBRATION_FLOOR)) @ vectors.T
    return r * np.outer(scale, scale), floored


def errors_in_variables(
    table: ImpactTable, inputs: ImpactInputs, observed: np.ndarray, sd: np.ndarray
) -> tuple[ImpactInputs, np.ndarray, InputErrors, str]:
    """Regression calibration of the inputs measured with error (module docstring).

    The three inputs ``vin``, ``vit``, ``omega_i`` are calibrated jointly (an
    impact's spin and tangential speed are strongly related, and calibrating each
    alone would break the relation): per material ``mu`` and ``Sigma_true`` by the
    method of moments, ``K = Sigma_true (Sigma_true + D)^-1`` with ``D`` the
    material's mean error covariance (diagonal: the *_sd columns squared; zero for
    an input given exactly), ``x_cal = mu + K (x_obs - mu)``. Returns the
    calibrated inputs, the observed rebounds corrected for the error they share
    with their inputs, the :class:`InputErrors` the effective variance needs and a
    note saying what was done.
    """
    n = len(table)
    labels = table.frame["material"].astype("string").to_numpy(str)
    x = np.column_stack([getattr(inputs, f[0]) for f in INPUT_ERRORS])
    err = np.zeros((n, 3))
    for j, (_, _, sd_column, _, _) in enumerate(INPUT_ERRORS):
        if sd_column in table.frame:
            err[:, j] = np.nan_to_num(np.abs(table.column(sd_column)), nan=0.0)
    corr = np.zeros((n, 3, 3))  # [row, input, rebound]: correlation of the errors
    shared = []
    for j, (*_, out, corr_column) in enumerate(INPUT_ERRORS):
        if out is not None and corr_column in table.frame:
            r = np.clip(np.nan_to_num(table.column(corr_column), nan=0.0), -1, 1)
            corr[:, j, out] = np.where(err[:, j] > 0, r, 0.0)
            if np.any(corr[:, j, out] != 0):
                shared.append(f"{('vfn', 'vft')[out]} by {corr_column}")
    x_cal = x.copy()
    sigmas, gains = np.zeros((n, 3, 3)), np.zeros((n, 3, 3))
    error_var, shared_w = np.zeros((n, 3)), np.zeros((n, 3, 3))
    mean, recolour = np.zeros((n, 3)), np.zeros((n, 3, 3))
    observed = observed.copy()
    floored = []
    for m in np.unique(labels):
        rows = labels == m
        sigma, low = _true_covariance(x[rows], err[rows] ** 2)
        if low:
            floored.append(m)
        mu = x[rows].mean(axis=0)
        # the best linear predictor: the material's mean error variance, not the
        # row's -- a row's SD grows with its own speed, so shrinking the rows with
        # larger SDs harder would pull the fastest impacts furthest from the truth
        v = sigma + np.diag((err[rows] ** 2).mean(axis=0))
        v_inv = np.linalg.inv(v)
        mean[rows] = mu
        recolour[rows] = _sqrtm(sigma) @ np.linalg.inv(_sqrtm(v))
        k = sigma @ v_inv
        d = x[rows] - mu
        x_cal[rows] = mu + d @ k.T
        # the weights take the inputs' error at the material's mean variance D
        # too, for the same reason: weights that shrink with a row's own D would
        # weight by its true speed (measured: 7.0 % false findings at 1,000
        # impacts with the row's D, 2.5 % with the mean)
        d_bar = (err[rows] ** 2).mean(axis=0)
        sigmas[rows] = sigma
        gains[rows] = k
        error_var[rows] = d_bar
        r = corr[rows]  # [row, input, rebound]
        shared_w[rows] = (
            r
            * np.sqrt(d_bar)[None, :, None]
            * np.nan_to_num(sd[rows], nan=0.0)[:, None, :]
        )
        # E[rebound error | x_obs] = a' (x_obs - mu), a = V^-1 c with the row's c
        # and V = Sigma + the row's D: the part of this rebound's error its own
        # input error predicts
        c = r * err[rows][:, :, None] * np.nan_to_num(sd[rows], nan=0.0)[:, None, :]
        v_rows = sigma[None] + np.einsum("rj,jk->rjk", err[rows] ** 2, np.eye(3))
        a_ = np.linalg.inv(v_rows) @ c
        observed[rows] -= np.einsum("rjk,rj->rk", a_, d)
    inputs = replace(inputs, **{f[0]: x_cal[:, j] for j, f in enumerate(INPUT_ERRORS)})
    errors = InputErrors(
        sigma=sigmas,
        gain=gains,
        error_var=error_var,
        shared=shared_w,
        sd_out=sd,
        mean=mean,
        recolour=recolour,
    )
    names = ", ".join(INPUT_ERRORS[j][1] for j in range(3) if np.any(err[:, j] > 0))
    note = (
        f"errors in variables: the impact's {names} carry error (their *_sd "
        "columns); vin, vit, omega_i replaced jointly by their regression "
        "calibration mu + K (v_obs - mu), K = Sigma_true (Sigma_true + D)^-1, D the "
        "material's mean error variances, mu and Sigma_true = cov(v_obs) - D by the "
        "method of moments per material"
        + (
            f" (eigenvalues floored at {CALIBRATION_FLOOR:g} of the observed "
            f"variance for {', '.join(floored)}: its observed spread is mostly error)"
            if floored
            else ""
        )
        + "; "
        + (
            "rebound corrected for the error it shares with its input ("
            + ", ".join(shared)
            + "); "
            if shared
            else "no error shared between impact and rebound (no "
            "vin_vfn_corr, vit_vft_corr); "
        )
        + "weights by effective variance (Orear 1982): the rebound's variance plus "
        "the calibrated inputs' remaining error carried through the model's local "
        "derivatives"
    )
    return inputs, observed, errors, note


def impact_problem(
    table: ImpactTable, model: Model, suspect: SuspectPolicy | None = None
) -> ImpactProblem:
    """Check ``table`` against ``model`` and gather the arrays of a fit.

    ``suspect`` says what to do with impacts flagged by the reduction or resting
    on an assumed launch angle (:mod:`fieldkit.fit.suspect`): excluded rows are
    left out before anything is computed from the table, weighted rows count
    ``w`` times in the objective (their residuals' SD divided by ``sqrt(w)``);
    stated in the notes and the weighting. None keeps every impact.

    Raises
    ------
    InputFileError
        Required columns missing, non-finite values (rows named), materials of the
        table not in the model (named), non-positive uncertainties.
    """
    policy = suspect or SuspectPolicy()
    skip = no_flight_rows(table)
    flags, assumed = impact_markers(table.derive().frame)  # qa_flags recomputed
    factor = policy.factors(flags, assumed)
    suspect_count = count(policy, flags[~skip], assumed[~skip])
    if "point" in table.frame:
        points = table.frame["point"].astype(str).to_numpy()
        suspect_count.points = points[~skip & (flags > 0)].tolist()
    excluded = (factor == 0.0) & ~skip
    check_table(table, model, skip | excluded)
    notes = []
    if skip.any():
        kinds = path_point_kinds(table.frame)
        named = "; ".join(f"row {row}, {what}" for row, what in kinds[:5])
        more = f"; and {len(kinds) - 5} more" if len(kinds) > 5 else ""
        notes.append(
            f"{len(kinds)} row{'' if len(kinds) == 1 else 's'} left out: no arriving "
            f"or leaving flight, not an impact ({named}{more})"
        )
    if skip.any() or excluded.any():
        table = ImpactTable(
            table.frame.loc[~skip & ~excluded].reset_index(drop=True),
            source=table.source,
        )
    if not policy.is_default:
        notes += [
            f"suspect data: {line}"
            for line in policy_lines(
                policy,
                {"impacts": suspect_count},
                "impacts",
                flights=False,
                arguments=False,
            )
        ]
    table = table.derive()
    inputs = impact_inputs(table, model)
    used = [m for m in inputs.material_names if m in set(table.frame["material"])]
    sd, weighting = _weights(table, inputs)
    observed = np.column_stack(
        [
            table.column("vfn_mps"),
            table.column("vft_mps"),
            table.column("omega_f_radps"),
        ]
    )
    errors = None
    if _has_input_errors(table):
        if weighting.startswith("1/sd from"):
            inputs, observed, errors, text = errors_in_variables(
                table, inputs, observed, sd
            )
            notes.append(text)
            weighting += " and, by effective variance (errors in variables), " + (
                ", ".join(c for c in ("vin_sd_mps", "vit_sd_mps", "omega_i_sd_radps")
                          if c in table.frame)
            )  # fmt: skip
        else:
            notes.append(
                "the impact velocities carry error (vin_sd_mps, vit_sd_mps) but the "
                "rebound's own SDs (vfn_sd_mps, vft_sd_mps) are not given: the "
                "impact velocities are taken as exact inputs"
            )
    problem = ImpactProblem(
        table=table,
        model=model,
        inputs=inputs,
        observed=observed,
        sd=sd,
        use=np.isfinite(sd) & np.isfinite(observed),
        weighting=weighting,
        materials=used,
        rows=np.flatnonzero(~skip & ~excluded),
        notes=notes,
        errors=errors,
        row_weight=(factor[~skip & ~excluded] if suspect_count.weighted else None),
        suspect=suspect_count,
        suspect_policy=policy,
    )
    if suspect_count.weighted:
        problem.weighting += (
            f"; {suspect_count.weighted} suspect impact(s) weighted (their terms "
            "count w times: sd / √w; "
            + ", ".join(
                f"{GROUPS[g]} {policy.treatment(g).words}"
                for g in GROUPS
                if 0.0 < policy.treatment(g).weight < 1.0
            )
            + ")"
        )
    if errors is None:
        return problem
    problem = problem.reweighted(model)
    bad = ~((problem.sd[:, :2] > 0).all(axis=1))
    if bad.any():
        raise InputFileError(
            "standard uncertainty is not a positive number (rebound and impact "
            "both exact)",
            source=table.source,
            where=_rows(bad),
        )
    return problem


def too_few(problem: ImpactProblem, names: list[str], rows=None) -> str | None:
    """Why ``rows`` of ``problem`` cannot fit ``names`` (None when they can)."""
    use = problem.use if rows is None else problem.use[rows]
    ndata, p = int(use.sum()), len(names)
    if ndata > p:
        return None
    n = len(use)
    per = max(1, int(use.sum(axis=1).max())) if n else 2
    need = p // per + 1
    return (
        f"too few impacts to fit: {n} impact(s) give {ndata} data for "
        f"{p} parameters ({', '.join(names)}); need more data than parameters, "
        f"at least {need} impacts"
    )


def too_few_for_errors(problem: ImpactProblem, names: list[str]) -> str | None:
    """Why ``problem`` cannot give ``names`` standard errors worth the name (None
    when it can): fewer than :data:`MIN_IMPACTS_PER_MATERIAL` impacts with data on
    a fitted material, or fewer than :data:`MIN_RESIDUAL_DOF` residual degrees of
    freedom."""
    used = problem.use.any(axis=1)
    index = problem.inputs.material_index[used]
    counts = {
        m: int(np.sum(index == problem.inputs.material_names.index(m)))
        for m in problem.materials
        if f"materials.{m}.e_n" in names or f"materials.{m}.e_t" in names
    }
    short = {m: n for m, n in counts.items() if n < MIN_IMPACTS_PER_MATERIAL}
    dof = int(problem.use.sum()) - len(names)
    if not short and dof >= MIN_RESIDUAL_DOF:
        return None
    parts = []
    if short:
        parts.append(
            ", ".join(
                f"material {m} has {n} impact{'s' if n != 1 else ''}"
                for m, n in short.items()
            )
            + f" (at least {MIN_IMPACTS_PER_MATERIAL} per fitted material)"
        )
    if dof < MIN_RESIDUAL_DOF:
        parts.append(
            f"{int(problem.use.sum())} data for {len(names)} parameters leave "
            f"{dof} residual degree{'s' if dof != 1 else ''} of freedom (at least "
            f"{MIN_RESIDUAL_DOF})"
        )
    return (
        "too few impacts for standard errors worth the name: "
        + "; ".join(parts)
        + ": no calibrated model"
    )


def _data_part(problem: ImpactProblem, fit, limit: float):
    """``(fit with the data residuals and Jacobian rows only, note)`` of a fit
    constrained to realised e_n <= ``limit``."""
    n = int(problem.use.sum())
    penalty = fit.fun[n:]
    margin = limit - REALISED_MARGIN
    largest = margin + float(penalty.max(initial=0.0)) / REALISED_PENALTIES[-1]
    active = int(np.sum(penalty > 0))
    words = (
        f"constrained to realised e_n <= {limit:g} at every observed impact (a "
        f"penalty residual per impact on its e_n beyond {margin:g}, raised to "
        f"{REALISED_PENALTIES[-1]:g} x the excess): "
        + (
            f"{active} impact(s) at the limit, the largest realised e_n {largest:.6f}"
            if active
            else "no impact reaches it"
        )
        + "; chi2, standard errors and AIC/BIC are of the data residuals alone"
    )
    if isinstance(fit, _NoFit):
        return replace(fit, fun=fit.fun[:n]), words
    data = dict(fit)
    data.update(fun=fit.fun[:n], jac=fit.jac[:n])
    return type(fit)(data), words


def fit_result(problem: ImpactProblem, names, start, fit, notes) -> FitResult:
    """The :class:`FitResult` of a :meth:`ImpactProblem.solve` on all rows."""
    r = fit.fun
    ndata, p = r.size, len(names)
    chi2 = float(r @ r)
    redchi = chi2 / (ndata - p)
    jac = fit.jac
    with np.errstate(divide="ignore", invalid="ignore"):
        try:
            cov = np.linalg.inv(jac.T @ jac) * redchi
        except np.linalg.LinAlgError:
            cov = np.full((p, p), np.inf)
        se = np.sqrt(np.where(np.diag(cov) >= 0, np.diag(cov), np.nan))
        corr = cov / np.outer(se, se)
    corr[~np.isfinite(corr)] = np.nan
    np.fill_diagonal(corr, 1.0)
    ln = ndata * math.log(chi2 / ndata) if chi2 > 0 else -math.inf
    use = problem.use
    rows = np.broadcast_to(np.arange(len(use))[:, None], use.shape)[use]
    kind = np.broadcast_to(np.array(["vfn", "vft", "omega_f"]), use.shape)[use]
    bounds = problem.bounds(problem.model, names)
    return FitResult(
        names=list(names),
        values=np.asarray(fit.x, float),
        stderr=se,
        start=start,
        lower=bounds[:, 0],
        upper=bounds[:, 1],
        correlation=corr,
        chi2=chi2,
        redchi=redchi,
        aic=ln + 2 * p,
        bic=ln + math.log(ndata) * p,
        ndata=ndata,
        nparams=p,
        n_impacts=len(use),
        success=bool(fit.success),
        message=str(fit.message),
        weighting=problem.weighting,
        notes=list(notes),
        residuals=r,
        residual_kind=kind,
        residual_row=rows,
    )


#: Said with the intervals of an impact fit to one path's impacts (issue 20).
ONE_PATH_IMPACTS = (
    "one path: its impacts are not independent (one rock, one slope, one survey), "
    "so the standard errors and intervals are a lower bound on the uncertainty of a "
    "site's parameters (another boulder, another path)"
)


def _profile(problem: ImpactProblem, model: Model, result: FitResult) -> dict:
    """The profile-likelihood intervals of ``result`` (:mod:`fieldkit.fit.
    impact_profile`), with the one-path statement when the table has one path."""
    prof = profile_intervals(
        problem, model, result.names, result.values, result.stderr, result.chi2,
        result.ndata - result.nparams,
    )  # fmt: skip
    paths = problem.table.frame["path_id"].astype(str).unique()
    prof["one_path"] = ONE_PATH_IMPACTS if len(paths) == 1 else None
    return prof


def solve_reweighted(
    problem: ImpactProblem,
    model: Model,
    names: list[str],
    start: np.ndarray,
    max_realised_e_n: float | None = None,
):
    """``(problem, least_squares result)`` of ``names`` from ``start`` on every row;
    with inputs measured with error, solved again with the effective variances'
    derivatives taken at the first solution (the problem returned is that one)."""
    fit = problem.solve(model, names, start=start, max_realised_e_n=max_realised_e_n)
    if problem.errors is not None:
        # the effective variances' derivatives once more, at the fitted values
        problem = problem.reweighted(model, names, fit.x)
        fit = problem.solve(model, names, start=np.asarray(fit.x, float),
                            max_realised_e_n=max_realised_e_n)  # fmt: skip
    return problem, fit


def fit_impacts(
    table: ImpactTable,
    model: Model,
    suspect: SuspectPolicy | None = None,
    max_realised_e_n: float | None = None,
) -> tuple[FitResult, Model]:
    """Fit ``model``'s impact laws to ``table``; ``(result, calibrated model)``.

    The calibrated model is ``model`` with the fitted values in place (its
    ``provenance`` is left to the caller, who knows the table's file name).
    ``suspect``: what to do with flagged impacts and impacts on an assumed launch
    angle (:func:`impact_problem`; default: keep them).

    ``max_realised_e_n`` constrains the fit so that the law's realised ``e_n =
    vfn / -vin`` at every observed impact (at the table's own impact velocities,
    as :func:`fieldkit.fit.plausibility.observed_restitution` applies it) is at
    most it: a penalty residual per impact (:func:`realised_penalty`), raised
    in steps (:data:`REALISED_PENALTIES`) and aimed :data:`REALISED_MARGIN` below
    the limit so that none is left above it (the largest value is in the notes).

    Raises
    ------
    InputFileError
        Required columns missing, non-finite values (rows named), materials of the
        table not in the model (named), fewer data than parameters, or too few
        for standard errors (:func:`too_few_for_errors`).
    """
    problem = impact_problem(table, model, suspect)
    names, notes = free_parameters(model, problem.materials)
    why = too_few(problem, names) or too_few_for_errors(problem, names)
    if why:
        if problem.suspect is not None and problem.suspect.excluded:
            policy = problem.suspect_policy
            given = ", ".join(
                f"`{g}` exclude" for g in GROUPS if policy.treatment(g).exclude
            )
            why += f" ({problem.suspect.excluded} suspect impacts left out: {given})"
        raise InputFileError(why, source=table.source)
    check_realised_limit(max_realised_e_n)
    limit = max_realised_e_n
    start, start_notes = problem.start(model, names)
    problem, fit = solve_reweighted(problem, model, names, start, limit)
    if limit is not None:
        fit, words = _data_part(problem, fit, limit)
        notes = [*notes, words]
    result = fit_result(problem, names, start, fit, problem.notes + notes + start_notes)
    result.profile = _profile(problem, model, result)
    result.suspect = problem.suspect
    calibrated = model.with_parameters(dict(zip(names, map(float, fit.x), strict=True)))
    return result, replace(calibrated, provenance=dict(model.provenance))
