"""Console script: every command has help with an example; usage errors are one line."""

from __future__ import annotations

import subprocess
import sys

import pytest

from fieldkit.cli import app

COMMANDS = ["reduce", "impact", "fence", "track", "view"]


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "fieldkit", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_every_registered_command_is_listed():
    registered = sorted(c.name for c in app.registered_commands)
    assert registered == sorted(COMMANDS)


@pytest.mark.parametrize("command", COMMANDS)
def test_help_has_a_runnable_example(cli, command):
    r = cli(command, "--help")
    assert r.exit_code == 0
    assert "example" in r.stdout.lower() and f"fieldkit {command} " in r.stdout


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["reduce", "--theta0", "abc"], "Invalid value for '--theta0'"),
        (["impact", "--no-such-option"], "No such option: --no-such-option"),
        (["nonsense"], "No such command 'nonsense'"),
    ],
)
def test_usage_errors_are_one_line(args, expected):
    done = _run(*args)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: fieldkit ")
    assert expected in lines[0]
    assert done.stdout == ""


def test_no_arguments_prints_help():
    done = _run()
    assert done.returncode == 0 and "Commands" in done.stdout
