"""The words a person reads for the names a diagnosis computes with.

The code, the ImpactTable and the ``--json`` file name quantities by their column
names (``theta_i_deg``, ``vfn``, ``cv_rmse_mps``, ``materials.rock.e_n``); the
report, the figures and the printed summary show them in words with units, through
this one mapping, so a figure's axis and the report's table always agree.

* :func:`feature` -- what the residuals are tested against (``theta_i_deg`` ->
  "impact angle to the ground θi (deg)");
* :func:`component` -- which residual (``omega_f`` -> the rebound spin as the
  surface speed r·ω_f, in m/s like the velocities);
* :func:`metric` -- the held-out error (``cv_rmse_mps``);
* :func:`effect` -- a candidate effect, with its thesis reference;
* :func:`parameter` and :func:`value_with_se` -- a fitted parameter and its
  standard error, or why there is none.

Examples
--------
>>> feature("theta_i_deg")
'impact angle to the ground θi (deg)'
>>> component("omega_f")
'rebound spin as surface speed r·ω_f'
>>> metric("cv_rmse_mps")
'held-out RMS error of the rebound velocities (m/s)'
"""

from __future__ import annotations

import math

from fieldkit.model.effects import registry

#: Feature (a column of the table, or a per-sample quantity of a flight) -> words.
FEATURES: dict[str, str] = {
    "theta_i_deg": "impact angle to the ground θi (deg)",
    "vin_mps": "normal impact speed v_in (m/s)",
    "vit_mps": "tangential impact velocity v_it (m/s)",
    "vi_mps": "impact speed v_i (m/s)",
    "omega_i_radps": "measured spin before impact ω_i (rad/s)",
    "x_m": "x, horizontal distance along the path (m)",
    "radius_m": "block radius r (m)",
    "mass_kg": "block mass (kg)",
    "material": "slope material",
    "tree_strike": "flight before the impact struck a tree",
    "time_from_mid_flight": (
        "absolute time from mid-flight / half the flight's duration "
        "(0 mid-flight, 1 take-off or landing)"
    ),
    "speed_mps": "speed along the fitted flight (m/s)",
}

#: Residual component -> words (without unit: the unit is the metric's).
COMPONENTS: dict[str, str] = {
    "vfn": "normal rebound velocity v_fn",
    "vft": "tangential rebound velocity v_ft",
    "omega_f": "rebound spin as surface speed r·ω_f",
    "x": "horizontal position x",
    "z": "vertical position z",
    "position_x": "horizontal position x",
    "position_z": "vertical position z",
}

#: Residual component -> its symbol (figure notes, where space is short).
SYMBOLS: dict[str, str] = {
    "vfn": "v_fn",
    "vft": "v_ft",
    "omega_f": "r·ω_f",
    "position_x": "x",
    "position_z": "z",
}

#: Metric -> (words, unit).
METRICS: dict[str, tuple[str, str]] = {
    "cv_rmse_mps": ("held-out RMS error of the rebound velocities", "m/s"),
    "cv_rmse_m": ("held-out RMS error of the flight positions", "m"),
}

#: Parameters that are not an effect's or a material's -> (words, unit).
OTHER_PARAMETERS: dict[str, tuple[str, str]] = {
    "gravity_mps2": ("gravity g", "m/s²"),
}

#: Material parameters -> words.
MATERIAL_PARAMETERS: dict[str, str] = {
    "e_n": "normal restitution e_n",
    "e_t": "tangential restitution e_t",
    "e_n_sd": "standard deviation of e_n",
    "e_t_sd": "standard deviation of e_t",
    "friction_deg": "friction angle (deg)",
}


def feature(name: str) -> str:
    """A feature in words with its unit (the name itself when unknown)."""
    return FEATURES.get(name, name)


def component(name: str) -> str:
    """A residual component in words (the name itself when unknown)."""
    return COMPONENTS.get(name, name)


def symbol(name: str) -> str:
    """A residual component's symbol (the name itself when unknown)."""
    return SYMBOLS.get(name, name)


def unit(metric_name: str) -> str:
    """The unit of a metric's residuals ("m/s" or "m")."""
    return METRICS.get(metric_name, (metric_name, "m" if metric_name.endswith("_m")
                                     else "m/s"))[1]  # fmt: skip


def metric_words(name: str) -> str:
    """A metric in words, without its unit."""
    return METRICS.get(name, (name, ""))[0]


def metric(name: str) -> str:
    """A metric in words with its unit."""
    return f"{metric_words(name)} ({unit(name)})"


def effect(name: str) -> str:
    """An effect in words: its name with spaces and its reference.

    Examples
    --------
    >>> effect("angle_dependent_restitution")
    'angle-dependent restitution (thesis eq. 5.4)'
    >>> effect("air_drag")
    'air drag (quadratic)'
    >>> effect("affine_rebound")
    'affine rebound (a straight line, not a law)'
    """
    spec = registry.BY_NAME.get(name)
    words = {
        "angle_dependent_restitution": "angle-dependent restitution",
        "velocity_scaled_restitution": "velocity-scaled restitution",
    }.get(name, name.replace("_", " "))
    if spec is None:
        return words
    ref = spec.reference.split(",")[0]
    if not spec.is_law:
        ref = "a straight line, not a law"
    elif ref.startswith("none"):
        ref = "quadratic"
    return f"{words} ({ref})"


