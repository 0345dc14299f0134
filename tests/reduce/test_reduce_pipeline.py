"""The reduction steps against synthetic paths with known truth and analytic limits."""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fieldkit.errors import ArgumentError, InputFileError, PhysicsError
from fieldkit.physics.bodies import parse_dimensions, resolve_body
from fieldkit.physics.flight import launch_speed
from fieldkit.reduce.flights import least_speed_launch_angle_deg
from fieldkit.reduce.pipeline import ReduceOptions, reduce_survey, section_slopes
from fieldkit.reduce.summary import format_summary, summarize
from fieldkit.survey import PointSet, Survey, TreeStrikes

G = 9.81


def points(names, x, z, **extra):
    frame = pd.DataFrame({"point": names, "x_m": x, "z_m": z, **extra})
    return PointSet(frame, source="synthetic.csv")


def trees(rows):
    frame = pd.DataFrame(
        rows,
        columns=[
            "after_impact",
            "horizontal_distance_m",
            "strike_height_m",
            "ground_z_m",
        ],
    )
    frame["row"] = np.arange(2, len(frame) + 2)
    return TreeStrikes(frame, source="trees.csv")


def test_section_slopes_chord_and_surveyed():
    psi, src = section_slopes(
        np.array([0.0, 10.0, 20.0, 30.0]),
        np.array([50.0, 40.0, 34.226, 34.226]),
        np.array([np.nan, np.nan, 12.0, np.nan]),
    )
    assert math.isnan(psi[0]) and src[0] is None
    assert psi[1] == pytest.approx(45.0)
    assert psi[2] == 12.0 and src[2] == "surveyed"
    assert psi[3] == pytest.approx(0.0) and src[3] == "chord"


@given(dx=st.floats(1.0, 50.0), dz=st.floats(-80.0, 10.0))
@settings(max_examples=40, deadline=None)
def test_least_speed_angle_minimises_eq_3_5(dx, dz):
    best = least_speed_launch_angle_deg(dx, dz)
    v_best = launch_speed(dx, dz, best)
    for delta in (-2.0, -0.5, 0.5, 2.0):
        alpha = best + delta
        if abs(alpha) < 89.0 and dx * math.tan(math.radians(alpha)) - dz > 0:
            assert launch_speed(dx, dz, alpha) >= v_best - 1e-9
    # V0^2 = g (L + dz) for the least-speed path.
    assert v_best**2 == pytest.approx(G * (math.hypot(dx, dz) + dz), rel=1e-9)


@st.composite
def synthetic_paths(draw):
    """A path of 4-7 impacts with a known launch velocity on every flight."""
    n = draw(st.integers(4, 7))
    x, z, vx, vz = [0.0], [100.0], [], []
    for _ in range(n - 1):
        speed = draw(st.floats(3.0, 25.0))
        alpha = draw(st.floats(-40.0, 50.0))
        t = draw(st.floats(0.4, 2.0))
        ux, uz = (
            speed * math.cos(math.radians(alpha)),
            speed * math.sin(math.radians(alpha)),
        )
        x.append(x[-1] + ux * t)
        z.append(z[-1] + uz * t - 0.5 * G * t * t)
        vx.append(ux)
        vz.append(uz)
    fraction = draw(st.lists(st.floats(0.2, 0.8), min_size=n - 1, max_size=n - 1))
    return np.array(x), np.array(z), np.array(vx), np.array(vz), fraction


@given(synthetic_paths())
@settings(max_examples=30, deadline=None)
def test_tree_strikes_recover_known_velocities(path):
    """Every flight fixed by a strike on the true parabola: exact velocities back."""
    x, z, vx, vz, fraction = path
    names = [f"P{i}" for i in range(len(x))]
    rows = []
    for j, f in enumerate(fraction):
        d = f * (x[j + 1] - x[j])
        t = d / vx[j]
        zs = z[j] + vz[j] * t - 0.5 * G * t * t
        ground = z[j] + (z[j + 1] - z[j]) * f - 0.25  # ground given, below the chord
        rows.append([names[j], d, zs - ground, ground])
    table = reduce_survey(
        Survey(points(names, x, z), trees(rows)),
        ReduceOptions("syn", None, resolve_body(mass_kg=100.0)),
    )
    f = table.frame
    np.testing.assert_allclose(f["vf_x_mps"].to_numpy()[:-1], vx, rtol=1e-7)
    np.testing.assert_allclose(f["vf_z_mps"].to_numpy()[:-1], vz, rtol=1e-7, atol=1e-7)
    t_flight = np.diff(x) / vx
    np.testing.assert_allclose(
        f["vi_z_mps"].to_numpy()[1:], vz - G * t_flight, rtol=1e-7, atol=1e-7
    )
    np.testing.assert_allclose(f["t_s"].to_numpy()[1:], np.cumsum(t_flight), rtol=1e-7)
    assert (f["theta0_source"].iloc[:-1] == "tree").all()
    # Energy head is constant through each flight (eq. 6.14, drag-free).
    np.testing.assert_allclose(
        f["energy_head_f_m"].to_numpy()[:-1],
        f["energy_head_i_m"].to_numpy()[1:],
        rtol=1e-9,
    )


