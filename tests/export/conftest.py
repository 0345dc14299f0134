"""Shared fixtures of the export tests: the thesis's Table 7-1 model, and grids
written and read back as a user's GIS would."""

from __future__ import annotations

import pytest

from fieldkit.io.dem import read_dem
from fieldkit.model.model_file import read_model


@pytest.fixture(scope="module")
def tornado(repo):
    """Tornado Mountain's Table 7-1 model (two materials, rock and colluvium)."""
    return read_model(repo / "surveys/tornado_mountain/model_rocfall_table_7_1.json")


@pytest.fixture(scope="session")
def written_grids():
    """``write(export, folder)``: every file of ``export`` written into ``folder``
    and read back with :func:`fieldkit.io.dem.read_dem` ({name: DemGrid})."""

    def write(export, folder):
        for name, text in export.files.items():
            (folder / name).write_text(text)
        return {name: read_dem(folder / name) for name in export.files}

    return write
