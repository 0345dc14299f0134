"""fieldkit.outputs: the OutputSet's promises and spreadsheet-safe text.

The command-line cases (inputs, links, FIFOs, errors) are in
tests/cli/test_cli_outputs.py; these cover what a command cannot easily reach.
"""

from __future__ import annotations

import doctest
import errno
import os
from pathlib import Path

import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fieldkit import outputs as outputs_module
from fieldkit.errors import OutputFileError
from fieldkit.impact_table import ImpactTable
from fieldkit.outputs import (
    FORMULA_STARTS,
    OutputSet,
    escape_formula,
    escape_formulas,
    unescape_formula,
    unescape_formulas,
    write_text,
)


def test_doctests():
    result = doctest.testmod(outputs_module)
    assert result.attempted >= 10 and result.failed == 0


def _files(root: Path) -> list[str]:
    return sorted(str(p.relative_to(root)) for p in root.rglob("*"))


@pytest.mark.parametrize("error", [ValueError("bad value"), KeyboardInterrupt()])
def test_a_failing_writer_leaves_nothing(tmp_path, error):
    (tmp_path / "old.txt").write_text("old")
    outputs = OutputSet()
    write_text(tmp_path / "old.txt", "new", outputs)
    write_text(tmp_path / "new" / "a.txt", "a", outputs)

    def broken(tmp: Path) -> None:
        tmp.write_text("half")
        raise error

    outputs.add(tmp_path / "new" / "b.txt", broken)
    with pytest.raises(type(error)):
        outputs.commit()
    assert _files(tmp_path) == ["old.txt"]
    assert (tmp_path / "old.txt").read_text() == "old"


def test_restores_by_copy_where_hard_links_are_not_allowed(tmp_path, monkeypatch):
    (tmp_path / "a.txt").write_text("old a")
    (tmp_path / "a.txt").chmod(0o600)
    real_replace = os.replace

    def no_link(src, dst, **kwargs):
        raise PermissionError(errno.EPERM, "Operation not permitted")

    def replace(src, dst):
        if Path(dst).name == "b.txt":
            raise OSError(errno.EIO, "Input/output error")
        return real_replace(src, dst)

    monkeypatch.setattr(os, "link", no_link)
    monkeypatch.setattr(os, "replace", replace)
    outputs = OutputSet()
    write_text(tmp_path / "a.txt", "new a", outputs)
    write_text(tmp_path / "b.txt", "new b", outputs)
    with pytest.raises(OutputFileError, match=r"b\.txt: input/output error"):
        outputs.commit()
    assert _files(tmp_path) == ["a.txt"]
    assert (tmp_path / "a.txt").read_text() == "old a"
    assert (tmp_path / "a.txt").stat().st_mode & 0o777 == 0o600


def test_commits_once_and_only_with_every_writer(tmp_path):
    outputs = OutputSet()
    outputs.plan(tmp_path / "a.txt")
    with pytest.raises(ValueError, match="without a writer"):
        outputs.commit()
    assert not (tmp_path / "a.txt").exists()
    outputs = OutputSet()
    write_text(tmp_path / "a.txt", "a", outputs)
    outputs.commit()
    with pytest.raises(RuntimeError, match="once"):
        outputs.commit()


def test_an_added_path_is_checked_like_a_planned_one(tmp_path):
    (tmp_path / "in.csv").write_text("x\n")
    os.link(tmp_path / "in.csv", tmp_path / "hard.csv")
    outputs = OutputSet(inputs=[tmp_path / "in.csv", None])
    with pytest.raises(OutputFileError, match="hard.csv: output would overwrite"):
        write_text(tmp_path / "hard.csv", "y", outputs)
    write_text(tmp_path / "a.txt", "a", outputs)
    with pytest.raises(OutputFileError, match="name the same file"):
        write_text(tmp_path / "a.txt", "b", outputs)


