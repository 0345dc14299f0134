"""The ``fieldkit`` command line: one typer app, one module per command.

Each command module defines a single function decorated with
:func:`fieldkit.cli.common.one_line_errors`; this module only registers them.
"""

from __future__ import annotations

import typer

from fieldkit.cli import fence, impact, reduce, track, view

app = typer.Typer(
    name="fieldkit",
    help="Rockfall engineering: field and video measurements -> impact physics.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

app.command("reduce")(reduce.reduce)
app.command("impact")(impact.impact)
app.command("fence")(fence.fence)
app.command("track")(track.track)
app.command("view")(view.view)
