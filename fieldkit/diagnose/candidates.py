"""Which effects an ImpactTable can inform, and what would separate look-alikes.

A candidate is an effect of the registry that changes the rebound the table
measures (``vfn``, ``vft``, ``omega_f``) as a function of what the table records.
Everything else is *skipped with its reason*, so a report never implies an effect
was tested when the data cannot speak to it.
"""

from __future__ import annotations

import numpy as np

from fieldkit.fit.impact_fit import ImpactProblem
from fieldkit.model.effects import registry
from fieldkit.model.model_file import Model

#: Impact-level candidates, in registry order (effect metadata: every effect an
#: ImpactTable can inform, the statistical alternative included).
IMPACT_CANDIDATES = tuple(s.name for s in registry.EFFECTS if not s.not_from_impacts)
#: Why the other effects are not candidates on an ImpactTable (effect metadata).
NOT_FROM_IMPACTS = {
    s.name: s.not_from_impacts for s in registry.EFFECTS if s.not_from_impacts
}
#: Least spread of a feature (degrees, m/s) for an effect reading it to be tested.
MIN_SPREAD = {"theta_i_deg": 2.0, "vin_mps": 0.5}


def measured_spin(problem: ImpactProblem) -> np.ndarray:
    """Rows whose impact spin ``omega_i`` is measured (not the v/r estimate)."""
    frame = problem.table.frame
    spin = np.isfinite(problem.table.column("omega_i_radps"))
    if "omega_source" in frame:
        src = frame["omega_source"].astype("string").fillna("none")
        spin &= ~src.isin(("estimated", "none")).to_numpy()
    return spin


def impact_candidates(
    problem: ImpactProblem, model: Model
) -> tuple[list[str], dict[str, str]]:
    """``(candidates, skipped effect -> reason)`` for ``problem`` on ``model``."""
    skipped: dict[str, str] = {}
    out: list[str] = []
    theta = np.abs(problem.table.column("theta_i_deg"))
    vin = np.abs(problem.inputs.vin_mps)
    for spec in registry.EFFECTS:
        name = spec.name
        if name in model.effects:
            skipped[name] = "already in the model"
        elif name in NOT_FROM_IMPACTS:
            skipped[name] = NOT_FROM_IMPACTS[name]
        elif (
            name == "angle_dependent_restitution"
            and _spread(theta) < MIN_SPREAD["theta_i_deg"]
        ):
            skipped[name] = (
                f"impact angles span only {_spread(theta):.2g} deg (IQR); "
                "nothing to tell an angle law from a constant"
            )
        elif (
            name == "velocity_scaled_restitution"
            and _spread(vin) < MIN_SPREAD["vin_mps"]
        ):
            skipped[name] = (
                f"normal impact speeds span only {_spread(vin):.2g} m/s (IQR)"
            )
        elif name == "rotation_friction" and measured_spin(problem).sum() < 3:
            skipped[name] = (
                "impact spins are not measured (estimated as rolling, v/r): a "
                "rolling body meets the ground without slip, so the rough-body "
                "impulse is zero; measure spin (video with a marker) to test it"
            )
        else:
            out.append(name)
    return out, skipped


def _spread(values: np.ndarray) -> float:
    v = values[np.isfinite(values)]
    if v.size < 2:
        return 0.0
    q1, q3 = np.percentile(v, [25, 75])
    return float(q3 - q1)


def separating_measurement(first: str, second: str, problem: ImpactProblem) -> str:
    """Why ``first`` and ``second`` look alike here and what would separate them."""
    pair = {first, second}
    speed = np.abs(problem.table.column("vi_mps"))
    theta = np.abs(problem.table.column("theta_i_deg"))
    lo, hi = np.nanpercentile(speed, [5, 95])
    a_lo, a_hi = np.nanpercentile(theta, [5, 95])
    if pair == {"angle_dependent_restitution", "velocity_scaled_restitution"}:
        return (
            f"{first} and {second} cannot be told apart with these data: impact "
            f"speeds span only {lo:.1f}-{hi:.1f} m/s, so the normal speed "
            "|v_in| = |v_i| sin θi rises with the impact angle θi "
            f"({a_lo:.0f}-{a_hi:.0f} deg) "
            "and an angle law and a speed law predict the same rebounds; impacts at "
            "similar angles over a wider range of speeds (drops from different "
            "heights, or a steeper and a gentler slope) would separate them"
        )
    alternatives = [n for n in (first, second) if not registry.effect(n).is_law]
    if len(alternatives) == 1:
        line = alternatives[0]
        law = (pair - {line}).pop()
        vin = np.abs(problem.inputs.vin_mps)
        n_lo, n_hi = np.nanpercentile(vin, [5, 95])
        return (
            f"{law} and {line} (a straight line in the impact velocities, not a "
            "law) cannot be told apart with these data: over the normal impact "
            f"speeds measured ({n_lo:.1f}-{n_hi:.1f} m/s) the law is as good as a "
            "straight line; impacts over a wider range of impact speeds and angles, "
            "where the law curves and a line does not, would separate them"
        )
    if "rotation_friction" in pair:
        other = (pair - {"rotation_friction"}).pop()
        return (
            f"rotation_friction and {other} cannot be told apart with these data: "
            "both change the rebound in the same direction over the impacts "
            "measured; spin measured before and after each impact (video with a "
            "marker) would separate them, since only rotation_friction moves it"
        )
    return (
        f"{first} and {second} cannot be told apart with these data (held-out "
        "errors equal within their standard error); more impacts over a wider "
        "range of the features they read would separate them"
    )
