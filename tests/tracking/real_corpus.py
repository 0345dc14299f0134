"""The corpus of real camera clips (tests/data/video_corpus) and its done-when checks.

The clips themselves are not in the repository (their licences are permissive, but
fetched material stays outside commits): :func:`find_corpus` looks for them in the
first existing of ``$FIELDKIT_VIDEO_CORPUS``, ``../shared/data/external/video_corpus``
(beside the repository) and ``/work/corpus``, one folder per clip named as its label
file. Each clip is checked against its hand-checked label file (issue 31):

- every labelled impact or net contact is found within one frame, and no fitted
  flight claims a labelled rolling or resting contact (beyond one frame at each
  end);
- no impact or contact is reported where the labels have none (a hand contact
  counts as a contact: an event inside one is not false);
- every labelled free flight has a fitted flight whose g is within 3 standard
  errors of 9.81 m/s^2, the error including the labelled scale and capture-rate
  uncertainty (g scales with the length scale and with the rate squared); a
  flight whose scale the labels derive from g itself is not checked for g;
- or the library refuses the clip with a one-line error;
- a labelled contact the tracker did not find counts as *refused with a reason*
  (not missed) only when the library itself refused to reduce the span holding it
  (a ``Refusal`` of kind ``unreduced``, flights kept apart, whose frames cover the
  contact within one frame); the table lists those contacts with the library's
  line, apart from the ones found, and says how many clips pass only through them.

:func:`evaluate_clip` returns a :class:`ClipResult`; :func:`result_table` prints
them. Used by tests/tracking/test_real_corpus.py and benchmarks/video_corpus.py.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
LABELS_DIR = REPO / "tests" / "data" / "video_corpus"
CORPUS_ENV = "FIELDKIT_VIDEO_CORPUS"
G_MPS2 = 9.81
#: How far (standard errors) a fitted g may lie from 9.81.
G_SIGMAS = 3.0
#: How far (frames) a found contact may lie from a labelled one.
CONTACT_TOLERANCE_FRAMES = 1
#: Label contact kinds the tracker must find as an event within the tolerance (a
#: hand is not a modelled surface: an event in one is not false, none is required).
SURFACE_KINDS = ("impact", "net")
#: Extended contacts (rolling, at rest): found when no fitted flight claims them
#: (one at a clip's start or end lies between no two flights, so has no event).
EXTENDED_KINDS = ("rolling", "rest")


def corpus_candidates(repo: Path = REPO) -> list[Path]:
    """Folders searched for the clips, in order."""
    env = os.environ.get(CORPUS_ENV)
    found = [Path(env)] if env else []
    return [
        *found,
        repo.parent / "shared" / "data" / "external" / "video_corpus",
        Path("/work/corpus"),
    ]


def find_corpus(repo: Path = REPO) -> Path | None:
    """The first existing folder of :func:`corpus_candidates`, or None."""
    for folder in corpus_candidates(repo):
        if folder.is_dir():
            return folder
    return None


def load_labels(folder: Path = LABELS_DIR) -> list[dict]:
    """Every ``*.labels.json`` of ``folder``, sorted by clip name."""
    return [json.loads(p.read_text()) for p in sorted(folder.glob("*.labels.json"))]


def clip_file(corpus: Path, label: dict) -> Path:
    """Where the clip of ``label`` lies in ``corpus``."""
    return corpus / label["clip"] / label["file"]


def sha256(path: Path) -> str:
    """Hex SHA-256 of a file."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def scale_of(label: dict) -> tuple[tuple[float, float, float, float], float, float]:
    """``(scale points U1,V1,U2,V2 [px], their distance [m], relative sd)``.

    A label given as metres per pixel becomes two points 100 px apart.
    """
    scale = label["scale"]
    if "points_px" in scale:
        (u1, v1), (u2, v2) = scale["points_px"]
        return (
            (u1, v1, u2, v2),
            scale["length_m"],
            scale["length_sd_m"] / scale["length_m"],
        )
    m_per_px = scale["m_per_px"]
    return (0.0, 0.0, 100.0, 0.0), 100.0 * m_per_px, scale["m_per_px_sd"] / m_per_px


