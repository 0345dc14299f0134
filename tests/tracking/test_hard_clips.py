"""Hard synthetic clips of video/hard.py: camera model, exact truth, determinism."""

from __future__ import annotations

import importlib.util
import json
import math
import sys

import cv2
import numpy as np
import pandas as pd
import pytest

G = 9.81


@pytest.fixture(scope="module")
def hard(repo):
    name = "fieldkit_video_render_hard"  # the name render.py's CLI loads it under
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, repo / "video" / "hard.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


def _frames(path):
    cap = cv2.VideoCapture(str(path))
    out = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        out.append(frame)
    cap.release()
    return out


def _blob_centre(mask):
    """Centroid of the largest blob of ``mask`` with its holes (the marker) filled."""
    contours, _ = cv2.findContours(
        mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE
    )
    filled = np.zeros(mask.shape, np.uint8)
    cv2.drawContours(filled, [max(contours, key=cv2.contourArea)], -1, 1, -1)
    vv, uu = np.nonzero(filled)
    return uu.mean(), vv.mean(), len(uu)


def _moving_lens_camera(hard):
    cam = hard.HardCamera(
        focal_px=420.0,
        k1=-0.28,
        k2=0.09,
        drift_m=0.01,
        drift_rad=0.015,
        shake_m=0.002,
        shake_rad=0.003,
        line_time_s=1e-4,
    )
    return cam, hard.Shake.draw(cam, np.random.default_rng(5))


def test_pixel_world_round_trip_through_lens_and_moving_camera(hard):
    cam, shake = _moving_lens_camera(hard)
    rng = np.random.default_rng(1)
    u, v = rng.uniform(0, cam.width - 1, 500), rng.uniform(0, cam.height - 1, 500)
    t = rng.uniform(0, 2, 500)
    x, z = hard.pixel_to_world(cam, shake, u, v, t)
    u2, v2 = hard.project(cam, shake, x, z, t)
    assert np.max(np.hypot(u2 - u, v2 - v)) < 1e-7
    # the still, undistorted camera is the plain clips' affine image
    still = hard.HardCamera()
    uu, vv = hard.project(still, hard.Shake.still(), 0.3, 0.2, 0.0)
    assert (uu, vv) == pytest.approx(
        (still.origin_u_px + 0.3 / 0.002, still.origin_v_px - 0.2 / 0.002), abs=1e-9
    )


def test_projection_matches_opencv_project_points(hard):
    """Independent reference: cv2.projectPoints with the camera's pose at time t."""
    cam, shake = _moving_lens_camera(hard)
    t = 0.37
    (cx_w, cy_w, cz_w), m = hard._camera_frame(cam, shake, t)
    rot = np.array([[float(m[i][j]) for j in range(3)] for i in range(3)])
    r0 = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], float)  # world -> camera axes
    r_wc = rot @ r0
    centre = np.array([cx_w, cy_w, cz_w], float)
    rvec, _ = cv2.Rodrigues(r_wc)
    tvec = -r_wc @ centre
    pts = np.array([[x, 0.0, z] for x in (-0.1, 0.4, 1.0) for z in (0.0, 0.3, 0.6)])
    ref, _ = cv2.projectPoints(pts, rvec, tvec, cam.matrix(), cam.distortion())
    u, v = hard.project(cam, shake, pts[:, 0], pts[:, 2], t)
    np.testing.assert_allclose(np.c_[u, v], ref.reshape(-1, 2), atol=1e-8)


