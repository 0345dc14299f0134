"""The model file: profile, materials, body, seeder, effects, core settings (JSON).

docs/architecture.md §5 fixes the format. Every problem is one line naming the file
and the field, e.g. ``model.json: materials.talus.e_n: must be >= 0 (got -0.1)``.
Core settings (``"core"``) all have defaults, stated by :data:`CORE_DEFAULTS`:

* ``slide_vn_mps`` = 0.5: a rebound with a normal speed below this starts the
  sliding/rolling phase (a 0.5 m/s hop rises 1.3 cm, well under any block radius:
  below it the lumped mass only chatters);
* ``stop_speed_mps`` = 0.05: a sliding rock slower than this at a concave break stops;
* ``max_impacts`` = 500, a whole number in [1, 1e6]: rocks reaching it are counted
  and reported, never silent;
* ``drag_dt_s`` = 0.25: longest flight substep when ``air_drag`` is on (substeps
  are also kept short enough for drag to change the speed by < 0.2 %, see
  :mod:`fieldkit.model.effects.air_drag`).

Every number must be finite (JSON's ``NaN`` and ``Infinity`` are refused) and lie
within a physical bound; the bounds are wide enough for any rockfall and narrow
enough to catch a typing or unit error:

* body (:data:`BODY_BOUNDS`): mass in (0, 1e9] kg and contact radius in (0, 50] m
  -- the largest single blocks of rockfall inventories are ~1e5 m3 (~3e8 kg, a
  sphere of r = 29 m); beyond that it is a rock avalanche, which a lumped-mass
  model does not describe; the gyration k must be <= r
  (:class:`fieldkit.physics.bodies.Body`: every mass point lies within r of the
  centre, a thin hoop is the limit k = r). k is ``gyration_m`` when given, else
  from the block's three principal lengths ``dimensions_m`` (the solid ellipsoid of
  those axes rolling about the shortest,
  :func:`fieldkit.physics.bodies.principal_gyration_m`; then k may exceed r), else
  the solid sphere's ``sqrt(2/5) radius_m``;
* seeder (:data:`SEEDER_BOUNDS`): speeds |v| <= 100 m/s (a free fall of 500 m) and
  spin |omega| <= 500 rad/s (a 0.2 m block rolling at 100 m/s), SDs as large; the
  start at most 1000 m above the ground; a release height <= 1000 m;
* trees: trunk diameter in (0, 5] m, height in (0, 150] m (the tallest trees are
  ~115 m);
* materials: see :mod:`fieldkit.model.materials` (also for the material names);
* effects: each parameter's own bounds (``fieldkit effects NAME``).

The profile's x must increase strictly, so every segment dips between -90 and 90
degrees (inside the contract's (-180, 180] degrees); vertex lists get the bounds of a
profile CSV (chainage within 100 km, elevation within 11 km, vertices at least 1 mm
apart: :func:`fieldkit.io.profile_csv.check_profile_vertices`, named as
``profile.z_m[5]``). A key given twice in one object is refused, naming its path
(``materials.rock.e_n given twice``): JSON readers otherwise keep the last silently.

Files a model reads
-------------------
A model whose profile comes from a CSV or a DEM reads those files too.
:attr:`Model.source_files` lists every file read (the model file first);
``read_model(path, outputs=outputs)`` adds them to a command's
:class:`~fieldkit.outputs.OutputSet` inputs, so no output of the command can
replace them.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.csv_table import parse_json
from fieldkit.io.dem import read_dem
from fieldkit.io.profile_csv import read_profile_csv
from fieldkit.model.dem_profile import (
    profile_along_polyline,
    section_from_vertices,
    steepest_descent_line,
)
from fieldkit.model.materials import Material, check_number
from fieldkit.model.model_blocks import (  # noqa: F401 (the model file's names)
    BODY_BOUNDS,
    CORE_DEFAULTS,
    G_MPS2,
    SEEDER_BOUNDS,
    TREE_BOUNDS,
    WHOLE_NUMBER_CORE,
    Body,
    Trees,
    number_lists,
    read_body,
    read_core,
    read_effects,
)
from fieldkit.model.model_blocks import object_field as _object
from fieldkit.model.model_blocks import read_body as _body
from fieldkit.model.model_blocks import refuse_unknown as _unknown
from fieldkit.model.profile import Profile
from fieldkit.model.seeder import Seeder
from fieldkit.outputs import OutputSet, json_text, write_file

#: JSON nesting deeper than this is refused (a model file is 4 levels deep).
MAX_JSON_DEPTH = 64


@dataclass(frozen=True)
class AnalysisLocation:
    """A point of the section where the designer reads the design quantities (a
    barrier, a road, a building): ``x_m`` along the section [m] and its ``name``
    (empty when not given)."""

    x_m: float
    name: str = ""


#: Most analysis points a model file may name (as ``fieldkit simulate --at``).
MAX_ANALYSIS_LOCATIONS = 100


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
    #: Every file read to build the model: the model file (when read from one),
    #: then its profile CSV or DEM (module docstring, "Files a model reads").
    source_files: tuple[str, ...] = ()
    #: Where the design quantities are read by default (``"analysis_points"``).
    analysis_points: tuple[AnalysisLocation, ...] = ()

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
        return replace(
            model, provenance=dict(self.provenance), source_files=self.source_files
        )


def model_from_dict(
    data: dict, *, source: str = "", base_dir: str | os.PathLike[str] | None = None
) -> Model:
    """Validate a parsed model file; one-line errors naming ``source`` and the field.

    A file with a ``terrain`` block (a DEM) instead of a ``profile`` is a 3-D
    model: a :class:`fieldkit.model.model3d.Model3D` is returned
    (:func:`fieldkit.model.terrain_file.model3d_from_dict`).

    ``base_dir`` is where relative file names in the model file (a profile CSV or
    DEM) are looked up: the model file's folder (None: the working directory).
    """
    data = _object(data, "model", source)
    if "terrain" in data:  # one model-file format: a DEM instead of a profile
        from fieldkit.model.terrain_file import model3d_from_dict

        return model3d_from_dict(data, source=source, base_dir=base_dir)
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
            "analysis_points",
        },
        "",
        source,
    )
    for key in ("profile", "materials", "body", "seeder"):
        if key not in data:
            raise InputFileError("missing", source=source, where=key)
    read: list[str] = []
    profile = _profile(
        _object(data["profile"], "profile", source), source, base_dir=base_dir,
        read=read,
    )  # fmt: skip
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
    body = _body(_object(data["body"], "body", source), source)
    seeder = _seeder(_object(data["seeder"], "seeder", source), profile, source)
    effects = read_effects(data, source)
    core = read_core(data, source)
    trees = None
    if "trees" in data:
        trees = _trees(_object(data["trees"], "trees", source), profile, source)
    if "tree_impacts" in effects and trees is None:
        raise InputFileError(
            "tree_impacts is on but the model has no trees",
            source=source,
            where="trees",
        )
    analysis_points = _analysis_points(data.get("analysis_points", []), profile,
                                       source)  # fmt: skip
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
        source_files=tuple(read),
        analysis_points=analysis_points,
    )


def _analysis_points(
    data: object, profile: Profile, source: str
) -> tuple[AnalysisLocation, ...]:
    """The optional ``"analysis_points"`` block: ``[{"x_m": 610.0, "name":
    "railway bench"}, ...]``, each x on the profile and given once, the name
    optional text; one-line errors naming ``analysis_points[i].field``."""
    if not isinstance(data, list):
        raise InputFileError(
            'must be a list of {"x_m": ..., "name": ...} objects',
            source=source,
            where="analysis_points",
        )
    if len(data) > MAX_ANALYSIS_LOCATIONS:
        raise InputFileError(
            f"at most {MAX_ANALYSIS_LOCATIONS} points (got {len(data)})",
            source=source,
            where="analysis_points",
        )
    x0, x1 = float(profile.x_m[0]), float(profile.x_m[-1])
    out: list[AnalysisLocation] = []
    for i, item in enumerate(data):
        where = f"analysis_points[{i}]"
        item = _object(item, where, source)
        _unknown(item, {"x_m", "name"}, where, source)
        if "x_m" not in item:
            raise InputFileError("missing", source=source, where=f"{where}.x_m")
        x = check_number(item["x_m"], x0, x1, source=source, where=f"{where}.x_m",
                         unit="m")  # fmt: skip
        name = item.get("name", "")
        if not isinstance(name, str):
            raise InputFileError(
                f"must be text (got {name!r})"[:80], source=source,
                where=f"{where}.name",
            )  # fmt: skip
        twice = [j for j, p in enumerate(out) if p.x_m == x]
        if twice:
            raise InputFileError(
                f"x_m = {x:g} m is given twice (also analysis_points[{twice[0]}])",
                source=source,
                where=f"{where}.x_m",
            )
        out.append(AnalysisLocation(x_m=x, name=name.strip()))
    return tuple(out)


#: Arguments of the section readers -> the profile field that gives them.
_PROFILE_FIELDS = {
    "ranges": "materials",
    "units": "units",
    "vertices_xy": "line",
    "start_xy": "from",
    "spacing_m": "step_m",
    "step_m": "step_m",
    "max_length_m": "max_length_m",
}


def _text(prof: dict, key: str, source: str) -> str:
    """A text field of a profile entry (a file name, units, ranges)."""
    value = prof[key]
    if not isinstance(value, str) or not value.strip():
        raise InputFileError(
            f"must be text (got {value!r})"[:80], source=source, where=f"profile.{key}"
        )
    return value


def _profile(prof: dict, source: str, *, base_dir, read: list[str]) -> Profile:
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
        path = base / _text(prof, kind, source)
        units = _text(prof, "units", source) if prof.get("units") is not None else None
        ranges = _text(prof, "materials", source) if "materials" in prof else None
        read.append(str(path))
        if kind == "dem" and path.with_suffix(".prj").is_file():
            read.append(str(path.with_suffix(".prj")))  # its CRS (fieldkit.io.dem)
        try:
            if kind == "csv":
                vertices = read_profile_csv(path, units=units)
                section = section_from_vertices(
                    vertices.x_m, vertices.z_m, vertices.material, source=str(path)
                )
            else:
                section = _dem_section(prof, path, source)
            if ranges is not None:
                section = section.with_materials(ranges)
        except ArgumentError as exc:  # names an argument: here a field of profile
            if exc.source not in _PROFILE_FIELDS:
                raise
            raise InputFileError(
                exc.message,
                source=source,
                where=f"profile.{_PROFILE_FIELDS[exc.source]}",
            ) from None
        return Profile.from_arrays(
            section.chainage_m, section.z_m, section.material, source=source,
            where=lambda axis, i: f"profile.{kind}: section vertex {i} ({axis})",
        )  # fmt: skip
    _unknown(prof, {"x_m", "z_m", "material"}, "profile", source)
    for key in ("x_m", "z_m", "material"):
        if key not in prof:
            raise InputFileError("missing", source=source, where=f"profile.{key}")
    return Profile.from_arrays(
        prof["x_m"], prof["z_m"], prof["material"], source=source
    )


def _dem_section(prof: dict, path: Path, source: str):
    """The section of a ``"dem"`` profile entry (steepest descent or polyline)."""
    if ("from" in prof) == ("line" in prof):
        raise InputFileError(
            "give either `from` [x, y] (steepest descent) or `line` [[x, y], ...]",
            source=source,
            where="profile.dem",
        )
    for key in ("step_m", "max_length_m"):
        if prof.get(key) is not None:
            check_number(prof[key], 0.0, 1e6, source=source, where=f"profile.{key}",
                         unit="m")  # fmt: skip
    points = _plan_points(prof, "line" if "line" in prof else "from", source)
    grid = read_dem(path)
    step = prof.get("step_m")
    step = 0.5 * grid.cellsize_m if step is None else float(step)
    if "line" in prof:
        return profile_along_polyline(grid, points, step)
    return steepest_descent_line(
        grid, points[0], step, max_length_m=prof.get("max_length_m")
    )


def _plan_points(prof: dict, key: str, source: str) -> list[tuple[float, float]]:
    """``from`` ([x, y]) or ``line`` ([[x, y], ...]) as checked plan points."""
    value = prof[key]
    shape = "[x, y]" if key == "from" else "[[x, y], ...] (two or more points)"
    items = [value] if key == "from" else value
    if not isinstance(items, list) or not items:
        raise InputFileError(f"must be {shape}", source=source, where=f"profile.{key}")
    points = []
    for i, item in enumerate(items):
        where = f"profile.{key}" + ("" if key == "from" else f"[{i}]")
        if not isinstance(item, list) or len(item) != 2:
            raise InputFileError(f"must be {shape}", source=source, where=where)
        points.append(
            tuple(check_number(v, -1e9, 1e9, source=source, where=where) for v in item)
        )
    return points


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
    span = float(profile.x_m[-1] - profile.x_m[0])
    for key in names:
        if data.get(key) is None:
            continue
        unit = key.rsplit("_", 1)[-1]
        lower, upper = -math.inf, math.inf
        if unit in ("mps", "radps"):
            upper = SEEDER_BOUNDS[unit]
            lower = -upper
        if "_sd_" in key or key == "height_m":
            lower = 0.0
        if key in ("x_sd_m",):
            upper = span
        elif key in ("z_sd_m", "height_m"):
            upper = SEEDER_BOUNDS["m"]
        elif key == "mass_sd_kg":
            upper = BODY_BOUNDS["mass_kg"][1]
        values[key] = check_number(
            data[key], lower, upper, source=source, where=f"seeder.{key}",
            unit={"mps": "m/s", "radps": "rad/s", "m": "m", "kg": "kg"}.get(unit, ""),
        )  # fmt: skip
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
        if seeder.z_m > ground + SEEDER_BOUNDS["m"]:
            raise InputFileError(
                f"start is more than {SEEDER_BOUNDS['m']:g} m above the ground "
                f"({seeder.z_m:g} m; ground {ground:g} m at x = {seeder.x_m:g} m)",
                source=source,
                where="seeder.z_m",
            )
    return seeder


def _trees(data: dict, profile: Profile, source: str) -> Trees:
    _unknown(data, {"x_m", "diameter_m", "height_m"}, "trees", source)
    arrays = number_lists(data, ("x_m", "diameter_m", "height_m"), "trees", source)
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
        if np.any(arrays[key] > TREE_BOUNDS[key]):
            raise InputFileError(
                f"must be <= {TREE_BOUNDS[key]:g} m (got {arrays[key].max():g})",
                source=source,
                where=f"trees.{key}",
            )
    order = np.argsort(arrays["x_m"], kind="stable")
    return Trees(**{k: v[order] for k, v in arrays.items()})


def read_model(
    path: str | os.PathLike[str],
    *,
    outputs: OutputSet | None = None,
    terrain: bool = False,
) -> Model:
    """Read and validate a JSON model file (one-line errors naming the file): a
    :class:`Model` for a ``profile``, a :class:`fieldkit.model.model3d.Model3D`
    for a ``terrain`` block.

    Parameters
    ----------
    path
        The model file (JSON, UTF-8).
    outputs
        The calling command's outputs: every file the model reads
        (:attr:`Model.source_files`) is added to its inputs, so no output replaces
        them (:meth:`fieldkit.outputs.OutputSet.add_inputs`).
    terrain
        Whether the caller runs a 3-D model (a ``terrain`` block): without it such a
        file is refused in one line (every reader of a profile model is safe).

    Raises
    ------
    InputFileError
        The file cannot be read, is not UTF-8 or not JSON, is nested deeper than
        :data:`MAX_JSON_DEPTH`, gives a key twice in one object
        (:func:`fieldkit.io.csv_table.parse_json`), or has a bad field (named); a
        terrain (3-D) model when ``terrain`` is False.
    OutputFileError
        A planned output of ``outputs`` is a file the model reads.
    """
    path = Path(path)
    if outputs is not None:
        outputs.add_inputs([path])
    try:
        text = path.read_text(encoding="utf-8-sig")  # a BOM, as Notepad writes
    except UnicodeDecodeError as exc:
        raise InputFileError(
            f"not a UTF-8 text file (byte {exc.start})", source=path
        ) from None
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise InputFileError(f"cannot read ({reason})", source=path) from None
    depth = _json_depth(text)
    if depth > MAX_JSON_DEPTH:
        raise InputFileError(
            f"JSON nested {depth} levels deep (a model file has at most "
            f"{MAX_JSON_DEPTH})",
            source=path,
        )
    # NaN and +-Infinity (not JSON, but Python writes them) are read as floats so
    # that the check of their field refuses them by name; a key given twice is
    # refused naming its path (Python's reader would keep the last silently)
    data = parse_json(text, str(path))
    if not terrain and isinstance(data, dict) and "terrain" in data:
        raise InputFileError(
            "a 3-D model (a terrain block, a DEM) where a profile model is needed",
            source=path,
            where="terrain",
        )
    model = model_from_dict(data, source=str(path), base_dir=path.parent)
    model = replace(model, source_files=(str(path), *model.source_files))
    if outputs is not None:
        outputs.add_inputs(model.source_files)
    return model


_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)


def _json_depth(text: str) -> int:
    """Deepest nesting of ``[`` and ``{`` outside strings (no recursion).

    Examples
    --------
    >>> _json_depth('{"a": [[1], "]]]"], "b": {"c": "[{"}}')
    3
    """
    code = np.frombuffer(_JSON_STRING.sub("", text).encode(), dtype=np.uint8)
    step = np.isin(code, (ord("["), ord("{"))).astype(np.int64)
    step -= np.isin(code, (ord("]"), ord("}")))
    return int(np.cumsum(step).max(initial=0))


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
    if model.analysis_points:
        data["analysis_points"] = [
            {"x_m": p.x_m, **({"name": p.name} if p.name else {})}
            for p in model.analysis_points
        ]
    if model.provenance:
        data["provenance"] = model.provenance
    return data


def write_model(
    model: Model, path: str | os.PathLike[str], *, outputs: OutputSet | None = None
) -> None:
    """Write ``model`` as JSON (through ``outputs`` when given)."""
    text = json_text(model_to_dict(model), indent=1)

    def writer(tmp: Path) -> None:
        tmp.write_text(text, encoding="utf-8")

    write_file(path, writer, outputs)
