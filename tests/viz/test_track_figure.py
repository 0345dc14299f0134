"""PNG figures of a track analysis."""

from __future__ import annotations

import numpy as np
from matplotlib.image import imread

from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball, net_capture
from fieldkit.viz.track_figure import write_track_figures


def test_figures_for_bounces_in_the_section_and_over_a_frame(tmp_path):
    s = bouncing_ball(
        duration_s=0.6, noise_m=3e-4, angle_noise_rad=0.02, rng=np.random.default_rng(2)
    )
    a = analyse_track(s.track, radius_m=0.0375, surface_angle_deg=10.0)
    names = [p.name for p in write_track_figures(tmp_path / "plane", a)]
    assert names == ["track.png", "speed_spin.png", "residuals.png"]
    f = a.track.frame
    f["u_px"], f["v_px"] = 50 + 400 * f["x_m"], 300 - 400 * f["z_m"]
    frame = np.zeros((480, 800, 3), np.uint8)
    paths = write_track_figures(tmp_path / "video", a, background_frame=frame)
    image = imread(paths[0])
    assert image.shape[0] > 400 and image.shape[1] > 600


def test_net_contact_figure(tmp_path):
    sim = net_capture(noise_m=3e-4, rng=np.random.default_rng(4))
    a = analyse_track(sim.track, radius_m=0.0375, mass_kg=0.14)
    paths = write_track_figures(tmp_path, a)
    assert [p.name for p in paths][-1] == "net_contact_0.png"
    assert all(p.stat().st_size > 10_000 for p in paths)
