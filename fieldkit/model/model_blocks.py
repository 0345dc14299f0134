"""Blocks shared by the 2-D and the 3-D model file: body, effects, core settings.

:mod:`fieldkit.model.model_file` (a ``profile``) and
:mod:`fieldkit.model.terrain_file` (a ``terrain``) read these blocks the same way;
their bounds and defaults are documented in :mod:`fieldkit.model.model_file`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fieldkit.errors import ArgumentError, FieldkitError, InputFileError
from fieldkit.model.effects import registry
from fieldkit.model.materials import check_number

#: Core settings -> (default, lower, upper, unit).
CORE_DEFAULTS: dict[str, tuple[float, float, float, str]] = {
    "slide_vn_mps": (0.5, 0.0, 10.0, "m/s"),
    "stop_speed_mps": (0.05, 0.0, 10.0, "m/s"),
    "max_impacts": (500.0, 1.0, 1e6, "-"),
    "drag_dt_s": (0.25, 1e-4, 5.0, "s"),
}
#: Core settings that count something: whole numbers only (500, not 500.5).
WHOLE_NUMBER_CORE = frozenset({"max_impacts"})
G_MPS2 = 9.81
#: Body fields -> (lower, upper) [SI]; the lower bound is exclusive (module docstring).
BODY_BOUNDS: dict[str, tuple[float, float]] = {
    "mass_kg": (0.0, 1e9),
    "radius_m": (0.0, 50.0),
    "gyration_m": (0.0, 50.0),
}
#: Largest |speed| [m/s], |spin| [rad/s] and height above the ground [m] of a start.
SEEDER_BOUNDS: dict[str, float] = {"mps": 100.0, "radps": 500.0, "m": 1000.0}
#: Largest tree trunk diameter and height [m].
TREE_BOUNDS: dict[str, float] = {"diameter_m": 5.0, "height_m": 150.0}


@dataclass(frozen=True)
class Body:
    """The rock: mass [kg], contact radius [m], radius of gyration [m]."""

    mass_kg: float
    radius_m: float
    gyration_m: float


@dataclass(frozen=True)
class Trees:
    """Trees along the profile: position [m], trunk diameter [m], height [m]."""

    x_m: np.ndarray
    diameter_m: np.ndarray
    height_m: np.ndarray


def object_field(data: object, where: str, source: str) -> dict:
    """``data`` as an object (a JSON ``{...}``); a one-line error naming ``where``."""
    if not isinstance(data, dict):
        raise InputFileError("must be an object", source=source, where=where)
    return data


def refuse_unknown(data: dict, known: set[str], where: str, source: str) -> None:
    for key in data:
        if key not in known:
            raise InputFileError(
                f"unknown field (known: {', '.join(sorted(known))})",
                source=source,
                where=f"{where}.{key}" if where else key,
            )


def number_lists(
    data: dict, keys: tuple[str, ...], where: str, source: str
) -> dict[str, np.ndarray]:
    """Each of ``keys`` of ``data`` as a finite 1-D float array (a block of lists of
    numbers, e.g. ``trees``); one-line errors at ``<where>.<key>``."""
    arrays = {}
    for key in keys:
        if key not in data:
            raise InputFileError("missing", source=source, where=f"{where}.{key}")
        try:
            if isinstance(data[key], str):
                raise TypeError(key)
            arrays[key] = np.asarray(data[key], float).reshape(-1)
        except (TypeError, ValueError, OverflowError):
            raise InputFileError(
                "must be a list of numbers", source=source, where=f"{where}.{key}"
            ) from None
        if not np.all(np.isfinite(arrays[key])):
            raise InputFileError(
                "not all finite", source=source, where=f"{where}.{key}"
            )
    return arrays


def read_effects(data: dict, source: str) -> dict[str, dict[str, float]]:
    """The model file's ``"effects"`` block, each effect validated by its registry
    entry (one-line errors naming ``effects.<name>``); 2-D and 3-D models alike."""
    effects_data = object_field(data.get("effects", {}), "effects", source)
    effects: dict[str, dict[str, float]] = {}
    for name, values in effects_data.items():
        if name not in registry.BY_NAME:
            raise InputFileError(
                f"unknown effect (known: {', '.join(registry.BY_NAME)})",
                source=source,
                where=f"effects.{name}",
            )
        values = object_field(values, f"effects.{name}", source)
        try:
            effects[name] = registry.validate(name, values, source=source)
        except FieldkitError as exc:
            raise InputFileError(exc.message, source=source, where=exc.where) from None
    return effects


def read_core(data: dict, source: str) -> dict[str, float]:
    """The model file's ``"core"`` block, every setting bounded and defaulted
    (:data:`CORE_DEFAULTS`); 2-D and 3-D models alike."""
    core_data = object_field(data.get("core", {}), "core", source)
    refuse_unknown(core_data, set(CORE_DEFAULTS), "core", source)
    core = {}
    for key, (default, lower, upper, unit) in CORE_DEFAULTS.items():
        core[key] = check_number(
            core_data.get(key, default),
            lower,
            upper,
            source=source,
            where=f"core.{key}",
            unit=unit,
            whole=key in WHOLE_NUMBER_CORE,
        )
    return core


def read_body(data: dict, source: str) -> Body:
    """The body, bounded (:data:`BODY_BOUNDS`) and checked as
    :class:`fieldkit.physics.bodies.Body` checks a body (k <= r).

    The radius of gyration is ``gyration_m`` when given; else, from the block's
    three principal lengths ``dimensions_m`` when given (the solid ellipsoid of
    those axes rolling about the shortest,
    :func:`fieldkit.physics.bodies.principal_gyration_m`; ``radius_m`` stays the
    contact radius); else the solid sphere's ``sqrt(2/5) radius_m``.
    """
    from fieldkit.physics.bodies import Body as PhysicalBody
    from fieldkit.physics.bodies import principal_gyration_m

    refuse_unknown(data, {*BODY_BOUNDS, "dimensions_m"}, "body", source)
    values = {}
    for key in ("mass_kg", "radius_m"):
        if key not in data:
            raise InputFileError("missing", source=source, where=f"body.{key}")
    given = {"gyration_m": None, **data}
    gyration_from = None
    if data.get("dimensions_m") is not None:
        if data.get("gyration_m") is not None:
            raise InputFileError(
                "give body.gyration_m or body.dimensions_m (which gives k), not both",
                source=source,
                where="body.dimensions_m",
            )
        lengths = data["dimensions_m"]
        if not isinstance(lengths, list) or len(lengths) != 3:
            raise InputFileError(
                "must be the block's 3 principal lengths [m], e.g. [0.5, 0.3, 0.39]",
                source=source,
                where="body.dimensions_m",
            )
        gyration_from = [
            check_number(
                v,
                0.0,
                BODY_BOUNDS["radius_m"][1] * 2,
                source=source,
                where=f"body.dimensions_m[{i}]",
                unit="m",
            )  # fmt: skip
            for i, v in enumerate(lengths)
        ]
        for i, v in enumerate(gyration_from):
            if v <= 0:
                raise InputFileError(
                    f"must be > 0 (got {v:g})",
                    source=source,
                    where=f"body.dimensions_m[{i}]",
                )
    for key, (lower, upper) in BODY_BOUNDS.items():
        value = given[key]
        if value is None and key == "gyration_m":
            if gyration_from is not None:
                value = principal_gyration_m(gyration_from)
            else:  # solid sphere k = sqrt(2/5) r (physics.bodies, Table 4-1)
                value = math.sqrt(0.4) * values["radius_m"]
        values[key] = check_number(
            value, lower, upper, source=source, where=f"body.{key}",
            unit="kg" if key == "mass_kg" else "m",
        )  # fmt: skip
        if values[key] <= lower:
            raise InputFileError(
                f"must be > {lower:g} (got {values[key]:g})",
                source=source,
                where=f"body.{key}",
            )
    try:  # an elongated block may have k > r, as the shapes of Table 4-1 may
        PhysicalBody(**values, shape="block" if gyration_from is not None else None)
    except ArgumentError as exc:
        raise InputFileError(
            exc.message, source=source, where=f"body.{exc.source}"
        ) from None
    return Body(**values)
