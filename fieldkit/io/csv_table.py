"""Plain-text tables (CSV, semicolon or tab separated) with file row numbers kept.

Every CSV reader in :mod:`fieldkit.io` goes through :func:`read_csv_table`, so they all
agree on what "row 7" means, how column names are normalised and aliased, how numbers
are parsed and what a bad file says.

Row numbers are spreadsheet row numbers: the header is row 1, the first data row is
row 2 (equal to the line number in a text editor unless a quoted cell spans lines).
Blank lines and lines starting with ``#`` are skipped but still counted.
"""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

from fieldkit.errors import ArgumentError, InputFileError

#: Length units a column name may carry, e.g. ``x_m``, ``x_ft`` or ``Altitude (ft)``.
LENGTH_UNITS: dict[str, float] = {"m": 1.0, "ft": 0.3048, "mm": 1e-3, "cm": 1e-2}

_UNIT_IN_NAME = re.compile(r"^(?P<base>.*?)(?:_(?P<suffix>m|ft|mm|cm|deg))?$")


def normalise_name(raw: str) -> tuple[str, str | None]:
    """Return ``(base name, unit)`` for a header cell.

    Lower-cases, turns spaces and hyphens into ``_``, and splits a unit given as a
    suffix (``x_m``) or in brackets (``Altitude (ft)``).

    Examples
    --------
    >>> normalise_name("Altitude (ft)")
    ('altitude', 'ft')
    >>> normalise_name("x_m")
    ('x', 'm')
    >>> normalise_name(" Point ID ")
    ('point_id', None)
    """
    text = raw.strip().lower()
    unit = None
    bracket = re.search(r"[\(\[]\s*([a-z°]+)\s*[\)\]]\s*$", text)
    if bracket:
        unit = bracket.group(1).replace("°", "deg")
        text = text[: bracket.start()]
    text = re.sub(r"[\s\-\.]+", "_", text.strip()).strip("_")
    match = _UNIT_IN_NAME.match(text)
    if unit is None and match and match.group("suffix") and match.group("base"):
        unit = match.group("suffix")
        text = match.group("base")
    if unit in ("meter", "meters", "metre", "metres"):
        unit = "m"
    if unit in ("feet", "foot"):
        unit = "ft"
    return text, unit


@dataclass(frozen=True)
class Column:
    """A header cell after normalisation: position, original text, base name, unit."""

    index: int
    header: str
    name: str
    unit: str | None


@dataclass(frozen=True)
class CsvTable:
    """Header and data rows of a text table, each row with its spreadsheet row."""

    source: str
    columns: tuple[Column, ...]
    rows: tuple[tuple[int, tuple[str, ...]], ...]
    delimiter: str

    def find(self, aliases: tuple[str, ...]) -> Column | None:
        """First column whose normalised name is in ``aliases`` (alias order wins)."""
        for alias in aliases:
            for column in self.columns:
                if column.name == alias:
                    return column
        return None

    def cell(self, row: tuple[str, ...], column: Column) -> str:
        """The stripped text of ``column`` in ``row`` ('' if the row is short)."""
        return row[column.index].strip() if column.index < len(row) else ""

    def number(
        self,
        row_number: int,
        row: tuple[str, ...],
        column: Column,
        *,
        required: bool = True,
        where: str | None = None,
    ) -> float:
        """Parse a cell as a float; NaN if empty and not required.

        Raises :class:`InputFileError` naming the column and the value for text in a
        number, and the column for a missing required value.
        """
        text = self.cell(row, column)
        place = where or f"row {row_number}"
        if text == "":
            if required:
                raise InputFileError(
                    f"column '{column.header.strip()}' is empty",
                    source=self.source,
                    where=place,
                )
            return math.nan
        candidate = text
        if self.delimiter != "," and "," in text and "." not in text:
            candidate = text.replace(",", ".")  # decimal comma (European locale)
        try:
            value = float(candidate)
        except ValueError:
            raise InputFileError(
                f"column '{column.header.strip()}': '{text}' is not a number",
                source=self.source,
                where=place,
            ) from None
        if not math.isfinite(value):
            raise InputFileError(
                f"column '{column.header.strip()}': '{text}' is not a finite number",
                source=self.source,
                where=place,
            )
        return value


