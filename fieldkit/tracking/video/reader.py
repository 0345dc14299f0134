"""Open a video file with OpenCV: frame size and count, container rate, frames in order.

High-speed cameras store a playback rate (often 30 frames/s) that is not the capture
rate; :class:`VideoReader` reports the container's rate but never uses it as time base
(the caller passes the capture rate). Unreadable, empty and truncated files raise or
report :class:`~fieldkit.errors.InputFileError` with the file name and frame numbers.
Works with OpenCV 4.x and 5.x (only ``VideoCapture`` and its ``CAP_PROP_*`` are used).
"""

from __future__ import annotations

import os
import queue
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from fieldkit.errors import InputFileError


def _backend() -> int:
    """FFmpeg when OpenCV has it (quiet, clean failures), else any backend."""
    try:
        if cv2.videoio_registry.hasBackend(cv2.CAP_FFMPEG):
            return cv2.CAP_FFMPEG
    except AttributeError:  # very old OpenCV without the registry
        pass
    return cv2.CAP_ANY


def _open_capture(path: Path) -> cv2.VideoCapture:
    """Open quietly: OpenCV's own warnings about unreadable files are not ours."""
    logging = getattr(getattr(cv2, "utils", None), "logging", None)
    previous = None
    if logging is not None and hasattr(logging, "getLogLevel"):
        previous = logging.getLogLevel()
        logging.setLogLevel(logging.LOG_LEVEL_ERROR)
    try:
        return cv2.VideoCapture(str(path), _backend())
    finally:
        if previous is not None:
            logging.setLogLevel(previous)


@dataclass(frozen=True)
class VideoInfo:
    """What the container says about a video."""

    path: Path
    width: int
    height: int
    frame_count: int  # as declared by the container (may over-count a truncated file)
    container_fps: float  # playback rate stored in the file [frames/s]; 0 when absent
    codec: str


def _fourcc_text(value: float) -> str:
    code = int(value)
    text = "".join(chr((code >> (8 * i)) & 0xFF) for i in range(4))
    return text if text.isprintable() else ""


