"""Delimited text tables (comma, semicolon, tab or space separated), rows numbered.

Every delimited-text reader in :mod:`fieldkit.io` goes through this module: the
field-data importers (GPX/CSV points, fieldbook, stations, trees) through
:func:`read_csv_table`, the tracking-program readers (OSP Tracker, Kinovea) through
:func:`read_text`, :func:`detect_delimiter`, :func:`split_row` and
:func:`parse_number`. So they all agree on how a file is decoded, which separator it
uses, how a decimal comma is read, what unit a column name carries, what "row 7"
means and what a bad file says.

Row numbers are file line numbers: the header of a plain table is row 1, its first
data row is row 2 (a row whose quoted cell spans lines is numbered by the line it
starts on). Blank lines are skipped but still counted; :func:`read_csv_table` also
skips lines starting with ``#``.

Numbers may be written in the user's locale: ``1.25`` or ``1,25`` (and ``1.2E-3`` or
``1,2E-3``, ``1.234,5``). With a tab, semicolon or space separator a comma can only be
a decimal mark; with a comma separator it cannot be: ``1,25`` there splits into two
cells, which the cell count catches (:func:`check_cell_count`), and a quoted
``"1,25"`` is refused as ambiguous (``1,250`` may be 1250).

Nothing is read silently wrong (each check is made here, once):

* every row has as many cells as the header (:func:`check_cell_count`). Empty cells
  after the last column -- a trailing separator, ``1,2,3,`` under a three-column
  header, as spreadsheets write -- carry nothing and are dropped; any other extra or
  missing cell is an error naming the row and both counts. Tracking-program exports
  may leave cells out at the end of a row (a value not tracked), which then read as
  empty; they may not have extra cells either;
* two columns that give one quantity (``x_m`` and ``x_ft``; ``elev`` and
  ``elevation_m``) are an error naming both (:meth:`CsvTable.find`);
* a length column whose name carries no unit needs ``units`` (:func:`length_factor`);
* quotes must pair up (an unclosed quote is reported at the row it opens in), no
  line may exceed :data:`MAX_LINE_CHARS` characters (nor a cell Python's csv field
  limit), and UTF-16, binary and non-UTF-8 JSON files are refused in one line
  (:func:`decode_text`, :func:`read_json`).
"""

from __future__ import annotations

