"""Read RocFall (lumped mass) input blocks back into a fieldkit model.

The inverse of :mod:`fieldkit.export.rocfall`: ``materials.txt``, ``rock_type.txt``,
``project_settings.txt`` and a RocFall-style slope (``slope.csv``: ``x, y,
material id`` of the segment to the next vertex), as fieldkit writes them or typed
by hand, so that a user starts a calibration from the RocFall model they have.

Text blocks: ``key (unit): value`` lines, ``#`` comments, blank lines ignored, keys
case-insensitive; a block starts at ``material N: name`` (``rock type N: name``).
A random value is ``distribution id, mean, sd, relative min, relative max`` (commas
or spaces) or one number (a constant). fieldkit draws ``N(mean, sd)`` clipped at 0,
so a normal keeps its mean and SD and its relative bounds are not carried; the other
distributions are read as a normal with their mean and SD (uniform: SD ``(max -
min)/sqrt(12)``; exponential: SD = mean), each stated in the notes.

What RocFall inputs do not carry gets a stated default, listed in the ``notes``
returned beside the model: the body radius (a lumped mass has none: a sphere of
:data:`DENSITY_KG_M3` with the rock type's mass, unless ``radius_m`` is given) and
gyration (solid sphere), the seeder (on the first slope vertex) and velocities (0)
when the rock type gives none, fieldkit's core settings, and the parameters of
``rotation_friction`` when rotational velocity is on. Bad input is one
:class:`~fieldkit.errors.InputFileError` naming the file and the line: a value the
model's own checks refuse (a release speed beyond 100 m/s, a mass beyond 1e9 kg)
is reported against the RocFall file and line it came from (:class:`_Origins`),
naming the RocFall key and the model field, e.g. ``rock_type.txt: line 5: initial
horizontal velocity (seeder.vx_mps): must be <= 100 m/s``.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.export.rocfall_keys import DISTRIBUTIONS, MATERIAL_KEYS, ROCK_KEYS
from fieldkit.io.profile_csv import check_profile_vertices
from fieldkit.model.materials import MATERIAL_FIELDS, check_material_name
from fieldkit.model.model_file import CORE_DEFAULTS, Model, model_from_dict

#: Density of the sphere that gives an imported rock its radius [kg/m^3] (stated).
DENSITY_KG_M3 = 2650.0
#: RocFall's default velocity-scaling constant K [m/s] (30 ft/s).
DEFAULT_K_MPS = 9.144
_LINE = re.compile(
    r"^(?P<key>[^:()]+?)\s*(?:\((?P<unit>[^)]*)\))?\s*:\s*(?P<value>.*?)\s*$"
)
_BLOCK = re.compile(r"^(?P<kind>material|rock type)\s+(?P<id>\S+)$")
#: Rock-type seeder keys -> the model field each gives.
_SEEDER_FIELDS = {
    "seeder x": "seeder.x_m",
    "seeder y": "seeder.z_m",
    "seeder x end": "seeder.x_max_m",
    "seeder height": "seeder.height_m",
}
_ON = {"on", "yes", "true", "1"}
_OFF = {"off", "no", "false", "0"}


@dataclass(frozen=True)
class Text:
    """One input: its text and the name errors give (a file name)."""

    text: str
    source: str


@dataclass
class _Entry:
    key: str
    unit: str | None
    value: str
    line: int


class _Origins:
    """Where each model field came from: a model-file path (``seeder.vx_mps``,
    ``materials.rock.e_n``) -> the RocFall file, line and key that gave it; a
    coarser path (``seeder``, ``materials.rock``) -> the file (and block line).

    :meth:`locate` turns an error of the model's checks (naming a model field)
    into one naming the RocFall file and line.
    """

    def __init__(self) -> None:
        self.paths: dict[str, tuple[str, int | None, str]] = {}

    def add(self, path: str, source: str, line: int | None, key: str = "") -> None:
        self.paths[path] = (source, line, key)

    def locate(self, exc: InputFileError) -> InputFileError:
        """``exc`` (naming a model field in ``where``) named in RocFall's terms."""
        path = exc.where or ""
        head = path
        while head and head not in self.paths:
            head = re.sub(r"(\.[^.\[]*|\[\d+\])$", "", head)
            if head == path:
                break
        if head not in self.paths:
            return exc
        source, line, key = self.paths[head]
        field_name = f"{key} ({path})" if key else path
        return InputFileError(
            f"{field_name}: {exc.message}" if field_name else exc.message,
            source=source,
            where=None if line is None else f"line {line}",
        )


