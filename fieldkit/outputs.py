"""Output files: planned, checked against the inputs, written all or nothing.

Every file a command writes goes through one :class:`OutputSet`:

1. **Plan** each output path as soon as the arguments are known
   (:meth:`OutputSet.plan`). A path that is the same file as an input -- the same
   path, a symbolic link to it, or a hard link (same device and inode) -- or as
   another output is refused at once, as are a folder, a path below a file, a name
   longer than the file system allows, a socket, a block device and a folder that
   cannot be written.
2. **Compute** everything, then **add** each file's writer (:meth:`OutputSet.add`,
   or the ``outputs=`` argument every file writer takes: ``ImpactTable.write``,
   ``Track.write``, ``fieldkit.viz.figure_files.save_png``, the rerun recordings).
   Nothing is written yet; an added path is checked like a planned one.
3. **Commit** (:meth:`OutputSet.commit`): every writer writes a temporary file, then
   the temporary files are renamed over their targets, in the order they were added.

What "together" guarantees
--------------------------
* If a writer fails, a rename fails or the command is interrupted (any exception,
  ``KeyboardInterrupt`` too), every output is left as it was before the command: new
  files and the folders made for them are removed, files that existed are restored
  (each is kept as a hard link until the end), no temporary file remains.
* Each file is replaced by one ``rename``: a reader sees the old file or the new one,
  never a part of it.
* Not guaranteed: the set is not atomic against a crash, a power cut or ``kill -9``
  during the renames (a few milliseconds at the end); then some files are new, some
  old, and backups ``.fk-XXXXXXXX.bak`` may remain beside them.

Files written during the computation (streamed)
-----------------------------------------------
An output too large to hold in memory (a simulation's impacts) is written while it
is computed: :meth:`OutputSet.stream` plans the path and returns a temporary file
beside it, which the caller fills progressively; :meth:`OutputSet.commit` renames it
into place with the others. If the command fails before the commit, :meth:`abort`
(or leaving ``with OutputSet(...) as outputs:`` by an exception) removes it and the
folders made for it, so nothing partial remains.

Targets that are not regular files
----------------------------------
A FIFO or a character device (``/dev/null``, a terminal) is *written through*: opened
and written in place, never renamed over (a FIFO still is a FIFO afterwards). What
went into it cannot be taken back, so these are written after every regular file is
in place; if writing one fails, the regular files are restored all the same. A socket
or a block device is refused. A symbolic link is followed: the file it points to is
replaced and the link stays a link; a link to an input is refused like the input.

Outputs confined to a folder
----------------------------
A command that writes a set of files *into* a folder (``export -o DIR``,
``--figures DIR``, ``--report DIR``) declares it with :meth:`OutputSet.confine`: every
output planned under DIR must then be written inside DIR. A path under DIR that
resolves outside it -- a symbolic link in DIR (or a linked sub-folder) pointing
elsewhere -- is **refused**, naming the link (``DIR/slope.csv: is a symbolic link to
/etc/x, outside DIR; remove it or write elsewhere``): following it would replace a
file the user never named, and silently replacing the link by a file would destroy
what the user set up. DIR itself may be a link (the user named it).

Inputs known late
-----------------
Some inputs are only known once a file is read (the profile CSV or DEM a model file
names). :meth:`OutputSet.add_inputs` adds them and checks every output planned so far
against them, so a command plans its outputs first and still never replaces a file
it read (``fieldkit.model.model_file.read_model(path, outputs=...)`` does this for
every file a model reads).

File-system errors (permission denied, read-only file system, no space left on the
device, ...) raise :class:`~fieldkit.errors.OutputFileError` naming the output path
(``out/x.csv: permission denied``). A new file gets the usual permissions, ``0o666``
less the umask, not the private mode of a temporary file. Temporary files have short
names (``.fk-XXXXXXXX.csv``) in the target's own folder, so any target name that fits
the file system has a temporary name that fits.

JSON files
----------
Every JSON file fieldkit writes goes through :func:`write_json` (text by
:func:`json_text`): numpy numbers and arrays become JSON numbers and lists, and a
number that is not finite (NaN, +-Infinity) becomes ``null`` -- JSON has no literal
for it (``NaN`` is not JSON; strict readers refuse the file). ``allow_nan=False``
makes any slip an error instead of an invalid file.

Spreadsheet safety
------------------
A text cell that begins with ``=``, ``+``, ``-``, ``@``, a tab or a carriage return is
run as a formula by a spreadsheet (CSV injection). :func:`protect_formula_cells` keeps
such cells as text in an XLSX sheet (string type, quote prefix: the value is kept
verbatim). In a CSV meant for spreadsheets (the ImpactTable CSV) :func:`escape_formulas`
prefixes them with a single quote ``'``, and :func:`unescape_formulas` removes exactly
that prefix when the file is read back, so a round trip is lossless. Only text cells
are touched: a column of numbers (``-2.5``) is never quoted. Small CSV files written
as text (exports) go through :func:`csv_text`: the csv module quotes commas, quotes
and line breaks, and :func:`escape_formula` protects text cells.

Examples
--------
>>> import tempfile
>>> folder = Path(tempfile.mkdtemp())
>>> (folder / "in.csv").write_text("x\\n1\\n")
4
>>> outputs = OutputSet(inputs=[folder / "in.csv"])
>>> outputs.plan(folder / "in.csv")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
fieldkit.errors.OutputFileError: ...in.csv: output would overwrite an input file
>>> table = outputs.plan(folder / "out" / "table.csv")
>>> # ... compute, then give each planned file its writer ...
>>> _ = outputs.add(table, lambda tmp: tmp.write_text("x\\n2\\n"))
>>> _ = write_text(folder / "out" / "note.txt", "done\\n", outputs)
>>> [p.name for p in outputs.commit()]
['table.csv', 'note.txt']
>>> sorted(p.name for p in (folder / "out").iterdir())
['note.txt', 'table.csv']
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from fieldkit.errors import OutputFileError

if TYPE_CHECKING:
    import pandas as pd

#: A file writer: writes the whole file at the (temporary) path it is given.
Writer = Callable[[Path], object]

PathArg = str | os.PathLike[str]

#: Temporary and backup files are ``.fk-`` + 8 hex digits + a short suffix.
_TEMP_PREFIX = ".fk-"
#: A target's suffix is kept on its temporary file (writers such as pandas' Excel
#: writer choose the format from it) when it is at most this long.
_MAX_TEMP_SUFFIX = 16
#: NAME_MAX where the file system does not say.
_NAME_MAX = 255

_REASONS: dict[int, str] = {
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EROFS: "read-only file system",
    errno.ENOSPC: "no space left on device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EFBIG: "file too large",
    errno.EISDIR: "is a directory",
    errno.ENOTDIR: "a folder in the path is a file",
    errno.ENAMETOOLONG: "file name too long",
    errno.EPIPE: "nothing is reading from it (broken pipe)",
}


def describe_os_error(exc: OSError) -> str:
    """A short lower-case reason for a file-system error, without the path.

    Examples
    --------
    >>> describe_os_error(PermissionError(errno.EACCES, "Permission denied", "x"))
    'permission denied'
    >>> describe_os_error(OSError(errno.ENOSPC, "No space left on device"))
    'no space left on device'
    """
    if exc.errno in _REASONS:
        return _REASONS[exc.errno]
    return (exc.strerror or str(exc) or type(exc).__name__).lower()


# ---------------------------------------------------------------- file identity
_Identity = tuple[str, tuple[int, int] | None]


def _identity(path: PathArg) -> _Identity:
    """The resolved path, and (st_dev, st_ino) when the file exists."""
    real = os.path.realpath(path)
    try:
        st = os.stat(real)
    except (OSError, ValueError):
        return real, None
    return real, (st.st_dev, st.st_ino)


def _same_file(a: _Identity, b: _Identity) -> bool:
    return a[0] == b[0] or (a[1] is not None and a[1] == b[1])


def _stat(path: PathArg) -> os.stat_result | None:
    try:
        return os.stat(path)
    except FileNotFoundError:
        return None


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


# ---------------------------------------------------------------- the set
@dataclass
class _Output:
    path: Path  # as the caller gave it (used in messages)
    real: Path  # symbolic links resolved: the file that is replaced
    identity: _Identity
    label: str | None
    write: Writer | None = None
    tmp: Path | None = None
    backup: Path | None = None
    through: bool = False  # written in place (FIFO, character device)
    placed: bool = False  # renamed into place
    streamed: bool = False  # tmp filled by the caller before commit (stream)


class OutputSet:
    """The files one command writes: planned first, written together at the end.

    Parameters
    ----------
    inputs
        Every file the command reads (``None`` entries are skipped). No output may
        be the same file as one of them.

    Notes
    -----
    See the module documentation for what :meth:`commit` guarantees, for targets
    that are not regular files, and for the errors raised. An :class:`OutputSet`
    commits once.
    """

    def __init__(self, inputs: Iterable[PathArg | None] = ()) -> None:
        self._inputs = [(Path(p), _identity(p)) for p in inputs if p is not None]
        self._outputs: list[_Output] = []
        self._committed = False
        self._created: list[Path] = []  # folders made before commit (stream)
        self._folders: list[Path] = []  # outputs under these stay inside them

    def confine(self, folder: PathArg | None) -> None:
        """Declare ``folder`` a folder of outputs (``None`` skipped): every output
        planned under it must be written inside it (module docstring, "Outputs
        confined to a folder"); a symbolic link there that leads out is refused."""
        if folder is not None:
            self._folders.append(Path(folder))

    def __enter__(self) -> OutputSet:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is not None:
            self.abort()

    @property
    def paths(self) -> list[Path]:
        """The planned paths, in order, as given."""
        return [o.path for o in self._outputs]

    def add_inputs(self, paths: Iterable[PathArg | None]) -> None:
        """Add files the command reads, known only now (``None`` skipped).

        Every output planned so far is checked against them at once.

        Raises
        ------
        OutputFileError
            A planned output is one of ``paths`` (naming the output).
        """
        new = [(Path(p), _identity(p)) for p in paths if p is not None]
        self._inputs.extend(new)
        for out in self._outputs:
            for given, other in new:
                if _same_file(out.identity, other):
                    also = "" if given == out.path else f" ({given})"
                    raise OutputFileError(
                        f"output would overwrite an input file{also}",
                        source=out.path,
                    )

    def plan(self, path: PathArg, *, argument: str | None = None) -> Path:
        """Reserve ``path`` for an output; its writer is added later.

        Parameters
        ----------
        path
            The output file.
        argument
            What named it, for messages: the command line passes its option
            (``"--json"``); without it the path is named.

        Returns
        -------
        Path
            ``path``.

        Raises
        ------
        OutputFileError
            ``path`` is an input or another output, or cannot be written (a folder,
            below a file, a name too long, a socket or block device, no permission),
            or a symbolic link takes it out of its :meth:`confine` folder.
        """
        target = Path(path)
        identity = _identity(target)
        for folder in self._folders:
            if folder in target.parents:
                _refuse_outside(target, folder)
        self._refuse_inputs(target, identity)
        through = _check_target(target, identity[0])
        for other in self._outputs:
            if _same_file(identity, other.identity) and not (
                through and other.through  # /dev/null twice is harmless
            ):
                names = dict.fromkeys([_name(other.label, other.path)])
                names[_name(argument, target)] = None
                raise OutputFileError(
                    f"{' and '.join(names)} name the same file", source=target
                )
        self._outputs.append(
            _Output(target, Path(identity[0]), identity, argument, through=through)
        )
        return target

    def add(self, path: PathArg, write: Writer, *, argument: str | None = None) -> Path:
        """Give ``path`` its writer (planning it now if it was not planned).

        ``write(tmp)`` must write the whole file at the path ``tmp`` it is given; it
        runs in :meth:`commit`, so what it needs must be computed by then.

        Returns
        -------
        Path
            ``path``.

        Raises
        ------
        OutputFileError
            As :meth:`plan`, or ``path`` already has a writer.
        """
        target = Path(path)
        identity = _identity(target)
        for out in self._outputs:
            if out.write is None and _same_file(identity, out.identity):
                out.write = write
                return target
        self.plan(target, argument=argument)
        self._outputs[-1].write = write
        return target

    def stream(self, path: PathArg, *, argument: str | None = None) -> Path:
        """Plan ``path`` and return a temporary file to write it into now.

        For an output written while it is computed (chunk by chunk): the caller
        opens the returned file, appends to it, closes it before :meth:`commit`,
        which renames it over ``path`` with the other outputs (or copies it into a
        FIFO or device). Nothing else writes it. On failure before the commit call
        :meth:`abort` (or use the set as a context manager), which removes it.

        Returns
        -------
        Path
            The temporary file (empty, in the target's folder, which is created
            now if missing; in the system's temporary folder for a FIFO or device).

        Raises
        ------
        OutputFileError
            As :meth:`plan`, or the temporary file cannot be made.

        Examples
        --------
        >>> import tempfile
        >>> folder = Path(tempfile.mkdtemp())
        >>> with OutputSet() as outputs:
        ...     tmp = outputs.stream(folder / "big.csv")
        ...     with open(tmp, "w") as f:
        ...         for chunk in ("a\\n", "b\\n"):
        ...             _ = f.write(chunk)
        ...     _ = outputs.commit()
        >>> (folder / "big.csv").read_text()
        'a\\nb\\n'
        """
        if self._committed:
            raise RuntimeError("an OutputSet commits once")
        target = self.plan(path, argument=argument)
        out = self._outputs[-1]
        try:
            if out.through:
                fd, tmp = tempfile.mkstemp(
                    prefix="fieldkit-", suffix=_temp_suffix(out.real)
                )
            else:
                _make_folders(out.real.parent, self._created)
                fd, tmp = tempfile.mkstemp(
                    prefix=_TEMP_PREFIX,
                    suffix=_temp_suffix(out.real),
                    dir=out.real.parent,
                )
        except OSError as exc:
            self._outputs.pop()
            raise OutputFileError(describe_os_error(exc), source=target) from None
        os.close(fd)
        out.tmp, out.streamed = Path(tmp), True
        out.write = _streamed
        return out.tmp

    def abort(self) -> None:
        """Give up before :meth:`commit`: remove streamed temporary files and the
        folders made for them. Nothing else has been written. Harmless after a
        commit (then it does nothing)."""
        if self._committed:
            return
        self._committed = True
        for out in self._outputs:
            _remove(out.tmp)
            out.tmp = None
        for folder in reversed(self._created):
            with contextlib.suppress(OSError):
                folder.rmdir()

    def commit(self) -> list[Path]:
        """Write every file: all into temporary files, then all renamed into place.

        Returns
        -------
        list of Path
            The paths written, in order, as given.

        Raises
        ------
        OutputFileError
            A file-system error, naming the output; nothing is left written.
        ValueError
            A planned path was never given a writer (a bug in the command).
        """
        if self._committed:
            raise RuntimeError("an OutputSet commits once")
        unwritten = [str(o.path) for o in self._outputs if o.write is None]
        if unwritten:
            raise ValueError(f"planned outputs without a writer: {unwritten}")
        self._committed = True
        created: list[Path] = self._created
        current: _Output | None = None
        try:
            mode = 0o666 & ~_umask()
            for out in self._outputs:
                current = out
                _stage(out, created, mode)
            for out in self._outputs:
                if not out.through:
                    current = out
                    _place(out)
            for out in self._outputs:
                if out.through:
                    current = out
                    _write_through(out)
        except BaseException as exc:
            self._undo(created)
            if isinstance(exc, OSError) and current is not None:
                raise OutputFileError(
                    describe_os_error(exc), source=current.path
                ) from None
            raise
        for out in self._outputs:
            _remove(out.backup)
            _remove(out.tmp)
        return self.paths

    def _refuse_inputs(self, target: Path, identity: _Identity) -> None:
        for given, other in self._inputs:
            if _same_file(identity, other):
                also = "" if given == target else f" ({given})"
                raise OutputFileError(
                    f"output would overwrite an input file{also}", source=target
                )

    def _undo(self, created: list[Path]) -> None:
        """Put every target back as it was; remove temporaries and new folders."""
        for out in reversed(self._outputs):
            if out.placed:
                try:
                    if out.backup is not None:
                        os.replace(out.backup, out.real)
                        out.backup = None
                    else:
                        os.unlink(out.real)
                except OSError:
                    out.backup = None  # keep the old file where it is
                out.placed = False
            _remove(out.tmp)
            _remove(out.backup)
        for folder in reversed(created):
            with contextlib.suppress(OSError):
                folder.rmdir()


def _refuse_outside(target: Path, folder: Path) -> None:
    """Refuse ``target`` (a path under ``folder``) when links take it outside."""
    root = os.path.realpath(folder)
    real = os.path.realpath(target)
    if os.path.commonpath([root, real]) == root:
        return
    link = target
    for part in [target, *target.parents]:  # the link nearest the file
        if part == folder or part in folder.parents:
            break
        if part.is_symlink():
            link = part
            break
    raise OutputFileError(
        f"is a symbolic link to {os.readlink(link)}, outside {folder}; remove it "
        "or write elsewhere"
        if link.is_symlink()
        else f"lies outside {folder}",
        source=link,
    )


def _name(argument: str | None, path: Path) -> str:
    return argument or str(path)


def _check_target(target: Path, real: str) -> bool:
    """Refuse what cannot be an output; True when the target is written through."""
    name_max = _NAME_MAX
    ancestor = next((p for p in target.parents if os.path.exists(p)), Path("."))
    with contextlib.suppress(OSError, ValueError):
        name_max = os.pathconf(ancestor, "PC_NAME_MAX")
    for part in target.parts:
        if len(os.fsencode(part)) > name_max:
            raise OutputFileError(
                f"file name too long ({len(os.fsencode(part))} bytes, at most "
                f"{name_max})",
                source=target,
            )
    if not ancestor.is_dir():
        raise OutputFileError(f"{ancestor} is a file, not a folder", source=target)
    try:
        st = _stat(real)
    except OSError as exc:
        raise OutputFileError(describe_os_error(exc), source=target) from None
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise OutputFileError("is a directory", source=target)
    if st is not None and not stat.S_ISREG(st.st_mode):
        if not (stat.S_ISFIFO(st.st_mode) or stat.S_ISCHR(st.st_mode)):
            kind = "a socket" if stat.S_ISSOCK(st.st_mode) else "a block device"
            raise OutputFileError(
                f"is {kind}; outputs go to files, FIFOs or character devices",
                source=target,
            )
        if not os.access(real, os.W_OK):
            raise OutputFileError("permission denied", source=target)
        return True
    folder = Path(real).parent
    while not folder.exists():
        folder = folder.parent
    if folder.is_dir() and not os.access(folder, os.W_OK | os.X_OK):
        read_only = False
        with contextlib.suppress(OSError):
            read_only = bool(os.statvfs(folder).f_flag & os.ST_RDONLY)
        reason = "read-only file system" if read_only else "permission denied"
        raise OutputFileError(reason, source=target)
    return False


def _temp_suffix(path: Path) -> str:
    suffix = path.suffix
    return suffix if 0 < len(os.fsencode(suffix)) <= _MAX_TEMP_SUFFIX else ".tmp"


def _make_folders(folder: Path, created: list[Path]) -> None:
    """Create ``folder`` and missing parents, recording each one made."""
    missing = []
    while not folder.exists():
        missing.append(folder)
        folder = folder.parent
    for new in reversed(missing):
        new.mkdir()
        created.append(new)


def _streamed(tmp: Path) -> None:
    """The writer of a streamed output: its file is already written."""


def _stage(out: _Output, created: list[Path], mode: int) -> None:
    """Run the writer into a temporary file (beside the target when renamed)."""
    if out.streamed:  # filled by the caller already
        if not out.through:
            os.chmod(out.tmp, mode)
        return
    st = _stat(out.real)
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(errno.EISDIR, "Is a directory", str(out.path))
    out.through = st is not None and not stat.S_ISREG(st.st_mode)
    if out.through:  # the content goes in place at the end; stage it elsewhere
        fd, tmp = tempfile.mkstemp(prefix="fieldkit-", suffix=_temp_suffix(out.real))
    else:
        _make_folders(out.real.parent, created)
        fd, tmp = tempfile.mkstemp(
            prefix=_TEMP_PREFIX, suffix=_temp_suffix(out.real), dir=out.real.parent
        )
    os.close(fd)
    out.tmp = Path(tmp)
    assert out.write is not None
    out.write(out.tmp)
    if not out.through:
        os.chmod(out.tmp, mode)


def _place(out: _Output) -> None:
    """Rename the temporary file over the target, keeping the old one as a backup."""
    if os.path.lexists(out.real):
        out.backup = _backup(out.real)
    assert out.tmp is not None
    os.replace(out.tmp, out.real)
    out.tmp = None
    out.placed = True


def _backup(path: Path) -> Path:
    """A second name for ``path`` (a hard link, else a copy) in its folder."""
    for _ in range(100):
        name = path.parent / f"{_TEMP_PREFIX}{secrets.token_hex(4)}.bak"
        try:
            os.link(path, name)
            return name
        except FileExistsError:
            continue
        except OSError as exc:
            if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EMLINK, errno.EXDEV):
                raise
        with open(path, "rb") as src, open(name, "xb") as dst:
            shutil.copyfileobj(src, dst)
        shutil.copymode(path, name)
        return name
    raise FileExistsError(errno.EEXIST, "no free backup name", str(path.parent))


