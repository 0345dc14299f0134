"""Figures of `impact`, `fence`, `profile`, `view` and video/render.py read as an
engineer expects (issue 17 review): every mark in the legend, symbols and units as
printed (ω, kN s), force laws as formulas, the profile's ending in words, contact
bands and the noise line explained, a `wrote` line per file.

The commands run in-process; each figure is caught as it is saved.
"""

from __future__ import annotations

import importlib.util
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball


def _run(cli, *args):
    """Run the CLI, keeping every figure it saves: (result, [Figure])."""
    saved: list[Figure] = []
    original = Figure.savefig

    def keep(self, *a, **kw):
        saved.append(self)
        return original(self, *a, **kw)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Figure, "savefig", keep)
        result = cli(*args)
    assert result.exit_code == 0, result.stderr
    return result, saved


def _legend_texts(ax) -> list[str]:
    legends = [ax.get_legend(), *ax.figure.legends]
    return [" ".join(t.get_text().split()) for g in legends if g for t in g.get_texts()]


def _unexplained_marks(ax) -> list[str]:
    """Lines with data whose label is not in a legend."""
    texts = _legend_texts(ax)
    return [
        line.get_label()
        for line in ax.get_lines()
        if len(line.get_xdata())
        and line.get_marker() not in ("None", "", None, " ")
        and " ".join(line.get_label().split()) not in texts
    ]


def test_impact_figure_explains_the_open_circle(cli, tmp_path):
    _, (fig,) = _run(
        cli, "impact", "--speed", "22", "--angle", "25", "--spin", "-15",
        "--shape", "sphere", "--dimensions", "0.75", "--law", "angle",
        "--figure", tmp_path / "p.png",
    )  # fmt: skip
    ax = fig.axes[0]
    (circle,) = [ln for ln in ax.get_lines() if ln.get_markerfacecolor() == "white"]
    assert circle.get_label().startswith("tangential velocity as slip stops")
    assert not _unexplained_marks(ax)


def test_fence_figure_symbols_units_and_force_laws(cli, tmp_path):
    _, (fig,) = _run(
        cli, "fence", "--mass", "520", "--gyration", "0.35", "--speed-in", "22",
        "--spin-in", "18", "--speed-out", "11.5", "--spin-out=-11.6",
        "--figure", tmp_path / "f.png",
    )  # fmt: skip
    energy, impulse, force = fig.axes[:3]
    assert "rotational ½ I ω²" in _legend_texts(energy)
    assert not [t for t in _legend_texts(energy) if "w^2" in t or "1/2" in t]
    # the rock's impulse in the unit of its axis: 520 kg x 22 m/s = 11.44 kN s
    assert "[kN s]" in impulse.get_ylabel()
    texts = [t.get_text() for t in impulse.texts]
    assert "rock impulse m v = 11.44 kN s" in texts
    laws = _legend_texts(force)
    assert "rigid: F = 1,000,000 t" in laws
    assert "flexible: F = 40,000 t²" in laws
    assert "stiff: F = 30,000 t⁰·⁶" in laws
    assert not [t for t in laws if "e+" in t or "^" in t]
    assert force.get_legend().get_title().get_text() == "force law: F in N, t in s"


def test_profile_title_says_how_the_descent_ended(cli, tmp_path, external_data):
    dem = Path(shutil.copy(external_data / "tschamut2014" / "terrain.asc", tmp_path))
    result, (fig,) = _run(
        cli, "profile", dem, "--from", "30.602,235.28", "-o", tmp_path / "p.csv",
        "--figure", tmp_path / "p.png",
    )  # fmt: skip
    assert "ended: a local minimum" in result.stdout
    titles = [ax.get_title() for ax in fig.axes]
    assert "section: the steepest descent stopped at a local minimum" in titles


def test_track_figures_explain_bands_and_noise_line(cli, tmp_path):
    """Grey contact bands were not in the legends of speed_spin.png and
    residuals.png; the dashed noise line (0.14 mm) sat 3x above the residual RMS
    (0.04 mm) unexplained: it is the 0.05 px floor the flight finding assumes."""
    s = bouncing_ball(
        duration_s=0.45,
        start_xz_m=(-0.06, 0.1001),
        start_velocity_mps=(1.4, 0.0),
        surface_angle_deg=15.0,
        e_n=0.7,
        e_t=0.8,
        noise_m=3e-5,
        rng=np.random.default_rng(0),
    )
    frame = s.track.frame.assign(radius_m=0.0375, radius_px=18.75)  # 2 mm/px
    path = tmp_path / "track.csv"
    frame.to_csv(path, index=False)
    _, saved = _run(
        cli, "view", path, "--radius", "0.0375", "-o", tmp_path / "t.rrd",
        "--figures", tmp_path / "figs",
    )  # fmt: skip
    by_name = {}
    for fig in saved:
        ylabel = fig.axes[-1].get_ylabel()
        by_name["residuals" if "fitted flight" in ylabel else ylabel] = fig
    residuals = by_name["residuals"].axes[0]
    spin = by_name["spin omega [rad/s]"]
    for ax in (residuals, *spin.axes):
        assert "contact: between two flights" in _legend_texts(ax), ax.get_ylabel()
    (noise,) = [t for t in _legend_texts(residuals) if t.startswith("position noise")]
    assert "(0.14 mm): its floor of 0.05 px" in noise  # 0.05 px x 2 mm x sqrt(2)
    rms = [float(m) for m in re.findall(r"RMS ([\d.]+) mm", " ".join(
        _legend_texts(residuals)))]  # fmt: skip
    assert rms and max(rms) < 0.07  # the floor, not the scatter, sets the line

    track = next(f for f in saved if f.axes[0].get_title().startswith("track"))
    texts = _legend_texts(track.axes[0])
    assert not [t for t in texts if "slope_deg" in t]
    assert "ground at each impact (the surface at its fitted dip)" in texts


def test_render_script_says_what_it_wrote(repo, tmp_path, capsys):
    name = "fieldkit_video_render_for_words"
    spec = importlib.util.spec_from_file_location(name, repo / "video" / "render.py")
    render = importlib.util.module_from_spec(spec)
    sys.modules[name] = render
    spec.loader.exec_module(render)
    assert render.main(["--out", str(tmp_path), "--frames", "12", "bounce_short"]) == 0
    wrote = [
        line.removeprefix("wrote ")
        for line in capsys.readouterr().out.splitlines()
        if line.startswith("wrote ")
    ]
    assert sorted(wrote) == sorted(str(p) for p in tmp_path.iterdir())
    assert len(wrote) == 5