def check_readable(path: str | PathLike[str]) -> Path:
    """Raise a one-line error if ``path`` is missing, a folder or empty."""
    file = Path(path)
    if not file.exists():
        raise InputFileError("file not found", source=path)
    if file.is_dir():
        raise InputFileError("is a folder, not a file", source=path)
    if file.stat().st_size == 0:
        raise InputFileError("file is empty", source=path)
    return file


def decode_text(data: bytes, source: str, kind: str = "CSV") -> str:
    """Decode file bytes as text (UTF-8 with or without BOM, else Latin-1).

    Raises if the bytes look binary (NUL bytes or mostly non-printable).
    """
    sample = data[:4096]
    if b"\x00" in sample:
        raise InputFileError(f"not a text {kind} file (binary content)", source=source)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
        controls = sum(1 for ch in text[:4096] if ord(ch) < 32 and ch not in "\r\n\t")
        if controls > 0.05 * min(len(text), 4096):
            raise InputFileError(
                f"not a text {kind} file (binary content)", source=source
            ) from None
        return text


def read_csv_table(path: str | PathLike[str]) -> CsvTable:
    """Read a delimited text table with its header.

    The delimiter (``,`` ``;`` or tab) is taken from the header line. Raises
    :class:`InputFileError` for a missing, empty, binary or header-only file.
    """
    file = check_readable(path)
    source = str(path)
    text = decode_text(file.read_bytes(), source)
    if not text.strip():
        raise InputFileError("file is empty", source=source)
    header_line = next(
        (ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")), None
    )
    if header_line is None:
        raise InputFileError("file has no header line", source=source)
    delimiter = max((",", ";", "\t"), key=header_line.count)
    if header_line.count(delimiter) == 0:
        delimiter = ","
    reader = csv.reader(io.StringIO(text, newline=""), delimiter=delimiter)
    header: list[str] | None = None
    rows: list[tuple[int, tuple[str, ...]]] = []
    for cells in reader:
        line_number = reader.line_num
        if not cells or all(not c.strip() for c in cells):
            continue
        if cells[0].lstrip().startswith("#"):
            continue
        if header is None:
            header = cells
            continue
        rows.append((line_number, tuple(cells)))
    assert header is not None
    columns = []
    for i, raw in enumerate(header):
        name, unit = normalise_name(raw)
        columns.append(Column(index=i, header=raw, name=name, unit=unit))
    seen: dict[str, str] = {}
    for column in columns:
        key = column.name if column.unit is None else f"{column.name}_{column.unit}"
        if key and key in seen:
            raise InputFileError(
                f"column '{column.header.strip()}' appears twice in the header",
                source=source,
                where="row 1",
            )
        seen[key] = column.header
    if not rows:
        raise InputFileError("no data rows after the header", source=source)
    return CsvTable(
        source=source, columns=tuple(columns), rows=tuple(rows), delimiter=delimiter
    )


def length_factor(
    table: CsvTable, column: Column, units: str, *, where: str = "row 1"
) -> float:
    """Factor converting ``column`` to metres.

    A unit in the column name (``x_m``, ``Elevation (ft)``) wins over ``units``
    (the file says what it holds); ``units`` applies to columns without one.
    """
    flag = units_factor(units)
    if column.unit is None or column.unit == "deg":
        return flag
    if column.unit not in LENGTH_UNITS:
        raise InputFileError(
            f"column '{column.header.strip()}': unknown unit '{column.unit}'",
            source=table.source,
            where=where,
        )
    return LENGTH_UNITS[column.unit]


def units_factor(units: str) -> float:
    """Metres per unit for the ``--units`` option (``m`` or ``ft``, international)."""
    if units not in ("m", "ft"):
        raise ArgumentError(
            f"units must be 'm' or 'ft', not '{units}'", source="--units"
        )
    return LENGTH_UNITS[units]