@pytest.mark.parametrize(
    "name",
    sorted(
        n
        for n in (
            "hard_shadow",
            "hard_dark",
            "hard_blur",
            "hard_rolling",
            "hard_lens",
            "hard_handheld",
            "hard_h264",
            "hard_h264_120",
            "hard_h264_30",
            "hard_dust",
            "hard_freefall",
            "hard_table",
            "hard_all",
        )
    ),
)
def test_ball_truth_flights_are_parabolas_and_impacts_follow_the_model(hard, name):
    clip = hard.CLIPS[name]
    fps, n = clip.camera.capture_fps, clip.frames
    times = np.arange(n) / fps
    states, impacts = hard.motion(clip, times)
    impacts = [imp for imp in impacts if imp["t_s"] <= times[-1]]
    scene, ball = clip.scene, clip.body
    normal = np.array(
        [
            math.sin(math.radians(scene.surface_deg)),
            math.cos(math.radians(scene.surface_deg)),
        ]
    )
    bounds = [-1.0] + [imp["t_s"] for imp in impacts] + [1e9]
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        sel = (times > a) & (times < b)
        if sel.sum() < 4:
            continue
        px = np.polyfit(times[sel], states[sel, 0], 1)
        pz = np.polyfit(times[sel], states[sel, 1], 2)
        assert np.max(np.abs(np.polyval(px, times[sel]) - states[sel, 0])) < 1e-9
        assert np.max(np.abs(np.polyval(pz, times[sel]) - states[sel, 1])) < 1e-9
        assert pz[0] == pytest.approx(-G / 2, rel=1e-7)
    for imp, e_n in zip(impacts, scene.e_n, strict=False):
        centre = np.array([imp["x_m"], imp["z_m"]])
        assert (centre - scene.plate_point_m) @ normal == pytest.approx(
            ball.radius_m, abs=1e-12
        )
        assert imp["e_n"] == pytest.approx(e_n, rel=1e-12)
    # the ball never enters the plate
    gap = (states[:, :2] - scene.plate_point_m) @ normal - ball.radius_m
    assert gap.min() > -1e-12
    if name == "hard_freefall":
        assert impacts == []
        np.testing.assert_allclose(
            states[:, 1], scene.start_m[1] - 0.5 * G * times**2, atol=1e-12
        )
        assert ball.radius_m / clip.camera.scale_m_per_px < 6  # a small ball
    if name == "hard_blur":  # both bounces happen while the shutter is open
        assert len(impacts) == 2
        for imp in impacts:
            k = round(imp["t_s"] * fps)
            assert abs(imp["t_s"] - k / fps) < clip.camera.exposure_s / 2
    if name == "hard_table":  # contacts far shorter than a frame, several of them
        assert len(impacts) >= 4
    if name not in ("hard_freefall",):
        assert len(impacts) >= 2


def test_block_truth_corner_impacts(hard):
    clip = hard.CLIPS["hard_block"]
    block, scene = clip.body, clip.scene
    times = np.arange(clip.frames) / clip.camera.capture_fps
    states, impacts = hard.motion(clip, times)
    normal = np.array(
        [
            math.sin(math.radians(scene.surface_deg)),
            math.cos(math.radians(scene.surface_deg)),
        ]
    )
    assert len(impacts) >= 3
    m, inertia = block.mass_kg, block.inertia_kgm2
    for imp in impacts:
        st, _ = hard.motion(clip, np.array([imp["t_s"]]))
        corners = st[0, :2] + hard.block_corners(block, st[0, 4])
        gaps = (corners - scene.plate_point_m) @ normal
        assert gaps[imp["corner"]] == pytest.approx(0.0, abs=1e-10)
        assert gaps.min() > -1e-10
        assert imp["e_n"] == pytest.approx(scene.e_n, rel=1e-9)
        # frictionless, e < 1: the impact takes energy, the tangential momentum stays
        ke_i = 0.5 * m * (imp["vi_x_mps"] ** 2 + imp["vi_z_mps"] ** 2)
        ke_f = 0.5 * m * (imp["vf_x_mps"] ** 2 + imp["vf_z_mps"] ** 2)
        ke_i += 0.5 * inertia * imp["omega_i_radps"] ** 2
        ke_f += 0.5 * inertia * imp["omega_f_radps"] ** 2
        assert ke_f < ke_i
        assert imp["vft_mps"] == pytest.approx(imp["vit_mps"], abs=1e-12)
    # no corner ever below the plate
    for st in states:
        corners = st[:2] + hard.block_corners(block, st[4])
        assert ((corners - scene.plate_point_m) @ normal).min() > -1e-9