def test_assumed_theta0_on_the_chord():
    x, z = np.array([0.0, 10.0, 20.0, 30.0]), np.array([30.0, 24.0, 18.0, 12.0])
    table = reduce_survey(
        Survey(points(["a", "b", "c", "d"], x, z), None),
        ReduceOptions("p", 32.6, resolve_body()),
    )
    f = table.frame
    psi = math.degrees(math.atan(0.6))
    assert f["theta0_deg"].iloc[1] == pytest.approx(32.6)
    assert f["theta_f_deg"].iloc[1] == pytest.approx(32.6)  # on the chord slope
    alpha = math.radians(32.6 - psi)
    assert math.atan2(f["vf_z_mps"].iloc[1], f["vf_x_mps"].iloc[1]) == pytest.approx(
        alpha
    )
    # No body: energies and spin are not invented.
    assert f["ke_i_j"].isna().all() and f["omega_f_radps"].isna().all()
    assert set(f["omega_source"]) == {"none"}
    assert f["tree_strike"].isna().all()  # no tree file: unknown, not False


def test_given_theta0_wins_over_assumed():
    x, z = np.array([0.0, 10.0, 20.0]), np.array([20.0, 14.0, 8.0])
    pts = points(["a", "b", "c"], x, z, theta0_deg=[np.nan, 20.0, np.nan])
    f = reduce_survey(Survey(pts, None), ReduceOptions("p", 40.0)).frame
    assert f["theta0_source"].tolist()[:2] == ["assumed", "given"]
    assert f["theta0_deg"].iloc[1] == pytest.approx(20.0)


def test_errors_name_the_file_and_point_or_row():
    x, z = np.array([0.0, 10.0, 20.0]), np.array([20.0, 14.0, 8.0])
    pts = points(["a", "b", "c"], x, z)
    with pytest.raises(ArgumentError, match=r"synthetic.csv: point b: .*`theta0_deg`"):
        reduce_survey(Survey(pts, None), ReduceOptions("p", None))
    below = trees([["a", 5.0, 0.5, 14.0]])  # strike at 14.5 m, chord at 17 m
    # that flight unsolved, the next one reduced; with no other flight, an error
    f = reduce_survey(Survey(pts, below), ReduceOptions("p", 30.0)).frame
    assert f["flight_unsolved"].notna().tolist() == [True, False, False]
    assert re.match(r"tree row 2: .*no parabola", f["flight_unsolved"][0])
    two = points(["a", "b"], x[:2], z[:2])
    with pytest.raises(PhysicsError, match=r"trees.csv: row 2: .*no parabola"):
        reduce_survey(Survey(two, below), ReduceOptions("p", 30.0))
    last = trees([["c", 1.0, 1.0, 8.0]])
    with pytest.raises(InputFileError, match=r"trees.csv: row 2: .*last point"):
        reduce_survey(Survey(pts, last), ReduceOptions("p", 30.0))
    with pytest.raises(InputFileError, match="at least two points"):
        reduce_survey(
            Survey(points(["a"], [0.0], [1.0]), None), ReduceOptions("p", 30.0)
        )


def test_body_options():
    b = resolve_body(shape="sphere", dimensions_m=(0.5,), unit_weight_kn_m3=26.0)
    volume = 4.0 / 3.0 * math.pi * 0.5**3
    assert b.mass_kg == pytest.approx(volume * 26e3 / G)
    assert b.gyration_m == pytest.approx(0.5 * math.sqrt(0.4))
    assert (
        resolve_body(
            shape="ellipsoid", dimensions_m=(1.6, 1.3, 1.3), radius_m=0.8
        ).radius_m
        == 0.8
    )  # Table 2-6's r = a
    with pytest.raises(ArgumentError, match="gyration_m"):
        resolve_body(mass_kg=1.0, radius_m=0.2, gyration_m=0.3)  # k > r
    with pytest.raises(ArgumentError, match="dimensions_m"):
        resolve_body(dimensions_m=(1.0,))
    with pytest.raises(ArgumentError, match="dimensions_m"):
        parse_dimensions("1.6,,1.3")


def test_summary_statistics_by_material():
    x = np.array([0.0, 10.0, 20.0, 30.0, 40.0])
    z = np.array([40.0, 34.0, 28.0, 22.0, 16.0])
    pts = points(list("abcde"), x, z, material=["rock", "rock", "talus", "talus", "x"])
    table = reduce_survey(
        Survey(pts, None), ReduceOptions("p", 30.0, resolve_body(mass_kg=10.0))
    )
    s = summarize(table)
    f = table.frame
    rock = f.loc[f["material"] == "rock", "e_n"].dropna()
    stats = {m.material: m for m in s.by_material}
    assert stats["rock"].n == 1 and stats["rock"].e_n_mean == pytest.approx(rock.mean())
    assert stats["talus"].n == 2
    assert stats["talus"].e_t_sd == pytest.approx(
        f.loc[f["material"] == "talus", "e_t"].std(ddof=1)
    )
    assert s.flight_ke_gain_j == pytest.approx(10.0 * G * 24.0)
    assert s.potential_released_j == pytest.approx(10.0 * G * 24.0)
    text = format_summary(s)
    assert "rock" in text and "talus" in text and "gained in flights" in text
