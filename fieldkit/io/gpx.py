"""GPX 1.0 / 1.1 waypoints in and out.

Reads with the standard-library XML parser and matches elements by local name, so both
namespaces (``http://www.topografix.com/GPX/1/0`` and ``.../1/1``), files without a
namespace, a UTF-8 byte-order mark and vendor ``<extensions>`` all work.

Which points are read
    ``points="waypoints"`` (default) reads ``<wpt>``: mapped impacts are waypoints. A
    file without waypoints raises an error that says how many track and route points it
    has. ``points="route"`` reads ``<rtept>`` of one route, ``points="track"`` reads
    ``<trkpt>`` of one track (its segments in order: a segment break is the receiver
    losing its fix on the same walk), and ``points="auto"`` takes waypoints, else route
    points, else track points.

One track, one path
    A file with several tracks (or routes) that have points is several paths. They
    are never joined into one path (that would invent a flight from the end of one
    track to the start of the next): reading it raises an error listing the tracks,
    and ``track=`` (``gpx_track`` of :func:`fieldkit.io.impacts.read_impacts`) picks
    one, by its ``<name>`` or by its number in the file (1 = first). Reduce the others
    with their own runs and path ids. Empty tracks are ignored.

Names
    A point without ``<name>`` is called ``wpt7`` / ``rtept7`` / ``trkpt7`` (1-based
    position among points of its kind).

Heights
    ``<ele>`` is kept as given (usually metres above sea level from the receiver's geoid
    model; GPX does not say) and never converted. A missing ``<ele>`` gives NaN here;
    :func:`fieldkit.io.impacts.read_impacts` refuses it and names the waypoint.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree
from os import PathLike
from xml.sax.saxutils import escape, quoteattr

import pandas as pd

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.csv_table import check_readable, encoding_problem, finite_number
from fieldkit.outputs import OutputSet, write_text

GPX_HEIGHT_REFERENCE = (
    "GPX <ele> as given (usually above sea level); no geoid conversion"
)

GPX_11_NAMESPACE = "http://www.topografix.com/GPX/1/1"
_KINDS = {"waypoints": "wpt", "route": "rtept", "track": "trkpt"}
COLUMNS = ("point", "lat_deg", "lon_deg", "elev_m", "time", "type")


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _child_text(element: ElementTree.Element, name: str) -> str | None:
    for child in element:
        if _local(child.tag) == name:
            return (child.text or "").strip()
    return None


def parse_gpx_root(path: str | PathLike[str]) -> ElementTree.Element:
    """Parse a GPX file and return its ``<gpx>`` root element.

    Raises :class:`InputFileError`: file missing or empty, UTF-16 ("save it as
    UTF-8"), binary ("not a GPX file"), a document type or entity declaration
    (``<!DOCTYPE``, ``<!ENTITY``: refused before parsing, so no entity is ever
    expanded), XML errors ("GPX is truncated or malformed (XML error at line N)"), or
    another root element.
    """
    file = check_readable(path)
    data = file.read_bytes()
    if not data.strip():
        raise InputFileError("file is empty", source=path)
    problem = encoding_problem(data)
    if problem and problem != "binary content":
        raise InputFileError(f"GPX is {problem}", source=path)
    head = data[:4096]
    stripped = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    if b"\x00" in head or not stripped.startswith(b"<"):
        raise InputFileError("not a GPX file (it does not start with XML)", source=path)
    for declaration in (b"<!DOCTYPE", b"<!ENTITY"):
        at = data.find(declaration)
        if at >= 0:
            line = data.count(b"\n", 0, at) + 1
            raise InputFileError(
                f"GPX declares {declaration.decode()}: document types and entities "
                "are not allowed in GPX (remove the declaration)",
                source=path,
                where=f"line {line}",
            )
    try:
        root = ElementTree.fromstring(data)
    except ElementTree.ParseError as error:
        line = error.position[0] if error.position else "?"
        raise InputFileError(
            f"GPX is truncated or malformed (XML error at line {line})", source=path
        ) from None
    if _local(root.tag) != "gpx":
        raise InputFileError(
            f"not a GPX file (root element is <{_local(root.tag)}>, not <gpx>)",
            source=path,
        )
    return root


def _collect(root: ElementTree.Element, kind: str) -> list[ElementTree.Element]:
    tag = _KINDS[kind]
    if kind == "waypoints":
        return [e for e in root if _local(e.tag) == tag]
    return [e for e in root.iter() if _local(e.tag) == tag]


_CONTAINERS = {"track": "trk", "route": "rte"}


def _groups(
    root: ElementTree.Element, kind: str
) -> list[tuple[str, list[ElementTree.Element]]]:
    """Each ``<trk>`` (or ``<rte>``) in file order: its name and its points."""
    out = []
    for element in root.iter():
        if _local(element.tag) != _CONTAINERS[kind]:
            continue
        points = [e for e in element.iter() if _local(e.tag) == _KINDS[kind]]
        out.append((_child_text(element, "name") or "", points))
    return out


def _one_group(
    root: ElementTree.Element,
    kind: str,
    track: str | None,
    path: str | PathLike[str],
) -> list[ElementTree.Element]:
    """The points of the one track/route to read (see "One track, one path")."""
    groups = _groups(root, kind)
    word = "track" if kind == "track" else "route"

    def label(i: int, count: bool = True) -> str:
        name, points = groups[i]
        named = f" '{name}'" if name else ""
        size = f" ({len(points)} points)" if count else ""
        return f"{word} {i + 1}{named}{size}"

    if track is not None:
        wanted = str(track).strip()
        matches = [i for i, (name, _) in enumerate(groups) if name == wanted]
        if not matches and wanted.isdigit() and 1 <= int(wanted) <= len(groups):
            matches = [int(wanted) - 1]
        if not matches:
            listed = ", ".join(label(i) for i in range(min(len(groups), 8)))
            raise ArgumentError(
                f"no {word} '{wanted}' in {path} (it has {len(groups)} {word}s: "
                f"{listed or 'none'})",
                source="gpx_track",
            )
        chosen = groups[matches[0]][1]
        if not chosen:
            raise InputFileError(
                f"{label(matches[0], count=False)} has no points", source=path
            )
        return chosen
    full = [i for i, (_, points) in enumerate(groups) if points]
    if len(full) > 1:
        listed = ", ".join(label(i) for i in full[:8])
        more = f" and {len(full) - 8} more" if len(full) > 8 else ""
        raise InputFileError(
            f"{len(full)} {word}s with points ({listed}{more}): each is its own path, "
            f"never joined into one; choose one with `gpx_track` (name or number) "
            "and reduce the others separately",
            source=path,
        )
    return groups[full[0]][1] if full else []


def read_gpx_waypoints(
    path: str | PathLike[str], *, points: str = "waypoints", track: str | None = None
) -> pd.DataFrame:
    """Read GPX points into a table.

    Parameters
    ----------
    path
        GPX 1.0 or 1.1 file.
    points
        ``"waypoints"`` (default), ``"route"``, ``"track"`` or ``"auto"`` (see module
        docstring).
    track
        The track (or route) to read when ``points`` selects tracks (routes): its
        ``<name>`` or its number in the file (1 = first). Needed when the file has
        several with points.

    Returns
    -------
    pandas.DataFrame
        Columns ``point`` (str), ``lat_deg``, ``lon_deg``, ``elev_m`` (NaN where the
        point has no ``<ele>``), ``time`` (UTC timestamps, NaT where absent), ``type``
        (the GPX ``<type>`` classification, e.g. a slope material; NaN where absent),
        in file order.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> frame = pd.DataFrame({"point": ["A1"], "lat_deg": [49.1], "lon_deg": [-117.2],
    ...                       "elev_m": [1510.25]})
    >>> _ = write_gpx_waypoints(folder / "a.gpx", frame)
    >>> read_gpx_waypoints(folder / "a.gpx")[["point", "elev_m"]].to_dict("records")
    [{'point': 'A1', 'elev_m': 1510.25}]
    """
    if points not in (*_KINDS, "auto"):
        raise ArgumentError(
            f"points must be one of waypoints, route, track, auto (not '{points}')",
            source="gpx_points",
        )
    root = parse_gpx_root(path)
    counts = {kind: len(_collect(root, kind)) for kind in _KINDS}
    kind = points
    if points == "auto":
        kind = next(
            (k for k in ("waypoints", "route", "track") if counts[k]), "waypoints"
        )
    if track is not None and kind == "waypoints":
        raise ArgumentError(
            "`gpx_track` picks one track or route; waypoints are read as one path "
            "(ask for track or route points with `gpx_points`)",
            source="gpx_track",
        )
    if kind == "waypoints" or not counts[kind]:
        elements = _collect(root, kind)
    else:
        elements = _one_group(root, kind, track, path)
    if not elements:
        if points == "waypoints":
            raise InputFileError(
                f"no waypoints (<wpt>) in this GPX (it has {counts['track']} track "
                f"points and {counts['route']} route points); impacts must be "
                "waypoints, or ask for track/route points explicitly (gpx_points=)",
                source=path,
            )
        raise InputFileError(
            f"no {kind} points (<{_KINDS[kind]}>) in this GPX "
            f"({counts['waypoints']} waypoints, {counts['route']} route points, "
            f"{counts['track']} track points)",
            source=path,
        )
    tag = _KINDS[kind]
    records = []
    for number, element in enumerate(elements, start=1):
        name = _child_text(element, "name") or f"{tag}{number}"
        where = f"{'waypoint' if tag == 'wpt' else tag} {number} ('{name}')"
        lat = _coordinate(element, "lat", -90.0, 90.0, path, where)
        lon = _coordinate(element, "lon", -180.0, 180.0, path, where)
        ele_text = _child_text(element, "ele")
        elev = math.nan
        if ele_text:
            elev = finite_number(ele_text, "<ele>", source=path, where=where)
        time_text = _child_text(element, "time") or None
        type_text = _child_text(element, "type") or None
        records.append((name, lat, lon, elev, time_text, where, type_text))
    frame = pd.DataFrame(
        {
            "point": pd.Series([r[0] for r in records], dtype="str"),
            "lat_deg": [r[1] for r in records],
            "lon_deg": [r[2] for r in records],
            "elev_m": [r[3] for r in records],
        }
    )
    frame["time"] = _parse_times([r[4] for r in records], [r[5] for r in records], path)
    frame["type"] = pd.Series([r[6] for r in records], dtype="str")
    return frame


def _coordinate(
    element: ElementTree.Element,
    name: str,
    low: float,
    high: float,
    path: str | PathLike[str],
    where: str,
) -> float:
    text = element.get(name)
    if text is None:
        raise InputFileError(f"no {name} attribute", source=path, where=where)
    try:
        value = float(text)
    except ValueError:
        raise InputFileError(
            f"{name} '{text}' is not a number", source=path, where=where
        ) from None
    if not low <= value <= high:
        raise InputFileError(
            f"{name} {text} is outside [{low:g}, {high:g}]", source=path, where=where
        )
    return value


def _parse_times(
    texts: list[str | None], wheres: list[str], path: str | PathLike[str]
) -> pd.Series:
    try:
        return pd.Series(pd.to_datetime(texts, utc=True, format="ISO8601"))
    except (ValueError, TypeError):
        for text, where in zip(texts, wheres, strict=True):
            if text is None:
                continue
            try:
                pd.to_datetime(text, utc=True, format="ISO8601")
            except (ValueError, TypeError):
                raise InputFileError(
                    f"<time> '{text}' is not an ISO 8601 time", source=path, where=where
                ) from None
        raise  # pragma: no cover - every single value parsed


def _format_time(value: object) -> str | None:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return None
    stamp = pd.Timestamp(value)
    if pd.isna(stamp):
        return None
    stamp = (
        stamp.tz_localize("UTC") if stamp.tzinfo is None else stamp.tz_convert("UTC")
    )
    text = stamp.strftime("%Y-%m-%dT%H:%M:%S")
    if stamp.microsecond:
        text += f".{stamp.microsecond:06d}".rstrip("0")
    return text + "Z"


def gpx_waypoints_text(frame: pd.DataFrame, *, creator: str = "fieldkit") -> str:
    """GPX 1.1 document with one ``<wpt>`` per row of ``frame``.

    ``frame`` needs ``point``, ``lat_deg``, ``lon_deg``; ``elev_m``, ``time`` and
    ``type`` (or ``material``, written as ``<type>``) are optional (missing values are
    left out). Latitude and longitude get 9
    decimals (0.1 mm), elevation 3 (1 mm).
    """
    for column in ("point", "lat_deg", "lon_deg"):
        if column not in frame.columns:
            raise ArgumentError(f"waypoint table needs a '{column}' column")
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<gpx version="1.1" creator={quoteattr(creator)} xmlns="{GPX_11_NAMESPACE}" '
        'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" '
        f'xsi:schemaLocation="{GPX_11_NAMESPACE} {GPX_11_NAMESPACE}/gpx.xsd">',
    ]
    has_elev = "elev_m" in frame.columns
    has_time = "time" in frame.columns
    type_column = next((c for c in ("type", "material") if c in frame.columns), None)
    for row in frame.itertuples(index=False):
        lat = float(row.lat_deg)
        lon = float(row.lon_deg)
        if not (math.isfinite(lat) and math.isfinite(lon)):
            raise ArgumentError(f"waypoint '{row.point}' has no latitude/longitude")
        lines.append(f'  <wpt lat="{lat:.9f}" lon="{lon:.9f}">')
        if has_elev and math.isfinite(float(row.elev_m)):
            lines.append(f"    <ele>{float(row.elev_m):.3f}</ele>")
        if has_time:
            text = _format_time(row.time)
            if text:
                lines.append(f"    <time>{text}</time>")
        lines.append(f"    <name>{escape(str(row.point))}</name>")
        if type_column is not None:
            value = getattr(row, type_column)
            if isinstance(value, str) and value:
                lines.append(f"    <type>{escape(value)}</type>")
        lines.append("  </wpt>")
    lines.append("</gpx>")
    return "\n".join(lines) + "\n"


def write_gpx_waypoints(
    path: str | PathLike[str],
    frame: pd.DataFrame,
    *,
    creator: str = "fieldkit",
    outputs: OutputSet | None = None,
) -> None:
    """Write ``frame`` as GPX 1.1 waypoints (:func:`gpx_waypoints_text`).

    Into ``outputs`` when given (written when it commits), else at once.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "s.gpx"
    >>> write_gpx_waypoints(target, pd.DataFrame(
    ...     {"point": ["S1"], "lat_deg": [49.0], "lon_deg": [-117.0],
    ...      "elev_m": [1500.0]}))
    >>> "<ele>1500.000</ele>" in target.read_text()
    True
    """
    write_text(path, gpx_waypoints_text(frame, creator=creator), outputs)
