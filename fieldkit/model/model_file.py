"""The model file: profile, materials, body, seeder, effects, core settings (JSON).

docs/architecture.md §5 fixes the format. Every problem is one line naming the file
and the field, e.g. ``model.json: materials.talus.e_n: must be >= 0 (got -0.1)``.
Core settings (``"core"``) all have defaults, stated by :data:`CORE_DEFAULTS`:

* ``slide_vn_mps`` = 0.5: a rebound with a normal speed below this starts the
  sliding/rolling phase (a 0.5 m/s hop rises 1.3 cm, well under any block radius:
  below it the lumped mass only chatters);
* ``stop_speed_mps`` = 0.05: a sliding rock slower than this at a concave break stops;
* ``max_impacts`` = 500: rocks reaching it are counted and reported, never silent;
* ``drag_dt_s`` = 0.25: longest flight substep when ``air_drag`` is on (substeps
  are also kept short enough for drag to change the speed by < 0.2 %, see
  :mod:`fieldkit.model.effects.air_drag`).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from fieldkit.errors import FieldkitError, InputFileError
from fieldkit.io.dem import read_dem
from fieldkit.io.profile_csv import read_profile_csv
from fieldkit.model.dem_profile import (
    profile_along_polyline,
    section_from_vertices,
    steepest_descent_line,
)
from fieldkit.model.effects import registry
from fieldkit.model.materials import Material, check_number
from fieldkit.model.profile import Profile
from fieldkit.model.seeder import Seeder
from fieldkit.outputs import OutputSet, write_file

#: Core settings -> (default, lower, upper, unit).
CORE_DEFAULTS: dict[str, tuple[float, float, float, str]] = {
    "slide_vn_mps": (0.5, 0.0, 10.0, "m/s"),
    "stop_speed_mps": (0.05, 0.0, 10.0, "m/s"),
    "max_impacts": (500.0, 1.0, 1e6, "-"),
    "drag_dt_s": (0.25, 1e-4, 5.0, "s"),
}
G_MPS2 = 9.81


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


@dataclass(frozen=True)
class Model:
    """A complete forward model (see the module docstring)."""

    profile: Profile
    materials: dict[str, Material]
    body: Body
    seeder: Seeder
    effects: dict[str, dict[str, float]]
    core: dict[str, float]
    trees: Trees | None = None
    source: str = ""
    provenance: dict = field(default_factory=dict)

    def parameters(self) -> dict[str, float]:
        """Flat namespaced view of the fittable numbers.

        Keys: ``materials.<name>.<field>``, ``<effect>.<param>`` (active effects),
        ``core.<setting>``, ``body.<field>``.
        """
        out: dict[str, float] = {}
        for name, material in self.materials.items():
            for f in fields(material):
                if f.name != "name":
                    out[f"materials.{name}.{f.name}"] = getattr(material, f.name)
        for name, values in self.effects.items():
            for key, value in values.items():
                out[f"{name}.{key}"] = value
        for key, value in self.core.items():
            out[f"core.{key}"] = value
        for f in fields(self.body):
            out[f"body.{f.name}"] = getattr(self.body, f.name)
        return out

    def with_parameters(self, values: dict[str, float]) -> Model:
        """A new Model with some :meth:`parameters` replaced (validated)."""
        data = model_to_dict(self)
        known = self.parameters()
        for key, value in values.items():
            if key not in known:
                raise InputFileError(
                    f"unknown parameter (known: {', '.join(known)})",
                    source="values",
                    where=key,
                )
            parts = key.split(".")
            if parts[0] == "materials":
                data["materials"][parts[1]][parts[2]] = value
            elif parts[0] in ("core", "body"):
                data[parts[0]][parts[1]] = value
            else:
                data["effects"][parts[0]][parts[1]] = value
        model = model_from_dict(data, source=self.source)
        return replace(model, provenance=dict(self.provenance))


def _object(data: object, where: str, source: str) -> dict:
    if not isinstance(data, dict):
        raise InputFileError("must be an object", source=source, where=where)
    return data


def _unknown(data: dict, known: set[str], where: str, source: str) -> None:
    for key in data:
        if key not in known:
            raise InputFileError(
                f"unknown field (known: {', '.join(sorted(known))})",
                source=source,
                where=f"{where}.{key}" if where else key,
            )


def model_from_dict(
    data: dict, *, source: str = "", base_dir: str | os.PathLike[str] | None = None
) -> Model:
    """Validate a parsed model file; one-line errors naming ``source`` and the field.

    ``base_dir`` is where relative file names in the model file (a profile CSV or
    DEM) are looked up: the model file's folder (None: the working directory).
    """
    data = _object(data, "model", source)
    _unknown(
        data,
        {
            "profile",
            "materials",
            "body",
            "seeder",
            "effects",
            "core",
            "trees",
            "provenance",
        },
        "",
        source,
    )
    for key in ("profile", "materials", "body", "seeder"):
        if key not in data:
            raise InputFileError("missing", source=source, where=key)
    profile = _profile(
        _object(data["profile"], "profile", source), source, base_dir=base_dir
    )
    mats = _object(data["materials"], "materials", source)
    materials = {
        name: Material.from_dict(name, value, source=source)
        for name, value in mats.items()
    }
    for j, name in enumerate(profile.material):
        if name not in materials:
            raise InputFileError(
                f"segment {j} names material {name!r}, not defined in materials "
                f"(defined: {', '.join(materials) or 'none'})",
                source=source,
                where="profile.material",
            )
    body_data = _object(data["body"], "body", source)
    _unknown(body_data, {"mass_kg", "radius_m", "gyration_m"}, "body", source)
    body_values = {}
    for key in ("mass_kg", "radius_m"):
        if key not in body_data:
            raise InputFileError("missing", source=source, where=f"body.{key}")
        body_values[key] = check_number(
            body_data[key], 1e-9, math.inf, source=source, where=f"body.{key}"
        )
    # Solid sphere k = sqrt(2/5) r when not given (stated here: eq. of bodies.py).
    gyration = body_data.get("gyration_m", math.sqrt(0.4) * body_values["radius_m"])
    body_values["gyration_m"] = check_number(
        gyration, 1e-9, math.inf, source=source, where="body.gyration_m"
    )
    body = Body(**body_values)
    seeder = _seeder(_object(data["seeder"], "seeder", source), profile, source)
    effects_data = _object(data.get("effects", {}), "effects", source)
    effects: dict[str, dict[str, float]] = {}
    for name, values in effects_data.items():
        if name not in registry.BY_NAME:
            raise InputFileError(
                f"unknown effect (known: {', '.join(registry.BY_NAME)})",
                source=source,
                where=f"effects.{name}",
            )
        values = _object(values, f"effects.{name}", source)
        try:
            effects[name] = registry.validate(name, values, source=source)
        except FieldkitError as exc:
            raise InputFileError(exc.message, source=source, where=exc.where) from None
    core_data = _object(data.get("core", {}), "core", source)
    _unknown(core_data, set(CORE_DEFAULTS), "core", source)
    core = {}
    for key, (default, lower, upper, unit) in CORE_DEFAULTS.items():
        core[key] = check_number(
            core_data.get(key, default),
            lower,
            upper,
            source=source,
            where=f"core.{key}",
            unit=unit,
        )
    trees = None
    if "trees" in data:
        trees = _trees(_object(data["trees"], "trees", source), profile, source)
    if "tree_impacts" in effects and trees is None:
        raise InputFileError(
            "tree_impacts is on but the model has no trees",
            source=source,
            where="trees",
        )
    provenance = data.get("provenance", {})
    return Model(
        profile=profile,
        materials=materials,
        body=body,
        seeder=seeder,
        effects=effects,
        core=core,
        trees=trees,
        source=source,
        provenance=dict(provenance) if isinstance(provenance, dict) else {},
    )


def _profile(prof: dict, source: str, *, base_dir) -> Profile:
    """The slope profile from where a user has it (docs/architecture.md §5).

    * vertex lists: ``{"x_m": [...], "z_m": [...], "material": [...]}``;
    * a CSV of vertices: ``{"csv": "profile.csv", "units": "ft"}`` (units as in
      :func:`fieldkit.io.profile_csv.read_profile_csv`);
    * a section cut from a DEM (ESRI ASCII grid or GeoTIFF): ``{"dem":
      "terrain.asc", "from": [x, y]}`` follows the steepest descent from a release
      point, ``{"dem": ..., "line": [[x, y], ...]}`` a polyline; optional
      ``"step_m"`` (default half a cell) and ``"max_length_m"``.

    A CSV or DEM profile takes its segment materials from ``"materials":
    "0-40:rock,40-:talus"`` (chainage ranges), else from the CSV's material column.
    """
    base = Path(base_dir) if base_dir is not None else Path()
    if "csv" in prof or "dem" in prof:
        kind = "csv" if "csv" in prof else "dem"
        allowed = (
            {"csv", "units", "materials"}
            if kind == "csv"
            else {"dem", "from", "line", "step_m", "max_length_m", "materials"}
        )
        _unknown(prof, allowed, "profile", source)
        path = base / str(prof[kind])
        if kind == "csv":
            vertices = read_profile_csv(path, units=prof.get("units"))
            section = section_from_vertices(
                vertices.x_m, vertices.z_m, vertices.material, source=str(path)
            )
        else:
            section = _dem_section(prof, path, source)
        if "materials" in prof:
            section = section.with_materials(str(prof["materials"]))
        return Profile.from_arrays(
            section.chainage_m, section.z_m, section.material, source=source
        )
    _unknown(prof, {"x_m", "z_m", "material"}, "profile", source)
    for key in ("x_m", "z_m", "material"):
        if key not in prof:
            raise InputFileError("missing", source=source, where=f"profile.{key}")
    return Profile.from_arrays(
        prof["x_m"], prof["z_m"], prof["material"], source=source
    )


def _dem_section(prof: dict, path: Path, source: str):
    """The section of a ``"dem"`` profile entry (steepest descent or polyline)."""
    grid = read_dem(path)
    step = prof.get("step_m")
    step = 0.5 * grid.cellsize_m if step is None else float(step)
    if ("from" in prof) == ("line" in prof):
        raise InputFileError(
            "give either `from` [x, y] (steepest descent) or `line` [[x, y], ...]",
            source=source,
            where="profile.dem",
        )
    if "line" in prof:
        return profile_along_polyline(grid, prof["line"], step)
    return steepest_descent_line(
        grid, prof["from"], step, max_length_m=prof.get("max_length_m")
    )


def _seeder(data: dict, profile: Profile, source: str) -> Seeder:
    names = {f.name for f in fields(Seeder)}
    _unknown(data, names, "seeder", source)
    line = data.get("x_max_m") is not None
    required = ("x_m", "height_m") if line else ("x_m", "z_m")
    for key in required:
        if data.get(key) is None:
            raise InputFileError(
                "missing"
                + (" (a release line needs a height above the ground)" if line else ""),
                source=source,
                where=f"seeder.{key}",
            )
    values: dict[str, float | None] = {}
    for key in names:
        if data.get(key) is None:
            continue
        lower = 0.0 if key.endswith("_sd_m") or "_sd_" in key else -math.inf
        if key == "height_m":
            lower = 0.0
        values[key] = check_number(
            data[key], lower, math.inf, source=source, where=f"seeder.{key}"
        )
    if "z_m" not in values:
        values["z_m"] = math.nan
    seeder = Seeder(**values)
    x0, x1 = profile.x_m[0], profile.x_m[-1]
    ends = [seeder.x_m] + ([seeder.x_max_m] if line else [])
    for key, x in zip(("x_m", "x_max_m"), ends, strict=False):
        if not x0 <= x <= x1:
            raise InputFileError(
                f"must lie on the profile [{x0:g}, {x1:g}] m (got {x:g})",
                source=source,
                where=f"seeder.{key}",
            )
    if line and seeder.x_max_m < seeder.x_m:
        raise InputFileError(
            f"must be >= seeder.x_m ({seeder.x_m:g})",
            source=source,
            where="seeder.x_max_m",
        )
    if not line:
        ground = float(profile.ground_z(seeder.x_m))
        if seeder.z_m < ground:
            raise InputFileError(
                f"start is below the ground ({seeder.z_m:g} m < {ground:g} m at "
                f"x = {seeder.x_m:g} m)",
                source=source,
                where="seeder.z_m",
            )
    return seeder


def _trees(data: dict, profile: Profile, source: str) -> Trees:
    _unknown(data, {"x_m", "diameter_m", "height_m"}, "trees", source)
    arrays = {}
    for key in ("x_m", "diameter_m", "height_m"):
        if key not in data:
            raise InputFileError("missing", source=source, where=f"trees.{key}")
        try:
            arrays[key] = np.asarray(data[key], float).reshape(-1)
        except (TypeError, ValueError):
            raise InputFileError(
                "must be a list of numbers", source=source, where=f"trees.{key}"
            ) from None
        if not np.all(np.isfinite(arrays[key])):
            raise InputFileError("not all finite", source=source, where=f"trees.{key}")
    n = arrays["x_m"].size
    for key in ("diameter_m", "height_m"):
        if arrays[key].size != n:
            raise InputFileError(
                f"has {arrays[key].size} values, trees.x_m has {n}",
                source=source,
                where=f"trees.{key}",
            )
        if np.any(arrays[key] <= 0):
            raise InputFileError("must be > 0", source=source, where=f"trees.{key}")
    order = np.argsort(arrays["x_m"], kind="stable")
    return Trees(**{k: v[order] for k, v in arrays.items()})


def read_model(path: str | os.PathLike[str]) -> Model:
    """Read and validate a JSON model file (one-line errors naming the file)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise InputFileError(f"cannot read ({exc.strerror})", source=path) from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputFileError(
            f"not valid JSON ({exc.msg})", source=path, where=f"line {exc.lineno}"
        ) from None
    return model_from_dict(data, source=str(path), base_dir=path.parent)


