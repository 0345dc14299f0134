"""An extended contact whose path was not measured is refused, never reported.

The synthetic net capture (``net_capture``: spring-damper net, 1205 fps, 0.3 mm
noise) gives one extended contact with its truth. Two ways a real clip spoils it,
each known exactly here: the body hidden (by a net, a hoop, a person) in most
frames of the contact, and one wrong detection a body could not reach (a metre
off in one frame interval). Either must turn the contact into a one-line
refusal naming its frames, not a row. Likewise a bounce at a track's end with too
few samples beyond it for a flight (a synthetic bouncing ball cut short).
"""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.track import Track
from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball, net_capture

MASS, R = 0.14, 0.0375


@pytest.fixture(scope="module")
def capture():
    sim = net_capture(
        net_normal_deg=150.0,
        start_velocity_mps=(12.0, -2.0),
        noise_m=3e-4,
        rng=np.random.default_rng(11),
        radius_m=R,
        mass_kg=MASS,
    )
    frame = sim.track.frame.copy()
    frame["frame"] = np.arange(len(frame))
    truth = sim.truth.iloc[0]
    inside = (frame["t_s"] > truth.t_start_s) & (frame["t_s"] < truth.t_end_s)
    return frame, inside.to_numpy(), sim.track


def _analyse(frame, track):
    spoilt = Track(frame.reset_index(drop=True), source="synthetic", fps=track.fps)
    return analyse_track(spoilt, radius_m=R, mass_kg=MASS)


def _unreduced(analysis):
    return [r for r in analysis.refusals if r.kind == "unreduced" and not r.merged]


def test_the_whole_contact_is_reduced(capture):
    frame, _, track = capture
    analysis = _analyse(frame, track)
    assert len(analysis.contacts) == 1 and not _unreduced(analysis)


def test_a_contact_hidden_in_most_frames_is_refused(capture):
    frame, inside, track = capture
    rows = np.flatnonzero(inside)
    # seen in 2 frames of every 5 (net strands in front of it): no longer a path
    hidden = rows[np.arange(rows.size) % 5 >= 2]
    kept = frame.drop(index=hidden)
    analysis = _analyse(kept, track)
    assert not analysis.contacts and len(analysis.impacts) == 0
    (refusal,) = _unreduced(analysis)
    first, last = refusal.frames
    assert first <= rows[0] and last >= rows[-1]
    between = last - first - 1
    seen = int(((kept["frame"] > first) & (kept["frame"] < last)).sum())
    unseen = between - seen
    assert unseen > 0.5 * between
    assert f"body not detected in {unseen} of the {between} frames" in refusal.reason
    assert "\n" not in refusal.reason


def test_a_detection_no_body_could_reach_is_refused(capture):
    frame, inside, track = capture
    k = int(np.flatnonzero(inside)[len(np.flatnonzero(inside)) // 2])
    wrong = frame.copy()
    wrong.loc[k, "z_m"] += 1.0  # 1 m in 1/1205 s: over 1000 m/s
    analysis = _analyse(wrong, track)
    assert not analysis.contacts and len(analysis.impacts) == 0
    (refusal,) = _unreduced(analysis)
    assert f"between frames {k - 1} and {k}" in refusal.reason
    assert "not one body's path" in refusal.reason


def _bounce_cut(after: int):
    """A bouncing ball (e_n 0.6 on a 10 deg slope) cut ``after`` samples past the
    sample nearest its impact, and that sample's position."""
    truth = bouncing_ball(duration_s=0.5, e_n=0.6, e_t=0.8)
    frame = truth.track.frame
    t_hit = float(truth.truth["t_s"].iloc[0])
    k = int(np.argmin(np.abs(frame["t_s"].to_numpy() - t_hit)))
    cut = frame.iloc[: k + after + 1].reset_index(drop=True)
    return Track(cut, source="synthetic", fps=truth.track.fps), k


def test_a_contact_with_too_few_samples_after_it_is_refused():
    # 3 samples after the bounce: too few for a flight (8), and off the parabola
    # before it, so the bounce is refused in one line, not left unsaid
    track, k = _bounce_cut(3)
    a = analyse_track(track, radius_m=0.0375, surface_angle_deg=10.0)
    assert len(a.flights) == 1 and len(a.impacts) == 0
    (refusal,) = _unreduced(a)
    first, last = refusal.frames
    assert first <= k <= last and last == len(track) - 1
    assert "samples after the last flight" in refusal.reason
    assert "\n" not in refusal.reason


def test_a_track_ending_in_flight_has_no_edge_refusal():
    # cut before the bounce: the last samples all lie on the one flight
    track, k = _bounce_cut(-5)
    a = analyse_track(track, radius_m=0.0375, surface_angle_deg=10.0)
    assert len(a.flights) == 1 and a.refusals == []
