"""Survey presets: one file holding a survey's reduce options and material mapping.

A preset (TOML) states once what every command needs to know about one surveyed
path, so the values are not copied into each command line and script::

    [reduce]
    theta0_deg = 32.6     # restitution angle of the flights no tree defines
    mass_kg = 3750.0
    radius_m = 0.725
    gyration_m = 0.46
    path_id = "boulder_a"

    [materials]           # surveyed material = the model's material
    talus = "colluvium"
    bench = "colluvium"

    [[measured]]          # a value measured at an analysis point (any number)
    x_m = 610.0
    speed_mps = 18.0
    ke_j = 600e3          # translational, 1/2 m v^2; also total_j, height_m
    source = "thesis §7.5.4"

``fieldkit reduce --preset`` reads ``[reduce]``; ``fieldkit fit`` and
``fieldkit diagnose --preset`` read ``[materials]``, applied by
:func:`fieldkit.fit.material_map.map_materials` only to surveyed materials the
model does not have. Values given on the command line override the preset's.
``fieldkit fit --preset`` compares its design quantities with each
``[[measured]]`` entry, beside those of ``--measured``.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from fieldkit.errors import InputFileError
from fieldkit.measured import QUANTITIES, Measured, measured_problem

#: ``[reduce]`` keys and their types (SI units in the names).
REDUCE_KEYS: dict[str, type] = {
    "theta0_deg": float,
    "mass_kg": float,
    "radius_m": float,
    "gyration_m": float,
    "path_id": str,
}
SECTIONS = ("reduce", "materials", "measured")
#: ``[[measured]]`` keys: the fields of :class:`fieldkit.measured.Measured`.
MEASURED_KEYS = ("x_m", *QUANTITIES, "source")


@dataclass(frozen=True)
class SurveyPreset:
    """A survey preset as read by :func:`read_preset`."""

    source: str
    reduce: dict[str, float | str] = field(default_factory=dict)
    materials: dict[str, str] = field(default_factory=dict)
    measured: tuple[Measured, ...] = ()

    def body(self) -> dict[str, float]:
        """The body values, as keyword arguments of
        :func:`fieldkit.physics.bodies.resolve_body` (``mass_kg``, ...)."""
        return {
            k: float(v)
            for k, v in self.reduce.items()
            if k in ("mass_kg", "radius_m", "gyration_m")
        }


def read_preset(path: str | Path) -> SurveyPreset:
    """Read a survey preset (module docstring for the format).

    Raises
    ------
    InputFileError
        The file is missing, not UTF-8 TOML, has an unknown section or key, or a
        value of the wrong type (numbers must be finite and positive).

    Examples
    --------
    >>> import tempfile
    >>> p = Path(tempfile.mkdtemp()) / "a.toml"
    >>> _ = p.write_text('[reduce]\\nmass_kg = 3750\\n[materials]\\ntalus = "rock"\\n')
    >>> read_preset(p).reduce, read_preset(p).materials
    ({'mass_kg': 3750.0}, {'talus': 'rock'})
    """
    path = Path(path)
    source = str(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputFileError("file not found", source=source) from None
    except IsADirectoryError:
        raise InputFileError("is a folder, not a preset file", source=source) from None
    except UnicodeDecodeError:
        raise InputFileError("not UTF-8 text", source=source) from None
    except tomllib.TOMLDecodeError as exc:
        raise InputFileError(f"not a TOML preset: {exc}", source=source) from None
    except OSError as exc:
        raise InputFileError(str(exc.strerror or exc).lower(), source=source) from None
    unknown = [k for k in data if k not in SECTIONS]
    if unknown:
        raise InputFileError(
            f"unknown section(s) {', '.join(unknown)} (a preset has "
            f"{', '.join(SECTIONS)})",
            source=source,
        )
    for name in SECTIONS[:2]:
        if not isinstance(data.get(name, {}), dict):
            raise InputFileError(f"{name} must be a [{name}] table", source=source)
    reduce: dict[str, float | str] = {}
    for key, value in data.get("reduce", {}).items():
        kind = REDUCE_KEYS.get(key)
        if kind is None:
            raise InputFileError(
                f"unknown key (known: {', '.join(REDUCE_KEYS)})",
                source=source,
                where=f"reduce.{key}",
            )
        if kind is float:
            ok = isinstance(value, int | float) and not isinstance(value, bool)
            if not (ok and math.isfinite(value) and value > 0):
                raise InputFileError(
                    f"must be a finite number > 0 (got {value!r})",
                    source=source,
                    where=f"reduce.{key}",
                )
            value = float(value)
        elif not (isinstance(value, str) and value.strip()):
            raise InputFileError(
                f"must be a non-empty text (got {value!r})",
                source=source,
                where=f"reduce.{key}",
            )
        reduce[key] = value
    materials: dict[str, str] = {}
    for key, value in data.get("materials", {}).items():
        if not (isinstance(value, str) and value.strip()):
            raise InputFileError(
                f"must name a model material (got {value!r})",
                source=source,
                where=f"materials.{key}",
            )
        materials[key] = value.strip()
    measured = _measured(data.get("measured", []), source)
    return SurveyPreset(
        source=source, reduce=reduce, materials=materials, measured=measured
    )


def _measured(entries: object, source: str) -> tuple[Measured, ...]:
    """The ``[[measured]]`` tables as :class:`~fieldkit.measured.Measured` values
    (each needs ``x_m`` and at least one measured quantity)."""
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        raise InputFileError(
            "measured must be an array of tables ([[measured]] entries)", source=source
        )
    out = []
    for i, entry in enumerate(entries):
        where = f"measured[{i}]"
        for key, value in entry.items():
            if key not in MEASURED_KEYS:
                raise InputFileError(
                    f"unknown key (known: {', '.join(MEASURED_KEYS)})",
                    source=source,
                    where=f"{where}.{key}",
                )
            if key == "source":
                if not isinstance(value, str):
                    raise InputFileError(
                        f"must be text (got {value!r})", source=source,
                        where=f"{where}.source",
                    )  # fmt: skip
                continue
            problem = measured_problem(key, value)
            if problem is not None:
                raise InputFileError(problem, source=source, where=f"{where}.{key}")
        if "x_m" not in entry:
            raise InputFileError("missing", source=source, where=f"{where}.x_m")
        if not any(k in entry for k in QUANTITIES):
            raise InputFileError(
                f"gives no measured value (one or more of {', '.join(QUANTITIES)})",
                source=source,
                where=where,
            )
        values = {k: float(v) for k, v in entry.items() if k != "source"}
        out.append(Measured(**values, source=entry.get("source", "").strip()))
    return tuple(out)