def _write_through(out: _Output) -> None:
    """Copy the staged content into a FIFO or device, opened in place."""
    assert out.tmp is not None
    with open(out.tmp, "rb") as src, open(out.real, "wb") as dst:
        shutil.copyfileobj(src, dst)


def _remove(path: Path | None) -> None:
    if path is not None:
        with contextlib.suppress(OSError):
            path.unlink(missing_ok=True)


# ---------------------------------------------------------------- one-file writers
def write_file(path: PathArg, write: Writer, outputs: OutputSet | None = None) -> Path:
    """Add ``path`` with its writer to ``outputs``, or write it now on its own.

    Every file writer of fieldkit ends here, so a command can gather its files in
    one :class:`OutputSet` and a library call still writes safely by itself.

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "a.txt"
    >>> write_file(path, lambda tmp: tmp.write_text("hi")).read_text()
    'hi'
    """
    if outputs is not None:
        return outputs.add(path, write)
    own = OutputSet()
    own.add(path, write)
    own.commit()
    return Path(path)


def write_text(path: PathArg, text: str, outputs: OutputSet | None = None) -> Path:
    """Write ``text`` as UTF-8 through :func:`write_file`."""
    data = text.encode("utf-8")
    return write_file(path, lambda tmp: tmp.write_bytes(data), outputs)