@dataclass
class _Block:
    kind: str
    ident: int
    name: str
    line: int
    entries: dict[str, _Entry] = field(default_factory=dict)


def read_rocfall(
    materials: str | os.PathLike[str],
    slope: str | os.PathLike[str],
    *,
    rock_type: str | os.PathLike[str],
    settings: str | os.PathLike[str] | None = None,
    radius_m: float | None = None,
) -> tuple[Model, list[str]]:
    """Read RocFall input files into ``(model, notes)`` (module docstring).

    Parameters
    ----------
    materials, slope, rock_type, settings
        The files (``settings`` optional: without it velocity scaling and
        rotation are off and the core settings are fieldkit's defaults).
    radius_m
        Body radius [m]; None: a sphere of :data:`DENSITY_KG_M3`.

    Raises
    ------
    InputFileError
        A file that cannot be read or has a bad line (file and line named).
    """
    texts = [_read(p) for p in (materials, slope, rock_type)]
    return model_from_rocfall(
        *texts,
        settings=None if settings is None else _read(settings),
        radius_m=radius_m,
    )


def _read(path: str | os.PathLike[str]) -> Text:
    """A RocFall file's text: UTF-8, with or without a BOM (as Windows editors
    write it, and as the CSV readers accept); CRLF line ends are read too."""
    path = Path(path)
    try:
        return Text(path.read_text(encoding="utf-8-sig"), str(path))
    except OSError as exc:
        raise InputFileError(f"cannot read ({exc.strerror})", source=path) from None
    except UnicodeDecodeError:
        raise InputFileError("not a UTF-8 text file", source=path) from None


def model_from_rocfall(
    materials: Text,
    slope: Text,
    rock_type: Text,
    *,
    settings: Text | None = None,
    radius_m: float | None = None,
) -> tuple[Model, list[str]]:
    """The model from RocFall texts, and the notes on what was assumed.

    Examples
    --------
    >>> m, notes = model_from_rocfall(
    ...     Text("material 1: rock\\nrn: 2, 0.5, 0.04, 0.12, 0.12\\nrt: 0.8\\n"
    ...          "friction angle (deg): 30\\n", "materials.txt"),
    ...     Text("x_m,y_m,material_id\\n0,10,1\\n10,0,\\n", "slope.csv"),
    ...     Text("rock type 1: block\\nmass (kg): 100\\nseeder x (m): 1\\n"
    ...          "seeder y (m): 11\\n", "rock_type.txt"), radius_m=0.2)
    >>> m.materials["rock"].e_n, m.materials["rock"].e_n_sd, m.body.mass_kg
    (0.5, 0.04, 100.0)
    """
    notes: list[str] = []
    origins = _Origins()
    mats = _materials(materials, notes, origins)
    names = {ident: name for ident, (name, _) in mats.items()}
    x, z, segment_ids = _slope(slope, names)
    origins.add("profile", slope.source, None)
    profile_materials = [names[i] for i in segment_ids]
    effects, core, friction_rule = _settings(settings, notes, origins)
    material_data = {}
    for name, values in mats.values():
        material_data[name] = _friction_rule(name, values, friction_rule, notes)
    rough = [v.get("roughness_deg_sd", 0.0) for _, v in mats.values()]
    if any(r > 0.0 for r in rough):
        effects["slope_roughness"] = {}
        origins.add("effects.slope_roughness", materials.source, None)
        notes.append(
            "slope_roughness on (scale 1): the materials' slope roughness SDs are "
            "fieldkit's roughness_deg_sd; roughness_m = 0 (RocFall has no CRSP s)"
        )
    body, seeder = _rock_type(rock_type, x, z, notes, origins)
    body["radius_m"] = _radius(radius_m, body["mass_kg"], notes)
    notes.append(
        "body.gyration_m: solid sphere sqrt(2/5) radius_m (RocFall's lumped mass has "
        "no shape)"
    )
    defaults = [k for k in CORE_DEFAULTS if k not in core]
    notes.append(
        "core settings "
        + ", ".join(f"{k} = {CORE_DEFAULTS[k][0]:g}" for k in defaults)
        + ": fieldkit's defaults (not in RocFall's inputs)"
    )
    sources = [t.source for t in (materials, slope, rock_type, settings) if t]
    data = {
        "profile": {"x_m": x, "z_m": z, "material": profile_materials},
        "materials": material_data,
        "body": body,
        "seeder": seeder,
        "effects": effects,
        "core": core,
        "provenance": {
            "title": "imported from RocFall input blocks",
            "imported_from": sources,
            "import_notes": list(notes),
        },
    }
    try:
        return model_from_dict(data, source=materials.source), notes
    except InputFileError as exc:  # a model field: named by the file that gave it
        raise origins.locate(exc) from None


