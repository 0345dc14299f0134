"""Net contact phases (thesis §8.5, Figs. 8.12-8.15, eq. 8.1) on a synthetic capture.

Truth: a 75 mm, 140 g ball (the thesis' model-test projectile) meets an inclined net
modelled as a linear spring-damper along the net normal, integrated with RK4 at 10 us
and sampled at 1205 fps with 0.3 mm noise. The energy the net absorbs is known from
the simulation (kinetic energy in minus out at the instants the net force starts and
stops), and the simulation itself is checked against energy conservation
(damper work + spring energy left = kinetic loss + potential drop).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fieldkit.physics.constants import G
from fieldkit.physics.fences import energy_efficiency
from fieldkit.physics.local_axes import to_local
from fieldkit.track import Track
from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.flights.synthetic_tracks import net_capture

MASS, R = 0.14, 0.0375


@pytest.fixture(scope="module", params=[150.0, 120.0], ids=["rebound", "redirect"])
def capture(request):
    rng = np.random.default_rng(11)
    speed = (12.0, -2.0) if request.param == 150.0 else (14.0, -3.0)
    sim = net_capture(
        net_normal_deg=request.param,
        start_velocity_mps=speed,
        noise_m=3e-4,
        rng=rng,
        radius_m=R,
        mass_kg=MASS,
    )
    analysis = analyse_track(sim.track, radius_m=R, mass_kg=MASS)
    return sim.truth.iloc[0], analysis


def test_the_simulated_truth_conserves_energy(capture):
    truth, _ = capture
    potential_drop = MASS * G * (truth.z_start_m - truth.z_end_m)
    lost = truth.ke_i_j - truth.ke_f_j + potential_drop
    assert truth.damper_j + truth.spring_j == pytest.approx(lost, rel=1e-3)


def test_one_extended_contact_with_absorbed_energy_and_efficiency(capture):
    truth, analysis = capture
    assert len(analysis.contacts) == 1 and len(analysis.impacts) == 1
    c = analysis.contacts[0]
    absorbed = truth.ke_i_j - truth.ke_f_j
    assert c.absorbed_j == pytest.approx(absorbed, rel=0.01)
    assert c.efficiency == pytest.approx(truth.ke_f_j / truth.ke_i_j, abs=0.01)
    vi = np.hypot(truth.vi_x_mps, truth.vi_z_mps)
    vf = np.hypot(truth.vf_x_mps, truth.vf_z_mps)
    assert c.vi_mps == pytest.approx(vi, rel=0.01)
    assert c.vf_mps == pytest.approx(vf, rel=0.01)
    assert c.v_min_mps == pytest.approx(truth.v_min_mps, rel=0.03)


def test_contact_time_series(capture):
    truth, analysis = capture
    c = analysis.contacts[0]
    # start and end from the onset fit of the deviation from each parabola: within
    # a frame or two although the net force fades below the noise at both ends
    assert c.t_start_s == pytest.approx(truth.t_start_s, abs=1.5 / 1205)
    assert c.t_end_s == pytest.approx(truth.t_end_s, abs=4 / 1205)
    true_duration = truth.t_end_s - truth.t_start_s
    assert c.duration_s == pytest.approx(true_duration, rel=0.1)
    # the flights keep no sample the net still acted on: gravity fits 9.81
    assert not any("g =" in w for w in analysis.warnings)
    series = c.to_frame()
    assert series["t_from_start_s"].iloc[0] == 0.0
    # Fig. 8.15: share of the impact impulse absorbed, 1 - V(t)/V_i, peaks where
    # the speed is lowest
    k = int(np.argmax(series["impulse_absorbed_fraction"]))
    assert series["speed_mps"].iloc[k] == pytest.approx(c.v_min_mps)
    assert series["impulse_absorbed_fraction"].iloc[0] == 0.0
    # impulse applied by the net (gravity removed) at the end is m |v_f - v_i - g t|
    vi = np.array([truth.vi_x_mps, truth.vi_z_mps])
    vf = np.array([truth.vf_x_mps, truth.vf_z_mps])
    expected = MASS * np.hypot(*(vf - vi + np.array([0.0, G * true_duration])))
    assert series["net_impulse_ns"].iloc[-1] == pytest.approx(expected, rel=0.05)


def test_efficiency_is_eq_8_1_of_the_contact_energies(capture):
    # eq. 8.1 comes from physics.fences (thesis §8.2.3: 39.2 / 138.8 = 28 per cent)
    assert energy_efficiency(138.8, 39.2) == pytest.approx(0.2824, abs=1e-4)
    _, analysis = capture
    c = analysis.contacts[0]
    assert c.efficiency == pytest.approx(energy_efficiency(c.energy_i_j, c.energy_f_j))


def test_efficiency_without_mass_is_per_unit_mass(capture):
    truth, analysis = capture
    track = analysis.track
    again = analyse_track(track, radius_m=R)
    c = again.contacts[0]
    assert np.isnan(c.absorbed_j) and np.isnan(c.net_impulse_ns).all()
    assert c.efficiency == pytest.approx(analysis.contacts[0].efficiency)


# --- the local frame of a net contact (docs/architecture.md §2: N faces the body) ---


def with_marker(track: Track, omega_radps: float, seed: int) -> Track:
    """The track with a marker angle: the synthetic net is frictionless (its force is
    along the normal, through the centre), so the true spin is constant throughout."""
    rng = np.random.default_rng(seed)
    t = track.frame["t_s"]
    angle = 0.3 + omega_radps * t + rng.normal(0.0, 0.02, len(t))
    frame = track.frame.assign(angle_rad=angle, omega_radps=np.nan)
    return Track(frame, source=track.source, fps=track.fps, meta=dict(track.meta))


def truth_normal_components(truth, normal_deg: float) -> dict[str, float]:
    """vin, vit, vfn, vft of the simulated contact on the net's own axes."""
    psi = 90.0 - normal_deg  # N = (cos a, sin a) = (sin psi, cos psi)
    vit, vin = to_local(truth.vi_x_mps, truth.vi_z_mps, psi)
    vft, vfn = to_local(truth.vf_x_mps, truth.vf_z_mps, psi)
    return dict(psi=psi, vin=vin, vit=vit, vfn=vfn, vft=vft)


