"""Shared fixtures: repository paths, a command-line runner and its checks."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from typer.testing import CliRunner

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def repo() -> Path:
    """The repository root."""
    return REPO


@pytest.fixture(scope="session")
def external_data() -> Path:
    """Third-party reference data copied into ``tests/data/`` with its licences.

    Part of the repository, so a fresh clone runs every test that reads it.
    """
    return REPO / "tests" / "data"


@pytest.fixture()
def cli():
    """Run ``fieldkit ARGS...``; returns the click Result (stdout/stderr separate)."""
    from fieldkit.cli import app

    runner = CliRunner()

    def run(*args: str):
        return runner.invoke(app, [str(a) for a in args])

    return run


@pytest.fixture(scope="session")
def fails():
    """Check a ``cli`` Result: exit code != 0, one 'error:' line naming every word."""

    def check(result, *words: str) -> None:
        assert result.exit_code != 0
        lines = [line for line in result.stderr.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
        for word in words:
            assert word in lines[0], (word, lines[0])

    return check


@pytest.fixture(scope="session")
def digest():
    """SHA-256 of a file's bytes, to show an input was left untouched."""

    def sha256(path) -> str:
        return hashlib.sha256(path.read_bytes()).hexdigest()

    return sha256
