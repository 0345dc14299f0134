"""The report per tracked clip (fieldkit.viz.track_report), against the clip's truth.

A short ``bounce_short`` clip (video/render.py, 1205 frames/s, its first impact at
frame ~170) is rendered and tracked once; the report's numbers are checked against
the track result and the drawn circles against the renderer's exact centres.
"""

from __future__ import annotations

import doctest
import json
import re

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from fieldkit.physics.constants import G
from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.video.calibration import read_homography_file
from fieldkit.tracking.video.pipeline import track_video
from fieldkit.tracking.video.reader import VideoReader
from fieldkit.viz import track_report_figure
from fieldkit.viz.figure_files import DPI
from fieldkit.viz.track_report import REPORT_NAMES, flight_rows, write_track_report
from fieldkit.viz.track_report_figure import (
    CIRCLE_COLOUR,
    contact_frames,
    crop_box,
    frame_flags,
    plot_frames,
    plot_time_height,
    refused_frames,
    sheet_frames,
)

FRAMES = 230  # one impact (frame ~170), two flights


@pytest.fixture(scope="module")
def clip(video_render, tmp_path_factory):
    """The rendered clip, its truth and the library's track result of it."""
    render = video_render
    folder = tmp_path_factory.mktemp("report_clip")
    render.render("bounce_short", folder, frames=FRAMES)
    calib = json.loads((folder / "bounce_short.calibration.json").read_text())
    truth = json.loads((folder / "bounce_short.truth.json").read_text())
    video = folder / calib["video"]
    fps = calib["capture_fps"]
    reader = VideoReader(video)
    size = (reader.info.width, reader.info.height)
    calibration = read_homography_file(folder / calib["homography_file"], size)
    radius = truth["ball"]["radius_m"]
    track, detections = track_video(
        video, fps=fps, calibration=calibration, radius_m=radius, reader=reader
    )
    analysis = analyse_track(
        track,
        radius_m=radius,
        surface_angle_deg=truth["scene_parameters"]["surface_deg"],
        mass_kg=truth["ball"]["mass_kg"],
    )
    return dict(
        video=video,
        fps=fps,
        analysis=analysis,
        detections=detections,
        truth=truth,
        positions=pd.read_csv(folder / "bounce_short.truth.csv"),
        calibration=calib,
    )


def _table(text: str, heading: str) -> list[list[str]]:
    """The body rows of the first Markdown table under ``## heading``."""
    section = text.split(f"## {heading}\n", 1)[1].split("\n## ", 1)[0]
    lines = [ln for ln in section.splitlines() if ln.startswith("| ")]
    return [[c.strip() for c in re.split(r"(?<!\\)\|", ln)[1:-1]] for ln in lines[1:]]


def test_report_numbers_are_the_track_results(clip, tmp_path):
    a, fps = clip["analysis"], clip["fps"]
    paths = write_track_report(
        tmp_path, a, clip["detections"], video=clip["video"], warnings=["check me"]
    )
    assert [p.name for p in paths] == list(REPORT_NAMES)
    assert all(p.stat().st_size > 0 for p in paths)
    text = (tmp_path / "report.md").read_text()
    # the clip's true impacts: one inside the rendered frames
    true_frames = [
        i["t_s"] * fps for i in clip["truth"]["impacts"] if i["t_s"] * fps < FRAMES
    ]
    assert len(true_frames) == 1 and len(a.flights) == 2
    flights = _table(text, "Flights")
    assert len(flights) == len(a.flights)
    for row, fl, numbers in zip(flights, a.flights, flight_rows(a), strict=True):
        assert int(row[0]) == fl.index
        assert row[4] == fl.g_text().replace("+/-", "±")
        g_text, se_text = row[4].split(" ± ")
        half_digit = 0.5 * 10.0 ** -len(se_text.split(".")[1])
        assert float(g_text) == pytest.approx(fl.g_mps2, abs=half_digit)
        assert float(se_text) == pytest.approx(fl.g_check_se_mps2, abs=half_digit)
        assert float(row[6]) == pytest.approx(
            abs(fl.g_mps2 - G) / fl.g_check_se_mps2, abs=0.006
        )
        assert float(row[5]) == pytest.approx(fl.g_mps2 - G, abs=6e-4)
        first, last = (int(k) for k in row[1].split("–"))
        assert (first, last) == (numbers["first_frame"], numbers["last_frame"])
        ts = a.track.frame["t_s"].to_numpy()[fl.rows]
        assert (first, last) == (round(ts.min() * fps), round(ts.max() * fps))
    contacts = _table(text, "Contacts")
    assert len(contacts) == 1
    assert contacts[0][1] == "impact"
    assert abs(int(contacts[0][2]) - true_frames[0]) <= 1.0
    for column, value in zip(("e_n", "e_t"), contacts[0][7:9], strict=True):
        assert float(value) == pytest.approx(a.impacts.frame[column].iloc[0], abs=6e-4)
    assert "* check me" in text
    assert "No frame was refused" in text
    for name in REPORT_NAMES[1:]:
        assert f"]({name})" in text


