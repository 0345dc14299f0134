"""An ImpactTable written chunk by chunk: millions of simulated impacts, flat memory.

A Monte Carlo of 10^5 rocks makes 10^6-10^7 impacts; holding them to write them at
the end costs gigabytes. :class:`ImpactStreamWriter` appends each chunk (an
:class:`~fieldkit.impact_table.ImpactTable`) to an open file as it is made, into the
temporary file :meth:`fieldkit.outputs.OutputSet.stream` returns, so the file still
appears all at once at the commit (and not at all on failure).

Formats (from the target's extension):

* ``.parquet`` -- :class:`pyarrow.parquet.ParquetWriter`, one row group per chunk
  (1.3-4.6 s per million rows of 41 columns here);
* ``.csv`` -- :func:`pyarrow.csv.write_csv` per chunk, header once, quoting only
  where needed (4-8 s per million rows, against 41-68 s for ``DataFrame.to_csv``:
  8-10 times faster; ``benchmarks/bench_impact_writing.py``). Text cells go
  through :func:`fieldkit.outputs.escape_formulas` like every ImpactTable CSV.
  Floats are written as their shortest round-trip text, as pandas does; booleans
  as ``true``/``false`` and whole floats without ``.0`` (``1000``), which
  :meth:`ImpactTable.read` reads back to the same values.

XLSX cannot be streamed (and holds at most 1,048,576 rows): write the whole table
with :meth:`ImpactTable.write`.
"""

from __future__ import annotations

import os
from pathlib import Path

import pyarrow as pa
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

from fieldkit.errors import ArgumentError
from fieldkit.impact_table import ImpactTable, is_stream_device
from fieldkit.outputs import escape_formulas

#: Formats a stream can write, by extension.
STREAM_FORMATS: dict[str, str] = {".csv": "csv", ".parquet": "parquet"}


def stream_format(path: str | os.PathLike[str], argument: str = "path") -> str:
    """``"csv"`` or ``"parquet"`` from the extension of ``path``; ``"csv"`` (the
    default table format) for a FIFO or character device without one
    (``--impacts /dev/null``).

    Raises
    ------
    ArgumentError
        Another extension (naming ``argument``).

    Examples
    --------
    >>> stream_format("out/impacts.PARQUET")
    'parquet'
    """
    fmt = STREAM_FORMATS.get(Path(path).suffix.lower())
    if fmt is None and is_stream_device(path):
        return "csv"
    if fmt is None:
        raise ArgumentError(
            f"cannot stream impacts to {Path(path).name!r}: use "
            f"{' or '.join(STREAM_FORMATS)}",
            source=argument,
        )
    return fmt


class ImpactStreamWriter:
    """Append ImpactTable chunks to one CSV or Parquet file.

    Parameters
    ----------
    path
        The file to write (usually the temporary file of
        :meth:`fieldkit.outputs.OutputSet.stream`); created or truncated.
    fmt
        ``"csv"`` or ``"parquet"`` (:func:`stream_format` of the target).

    Notes
    -----
    Every chunk must have the columns of the first (the ImpactTable contract order
    plus the same extras); values are cast to the first chunk's types. Use as a
    context manager, or call :meth:`close` (a Parquet file is valid only then).

    Examples
    --------
    >>> import tempfile, pandas as pd
    >>> path = Path(tempfile.mkdtemp()) / "impacts.csv"
    >>> chunk = ImpactTable(pd.DataFrame({"path_id": ["0"], "point": ["1"],
    ...     "x_m": [1.0], "z_m": [0.0], "slope_deg": [30.0], "vi_x_mps": [3.0],
    ...     "vi_z_mps": [-4.0], "vf_x_mps": [3.0], "vf_z_mps": [2.0]}))
    >>> with ImpactStreamWriter(path, "csv") as writer:
    ...     writer.write(chunk)
    ...     writer.write(chunk)  # same point twice: the file does not check
    >>> writer.rows, len(path.read_text().splitlines())
    (2, 3)
    """

    def __init__(self, path: str | os.PathLike[str], fmt: str) -> None:
        if fmt not in STREAM_FORMATS.values():
            raise ValueError(f"unknown stream format {fmt!r}")
        self.path = Path(path)
        self.fmt = fmt
        self.rows = 0
        self._schema: pa.Schema | None = None
        self._parquet: pq.ParquetWriter | None = None
        self._csv: pa_csv.CSVWriter | None = None
        self._sink = None

    def __enter__(self) -> ImpactStreamWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def write(self, table: ImpactTable) -> None:
        """Append the rows of ``table``."""
        frame = table.frame
        if self.fmt == "csv":
            frame = escape_formulas(frame)
        chunk = pa.Table.from_pandas(frame, preserve_index=False)
        if self._schema is None:
            self._open(chunk.schema)
        assert self._schema is not None
        if chunk.schema.names != self._schema.names:
            raise ValueError(
                "an impact chunk has other columns than the first: "
                f"{chunk.schema.names} != {self._schema.names}"
            )
        chunk = chunk.cast(self._schema)
        if self._parquet is not None:
            self._parquet.write_table(chunk)
        elif self._csv is not None:
            self._csv.write_table(chunk)
        self.rows += chunk.num_rows

    def close(self) -> None:
        """Finish the file (Parquet footer); an empty stream writes nothing."""
        if self._parquet is not None:
            self._parquet.close()
            self._parquet = None
        if self._csv is not None:
            self._csv.close()
            self._csv = None
        if self._sink is not None:
            self._sink.close()
            self._sink = None

    def _open(self, schema: pa.Schema) -> None:
        # pandas metadata would pin the first chunk's index; not wanted in a stream
        self._schema = schema.remove_metadata()
        if self.fmt == "parquet":
            self._parquet = pq.ParquetWriter(self.path, self._schema)
        else:
            self._sink = pa.OSFile(str(self.path), "wb")
            self._csv = pa_csv.CSVWriter(
                self._sink,
                self._schema,
                write_options=pa_csv.WriteOptions(quoting_style="needed"),
            )


