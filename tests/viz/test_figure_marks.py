"""Figures a reader can trust: legends beside the data, velocity arrows with a scale,
the source of theta0 told apart, the ground under a track, units on every axis,
quality flags marked; net contacts print their efficiency.

Asserted on the matplotlib Figure objects (drawn with Agg, bounding boxes in pixels).
"""

from __future__ import annotations

import importlib.util
import json
import re
import sys

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PathCollection
from matplotlib.figure import Figure
from matplotlib.quiver import Quiver, QuiverKey

from fieldkit.impact_table import ImpactTable
from fieldkit.physics.bodies import resolve_body
from fieldkit.physics.fences import fence_energy_split
from fieldkit.physics.impulse_history import impulse_history
from fieldkit.reduce.pipeline import ReduceOptions, reduce_survey
from fieldkit.survey import PointSet, Survey, TreeStrikes
from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball, net_capture
from fieldkit.viz.energy_figure import plot_energy_head, plot_energy_partition
from fieldkit.viz.fence_figure import plot_fence
from fieldkit.viz.marks import QA_LABEL, free_corner, nice_speed, qa_flagged
from fieldkit.viz.pnv_figure import pnv_figure
from fieldkit.viz.restitution_figure import plot_en_theta, plot_et_impacts
from fieldkit.viz.section_figure import plot_section
from fieldkit.viz.track_figure import (
    plot_net_contact,
    plot_residuals,
    plot_speed_spin,
    plot_track,
)

R, MASS, GYRATION = 0.0375, 0.14, 0.02372
FLAGS = ["", "e_t > 1", np.nan, "energy gained;spin estimated", " "]


# --- fixtures: a reduced survey with trees and flags, tracks -----------------------


@pytest.fixture(scope="module")
def survey_table():
    x = np.array([0.0, 10.0, 22.0, 31.0, 45.0])
    z = np.array([60.0, 52.0, 44.0, 39.0, 30.0])
    points = PointSet(
        frame=pd.DataFrame({"point": list("abcde"), "x_m": x, "z_m": z}),
        source="p.csv",
    )
    trees = TreeStrikes(
        frame=pd.DataFrame(
            {
                "after_impact": ["b"],
                "horizontal_distance_m": [6.0],
                "strike_height_m": [1.5],
                "ground_z_m": [np.nan],
                "row": [2],
            }
        ),
        source="t.csv",
    )
    survey = Survey(points, trees)
    body = resolve_body(mass_kg=500.0, radius_m=0.36, gyration_m=0.295)
    return reduce_survey(survey, ReduceOptions("p", 30.0, body)), survey


@pytest.fixture(scope="module")
def flagged_table(survey_table):
    table, _ = survey_table
    frame = table.frame.copy()
    frame["qa_flags"] = FLAGS  # the contract: ';'-separated flags, empty = none
    return ImpactTable(frame)


@pytest.fixture(scope="module")
def bounces():
    s = bouncing_ball(
        duration_s=0.6,
        surface_angle_deg=10.0,
        noise_m=3e-4,
        angle_noise_rad=0.02,
        rng=np.random.default_rng(2),
    )
    return analyse_track(s.track, radius_m=R, surface_angle_deg=10.0, mass_kg=MASS)


@pytest.fixture(scope="module")
def net():
    sim = net_capture(noise_m=3e-4, rng=np.random.default_rng(4), mass_kg=MASS)
    return sim, analyse_track(sim.track, radius_m=R, mass_kg=MASS)


def over_frame(analysis):
    """The analysis's track seen by a level camera, 400 px/m, and a blank frame."""
    f = analysis.track.frame
    f["u_px"], f["v_px"] = 50 + 400 * f["x_m"], 300 - 400 * f["z_m"]
    return np.zeros((480, 800, 3), np.uint8)


def drawn(fig: Figure):
    canvas = FigureCanvasAgg(fig)
    fig.draw_without_rendering()
    return canvas.get_renderer()


def legends(fig: Figure):
    return [ax.get_legend() for ax in fig.axes if ax.get_legend()] + list(fig.legends)