# ---------------------------------------------------------------- spreadsheets
#: First characters that make a spreadsheet run a text cell as a formula (OWASP
#: CSV injection: ``=``, ``+``, ``-``, ``@``, tab, carriage return).
FORMULA_STARTS: tuple[str, ...] = ("=", "+", "-", "@", "\t", "\r")


def is_formula_like(text: str) -> bool:
    """True when a spreadsheet would run ``text`` as a formula.

    Examples
    --------
    >>> [is_formula_like(t) for t in ("=1+1", "-2", "P1", "")]
    [True, True, False, False]
    """
    return text[:1] in FORMULA_STARTS


def escape_formula(text: str) -> str:
    """``text`` for a CSV cell: a formula-like text gets a leading ``'``.

    Text that is already quotes followed by formula-like text gets one more quote,
    so :func:`unescape_formula` can always undo exactly this.

    Examples
    --------
    >>> escape_formula('=HYPERLINK("x")'), escape_formula("P1")
    ('\\'=HYPERLINK("x")', 'P1')
    >>> escape_formula("'=x")
    "''=x"
    """
    return "'" + text if is_formula_like(text.lstrip("'")) else text


def unescape_formula(text: str) -> str:
    """Undo :func:`escape_formula` (remove one ``'`` before formula-like text).

    Examples
    --------
    >>> unescape_formula("'-2"), unescape_formula("''=x"), unescape_formula("'P1")
    ('-2', "'=x", "'P1")
    """
    if text.startswith("'") and is_formula_like(text[1:].lstrip("'")):
        return text[1:]
    return text


