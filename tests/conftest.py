"""Shared fixtures: repository paths, a command-line runner and its checks."""

from __future__ import annotations

import contextlib
import hashlib
import shlex
import shutil
import subprocess
import sys
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


#: What a fresh clone ships for examples to read, copied into a scratch repository root.
BUNDLED = ("surveys", "video", "tests/data", "tests/io/data")


@pytest.fixture()
def repo_copy(tmp_path) -> Path:
    """A scratch folder laid out like the repository root, holding copies of the bundled
    inputs (:data:`BUNDLED`, without rendered clips): examples written for the root run
    in it and write only there."""
    root = tmp_path / "repo"
    for part in BUNDLED:
        shutil.copytree(
            REPO / part, root / part, ignore=shutil.ignore_patterns("*.avi", "*.mp4")
        )
    return root


def _shell_commands(text: str) -> list[str]:
    """The ``fieldkit ...`` and ``python ...`` command lines in ``text``, in order, with
    backslash-continued lines joined (comments are left to :func:`shlex.split`)."""
    commands, current = [], ""
    for raw in text.splitlines():
        line = raw.strip()
        if current:
            current = f"{current} {line}"
        elif line.startswith(("fieldkit ", "python ")):
            current = line
        else:
            continue
        if current.endswith("\\"):
            current = current[:-1].rstrip()
            continue
        commands.append(current)
        current = ""
    assert not current, f"unfinished command line: {current}"
    return commands


def _run_shell(line: str, cwd: Path) -> tuple[int, str]:
    """Run one command line in ``cwd`` as a shell would: ``fieldkit ...`` in process
    (the console script's app), ``python ...`` with this interpreter. Returns the exit
    code and the output."""
    argv = shlex.split(line, comments=True)
    for arg in argv:  # examples read and write inside the repository only
        assert not arg.startswith(("/", "~")) and ".." not in Path(arg).parts, line
    if argv[0] == "fieldkit":
        from fieldkit.cli import app

        with contextlib.chdir(cwd):
            result = CliRunner().invoke(app, argv[1:])
        return result.exit_code, f"{result.stdout}{result.stderr}{result.exception!r}"
    assert argv[0] == "python", line
    done = subprocess.run(
        [sys.executable, *argv[1:]],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=600,
    )
    return done.returncode, done.stdout + done.stderr


@pytest.fixture(scope="session")
def shell_commands():
    """:func:`_shell_commands`: command lines of a README block or a help text."""
    return _shell_commands


@pytest.fixture(scope="session")
def run_shell():
    """:func:`_run_shell`: run one example command line in a folder."""
    return _run_shell
