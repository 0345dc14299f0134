"""README.md works as written: every command in it runs from the repository root on the
bundled files, its Python runs, and it points only at files inside the repository.

Shell blocks run in order in one copy of the repository root (:func:`repo_copy`), so a
block may read what an earlier one wrote, as a reader pasting them would; blocks that
render a video clip are marked slow.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
README = (REPO / "README.md").read_text()
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.M | re.S)
#: Top-level folders a README path may point into.
TOP = (
    "fieldkit",
    "docs",
    "surveys",
    "video",
    "tests",
    "examples",
    "benchmarks",
    "tools",
)


def blocks(language: str) -> list[str]:
    return [body for lang, body in FENCE.findall(README) if lang == language]


def renders_video(block: str) -> bool:
    return "video/render.py" in block


def run_blocks(selected, repo_copy, shell_commands, run_shell, monkeypatch) -> int:
    monkeypatch.setenv("MPLBACKEND", "Agg")
    count = 0
    for block in selected:
        for line in shell_commands(block):
            code, output = run_shell(line, repo_copy)
            assert code == 0, (line, output)
            count += 1
    return count


def test_shell_blocks_run(repo_copy, shell_commands, run_shell, monkeypatch):
    selected = [b for b in blocks("") if not renders_video(b)]
    before = {p.name for p in repo_copy.iterdir()}
    ran = run_blocks(selected, repo_copy, shell_commands, run_shell, monkeypatch)
    # --version, reduce, impact, fence, view (2), effects, simulate, simulate (3-D),
    # profile, synth, fit, fit --paths (2), fit (3-D), diagnose, synth --track,
    # diagnose (track), track3d (2: its data, the command), synth --survey,
    # reduce --campaign, diagnose (campaign), export (3), import-model,
    # import-results, corridor (2: 2-D, 3-D on 2 workers); the video block runs when
    # slow
    assert ran == 30
    # every README command writes under out/ only (issue 17): nothing new at the root
    assert {p.name for p in repo_copy.iterdir()} - before == {"out"}
    out = repo_copy / "out"
    assert (out / "boulder_a.csv").is_file()
    assert (out / "boulder_a.rrd").is_file()
    assert {p.name for p in (out / "reduce_figures").iterdir()} >= {"section.png"}
    assert (out / "sim" / "summary.json").is_file()
    assert (out / "sim" / "impacts.parquet").is_file()
    assert (out / "tschamut_profile.csv").is_file()
    assert (out / "calibrated.json").is_file() and (out / "after.json").is_file()
    assert (out / "tschamut_calibrated.json").is_file()
    assert (out / "boulder_a_path.json").is_file()
    assert (out / "from_rocfall.json").is_file()
    assert (out / "r3d" / "soiltype.asc").is_file()
    assert (out / "rstone_tschamut" / "run_rstone.sh").is_file()
    assert (out / "rstone_results" / "summary.json").is_file()
    assert (out / "diagnosis" / "report.md").is_file()
    assert (out / "track_diagnosis" / "report.md").is_file()
    assert (out / "track3d" / "impacts.csv").is_file()
    assert (out / "campaign" / "campaign.json").is_file()
    campaign = (out / "campaign_diagnosis.json").read_text()
    assert '"kind": "campaigns"' in campaign and '"size": 19' in campaign


@pytest.mark.slow
def test_video_blocks_run(repo_copy, shell_commands, run_shell, monkeypatch):
    selected = [b for b in blocks("") if renders_video(b)]
    assert len(selected) == 1
    assert run_blocks(selected, repo_copy, shell_commands, run_shell, monkeypatch) == 2
    bounce = repo_copy / "out" / "bounce"
    assert (bounce / "impacts.csv").is_file() and (bounce / "bounce.rrd").is_file()


def test_python_blocks_run_and_print_what_the_comments_say():
    (block,) = blocks("python")
    namespace: dict = {}
    *body, last = block.strip().splitlines()
    exec("\n".join(body), namespace)
    expression, comment = last.split("#")
    value = eval(expression, namespace)
    expected = eval(comment.strip(), {})
    assert tuple(round(v, 2) for v in value) == expected


def test_every_command_shown_is_in_a_block_that_runs():
    """Inline code naming a command with arguments would be untested: outside the
    blocks only command names appear (`fieldkit reduce`, `fieldkit track --help`)."""
    inline = re.findall(r"`(fieldkit [^`]*)`", FENCE.sub("", README))
    assert inline
    for text in inline:
        assert re.fullmatch(r"fieldkit [a-z][a-z0-9-]*( --help)?", text), text


def test_points_only_inside_the_repository():
    assert "../" not in README and "shared/" not in README
    top = "|".join(TOP)
    paths = set(re.findall(rf"[`(]((?:{top})/[\w./-]*)", README))
    assert len(paths) > 10
    for path in paths:
        assert (REPO / path).exists(), path
    for link in re.findall(r"\]\(([^)]+)\)", README):
        assert link.startswith("https://") or (REPO / link).exists(), link