#: Rows an XLSX sheet holds (the header takes one).
XLSX_MAX_ROWS = 1_048_576 - 1


def check_impacts_target(path: str | os.PathLike[str], argument: str) -> None:
    """Refuse, before any work, a target :class:`ImpactTableOutput` cannot write
    (an extension other than .csv, .parquet, .xlsx; naming ``argument``)."""
    if Path(path).suffix.lower() != ".xlsx":
        stream_format(path, argument)


class ImpactTableOutput:
    """A simulation's ImpactTable file, written chunk by chunk as the run makes it.

    CSV and Parquet are streamed (:class:`ImpactStreamWriter` into the temporary
    file of :meth:`fieldkit.outputs.OutputSet.stream`: memory bounded by a chunk);
    XLSX cannot be, so its chunks are kept and written whole by :meth:`finish`, at
    most :data:`XLSX_MAX_ROWS` rows. The 2-D and 3-D simulations write through it.

    Parameters
    ----------
    path
        The target (.csv, .parquet or .xlsx; a FIFO or device streams CSV).
    outputs
        The command's output set (the file appears at its commit).
    argument
        The option naming the target, in errors.

    Examples
    --------
    >>> import tempfile, pandas as pd
    >>> from fieldkit.outputs import OutputSet
    >>> folder = Path(tempfile.mkdtemp())
    >>> chunk = ImpactTable(pd.DataFrame({"path_id": ["0"], "point": ["1"],
    ...     "x_m": [1.0], "z_m": [0.0], "slope_deg": [30.0], "vi_x_mps": [3.0],
    ...     "vi_z_mps": [-4.0], "vf_x_mps": [3.0], "vf_z_mps": [2.0]}))
    >>> with OutputSet() as outputs:
    ...     out = ImpactTableOutput(folder / "i.xlsx", outputs, argument="--impacts")
    ...     out.write(chunk)
    ...     out.finish()
    ...     written = outputs.commit()
    >>> len(ImpactTable.read(folder / "i.xlsx"))
    1
    """

    def __init__(
        self, path: str | os.PathLike[str], outputs, *, argument: str
    ) -> None:
        self.path = Path(path)
        self.outputs = outputs
        self.argument = argument
        self.rows = 0
        self._frames: list = []
        self._writer: ImpactStreamWriter | None = None
        check_impacts_target(self.path, argument)
        if self.path.suffix.lower() != ".xlsx":
            tmp = outputs.stream(self.path, argument=argument)
            self._writer = ImpactStreamWriter(tmp, stream_format(self.path, argument))

    def write(self, table: ImpactTable) -> None:
        """Append the rows of ``table`` (a chunk of whole rocks, in order)."""
        self.rows += len(table)
        if self._writer is not None:
            self._writer.write(table)
        else:
            self._frames.append(table.frame)

    def close(self) -> None:
        """Close the stream (safe to call again; call it on failure too)."""
        if self._writer is not None:
            self._writer.close()

    def finish(self) -> None:
        """Close the stream, or write the XLSX table into the output set.

        Raises
        ------
        ArgumentError
            An XLSX target and more than :data:`XLSX_MAX_ROWS` rows.
        """
        self.close()
        if self._writer is not None:
            return
        if self.rows > XLSX_MAX_ROWS:
            raise ArgumentError(
                f"{self.rows:,} impacts do not fit an XLSX sheet "
                f"({XLSX_MAX_ROWS:,} rows); write .csv or .parquet",
                source=self.argument,
            )
        import pandas as pd

        frame = pd.concat(self._frames, ignore_index=True)
        ImpactTable(frame, source="simulation").write(self.path, outputs=self.outputs)
