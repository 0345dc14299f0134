"""Camera drift: the motion of a hand-held or wind-shaken camera, measured and removed.

A static-background detector sees a drifting scene as motion everywhere. The scene's
motion from a reference frame is measured on background corners
(``cv2.goodFeaturesToTrack``, tracked with pyramidal Lucas-Kanade optical flow) and
fitted as a similarity transform (rotation, uniform scale, shift;
``cv2.estimateAffinePartial2D`` with RANSAC, so the moving body and other movers
are outliers; corners near the body's predicted position are left out first). Each
frame is warped onto the reference before it is compared with the background, so
detections are in the reference frame's pixels, where the calibration points were
taken.
"""

from __future__ import annotations

import cv2
import numpy as np

#: drift [px] below which a clip is not stabilised: warping resamples every pixel
#: (a slight blur) and below this the measured motion is mostly measurement noise
MIN_DRIFT_PX = 0.3


def _grey(image: np.ndarray) -> np.ndarray:
    return image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)


class Stabiliser:
    """Motion of each frame relative to ``reference`` (uint8 BGR or grey).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> ref = cv2.GaussianBlur(rng.integers(0, 255, (120, 160), np.uint8), (5, 5), 0)
    >>> moved = np.roll(ref, (2, 3), axis=(0, 1))  # 3 px right, 2 px down
    >>> s = Stabiliser(ref)
    >>> m = s.motion(moved)
    >>> [round(float(x), 1) for x in (m[0, 2], m[1, 2])]
    [-3.0, -2.0]
    >>> 3.5 < s.drift_px(m) < 3.8  # hypot(3, 2) = 3.6, plus a slight rotation
    True
    """

    def __init__(self, reference: np.ndarray, max_corners: int = 400) -> None:
        self.reference = _grey(reference)
        h, w = self.reference.shape[:2]
        self.size = (w, h)
        points = cv2.goodFeaturesToTrack(
            self.reference, max_corners, qualityLevel=0.01, minDistance=8, blockSize=7
        )
        self.points = (
            np.empty((0, 1, 2), np.float32) if points is None else points
        ).astype(np.float32)

    def motion(
        self, frame: np.ndarray, exclude: tuple[float, float, float] | None = None
    ) -> np.ndarray | None:
        """2x3 matrix taking ``frame`` pixels to reference pixels, or None.

        ``exclude`` = (u, v, radius) [px]: corners within it (the body) are not used.
        None when fewer than 8 corners are followed.
        """
        points = self.points
        if exclude is not None and len(points):
            u, v, reach = exclude
            far = np.hypot(points[:, 0, 0] - u, points[:, 0, 1] - v) > reach
            points = points[far]
        if len(points) < 8:
            return None
        grey = _grey(frame)
        moved, status, _ = cv2.calcOpticalFlowPyrLK(
            self.reference, grey, points, None, winSize=(21, 21), maxLevel=3
        )
        back, status_back, _ = cv2.calcOpticalFlowPyrLK(
            grey, self.reference, moved, None, winSize=(21, 21), maxLevel=3
        )
        ok = (status.ravel() == 1) & (status_back.ravel() == 1)
        ok &= np.hypot(*(back - points).reshape(-1, 2).T) < 0.5  # forward-backward
        if ok.sum() < 8:
            return None
        matrix, inliers = cv2.estimateAffinePartial2D(
            moved[ok],
            points[ok],
            method=cv2.RANSAC,
            ransacReprojThreshold=1.0,
            refineIters=20,
        )
        if matrix is None or inliers is None or inliers.sum() < 8:
            return None
        return matrix

    def drift_px(self, matrix: np.ndarray | None) -> float:
        """Largest shift [px] the motion ``matrix`` gives a corner of the frame."""
        if matrix is None:
            return float("nan")
        w, h = self.size
        corners = np.array([[0, 0], [w - 1, 0], [0, h - 1], [w - 1, h - 1]], float)
        mapped = corners @ matrix[:, :2].T + matrix[:, 2]
        return float(np.max(np.hypot(*(mapped - corners).T)))

    def warp(
        self,
        frame: np.ndarray,
        matrix: np.ndarray | None,
        fill: np.ndarray | None = None,
    ) -> np.ndarray:
        """``frame`` resampled onto the reference (as it is when ``matrix`` is None).

        Reference pixels the frame does not see are taken from ``fill`` (the
        background model, so they differ from nothing), else from the nearest edge.
        """
        if matrix is None:
            return frame
        if fill is not None:
            return cv2.warpAffine(
                frame,
                matrix,
                self.size,
                dst=fill.copy(),
                flags=cv2.INTER_LINEAR,
                borderMode=cv2.BORDER_TRANSPARENT,
            )
        return cv2.warpAffine(
            frame,
            matrix,
            self.size,
            flags=cv2.INTER_LINEAR,
            borderMode=cv2.BORDER_REPLICATE,
        )
