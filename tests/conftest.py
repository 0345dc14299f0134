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


_TORNADO = Path(__file__).resolve().parents[1] / "surveys" / "tornado_mountain"

@pytest.fixture(scope="session")
def repo() -> Path:
    """The repository root."""
    return REPO


@pytest.fixture(scope="session")
def video_render():
    """The clip renderer ``video/render.py`` (a script, not a package), loaded once."""
    import importlib.util

    name = "fieldkit_video_render"
    if name not in sys.modules:
        path = REPO / "video" / "render.py"
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


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
BUNDLED = (
    "surveys",
    "video",
    "tests/data",
    "tests/io/data",
    "examples/tschamut",
    "examples/rstone_tornado",
    "examples/track3d",
)


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


@pytest.fixture()
def synthetic_simulation():
    """A SimulationResult built from numpy arrays with known distributions.

    ``make(rocks, seed)`` -> result on a 3-vertex profile (x 0, 50, 100 m; materials
    rock, talus) whose runout is U(60, 100) m, with one analysis point at x = 70 m
    crossed by the rocks whose runout exceeds 70 m (speed ~ N(10, 2) m/s, height ~
    N(1, 0.2) m), an envelope of 10 bins and 3 straight-line trajectories. The model
    is a stand-in with the attributes the summary and figures read.
    """
    from types import SimpleNamespace

    import numpy as np

    from fieldkit.model.results import AnalysisPoint, SimulationResult

    def make(rocks: int = 1000, seed: int = 1) -> SimulationResult:
        rng = np.random.default_rng(seed)
        profile = SimpleNamespace(
            x_m=np.array([0.0, 50.0, 100.0]),
            z_m=np.array([60.0, 20.0, 10.0]),
            material=("rock", "talus"),
            source="synthetic",
        )
        profile.ground_z = lambda x: np.interp(x, profile.x_m, profile.z_m)
        model = SimpleNamespace(
            profile=profile,
            materials={},
            effects={"air_drag": {"cd": 0.5}},
            core={"slide_vn_mps": 0.5},
            source="synthetic.json",
            provenance={},
        )
        runout = rng.uniform(60.0, 100.0, rocks)
        crossed = runout > 70.0
        speed = np.where(crossed, rng.normal(10.0, 2.0, rocks), np.nan)
        mass, k, omega = 1000.0, 0.4, speed / 0.5
        ke = 0.5 * mass * speed**2
        re = 0.5 * mass * k**2 * omega**2
        point = AnalysisPoint(
            x_m=70.0,
            crossed=crossed,
            speed_mps=speed,
            ke_j=ke,
            re_j=re,
            total_j=ke + re,
            height_m=np.where(crossed, rng.normal(1.0, 0.2, rocks), np.nan),
        )
        edges = np.linspace(0.0, 100.0, 11)
        centres = (edges[:-1] + edges[1:]) / 2
        env = rng.exponential(1.0, (rocks, 10)).astype(np.float32)
        env[centres[None, :] > runout[:, None]] = np.nan
        trajectories = [
            np.column_stack(
                [
                    np.linspace(0, r, 20),
                    np.interp(np.linspace(0, r, 20), profile.x_m, profile.z_m) + 1.0,
                ]
            )
            for r in runout[:3]
        ]
        state = np.where(runout < 100.0, 0, 1)
        return SimulationResult(
            model=model,
            rocks=rocks,
            seed=seed,
            wall_s=0.5,
            impacts=rocks * 7,
            runout_x_m=runout,
            state=state,
            impacts_per_rock=np.full(rocks, 7),
            analysis=[point],
            envelope_x_m=edges,
            envelope_height_m=env,
            trajectories=trajectories,
        )

    return make


@pytest.fixture(scope="session")
def boulder_a(tmp_path_factory) -> Path:
    """Boulder A reduced with its preset, as ``fieldkit reduce`` writes it (the
    README's table); read only."""
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("boulder") / "boulder_a.csv"
    r = CliRunner().invoke(app, [
        "reduce", "--impacts", str(_TORNADO / "boulder_a_impacts.gpx"),
        "--trees", str(_TORNADO / "boulder_a_trees.csv"),
        "--preset", str(_TORNADO / "boulder_a_preset.toml"), "-o", str(out),
    ])  # fmt: skip
    assert r.exit_code == 0, r.output
    return out
