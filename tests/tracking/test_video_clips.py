"""Synthetic clips of video/render.py: physics of the truth, calibration, reading."""

from __future__ import annotations

import importlib.util
import json
import sys

import numpy as np
import pandas as pd
import pytest

from fieldkit.physics.local_axes import to_local
from fieldkit.tracking.video.reader import VideoReader, fps_mismatch_message


@pytest.fixture(scope="module")
def render(repo):
    name = "fieldkit_video_render_for_clips"
    spec = importlib.util.spec_from_file_location(name, repo / "video" / "render.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def test_bounce_truth_obeys_the_stated_impact_model(render):
    ball, scene = render.Ball(), render.BounceScene()
    times = np.arange(int(scene.duration_s * 1205)) / 1205.0
    states, impacts = render.bounce_motion(scene, ball, times)
    assert len(impacts) >= 3
    r, k = ball.radius_m, ball.gyration_m
    psi = scene.surface_deg
    for imp, e_n in zip(impacts, scene.e_n, strict=False):
        vit, vin = to_local(imp["vi_x_mps"], imp["vi_z_mps"], psi)
        vft, vfn = to_local(imp["vf_x_mps"], imp["vf_z_mps"], psi)
        assert vin < 0 < vfn
        assert -vfn / vin == pytest.approx(e_n, rel=1e-12)
        # rough sphere: impulse J/m changes v_T by -J and omega by -J r/k^2
        j = vit - vft
        assert imp["omega_f_radps"] == pytest.approx(
            imp["omega_i_radps"] - j * r / k**2, rel=1e-12
        )
        slip_after = vft + r * imp["omega_f_radps"]
        if imp["ends_rolling"]:
            assert slip_after == pytest.approx(0.0, abs=1e-12)
        else:  # sliding throughout: Coulomb limit mu (1 + e_n) |vin|
            assert abs(j) == pytest.approx(scene.friction * (1 + e_n) * abs(vin))
        # the centre is one radius from the plate at contact
        n = np.array([np.sin(np.radians(psi)), np.cos(np.radians(psi))])
        d = (np.array([imp["x_m"], imp["z_m"]]) - scene.plate_point_m) @ n
        assert d == pytest.approx(r, abs=1e-12)
    # free flight between impacts: constant vx, vz slope -g, constant omega
    flight = (times > impacts[0]["t_s"] + 0.01) & (times < impacts[1]["t_s"] - 0.01)
    assert np.ptp(states[flight, 2]) < 1e-12
    assert np.allclose(np.diff(states[flight, 3]) * 1205.0, -9.81)
    assert np.ptp(states[flight, 5]) == 0.0


def test_net_truth_energy_balance(render):
    ball, scene = render.Ball(), render.NetScene()
    times = np.arange(int(scene.duration_s * 1205)) / 1205.0
    states, in_contact, contact = render.net_motion(scene, ball, times)
    # a long contact, as in the thesis model tests (61 frames at 1205 fps)
    assert 40 <= contact["frames"] <= 90
    e_i = contact["ke_i_j"] + contact["re_i_j"]
    e_f = contact["ke_f_j"] + contact["re_f_j"]
    assert contact["efficiency_percent"] == pytest.approx(100 * e_f / e_i)  # eq. 8.1
    assert 0 < contact["efficiency_percent"] < 100  # the net absorbs energy
    assert contact["v_min_mps"] < contact["vf_mps"] < contact["vi_mps"]
    # in free flight the total mechanical energy is conserved by the integrator
    m, k2 = ball.mass_kg, ball.gyration_m**2
    energy = (
        0.5 * m * (states[:, 2] ** 2 + states[:, 3] ** 2)
        + 0.5 * m * k2 * states[:, 5] ** 2
        + m * 9.81 * states[:, 1]
    )
    before = ~in_contact & (np.arange(len(times)) < contact["first_frame"])
    assert np.ptp(energy[before]) < 1e-9 * energy[before].mean()


def test_short_clip_files_calibration_and_reader(render, tmp_path):
    truth = render.render("bounce_short", tmp_path, frames=60)
    clip = tmp_path / "bounce_short.avi"
    reader = VideoReader(clip)
    assert (reader.info.width, reader.info.height) == (480, 320)
    assert reader.info.frame_count == 60
    assert reader.info.container_fps == pytest.approx(30.0)
    assert reader.info.codec == "MJPG"
    frames = [i for i, _ in reader.frames()]
    assert frames == list(range(60))
    assert reader.truncation_message() is None
    message = fps_mismatch_message(reader.info, 1205.0)
    assert "30" in message and "1205" in message
    assert fps_mismatch_message(reader.info, 30.0) is None
    table = pd.read_csv(tmp_path / "bounce_short.truth.csv")
    assert len(table) == truth["frames"] == 60
    np.testing.assert_allclose(np.diff(table["t_s"]), 1 / 1205.0)
    calib = json.loads((tmp_path / "bounce_short.calibration.json").read_text())
    u1, v1, u2, v2 = calib["scale_points_px"]
    assert calib["scale_length_m"] == pytest.approx(np.hypot(u2 - u1, v2 - v1) * 0.002)
    # determinism: the same call writes the same video bytes
    again = tmp_path / "again"
    render.render("bounce_short", again, frames=60)
    assert (again / "bounce_short.avi").read_bytes() == clip.read_bytes()


def test_truncated_video_reports_the_missing_frames(render, tmp_path):
    render.render("bounce_short", tmp_path, frames=80)
    data = (tmp_path / "bounce_short.avi").read_bytes()
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[: len(data) // 2])
    reader = VideoReader(cut)
    n = sum(1 for _ in reader.frames())
    assert 20 < n < 80
    message = reader.truncation_message()
    assert f"frames {n}-79" in message and "truncated" in message


@pytest.mark.parametrize("name", ["bounce", "net"])
def test_committed_truth_matches_the_renderer(render, repo, name):
    committed = json.loads((repo / "video" / f"{name}.truth.json").read_text())
    ball = render.Ball()
    scene = render.PRESETS[name][1]()
    times = np.arange(committed["frames"]) / 1205.0
    if name == "bounce":
        states, impacts = render.bounce_motion(scene, ball, times)
        assert len(impacts) == len(committed["impacts"])
        for new, old in zip(impacts, committed["impacts"], strict=True):
            for key in ("t_s", "x_m", "z_m", "vi_x_mps", "vf_z_mps", "omega_f_radps"):
                assert new[key] == pytest.approx(old[key], rel=1e-9, abs=1e-12)
    else:
        states, _, contact = render.net_motion(scene, ball, times)
        for key in ("t_start_s", "t_end_s", "vi_mps", "vf_mps", "efficiency_percent"):
            assert contact[key] == pytest.approx(committed["contact"][key], rel=1e-9)
    table = pd.read_csv(repo / "video" / f"{name}.truth.csv")
    np.testing.assert_allclose(table["x_m"], states[:, 0], rtol=1e-9, atol=1e-12)


#: Files `make video` writes beside the clips and the repository commits.
COMMITTED = [
    f"{clip}.{kind}"
    for clip in ("bounce", "net")
    for kind in ("calibration.json", "homography.json", "truth.json", "truth.csv")
]


def test_json_floats_survive_last_bit_differences(render, repo):
    """Machines differ in the last bits of a float (numpy picks SIMD paths by CPU); the
    12 significant digits written absorb that, so the bytes do not change."""
    text = (repo / "video" / "bounce.truth.json").read_text()

    def nudge(value):
        if isinstance(value, float) and value != 0.0:
            return float(np.nextafter(value, np.inf))
        if isinstance(value, dict):
            return {k: nudge(v) for k, v in value.items()}
        if isinstance(value, list):
            return [nudge(v) for v in value]
        return value

    nudged = nudge(json.loads(text))
    assert nudged != json.loads(text)
    assert json.dumps(render._rounded(nudged), indent=1) == text


@pytest.mark.slow
def test_make_video_reproduces_the_committed_files(repo, tmp_path):
    """`make video` (video/render.py, both clips) writes the committed files byte for
    byte (about 30 s: it renders 1627 frames)."""
    import subprocess

    done = subprocess.run(
        [sys.executable, str(repo / "video" / "render.py"), "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    for name in COMMITTED:
        assert (tmp_path / name).read_bytes() == (repo / "video" / name).read_bytes(), (
            name
        )
    assert (tmp_path / "bounce.avi").stat().st_size > 10_000_000
