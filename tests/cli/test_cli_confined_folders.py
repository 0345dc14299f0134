"""A folder of outputs (``--figures``, ``--report``, ``export -o``) is never left
through a symbolic link inside it (issue 17: ``export --force`` replaced a link's target
outside its folder; every folder-writing command shares the rule: OutputSet.confine)."""

from __future__ import annotations

import pytest

SURVEY = ("surveys", "tornado_mountain")


def _commands(repo, folder):
    survey = repo.joinpath(*SURVEY)
    model = survey / "model_rocfall_table_7_1.json"
    reduce = ["reduce", "--preset", survey / "boulder_a_preset.toml",
              "--impacts", survey / "boulder_a_impacts.gpx"]  # fmt: skip
    return {
        "reduce --figures": (
            [*reduce, "--figures", folder],
            "section.png",
        ),
        "simulate --figures": (
            ["simulate", model, "--rocks", "20", "--seed", "1", "--figures", folder],
            "runout.png",
        ),
    }


@pytest.mark.parametrize("which", ["reduce --figures", "simulate --figures"])
def test_a_link_in_a_figures_folder_is_refused_not_followed(
    cli, fails, repo, tmp_path, which
):
    folder = tmp_path / "figs"
    folder.mkdir()
    outside = tmp_path / "elsewhere.png"
    outside.write_bytes(b"precious")
    argv, name = _commands(repo, folder)[which]
    (folder / name).symlink_to(outside)
    result = cli(*argv)
    fails(result, name, "symbolic link", "outside")
    assert outside.read_bytes() == b"precious"
    assert (folder / name).is_symlink()


def test_a_link_in_a_report_folder_is_refused_not_followed(cli, fails, repo, tmp_path):
    survey = repo.joinpath(*SURVEY)
    table = tmp_path / "b.csv"
    done = cli("reduce", "--preset", survey / "boulder_a_preset.toml",
               "--impacts", survey / "boulder_a_impacts.gpx", "-o", table)  # fmt: skip
    assert done.exit_code == 0, done.stderr
    folder = tmp_path / "report"
    folder.mkdir()
    outside = tmp_path / "notes.md"
    outside.write_text("mine\n")
    (folder / "report.md").symlink_to(outside)
    result = cli(
        "diagnose", table, "--model", survey / "model_rocfall_table_7_1.json",
        "--preset", survey / "boulder_a_preset.toml", "--seed", "1",
        "--report", folder, "--null", "0",
    )  # fmt: skip
    fails(result, "report.md", "symbolic link", "outside")
    assert outside.read_text() == "mine\n"


def test_a_link_that_stays_inside_the_folder_is_followed(cli, repo, tmp_path):
    folder = tmp_path / "figs"
    (folder / "kept").mkdir(parents=True)
    argv, name = _commands(repo, folder)["reduce --figures"]
    (folder / name).symlink_to(folder / "kept" / name)
    result = cli(*argv)
    assert result.exit_code == 0, result.stderr
    assert (folder / name).is_symlink() and (folder / "kept" / name).is_file()
