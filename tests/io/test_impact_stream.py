"""Streamed outputs: OutputSet.stream and the chunked ImpactTable writer."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fieldkit.errors import ArgumentError, OutputFileError
from fieldkit.impact_table import ImpactTable
from fieldkit.io.impact_stream import ImpactStreamWriter, stream_format
from fieldkit.outputs import OutputSet, write_text


def _chunk(first_rock: int, rocks: int, impacts: int = 3) -> ImpactTable:
    rng = np.random.default_rng(first_rock)
    n = rocks * impacts
    return ImpactTable(
        pd.DataFrame(
            {
                "path_id": np.repeat(
                    np.arange(first_rock, first_rock + rocks), impacts
                ).astype(str),
                "point": np.tile(np.arange(1, impacts + 1), rocks).astype(str),
                "x_m": rng.uniform(0, 100, n),
                "z_m": rng.uniform(0, 50, n),
                "slope_deg": rng.uniform(10, 40, n),
                "material": np.where(rng.random(n) < 0.5, "=rock", "talus"),
                "mass_kg": 1000.0,
                "vi_x_mps": rng.normal(5, 1, n),
                "vi_z_mps": -rng.uniform(1, 10, n),
                "vf_x_mps": rng.normal(4, 1, n),
                "vf_z_mps": rng.uniform(0.5, 3, n),
                "t_s": rng.uniform(0, 20, n),
                "tree_strike": rng.random(n) < 0.1,
            }
        )
    ).derive()


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_chunks_stream_into_one_table_that_reads_back_equal(tmp_path, suffix):
    target = tmp_path / "out" / f"impacts{suffix}"
    chunks = [_chunk(0, 4), _chunk(4, 5), _chunk(9, 2)]
    with OutputSet() as outputs:
        tmp = outputs.stream(target, argument="impacts")
        assert tmp.parent == target.parent and not target.exists()
        with ImpactStreamWriter(tmp, stream_format(target)) as writer:
            for chunk in chunks:
                writer.write(chunk)
        outputs.commit()
    assert writer.rows == 33
    back = ImpactTable.read(target).frame
    whole = pd.concat([c.frame for c in chunks], ignore_index=True)
    assert back["path_id"].tolist() == whole["path_id"].tolist()
    assert back["material"].tolist() == whole["material"].tolist()  # '=rock' kept
    assert back["tree_strike"].tolist() == whole["tree_strike"].tolist()
    for name in ("x_m", "vi_z_mps", "e_n", "ke_i_j", "t_s"):
        np.testing.assert_array_equal(back[name].to_numpy(), whole[name].to_numpy())
    if suffix == ".csv":  # formula-like text is escaped, as ImpactTable.write does
        assert "'=rock" in target.read_text()
    assert [p.name for p in target.parent.iterdir()] == [target.name]


def test_a_failure_before_commit_leaves_nothing(tmp_path):
    target = tmp_path / "new" / "deeper" / "impacts.csv"
    with pytest.raises(RuntimeError), OutputSet() as outputs:
        tmp = outputs.stream(target)
        write_text(tmp_path / "summary.json", "{}", outputs)
        tmp.write_text("half a file")
        raise RuntimeError("the simulation failed")
    assert not (tmp_path / "new").exists()
    assert sorted(tmp_path.iterdir()) == []


def test_stream_replaces_an_existing_file_only_at_commit(tmp_path):
    target = tmp_path / "impacts.csv"
    target.write_text("old\n")
    outputs = OutputSet()
    tmp = outputs.stream(target)
    tmp.write_text("new\n")
    assert target.read_text() == "old\n"
    outputs.commit()
    assert target.read_text() == "new\n" and not tmp.exists()


def test_stream_is_checked_like_a_planned_output(tmp_path):
    source = tmp_path / "model.json"
    source.write_text("{}")
    outputs = OutputSet(inputs=[source])
    with pytest.raises(OutputFileError, match="overwrite an input"):
        outputs.stream(source)
    outputs.abort()
    assert source.read_text() == "{}"


def test_stream_format_refuses_xlsx():
    with pytest.raises(ArgumentError, match=r"\.csv or \.parquet"):
        stream_format("a.xlsx", "impacts_path")