def figures(survey_table, flagged_table, bounces, net):
    table, survey = survey_table
    f = flagged_table.frame
    split = fence_energy_split(520.0, 0.35, 22.0, 18.0, 11.5, -11.6)
    history = impulse_history(
        19.9, -9.3, -15.0, radius_m=0.75, gyration_m=0.47, e_n=0.71, friction=0.5
    )
    frame = over_frame(bounces)
    return {
        "section": plot_section(flagged_table, survey),
        "en_theta": plot_en_theta(
            f["theta_i_deg"], f["e_n"], theta0_source=f["theta0_source"].tolist()
        ),
        "et": plot_et_impacts(f["e_t"], qa_flags=f["qa_flags"]),
        "energy_partition": plot_energy_partition(flagged_table),
        "energy_head": plot_energy_head(flagged_table),
        "fence": plot_fence(11440.0, split=split),
        "pnv": pnv_figure(history),
        "track_plane": plot_track(net[1]),
        "track_frame": plot_track(bounces, frame),
        "speed_spin": plot_speed_spin(bounces),
        "residuals": plot_residuals(bounces),
        "net_contact": plot_net_contact(net[1].contacts[0]),
    }


# --- legends -----------------------------------------------------------------------


def test_legends_sit_outside_every_axes_and_clear_of_labels(
    survey_table, flagged_table, bounces, net
):
    for name, fig in figures(survey_table, flagged_table, bounces, net).items():
        renderer = drawn(fig)
        found = legends(fig)
        assert found or name == "net_contact", name  # one curve per panel: no legend
        for legend in found:
            box = legend.get_window_extent(renderer)
            for ax in fig.axes:
                assert not box.overlaps(ax.bbox), (name, ax.get_title())
                for text in ax.texts:
                    if text.get_text().strip():
                        other = text.get_window_extent(renderer)
                        assert not box.overlaps(other), (name, text.get_text())


def test_a_legend_inside_the_axes_would_be_caught(survey_table):
    """The check above can fail: loc='best' puts the legend inside the axes."""
    table, survey = survey_table
    fig = plot_section(table, survey)
    ax = fig.axes[0]
    ax.legend(loc="best")
    drawn(fig)
    assert ax.get_legend().get_window_extent().overlaps(ax.bbox)


# --- velocity scales ---------------------------------------------------------------


def keys(ax) -> list[QuiverKey]:
    return [c for c in ax.get_children() if isinstance(c, QuiverKey)]


def test_section_velocity_arrows_carry_a_scale(flagged_table, survey_table):
    _, survey = survey_table
    fig = plot_section(flagged_table, survey)
    drawn(fig)
    ax = fig.axes[0]
    (quiver,) = [c for c in ax.get_children() if isinstance(c, Quiver)]
    (key,) = keys(ax)
    f = flagged_table.frame
    vf = np.hypot(f["vf_x_mps"], f["vf_z_mps"]).dropna()
    assert key.Q is quiver and key.U == nice_speed(vf.max()) == 10.0  # 11.0 m/s top
    assert key.text.get_text() == "10 m/s"
    # the arrows are the table's restitution velocities at the key's scale
    np.testing.assert_allclose(np.hypot(quiver.U, quiver.V), vf.to_numpy())
    # the key sits where nothing is drawn: the upper right of a descending path
    assert (key.X, key.Y) == pytest.approx((1 - 0.3 * 0.24, 1 - 0.6 * 0.1))
    detail = fig.axes[1]
    assert "10 m/s" in [t.get_text() for t in detail.texts]


@pytest.mark.parametrize("over", [False, True], ids=["plane", "frame"])
def test_track_velocity_arrows_carry_a_scale(bounces, over):
    frame = over_frame(bounces) if over else None
    fig = plot_track(bounces, frame)
    drawn(fig)
    ax = fig.axes[0]
    (key,) = keys(ax)
    f = bounces.impacts.frame
    speeds = np.concatenate([f["vi_mps"], f["vf_mps"]])
    assert key.U == nice_speed(speeds.max())
    assert key.text.get_text() == f"{key.U:g} m/s"
    # arrow lengths in m/s: the key's scale holds for every arrow (a level camera
    # keeps it exact over the frame too)
    np.testing.assert_allclose(np.hypot(key.Q.U, key.Q.V), speeds, rtol=1e-6)


def test_free_corner_avoids_the_data():
    fig = Figure()
    ax = fig.add_subplot()
    x, y = np.linspace(0, 1, 50), np.linspace(0, 1, 50)  # rising: two corners taken
    ax.plot(x, y)
    assert free_corner(ax, x, y) == "upper left"
    assert free_corner(ax, x, 1 - y) == "upper right"
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    full = np.array([[0.02, 0.98], [0.98, 0.98], [0.02, 0.02], [0.98, 0.02]])
    assert free_corner(ax, *np.vstack([full, full[[0, 1, 2]]]).T) == "lower right"


# --- theta0 sources in the [theta_i - e_N] figure ------------------------------------


