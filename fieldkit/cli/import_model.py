"""`fieldkit import-model`: another simulator's inputs -> a fieldkit model file.

Glue only: RocFall's material, rock-type and project-settings blocks and its slope
(:mod:`fieldkit.export.rocfall_import`) read into a model file a calibration can
start from; every default the RocFall files do not fix is printed.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import note, one_line_errors
from fieldkit.cli.progress import report_written
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet

FLAGS = {
    "source": "--from",
    "output": "-o",
    "folder": "FOLDER",
    "radius_m": "--radius",
}
#: RocFall files in a folder, as `fieldkit export --to rocfall` writes them.
ROCFALL_FILES = {
    "materials": "materials.txt",
    "slope": "slope.csv",
    "rock_type": "rock_type.txt",
    "settings": "project_settings.txt",
}


@one_line_errors(flags=FLAGS)
def import_model(
    folder: Annotated[
        Path,
        typer.Argument(
            help="Folder with materials.txt, slope.csv, rock_type.txt and "
            "(optional) project_settings.txt."
        ),
    ],
    source: Annotated[
        str, typer.Option("--from", help="The simulator: rocfall.")
    ] = "rocfall",
    output: Annotated[
        Path, typer.Option("-o", help="The fieldkit model file to write.")
    ] = Path("model.json"),
    radius: Annotated[
        float | None,
        typer.Option(
            "--radius",
            help="Block radius [m] (RocFall has none; default a 2650 kg/m3 sphere).",
        ),
    ] = None,
) -> None:
    """Read a RocFall model (materials, rock type, settings, slope) into fieldkit.

    The files are RocFall's input blocks as `fieldkit export --to rocfall` writes
    them (distributions as `id, mean, sd, relative min, relative max`), or the same
    typed by hand from a RocFall project. What RocFall does not fix (block radius,
    gyration, the simulator's core settings) is set to stated defaults, printed.

    Example (from the repository root):

        fieldkit export surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --to rocfall -o out/rocfall --force
        fieldkit import-model out/rocfall --from rocfall -o out/from_rocfall.json
    """
    from fieldkit.export.rocfall_import import read_rocfall
    from fieldkit.model.model_file import write_model

    if source != "rocfall":
        raise ArgumentError(
            f"unknown source {source!r} (known: rocfall)", source="source"
        )
    if not folder.is_dir():
        raise ArgumentError(f"{folder} is not a folder", source="folder")
    paths = {key: folder / name for key, name in ROCFALL_FILES.items()}
    settings = paths.pop("settings")
    for path in paths.values():
        if not path.is_file():
            raise ArgumentError(
                f"{path} missing (a RocFall folder holds "
                f"{', '.join(ROCFALL_FILES.values())})",
                source="folder",
            )
    inputs = [*paths.values()] + ([settings] if settings.is_file() else [])
    with OutputSet(inputs=inputs) as outputs:
        outputs.plan(output, argument="-o")
        model, notes = read_rocfall(
            paths["materials"],
            paths["slope"],
            rock_type=paths["rock_type"],
            settings=settings if settings.is_file() else None,
            radius_m=radius,
        )
        provenance = {**model.provenance, "import": {"from": source,
                                                    "folder": str(folder),
                                                    "notes": notes}}  # fmt: skip
        write_model(replace(model, provenance=provenance), output, outputs=outputs)
        written = outputs.commit()
    for line in notes:
        note(line)
    report_written(written)
    typer.echo(
        f"{len(model.materials)} materials, {len(model.profile.x_m)} slope vertices "
        f"-> {output}"
    )
