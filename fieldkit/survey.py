"""The Survey: what a geologist brings back from a slope, in section coordinates.

One of the three data types of fieldkit (docs/architecture.md §1), beside
:class:`~fieldkit.track.Track` and :class:`~fieldkit.impact_table.ImpactTable`:

* :class:`PointSet` -- impact points along one fall path, in order of travel, with
  section coordinates (``x_m`` = cumulative plan distance, ``z_m`` = elevation) and,
  when known, geographic and projected coordinates;
* :class:`Stations` -- instrument stations (GPS positions) that rangefinder shots are
  taken from;
* :class:`TreeStrikes` -- scars on trees hit by the rock in flight, each tied to the
  flight it interrupted; :class:`TreeStrike` is one of them as the reduction uses it;
* :class:`Survey` -- the points of one path and the tree strikes on it: what
  :func:`fieldkit.reduce.pipeline.reduce_survey` reduces to an ImpactTable.

The readers in :mod:`fieldkit.io` build these; nothing here reads a file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import pandas as pd

from fieldkit.errors import InputFileError

#: Columns every PointSet frame has, in this order.
POINT_COLUMNS = ("point", "x_m", "z_m", "lat_deg", "lon_deg", "easting_m", "northing_m")
#: Columns a PointSet frame may add when the source has them.
OPTIONAL_COLUMNS = ("material", "slope_deg", "theta0_deg", "time")
#: Columns every TreeStrikes frame has, in this order.
TREE_COLUMNS = (
    "after_impact",
    "horizontal_distance_m",
    "strike_height_m",
    "ground_z_m",
    "species",
    "dbh_mm",
    "tree",
    "row",
    "offset_m",
)


@dataclass(frozen=True)
class PointSet:
    """Points along one fall path, in order of travel.

    Attributes
    ----------
    frame
        One row per point: ``point`` (str), ``x_m``, ``z_m`` (section coordinates
        [m]), ``lat_deg``, ``lon_deg`` (WGS 84), ``easting_m``, ``northing_m`` (in
        ``crs``; NaN where unknown), optionally ``material``, ``slope_deg`` (surveyed
        ground dip, positive descending toward +x [deg]), ``theta0_deg`` (measured
        restitution angle [deg]) and ``time`` (UTC).
    source
        The file the points came from.
    crs
        ``"section"`` when only section coordinates are known, else the CRS of
        ``easting_m``/``northing_m``, e.g. ``"EPSG:32611"``.
    height_reference
        What ``z_m`` is measured from, in words (heights are never converted).
    notes
        Things the reader decided or noticed that a user should know.
    """

    frame: pd.DataFrame
    source: str
    crs: str = "section"
    height_reference: str = "as given"
    notes: tuple[str, ...] = field(default_factory=tuple)

    def __len__(self) -> int:
        return len(self.frame)

    @property
    def names(self) -> list[str]:
        """Point names in order."""
        return [str(name) for name in self.frame["point"]]


@dataclass(frozen=True)
class Stations:
    """Instrument stations that rangefinder shots are taken from.

    Attributes
    ----------
    frame
        ``station`` (str), ``lat_deg``, ``lon_deg``, ``elev_m`` (NaN when a GPX
        waypoint has no ``<ele>``).
    source
        The file.
    height_reference
        What ``elev_m`` is measured from, in words.
    """

    frame: pd.DataFrame
    source: str
    height_reference: str

    def lookup(self, station: str) -> pd.Series | None:
        """The row of ``station``, or None."""
        match = self.frame[self.frame["station"] == station]
        return None if match.empty else match.iloc[0]


@dataclass(frozen=True)
class TreeStrikes:
    """Tree strikes in a fall path, as read from a tree file.

    Attributes
    ----------
    frame
        ``after_impact`` (str), ``horizontal_distance_m`` (plan distance from that
        impact toward the next [m]), ``strike_height_m`` (scar above the ground at the
        tree [m]), ``ground_z_m`` (NaN unless given), ``species`` (str or NA),
        ``dbh_mm`` (NaN unless given), ``tree`` (id from the file or "row N"),
        ``row`` (row number in the file, for messages), ``offset_m`` (plan distance
        of a lat/lon tree from the flight line, NaN otherwise).
    source
        The file.
    notes
        Decisions worth telling the user.
    """

    frame: pd.DataFrame
    source: str
    notes: tuple[str, ...] = field(default_factory=tuple)

    def __len__(self) -> int:
        return len(self.frame)


@dataclass(frozen=True)
class TreeStrike:
    """A tree struck during the flight that leaves impact ``after_impact``.

    Attributes
    ----------
    after_impact
        Name of the launch impact.
    distance_m
        Horizontal distance of the tree from that impact [m].
    height_m
        Height of the strike (the boulder's centre, lumped mass) above the ground [m].
    ground_z_m
        Ground elevation at the tree [m] (section datum).
    where
        Location in the tree file for messages, e.g. ``"row 4"``.
    """

    after_impact: str
    distance_m: float
    height_m: float
    ground_z_m: float
    where: str

    @property
    def z_m(self) -> float:
        """Elevation of the strike (ground plus strike height) [m]."""
        return self.ground_z_m + self.height_m


@dataclass(frozen=True)
class Survey:
    """One surveyed fall path: its impact points and the tree strikes on it.

    Attributes
    ----------
    points
        The impacts in order of travel (first = source, last = where it stopped).
    trees
        Tree strikes on the path's flights, or None when no tree file was given
        (``tree_strike`` then stays unknown in the ImpactTable, not False).
    """

    points: PointSet
    trees: TreeStrikes | None = None

    @property
    def source(self) -> str:
        """The points file."""
        return self.points.source

    def trees_by_launch(self) -> dict[str, TreeStrike]:
        """Tree strikes keyed by the launch impact of the flight they fix.

        Where ``ground_z_m`` is not given, the ground at the tree is interpolated on
        the straight line between the two impacts. Two strikes on one flight
        over-determine the parabola and raise :class:`InputFileError` naming both rows.

        Examples
        --------
        >>> frame = pd.DataFrame({"point": ["A", "B"], "x_m": [0.0, 10.0],
        ...                       "z_m": [10.0, 0.0]})
        >>> trees = pd.DataFrame({"after_impact": ["A"], "horizontal_distance_m": [4.0],
        ...                       "strike_height_m": [2.0], "ground_z_m": [np.nan]})
        >>> survey = Survey(PointSet(frame, "p.csv"), TreeStrikes(trees, "t.csv"))
        >>> survey.trees_by_launch()["A"].z_m
        8.0
        """
        if self.trees is None:
            return {}
        frame = self.points.frame
        points = self.points.names
        x_m = frame["x_m"].to_numpy(float)
        z_m = frame["z_m"].to_numpy(float)
        source = self.trees.source
        index = {name: i for i, name in enumerate(points)}
        out: dict[str, TreeStrike] = {}
        for i, row in enumerate(self.trees.frame.itertuples(index=False)):
            number = getattr(row, "row", None)
            where = f"row {int(number) if number is not None else i + 2}"
            key = str(row.after_impact)
            j = index.get(key)
            if j is None or j == len(points) - 1:
                what = "is not a point of" if j is None else "is the last point of"
                raise InputFileError(
                    f"tree strike after impact {key}, which {what} the path "
                    "(no flight leaves it)",
                    source=source,
                    where=where,
                )
            distance = float(row.horizontal_distance_m)
            ground = float(row.ground_z_m)
            if not math.isfinite(ground):
                dx = x_m[j + 1] - x_m[j]
                ground = (
                    float(z_m[j] + (z_m[j + 1] - z_m[j]) * distance / dx)
                    if dx > 0
                    else math.nan
                )
            if key in out:
                raise InputFileError(
                    f"a second tree strike on the flight after point {key} "
                    f"(first at {out[key].where}): one strike fixes the parabola; "
                    "keep the better measured one",
                    source=source,
                    where=where,
                )
            out[key] = TreeStrike(
                after_impact=key,
                distance_m=distance,
                height_m=float(row.strike_height_m),
                ground_z_m=ground,
                where=where,
            )
        return out
