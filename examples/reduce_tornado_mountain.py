"""Walk-through: a mapped rockfall -> per-impact physics (thesis §2.2.2, Table 2-4).

Tornado Mountain boulder A was mapped with GPS and a laser rangefinder: 46 impact
points and 21 broken trees. This script does with the Python API what
``fieldkit reduce`` does on the command line:

1. read the GPS waypoints and the tree strikes,
2. solve every flight (a tree strike fixes its parabola exactly; other flights use the
   site's mean restitution angle; it, the body and the path id are boulder A's preset,
   ``surveys/tornado_mountain/boulder_a_preset.toml``, as ``fieldkit reduce --preset``
   reads them),
3. look at impact #26, the one the thesis details in Fig. 2.8,
4. write the ImpactTable and the section figure.

Run:  python examples/reduce_tornado_mountain.py [OUT_DIR]
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from fieldkit.io.impacts import read_impacts
from fieldkit.io.preset import read_preset
from fieldkit.io.trees import read_trees
from fieldkit.physics.bodies import resolve_body
from fieldkit.reduce.pipeline import ReduceOptions, reduce_path
from fieldkit.reduce.summary import format_summary, summarize
from fieldkit.survey import Survey
from fieldkit.viz.section_figure import write_section_figure

SURVEY = Path(__file__).resolve().parents[1] / "surveys" / "tornado_mountain"


def main(out_dir: Path) -> None:
    points = read_impacts(SURVEY / "boulder_a_impacts.gpx")
    trees = read_trees(SURVEY / "boulder_a_trees.csv", points)
    print(f"{len(points.frame)} points, {len(trees.frame)} tree strikes")
    print(f"heights: {points.height_reference}")

    preset = read_preset(SURVEY / "boulder_a_preset.toml")
    options = ReduceOptions(
        path_id=preset.reduce["path_id"],
        theta0_deg=preset.reduce["theta0_deg"],
        body=resolve_body(**preset.body()),
    )
    reduction = reduce_path(Survey(points, trees), options)
    table = reduction.table  # e_n_sd etc. from the default position error, stated:
    print(format_summary(summarize(table, reduction.uncertainty)))

    row = table.frame.set_index("point").loc["26"]
    print(
        "impact 26 (thesis Fig. 2.8: theta_i 22, e_N 1.29, e_T 0.27): "
        f"theta_i {row['theta_i_deg']:.1f}, e_N {row['e_n']:.2f}, "
        f"e_T {row['e_t']:.2f}; theta_f {row['theta_f_deg']:.1f} deg from a "
        f"{row['theta0_source']} strike on the flight leaving it"
    )
    out_dir.mkdir(parents=True, exist_ok=True)
    table.write(out_dir / "boulder_a.csv")
    write_section_figure(table, out_dir / "section.png", survey=Survey(points, trees))
    print(f"wrote {out_dir / 'boulder_a.csv'} and {out_dir / 'section.png'}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()))