def test_time_height_draws_each_flight_and_contact(clip):
    a = clip["analysis"]
    fig = plot_time_height(a, clip["detections"], title="clip")
    ax = fig.axes[0]
    fits = [ln for ln in ax.get_lines() if ln.get_label().startswith("flight ")]
    assert len(fits) == len(a.flights)
    for line, fl in zip(fits, a.flights, strict=True):
        t, z = line.get_data()
        assert t[0] == pytest.approx(fl.t_start_s) and t[-1] == pytest.approx(
            fl.t_end_s
        )
        assert np.allclose(z, fl.position(t)[1])
    impact = [ln for ln in ax.get_lines() if ln.get_label().startswith("impact")]
    assert len(impact) == 1
    assert impact[0].get_xdata()[0] == pytest.approx(a.impacts.frame["t_s"].iloc[0])
    # flight 1 rises after the impact: its apex is marked at vz = 0
    apex = track_report_figure.flight_apex(a.flights[1])
    assert apex is not None
    assert a.flights[1].velocity(apex[0])[1] == pytest.approx(0.0, abs=1e-9)


def test_contact_sheet_shows_the_contact_frames_and_circles_at_the_truth(clip):
    a, det, truth = clip["analysis"], clip["detections"], clip["positions"]
    (contact,) = contact_frames(a)
    wanted = sheet_frames(a, det)
    around = [contact.first - 1, contact.first, contact.first + 1]
    assert set(around) <= set(wanted)
    assert len(wanted) == track_report_figure.SHEET_FRAMES
    images = dict(VideoReader(clip["video"]).read_frames(wanted))
    fig = plot_frames(images, det, a, title="clip")
    fig.set_dpi(DPI)  # as save_png writes it
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba())
    radius_px = clip["truth"]["ball"]["radius_m"] / 0.002  # 2 mm/px (homography)
    checked = 0
    for ax, k in zip(fig.axes, sorted(images), strict=False):
        assert ax.get_title(loc="left").startswith(
            f"frame {k}, t = {k / clip['fps']:.4f} s"
        )
        if k in around:
            which = (
                "before"
                if k < contact.first
                else "after"
                if k > contact.first
                else "at"
            )
            assert f"{which} impact 1 (frame {contact.first})" in ax.get_title(
                loc="left"
            )
        circles = [p for p in ax.patches if p.get_edgecolor()[:3] == (0.0, 1.0, 0.0)]
        u, v = truth.loc[truth["frame"] == k, ["u_px", "v_px"]].to_numpy()[0]
        if not truth.loc[truth["frame"] == k, "visible"].iloc[0] == 1:
            continue
        (circle,) = circles
        assert np.hypot(*(np.array(circle.center) - (u, v))) < 0.25
        assert circle.radius == pytest.approx(radius_px, abs=0.3)
        # read the drawn image back: green on the circle right of the true centre,
        # not at the true centre nor halfway to the rim
        if u - radius_px < ax.get_xlim()[0]:
            continue  # the body is cut by the frame edge
        h = rgba.shape[0]

        def pixel(du, _ax=ax, _u=u, _v=v, _h=h):
            x, y = _ax.transData.transform((_u + du, _v))
            patch = rgba[int(_h - y) - 1 : int(_h - y) + 2, int(x) - 1 : int(x) + 2, :3]
            return patch.reshape(-1, 3).astype(int)

        green = np.array([0, 255, 0])
        assert (np.abs(pixel(radius_px) - green).max(axis=1) < 60).any(), k
        for du in (0.5 * radius_px, -0.5 * radius_px):
            assert (np.abs(pixel(du) - green).max(axis=1) > 120).all(), k
        checked += 1
    assert checked >= 12
    assert CIRCLE_COLOUR == "#00ff00"