def test_en_theta_tells_tree_fixed_from_assumed_theta0(survey_table):
    table, _ = survey_table
    f = table.frame
    fig = plot_en_theta(
        f["theta_i_deg"], f["e_n"], theta0_source=f["theta0_source"].tolist()
    )
    ax = fig.axes[0]
    groups = {c.get_gid(): c for c in ax.collections if c.get_gid()}
    assert set(groups) == {"theta0-fixed", "theta0-assumed"}
    ok = np.isfinite(f["theta_i_deg"]) & np.isfinite(f["e_n"])
    tree = ok & (f["theta0_source"] == "tree")
    assert len(groups["theta0-fixed"].get_offsets()) == tree.sum() == 1
    assert len(groups["theta0-assumed"].get_offsets()) == (ok & ~tree).sum() > 0
    np.testing.assert_allclose(
        groups["theta0-fixed"].get_offsets()[0],
        [f.loc[tree, "theta_i_deg"].iloc[0], f.loc[tree, "e_n"].iloc[0]],
    )
    assert len(groups["theta0-assumed"].get_facecolors()) == 0  # open markers
    assert len(groups["theta0-fixed"].get_facecolors()) > 0  # filled
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "θ0 fixed by a tree strike or measured (1)" in texts
    assert f"θ0 assumed ({(ok & ~tree).sum()})" in texts


def test_en_theta_without_sources_draws_one_group():
    fig = plot_en_theta([20.0, 40.0], [0.9, 0.5])
    assert not [c for c in fig.axes[0].collections if c.get_gid()]


# --- the ground under a track, units -------------------------------------------------


def test_track_figure_draws_the_ground_one_radius_below_each_impact(bounces):
    fig = plot_track(bounces)
    ax = fig.axes[0]
    ground = [line for line in ax.lines if line.get_color() == "#6b4f2a"]
    f = bounces.impacts.frame
    assert len(ground) == len(f) >= 2
    assert ground[0].get_label().startswith("ground at each impact")
    for line, row in zip(ground, f.itertuples(), strict=True):
        (x0, z0), (x1, z1) = line.get_xydata()
        assert np.degrees(np.arctan2(z0 - z1, x1 - x0)) == pytest.approx(row.slope_deg)
        # distance of the impact centre from the surface line = the radius
        d = abs((x1 - x0) * (z0 - row.z_m) - (x0 - row.x_m) * (z1 - z0)) / np.hypot(
            x1 - x0, z1 - z0
        )
        assert d == pytest.approx(R, rel=1e-9)
        assert (z0 + z1) / 2 < row.z_m  # below the centre, on the ground's side


def test_track_figure_over_a_frame_draws_the_ground_too(bounces):
    fig = plot_track(bounces, over_frame(bounces))
    labels = [line.get_label() for line in fig.axes[0].lines]
    assert "ground at each impact (the surface at its fitted dip)" in labels


def test_every_track_axis_names_its_unit(bounces, net):
    for fig in (
        plot_track(bounces),
        plot_track(bounces, over_frame(bounces)),
        plot_speed_spin(bounces),
        plot_residuals(bounces),
        plot_net_contact(net[1].contacts[0]),
    ):
        assert fig.axes[-1].get_xlabel()  # stacked panels share the bottom one's
        for ax in fig.axes:
            assert ax.get_ylabel()
            for label in (ax.get_xlabel(), ax.get_ylabel()):
                assert not label or re.search(r"\[[^\]]+\]", label), label


# --- quality flags -------------------------------------------------------------------


def rings(ax) -> list[PathCollection]:
    return [c for c in ax.collections if c.get_label().startswith(QA_LABEL)]


def test_qa_flags_follow_the_contract():
    frame = pd.DataFrame({"qa_flags": FLAGS})
    assert qa_flagged(frame).tolist() == [False, True, False, True, False]
    assert not qa_flagged(pd.DataFrame({"x": [1]})).any()


def test_figures_ring_the_flagged_impacts(flagged_table, survey_table):
    _, survey = survey_table
    f = flagged_table.frame
    flagged = qa_flagged(f)
    section = plot_section(flagged_table, survey).axes[0]
    head = plot_energy_head(flagged_table).axes[0]
    et = plot_et_impacts(f["e_t"], qa_flags=f["qa_flags"]).axes[0]
    for ax, (x, y) in (
        (section, (f["x_m"], f["z_m"])),
        (head, (f["x_m"], f["energy_head_i_m"])),
        (et, (np.arange(1, len(f) + 1), f["e_t"])),
    ):
        (ring,) = rings(ax)
        # the legend names each flag that sets a ringed impact apart, with its count
        label = f"{QA_LABEL} on 2: e_t > 1 (1), energy gained (1), spin estimated (1)"
        assert " ".join(ring.get_label().split()) == label  # wrapped in the legend
        expected = np.column_stack([x, y])[flagged & np.isfinite(y)]
        np.testing.assert_allclose(ring.get_offsets(), expected)
        assert len(ring.get_facecolors()) == 0  # an open ring
        assert ring.get_label() in [
            t.get_text() for t in legends(ax.figure)[0].get_texts()
        ]


