"""Glue for `fieldkit diagnose` on a video track: read, find flights, diagnose.

:mod:`fieldkit.diagnose` may not import the tracking stage, so the command line joins
them: the flights come from the track's ``flight`` column when it has one (a track
written by `fieldkit track`), else from
:func:`fieldkit.tracking.flights.pipeline.analyse_track`; their samples go to
:func:`fieldkit.diagnose.flights.diagnose_flights`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from fieldkit.diagnose.diagnosis import Diagnosis
from fieldkit.diagnose.flights import FlightSamples, check_body, diagnose_flights
from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.track_files import read_track
from fieldkit.track import Track
from fieldkit.tracking.flights.pipeline import analyse_track


def _rows_text(rows: np.ndarray) -> str:
    """File rows (header = row 1) of track positions ``rows``."""
    return f"rows {int(rows.min()) + 2}-{int(rows.max()) + 2}"


def track_flights(track: Track, *, radius_m: float) -> list[FlightSamples]:
    """The flights of a track as :class:`FlightSamples`, labelled with file rows.

    Uses the track's ``flight`` column (flight index, -1 outside flights) when
    present, else segments the track (:func:`analyse_track`).
    """
    frame = track.frame
    if "flight" in frame and (frame["flight"].fillna(-1) >= 0).any():
        label = frame["flight"].fillna(-1).to_numpy(int)
        rows_of = [np.flatnonzero(label == f) for f in np.unique(label[label >= 0])]
        origin = "the track's flight column"
    else:
        analysis = analyse_track(track, radius_m=radius_m)
        # analyse_track sorts by time; map back to the file's rows
        order = np.argsort(frame["t_s"].to_numpy(float), kind="stable")
        rows_of = [order[f.rows] for f in analysis.flights]
        origin = "segmentation"
    t, x, z = track.t, track.x, track.z
    flights = []
    for i, rows in enumerate(rows_of):
        rows = rows[np.argsort(t[rows], kind="stable")]
        flights.append(
            FlightSamples(
                t[rows], x[rows], z[rows], label=f"flight {i} ({_rows_text(rows)})"
            )
        )
    track.meta["flights_from"] = origin
    return flights


#: Track file columns holding the body `fieldkit track` was given (one value).
BODY_COLUMNS = {"radius_m": "body_radius_m", "mass_kg": "body_mass_kg"}


def track_body(
    path: Path, *, radius_m: float | None, mass_kg: float | None
) -> tuple[float, float | None, list[str]]:
    """The body of a track file: ``(radius_m, mass_kg, notes)``.

    The file is read and checked first (:func:`fieldkit.io.track_files.read_track`:
    its own errors come before any about the body). A value given explicitly must
    agree with the file's ``body_radius_m`` / ``body_mass_kg`` (written by
    `fieldkit track` and `synth --track`); a value not given is read from the file
    (and said so in the notes).

    Raises
    ------
    ArgumentError
        No radius given and none in the file, or a given value that disagrees with
        the file's (naming both and the file).
    InputFileError
        An unreadable track, or a body column that does not hold one positive
        number.
    """
    import pandas as pd

    frame = read_track(path, "track").frame
    given = {"radius_m": radius_m, "mass_kg": mass_kg}
    notes = []
    for name, column in BODY_COLUMNS.items():
        if column not in frame.columns:
            continue
        values = pd.to_numeric(frame[column], errors="coerce").dropna().unique()
        if len(values) != 1 or not values[0] > 0:
            raise InputFileError(
                f"column {column} must hold one positive number (the body the track "
                f"was made with), got {[float(v) for v in values[:3]]}",
                source=str(path),
            )
        value = float(values[0])
        if given[name] is None:
            given[name] = value
            notes.append(f"{name} = {value:g} from the track file's {column}")
        elif not math.isclose(given[name], value, rel_tol=1e-6):
            raise ArgumentError(
                f"{given[name]:g} disagrees with {path}'s {column} = {value:g} "
                "(the body the track was made with)",
                source=name,
            )
    if given["radius_m"] is None:
        raise ArgumentError(
            "a track needs --radius (the body's radius, m): the file has no "
            "body_radius_m column (`fieldkit track` and `synth --track` write it)"
        )
    return given["radius_m"], given["mass_kg"], notes


def diagnose_track_file(
    path: Path,
    *,
    radius_m: float,
    mass_kg: float | None,
    rng: np.random.Generator,
    folds: int,
    progress: Callable[[str], None] | None = None,
) -> Diagnosis:
    """Diagnose the flights of the track file ``path`` (is ``air_drag`` missing?).

    Parameters
    ----------
    path
        A fieldkit track CSV (``t_s``, ``x_m``, ``z_m``; ``flight`` used if present).
    radius_m, mass_kg
        The body; without a mass, a sphere of rock (stated in the notes).
    rng
        Random generator for the cross-validation folds.
    folds
        Folds (whole flights held out).
    progress
        Passed to :func:`diagnose_flights` (called once the flights are checked).

    Raises
    ------
    InputFileError
        Unreadable track, times that do not increase or coordinates beyond bounds
        (:func:`fieldkit.io.track_files.read_track`), fewer than three flights, a
        flight with too few samples (naming the file and the flight's rows).
    ArgumentError
        A radius or mass that is not finite, not positive or beyond its bound.
    """
    check_body(radius_m, mass_kg)
    # the reader every track command uses: times strictly increasing, finite and
    # bounded coordinates (fieldkit.io.tracking_export.check_track_values)
    track = read_track(path, "track")
    track.source = str(path)
    flights = track_flights(track, radius_m=radius_m)
    diagnosis = diagnose_flights(
        flights,
        radius_m=radius_m,
        mass_kg=mass_kg,
        rng=rng,
        folds=folds,
        source=str(path),
        progress=progress,
    )
    diagnosis.notes.insert(
        0, f"{len(flights)} flights from {track.meta['flights_from']}"
    )
    return diagnosis