import csv
import io
import json
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

    The error reads ``<label> '<text>' is not a number`` (or ``a finite number``);
    a decimal comma in a comma-separated file says so.

    Examples
    --------
    >>> finite_number("1,5", "<ele>", delimiter=";", source="a.csv", where="row 2")
    1.5
    """
    try:
        value = parse_number(text, delimiter)
    except ValueError:
        if delimiter == "," and "," in text:
            raise InputFileError(
                f"{label} '{text}' has a comma in a comma-separated file (a decimal "
                "comma, or thousands?): write the number with a decimal point, or "
                "separate the columns with ; or tab",
                source=source,
                where=where,
            ) from None
        raise InputFileError(
            f"{label} '{text}' is not a number", source=source, where=where
        ) from None
    if not math.isfinite(value):
        raise InputFileError(
            f"{label} '{text}' is not a finite number", source=source, where=where
        )
    return value


def check_cell_count(
    cells: list[str],
    header: list[str],
    delimiter: str,
    *,
    source: str,
    where: str,
    allow_short: bool = False,
) -> list[str]:
    """``cells`` of one row, checked against the ``header`` cells.

    Empty cells after the last column (a trailing separator) are dropped. More cells
    than columns is an error naming both counts (with a comma separator, a decimal
    comma is the usual cause and the message says so); so is fewer, unless
    ``allow_short`` (tracking exports leave untracked values out at the end).

    Examples
    --------
    >>> check_cell_count(["1", "2", "3", ""], ["a", "b", "c"], ",", source="f",
    ...                  where="row 2")
    ['1', '2', '3']
    >>> check_cell_count(["1", "25", "3"], ["a", "b"], ",", source="f",
    ...                  where="row 2")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.InputFileError: f: row 2: 3 cells for 2 columns (a, b): decimal...
    """
    n = len(header)
    if len(cells) > n and not any(c.strip() for c in cells[n:]):
        cells = cells[:n]
    if len(cells) == n or (allow_short and len(cells) < n):
        return cells
    names = ", ".join(h.strip() for h in header)
    counts = f"{len(cells)} cells for {n} columns ({names})"
    if len(cells) > n:
        hint = (
            "decimal commas with a comma separator split numbers (1,25); write "
            "1.25, or separate the columns with ; or tab"
            if delimiter == ","
            else "a value holds the separator; quote it or remove it"
        )
    else:
        hint = "a value is missing; leave its cell empty (two separators) instead"
    raise InputFileError(f"{counts}: {hint}", source=source, where=where)


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

    def find(self, aliases: tuple[str, ...], what: str | None = None) -> Column | None:
        """The column whose normalised name is in ``aliases``, or None.

        Two such columns (``x_m`` and ``x_ft``, ``lat`` and ``latitude``) are an
        error naming both: which one holds the values cannot be guessed. ``what``
        names the quantity in that message (default: the first alias).
        """
        found = [column for column in self.columns if column.name in aliases]
        if len(found) > 1:
            first, second = (f"'{c.header.strip()}'" for c in found[:2])
            raise InputFileError(
                f"columns {first} and {second} both give {what or aliases[0]}; keep "
                "one (delete or rename the other)",
                source=self.source,
                where="row 1",
            )
        return found[0] if found else None

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
        found = {key: self.find(names, key) for key, names in aliases.items()}
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


#: Longest line any text reader accepts: Python's csv field limit (131072), so no
#: cell of an accepted line can exceed it. Field data lines are a few hundred long.
MAX_LINE_CHARS = 131_072


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


def encoding_problem(data: bytes) -> str | None:
    """Why ``data`` is not UTF-8 or Latin-1 text we can read, or None.

    UTF-16 and UTF-32 (by their byte-order mark, or NUL bytes in every other byte)
    are named, with the fix; other NUL bytes mean a binary file.

    Examples
    --------
    >>> encoding_problem("x,z\\n1,2\\n".encode("utf-16-le"))
    'UTF-16 encoded; save it as UTF-8'
    >>> encoding_problem(b"PK\\x03\\x04" + bytes(40)), encoding_problem(b"x,z")
    ('binary content', None)
    """
    if data.startswith((b"\xff\xfe\x00\x00", b"\x00\x00\xfe\xff")):
        return "UTF-32 encoded; save it as UTF-8"
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        return "UTF-16 encoded; save it as UTF-8"
    sample = data[:4096]
    if b"\x00" not in sample:
        return None
    half = max(len(sample) // 2, 1)
    even = sample[0::2].count(0) / half
    odd = sample[1::2].count(0) / half
    if max(even, odd) > 0.3 and min(even, odd) < 0.02:
        return "UTF-16 encoded; save it as UTF-8"
    return "binary content"


def decode_text(data: bytes, source: str, kind: str = "CSV") -> str:
    """Decode file bytes as text (UTF-8 with or without BOM, else Latin-1).

    Raises for UTF-16/UTF-32 (saying so) and if the bytes look binary (NUL bytes or
    mostly non-printable).
    """
    problem = encoding_problem(data)
    if problem == "binary content":
        raise InputFileError(f"not a text {kind} file (binary content)", source=source)
    if problem:
        raise InputFileError(problem, source=source)
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
    """The text of a readable, non-binary, non-blank file; one-line errors otherwise.

    A line longer than :data:`MAX_LINE_CHARS` is an error naming its row.
    """
    file = check_readable(path)
    text = decode_text(file.read_bytes(), str(path), kind)
    if not text.strip():
        raise InputFileError("file is empty", source=str(path))
    if len(text) > MAX_LINE_CHARS:
        for number, line in enumerate(text.splitlines(), 1):
            if len(line) > MAX_LINE_CHARS:
                raise InputFileError(
                    f"line is {len(line)} characters long (at most {MAX_LINE_CHARS}): "
                    f"not a {kind} file",
                    source=str(path),
                    where=f"row {number}",
                )
    return text


def read_json(path: str | PathLike[str], kind: str = "JSON") -> object:
    """The parsed content of a JSON file; one-line errors for every bad file.

    JSON is UTF-8 by its standard (a BOM is allowed): UTF-16, binary and other
    encodings are refused, as are syntax errors (naming the line) and nesting too
    deep for Python's parser.
    """
    file = check_readable(path)
    data = file.read_bytes()
    problem = encoding_problem(data)
    if problem:
        raise InputFileError(f"not a {kind} file ({problem})", source=path)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputFileError(
            f"not UTF-8 (byte 0x{data[exc.start]:02x}); JSON must be UTF-8: save it "
            "as UTF-8",
            source=path,
            where=f"line {line}",
        ) from None
    if not text.strip():
        raise InputFileError("file is empty", source=path)
    try:
        return parse_json(text, str(path))
    except RecursionError:
        raise InputFileError(
            f"JSON nested too deeply to be a {kind} file", source=path
        ) from None


class _DuplicateKey(dict):
    """An object of parsed JSON that had ``key`` twice (:func:`parse_json`)."""

    key: str


def parse_json(text: str, source: str) -> object:
    """Parse JSON text, refusing a key given twice in one object, at any depth.

    Python's reader keeps the last of two equal keys, so ``{"e_n": 0.75, "e_n":
    4.5}`` would silently be 4.5; here it is an error naming the key's path
    (``materials.rock.e_n given twice``). ``NaN`` and ``Infinity`` are parsed, for
    the reader of each field to refuse by name.

    Raises
    ------
    InputFileError
        Not valid JSON (naming the line), or a key given twice (naming its path).

    Examples
    --------
    >>> parse_json('{"a": {"b": [1, {"c": 2}]}}', "m.json")
    {'a': {'b': [1, {'c': 2}]}}
    >>> parse_json('{"a": {"b": [1, {"c": 2, "c": 3}]}}', "m.json")
    Traceback (most recent call last):
    ...
    fieldkit.errors.InputFileError: m.json: a.b[1].c given twice: give each key once
    """
    found: list[_DuplicateKey] = []

    def pairs_hook(pairs: list[tuple[str, object]]) -> dict:
        keys = [key for key, _ in pairs]
        if len(set(keys)) == len(keys):
            return dict(pairs)
        duplicate = _DuplicateKey(pairs)
        duplicate.key = next(k for i, k in enumerate(keys) if k in keys[:i])
        found.append(duplicate)
        return duplicate

    try:
        data = json.loads(text, object_pairs_hook=pairs_hook)
    except json.JSONDecodeError as exc:
        raise InputFileError(
            f"not valid JSON ({exc.msg})", source=source, where=f"line {exc.lineno}"
        ) from None
    if found:
        path = _json_path(data, found[0])
        raise InputFileError(
            f"{path}{'.' if path else ''}{found[0].key} given twice: give each key "
            "once",
            source=source,
        )
    return data


def _json_path(data: object, target: object) -> str:
    """The path (``a.b[1]``) of the object ``target`` inside ``data`` (no recursion:
    a deep file cannot overflow the stack)."""
    stack: list[tuple[object, str]] = [(data, "")]
    while stack:
        item, path = stack.pop()
        if item is target:
            return path
        if isinstance(item, dict):
            stack.extend(
                (value, f"{path}.{key}" if path else str(key))
                for key, value in item.items()
            )
        elif isinstance(item, list):
            stack.extend((value, f"{path}[{i}]") for i, value in enumerate(item))
    return ""


def numbered_lines(text: str) -> list[tuple[int, str]]:
    """The non-blank lines of ``text``, each with its line number (from 1)."""
    return [(n, line) for n, line in enumerate(text.splitlines(), 1) if line.strip()]


def _quote_error(error: csv.Error, start: int, end: int) -> str:
    """A one-line reason for a csv error in the row from line ``start`` to ``end``."""
    spans = end > start
    if "field larger than field limit" in str(error):
        if spans:
            return (
                f"a quoted cell opened in this row runs on past line {end}, longer "
                f"than {csv.field_size_limit()} characters: a quote that never closes?"
            )
        return f"a cell is longer than {csv.field_size_limit()} characters"
    if "unexpected end of data" in str(error):
        return "a quote opened in this row never closes (the cell runs to the end)"
    closed = f" (the quoted cell closes on line {end})" if spans else ""
    return (
        f"text after a closing quote{closed}: a quote inside a quoted cell must be "
        'doubled ("")'
    )


def _rows(text: str, delimiter: str, source: str):
    """``(row number, cells)`` of every non-blank, non-comment row (strict quotes)."""
    lines = text.splitlines(keepends=True)
    kept = [
        line if line.strip() and not line.lstrip().startswith("#") else "\n"
        for line in lines
    ]
    reader = csv.reader(
        io.StringIO("".join(kept), newline=""), delimiter=delimiter, strict=True
    )
    end = 0
    while True:
        start = end + 1
        try:
            cells = next(reader)
        except StopIteration:
            return
        except csv.Error as error:
            raise InputFileError(
                _quote_error(error, start, reader.line_num),
                source=source,
                where=f"row {start}",
            ) from None
        end = reader.line_num
        if cells and any(c.strip() for c in cells):
            yield start, cells


def read_csv_table(
    path: str | PathLike[str], *, open_last: tuple[str, ...] = ()
) -> CsvTable:
    """Read a delimited text table with its header.

    The delimiter (``,`` ``;`` or tab) is taken from the header line. Every row must
    have as many cells as the header (:func:`check_cell_count`), except that a last
    column whose name is in ``open_last`` takes the extra cells of a row, re-joined
    (a TruPulse sentence written without quotes). Raises :class:`InputFileError` for
    a missing, empty, binary, UTF-16 or header-only file, bad quoting and ragged rows.
    """
    source = str(path)
    text = read_text(path)
    header_line = next(
        (
            ln
            for ln in text.splitlines()
            if ln.strip() and not ln.lstrip().startswith("#")
        ),
        None,
    )
    if header_line is None:
        raise InputFileError("file has no header line", source=source)
    delimiter = detect_delimiter(header_line)
    header: list[str] | None = None
    open_end: int | None = None
    rows: list[tuple[int, tuple[str, ...]]] = []
    for line_number, cells in _rows(text, delimiter, source):
        if header is None:
            while len(cells) > 1 and not cells[-1].strip():
                cells = cells[:-1]  # a trailing separator names no column
            header = cells
            last = normalise_name(header[-1])[0]
            open_end = len(header) - 1 if last and last in open_last else None
            continue
        if open_end is not None and len(cells) > len(header):
            cells = [*cells[:open_end], delimiter.join(cells[open_end:])]
        cells = check_cell_count(
            cells, header, delimiter, source=source, where=f"row {line_number}"
        )
        rows.append((line_number, tuple(cells)))
    if header is None:
        raise InputFileError("file has no header line", source=source)
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
    table: CsvTable, column: Column, units: str | None, *, where: str = "row 1"
) -> float:
    """Factor converting ``column`` to metres.

    A unit in the column name (``x_m``, ``Elevation (ft)``) wins over ``units``
    (the file says what it holds); ``units`` applies to columns without one. A
    column without a unit when ``units`` is None is an error saying how to fix it:
    metres and feet differ by a factor 3.28, so neither is assumed.
    """
    flag = units_factor(units) if units is not None else None
    if column.unit is None:
        if flag is None:
            header = column.header.strip()
            raise InputFileError(
                f"column '{header}' has no length unit: name it in the header "
                f"('{header}_m', '{header} (ft)') or give `units` (m or ft)",
                source=table.source,
                where=where,
            )
        return flag
    if column.unit not in LENGTH_UNITS:
        raise InputFileError(
            f"column '{column.header.strip()}': unknown length unit '{column.unit}' "
            f"(use {', '.join(LENGTH_UNITS)})",
            source=table.source,
            where=where,
        )
    return LENGTH_UNITS[column.unit]


#: Plan coordinates in a DEM's coordinate system (release and alignment files).
PLAN_X_ALIASES = ("x", "easting")
PLAN_Y_ALIASES = ("y", "northing")


def plan_columns(table: CsvTable, what: str) -> tuple[dict, dict]:
    """The ``x``, ``y`` plan-coordinate columns of ``table`` (a file of ``what``,
    e.g. ``"a release file"``) and each one's factor to metres.

    A DEM's coordinate system gives no default unit, so each column must name its
    length unit in the header (``x_m``, ``x_ft``); without one, an
    :class:`InputFileError` says how to name it (row 1).
    """
    found = table.require(
        {"x": PLAN_X_ALIASES, "y": PLAN_Y_ALIASES},
        f"{what} needs plan coordinates in columns x, y (e.g. x_m, y_m)",
    )
    for column in found.values():
        if column.unit is None:
            header = column.header.strip()
            raise InputFileError(
                f"column '{header}' has no length unit: name it in the header "
                f"('{header}_m', '{header}_ft'), in the DEM's coordinate system",
                source=table.source,
                where="row 1",
            )
    return found, {k: length_factor(table, c, None) for k, c in found.items()}


def units_factor(units: str) -> float:
    """Metres per unit of ``units`` (``m`` or ``ft``, international)."""
    if units not in ("m", "ft"):
        raise ArgumentError(f"units must be 'm' or 'ft', not '{units}'", source="units")
    return LENGTH_UNITS[units]