def test_crop_box_keeps_the_body_inside_the_frame():
    assert doctest.testmod(track_report_figure, verbose=False).failed == 0
    for u, v in [(0.0, 0.0), (479.9, 319.9), (240.0, 5.0), (13.3, 200.7)]:
        u0, v0, u1, v1 = crop_box(u, v, 18.75, (480, 320))
        assert 0 <= u0 <= u < u1 <= 480 and 0 <= v0 <= v < v1 <= 320
        assert u1 - u0 == v1 - v0 == int(np.ceil(5 * 18.75))
        # centred unless the edge pushed it
        if 47 < u < 433:
            assert abs((u0 + u1) / 2 - u) <= 1.0
    assert crop_box(10.0, 10.0, 400.0, (480, 320)) == (0, 0, 320, 320)


def test_refused_frames_and_flags_show_a_detectors_fields():
    det = pd.DataFrame(
        {
            "frame": [0, 1, 2, 3, 4],
            "found": [True, False, False, True, True],
            "partial": [True, np.nan, np.nan, False, False],
            "visible_fraction": [0.4, np.nan, np.nan, 1.0, 1.0],
            "blurred": [False, np.nan, np.nan, True, False],
            "detect_status": ["ok", "blurred: streak 4 px", "", "ok", "low contrast"],
        }
    )
    refused = refused_frames(det)
    assert refused["frame"].tolist() == [1, 2]
    assert refused["reason"].tolist() == ["blurred: streak 4 px", "no body detected"]
    status = track_report_figure.detection_status(det)
    flags = [frame_flags(det.iloc[i], status.iloc[i]) for i in range(5)]
    assert flags[0] == ["partial (40 % visible)"]
    assert flags[1] == ["refused: blurred: streak 4 px"]
    assert flags[3] == ["blurred"]
    assert flags[4] == ["low contrast"]
    flagged = track_report_figure.flagged_frames(det)
    assert {k: v.tolist() for k, v in flagged.items()} == {
        "partial": [0],
        "blurred": [3],
        "low contrast": [4],
    }
    # without the columns: nothing refused, no flag
    plain = det[["frame"]].assign(found=True)
    assert refused_frames(plain).empty
    assert frame_flags(plain.iloc[0]) == []


def test_cli_report_holds_every_warning_it_printed(cli, clip, tmp_path):
    c = clip["calibration"]
    folder = clip["video"].parent
    out = tmp_path / "report"
    result = cli(
        "track", clip["video"], "--fps", clip["fps"],
        "--homography", folder / c["homography_file"], "--radius", 0.0375,
        "--surface-angle", 15, "--report", out, "-q",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert sorted(p.name for p in out.iterdir()) == sorted(REPORT_NAMES)
    text = " ".join((out / "report.md").read_text().split())
    printed = [
        ln.removeprefix("warning: ")
        for ln in result.stderr.splitlines()
        if ln.startswith("warning: ")
    ]
    assert any("--fps" in w for w in printed)  # the container's 30 frames/s
    for message in printed:
        assert message in text
    g_lines = re.findall(
        r"flight (\d+) \(t = .*?\): g = ([\d.]+ \+/- [\d.]+)", result.stdout
    )
    flights = _table((out / "report.md").read_text(), "Flights")
    assert [(r[0], r[4]) for r in flights] == [
        (i, g.replace("+/-", "±")) for i, g in g_lines
    ]


def test_net_contact_is_a_band_with_its_frames():
    from fieldkit.tracking.flights.synthetic_tracks import net_capture
    from fieldkit.viz.track_report import markdown

    sim = net_capture(noise_m=3e-4, rng=np.random.default_rng(4))
    a = analyse_track(sim.track, radius_m=0.0375, mass_kg=0.14)
    (net,) = a.contacts
    (c,) = contact_frames(a)
    fps = a.track.fps
    assert c.kind == "net"
    assert (c.t_start_s, c.t_end_s) == pytest.approx((net.t_start_s, net.t_end_s))
    assert (c.first, c.last) == (round(net.t_start_s * fps), round(net.t_end_s * fps))
    ax = plot_time_height(a, None, title="net").axes[0]
    (band,) = [p for p in ax.patches if p.get_label() == "net contact"]
    span = (band.get_x(), band.get_x() + band.get_width())
    assert span == pytest.approx((net.t_start_s, net.t_end_s))
    text = markdown(a, None, video="net.avi", warnings=[])
    (row,) = _table(text, "Contacts")
    assert row[1:3] == ["net", f"{c.first}–{c.last}"]
    assert net.summary() in text