def test_rendered_truth_files_are_consistent(hard, tmp_path):
    name = "hard_table"
    truth = hard.render_hard(name, tmp_path, frames=60)
    clip = hard.CLIPS[name]
    fps = clip.camera.capture_fps
    table = pd.read_csv(tmp_path / f"{name}.truth.csv")
    labels = json.loads((tmp_path / f"{name}.labels.json").read_text())
    assert len(table) == truth["frames"] == labels["frames"] == 60
    u, v = hard.project(
        clip.camera, hard.Shake.still(), table["x_m"], table["z_m"], table["t_s"]
    )
    np.testing.assert_allclose(table["u_px"], u, atol=1e-6)
    np.testing.assert_allclose(table["v_px"], v, atol=1e-6)
    assert set(labels) >= {
        "clip",
        "file",
        "frames",
        "container_fps",
        "capture_fps",
        "capture_fps_sd",
        "capture_fps_how",
        "size_px",
        "scale",
        "body",
        "contacts",
        "flights",
        "conditions",
        "label_uncertainty_frames",
        "notes",
    }
    assert labels["size_px"] == [clip.camera.width, clip.camera.height]
    assert len(labels["contacts"]) == len(truth["impacts"]) == 1
    for c, imp in zip(labels["contacts"], truth["impacts"], strict=True):
        assert c["first_frame"] / fps <= imp["t_s"] < (c["first_frame"] + 1) / fps
        assert c["last_frame"] == c["first_frame"] + 1 and c["sub_frame"] is True
    flights = labels["flights"]
    assert [f["last_frame"] + 1 for f in flights[:-1]] == [
        c["last_frame"] for c in labels["contacts"]
    ]
    # the scale points are the imaged scale marks, their distance the stated length
    (x1, z1), (x2, z2) = truth["scale_points_m"]
    assert labels["scale"]["length_m"] == pytest.approx(math.hypot(x2 - x1, z2 - z1))
    # the first box holds the ball's image: 2 r / scale wide
    box = labels["body"]["first_box_px"]
    diameter_px = 2 * clip.body.radius_m / clip.camera.scale_m_per_px
    assert box[2] == pytest.approx(diameter_px, rel=0.01)
    # the rendered ball's colour centroid sits on the truth's pixel centre
    frames = _frames(tmp_path / f"{name}.avi")
    assert len(frames) == 60
    k = 20
    f = frames[k].astype(float)
    mask = (f[:, :, 1] - f[:, :, 0] > 100) & (f[:, :, 2] > 150)
    uc, vc, _ = _blob_centre(mask)
    assert np.hypot(uc - table["u_px"][k], vc - table["v_px"][k]) < 0.5


def test_rolling_shutter_shows_the_ball_where_its_rows_were_read(hard, tmp_path):
    name = "hard_rolling"
    hard.render_hard(name, tmp_path, frames=24)
    table = pd.read_csv(tmp_path / f"{name}.truth.csv")
    frames = _frames(tmp_path / f"{name}.avi")
    errors_rs, errors_frame = [], []
    for k in range(2, 24):
        f = frames[k].astype(float)
        mask = (f[:, :, 2] - f[:, :, 0] > 100) & (f[:, :, 1] > 120)
        uc, vc, area = _blob_centre(mask)
        if area < 200:
            continue
        errors_rs.append(np.hypot(uc - table["u_rs_px"][k], vc - table["v_rs_px"][k]))
        errors_frame.append(np.hypot(uc - table["u_px"][k], vc - table["v_px"][k]))
    assert len(errors_rs) >= 16
    assert max(errors_rs) < 0.35  # measured 0.02-0.28 px (the shear, the codec)
    assert max(errors_frame) > 20.0  # the frame-time centre: up to 35 px off


