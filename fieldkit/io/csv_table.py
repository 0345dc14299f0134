"""Delimited text tables (comma, semicolon, tab or space separated), rows numbered.

Every delimited-text reader in :mod:`fieldkit.io` goes through this module: the
field-data importers (GPX/CSV points, fieldbook, stations, trees) through
:func:`read_csv_table`, the tracking-program readers (OSP Tracker, Kinovea) through
:func:`read_text`, :func:`detect_delimiter`, :func:`split_row` and
:func:`parse_number`. So they all agree on how a file is decoded, which separator it
uses, how a decimal comma is read, what unit a column name carries, what "row 7"
means and what a bad file says.

Row numbers are file line numbers: the header of a plain table is row 1, its first
data row is row 2 (equal to the line number in a text editor unless a quoted cell
spans lines). Blank lines are skipped but still counted; :func:`read_csv_table`
also skips lines starting with ``#``.

Numbers may be written in the user's locale: ``1.25`` or ``1,25`` (and ``1.2E-3`` or
``1,2E-3``, ``1.234,5``). With a tab, semicolon or space separator a comma can only be
a decimal mark; with a comma separator it cannot be.
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

#: Spelled-out unit names and the short name they stand for.
_UNIT_SPELLINGS: dict[str, str] = {
    "meter": "m",
    "meters": "m",
    "metre": "m",
    "metres": "m",
    "feet": "ft",
    "foot": "ft",
    "pixel": "px",
    "pixels": "px",
}

#: Separators in order of preference when a header line uses two equally often.
_SEPARATORS = ("\t", ";", ",")

#: ``1.234,5`` (dots grouping thousands, a decimal comma).
_GROUPED_DECIMAL_COMMA = re.compile(
    r"^[+-]?\d{1,3}(?:\.\d{3})+(?:,\d*)?(?:[eE][+-]?\d+)?$"
)

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
    return text, unit_name(unit)


def unit_name(text: str | None) -> str | None:
    """The short name of a unit written in a header (``metres`` -> ``m``).

    Examples
    --------
    >>> unit_name("Metres"), unit_name(" pixels "), unit_name("°"), unit_name("")
    ('m', 'px', 'deg', None)
    """
    if not text:
        return None
    unit = text.strip().lower().replace("°", "deg")
    return _UNIT_SPELLINGS.get(unit, unit)


def detect_delimiter(header: str, default: str = ",") -> str:
    """The separator the header line uses most: tab, semicolon or comma.

    Ties go to tab, then semicolon (a comma may also be text or a decimal mark).
    ``default`` when the line has none of them (``" "``: split on white space).

    Examples
    --------
    >>> detect_delimiter("t\\tx\\ty"), detect_delimiter("x;y,z")
    ('\\t', ';')
    >>> detect_delimiter("t x y", default=" ")
    ' '
    """
    best = max(_SEPARATORS, key=header.count)
    return best if header.count(best) else default


def split_row(line: str, delimiter: str) -> list[str]:
    """Cells of one line, honouring double quotes (RFC 4180); ``" "``: white space."""
    if delimiter == " ":
        return line.split()
    return next(csv.reader(io.StringIO(line), delimiter=delimiter), [])


def parse_number(cell: str, delimiter: str) -> float:
    """A number in either locale; empty cells are NaN. Raises ValueError otherwise.

    A comma is a decimal mark unless the separator is a comma; dots then may only
    group thousands (``1.234,5``).

    Examples
    --------
    >>> parse_number("1,25E-3", "\\t"), parse_number("", ";"), parse_number("-0.5", ",")
    (0.00125, nan, -0.5)
    >>> parse_number("1.234,5", ";")
    1234.5
    """
    text = cell.strip().strip('"').replace("\u2212", "-")
    if not text:
        return math.nan
    if delimiter != "," and "," in text:
        if "." in text:
            if not _GROUPED_DECIMAL_COMMA.match(text):
                raise ValueError(f"could not convert string to float: {cell!r}")
            text = text.replace(".", "")
        text = text.replace(",", ".")
    return float(text)


def finite_number(
    text: str,
    label: str,
    *,
    delimiter: str = ",",
    source: str | PathLike[str],
    where: str | None,
) -> float:
    """``text`` as a finite number (:func:`parse_number`), else a one-line error.

    The error reads ``<label> '<text>' is not a number`` (or ``a finite number``).

    Examples
    --------
    >>> finite_number("1,5", "<ele>", delimiter=";", source="a.csv", where="row 2")
    1.5
    """
    try:
        value = parse_number(text, delimiter)
    except ValueError:
        raise InputFileError(
            f"{label} '{text}' is not a number", source=source, where=where
        ) from None
    if not math.isfinite(value):
        raise InputFileError(
            f"{label} '{text}' is not a finite number", source=source, where=where
        )
    return value


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

    def header_text(self) -> str:
        """The header cells as written, comma separated (for error messages)."""
        return ", ".join(column.header.strip() for column in self.columns)

    def require(
        self, aliases: dict[str, tuple[str, ...]], needs: str
    ) -> dict[str, Column]:
        """The column for each key of ``aliases``; raise naming the keys not found.

        ``needs`` begins the message, e.g. ``"stations CSV needs columns station,
        lat"``; the keys not found and the header follow it.
        """
        found = {key: self.find(names) for key, names in aliases.items()}
        missing = [key for key, column in found.items() if column is None]
        if missing:
            raise InputFileError(
                f"{needs}; missing {', '.join(missing)} (have: {self.header_text()})",
                source=self.source,
                where="row 1",
            )
        return found  # type: ignore[return-value]

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
        return finite_number(
            text,
            f"column '{column.header.strip()}':",
            delimiter=self.delimiter,
            source=self.source,
            where=place,
        )


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


def read_text(path: str | PathLike[str], kind: str = "CSV") -> str:
    """The text of a readable, non-binary, non-blank file; one-line errors otherwise."""
    file = check_readable(path)
    text = decode_text(file.read_bytes(), str(path), kind)
    if not text.strip():
        raise InputFileError("file is empty", source=str(path))
    return text


def numbered_lines(text: str) -> list[tuple[int, str]]:
    """The non-blank lines of ``text``, each with its line number (from 1)."""
    return [(n, line) for n, line in enumerate(text.splitlines(), 1) if line.strip()]


def read_csv_table(path: str | PathLike[str]) -> CsvTable:
    """Read a delimited text table with its header.

    The delimiter (``,`` ``;`` or tab) is taken from the header line. Raises
    :class:`InputFileError` for a missing, empty, binary or header-only file.
    """
    source = str(path)
    text = read_text(path)
    header_line = next(
        (ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")), None
    )
    if header_line is None:
        raise InputFileError("file has no header line", source=source)
    delimiter = detect_delimiter(header_line)
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
    """Metres per unit of ``units`` (``m`` or ``ft``, international)."""
    if units not in ("m", "ft"):
        raise ArgumentError(f"units must be 'm' or 'ft', not '{units}'", source="units")
    return LENGTH_UNITS[units]