def model_to_dict(model: Model) -> dict:
    """The model as a JSON-ready dict (inverse of :func:`model_from_dict`)."""
    seeder = {
        f.name: getattr(model.seeder, f.name)
        for f in fields(model.seeder)
        if getattr(model.seeder, f.name) is not None
        and not (f.name == "z_m" and math.isnan(model.seeder.z_m))
    }
    data = {
        "profile": {
            "x_m": model.profile.x_m.tolist(),
            "z_m": model.profile.z_m.tolist(),
            "material": list(model.profile.material),
        },
        "materials": {
            name: {f.name: getattr(m, f.name) for f in fields(m) if f.name != "name"}
            for name, m in model.materials.items()
        },
        "body": {f.name: getattr(model.body, f.name) for f in fields(model.body)},
        "seeder": seeder,
        "effects": {name: dict(values) for name, values in model.effects.items()},
        "core": dict(model.core),
    }
    if model.trees is not None:
        data["trees"] = {
            "x_m": model.trees.x_m.tolist(),
            "diameter_m": model.trees.diameter_m.tolist(),
            "height_m": model.trees.height_m.tolist(),
        }
    if model.provenance:
        data["provenance"] = model.provenance
    return data


def write_model(
    model: Model, path: str | os.PathLike[str], *, outputs: OutputSet | None = None
) -> None:
    """Write ``model`` as JSON (through ``outputs`` when given)."""
    text = json.dumps(model_to_dict(model), indent=1) + "\n"

    def writer(tmp: Path) -> None:
        tmp.write_text(text, encoding="utf-8")

    write_file(path, writer, outputs)
