"""When the reduce summary gives the impact-mechanics median, and why not."""

from __future__ import annotations

import numpy as np
import pandas as pd

from fieldkit.impact_table import ImpactTable
from fieldkit.reduce.summary import (
    THEORY_MIN_IMPACTS,
    format_summary,
    summarize,
    theory_verdict,
)


def test_each_reason_is_given():
    lost = np.full(8, -1.0)
    assert theory_verdict(np.full(8, 0.2), lost, 8) is None
    few = theory_verdict(np.full(THEORY_MIN_IMPACTS - 1, 0.2), lost[:4], 4)
    assert few.startswith("only 4 impacts lost kinetic energy")
    gained = theory_verdict(np.full(5, 0.2), np.array([-1.0] * 5 + [1.0] * 3), 8)
    assert gained.startswith("kinetic energy was gained at 3 of 8 impacts")
    scattered = theory_verdict(np.array([0.2, 0.2, 0.2, -3.0, 1.5, 0.25]), lost, 8)
    assert scattered.startswith("at 2 of the 6 impacts that lost kinetic energy")
    assert "from -300 % to 150 %" in scattered
    # at the limit (a quarter outside) the median still stands
    assert theory_verdict(np.array([0.2] * 6 + [-1.0, 2.0]), lost, 8) is None


def _table(fractions, dke):
    n = len(fractions)
    return ImpactTable(
        pd.DataFrame(
            {
                "path_id": "p",
                "point": [str(i) for i in range(n)],
                "x_m": np.arange(n, dtype=float),
                "z_m": -np.arange(n, dtype=float),
                "slope_deg": 30.0,
                "vi_x_mps": 5.0,
                "vi_z_mps": -8.0,
                "vf_x_mps": 4.0,
                "vf_z_mps": 2.0,
                "mass_kg": 10.0,
                "dke_j": dke,
                "theory_loss_fraction": fractions,
            }
        )
    ).derive()


def test_the_printed_line_follows_the_verdict():
    fine = format_summary(summarize(_table([0.2, 0.3, 0.25, 0.2, 0.3, 0.1], -1.0)))
    assert "explains a median 22 % (quartiles 20-29 %)" in fine
    assert "median over the 6 of 6 impacts that lost kinetic energy" in fine
    few = format_summary(summarize(_table([0.2, 0.3], -1.0)))
    assert "no median given, only 2 impacts" in few and "explains" not in few
    none = format_summary(summarize(_table([np.nan, np.nan], -1.0)))
    assert "impact mechanics" not in none  # no theory values, nothing to say