def parameter(name: str) -> tuple[str, str]:
    """``(words, unit)`` of a fitted parameter named as in the JSON.

    Examples
    --------
    >>> parameter("materials.rock.e_n")
    ('rock: normal restitution e_n', '-')
    >>> parameter("velocity_scaled_restitution.k_mps")[1]
    'm/s'
    """
    if name in OTHER_PARAMETERS:
        return OTHER_PARAMETERS[name]
    parts = name.split(".")
    if parts[0] == "materials" and len(parts) == 3:
        words = MATERIAL_PARAMETERS.get(parts[2], parts[2])
        return f"{parts[1]}: {words}", "deg" if parts[2].endswith("_deg") else "-"
    spec = registry.BY_NAME.get(parts[0])
    if spec is not None and len(parts) == 2:
        for p in spec.parameters:
            if p.name == parts[1]:
                return f"{effect(parts[0])}: {p.name}, {p.description}", p.units
    return name, ""


def short(name: str) -> str:
    """The parameter's own name without its namespace (``b``, ``rock e_n``)."""
    parts = name.split(".")
    if parts[0] == "materials" and len(parts) == 3:
        return f"{parts[1]} {parts[2]}"
    return parts[-1]


def value_with_se(
    value: float, sd: float | None, *, unit: str = "", digits: int = 4
) -> str:
    """``value ± SE unit``; a missing SE says why (fixed) instead of a dash.

    Examples
    --------
    >>> value_with_se(1.0529, 0.0157)
    '1.053 ± 0.016'
    >>> value_with_se(9.81, None, unit="m/s²")
    '9.81 m/s² (fixed, not fitted)'
    >>> value_with_se(0.3, math.inf)
    '0.3 (standard error undetermined: the data do not constrain it)'
    """
    tail = f" {unit}" if unit and unit != "-" else ""
    text = f"{value:.{digits}g}" if math.isfinite(value) else "not finite"
    if sd is None:
        return f"{text}{tail} (fixed, not fitted)"
    if not math.isfinite(sd):
        return (
            f"{text}{tail} (standard error undetermined: the data do not constrain it)"
        )
    return f"{text} ± {sd:.2g}{tail}"


#: A fitted value this many times an effect parameter's default, when the
#: parameter's neutral value is infinite, leaves the effect practically off.
PRACTICALLY_OFF = 100.0


def remark(name: str, value: float) -> str:
    """Why an effect parameter's value is special: at a bound, or so far towards an
    infinite neutral value that the effect does nothing (empty otherwise)."""
    parts = name.split(".")
    spec = registry.BY_NAME.get(parts[0])
    if spec is None or len(parts) != 2 or not math.isfinite(value):
        return ""
    for p in spec.parameters:
        if p.name != parts[1]:
            continue
        if is_off(name, value):
            return " (practically its neutral value ∞: the effect is off)"
        for bound, side in ((p.lower, "lower"), (p.upper, "upper")):
            if math.isfinite(bound) and abs(value - bound) <= 1e-6 * max(1, abs(bound)):
                return f" (at its {side} bound)"
    return ""


def is_off(name: str, value: float) -> bool:
    """Whether ``value`` of the effect parameter ``name`` lies so far towards an
    infinite neutral value that the effect does nothing (see :func:`remark`)."""
    parts = name.split(".")
    spec = registry.BY_NAME.get(parts[0])
    if spec is None or len(parts) != 2 or not math.isfinite(value):
        return False
    return any(
        p.name == parts[1]
        and p.neutral == math.inf
        and value > PRACTICALLY_OFF * p.default
        for p in spec.parameters
    )


def value_text(name: str, value: float, sd: float | None) -> str:
    """A fitted parameter's value for a reader: ``value ± SE unit``, saying when
    it sits at a bound; a value that switches its effect off says so instead of a
    standard error (the fit ran towards the infinite neutral value, so neither the
    value nor its standard error means anything beyond "off").

    Examples
    --------
    >>> value_text("velocity_scaled_restitution.k_mps", 37.77, 1.91)
    '37.77 ± 1.9 m/s'
    >>> value_text("velocity_scaled_restitution.k_mps", 1.0e5, 1.1e10)
    '1e+05 m/s, practically its neutral value ∞: the effect is off (no standard error)'
    """
    unit = parameter(name)[1]
    if is_off(name, value):
        tail = f" {unit}" if unit and unit != "-" else ""
        return (
            f"{value:.3g}{tail}, practically its neutral value ∞: the effect is off "
            "(no standard error)"
        )
    return value_with_se(value, sd, unit=unit) + remark(name, value)


def parameter_text(name: str, value: float, sd: float | None) -> str:
    """``short name = value ± SE unit`` for one parameter (compact, for tables),
    saying when the value sits at a bound or leaves its effect off.

    Examples
    --------
    >>> parameter_text("velocity_scaled_restitution.k_mps", 37.77, 1.91)
    'k_mps = 37.77 ± 1.9 m/s'
    >>> text = parameter_text("velocity_scaled_restitution.k_mps", 1.0e5, 1.1e10)
    >>> text.split(", ")[0], "±" in text
    ('k_mps = 1e+05 m/s', False)
    >>> parameter_text("gravity_mps2", 9.81, None)
    'gravity_mps2 = 9.81 m/s² (fixed, not fitted)'
    """
    return f"{short(name)} = {value_text(name, value, sd)}"
