"""Fixtures shared by the fit tests."""

from __future__ import annotations

from pathlib import Path

import pytest

TORNADO = Path(__file__).resolve().parents[2] / "surveys" / "tornado_mountain"


@pytest.fixture(scope="session")
def boulder_a(tmp_path_factory) -> Path:
    """Boulder A reduced with its preset, as ``fieldkit reduce`` writes it (the
    README's table); read only."""
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("boulder") / "boulder_a.csv"
    r = CliRunner().invoke(app, [
        "reduce", "--impacts", str(TORNADO / "boulder_a_impacts.gpx"),
        "--trees", str(TORNADO / "boulder_a_trees.csv"),
        "--preset", str(TORNADO / "boulder_a_preset.toml"), "-o", str(out),
    ])  # fmt: skip
    assert r.exit_code == 0, r.output
    return out