# ---------------------------------------------------------------- text blocks --


def _key_value_lines(text: Text) -> Iterator[tuple[int, re.Match, str]]:
    """(line number, match of :data:`_LINE`, normalised key) of every line that is
    not blank or a comment; a line that is not ``key: value`` is an error."""
    for n, raw in enumerate(text.text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        match = _LINE.match(line)
        if match is None:
            raise InputFileError(
                f"expected 'key: value' (got {line!r})",
                source=text.source,
                where=f"line {n}",
            )
        yield n, match, " ".join(match["key"].lower().split())


def _entries(text: Text, kind: str) -> list[_Block]:
    """The blocks of a materials or rock-type text (``kind`` names the header)."""
    blocks: list[_Block] = []
    for n, match, key in _key_value_lines(text):
        header = _BLOCK.match(key)
        if header is not None and header["kind"] == kind:
            try:
                ident = int(header["id"])
            except ValueError:
                raise InputFileError(
                    f"{kind} id must be a whole number (got {header['id']!r})",
                    source=text.source,
                    where=f"line {n}",
                ) from None
            name = match["value"].strip() or f"{kind.replace(' ', '_')}_{ident}"
            for b in blocks:
                if b.ident == ident:
                    raise InputFileError(
                        f"{kind} {ident} defined twice (first on line {b.line})",
                        source=text.source,
                        where=f"line {n}",
                    )
            blocks.append(_Block(kind, ident, name, n))
            continue
        if not blocks:
            raise InputFileError(
                f"expected '{kind} N: name' before {key!r}",
                source=text.source,
                where=f"line {n}",
            )
        block = blocks[-1]
        if key in block.entries:
            raise InputFileError(
                f"{key} given twice in {kind} {block.ident} (first on line "
                f"{block.entries[key].line})",
                source=text.source,
                where=f"line {n}",
            )
        unit = None if match["unit"] is None else match["unit"].strip().lower()
        block.entries[key] = _Entry(key, unit, match["value"], n)
    if not blocks:
        raise InputFileError(f"no '{kind} N: name' block", source=text.source)
    return blocks


def _check_unit(entry: _Entry, expected: str, source: str) -> None:
    if entry.unit is None or entry.unit in (expected, "-" if not expected else ""):
        return
    raise InputFileError(
        f"{entry.key}: unit must be {expected or 'none'} (got {entry.unit})",
        source=source,
        where=f"line {entry.line}",
    )


def _number(token: str, what: str, source: str, line: int) -> float:
    try:
        value = float(token)
    except ValueError:
        raise InputFileError(
            f"{what}: not a number ({token!r})", source=source, where=f"line {line}"
        ) from None
    if not math.isfinite(value):
        raise InputFileError(
            f"{what}: not a finite number ({token!r})",
            source=source,
            where=f"line {line}",
        )
    return value


def _distribution(
    entry: _Entry, what: str, source: str, notes: list[str]
) -> tuple[float, float]:
    """``(mean, sd)`` of a random value (module docstring)."""
    tokens = [t for t in re.split(r"[,;\s]+", entry.value.strip()) if t]
    where = f"line {entry.line}"
    if len(tokens) == 1:
        return _number(tokens[0], what, source, entry.line), 0.0
    if len(tokens) != 5:
        raise InputFileError(
            f"{what}: expected distribution id, mean, sd, relative min, relative max "
            f"(got {len(tokens)} values)",
            source=source,
            where=where,
        )
    kind_value, mean, sd, rel_min, rel_max = (
        _number(t, what, source, entry.line) for t in tokens
    )
    if kind_value not in DISTRIBUTIONS:
        raise InputFileError(
            f"{what}: distribution id must be one of "
            f"{', '.join(f'{k} {v}' for k, v in DISTRIBUTIONS.items())} "
            f"(got {tokens[0]})",
            source=source,
            where=where,
        )
    for label, value in (
        ("sd", sd),
        ("relative min", rel_min),
        ("relative max", rel_max),
    ):
        if value < 0.0:
            raise InputFileError(
                f"{what}: {label} must be >= 0 (got {value:g})",
                source=source,
                where=where,
            )
    kind = int(kind_value)
    if kind == 1:
        if sd > 0.0:
            notes.append(f"{what}: distribution 1 (none): sd {sd:g} ignored")
        return mean, 0.0
    if kind == 3:
        sd = (rel_min + rel_max) / math.sqrt(12.0)
        notes.append(
            f"{what}: uniform on [{mean - rel_min:g}, {mean + rel_max:g}] read as a "
            f"normal with mean {mean:g}, sd (max - min)/sqrt(12) = {sd:.4g}"
        )
    elif kind == 6:
        notes.append(f"{what}: exponential read as a normal with sd = mean {mean:g}")
        sd = abs(mean)
    elif kind != 2:
        notes.append(
            f"{what}: {DISTRIBUTIONS[kind]} read as a normal with mean {mean:g}, sd "
            f"{sd:g}"
        )
    return mean, sd


def _materials(
    text: Text, notes: list[str], origins: _Origins
) -> dict[int, tuple[str, dict]]:
    out: dict[int, tuple[str, dict]] = {}
    seen: dict[str, int] = {}
    for block in _entries(text, "material"):
        check_material_name(block.name, source=text.source, where=f"line {block.line}")
        label = f"material {block.ident} ({block.name})"
        if block.name in seen:
            raise InputFileError(
                f"{label}: name also used by material {seen[block.name]}",
                source=text.source,
                where=f"line {block.line}",
            )
        seen[block.name] = block.ident
        origins.add(f"materials.{block.name}", text.source, block.line, label)
        values: dict[str, float] = {}
        for key, entry in block.entries.items():
            if key not in MATERIAL_KEYS:
                raise InputFileError(
                    f"{label}: unknown key {key!r} (known: {', '.join(MATERIAL_KEYS)})",
                    source=text.source,
                    where=f"line {entry.line}",
                )
            fk, unit = MATERIAL_KEYS[key]
            _check_unit(entry, unit, text.source)
            for name in (fk, f"{fk}_sd"):
                origins.add(f"materials.{block.name}.{name}", text.source,
                            entry.line, key)  # fmt: skip
            what = f"{key} of {label}"
            if fk == "roughness_deg_sd":
                values[fk] = _number(entry.value, what, text.source, entry.line)
            else:
                values[fk], values[f"{fk}_sd"] = _distribution(
                    entry, what, text.source, notes
                )
            for name in (fk, f"{fk}_sd"):
                if name in values:
                    _bounds(name, values[name], what, text.source, entry.line)
        for key, (fk, _) in MATERIAL_KEYS.items():
            if fk not in values and fk != "roughness_deg_sd":
                raise InputFileError(
                    f"{label}: {key} missing",
                    source=text.source,
                    where=f"line {block.line}",
                )
        out[block.ident] = (block.name, values)
    notes.append(
        "distribution bounds (relative min, max) are not carried: fieldkit draws "
        "N(mean, sd) clipped at 0, without an upper bound"
    )
    return out


def _bounds(name: str, value: float, what: str, source: str, line: int) -> None:
    lower, upper, unit, _ = MATERIAL_FIELDS[name]
    if not lower <= value <= upper:
        unit = "" if unit == "-" else f" {unit}"
        raise InputFileError(
            f"{what}: {name} must be in [{lower:g}, {upper:g}]{unit} (got {value:g})",
            source=source,
            where=f"line {line}",
        )


def _friction_rule(name: str, values: dict, rule: str, notes: list[str]) -> dict:
    out = dict(values)
    if rule == "rt":
        rt = out["e_t"]
        out["friction_deg"] = math.degrees(math.atan((1.0 - rt) / rt)) if rt else 89.0
        out["friction_deg_sd"] = 0.0
        notes.append(
            f"materials.{name}.friction_deg = {out['friction_deg']:.4g} deg from Rt "
            "(RocFall's 'calculate from Rt': arctan((1 - Rt)/Rt)), sd 0"
        )
    elif rule == "zero":
        out["friction_deg"] = out["friction_deg_sd"] = 0.0
        notes.append(f"materials.{name}.friction_deg = 0 (RocFall: rolling)")
    return out


# -------------------------------------------------------------------- slope --


def _slope(text: Text, names: dict[int, str]) -> tuple[list, list, list]:
    """Vertices ``x, y`` and the material id of each segment."""
    rows: list[tuple[int, list[str]]] = []
    first = True
    for n, raw in enumerate(text.text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        cells = re.split(r"\s*[,;\t]\s*|\s+", line)
        if first and not _is_number(cells[0]):
            first = False
            continue  # the header
        first = False
        rows.append((n, cells))
    if len(rows) < 2:
        raise InputFileError(
            f"needs at least two vertices (got {len(rows)})", source=text.source
        )
    x, z, ids = [], [], []
    for k, (n, cells) in enumerate(rows):
        if len(cells) < 2 or not cells[1]:
            raise InputFileError(
                "expected x, y, material id", source=text.source, where=f"line {n}"
            )
        x.append(_number(cells[0], "x", text.source, n))
        z.append(_number(cells[1], "y", text.source, n))
        if k and x[-1] <= x[-2]:
            raise InputFileError(
                f"x must increase along the slope, left to right (got {x[-1]:g} "
                f"after {x[-2]:g})",
                source=text.source,
                where=f"line {n}",
            )
        if k == len(rows) - 1:
            break  # the last vertex ends the last segment: no material
        token = cells[2] if len(cells) > 2 else ""
        if not token:
            raise InputFileError(
                "material id of the segment to the next vertex missing",
                source=text.source,
                where=f"line {n}",
            )
        ident = _number(token, "material id", text.source, n)
        if ident not in names:
            raise InputFileError(
                f"material id {token} is not in the materials "
                f"({', '.join(f'{i} {v}' for i, v in names.items())})",
                source=text.source,
                where=f"line {n}",
            )
        ids.append(int(ident))
    check_profile_vertices(  # the bounds of every profile (a profile CSV's)
        np.array(x), np.array(z), source=text.source,
        where=lambda axis, i: f"line {rows[i][0]}: {'x' if axis == 'x' else 'y'}",
    )  # fmt: skip
    return x, z, ids


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


# -------------------------------------------------------- rock type, seeder --


def _rock_type(
    text: Text, x: list, z: list, notes: list[str], origins: _Origins
) -> tuple[dict, dict]:
    blocks = _entries(text, "rock type")
    if len(blocks) > 1:
        raise InputFileError(
            f"fieldkit models one body: give one rock type (got {len(blocks)})",
            source=text.source,
            where=f"line {blocks[1].line}",
        )
    block = blocks[0]
    for part in ("body", "seeder"):
        origins.add(part, text.source, block.line, f"rock type {block.ident}")
    seeder_keys = {"seeder", *_SEEDER_FIELDS}
    for key, entry in block.entries.items():
        if key in ROCK_KEYS:
            fk, sd_key, _ = ROCK_KEYS[key]
            origins.add(f"{'body' if fk == 'mass_kg' else 'seeder'}.{fk}", text.source,
                        entry.line, key)  # fmt: skip
            origins.add(f"seeder.{sd_key}", text.source, entry.line, key)
        elif key in _SEEDER_FIELDS:
            origins.add(_SEEDER_FIELDS[key], text.source, entry.line, key)
    body: dict[str, float] = {}
    seeder: dict[str, float] = {}
    for key, entry in block.entries.items():
        if key in ROCK_KEYS:
            fk, sd_key, unit = ROCK_KEYS[key]
            _check_unit(entry, unit, text.source)
            mean, sd = _distribution(entry, key, text.source, notes)
            (body if fk == "mass_kg" else seeder)[fk] = mean
            seeder[sd_key] = sd
        elif key not in seeder_keys:
            known = ", ".join([*ROCK_KEYS, *sorted(seeder_keys)])
            raise InputFileError(
                f"rock type {block.ident}: unknown key {key!r} (known: {known})",
                source=text.source,
                where=f"line {entry.line}",
            )
    if "mass_kg" not in body:
        raise InputFileError(
            f"rock type {block.ident} ({block.name}): mass missing",
            source=text.source,
            where=f"line {block.line}",
        )
    mass = block.entries["mass"]
    if body["mass_kg"] <= 0.0:
        raise InputFileError(
            f"mass must be > 0 kg (got {body['mass_kg']:g})",
            source=text.source,
            where=f"line {mass.line}",
        )
    for key in ("initial horizontal velocity", "initial vertical velocity"):
        if key not in block.entries:
            notes.append(f"seeder: {key} not given: 0 m/s")
    seeder.update(_seeder_location(block, text.source, x, z, notes))
    return body, seeder


def _seeder_location(
    block: _Block, source: str, x: list, z: list, notes: list[str]
) -> dict[str, float]:
    entries = block.entries

    def value(key: str, unit: str = "m") -> float | None:
        entry = entries.get(key)
        if entry is None:
            return None
        _check_unit(entry, unit, source)
        return _number(entry.value, key, source, entry.line)

    def fail(message: str, key: str) -> InputFileError:
        line = entries[key].line if key in entries else block.line
        return InputFileError(message, source=source, where=f"line {line}")

    kind = entries["seeder"].value.strip().lower() if "seeder" in entries else "point"
    if kind not in ("point", "line"):
        raise fail(f"seeder must be point or line (got {kind!r})", "seeder")
    sx = value("seeder x")
    if sx is None:
        notes.append(
            f"seeder: no location given: on the first slope vertex ({x[0]:g}, "
            f"{z[0]:g}) m"
        )
        return {"x_m": x[0], "z_m": z[0]}
    if not x[0] <= sx <= x[-1]:
        raise fail(
            f"seeder x must lie on the slope [{x[0]:g}, {x[-1]:g}] m", "seeder x"
        )
    if kind == "line":
        end, height = value("seeder x end"), value("seeder height")
        if end is None or height is None:
            raise fail("a line seeder needs seeder x end and seeder height", "seeder")
        if not sx <= end <= x[-1]:
            raise fail(
                f"seeder x end must lie in [{sx:g}, {x[-1]:g}] m", "seeder x end"
            )
        if height < 0.0:
            raise fail("seeder height must be >= 0 m", "seeder height")
        return {"x_m": sx, "x_max_m": end, "height_m": height}
    sy = value("seeder y")
    ground = _interp(sx, x, z)
    if sy is None:
        notes.append(f"seeder y not given: on the slope at x = {sx:g} m")
        sy = ground
    if sy < ground:
        raise fail(
            f"seeder y = {sy:g} m is below the slope ({ground:g} m at x = {sx:g} m)",
            "seeder y",
        )
    return {"x_m": sx, "z_m": sy}


def _interp(xq: float, x: list, z: list) -> float:
    for j in range(len(x) - 1):
        if x[j] <= xq <= x[j + 1]:
            t = (xq - x[j]) / (x[j + 1] - x[j])
            return z[j] + t * (z[j + 1] - z[j])
    return z[-1]


def _radius(radius_m: float | None, mass_kg: float, notes: list[str]) -> float:
    if radius_m is not None:
        r = float(radius_m)
        if not (math.isfinite(r) and r > 0.0):
            raise ArgumentError(f"radius_m must be > 0 (got {r:g})", source="radius_m")
        notes.append(f"body.radius_m = {r:g} m (given)")
        return r
    r = (3.0 * mass_kg / (4.0 * math.pi * DENSITY_KG_M3)) ** (1.0 / 3.0)
    notes.append(
        f"body.radius_m = {r:.4g} m: RocFall's lumped-mass rock has no size; a "
        f"sphere of {DENSITY_KG_M3:g} kg/m^3 with the rock type's mass (give "
        "`radius_m` to set it)"
    )
    return r


# ----------------------------------------------------------------- settings --


def _settings(
    text: Text | None, notes: list[str], origins: _Origins
) -> tuple[dict, dict, str]:
    """``(effects, core, friction rule)`` from the project settings."""
    if text is None:
        notes.append(
            "no project settings: velocity scaling and rotation off, friction "
            "angles from the materials"
        )
        return {}, {}, "material"
    entries: dict[str, _Entry] = {}
    for n, match, key in _key_value_lines(text):
        if key in entries:
            raise InputFileError(
                f"setting {key!r} given twice (first on line {entries[key].line}); "
                "give each setting once",
                source=text.source,
                where=f"line {n}",
            )
        unit = None if match["unit"] is None else match["unit"].strip().lower()
        entries[key] = _Entry(key, unit, match["value"].strip(), n)
    for path in ("core", "effects"):
        origins.add(path, text.source, None)
    for key, path in (
        ("scale rn velocity k", "effects.velocity_scaled_restitution"),
        ("scale rn by velocity", "effects.velocity_scaled_restitution"),
        ("consider rotational velocity", "effects.rotation_friction"),
        ("stopped velocity cutoff", "core.stop_speed_mps"),
    ):
        if key in entries and path not in origins.paths:
            origins.add(path, text.source, entries[key].line, key)
    known = {
        "analysis method",
        "units",
        "scale rn by velocity",
        "scale rn velocity k",
        "scale rn by mass",
        "consider rotational velocity",
        "friction angle",
        "stopped velocity cutoff",
    }
    for key, entry in entries.items():
        if key not in known:
            raise InputFileError(
                f"unknown setting {key!r} (known: {', '.join(sorted(known))})",
                source=text.source,
                where=f"line {entry.line}",
            )

    def fail(entry: _Entry, message: str) -> InputFileError:
        return InputFileError(message, source=text.source, where=f"line {entry.line}")

    def flag(key: str) -> bool | None:
        entry = entries.get(key)
        if entry is None:
            return None
        word = entry.value.lower()
        if word not in _ON | _OFF:
            raise fail(entry, f"{key} must be on or off (got {entry.value!r})")
        return word in _ON

    method = entries.get("analysis method")
    if method is not None and " ".join(method.value.lower().split()) not in (
        "lumped mass",
        "lump mass",
    ):
        raise fail(method, f"only lumped mass is read (got {method.value!r})")
    units = entries.get("units")
    if units is not None and not units.value.lower().startswith("metric"):
        raise fail(units, f"only metric units are read (got {units.value!r})")
    effects: dict[str, dict] = {}
    core: dict[str, float] = {}
    scaled = flag("scale rn by velocity")
    k_entry = entries.get("scale rn velocity k")
    if scaled or (scaled is None and k_entry is not None):
        if k_entry is None:
            k = DEFAULT_K_MPS
            notes.append(f"scale rn velocity k not given: RocFall's default {k:g} m/s")
        else:
            _check_unit(k_entry, "m/s", text.source)
            k = _number(k_entry.value, "scale rn velocity k", text.source, k_entry.line)
            if k <= 0.0:
                raise fail(k_entry, f"scale rn velocity k must be > 0 m/s (got {k:g})")
        effects["velocity_scaled_restitution"] = {"k_mps": k}
    if flag("scale rn by mass"):
        notes.append(
            "scale rn by mass: fieldkit has no such effect; the model starts without it"
        )
    if flag("consider rotational velocity"):
        effects["rotation_friction"] = {}
        notes.append(
            "consider rotational velocity on -> rotation_friction with fieldkit's "
            "defaults (friction 0.5, coupling 1): RocFall gives no parameters"
        )
    rule = "material"
    friction = entries.get("friction angle")
    if friction is not None:
        word = friction.value.lower()
        if "rt" in word.split() or "from rt" in word:
            rule = "rt"
        elif "zero" in word or "rolling" in word:
            rule = "zero"
        elif "material" not in word:
            raise fail(
                friction,
                "friction angle must be 'use material friction angle', 'calculate "
                f"from rt' or 'zero (rolling)' (got {friction.value!r})",
            )
    stop = entries.get("stopped velocity cutoff")
    if stop is not None:
        _check_unit(stop, "m/s", text.source)
        value = _number(stop.value, "stopped velocity cutoff", text.source, stop.line)
        lower, upper = CORE_DEFAULTS["stop_speed_mps"][1:3]
        if not lower <= value <= upper:
            raise fail(
                stop,
                f"stopped velocity cutoff must be in [{lower:g}, {upper:g}] m/s "
                f"(got {value:g})",
            )
        core["stop_speed_mps"] = value
    return effects, core, rule