# overhang: the net leans over the incoming ball (like video/net), psi beyond -90 deg
OVERHANG = dict(net_normal_deg=200.0, start_velocity_mps=(5.0, -1.0), duration_s=0.25)
CASES = {
    "overhang": OVERHANG,
    "rebound": dict(net_normal_deg=150.0, start_velocity_mps=(12.0, -2.0)),
    "redirect": dict(net_normal_deg=120.0, start_velocity_mps=(14.0, -3.0)),
}


@pytest.mark.parametrize("name", list(CASES))
def test_net_normal_faces_the_body_and_e_n_matches_the_truth(name):
    kw = CASES[name]
    sim = net_capture(noise_m=3e-4, rng=np.random.default_rng(11), radius_m=R, **kw)
    truth = sim.truth.iloc[0]
    ref = truth_normal_components(truth, kw["net_normal_deg"])
    assert ref["vin"] < 0 < ref["vfn"]  # the simulation's own axes obey §2
    a = analyse_track(with_marker(sim.track, -25.0, 3), radius_m=R, mass_kg=MASS)
    row = a.impacts.frame.iloc[0]
    assert len(a.impacts) == 1 and len(a.contacts) == 1
    # surface from the velocity and spin change over the contact (no spin change:
    # the net impulse is along N once gravity is removed)
    assert row.slope_deg == pytest.approx(ref["psi"], abs=0.2)
    assert row.vin_mps < 0 < row.vfn_mps
    assert row.vin_mps == pytest.approx(ref["vin"], rel=0.03)
    assert row.vfn_mps == pytest.approx(ref["vfn"], rel=0.03)
    assert row.e_n == pytest.approx(-ref["vfn"] / ref["vin"], abs=0.05)
    assert row.e_t == pytest.approx(ref["vft"] / ref["vit"], abs=0.05)
    assert any("angular-momentum balance" in w for w in a.warnings)


def test_overhang_psi_is_beyond_90_deg_with_t_up_the_net():
    sim = net_capture(
        noise_m=3e-4, rng=np.random.default_rng(6), radius_m=R, **OVERHANG
    )
    a = analyse_track(with_marker(sim.track, 0.0, 4), radius_m=R)
    row = a.impacts.frame.iloc[0]
    # N = (sin psi, cos psi) points down and back toward the ball; T, its right-handed
    # partner, points up the net while the ball slides down it: vit < 0
    assert -180.0 < row.slope_deg < -90.0
    assert row.vit_mps < 0 and row.theta_i_deg > 90.0
    assert row.e_t > 0  # vft / vit: both against T


def test_net_without_spin_leaves_e_n_nan_and_says_why():
    sim = net_capture(
        noise_m=3e-4, rng=np.random.default_rng(7), radius_m=R, **OVERHANG
    )
    a = analyse_track(sim.track, radius_m=R, mass_kg=MASS)  # no marker angle
    row = a.impacts.frame.iloc[0]
    for col in ("slope_deg", "vin_mps", "vfn_mps", "e_n", "e_t"):
        assert np.isnan(row[col]), col
    assert pd.isna(row.slope_source)
    assert any("cannot be identified without spin" in w for w in a.warnings)
    # speeds, energies and the contact phase do not need the surface
    assert row.vi_mps > 0 and np.isfinite(row.ke_i_j)
    assert np.isfinite(a.contacts[0].efficiency)


def test_given_net_angle_is_turned_to_face_the_body():
    kw = OVERHANG
    sim = net_capture(noise_m=3e-4, rng=np.random.default_rng(8), radius_m=R, **kw)
    truth = sim.truth.iloc[0]
    ref = truth_normal_components(truth, kw["net_normal_deg"])
    line_dip = ref["psi"] + 180.0  # 70 deg: the same line, normal into the net
    a = analyse_track(sim.track, radius_m=R, surface_angle_deg=line_dip)
    row = a.impacts.frame.iloc[0]
    assert row.slope_deg == pytest.approx(ref["psi"])
    assert row.slope_source == "given"
    assert any("from below" in w for w in a.warnings)
    assert row.vin_mps < 0 < row.vfn_mps
    assert row.e_n == pytest.approx(-ref["vfn"] / ref["vin"], abs=0.05)


def test_measured_velocity_is_the_local_derivative_of_the_track():
    # a noiseless parabola: the local quadratic fit is exact; a missing sample is NaN
    t = np.arange(40) / 200.0
    frame = pd.DataFrame(
        {"frame": np.arange(40), "t_s": t, "x_m": 2.0 * t, "z_m": 1.0 + 3.0 * t}
    )
    frame["z_m"] -= 0.5 * G * t**2
    frame.loc[7, "x_m"] = np.nan
    analysis = analyse_track(Track(frame), radius_m=R)
    vx, vz = analysis.measured_velocity
    ok = np.arange(40) != 7
    np.testing.assert_allclose(vx[ok], 2.0, atol=1e-9)
    np.testing.assert_allclose(vz[ok], 3.0 - G * t[ok], atol=1e-9)
    assert np.isnan(vx[7]) and np.isnan(vz[7])
