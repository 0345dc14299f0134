"""Detection on what real footage brings: shadows, dark-on-dark, motion blur, drift,
lens distortion; refusal reasons. Synthetic frames with exact truth."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from fieldkit.tracking.video.calibration import Lens, calibrate_lens
from fieldkit.tracking.video.detection import BallDetector, DetectorSettings
from fieldkit.tracking.video.image_difference import shadow_mask
from fieldkit.tracking.video.stabilisation import Stabiliser

H, W = 240, 320


def _texture(rng, mean=(120, 130, 110), spread=40.0):
    """A smooth colour texture (uint8 BGR) with corners for the stabiliser."""
    noise = rng.standard_normal((H, W, 3)).astype(np.float32)
    smooth = cv2.GaussianBlur(noise, (0, 0), 3.0)
    smooth /= smooth.std()
    img = np.asarray(mean, np.float32) + spread * smooth
    return np.clip(img, 0, 255)


def _coverage(uc, vc, r, shape=(H, W), ss=8, sweep=(0.0, 0.0), steps=1):
    """Exact-ish area coverage of a disc (super-sampled ss x ss), optionally
    averaged over ``steps`` positions along ``sweep`` [px] (motion blur), centred on
    (uc, vc) at mid-exposure."""
    h, w = shape
    offs = (np.arange(ss) + 0.5) / ss - 0.5
    uu = (np.arange(w)[None, :, None, None] + offs[None, None, None, :]).astype(
        np.float32
    )
    vv = (np.arange(h)[:, None, None, None] + offs[None, None, :, None]).astype(
        np.float32
    )
    total = np.zeros(shape, np.float32)
    for t in np.linspace(-0.5, 0.5, steps) if steps > 1 else [0.0]:
        cu, cv = uc + t * sweep[0], vc + t * sweep[1]
        inside = (uu - cu) ** 2 + (vv - cv) ** 2 <= r * r
        total += inside.mean(axis=(2, 3))
    return total / steps


def _compose(background, alpha, colour, rng, noise=2.0):
    img = background * (1 - alpha[..., None]) + np.asarray(colour) * alpha[..., None]
    img = img + noise * rng.standard_normal(img.shape[:2])[..., None]
    return np.clip(img + 0.5, 0, 255).astype(np.uint8)


def _background_u8(background):
    return np.clip(background + 0.5, 0, 255).astype(np.uint8)


def test_shadow_merged_with_the_ball_is_left_out():
    rng = np.random.default_rng(3)
    bg = _texture(rng)
    uc, vc, r = 150.3, 100.6, 12.0
    # a soft elliptic cast shadow below-right of the ball, touching it: 55 % light
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float32)
    ellipse = ((xx - 168.0) / 22.0) ** 2 + ((yy - 116.0) / 11.0) ** 2
    shade = 1.0 - 0.45 * np.clip((1.15 - ellipse) / 0.3, 0.0, 1.0)
    shaded = bg * shade[..., None]
    frame = _compose(shaded, _coverage(uc, vc, r), (30, 140, 230), rng)
    background = _background_u8(bg)
    assert shadow_mask(frame, background)[116, 175]  # the test labels it
    detector = BallDetector(background, 20.0)
    det = detector.detect(frame)
    assert det is not None and det.status == "ok"
    assert np.hypot(det.u_px - uc, det.v_px - vc) < 0.3
    assert det.radius_px == pytest.approx(r, abs=0.4)
    # without the shadow test the blob is ball + shadow: refused or off-centre
    plain = BallDetector(
        background, 20.0, settings=DetectorSettings(suppress_shadows=False)
    )
    det = plain.detect(frame)
    assert det is None or np.hypot(det.u_px - uc, det.v_px - vc) > 1.0


def test_a_shadow_alone_is_refused_as_shadow():
    rng = np.random.default_rng(4)
    bg = _texture(rng)
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float32)
    disc = ((xx - 160.0) ** 2 + (yy - 120.0) ** 2) <= 14.0**2  # a round shadow
    shaded = bg * np.where(disc, 0.6, 1.0)[..., None]
    frame = _compose(shaded, np.zeros((H, W), np.float32), (0, 0, 0), rng)
    detector = BallDetector(_background_u8(bg), 20.0)
    assert detector.detect(frame) is None
    assert detector.status == "shadow"


def test_dark_ball_on_dark_texture_whole_silhouette():
    """A dark grey ball (shaded: one side 12 grey levels above the scene, the other
    30) on a dark texture: the radius is the whole disc's, not the bright side's."""
    rng = np.random.default_rng(5)
    bg = _texture(rng, mean=(28, 28, 30), spread=3.0)
    uc, vc, r = 161.4, 118.2, 14.0
    alpha = _coverage(uc, vc, r)
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float32)
    lit = np.clip(0.5 + 0.5 * (xx - uc) / r, 0.0, 1.0)  # brighter to the right
    body = 40.0 + 18.0 * lit
    img = bg * (1 - alpha[..., None]) + (body * alpha)[..., None]
    img += 1.5 * rng.standard_normal((H, W))[..., None]
    frame = np.clip(img + 0.5, 0, 255).astype(np.uint8)
    detector = BallDetector(_background_u8(bg), 17.5)  # noise 1.5: 5 sigma + 10
    det = detector.detect(frame)
    assert det is not None
    assert det.radius_px == pytest.approx(r, abs=1.0)
    assert np.hypot(det.u_px - uc, det.v_px - vc) < 0.6


def test_motion_streak_centre_is_the_mid_exposure_position():
    rng = np.random.default_rng(6)
    bg = _texture(rng)
    uc, vc, r = 160.2, 110.7, 9.0
    sweep = (26.0, 9.0)  # px travelled during the exposure
    alpha = _coverage(uc, vc, r, sweep=sweep, steps=40)
    frame = _compose(bg, alpha, (40, 60, 230), rng)
    detector = BallDetector(_background_u8(bg), 20.0, expected_radius_px=r)
    det = detector.detect(frame, (uc - 5, vc - 2, 60.0), velocity=sweep)
    assert det is not None and det.blurred and det.status == "blurred"
    assert np.hypot(det.u_px - uc, det.v_px - vc) < 0.5
    assert det.position_sd_px > 0.5
    # a streak across the predicted velocity is not this body
    across = (-sweep[1], sweep[0])
    detector = BallDetector(_background_u8(bg), 20.0, expected_radius_px=r)
    assert detector.detect(frame, (uc, vc, 60.0), velocity=across) is None
    assert detector.status == "not_round"


def test_stabilised_frame_gives_the_centre_in_reference_pixels():
    rng = np.random.default_rng(7)
    pad = 20
    global H, W
    big = np.zeros((H + 2 * pad, W + 2 * pad, 3), np.float32)
    shape = big.shape[:2]
    noise = rng.standard_normal(big.shape).astype(np.float32)
    big = np.clip(120 + 40 * cv2.GaussianBlur(noise, (0, 0), 3.0) / 0.09, 0, 255)
    uc, vc, r = 170.4, 90.3, 10.0
    alpha = _coverage(uc + pad, vc + pad, r, shape=shape)
    scene = big * (1 - alpha[..., None]) + np.float32((30, 200, 240)) * alpha[..., None]
    # the camera turned 0.4 deg and moved (3.3, -2.2) px: frame = M(reference)
    m = cv2.getRotationMatrix2D((W / 2 + pad, H / 2 + pad), 0.4, 1.0)
    m[:, 2] += (3.3, -2.2)
    moved = cv2.warpAffine(scene, m, shape[::-1], flags=cv2.INTER_LINEAR)
    crop = (slice(pad, pad + H), slice(pad, pad + W))
    frame = np.clip(moved[crop] + 0.5, 0, 255).astype(np.uint8)
    background = _background_u8(big[crop])
    stab = Stabiliser(background)
    matrix = stab.motion(frame, exclude=None)
    back = cv2.invertAffineTransform(m)
    corners = np.array([[0, 0], [W - 1, H - 1], [W - 1, 0]], float)
    got = corners @ matrix[:, :2].T + matrix[:, 2]
    want = (corners + pad) @ back[:, :2].T + back[:, 2] - pad
    assert np.max(np.hypot(*(got - want).T)) < 0.1
    detector = BallDetector(background, 20.0)
    det = detector.detect(stab.warp(frame, matrix, fill=background))
    assert det is not None and det.status == "ok"
    assert np.hypot(det.u_px - uc, det.v_px - vc) < 0.1
    # without stabilising, the drifted texture swamps the difference
    det = BallDetector(background, 20.0).detect(frame)
    assert det is None or np.hypot(det.u_px - uc, det.v_px - vc) > 1.0


def _distortion_map(lens: Lens, size):
    """Where each pixel of the distorted image samples the ideal image: its
    undistorted position (cv2.remap maps)."""
    w, h = size
    vv, uu = np.mgrid[0:h, 0:w].astype(np.float64)
    u, v = lens.undistort(uu, vv)
    return u.astype(np.float32), v.astype(np.float32)


def test_lens_from_checkerboard_views_recovers_the_distortion():
    k = np.array([[420.0, 0, 322.0], [0, 420.0, 238.0], [0, 0, 1]])
    truth = Lens(k, np.array([-0.25, 0.08, 0.0, 0.0, 0.0]), (640, 480))
    square = 40
    board = np.kron(
        (np.indices((8, 11)).sum(axis=0) % 2) * 255, np.ones((square, square))
    ).astype(np.uint8)
    board = cv2.copyMakeBorder(
        board, square, square, square, square, cv2.BORDER_CONSTANT, value=255
    )
    bh, bw = board.shape
    # board pixels -> plane metres (a square is 0.1 m), centred
    plane = np.array(
        [[0.0025, 0, -0.0025 * bw / 2], [0, 0.0025, -0.0025 * bh / 2], [0, 0, 1]]
    )
    rng = np.random.default_rng(8)
    remap = _distortion_map(truth, (640, 480))
    views = []
    for i in range(16):  # the board from random poses, centre and corners
        rvec = np.array(
            [rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3)]
        )
        rot, _ = cv2.Rodrigues(rvec)
        z = rng.uniform(1.9, 2.3)
        corner = np.array([(-1) ** i, (-1) ** (i // 2)]) * (i >= 4)
        t = np.array([*(corner * (0.75, 0.55) * z / 2.1), z])
        h = k @ np.column_stack([rot[:, 0], rot[:, 1], t]) @ plane
        ideal = cv2.warpPerspective(board, h, (640, 480), borderValue=128)
        views.append(cv2.remap(ideal, *remap, cv2.INTER_LINEAR, borderValue=128))
    lens = calibrate_lens(views, (10, 7))
    assert lens.frames_used >= 7
    assert lens.rms_px < 0.3
    # points toward the corners undistort to where the true lens puts them
    u = np.array([40.0, 600.0, 320.0, 100.0])
    v = np.array([40.0, 430.0, 100.0, 400.0])
    ut, vt = truth.undistort(u, v)
    ue, ve = lens.undistort(u, v)
    # measured: 1.1 px at (40, 40) where the lens moves the point by 57 px, 0.6 px
    # at (600, 430) (a 17-view calibration, corners from 0.19 px RMS)
    shift = np.hypot(ut - u, vt - v)
    assert shift[0] > 50.0  # the distortion is real
    assert np.all(np.hypot(ue - ut, ve - vt) < 0.03 * shift + 0.2)
    assert lens.camera_matrix[0, 0] == pytest.approx(420.0, rel=0.01)


def test_refusal_reasons_name_what_was_seen():
    rng = np.random.default_rng(9)
    bg = _texture(rng)
    background = _background_u8(bg)
    detector = BallDetector(background, 20.0, expected_radius_px=10.0)
    empty = _compose(bg, np.zeros((H, W), np.float32), (0, 0, 0), rng)
    assert detector.detect(empty) is None and detector.status == "no_candidate"
    bar = empty.copy()
    cv2.rectangle(bar, (100, 100), (220, 125), (250, 250, 250), -1)
    assert detector.detect(bar) is None and detector.status == "not_round"
    big = _compose(bg, _coverage(160.0, 120.0, 25.0), (30, 140, 230), rng)
    assert detector.detect(big) is None and detector.status == "off_size"
    roi = BallDetector(background, 20.0, roi=(0, 0, 100, 100))
    ball = _compose(bg, _coverage(200.0, 150.0, 10.0), (30, 140, 230), rng)
    assert roi.detect(ball) is None and roi.status == "outside_roi"


def test_track_video_on_a_drifting_clip_with_shadow_and_gaps(tmp_path):
    """A short MJPG clip: the ball with a cast shadow crosses a textured scene
    filmed by a drifting camera; three frames show no ball. The track is in the
    first frame's pixels, every frame has a status and the drift is found."""
    from fieldkit.tracking.video.calibration import two_point_scale
    from fieldkit.tracking.video.pipeline import track_video

    rng = np.random.default_rng(10)
    pad, n = 16, 30
    shape = (H + 2 * pad, W + 2 * pad)
    noise = rng.standard_normal((*shape, 3)).astype(np.float32)
    smooth = cv2.GaussianBlur(noise, (0, 0), 3.0)
    big = np.clip(120 + 40 * smooth / smooth.std(), 0, 255)
    yy, xx = np.mgrid[0 : shape[0], 0 : shape[1]].astype(np.float32)
    path = tmp_path / "drift.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 30, (W, H))
    truth = {}
    for k in range(n):
        uc, vc = 40.0 + 8.1 * k, 60.0 + 0.12 * k * k  # reference-frame pixels
        img = big.copy()
        if k not in (12, 13, 14):
            ellipse = ((xx - uc - pad - 14) / 20) ** 2 + ((yy - vc - pad - 12) / 9) ** 2
            img *= (1.0 - 0.4 * np.clip((1.1 - ellipse) / 0.2, 0, 1))[..., None]
            alpha = _coverage(uc + pad, vc + pad, 10.0, shape=shape)[..., None]
            img = img * (1 - alpha) + np.float32((40, 90, 235)) * alpha
            truth[k] = (uc, vc + 1.2)  # in frame 0, shifted by (0, 1.2) px
        shift = (1.5 * np.sin(k / 4.0) + 0.1 * k, 1.2 * np.cos(k / 5.0))
        m = np.float32([[1, 0, shift[0]], [0, 1, shift[1]]])
        moved = cv2.warpAffine(img, m, shape[::-1], flags=cv2.INTER_LINEAR)
        frame = moved[pad : pad + H, pad : pad + W]
        frame = frame + 1.5 * rng.standard_normal((H, W, 1))
        writer.write(np.clip(frame + 0.5, 0, 255).astype(np.uint8))
    writer.release()
    cal = two_point_scale((0.0, 0.0, 100.0, 0.0), 1.0, (W, H))
    track, detections = track_video(path, fps=30.0, calibration=cal, radius_m=0.1)
    assert track.meta["stabilised"] and track.meta["camera_drift_px"] > 1.0
    found = detections[detections["found"]].set_index("frame")
    assert set(found.index) == set(truth)
    err = [
        np.hypot(found.at[k, "u_px"] - u, found.at[k, "v_px"] - v)
        for k, (u, v) in truth.items()
    ]
    assert np.median(err) < 0.3 and np.max(err) < 1.0
    status = detections.set_index("frame")["detect_status"]
    assert set(status.loc[[12, 13, 14]]) <= {"no_candidate", "shadow"}
    assert sum(track.meta["detect_status"].values()) == n