def _text_columns(frame: pd.DataFrame) -> list[str]:
    import pandas as pd

    return [
        c
        for c in frame.columns
        if frame[c].dtype == object or pd.api.types.is_string_dtype(frame[c].dtype)
    ]


def escape_formulas(frame: pd.DataFrame) -> pd.DataFrame:
    """A copy of ``frame`` whose text cells are safe in a spreadsheet's CSV.

    Only columns of text (object or string dtype) are looked at, and in them only
    ``str`` values: numbers, booleans and missing values are never changed.
    """
    out = frame.copy()
    for col in _text_columns(out):
        # only the cells escape_formula changes go through it (a column of digits,
        # such as a simulation's rock numbers, costs one vectorised test)
        column = out[col]
        text = column.astype("string")
        starts = text.str.lstrip("'").str[:1].isin(FORMULA_STARTS)
        rows = np.flatnonzero(starts.fillna(False).to_numpy(bool))
        rows = [i for i in rows if isinstance(column.iloc[i], str)]
        if rows:
            column = column.copy()
            column.iloc[rows] = [escape_formula(column.iloc[i]) for i in rows]
            out[col] = column
    return out


def unescape_formulas(frame: pd.DataFrame) -> pd.DataFrame:
    """Undo :func:`escape_formulas` on a frame read back from CSV (a copy)."""
    out = frame.copy()
    for col in _text_columns(out):
        out[col] = out[col].map(
            lambda v: unescape_formula(v) if isinstance(v, str) else v
        )
    return out


