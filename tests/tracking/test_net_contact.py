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
import pytest

from fieldkit.physics.constants import G
from fieldkit.physics.fences import energy_efficiency
from fieldkit.tracking.analysis import analyse_track
from fieldkit.tracking.synthetic import net_capture

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