def g_standard_error(
    g: float, g_se: float, scale_rel_sd: float, fps_rel_sd: float
) -> float:
    """Standard error of a fitted g with the scale and rate uncertainty (the
    library's ``FlightFit.g_check_se_mps2``).

    g is proportional to the length scale and to the capture rate squared.

    Examples
    --------
    >>> round(g_standard_error(10.0, 0.3, 0.04, 0.0), 6)
    0.5
    """
    from fieldkit.tracking.flights.ballistic_fit import calibration_rel_sd

    return math.hypot(g_se, g * calibration_rel_sd(scale_rel_sd, fps_rel_sd))


@dataclass
class FlightCheck:
    """One labelled free flight against the fitted flights."""

    label: tuple[int, int]
    fitted: tuple[int, int] | None = None
    g_mps2: float = math.nan
    g_se_mps2: float = math.nan
    se_total_mps2: float = math.nan
    g_checked: bool = True

    @property
    def z(self) -> float:
        """Standard errors from 9.81 (NaN without a fit)."""
        return (self.g_mps2 - G_MPS2) / self.se_total_mps2

    @property
    def ok(self) -> bool:
        if self.fitted is None:
            return False
        return (not self.g_checked) or abs(self.z) <= G_SIGMAS

    def text(self) -> str:
        a, b = self.label
        if self.fitted is None:
            return f"flight {a}-{b}: not fitted"
        c, d = self.fitted
        g = (
            f"g {self.g_mps2:.2f} +/- {self.se_total_mps2:.2f} "
            f"(fit {self.g_se_mps2:.2f})"
        )
        check = (
            f"{self.z:+.1f} SE" if self.g_checked else "g not checked (scale from g)"
        )
        verdict = "ok" if self.ok else "FAIL"
        return f"flight {a}-{b}: fitted {c}-{d}, {g}, {check} {verdict}"


@dataclass
class ClipResult:
    """The done-when checks of one clip."""

    clip: str
    status: str = "checked"  # checked | refused | missing | bad-checksum
    message: str = ""
    found: list[tuple[int, int, int]] = field(default_factory=list)
    missed: list[tuple[int, int]] = field(default_factory=list)
    #: ``(first, last, reason)`` per labelled contact the library refused to reduce
    refused: list[tuple[int, int, str]] = field(default_factory=list)
    false_events: list[int] = field(default_factory=list)
    flights: list[FlightCheck] = field(default_factory=list)
    seconds: float = 0.0
    warnings: list[str] = field(default_factory=list)
    summary: str = ""

    @property
    def passed(self) -> bool:
        """The clip meets the criteria (or was refused with one line)."""
        if self.status == "refused":
            return "\n" not in self.message.strip()
        if self.status != "checked":
            return False
        return (
            not self.missed
            and not self.false_events
            and all(f.ok for f in self.flights)
        )

    def lines(self) -> list[str]:
        """The result, one line per fact."""
        head = f"{self.clip}: {'PASS' if self.passed else 'FAIL'} [{self.status}]"
        if self.status != "checked":
            return [f"{head} {self.message}"]
        out = [f"{head} ({self.seconds:.0f} s)"]
        if self.summary:
            out.append(f"  tracker: {self.summary}")
        out.append(
            "  contacts found: "
            + (", ".join(f"{a}-{b} at {f}" for a, b, f in self.found) or "none")
            + "; missed: "
            + (", ".join(f"{a}-{b}" for a, b in self.missed) or "none")
            + "; false: "
            + (", ".join(str(f) for f in self.false_events) or "none")
        )
        out += [
            f"  contact {a}-{b} refused with a reason: {why}"
            for a, b, why in self.refused
        ]
        out += [f"  {f.text()}" for f in self.flights]
        return out


