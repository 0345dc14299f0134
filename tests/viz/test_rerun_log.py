"""Rerun recordings: read back with rerun.chunk.RrdReader (rerun-sdk 0.41)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from rerun.chunk import RrdReader

from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball, net_capture
from fieldkit.viz.rerun_log import (
    MAX_FRAME_SIDE_PX,
    MAX_FRAMES,
    write_impact_recording,
    write_recording,
)


def entities(path) -> dict[str, int]:
    """Entity path -> total non-static rows (static-only entities map to 0)."""
    out: dict[str, int] = {}
    for line in RrdReader(path).store().summary().splitlines():
        name, rest = line.split(" ", 1)
        rows = int(rest.split("rows=")[1].split()[0])
        static = "static=True" in rest
        out[name] = out.get(name, 0) + (0 if static else rows)
    return out


@pytest.fixture(scope="module")
def bounce_analysis():
    rng = np.random.default_rng(3)
    s = bouncing_ball(
        duration_s=0.8,
        start_velocity_mps=(1.5, 0.5),
        surface_angle_deg=12.0,
        omega0_radps=-20.0,
        noise_m=4e-4,
        angle_noise_rad=0.02,
        rng=rng,
    )
    a = analyse_track(s.track, radius_m=0.0375)
    f = a.track.frame
    # image coordinates of a camera looking at the plane: 300 px/m, v down
    f["u_px"] = 100.0 + 300.0 * f["x_m"]
    f["v_px"] = 400.0 - 300.0 * f["z_m"]
    return a


def test_track_recording_holds_track_flights_series_and_frames(
    tmp_path, bounce_analysis
):
    a = bounce_analysis
    n = len(a.track)
    frames = ((i, np.full((960, 1600, 3), i % 250, np.uint8)) for i in range(n))
    det = a.track.frame[["frame", "u_px", "v_px"]].assign(
        marker_du_px=5.0, marker_dv_px=0.0
    )
    path = write_recording(tmp_path / "rec.rrd", a, frames=frames, detections=det)
    e = entities(path)
    assert e["/plots/speed/measured"] == n
    assert e["/plots/speed/fitted"] == sum(f.n_samples for f in a.flights)
    assert e["/plots/spin"] == n and e["/plots/residual_mm"] > 0.9 * n
    assert "/world/flights" in e and "/world/impacts" in e and "/world/track" in e
    assert e["/world/velocity"] > 0
    assert e["/events"] == len(a.impacts)
    # frames subsampled to at most MAX_FRAMES, with centre, marker and flights
    assert 0 < e["/video/frame"] <= MAX_FRAMES
    assert e["/video/frame/centre"] == e["/video/frame"] == e["/video/frame/marker"]
    assert e["/video/frame/flights"] == e["/video/frame"]
    # downscaled JPEGs keep the file small: well under the raw 120 x 1.4 MB
    assert path.stat().st_size < 3_000_000
    assert MAX_FRAME_SIDE_PX <= 640


def test_recordings_are_deterministic(tmp_path, bounce_analysis):
    a = write_recording(tmp_path / "a.rrd", bounce_analysis)
    b = write_recording(tmp_path / "b.rrd", bounce_analysis)
    sa = RrdReader(a).store().summary()
    assert sa == RrdReader(b).store().summary()
    assert "log_time" not in sa and "RecordingInfo:start_time" not in sa


def test_impact_table_recording(tmp_path, bounce_analysis):
    table = bounce_analysis.impacts
    path = write_impact_recording(tmp_path / "impacts.rrd", table)
    e = entities(path)
    # one entity per kind for every path (columnar, the path on the `path` timeline)
    for name in ("impacts", "path", "slope", "vi", "vf"):
        assert e[f"/section/{name}"] == 1  # one path: one row
    for col in ("e_n", "e_t", "vi_mps", "vf_mps"):
        assert e[f"/section/plots/{col}"] == len(table)


def test_net_contact_series(tmp_path):
    sim = net_capture(noise_m=3e-4, rng=np.random.default_rng(1))
    a = analyse_track(sim.track, radius_m=0.0375, mass_kg=0.14)
    e = entities(write_recording(tmp_path / "net.rrd", a))
    c = a.contacts[0]
    assert e["/contacts/0/speed"] == len(c.t_s)
    assert e["/contacts/0/impulse_absorbed_pct"] == len(c.t_s)


def test_no_partial_file_on_failure(tmp_path, bounce_analysis):
    bad = pd.DataFrame({"frame": [0], "u_px": ["not a number"], "v_px": [1.0]})
    with pytest.raises((ValueError, TypeError)):
        write_recording(
            tmp_path / "x.rrd",
            bounce_analysis,
            frames=[(0, np.zeros((10, 10, 3), np.uint8))],
            detections=bad,
        )
    assert list(tmp_path.iterdir()) == []
