"""Console script: every command's help has examples that run as pasted from the
repository root; --version; usage errors are one line."""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import fieldkit
from fieldkit.cli import app

COMMANDS = [
    "corridor",
    "diagnose",
    "reduce",
    "impact",
    "fence",
    "track",
    "track3d",
    "lens",
    "view",
    "profile",
    "simulate",
    "effects",
    "synth",
    "fit",
    "export",
    "import-model",
    "import-results",
]
REPO = Path(__file__).resolve().parents[2]


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


#: Commands whose examples need the simulator core.
NEEDS_CORE = {"simulate", "effects", "synth", "fit", "diagnose", "corridor"}

#: Commands whose examples render and track a video clip (about 15 s).
SLOW_EXAMPLES = {"track"}


def _help(cli, command: str, monkeypatch) -> str:
    monkeypatch.setenv("COLUMNS", "80")  # as a terminal shows it: no wrapped examples
    r = cli(command, "--help")
    assert r.exit_code == 0
    return r.stdout


@pytest.mark.parametrize("command", COMMANDS)
def test_help_has_a_runnable_example(cli, command, shell_commands, monkeypatch):
    text = _help(cli, command, monkeypatch)
    assert "example" in text.lower()
    assert any(c.startswith(f"fieldkit {command} ") for c in shell_commands(text))


@pytest.mark.parametrize(
    "command",
    [
        pytest.param(c, marks=pytest.mark.slow) if c in SLOW_EXAMPLES else c
        for c in COMMANDS
    ],
)
def test_every_help_example_runs_from_the_repository_root(
    cli, command, shell_commands, run_shell, repo_copy, monkeypatch
):
    """Each example line of ``--help`` (continuations joined), in order, in a copy of
    the repository root: exit 0, and every output it names is written there."""
    monkeypatch.setenv("MPLBACKEND", "Agg")
    if command in NEEDS_CORE:  # the simulator core is built in parallel (issue 9)
        pytest.importorskip("fieldkit.model.simulate")
        pytest.importorskip("fieldkit.model.effects.registry")
    examples = shell_commands(_help(cli, command, monkeypatch))
    assert examples
    for line in examples:
        code, output = run_shell(line, repo_copy)
        assert code == 0, (line, output)
        for flag, path in re.findall(
            r"(-o|--impacts|--rrd|--figures?|--json) (\S+)", line
        ):
            assert (repo_copy / path).exists(), (flag, path, line)


def test_version_has_one_source(cli):
    r = cli("--version")
    assert r.exit_code == 0
    assert r.stdout == f"fieldkit {fieldkit.__version__}\n"
    assert re.fullmatch(r"\d+\.\d+\.\d+", fieldkit.__version__)
    project = tomllib.loads((REPO / "pyproject.toml").read_text())
    assert "version" not in project["project"]
    assert project["project"]["dynamic"] == ["version"]
    dynamic = project["tool"]["setuptools"]["dynamic"]["version"]
    assert dynamic == {"attr": "fieldkit._version.__version__"}


def test_version_from_the_console_script():
    done = _run("--version")
    assert done.returncode == 0
    assert done.stdout == f"fieldkit {fieldkit.__version__}\n"


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
