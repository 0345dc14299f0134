"""Shared fixtures: repository paths and a command-line runner."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"


@pytest.fixture(scope="session")
def repo() -> Path:
    """The repository root."""
    return REPO


@pytest.fixture(scope="session")
def external_data() -> Path:
    """Third-party reference data beside the repository (skips if absent)."""
    path = SHARED / "data" / "external"
    if not path.is_dir():
        pytest.skip("shared/data/external not available")
    return path


@pytest.fixture()
def cli():
    """Run ``fieldkit ARGS...``; returns the click Result (stdout/stderr separate)."""
    from fieldkit.cli import app

    runner = CliRunner()

    def run(*args: str):
        return runner.invoke(app, [str(a) for a in args])

    return run
