"""`fieldkit reduce -o /dev/null`: written through like every other output (issue 17:
reduce kept its own copy of the extension check and refused it)."""

from __future__ import annotations

import os
import stat


def test_reduce_table_to_dev_null(cli, repo):
    survey = repo / "surveys" / "tornado_mountain"
    result = cli(
        "reduce", "--preset", survey / "boulder_a_preset.toml",
        "--impacts", survey / "boulder_a_impacts.gpx",
        "--trees", survey / "boulder_a_trees.csv", "-o", "/dev/null",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "wrote /dev/null (50 rows)" in result.stdout
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


def test_reduce_unknown_table_format_is_one_line(cli, repo, tmp_path, fails):
    survey = repo / "surveys" / "tornado_mountain"
    result = cli(
        "reduce", "--preset", survey / "boulder_a_preset.toml",
        "--impacts", survey / "boulder_a_impacts.gpx", "-o", tmp_path / "t.txt",
    )  # fmt: skip
    fails(result, "t.txt", "unknown table format '.txt'")
    assert not (tmp_path / "t.txt").exists()
