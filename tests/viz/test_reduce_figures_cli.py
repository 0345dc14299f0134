"""The figures ``fieldkit reduce --figures`` writes for boulder A (issue 17): rings
only where a quality flag sets an impact apart, the method flags every survey row
carries said once in the legend, every mark explained, axes in words with units.

The command runs in-process; each figure is caught as it is saved.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from fieldkit.impact_table import METHOD_QA_FLAGS
from fieldkit.viz.marks import QA_LABEL, SHARED_LABEL

BOULDER_A = (
    "--impacts",
    "surveys/tornado_mountain/boulder_a_impacts.gpx",
    "--trees",
    "surveys/tornado_mountain/boulder_a_trees.csv",
    "--theta0",
    "32.6",
    "--mass",
    "3750",
    "--radius",
    "0.725",
    "--gyration",
    "0.46",
)


@pytest.fixture(scope="module")
def reduced(tmp_path_factory, repo):
    """(table, {title: Figure}) of boulder A reduced with figures."""
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("reduce")
    saved: list[Figure] = []
    original = Figure.savefig

    def keep(self, *args, **kwargs):
        saved.append(self)
        return original(self, *args, **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(repo)
        mp.setattr(Figure, "savefig", keep)
        result = CliRunner().invoke(
            app,
            [
                "reduce",
                *BOULDER_A,
                "-o",
                str(out / "b.csv"),
                "--figures",
                str(out / "figs"),
            ],
        )
    assert result.exit_code == 0, result.output
    assert len(saved) == 5
    table = pd.read_csv(out / "b.csv", keep_default_na=False)
    table.attrs["path"] = out / "b.csv"
    table.attrs["stdout"] = result.stdout
    return table, {fig.axes[0].get_title(): fig for fig in saved}


def _flags(table) -> list[set[str]]:
    return [{p for p in str(v).split(";") if p} for v in table["qa_flags"]]


def rings(ax):
    return [c for c in ax.collections if c.get_label().startswith(QA_LABEL)]


def legend_texts(fig: Figure) -> list[str]:
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    return [t.get_text() for leg in [*legends, *fig.legends] for t in leg.get_texts()]


def test_method_flags_ring_no_impact(reduced):
    table, figures = reduced
    flags = _flags(table)
    # the survey's method flags sit on (almost) every row ...
    assert sum("spin_estimated" in f for f in flags) == 50
    assert sum("slope_from_chord" in f for f in flags) == 49
    # ... the rows other flags set apart: e_N slope-sensitive 20, KE gained 3, e_T > 1 3
    apart = np.array([bool(f - METHOD_QA_FLAGS) for f in flags])
    assert apart.sum() == 22
    section = next(f for t, f in figures.items() if "mapped impact points" in t)
    (ring,) = rings(section.axes[0])
    np.testing.assert_allclose(
        ring.get_offsets(), table.loc[apart, ["x_m", "z_m"]].to_numpy()
    )
    for title, fig in figures.items():
        ax = fig.axes[0]
        (ring,) = rings(ax)
        assert len(ring.get_offsets()) <= 22, title  # never all 48-50 points
        label = " ".join(ring.get_label().split())
        assert "slope from the chord" not in label and "v/r" not in label, title
        assert "kinetic energy gained (3)" in label, title
        (said_once,) = [
            t for t in legend_texts(fig) if " ".join(t.split()).startswith(SHARED_LABEL)
        ]
        said_once = " ".join(said_once.split())
        assert "spin estimated as v/r" in said_once, title
        assert "slope from the chord to the previous point" in said_once, title


def test_every_axis_is_words_with_a_unit(reduced):
    _, figures = reduced
    for title, fig in figures.items():
        ax = fig.axes[0]
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            assert re.search(r"[a-z]{3,}.*\[[^\]]+\]", label), (title, label)


def test_every_line_drawn_is_in_the_legend(reduced):
    """The dotted e = 1 reference lines used to be unexplained."""
    _, figures = reduced
    for title, fig in figures.items():
        ax = fig.axes[0]
        texts = legend_texts(fig)
        for line in ax.get_lines():
            if line.get_label().startswith("_") or len(line.get_xdata()) == 0:
                continue
            assert line.get_label() in texts, (title, line.get_label())
    en_theta = next(f for t, f in figures.items() if "Fig. 5.7" in t)
    assert "$e_N$ = 1: normal speed kept" in legend_texts(en_theta)
    partition = next(f for t, f in figures.items() if "energy partition" in t)
    assert "impact elevation (some labelled with the point)" in legend_texts(partition)


def test_impacts_are_counted_the_same_way_everywhere(reduced, cli, tmp_path):
    """Issue 17 review: reduce says 48 impacts, but `view` printed "50 impacts", the
    section title "mapped impact points (50)" and section.png / energy_head.png
    "50 of 50", "49 of 50" for the method flags (the first and last rows are the
    release and the stop point). Impacts are rows with an impact everywhere; the
    release and stop points are named apart."""
    table, figures = reduced
    assert len(table) == 50
    assert re.search(r"\b48 impacts\b", table.attrs["stdout"])
    both = "48 impacts (plus the release point and the stop point)"
    section = next(f for t, f in figures.items() if "mapped impact points" in t)
    assert both in section.axes[0].get_title()
    for title, fig in figures.items():
        (said_once,) = [
            " ".join(t.split())
            for t in legend_texts(fig)
            if " ".join(t.split()).startswith(SHARED_LABEL)
        ]
        counts = re.findall(r"\((\d+) of (\d+)\)", said_once)
        assert counts, (title, said_once)
        assert {of for _, of in counts} == {"48"}, (title, said_once)
        assert {n for n, _ in counts} == {"48"}, (title, said_once)

    result = cli("view", table.attrs["path"], "-o", tmp_path / "b.rrd")
    assert result.exit_code == 0, result.stderr
    assert result.stdout.startswith(f"{both}, 1 path(s):")