# ---------------------------------------------------------------- spreadsheets
@given(st.text(alphabet=["'", "=", "+", "-", "@", "\t", "\r", "a", "1", " "]))
def test_escaping_is_undone_exactly_and_never_leaves_a_formula(text):
    escaped = escape_formula(text)
    assert unescape_formula(escaped) == text
    assert escaped[:1] not in FORMULA_STARTS


def test_only_text_cells_are_quoted():
    frame = pd.DataFrame(
        {
            "point": pd.array(["-2", "P1", None], dtype="string"),
            "note": ["=1+1", 3, None],  # object: only the str value changes
            "vi_z_mps": [-2.5, -1.0, float("nan")],
            "tree_strike": pd.array([True, False, None], dtype="boolean"),
        }
    )
    safe = escape_formulas(frame)
    assert safe["point"].tolist()[:2] == ["'-2", "P1"] and pd.isna(safe["point"][2])
    assert safe["note"].tolist()[:2] == ["'=1+1", 3]
    pd.testing.assert_series_equal(safe["vi_z_mps"], frame["vi_z_mps"])
    pd.testing.assert_series_equal(safe["tree_strike"], frame["tree_strike"])
    back = unescape_formulas(safe)
    pd.testing.assert_frame_equal(back, frame)


@pytest.mark.parametrize("suffix", [".csv", ".xlsx", ".parquet"])
def test_impact_table_round_trip_keeps_formula_like_names(tmp_path, suffix):
    names = ['=HYPERLINK("x")', "+1", "-2", "@SUM(A1)", "'=x", "'plain", "\tP"]
    n = len(names)
    table = ImpactTable(
        pd.DataFrame(
            {
                "path_id": ["=A1"] * n,
                "point": names,
                "material": ["-rock"] * n,
                "x_m": range(n),
                "z_m": [-1.0] * n,
                "slope_deg": [-30.0] * n,
                "vi_x_mps": [1.0] * n,
                "vi_z_mps": [-2.0] * n,
                "vf_x_mps": [1.0] * n,
                "vf_z_mps": [1.0] * n,
            }
        )
    )
    path = table.write(tmp_path / f"t{suffix}")
    back = ImpactTable.read(path).frame
    assert back["point"].tolist() == names
    assert set(back["path_id"]) == {"=A1"} and set(back["material"]) == {"-rock"}
    assert back["z_m"].tolist() == [-1.0] * n


@given(st.lists(st.lists(st.text(), min_size=1, max_size=4), min_size=1, max_size=5))
def test_csv_text_reads_back_cell_for_cell(rows):
    import csv
    import io

    from fieldkit.outputs import csv_text

    back = list(csv.reader(io.StringIO(csv_text(rows), newline="")))
    expected = []
    for row in rows:
        cells = []
        for cell in row:
            try:
                float(cell)
                cells.append(cell)
            except ValueError:
                cells.append(escape_formula(cell))
        expected.append(cells)
    # the csv module writes a row of one empty cell as an empty line, read back as []
    assert [r or [""] for r in back] == expected
    for read, written in zip(back, rows, strict=True):
        if read:
            assert [unescape_formula(c) for c in read] == written


def test_add_inputs_checks_outputs_planned_before(tmp_path):
    read_late = tmp_path / "profile.csv"
    read_late.write_text("x\n")
    outputs = OutputSet()
    outputs.plan(tmp_path / "other.json")
    outputs.plan(read_late)
    with pytest.raises(OutputFileError, match="would overwrite an input"):
        outputs.add_inputs([read_late])


def test_confine_refuses_a_link_out_but_not_a_file_in(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / "link.txt").symlink_to(tmp_path / "elsewhere.txt")
    (tmp_path / "beside.txt").symlink_to(tmp_path / "elsewhere.txt")
    outputs = OutputSet()
    outputs.confine(folder)
    outputs.plan(folder / "plain.txt")
    outputs.plan(tmp_path / "beside.txt")  # not in the folder: a link is followed
    with pytest.raises(OutputFileError, match="symbolic link .* outside"):
        outputs.plan(folder / "link.txt")