def protect_formula_cells(worksheet) -> None:
    """Keep every formula-like text cell of an openpyxl worksheet as text.

    The cell is typed as a string (openpyxl makes a text starting with ``=`` a
    formula) and given the quote prefix a spreadsheet uses for typed-in text, so
    the value stays verbatim and is never evaluated.
    """
    for row in worksheet.iter_rows():
        for cell in row:
            if isinstance(cell.value, str) and is_formula_like(cell.value):
                cell.data_type = "s"
                cell.quotePrefix = True


# ---------------------------------------------------------------- JSON and CSV text
def _json_ready(value: object) -> object:
    """``value`` with numpy types made plain and non-finite numbers made None."""
    if isinstance(value, dict):
        return {str(k): _json_ready(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return [_json_ready(v) for v in value.tolist()]
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        number = float(value)
        return number if np.isfinite(number) else None
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return value


def json_text(data: object, *, indent: int = 2) -> str:
    """``data`` as JSON text ending in a newline; non-finite numbers as ``null``.

    Examples
    --------
    >>> json_text({"a": float("nan"), "b": np.float64(2.5), "c": [np.int64(3)]},
    ...           indent=None)
    '{"a": null, "b": 2.5, "c": [3]}\\n'
    """
    import json

    return (
        json.dumps(_json_ready(data), indent=indent, allow_nan=False, default=str)
        + "\n"
    )


def write_json(
    path: PathArg, data: object, outputs: OutputSet | None = None, *, indent: int = 2
) -> Path:
    """Write ``data`` as a JSON file (:func:`json_text`) through :func:`write_file`.

    The one JSON writer of fieldkit: numpy values are plain JSON and NaN or
    +-Infinity are written as ``null`` (never as the invalid literals ``NaN``,
    ``Infinity``).
    """
    return write_text(path, json_text(data, indent=indent), outputs)


def csv_text(rows: Iterable[Iterable[object]]) -> str:
    """Rows as CSV text: cells quoted by the csv module where needed (commas,
    quotes, line breaks), formula-like text cells escaped (:func:`escape_formula`);
    numbers, and text that is a number (``"-2.5"``), are written as given.

    Examples
    --------
    >>> csv_text([["id", "name"], [1, "=cmd|' /C calc'!A0"], [2, "a,b"], ["-2.5", 3]])
    'id,name\\n1,\\'=cmd|\\' /C calc\\'!A0\\n2,"a,b"\\n-2.5,3\\n'
    """
    import csv
    import io

    lines = []
    for row in rows:
        # "\r\n" makes the writer quote a cell holding either character; each
        # line then ends in "\n" alone, as every other text file fieldkit writes
        buffer = io.StringIO()
        csv.writer(buffer, lineterminator="\r\n").writerow([_csv_cell(c) for c in row])
        lines.append(buffer.getvalue()[:-2] + "\n")
    return "".join(lines)


def _csv_cell(cell: object) -> object:
    if not isinstance(cell, str):
        return cell
    try:
        float(cell)
    except ValueError:
        return escape_formula(cell)
    return cell