def score_events(
    label: dict,
    event_frames: list[int | tuple[int, int]],
    fitted: list[tuple[int, int, float, float]],
) -> tuple[list, list, list, list[FlightCheck]]:
    """Compare found events and fitted flights with a clip's labels.

    Parameters
    ----------
    label
        The clip's label dictionary.
    event_frames
        Frame of every impact the tracker reported, or ``(first, last)`` frames of
        an extended contact (a net, a rolling phase).
    fitted
        ``(first frame, last frame, g, g standard error)`` of every fitted flight.

    Returns
    -------
    found, missed, false_events, flights
        ``(first, last, found frame)`` per labelled impact or net contact found (an
        event beginning and ending within :data:`CONTACT_TOLERANCE_FRAMES` of the
        label's first and last frames), and per rolling or resting contact no fitted
        flight claims (its first frame); ``(first, last)`` per one missed; the first
        frame of each event not inside a labelled contact (of any kind, within the
        tolerance); one :class:`FlightCheck` per labelled free flight, with the
        fitted flight overlapping it most.
    """
    tol = CONTACT_TOLERANCE_FRAMES
    contacts = label["contacts"]
    events = [(e, e) if isinstance(e, int) else tuple(e) for e in event_frames]
    found, missed = [], []
    for c in contacts:
        a, b = c["first_frame"], c["last_frame"]
        if c["kind"] in EXTENDED_KINDS:
            # found unless a fitted flight claims more than the tolerance of it
            inside = [min(b, d) - max(a, e) for e, d, _, _ in fitted]
            if all(overlap < 2 * tol for overlap in inside):
                found.append((a, b, a))
            else:
                missed.append((a, b))
            continue
        if c["kind"] not in SURFACE_KINDS:
            continue
        near = [s for s, e in events if abs(s - a) <= tol and abs(e - b) <= tol]
        if near:
            found.append((a, b, near[0]))
        else:
            missed.append((a, b))
    false_events = [
        s
        for s, e in events
        if not any(
            c["first_frame"] - tol <= s and e <= c["last_frame"] + tol for c in contacts
        )
    ]
    _, _, scale_rel = scale_of(label)
    fps_rel = label["capture_fps_sd"] / label["capture_fps"]
    g_checked = not label["scale"].get("derived_from_gravity", False)
    flights = []
    for fl in label["flights"]:
        if not fl.get("free", True):
            continue
        a, b = fl["first_frame"], fl["last_frame"]
        check = FlightCheck(label=(a, b), g_checked=g_checked)
        overlaps = [(min(b, d) - max(a, c), c, d, g, se) for c, d, g, se in fitted]
        overlaps = [o for o in overlaps if o[0] >= 0]
        if overlaps:
            _, c, d, g, se = max(overlaps)
            check.fitted = (c, d)
            check.g_mps2, check.g_se_mps2 = g, se
            check.se_total_mps2 = g_standard_error(g, se, scale_rel, fps_rel)
        flights.append(check)
    return found, missed, false_events, flights


#: Refusal kinds that say a span cannot be reduced (not that it holds no contact).
UNREDUCED_KINDS = ("unreduced",)


def refused_contacts(
    missed: list[tuple[int, int]], refusals: list[tuple[int, int, str]]
) -> tuple[list[tuple[int, int]], list[tuple[int, int, str]]]:
    """Split missed contacts into still missed and refused by the library.

    Parameters
    ----------
    missed
        ``(first, last)`` frames of each labelled contact not found.
    refusals
        ``(first frame, last frame, reason)`` of each span the library refused to
        reduce (kind ``unreduced``, flights not joined).

    Returns
    -------
    missed, refused
        The contacts no refusal covers, and ``(first, last, reason)`` per contact a
        refusal's frames cover within :data:`CONTACT_TOLERANCE_FRAMES`.

    Examples
    --------
    >>> refused_contacts([(29, 29), (90, 92)], [(26, 63, "not one body's path")])
    ([(90, 92)], [(29, 29, "not one body's path")])
    """
    tol = CONTACT_TOLERANCE_FRAMES
    still, refused = [], []
    for a, b in missed:
        why = [r for s, e, r in refusals if s - tol <= a and b <= e + tol]
        if why:
            refused.append((a, b, why[0]))
        else:
            still.append((a, b))
    return still, refused