def test_no_rings_without_flags(survey_table):
    """qa_flags is a contract column now: with no impact flagged, no ring is drawn."""
    table, survey = survey_table
    frame = table.frame.copy()
    frame["qa_flags"] = pd.NA
    assert not rings(plot_section(ImpactTable(frame), survey).axes[0])


def test_track_figure_rings_flagged_impacts(bounces):
    imp = bounces.impacts.frame.copy()
    imp["qa_flags"] = [""] * len(imp)
    imp.loc[1, "qa_flags"] = "e_t > 1"
    flagged = bounces.__class__(
        track=bounces.track,
        flights=bounces.flights,
        impacts=ImpactTable(imp),
        contacts=bounces.contacts,
        warnings=bounces.warnings,
    )
    (ring,) = rings(plot_track(flagged).axes[0])
    np.testing.assert_allclose(ring.get_offsets(), [[imp.x_m[1], imp.z_m[1]]])


# --- the net contact's energy efficiency on the console -----------------------------

EFFICIENCY = re.compile(r"energy efficiency E_f/E_i \(eq\. 8\.1\) ([\d.]+) %")


def test_view_prints_the_net_contact_efficiency(cli, repo, tmp_path):
    truth = json.loads((repo / "video" / "net.truth.json").read_text())["contact"]
    args = ["view", repo / "video" / "net.truth.csv", "--radius", R, "--mass", MASS]
    r = cli(*args, "--gyration", GYRATION, "-o", tmp_path / "n.rrd")
    assert r.exit_code == 0, r.stderr
    (line,) = [x for x in r.stdout.splitlines() if "net contact 0" in x]
    # the force contact's ends (see NetContact.efficiency): 71.44 % at the true ends,
    # 72.95 % (the truth file) at the end of penetration, 5 ballistic frames later
    assert float(EFFICIENCY.search(line).group(1)) == pytest.approx(71.4, abs=0.1)
    assert truth["efficiency_percent"] == pytest.approx(72.95, abs=0.01)
    assert "translational + rotational energy" in line and "absorbed 0.464 J" in line
    r = cli(*args[:-2], "-o", tmp_path / "m.rrd")  # no mass, no gyration: said so
    (line,) = [x for x in r.stdout.splitlines() if "net contact 0" in x]
    assert "per unit mass (no mass given)" in line
    assert "translational energy only (no spin or gyration)" in line


@pytest.fixture(scope="module")
def net_clip(repo, tmp_path_factory, net):
    name = "fieldkit_video_render_for_marks"
    spec = importlib.util.spec_from_file_location(name, repo / "video" / "render.py")
    render = importlib.util.module_from_spec(spec)
    sys.modules[name] = render
    spec.loader.exec_module(render)
    sim, _ = net
    f = sim.track.frame
    camera = render.Camera(width=480, height=400, origin_u_px=40.0, origin_v_px=380.0)
    rng = np.random.default_rng(4)
    scene = render.BounceScene(plate_point_m=(0.0, -1.0))  # plate out of view
    bg = np.clip(render.background(camera, rng, scene) + 0.5, 0, 255).astype(np.uint8)
    poses = f[["x_m", "z_m", "angle_rad"]].to_numpy(float)
    path = tmp_path_factory.mktemp("net") / "net.avi"
    render.write_clip(path, camera, render.Ball(), bg, poses, rng)
    return path, camera


def test_track_prints_the_net_contact_efficiency(cli, net_clip, net):
    path, camera = net_clip
    sim, _ = net
    u0, v0 = camera.origin_u_px, camera.origin_v_px
    scale = f"{u0},{v0},{u0 + 400},{v0}"
    r = cli(
        "track", path, "--fps", 1205, "--scale-points", scale, "--scale-length", 0.8,
        "--radius", R, "--mass", MASS, "-q",
    )  # fmt: skip
    assert r.exit_code == 0, r.stderr
    (line,) = [x for x in r.stdout.splitlines() if "net contact 0" in x]
    truth = sim.truth.iloc[0]
    expected = 100 * truth.ke_f_j / truth.ke_i_j  # no spin in the synthetic capture
    assert float(EFFICIENCY.search(line).group(1)) == pytest.approx(expected, abs=1.5)
    assert "absorbed" in line and " J" in line