def test_checkerboard_clip_calibrates_the_lens(hard, tmp_path):
    truth = hard.render_checker(tmp_path, views=10)
    frames = _frames(tmp_path / "hard_lens_checker.avi")
    assert len(frames) == truth["frames"]
    pattern = tuple(truth["pattern_size"])
    obj = np.array(truth["object_points_m"], np.float32)
    obj_pts, img_pts, errs = [], [], []
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-4)
    for frame, view in zip(frames, truth["views"], strict=True):
        grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
        ok, corners = cv2.findChessboardCorners(grey, pattern)
        if not ok:
            continue
        corners = cv2.cornerSubPix(grey, corners, (5, 5), (-1, -1), crit)
        ref = np.array(view["corners_px"])
        found = corners.reshape(-1, 2)
        if np.linalg.norm(found[0] - ref[0]) > np.linalg.norm(found[0] - ref[-1]):
            found = found[::-1]  # the detector may start at the opposite corner
        errs.append(np.sqrt(np.mean(np.sum((found - ref) ** 2, axis=1))))
        obj_pts.append(obj)
        img_pts.append(found.astype(np.float32).reshape(-1, 1, 2))
    assert len(obj_pts) == 10
    assert np.median(errs) < 0.15  # px: the rendered corners sit where the truth says
    rms, k_mat, dist, _, _ = cv2.calibrateCamera(
        obj_pts,
        img_pts,
        (640, 360),
        None,
        None,
        flags=cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K3,
    )
    true_k, true_d = np.array(truth["camera_matrix"]), np.array(truth["distortion"])
    assert rms < 0.2
    assert k_mat[0, 0] == pytest.approx(true_k[0, 0], rel=0.01)
    assert k_mat[1, 1] == pytest.approx(true_k[1, 1], rel=0.01)
    assert dist[0, 0] == pytest.approx(true_d[0], abs=0.01)  # k1 = -0.28
    assert dist[0, 1] == pytest.approx(true_d[1], abs=0.03)  # k2 = 0.09


@pytest.mark.parametrize("name, frames", [("hard_all", 6), ("hard_block", 4)])
def test_rendering_is_deterministic(hard, tmp_path, name, frames):
    hard.render_hard(name, tmp_path / "a", frames=frames)
    hard.render_hard(name, tmp_path / "b", frames=frames)
    for suffix in ("truth.json", "truth.csv", "labels.json", "calibration.json"):
        a = (tmp_path / "a" / f"{name}.{suffix}").read_bytes()
        assert a == (tmp_path / "b" / f"{name}.{suffix}").read_bytes(), suffix
    ext = hard.CLIPS[name].camera.extension
    fa, fb = (
        _frames(tmp_path / "a" / f"{name}{ext}"),
        _frames(tmp_path / "b" / f"{name}{ext}"),
    )
    assert len(fa) == len(fb) == frames
    assert all(np.array_equal(x, y) for x, y in zip(fa, fb, strict=True))


