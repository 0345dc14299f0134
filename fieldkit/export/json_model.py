"""The ``json`` target: the calibrated model itself, with uncertainties and provenance.

``model.json`` is a fieldkit model file (:func:`fieldkit.model.model_file.
read_model` reads it back unchanged, provenance included); ``parameters.json`` lists
every parameter of the model with, where a fit gave one, its standard error and
which fit (``fit``: the impacts; ``fit_paths``: observed runs or a surveyed path) --
the table a report or another tool reads without knowing fieldkit's model format.
"""

from __future__ import annotations

import math

from fieldkit.export.fitted import fitted_parameters, with_error
from fieldkit.export.lumped import effects_account
from fieldkit.export.result import Export, Mapped
from fieldkit.export.site import ExportSite
from fieldkit.model.effects import registry
from fieldkit.model.model_file import Model, model_to_dict
from fieldkit.outputs import json_text


def export_json(model: Model, site: ExportSite | None = None) -> Export:
    """The model file and its parameter table (module docstring); ``site`` unused.

    Examples
    --------
    >>> import json
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 10], "z_m": [5, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 6}})
    >>> e = export_json(m)
    >>> sorted(e.files), json.loads(e.files["parameters.json"])[0]["name"]
    (['model.json', 'parameters.json'], 'materials.rock.e_n')
    """
    fitted = fitted_parameters(model)
    rows = []
    mapped = []
    for name, value in model.parameters().items():
        fit = fitted.get(name)
        se = fit.stderr if fit is not None else math.nan
        rows.append(
            {
                "name": name,
                "value": value,
                "stderr": se if math.isfinite(se) else None,
                "fit": fit.fit if fit is not None else None,
            }
        )
        if fit is not None:
            mapped.append(
                Mapped(with_error(model, name, value), f"parameters.json: {name}")
            )
    n_fitted = sum(r["fit"] is not None for r in rows)
    # the model file carries every effect of the registry, on or off
    rules = {
        spec.name: (True, "model.json's effects (with its parameters when on)")
        for spec in registry.EFFECTS
    }
    return Export(
        target="json",
        title="fieldkit model (JSON)",
        files={
            "model.json": json_text(model_to_dict(model), indent=1),
            "parameters.json": json_text(rows, indent=1),
        },
        mapped=mapped,
        notes=[
            f"{len(rows)} parameters, {n_fitted} with a fitted value "
            "(their standard errors in parameters.json); the fits' full records "
            "(correlations, bootstrap, held-out scores) are in model.json's "
            "provenance",
            "every other parameter is the base model's value, not fitted",
            *effects_account(model, "json", rules),
        ],
        sources=[
            "fieldkit's model file: docs/architecture.md 'Model file (contract)', "
            "read by fieldkit.model.model_file.read_model",
        ],
        unconfirmed=[
            "nothing: model.json is fieldkit's own format, read back unchanged"
        ],
        how_to_use=(
            "`fieldkit simulate model.json`, `fieldkit fit ... --model model.json`: "
            "model.json is a fieldkit model file. parameters.json is a list of "
            "`{name, value, stderr, fit}`."
        ),
    )
