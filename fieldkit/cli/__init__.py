"""The ``fieldkit`` command line: one typer app, one module per command.

Each command module defines a single function decorated with
:func:`fieldkit.cli.common.one_line_errors`; this module registers them, and
:func:`main` (the console script) makes usage errors one line as well.
"""

from __future__ import annotations

import sys
from typing import Annotated

import typer

from fieldkit._version import __version__
from fieldkit.cli import (
    diagnose,
    effects,
    export,
    fence,
    fit,
    impact,
    import_model,
    profile,
    reduce,
    simulate,
    synth,
    track,
    view,
)

app = typer.Typer(
    name="fieldkit",
    help="Rockfall engineering: field and video measurements -> impact physics.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"fieldkit {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            callback=_print_version,
            is_eager=True,
            help="Print the version and exit.",
        ),
    ] = False,
) -> None:
    pass


app.command("reduce")(reduce.reduce)
app.command("impact")(impact.impact)
app.command("fence")(fence.fence)
app.command("track")(track.track)
app.command("view")(view.view)
app.command("profile")(profile.profile)
app.command("simulate")(simulate.simulate)
app.command("effects")(effects.effects)
app.command("synth")(synth.synth)
app.command("fit")(fit.fit)
app.command("diagnose")(diagnose.diagnose)
app.command("export")(export.export)
app.command("import-model")(import_model.import_model)

# typer bundles its own click; reach its base exception through a public class.
_USAGE_ERRORS = next(
    c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException"
)


def main(argv: list[str] | None = None) -> None:
    """Console entry point: like ``app()``, but a usage error is one line on stderr.

    ``fieldkit reduce --theta0 abc`` prints ``error: fieldkit reduce: Invalid value
    for '--theta0': ...`` and exits 2 (typer's default is a framed box).
    """
    args = sys.argv[1:] if argv is None else list(argv)
    if not args:
        args = ["--help"]
    try:
        code = app(args=args, prog_name="fieldkit", standalone_mode=False)
    except _USAGE_ERRORS as exc:
        command = " ".join(["fieldkit", *args[:1]]) if args[:1] else "fieldkit"
        message = " ".join(exc.format_message().split())
        typer.echo(f"error: {command}: {message} (see --help)", err=True)
        sys.exit(exc.exit_code)
    except typer.Abort:
        typer.echo("error: aborted", err=True)
        sys.exit(1)
    sys.exit(code if isinstance(code, int) else 0)