def test_handheld_truth_gives_the_camera_motion(hard, tmp_path):
    name = "hard_handheld"
    truth = hard.render_hard(name, tmp_path, frames=8)
    table = pd.read_csv(tmp_path / f"{name}.truth.csv")
    clip = hard.CLIPS[name]
    shake = hard.Shake(
        *(
            np.array(truth["camera_model"]["shake"][k])
            for k in ("freq_hz", "amp", "phase_rad")
        )
    )
    pose = shake.pose(table["t_s"].to_numpy())
    cols = [
        "cam_x_m",
        "cam_y_m",
        "cam_z_m",
        "cam_yaw_rad",
        "cam_pitch_rad",
        "cam_roll_rad",
    ]
    np.testing.assert_allclose(table[cols].to_numpy(), pose.T, atol=1e-9)
    u, v = hard.project(clip.camera, shake, table["x_m"], table["z_m"], table["t_s"])
    np.testing.assert_allclose(table["u_px"], u, atol=1e-6)
    # the stated sds: sum_k a_k^2 / 2 per axis, drift and shake together
    cam = clip.camera
    stated = (
        np.array([cam.drift_m] * 3 + [cam.drift_rad] * 3) ** 2
        + np.array([cam.shake_m] * 3 + [cam.shake_rad] * 3) ** 2
    )
    np.testing.assert_allclose(0.5 * (shake.amp**2).sum(axis=1), stated, rtol=1e-9)
    long = shake.pose(np.arange(0, 400, 0.01))
    np.testing.assert_allclose(long.std(axis=1), np.sqrt(stated), rtol=0.05)
    # the camera moves: the world origin's image drifts by pixels over the clip
    t = np.linspace(0, clip.frames / clip.camera.capture_fps, 50)
    u0, v0 = hard.project(clip.camera, shake, 0.0, 0.0, t)
    assert np.ptp(u0) > 3 and np.ptp(v0) > 3


def test_shadow_touches_the_ball_at_contact_and_lies_down_light_when_high(hard):
    clip = hard.CLIPS["hard_shadow"]
    sh, scene, r = clip.shadow, clip.scene, clip.body.radius_m
    psi = math.radians(scene.surface_deg)
    tangent = np.array([math.cos(psi), -math.sin(psi)])
    normal = np.array([math.sin(psi), math.cos(psi)])
    p0 = np.array(scene.plate_point_m)
    foot = p0 + 0.3 * tangent
    # at contact: just below the contact point the ground is in full shadow
    centre = foot + r * normal
    below = foot - 0.3 * r * normal
    fac = hard.shadow_factor(clip, below[0], below[1], *centre)
    assert fac < 1 - 0.8 * sh.strength  # 0.42 at 0.65 strength
    edge = foot - 0.02 * r * normal  # the shadow's edge reaches the contact point
    fac = hard.shadow_factor(clip, edge[0], edge[1], *centre)
    assert fac < 1 - 0.4 * sh.strength
    # 0.3 m above the plate: no shadow under the ball, full shadow down the light
    centre = foot + (r + 0.3) * normal
    fac = hard.shadow_factor(clip, below[0], below[1], *centre)
    assert fac > 0.999  # only the logistic penumbra tail
    light = np.array(
        [math.cos(math.radians(sh.light_deg)), -math.sin(math.radians(sh.light_deg))]
    )
    hit = centre + (r + 0.3) / -(light @ normal) * light  # the ray meets the plate
    spot = hit - sh.face_offset_r * r * normal
    fac = hard.shadow_factor(clip, spot[0], spot[1], *centre)
    soft = (sh.soft_r * r + sh.soft_per_m * 0.3) / (sh.across_r * r)  # penumbra
    assert fac == pytest.approx(1 - sh.strength / (1 + math.exp(-1 / soft)), rel=1e-9)
    assert fac < 1 - 0.9 * sh.strength  # its darkest point: 0.40
    assert np.linalg.norm(hit - foot) > 0.2  # the shadow lies > 0.2 m from the ball
    # nothing above the plate's surface line is shaded
    above = hit + 0.01 * normal
    assert hard.shadow_factor(clip, above[0], above[1], *centre) == 1.0