def evaluate_clip(corpus: Path, label: dict) -> ClipResult:
    """Run the tracker (as `fieldkit track` does) on one clip of the corpus and check
    its labels; a clip absent or not the labelled file is reported, not run."""
    path = clip_file(corpus, label)
    if not path.exists():
        return ClipResult(label["clip"], status="missing", message=f"{path} not found")
    if sha256(path) != label["sha256"]:
        return ClipResult(
            label["clip"], status="bad-checksum", message=f"{path}: SHA-256 differs"
        )
    return evaluate_video(path, label)


def evaluate_video(path: Path, label: dict) -> ClipResult:
    """Run the tracker (as `fieldkit track` does) on the video at ``path`` and check
    it against ``label`` (a corpus label, or a rendered clip's from video/hard.py)."""
    from fieldkit.errors import FieldkitError
    from fieldkit.tracking.flights.ballistic_fit import calibration_rel_sd
    from fieldkit.tracking.flights.pipeline import analyse_track
    from fieldkit.tracking.video.calibration import two_point_scale
    from fieldkit.tracking.video.pipeline import track_video

    result = ClipResult(label["clip"])
    fps = float(label["capture_fps"])
    points, length_m, scale_rel = scale_of(label)
    stated = calibration_rel_sd(scale_rel, label["capture_fps_sd"] / fps)
    radius_m = label["body"]["radius_m"]
    start = time.perf_counter()
    try:
        calibration = two_point_scale(points, length_m, tuple(label["size_px"]))
        track, _ = track_video(
            path, fps=fps, calibration=calibration, radius_m=radius_m
        )
        analysis = analyse_track(
            track, radius_m=radius_m, path_id=label["clip"],
            calibration_rel_sd=stated,
        )  # fmt: skip
    except FieldkitError as error:
        result.status, result.message = "refused", str(error)
        return result
    finally:
        result.seconds = time.perf_counter() - start
    frames = track.frame["frame"].to_numpy()
    table = analysis.impacts.frame
    start = table["t_s"].astype(float).to_numpy()
    if "contact_duration_s" in table.columns:
        duration = table["contact_duration_s"].astype(float).fillna(0.0).to_numpy()
    else:
        duration = 0.0 * start
    events = [
        (int(round(t * fps)), int(round((t + d) * fps)))
        for t, d in zip(start, duration, strict=True)
    ]
    fitted = [
        (int(frames[f.rows[0]]), int(frames[f.rows[-1]]), f.g_mps2, f.g_se_mps2)
        for f in analysis.flights
    ]
    result.found, result.missed, result.false_events, result.flights = score_events(
        label, events, fitted
    )
    unreduced = [
        (r.frames[0], r.frames[1], r.reason)
        for r in analysis.refusals
        if r.kind in UNREDUCED_KINDS and not r.merged
    ]
    result.missed, result.refused = refused_contacts(result.missed, unreduced)
    result.warnings = [*track.meta.get("warnings", []), *analysis.warnings]
    result.summary = (
        f"{analysis.counts_text()}; body in {len(frames)} of {label['frames']} frames"
    )
    return result


def result_table(results: list[ClipResult]) -> str:
    """The results as text, clip by clip."""
    lines = []
    for r in results:
        lines += r.lines()
    n = sum(r.passed for r in results)
    k = sum(r.passed and bool(r.refused) for r in results)
    lines.append(
        f"{n} of {len(results)} clips pass ({k} of them with contacts refused with "
        "a reason, not reduced)"
    )
    return "\n".join(lines)
