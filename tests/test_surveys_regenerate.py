"""surveys/make_surveys.py regenerates every committed survey file byte for byte."""

from __future__ import annotations

import importlib.util


def test_make_surveys_reproduces_the_committed_files(repo, monkeypatch):
    spec = importlib.util.spec_from_file_location(
        "make_surveys", repo / "surveys" / "make_surveys.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    written = {}
    monkeypatch.setattr(
        module, "write", lambda path, text: written.update({path: text})
    )
    module.main()
    assert len(written) == 14
    for path, text in written.items():
        assert path.read_bytes() == text.encode("utf-8"), path
    book = repo / "surveys" / "tornado_mountain" / "boulder_a_fieldbook.csv"
    assert book.read_text().splitlines()[0].split(",")[4] == "azimuth_reference"
