"""The fitted values and standard errors a calibrated model file carries.

``fieldkit fit`` (impacts) writes ``provenance.fit.parameters`` as ``{name: {value,
stderr}}``; the path fit writes ``provenance.fit_paths.parameters`` as a list of
``{name, value, stderr, interval90}``. Exports state a calibrated value with its
uncertainty where the model has one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fieldkit.model.model_file import Model


@dataclass(frozen=True)
class Fitted:
    """A fitted parameter: value, standard error (NaN: none) and which fit."""

    value: float
    stderr: float
    fit: str


def fitted_parameters(model: Model) -> dict[str, Fitted]:
    """Namespaced parameter -> :class:`Fitted`, from the model's provenance (the
    path fit's entry wins where both fitted a parameter: it is the later stage).

    Examples
    --------
    >>> from dataclasses import replace
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 10], "z_m": [5, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 6}})
    >>> m = replace(m, provenance={"fit": {"parameters": {"materials.rock.e_n":
    ...     {"value": 0.3, "stderr": 0.02}}}})
    >>> fitted_parameters(m)["materials.rock.e_n"]
    Fitted(value=0.3, stderr=0.02, fit='fit')
    """
    out: dict[str, Fitted] = {}
    fit = model.provenance.get("fit") if isinstance(model.provenance, dict) else None
    if isinstance(fit, dict) and isinstance(fit.get("parameters"), dict):
        for name, p in fit["parameters"].items():
            if isinstance(p, dict) and "value" in p:
                out[name] = Fitted(float(p["value"]), _number(p.get("stderr")), "fit")
    paths = (
        model.provenance.get("fit_paths")
        if isinstance(model.provenance, dict)
        else None
    )
    if isinstance(paths, dict) and isinstance(paths.get("parameters"), list):
        for p in paths["parameters"]:
            if isinstance(p, dict) and "name" in p and "value" in p:
                out[str(p["name"])] = Fitted(
                    float(p["value"]), _number(p.get("stderr")), "fit_paths"
                )
    return out


def _number(value: object) -> float:
    try:
        out = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return math.nan
    return out


def with_error(model: Model, name: str, value: float, unit: str = "") -> str:
    """``"name = value ± se unit"`` (or without ± when not fitted), for a README.

    A value an export wrote in place of the calibrated one (the provenance entry
    ``lumped`` of :func:`fieldkit.export.lumped.with_coefficients`) is shown with
    its own spread over the impacts it was fitted to, and the calibrated value
    beside it -- never with the calibrated parameter's standard error.

    Examples
    --------
    >>> from dataclasses import replace
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 10], "z_m": [5, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 6}})
    >>> m = replace(m, provenance={"fit": {"parameters": {"materials.rock.e_n":
    ...     {"value": 1.2, "stderr": 0.02}}}, "lumped": {"materials.rock.e_n":
    ...     {"value": 0.3, "spread": 0.11, "impacts": 50, "calibrated": 1.2}}})
    >>> for part in with_error(m, "materials.rock.e_n", 0.3).split("; "):
    ...     print(part)
    materials.rock.e_n = 0.3 written (spread 0.11 over 50 impacts)
    calibrated 1.2 ± 0.02 (fit)
    """
    unit = f" {unit}" if unit else ""
    lumped = (
        model.provenance.get("lumped") if isinstance(model.provenance, dict) else None
    )
    if isinstance(lumped, dict) and isinstance(lumped.get(name), dict):
        entry = lumped[name]
        spread = _number(entry.get("spread"))
        own = (
            f"spread {spread:.2g} over {int(entry.get('impacts') or 0)} impacts"
            if math.isfinite(spread)
            else str(entry.get("unfitted") or "not fitted to impacts")
        )
        calibrated = f"{_number(entry.get('calibrated')):.4g}"
        fitted = fitted_parameters(model).get(name)
        if fitted is not None and math.isfinite(fitted.stderr):
            calibrated += f" ± {fitted.stderr:.2g}{unit} ({fitted.fit})"
        else:
            calibrated += unit
        return f"{name} = {value:.4g}{unit} written ({own}); calibrated {calibrated}"
    fitted = fitted_parameters(model).get(name)
    if fitted is not None and math.isfinite(fitted.stderr):
        return f"{name} = {value:.4g} ± {fitted.stderr:.2g}{unit} ({fitted.fit})"
    return f"{name} = {value:.4g}{unit}"
