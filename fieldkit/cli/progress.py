"""What a command shows while it works, and what it wrote.

Every step that can take more than about five seconds runs inside :func:`step`: on a
terminal it shows a transient rich progress line on stderr (a bar with a count and
the time left when the total is known, a spinner with the elapsed time otherwise);
in a log or a pipe it prints the step's description once, on stderr, so a long
silence always has a name. :func:`report_written` prints one ``wrote <path>`` line
per file a command committed, on stdout.

Examples
--------
>>> with step("counting", total=3) as advance:
...     for i in range(3):
...         advance(i + 1, 3)
>>> report_written([])
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import typer

#: ``advance(done, total)``: report progress within a step.
Advance = Callable[[int, int], None]


def _on_terminal() -> bool:
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


@contextlib.contextmanager
def step(
    description: str, total: int | None = None, *, announce: bool = True
) -> Iterator[Advance]:
    """Show progress for one step of a command.

    Parameters
    ----------
    description
        What the step does, in words ("simulating 2,000 rocks").
    total
        Units of work when known (a bar with a count and the time left); ``None``
        for a spinner with the elapsed time.
    announce
        Off a terminal, print ``description ...`` once on stderr (default). Steps
        known to be short may pass ``False``.

    Yields
    ------
    advance
        ``advance(done, total)`` to move the bar; harmless to call off a terminal.
    """
    if not _on_terminal():
        if announce:
            typer.echo(f"{description} ...", err=True)
        yield lambda done, of: None
        return
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        SpinnerColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = [SpinnerColumn(), TextColumn("{task.description}")]
    if total is not None:
        columns += [BarColumn(), MofNCompleteColumn(), TimeRemainingColumn()]
    else:
        columns += [TimeElapsedColumn()]
    with Progress(*columns, console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task(description, total=total)

        def advance(done: int, of: int) -> None:
            bar.update(task, completed=done, total=of)

        yield advance


def report_written(paths: Iterable[Path | str]) -> None:
    """Print ``wrote <path>`` for every file written (stdout, one line each)."""
    for path in paths:
        typer.echo(f"wrote {path}")
