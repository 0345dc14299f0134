"""The ``fieldkit`` command line: one typer app, one module per command.

Each command module defines a single function decorated with
:func:`fieldkit.cli.common.one_line_errors`; this module registers them, and
:func:`main` (the console script) makes usage errors one line as well.

Termination
-----------
``SIGTERM`` (a timeout, a CI job cancelled, ``docker stop``, ``kill``), ``SIGHUP``
(the terminal closed) and ``SIGINT`` (Ctrl-C) end a command one way: :func:`main`
turns them into a :class:`Terminated` exception, so every
:class:`~fieldkit.outputs.OutputSet` unwinds -- a streamed temporary file and the
folders made for it are removed, files already there are left as they were -- then
prints ``error: terminated by SIGTERM`` (``interrupted by SIGINT``) and exits with
``128 + signal`` (143, 129, 130), as a shell reports a process killed by that signal.
A second signal while unwinding is ignored so the cleanup finishes. ``kill -9``
cannot be caught (see :mod:`fieldkit.outputs`).
"""

from __future__ import annotations

import signal
import sys
import threading
from typing import Annotated

import typer

from fieldkit._version import __version__
from fieldkit.cli import (
    corridor,
    diagnose,
    effects,
    export,
    fence,
    fit,
    impact,
    import_model,
    import_results,
    lens,
    profile,
    reduce,
    simulate,
    synth,
    track,
    track3d,
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
app.command("track3d")(track3d.track3d)
app.command("lens")(lens.lens)
app.command("view")(view.view)
app.command("profile")(profile.profile)
app.command("simulate")(simulate.simulate)
app.command("effects")(effects.effects)
app.command("synth")(synth.synth)
app.command("fit")(fit.fit)
app.command("diagnose")(diagnose.diagnose)
app.command("corridor")(corridor.corridor)
app.command("export")(export.export)
app.command("import-model")(import_model.import_model)
app.command("import-results")(import_results.import_results)

# typer bundles its own click; reach its base exception through a public class.
_USAGE_ERRORS = next(
    c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException"
)


#: Signals that end a command like Ctrl-C (module docstring, "Termination").
TERMINATING_SIGNALS = (signal.SIGTERM, signal.SIGHUP, signal.SIGINT)


class Terminated(BaseException):  # noqa: N818 -- named for what happened, as SystemExit
    """A terminating signal arrived (not an ``Exception``: nothing may swallow it).

    Parameters
    ----------
    signum
        The signal's number.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _terminate(signum: int, frame: object) -> None:
    for other in TERMINATING_SIGNALS:  # let the unwinding finish
        signal.signal(other, signal.SIG_IGN)
    raise Terminated(signum)


def main(argv: list[str] | None = None) -> None:
    """Console entry point: like ``app()``, but a usage error is one line on stderr.

    ``fieldkit reduce --theta0 abc`` prints ``error: fieldkit reduce: Invalid value
    for '--theta0': ...`` and exits 2 (typer's default is a framed box). SIGTERM and
    SIGHUP unwind the command like Ctrl-C (module docstring, "Termination").
    """
    args = sys.argv[1:] if argv is None else list(argv)
    if not args:
        args = ["--help"]
    previous = {}
    if threading.current_thread() is threading.main_thread():
        previous = {s: signal.signal(s, _terminate) for s in TERMINATING_SIGNALS}
    try:
        _run(args)
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _run(args: list[str]) -> None:
    try:
        code = app(args=args, prog_name="fieldkit", standalone_mode=False)
    except Terminated as exc:
        name = signal.Signals(exc.signum).name
        how = "interrupted" if exc.signum == signal.SIGINT else "terminated"
        typer.echo(f"error: {how} by {name}; unfinished outputs were removed", err=True)
        sys.exit(128 + exc.signum)
    except _USAGE_ERRORS as exc:
        command = " ".join(["fieldkit", *args[:1]]) if args[:1] else "fieldkit"
        message = " ".join(exc.format_message().split())
        typer.echo(f"error: {command}: {message} (see --help)", err=True)
        sys.exit(exc.exit_code)
    except typer.Abort:
        typer.echo("error: aborted", err=True)
        sys.exit(1)
    sys.exit(code if isinstance(code, int) else 0)