def test_dust_appears_at_the_impacts_above_the_plate_and_fades(hard):
    clip = hard.CLIPS["hard_dust"]
    times = np.arange(clip.frames) / clip.camera.capture_fps
    _, impacts = hard.motion(clip, times)
    impacts = [imp for imp in impacts if imp["t_s"] <= times[-1]]
    particles = hard.dust_particles(clip, impacts, np.random.default_rng(3))
    assert len(particles) == clip.dust.particles * len(impacts)
    t1 = impacts[0]["t_s"]
    assert len(hard.dust_state(clip, particles, t1 - 1e-6)[0]) == 0
    psi = math.radians(clip.scene.surface_deg)
    normal = np.array([math.sin(psi), math.cos(psi)])
    opacity = []
    for dt in (0.01, 0.05, 0.2):
        x, z, size, opac = hard.dust_state(clip, particles, t1 + dt)
        assert len(x) == clip.dust.particles
        height = (np.c_[x, z] - clip.scene.plate_point_m) @ normal
        assert height.min() > 0.0
        opacity.append(opac.sum())
    assert opacity[0] > opacity[1] > opacity[2]


_ALL_CLIPS = (
    "hard_shadow",
    "hard_dark",
    "hard_blur",
    "hard_rolling",
    "hard_lens",
    "hard_lens_checker",
    "hard_handheld",
    "hard_h264",
    "hard_h264_120",
    "hard_h264_30",
    "hard_block",
    "hard_dust",
    "hard_freefall",
    "hard_table",
    "hard_all",
)


@pytest.mark.parametrize(
    "name", sorted(n for n in _ALL_CLIPS if n != "hard_lens_checker")
)
def test_labels_agree_with_the_exact_truth(hard, tmp_path, name):
    """Every clip's labels (the real corpus's schema) against its truth files."""
    truth = hard.render_hard(name, tmp_path, video=False)
    clip = hard.CLIPS[name]
    cam, fps = clip.camera, clip.camera.capture_fps
    labels = json.loads((tmp_path / f"{name}.labels.json").read_text())
    table = pd.read_csv(tmp_path / f"{name}.truth.csv")
    assert labels["capture_fps"] == fps and labels["container_fps"] == cam.container_fps
    assert labels["file"] == f"{name}{cam.extension}"
    assert labels["conditions"] == truth["conditions"] and labels["conditions"]
    assert len(table) == labels["frames"] == clip.frames
    # contacts bracket the exact impact times; none in a free fall
    assert len(labels["contacts"]) == len(truth["impacts"])
    for c, imp in zip(labels["contacts"], truth["impacts"], strict=True):
        assert c["first_frame"] <= imp["t_s"] * fps < c["first_frame"] + 1
        assert c["sub_frame"] is True and c["kind"] == "impact"
        assert c["surface"] == clip.surface
    # flights: the in-image frames strictly between contacts
    times = table["t_s"].to_numpy()
    for f in labels["flights"]:
        sel = slice(f["first_frame"], f["last_frame"] + 1)
        assert table["visible"][sel].all()
        inside = [
            imp
            for imp in truth["impacts"]
            if times[sel][0] < imp["t_s"] < times[sel][-1]
        ]
        assert inside == []
    # world <-> pixel through the camera model at each frame's time
    shake = hard.Shake(
        *(
            np.array(truth["camera_model"]["shake"][k])
            for k in ("freq_hz", "amp", "phase_rad")
        )
    )
    u, v = hard.project(cam, shake, table["x_m"], table["z_m"], times)
    np.testing.assert_allclose(
        np.c_[table["u_px"], table["v_px"]], np.c_[u, v], atol=1e-6
    )
    x, z = hard.pixel_to_world(cam, shake, table["u_px"], table["v_px"], times)
    np.testing.assert_allclose(np.c_[x, z], table[["x_m", "z_m"]], atol=1e-8)
    # the scale points are the scale marks' images, the box the body's first image
    for (xm, zm), (us, vs) in zip(
        truth["scale_points_m"], labels["scale"]["points_px"], strict=True
    ):
        assert hard.project(cam, shake, xm, zm, 0.0) == pytest.approx(
            (us, vs), abs=1e-6
        )
    k = labels["body"]["first_box_frame"]
    u0, v0, w, h = labels["body"]["first_box_px"]
    assert u0 < table["u_px"][k] < u0 + w and v0 < table["v_px"][k] < v0 + h