class VideoReader:
    """Sequential and random access to the frames of one video file.

    Parameters
    ----------
    path
        A file OpenCV's FFmpeg backend decodes (AVI/MP4/MKV; MJPG, FFV1, mp4v...).

    Raises
    ------
    InputFileError
        The file does not exist, is not a video OpenCV can decode, or holds no
        decodable frame or only one (a still image).

    Examples
    --------
    >>> reader = VideoReader("video/bounce.avi")  # doctest: +SKIP
    >>> reader.info.container_fps                  # doctest: +SKIP
    30.0
    """

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        if not self.path.is_file():
            raise InputFileError("video file not found", source=self.path)
        if self.path.stat().st_size == 0:
            raise InputFileError("video file is empty (0 bytes)", source=self.path)
        capture = _open_capture(self.path)
        if not capture.isOpened():
            raise InputFileError(
                "cannot open as a video: not a container and codec OpenCV can decode "
                "(another kind of file renamed, or a damaged header)",
                source=self.path,
            )
        width = int(capture.get(cv2.CAP_PROP_FRAME_WIDTH))
        height = int(capture.get(cv2.CAP_PROP_FRAME_HEIGHT))
        count = int(max(capture.get(cv2.CAP_PROP_FRAME_COUNT), 0))
        fps = float(capture.get(cv2.CAP_PROP_FPS) or 0.0)
        codec = _fourcc_text(capture.get(cv2.CAP_PROP_FOURCC))
        ok, first = capture.read()
        second = capture.read()[0] if ok and count <= 1 else True
        capture.release()
        if not ok or first is None:
            raise InputFileError(
                "video holds no decodable frame (0 frames)", source=self.path
            )
        if not second:
            raise InputFileError(
                "holds a single frame: a still image, not a video", source=self.path
            )
        height, width = first.shape[:2] if first.ndim >= 2 else (height, width)
        self.info = VideoInfo(
            self.path, width, height, count, fps if np.isfinite(fps) else 0.0, codec
        )
        #: frames actually decoded by the last full pass (None before one)
        self.decoded_frames: int | None = None

    @property
    def shape(self) -> tuple[int, int]:
        """(height, width) in pixels."""
        return self.info.height, self.info.width

    def frames(
        self, start: int = 0, stop: int | None = None, *, prefetch: int = 6
    ) -> Iterator[tuple[int, np.ndarray]]:
        """Yield ``(index, BGR image)`` from ``start`` until ``stop`` or the last frame.

        A background thread decodes up to ``prefetch`` frames ahead (OpenCV releases
        the GIL while decoding), so the caller's per-frame work overlaps decoding.
        After a full loop :attr:`decoded_frames` holds how many frames could be
        decoded, so a truncated file can be reported by :meth:`truncation_message`.
        """
        if prefetch <= 0:
            yield from self._frames_direct(start, stop)
            return
        frames: queue.Queue = queue.Queue(maxsize=int(prefetch))
        done = threading.Event()
        failure: list[BaseException] = []

        def produce() -> None:
            capture = _open_capture(self.path)
            try:
                if start:
                    capture.set(cv2.CAP_PROP_POS_FRAMES, start)
                index = start
                while not done.is_set() and (stop is None or index < stop):
                    ok, image = capture.read()
                    if not ok or image is None:
                        break
                    while not done.is_set():
                        try:
                            frames.put((index, image), timeout=0.1)
                            break
                        except queue.Full:
                            continue
                    index += 1
            except BaseException as exc:  # pragma: no cover - surfaced to the caller
                failure.append(exc)
            finally:
                capture.release()
                while not done.is_set():
                    try:
                        frames.put(None, timeout=0.1)
                        break
                    except queue.Full:
                        continue

        worker = threading.Thread(
            target=produce, name="fieldkit-video-decode", daemon=True
        )
        worker.start()
        count = start
        try:
            while True:
                item = frames.get()
                if item is None:
                    break
                count = item[0] + 1
                yield item
            if failure:
                raise failure[0]
            if stop is None:
                self.decoded_frames = count
        finally:
            done.set()
            while worker.is_alive():
                try:
                    frames.get(timeout=0.05)
                except queue.Empty:
                    pass
            worker.join()

    def _frames_direct(
        self, start: int, stop: int | None
    ) -> Iterator[tuple[int, np.ndarray]]:
        capture = _open_capture(self.path)
        try:
            if start:
                capture.set(cv2.CAP_PROP_POS_FRAMES, start)
            index = start
            while stop is None or index < stop:
                ok, image = capture.read()
                if not ok or image is None:
                    break
                yield index, image
                index += 1
            if stop is None:
                self.decoded_frames = index
        finally:
            capture.release()

    def read_frames(self, indices: list[int]) -> list[tuple[int, np.ndarray]]:
        """Random access to a few frames (seeking); undecodable ones are skipped."""
        capture = _open_capture(self.path)
        out = []
        try:
            for index in sorted(set(int(i) for i in indices)):
                if int(capture.get(cv2.CAP_PROP_POS_FRAMES)) != index:
                    capture.set(cv2.CAP_PROP_POS_FRAMES, index)
                ok, image = capture.read()
                if ok and image is not None:
                    out.append((index, image))
        finally:
            capture.release()
        return out

    def truncation_message(self) -> str | None:
        """A one-line warning when fewer frames decoded than the container declares."""
        n, declared = self.decoded_frames, self.info.frame_count
        if n is None or declared <= 0 or n >= declared:
            return None
        return (
            f"{self.path}: frames {n}-{declared - 1}: video truncated or damaged; "
            f"only {n} of the {declared} declared frames could be decoded"
        )


def fps_mismatch_message(info: VideoInfo, capture_fps: float) -> str | None:
    """Warn when the container's playback rate differs from the stated capture rate."""
    if info.container_fps <= 0:
        return (
            f"{info.path}: the file stores no frame rate; using `fps` {capture_fps:g}"
        )
    if abs(info.container_fps - capture_fps) > 1e-3 * capture_fps:
        return (
            f"{info.path}: the container's frame rate is {info.container_fps:g} "
            "frames/s but "
            f"`fps` is {capture_fps:g}; times use `fps` (high-speed cameras store a "
            "playback "
            "rate — check the fitted gravity)"
        )
    return None
