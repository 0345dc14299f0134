"""Image pixels (u right, v down) -> world metres (x horizontal, z up).

Two ways to calibrate a video:

* **Two scale points** ``U1,V1,U2,V2`` a known distance ``L`` apart (a scale bar in the
  scene). The camera is taken as level and upright: ``x = s (u - U1)``,
  ``z = s (V1 - v)`` with ``s = L / |P2 - P1|`` metres per pixel; the world origin is
  the first scale point. For a tilted, rotated or mirrored camera use a homography.
* **A homography file** with at least four image <-> world points (not three on a line),
  in the world frame the user chose (z up). Formats:

  JSON ::

      {"points": [{"u_px": 40, "v_px": 440, "x_m": 0.0, "z_m": 0.0}, ...]}

  (a bare list of such objects, or of ``[u_px, v_px, x_m, z_m]`` rows, also works)

  CSV with a header ``u_px,v_px,x_m,z_m`` (one point per row; ``#`` comments allowed;
  read like every fieldkit CSV: ``,`` ``;`` or tab, decimal commas, ``x_ft`` etc.).

Pixel centres sit at integer (u, v), as in OpenCV. Both calibrations become one 3x3
matrix ``H`` mapping ``(u, v, 1)`` to ``(x, z, 1)``, so world z is up whatever the
image orientation: a camera on its side or mirrored just has a different ``H``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from itertools import combinations
from pathlib import Path

import cv2
import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.csv_table import length_factor, read_csv_table, read_json
from fieldkit.io.tracking_export import MAX_METRES_PER_PIXEL, MIN_METRES_PER_PIXEL


@dataclass(frozen=True)
class Calibration:
    """A plane-to-plane mapping from image pixels to world metres.

    Examples
    --------
    >>> cal = two_point_scale((100, 30, 700, 30), 1.2)
    >>> [round(float(c), 6) for c in cal.to_world(400.0, 130.0)]
    [0.6, -0.2]
    """

    homography: np.ndarray
    description: str = ""
    residual_m: float = 0.0  # RMS fit residual of the calibration points [m]
    meta: dict = field(default_factory=dict)

    def to_world(self, u, v) -> tuple[np.ndarray, np.ndarray]:
        """Map pixel coordinates [px] to world ``(x, z)`` [m] (arrays broadcast)."""
        u = np.asarray(u, dtype=float)
        v = np.asarray(v, dtype=float)
        h = self.homography
        w = h[2, 0] * u + h[2, 1] * v + h[2, 2]
        x = (h[0, 0] * u + h[0, 1] * v + h[0, 2]) / w
        z = (h[1, 0] * u + h[1, 1] * v + h[1, 2]) / w
        return x, z

    def metres_per_pixel(self, u, v) -> np.ndarray:
        """Local scale sqrt(|det J|) of the mapping at ``(u, v)`` [m/px]."""
        step = 0.5
        x0, z0 = self.to_world(u, v)
        xu, zu = self.to_world(np.asarray(u, float) + step, v)
        xv, zv = self.to_world(u, np.asarray(v, float) + step)
        det = ((xu - x0) * (zv - z0) - (zu - z0) * (xv - x0)) / (step * step)
        return np.sqrt(np.abs(det))

    def to_dict(self) -> dict:
        return {
            "homography": self.homography.tolist(),
            "description": self.description,
            "residual_m": self.residual_m,
            **self.meta,
        }


def parse_scale_points(scale_points: str) -> tuple[float, float, float, float]:
    """Parse ``"U1,V1,U2,V2"`` (pixels): the ``scale_points`` of
    :func:`two_point_scale`.

    Examples
    --------
    >>> parse_scale_points("100,30, 700,30")
    (100.0, 30.0, 700.0, 30.0)
    """
    text = scale_points
    parts = [p for p in str(text).replace(";", ",").split(",") if p.strip()]
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise ArgumentError(
            f"expected four numbers U1,V1,U2,V2 (pixels), got {text!r}",
            source="scale_points",
        ) from None
    if len(values) != 4 or not all(np.isfinite(values)):
        raise ArgumentError(
            f"expected four numbers U1,V1,U2,V2 (pixels), got {text!r}",
            source="scale_points",
        )
    return values  # type: ignore[return-value]


def _check_inside(u: float, v: float, image_size, source: str, where: str) -> None:
    if image_size is None:
        return
    width, height = image_size
    if not (-0.5 <= u <= width - 0.5 and -0.5 <= v <= height - 0.5):
        raise ArgumentError(
            f"({u:g}, {v:g}) px lies outside the {width}x{height} frame",
            source=source,
            where=where,
        )


def two_point_scale(
    scale_points: tuple[float, float, float, float],
    scale_length_m: float,
    image_size: tuple[int, int] | None = None,
) -> Calibration:
    """Calibration from two image points a known distance apart (level camera).

    Parameters
    ----------
    scale_points
        ``(U1, V1, U2, V2)`` [px].
    scale_length_m
        Their distance in the scene [m].
    image_size
        ``(width, height)`` [px]; when given, both points must lie inside the frame.
    """
    u1, v1, u2, v2 = (float(p) for p in scale_points)
    length_m = scale_length_m
    if length_m is None or not np.isfinite(length_m) or length_m <= 0:
        raise ArgumentError(
            f"must be a positive length in metres, got {length_m}",
            source="scale_length_m",
        )
    _check_inside(u1, v1, image_size, "scale_points", "point 1")
    _check_inside(u2, v2, image_size, "scale_points", "point 2")
    distance = float(np.hypot(u2 - u1, v2 - v1))
    if distance < 1.0:
        raise ArgumentError(
            f"the two scale points are identical ({distance:.2g} px apart)",
            source="scale_points",
        )
    s = length_m / distance
    if not MIN_METRES_PER_PIXEL <= s <= MAX_METRES_PER_PIXEL:
        raise ArgumentError(
            f"{length_m:g} m over {distance:.4g} px is {s:.3g} m per pixel, outside "
            f"{MIN_METRES_PER_PIXEL:g}-{MAX_METRES_PER_PIXEL:g} m/px (a wrong unit?)",
            source="scale_length_m",
        )
    h = np.array([[s, 0.0, -s * u1], [0.0, -s, s * v1], [0.0, 0.0, 1.0]])
    return Calibration(
        h,
        f"two-point scale {s * 1000:.4g} mm/px, origin at ({u1:g}, {v1:g}) px",
        meta={"scale_points_px": [u1, v1, u2, v2], "scale_length_m": float(length_m)},
    )


def homography_from_points(
    image_points: np.ndarray,
    world_points: np.ndarray,
    *,
    image_size: tuple[int, int] | None = None,
    source: str = "homography",
) -> Calibration:
    """Least-squares homography from >= 4 image <-> world point pairs.

    Raises :class:`~fieldkit.errors.InputFileError` (``source``: the points' file)
    naming the point when there are too few points, a point lies outside the frame or
    points repeat; and for layouts no homography comes from: all image or all world
    points on one line, three of four on a line (the mapping is undetermined or
    singular), or the world points in another arrangement than the image points (the
    mapping would fold the picture through infinity).
    """
    img = np.asarray(image_points, dtype=float).reshape(-1, 2)
    wld = np.asarray(world_points, dtype=float).reshape(-1, 2)
    if len(img) < 4:
        raise InputFileError(
            f"needs at least 4 image<->world points, found {len(img)}", source=source
        )
    bad = ~np.all(np.isfinite(np.hstack([img, wld])), axis=1)
    if bad.any():
        raise InputFileError(
            "non-numeric or missing value",
            source=source,
            where=f"point {int(np.flatnonzero(bad)[0]) + 1}",
        )
    for i, (u, v) in enumerate(img):
        if image_size is not None:
            width, height = image_size
            if not (-0.5 <= u <= width - 0.5 and -0.5 <= v <= height - 0.5):
                raise InputFileError(
                    f"({u:g}, {v:g}) px lies outside the {width}x{height} frame",
                    source=source,
                    where=f"point {i + 1}",
                )
        for j in range(i):
            if (
                np.hypot(*(img[i] - img[j])) < 1.0
                or np.hypot(*(wld[i] - wld[j])) < 1e-9
            ):
                raise InputFileError(
                    f"same position as point {j + 1}",
                    source=source,
                    where=f"point {i + 1}",
                )
    for points, where in ((img, "image"), (wld, "world")):
        centred = points - points.mean(axis=0)
        singular = np.linalg.svd(centred, compute_uv=False)
        if singular[-1] < 1e-3 * singular[0]:
            raise InputFileError(
                f"the {where} points lie on one line; the mapping is undetermined "
                "(give at least 4 points with no three on a line)",
                source=source,
            )
    h = _direct_linear_transform(img, wld)
    if h is None or not np.all(np.isfinite(h)):
        line = _three_on_a_line(img, wld)
        detail = f" (points {line})" if line else ""
        raise InputFileError(
            f"these points do not fix a homography{detail}: give at least 4 points "
            "with no three on a line, in the image and in the world",
            source=source,
        )
    w = h[2, 0] * img[:, 0] + h[2, 1] * img[:, 1] + h[2, 2]
    if np.any(w > 0) and np.any(w < 0):
        side = w > 0 if np.count_nonzero(w > 0) <= np.count_nonzero(w < 0) else w < 0
        odd = ", ".join(str(i + 1) for i in np.flatnonzero(side))
        raise InputFileError(
            "the world points are not in the same arrangement as the image points "
            f"(points {odd} are on the wrong side: two points swapped?); the mapping "
            "would fold the picture through infinity",
            source=source,
        )
    cal = Calibration(np.asarray(h, float))
    x, z = cal.to_world(img[:, 0], img[:, 1])
    residual = float(np.sqrt(np.mean((x - wld[:, 0]) ** 2 + (z - wld[:, 1]) ** 2)))
    return Calibration(
        cal.homography,
        f"homography from {len(img)} points (RMS residual {residual * 1000:.3g} mm)",
        residual,
        {"homography_points": int(len(img))},
    )


def _three_on_a_line(img: np.ndarray, wld: np.ndarray) -> str | None:
    """``"i, j, k on one line in the image"`` (1-based) for the first such triple."""
    for points, where in ((img, "image"), (wld, "world")):
        scale = float(np.ptp(points, axis=0).max()) or 1.0
        for i, j, k in combinations(range(min(len(points), 60)), 3):
            a, b = points[j] - points[i], points[k] - points[i]
            if abs(a[0] * b[1] - a[1] * b[0]) < 1e-6 * scale * scale:
                return f"{i + 1}, {j + 1}, {k + 1} on one line in the {where}"
    return None


def _normalising_transform(points: np.ndarray) -> np.ndarray:
    centre = points.mean(axis=0)
    spread = np.sqrt(np.mean(np.sum((points - centre) ** 2, axis=1)))
    s = np.sqrt(2.0) / max(spread, 1e-300)
    return np.array(
        [[s, 0.0, -s * centre[0]], [0.0, s, -s * centre[1]], [0.0, 0.0, 1.0]]
    )


def _direct_linear_transform(src: np.ndarray, dst: np.ndarray) -> np.ndarray | None:
    """Least-squares homography src -> dst (Hartley-normalised DLT, numpy SVD)."""
    ts, td = _normalising_transform(src), _normalising_transform(dst)
    a = (ts @ np.column_stack([src, np.ones(len(src))]).T).T
    b = (td @ np.column_stack([dst, np.ones(len(dst))]).T).T
    rows = []
    for (x, y, _), (u, v, _) in zip(a, b, strict=True):
        rows.append([-x, -y, -1, 0, 0, 0, u * x, u * y, u])
        rows.append([0, 0, 0, -x, -y, -1, v * x, v * y, v])
    _, singular, vt = np.linalg.svd(np.asarray(rows, float))
    if singular[7] < 1e-8 * singular[0]:  # more than one solution: degenerate
        return None
    normalised = vt[-1].reshape(3, 3)
    scales = np.linalg.svd(normalised, compute_uv=False)
    if scales[-1] < 1e-8 * scales[0]:  # singular: the image maps onto a line
        return None
    h = np.linalg.inv(td) @ normalised @ ts
    if abs(h[2, 2]) < 1e-300:
        return None
    return h / h[2, 2]


def read_homography_file(
    path: str | os.PathLike[str],
    image_size: tuple[int, int] | None = None,
    lens: Lens | None = None,
) -> Calibration:
    """Read image <-> world points (JSON or CSV, see the module docstring) and fit.

    Every problem is reported against the file (and the point at fault): bad JSON
    or CSV, too few points, and layouts no homography can come from
    (:func:`homography_from_points`). With a ``lens`` the image points (read on the
    distorted frames) are undistorted first, to match undistorted detections.
    """
    path = Path(path)
    if not path.is_file():
        raise InputFileError("homography file not found", source=path)
    with path.open("rb") as handle:
        head = handle.read(512).lstrip(b"\xef\xbb\xbf \t\r\n")
    rows: list[list[float]] = []
    if path.suffix.lower() == ".json" or head.startswith((b"{", b"[")):
        data = read_json(path, kind="homography")
        items = data.get("points") if isinstance(data, dict) else data
        if not isinstance(items, list):
            raise InputFileError(
                'expected {"points": [{"u_px", "v_px", "x_m", "z_m"}, ...]}',
                source=path,
            )
        for i, item in enumerate(items):
            try:
                if isinstance(item, dict):
                    rows.append(
                        [float(item[k]) for k in ("u_px", "v_px", "x_m", "z_m")]
                    )
                else:
                    values = [float(v) for v in item]
                    if len(values) != 4:
                        raise ValueError
                    rows.append(values)
            except (KeyError, TypeError, ValueError):
                raise InputFileError(
                    "needs numbers u_px, v_px, x_m, z_m",
                    source=path,
                    where=f"point {i + 1}",
                ) from None
    else:
        table = read_csv_table(path)
        columns = table.require(
            {"u_px": ("u_px",), "v_px": ("v_px",), "x_m": ("x",), "z_m": ("z",)},
            "homography CSV needs columns u_px, v_px, x_m, z_m",
        )
        factors = {
            key: length_factor(table, column, None) if key in ("x_m", "z_m") else 1.0
            for key, column in columns.items()
        }
        for number, row in table.rows:
            rows.append(
                [table.number(number, row, c) * factors[k] for k, c in columns.items()]
            )
    points = np.array(rows, dtype=float).reshape(-1, 4)
    if lens is not None:
        for i, (u, v) in enumerate(points[:, :2]):
            if image_size is not None:
                _check_inside(u, v, image_size, str(path), f"point {i + 1}")
        points[:, 0], points[:, 1] = lens.undistort(points[:, 0], points[:, 1])
        image_size = None  # undistorted points may lie beyond the frame's edge
    cal = homography_from_points(
        points[:, :2], points[:, 2:], image_size=image_size, source=str(path)
    )
    return Calibration(
        cal.homography,
        cal.description,
        cal.residual_m,
        {**cal.meta, "homography_file": str(path)},
    )


@dataclass(frozen=True)
class Lens:
    """Lens distortion of a camera (OpenCV's pinhole + radial/tangential model).

    ``camera_matrix`` is the 3x3 intrinsic matrix [px], ``distortion`` OpenCV's
    coefficients ``(k1, k2, p1, p2, k3)``; ``rms_px`` is the calibration's RMS
    reprojection error.

    Examples
    --------
    >>> lens = Lens(np.array([[500.0, 0, 320], [0, 500, 240], [0, 0, 1]]),
    ...             np.array([-0.2, 0.0, 0.0, 0.0, 0.0]), (640, 480))
    >>> u, v = lens.undistort(np.array([320.0, 600.0]), np.array([240.0, 240.0]))
    >>> round(float(u[0]), 6), bool(u[1] > 600.0)  # barrel: the edge moves out
    (320.0, True)
    """

    camera_matrix: np.ndarray
    distortion: np.ndarray
    image_size: tuple[int, int]
    rms_px: float = 0.0
    frames_used: int = 0
    source: str = ""

    @property
    def description(self) -> str:
        k = np.ravel(self.distortion)
        return (
            f"lens {self.source or 'model'}: f = {self.camera_matrix[0, 0]:.1f} px, "
            f"k1 = {k[0]:.4g}, RMS reprojection {self.rms_px:.3f} px"
        )

    def undistort(self, u, v) -> tuple[np.ndarray, np.ndarray]:
        """Distorted pixel positions -> undistorted ones [px] (``cv2.undistortPoints``
        with the same camera matrix, so the pixel scale stays)."""
        u = np.asarray(u, dtype=float)
        v = np.asarray(v, dtype=float)
        pts = np.stack([u.ravel(), v.ravel()], axis=1).reshape(-1, 1, 2)
        if len(pts) == 0:
            return u.copy(), v.copy()
        criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 50, 1e-9)
        out = cv2.undistortPoints(  # iterated to 1e-9: strong barrel near corners
            pts,
            self.camera_matrix,
            self.distortion,
            R=None,
            P=self.camera_matrix,
            criteria=criteria,
        ).reshape(-1, 2)
        return out[:, 0].reshape(u.shape), out[:, 1].reshape(v.shape)

    def corner_shift_px(self) -> float:
        """How far the lens moves a point at the image corners [px]: the largest
        distance between a corner pixel and its undistorted position."""
        w, h = self.image_size
        u = np.array([0.0, w - 1.0, 0.0, w - 1.0])
        v = np.array([0.0, 0.0, h - 1.0, h - 1.0])
        ud, vd = self.undistort(u, v)
        return float(np.max(np.hypot(ud - u, vd - v)))

    def to_dict(self) -> dict:
        return {
            "camera_matrix": np.asarray(self.camera_matrix).tolist(),
            "distortion": np.ravel(self.distortion).tolist(),
            "image_size_px": list(self.image_size),
            "rms_reprojection_px": self.rms_px,
            "frames_used": self.frames_used,
        }

    def write(self, path: str | os.PathLike[str], outputs=None) -> Path:
        """Save as JSON (:func:`read_lens_file` reads it back; ``outputs``: a
        :class:`fieldkit.outputs.OutputSet` to write with, all or nothing)."""
        from fieldkit.outputs import write_json

        return write_json(path, self.to_dict(), outputs, indent=1)


def read_lens_file(
    path: str | os.PathLike[str], image_size: tuple[int, int] | None = None
) -> Lens:
    """Read a lens JSON written by :meth:`Lens.write` (checked against the frame)."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError("lens file not found", source=path)
    data = read_json(path, kind="lens")
    try:
        matrix = np.array(data["camera_matrix"], dtype=float).reshape(3, 3)
        dist = np.array(data["distortion"], dtype=float).ravel()
        size = tuple(int(x) for x in data["image_size_px"])
    except (KeyError, TypeError, ValueError):
        raise InputFileError(
            "needs camera_matrix (3x3), distortion and image_size_px", source=path
        ) from None
    if not (np.all(np.isfinite(matrix)) and np.all(np.isfinite(dist))) or len(
        dist
    ) not in (4, 5, 8, 12, 14):
        raise InputFileError("camera_matrix or distortion not valid", source=path)
    if image_size is not None and tuple(image_size) != size:
        raise InputFileError(
            f"calibrated for {size[0]}x{size[1]} frames, the video has "
            f"{image_size[0]}x{image_size[1]}",
            source=path,
        )
    return Lens(
        matrix,
        dist,
        (size[0], size[1]),
        float(data.get("rms_reprojection_px", 0.0)),
        int(data.get("frames_used", 0)),
        path.name,
    )


#: Fewest views of the whole board :func:`fit_lens` accepts by default: with fewer
#: the focal length and the distortion terms trade off (five parameters and the
#: principal point from a handful of poses).
MIN_LENS_VIEWS = 5

#: RMS reprojection error above which a lens calibration is suspect [px]: corners
#: found to a tenth of a pixel fit the model to well below this, so a larger error
#: means a wrong pattern, a bent board, motion blur or a lens the model cannot follow.
MAX_LENS_RMS_PX = 1.0

#: Fraction of the frame the board's corners should span (their convex hull): the
#: distortion grows fastest toward the edges, and beyond the corners seen it is
#: extrapolated from the polynomial (OpenCV's advice: cover the whole frame).
MIN_LENS_COVERAGE = 0.3


def parse_pattern(text: str) -> tuple[int, int]:
    """Parse ``"9x6"`` (inner corners: columns x rows; ``,`` and ``*`` also work).

    Raises :class:`~fieldkit.errors.ArgumentError` (source ``pattern``) unless both
    counts are whole numbers of at least 3 (OpenCV's smallest board).

    Examples
    --------
    >>> parse_pattern("9x6"), parse_pattern(" 10 , 7 ")
    ((9, 6), (10, 7))
    """
    parts = [p.strip() for p in str(text).lower().replace("*", "x").replace(
        ",", "x").split("x")]  # fmt: skip
    try:
        cols, rows = (int(p) for p in parts)
    except ValueError:
        raise ArgumentError(
            f"expected inner corners COLUMNSxROWS, e.g. 9x6, got {text!r}",
            source="pattern",
        ) from None
    if cols < 3 or rows < 3:
        raise ArgumentError(
            f"a checkerboard needs at least 3x3 inner corners, got {text!r}",
            source="pattern",
        )
    return cols, rows


@dataclass(frozen=True)
class LensCalibration:
    """A lens calibrated from checkerboard views, and how well the views fit it.

    Attributes
    ----------
    lens
        The fitted :class:`Lens`.
    pattern
        Inner corners (columns, rows) searched for.
    frames_searched
        Frames looked at.
    views_found
        Frames in which the whole pattern was found.
    view_frames
        The frame number of each view used (the frame's index among those
        searched, or the clip's frame number).
    view_rms_px
        Each used view's RMS reprojection error [px].
    coverage
        Fraction of the frame inside the convex hull of every corner used: the
        distortion beyond it is extrapolated.

    Examples
    --------
    >>> lens = Lens(np.array([[500.0, 0, 320], [0, 500, 240], [0, 0, 1]]),
    ...             np.array([-0.2, 0.0, 0.0, 0.0, 0.0]), (640, 480), 0.12, 8)
    >>> fit = LensCalibration(lens, (9, 6), 60, 8, tuple(range(8)), (0.1,) * 8, 0.7)
    >>> fit.summary()[0]
    'the 9x6 inner corners were found in 8 of 60 frames searched; 8 views used'
    """

    lens: Lens
    pattern: tuple[int, int]
    frames_searched: int
    views_found: int
    view_frames: tuple[int, ...]
    view_rms_px: tuple[float, ...]
    coverage: float

    @property
    def warnings(self) -> list[str]:
        """One line for each sign that the lens may not be trusted."""
        out = []
        if self.lens.rms_px > MAX_LENS_RMS_PX:
            worst = int(np.argmax(self.view_rms_px))
            out.append(
                f"RMS reprojection error {self.lens.rms_px:.2f} px exceeds "
                f"{MAX_LENS_RMS_PX:g} px (worst view: frame "
                f"{self.view_frames[worst]}, {self.view_rms_px[worst]:.2f} px): a "
                "bent or blurred board, or a lens the model cannot follow; check the "
                "views"
            )
        if self.coverage < MIN_LENS_COVERAGE:
            out.append(
                f"the board's corners cover only {self.coverage:.0%} of the frame: "
                "the distortion near the edges is extrapolated; film the board near "
                "the edges and corners of the frame too"
            )
        return out

    def summary(self) -> list[str]:
        """The calibration in words: views, fit, intrinsics, distortion, its size."""
        cols, rows = self.pattern
        lens = self.lens
        k = np.ravel(lens.distortion)
        k = np.concatenate([k, np.zeros(max(0, 5 - len(k)))])
        m = lens.camera_matrix
        w, h = lens.image_size
        shift = lens.corner_shift_px()
        errors = np.asarray(self.view_rms_px)
        return [
            f"the {cols}x{rows} inner corners were found in {self.views_found} of "
            f"{self.frames_searched} frames searched; {len(self.view_frames)} views "
            "used",
            f"RMS reprojection error {lens.rms_px:.3f} px (per view "
            f"{errors.min():.3f}-{errors.max():.3f} px); the corners cover "
            f"{self.coverage:.0%} of the {w}x{h} frame",
            f"focal length fx = {m[0, 0]:.2f} px, fy = {m[1, 1]:.2f} px; principal "
            f"point cx = {m[0, 2]:.2f} px, cy = {m[1, 2]:.2f} px",
            f"distortion k1 = {k[0]:.5f}, k2 = {k[1]:.5f}, p1 = {k[2]:.5f}, "
            f"p2 = {k[3]:.5f}, k3 = {k[4]:.5f}",
            f"at the image corners the lens moves a point by up to {shift:.1f} px"
            + (
                " (negligible)"
                if shift < 0.5
                else " (undistorting matters)"
                if shift >= 2.0
                else ""
            ),
        ]

    def to_dict(self) -> dict:
        """The lens file's content (:func:`read_lens_file` reads it), with the
        calibration's record."""
        return {
            **self.lens.to_dict(),
            "source": self.lens.source,
            "pattern_inner_corners": list(self.pattern),
            "frames_searched": self.frames_searched,
            "views_found": self.views_found,
            "view_frames": list(self.view_frames),
            "view_rms_px": list(self.view_rms_px),
            "coverage": self.coverage,
            "corner_shift_px": self.lens.corner_shift_px(),
        }

    def write(self, path: str | os.PathLike[str], outputs=None) -> Path:
        """Save as the lens JSON (``outputs``: a :class:`fieldkit.outputs.OutputSet`
        to write with, all or nothing)."""
        from fieldkit.outputs import write_json

        return write_json(path, self.to_dict(), outputs, indent=1)


def fit_lens(
    frames,
    pattern: tuple[int, int],
    *,
    max_frames: int = 40,
    fix_k3: bool = True,
    min_views: int = MIN_LENS_VIEWS,
    source: str = "checkerboard",
) -> LensCalibration:
    """Lens distortion from images of a checkerboard (``cv2.calibrateCamera``).

    Parameters
    ----------
    frames
        Iterable of uint8 BGR (or grey) images of a flat checkerboard in various
        positions and tilts (e.g. frames sampled from a clip), all of one size.
    pattern
        Inner corners per row and per column (a board of 10 x 7 squares has 9 x 6).
    max_frames
        At most this many views with the whole pattern found are used (evenly).
    fix_k3
        Keep the sixth-order radial term at 0 (OpenCV's advice for all but
        fisheye lenses): with it free, ``k2`` and ``k3`` trade off and the model
        extrapolates wildly beyond the area the board covered.
    min_views
        Fewest views of the whole board accepted.
    source
        The frames' origin (a clip's name), for messages.

    Raises
    ------
    InputFileError
        The pattern is found in no frame (naming how many were searched), or in
        fewer than ``min_views``; frames of different sizes.
    """
    return _fit_numbered_frames(
        enumerate(frames),
        pattern,
        max_frames=max_frames,
        fix_k3=fix_k3,
        min_views=min_views,
        source=source,
    )


def _fit_numbered_frames(
    numbered, pattern, *, max_frames, fix_k3, min_views, source
) -> LensCalibration:
    """:func:`fit_lens` on ``(frame number, image)`` pairs."""
    cols, rows = int(pattern[0]), int(pattern[1])
    board = np.zeros((cols * rows, 3), np.float32)
    board[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2)
    criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 40, 1e-3)
    views, numbers, size, searched = [], [], None, 0
    for number, image in numbered:
        searched += 1
        grey = image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
        if size is not None and size != (grey.shape[1], grey.shape[0]):
            raise InputFileError(
                f"{grey.shape[1]}x{grey.shape[0]} px, the frames before it "
                f"{size[0]}x{size[1]} px",
                source=source,
                where=f"frame {number}",
            )
        size = (grey.shape[1], grey.shape[0])
        found, corners = cv2.findChessboardCorners(
            grey,
            (cols, rows),
            flags=cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE,
        )
        if found:
            half = _corner_window(corners.reshape(rows, cols, 2))
            views.append(
                cv2.cornerSubPix(grey, corners, (half, half), (-1, -1), criteria)
            )
            numbers.append(int(number))
    if searched == 0:
        raise InputFileError("no frame could be decoded", source=source)
    if not views:
        raise InputFileError(
            f"no {cols}x{rows} checkerboard (inner corners, columns x rows) found in "
            f"any of the {searched} frames searched; check `pattern` (a board of "
            f"{cols + 1} x {rows + 1} squares has {cols}x{rows} inner corners)",
            source=source,
        )
    if len(views) < min_views:
        raise InputFileError(
            f"the {cols}x{rows} inner corners were found in only {len(views)} of the "
            f"{searched} frames searched; at least {min_views} views of the whole "
            "board are needed ("
            + (
                "search more frames, or film it in more positions and tilts)"
                if len(views) == searched
                else "film it whole in more positions and tilts; check `pattern` "
                "if it is)"
            ),
            source=source,
        )
    found_count = len(views)
    if len(views) > max_frames:
        keep = np.linspace(0, len(views) - 1, max_frames).round().astype(int)
        views = [views[i] for i in keep]
        numbers = [numbers[i] for i in keep]
    rms, matrix, dist, rvecs, tvecs = cv2.calibrateCamera(
        [board] * len(views),
        views,
        size,
        None,
        None,
        flags=cv2.CALIB_FIX_K3 if fix_k3 else 0,
    )
    errors = []
    for corners, rvec, tvec in zip(views, rvecs, tvecs, strict=True):
        projected, _ = cv2.projectPoints(board, rvec, tvec, matrix, dist)
        diff = projected.reshape(-1, 2) - corners.reshape(-1, 2)
        errors.append(float(np.sqrt(np.mean(np.sum(diff**2, axis=1)))))
    hull = cv2.convexHull(np.concatenate(views).reshape(-1, 2).astype(np.float32))
    coverage = float(cv2.contourArea(hull)) / float(size[0] * size[1])
    lens = Lens(matrix, dist.ravel(), size, float(rms), len(views), source)
    return LensCalibration(
        lens,
        (cols, rows),
        searched,
        found_count,
        tuple(numbers),
        tuple(errors),
        min(coverage, 1.0),
    )


def _corner_window(grid: np.ndarray) -> int:
    """Half-size of the corner refinement window [px]: at most 5 (an 11 px square
    window), and less than a third of the closest corner spacing, so the window
    never reaches the neighbouring corners on a board filmed small."""
    spacing = min(
        float(np.min(np.hypot(*np.moveaxis(np.diff(grid, axis=0), -1, 0)))),
        float(np.min(np.hypot(*np.moveaxis(np.diff(grid, axis=1), -1, 0)))),
    )
    return int(np.clip(spacing // 3, 2, 5))


def calibrate_lens(
    frames,
    pattern: tuple[int, int],
    *,
    max_frames: int = 40,
    fix_k3: bool = True,
    source: str = "checkerboard",
) -> Lens:
    """The :class:`Lens` of :func:`fit_lens` (which see), from at least 3 views."""
    return fit_lens(
        frames,
        pattern,
        max_frames=max_frames,
        fix_k3=fix_k3,
        min_views=3,
        source=source,
    ).lens


def fit_lens_from_clip(
    path: str | os.PathLike[str],
    pattern: tuple[int, int],
    *,
    samples: int = 60,
    min_views: int = MIN_LENS_VIEWS,
) -> LensCalibration:
    """:func:`fit_lens` on ``samples`` frames spread evenly over a checkerboard clip
    (every frame when the clip has fewer); views are named by frame number."""
    from fieldkit.tracking.video.reader import VideoReader

    if int(samples) != samples or samples < 1:
        raise ArgumentError(
            f"samples must be a whole number >= 1, got {samples}", source="samples"
        )
    reader = VideoReader(path)
    count = max(reader.info.frame_count, 1)
    spread = np.linspace(0, count - 1, int(samples)).astype(int)
    indices = [int(i) for i in np.unique(spread)]

    def frames():
        for start in range(0, len(indices), 8):  # a few decoded frames at a time
            yield from reader.read_frames(indices[start : start + 8])

    return _fit_numbered_frames(
        frames(),
        pattern,
        max_frames=40,
        fix_k3=True,
        min_views=min_views,
        source=str(path),
    )


def calibrate_lens_from_clip(
    path: str | os.PathLike[str], pattern: tuple[int, int], *, samples: int = 60
) -> Lens:
    """The :class:`Lens` of :func:`fit_lens_from_clip`, from at least 3 views."""
    return fit_lens_from_clip(path, pattern, samples=samples, min_views=3).lens
