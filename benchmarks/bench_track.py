"""Frames per second of `fieldkit track`'s pipeline vs decode-only, same file, same run.

The clip is the 800x480 MJPG ``bounce`` clip of video/render.py (1145 frames at a
1205 frames/s capture rate): ``video/bounce.avi`` when `make video` has rendered it,
else rendered into a temporary folder. Decode-only = OpenCV reading every frame (the
I/O limit). Pipeline = background model, detection, sub-pixel centres, marker spin,
calibration, flight segmentation and fits, impacts (what `fieldkit track` computes
before writing files). Each is timed twice, alternating; the faster run counts.
Target (issue 4): pipeline within 2x of decode-only.
"""

from __future__ import annotations

import importlib.util
import json
import sys
import tempfile
import time
from pathlib import Path

import cv2

from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.video.calibration import read_homography_file
from fieldkit.tracking.video.pipeline import track_video

REPO = Path(__file__).resolve().parents[1]


def _clip(folder: Path) -> Path:
    if (REPO / "video" / "bounce.avi").exists() and (
        REPO / "video" / "bounce.truth.json"
    ).exists():
        return REPO / "video"
    spec = importlib.util.spec_from_file_location(
        "bench_render", REPO / "video" / "render.py"
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_render"] = module
    spec.loader.exec_module(module)
    module.render("bounce", folder)
    return folder


def decode_only(path: Path) -> tuple[int, float]:
    start = time.perf_counter()
    capture = cv2.VideoCapture(str(path))
    n = 0
    while True:
        ok, _ = capture.read()
        if not ok:
            break
        n += 1
    capture.release()
    return n, time.perf_counter() - start


def pipeline(folder: Path) -> tuple[int, float, int]:
    truth = json.loads((folder / "bounce.truth.json").read_text())
    start = time.perf_counter()
    calibration = read_homography_file(folder / "bounce.homography.json", (800, 480))
    track, detections = track_video(
        folder / "bounce.avi", fps=1205.0, calibration=calibration, radius_m=0.0375
    )
    analysis = analyse_track(
        track,
        radius_m=0.0375,
        mass_kg=truth["ball"]["mass_kg"],
        gyration_m=truth["ball"]["gyration_m"],
    )
    elapsed = time.perf_counter() - start
    return len(detections), elapsed, len(analysis.impacts.frame)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = _clip(Path(tmp))
        video = folder / "bounce.avi"
        decode_times, track_times = [], []
        for _ in range(2):
            n_decoded, t_decode = decode_only(video)
            n_tracked, t_track, n_impacts = pipeline(folder)
            decode_times.append(t_decode)
            track_times.append(t_track)
        t_decode, t_track = min(decode_times), min(track_times)
        print(f"clip: {video.name}, 800x480 MJPG, {n_decoded} frames")
        print(f"decode only : {n_decoded / t_decode:8.1f} frames/s ({t_decode:.2f} s)")
        print(
            f"track       : {n_tracked / t_track:8.1f} frames/s ({t_track:.2f} s, "
            f"{n_impacts} impacts)"
        )
        print(
            f"ratio track/decode time: {t_track / t_decode:.2f} "
            f"(target <= 2.0, OpenCV threads: {cv2.getNumThreads()})"
        )


if __name__ == "__main__":
    main()
