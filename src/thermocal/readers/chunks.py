"""Formats read in chunks with constant memory (CSV, Parquet, a station's recording
folder): what a file holds before its rows are read (:func:`csv_head`, :func:`parquet_head`,
:func:`station_head`) and its rows a chunk at a time (:func:`csv_chunks`,
:func:`parquet_chunks`, :func:`station_chunks`).  The file-format registry
(:mod:`thermocal.readers.formats`) names them for the formats that stream; the chunked
compensation goes through them."""

from __future__ import annotations

import contextlib
import signal
import threading
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal._lazy import LazyModule
from thermocal.errors import FileFormatError, TextLayoutWarning
from thermocal.readers.common import csv_encoding, csv_float_options, thermocal_metadata
from thermocal.readers.station import station_files
from thermocal.readers.text import csv_chunk_options

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq
else:
    pd = LazyModule("pandas")
    pa = LazyModule("pyarrow")
    pq = LazyModule("pyarrow.parquet")

Head = tuple[list[str], dict[str, Any], "int | None"]
"""Column names, the file's own metadata and its number of rows (None: not known)."""


@dataclass
class _CtrlC:
    seen: bool = False


@contextlib.contextmanager
def _ctrl_c_noted() -> Iterator[_CtrlC]:
    """Note a Ctrl-C (SIGINT) while pandas' C parser reads a CSV file: it turns the
    KeyboardInterrupt raised inside its ``read`` into a ParserError ("Calling read(nbytes)
    on source failed"), which would read as a damaged file.  The handler notes it and
    raises KeyboardInterrupt as Python's default does; installed only where a handler can
    be (the main thread) and where SIGINT is not ignored (fleet workers)."""
    note = _CtrlC()
    if threading.current_thread() is not threading.main_thread():
        yield note
        return
    before = signal.getsignal(signal.SIGINT)
    if before is not signal.default_int_handler:
        yield note
        return

    def handler(signum: int, frame: Any) -> None:
        note.seen = True
        signal.default_int_handler(signum, frame)

    signal.signal(signal.SIGINT, handler)
    try:
        yield note
    finally:
        signal.signal(signal.SIGINT, before)


def csv_head(path: Path) -> Head:
    """The column names of a CSV or text log (its layout detected), without its rows.

    Parameters
    ----------
    path : Path
        The file.

    Returns
    -------
    tuple
        ``(names, {}, None)``: the names stripped of blanks; a CSV states no metadata of its
        own (its sidecar is read by the caller) nor its number of rows.

    Raises
    ------
    thermocal.errors.FileFormatError
        Not a readable CSV file.
    """
    enc = csv_encoding(path)
    opts = csv_chunk_options(path, enc)
    try:
        head = pd.read_csv(path, nrows=0, skipinitialspace=True, encoding=enc, **opts)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FileFormatError(f"{path}: not a readable CSV file ({msg})") from None
    return [str(c).strip() for c in head.columns], {}, None


def parquet_head(path: Path) -> Head:
    """The column names, thermocal key-value metadata and number of rows of a Parquet file.

    Parameters
    ----------
    path : pathlib.Path
        The Parquet file.

    Returns
    -------
    Head
        ``(column names, thermocal metadata dict, number of rows)``.

    Raises
    ------
    thermocal.errors.FileFormatError
        Not a readable Parquet file.
    """
    try:
        pf = pq.ParquetFile(path)
    except (pa.ArrowInvalid, OSError) as exc:
        raise FileFormatError(f"{path}: not a readable Parquet file ({exc})") from None
    names = list(pf.schema_arrow.names)
    return names, thermocal_metadata(pf.schema_arrow.metadata, path), int(pf.metadata.num_rows)


def station_head(path: Path) -> Head:
    """Columns, metadata (the last closed part's, as
    :func:`~thermocal.readers.station.read_station` reads it) and row count of a station
    recording ``DIR/SENSOR`` (its closed Parquet parts, in order).

    Parameters
    ----------
    path : pathlib.Path
        ``DIR`` or ``DIR/SENSOR``.

    Returns
    -------
    Head
        ``(column names, thermocal metadata dict, number of rows)`` over every part.

    Raises
    ------
    thermocal.errors.FileFormatError
        A part is unreadable or its columns differ from the first part's.
    """
    names: list[str] | None = None
    n_rows, meta = 0, {}
    for f in station_files(path):
        try:
            pf = pq.ParquetFile(f)
        except (pa.ArrowInvalid, OSError) as exc:
            raise FileFormatError(f"{f}: not a readable Parquet part ({exc})") from None
        these = list(pf.schema_arrow.names)
        if names is not None and these != names:
            raise FileFormatError(f"{f}: columns {these} differ from the first part's {names}")
        names = these
        n_rows += int(pf.metadata.num_rows)
        meta = thermocal_metadata(pf.schema_arrow.metadata, f)
    return names or [], meta, n_rows


def parquet_chunks(path: Path, chunk_rows: int) -> Iterator[pa.RecordBatch]:
    """The rows of a Parquet file, ``chunk_rows`` at a time, its pages checked against their
    checksums; a read failure mid-file is a :class:`~thermocal.errors.FileFormatError`.

    Parameters
    ----------
    path : pathlib.Path
        The Parquet file.
    chunk_rows : int
        Rows per chunk.

    Yields
    ------
    pyarrow.RecordBatch
        Up to ``chunk_rows`` rows each.

    Raises
    ------
    FileFormatError
        An unreadable file or a page whose checksum fails.
    """
    try:
        # a buffered stream without pre-buffering: with the defaults the reader's
        # allocations grow with the file (≈ 20 B/row); this way they stay at ≈ 1 MB
        pf = pq.ParquetFile(
            path, page_checksum_verification=True, buffer_size=1 << 20, pre_buffer=False
        )
        yield from pf.iter_batches(batch_size=chunk_rows)
    except (pa.ArrowInvalid, OSError) as exc:
        raise FileFormatError(f"{path}: not a readable Parquet file ({exc})") from None


def station_chunks(path: Path, chunk_rows: int) -> Iterator[pa.RecordBatch]:
    """The closed parts of a station recording in order, each in chunks (constant memory).

    Parameters
    ----------
    path : pathlib.Path
        ``DIR`` or ``DIR/SENSOR``.
    chunk_rows : int
        Rows per chunk.

    Yields
    ------
    pyarrow.RecordBatch
        Up to ``chunk_rows`` rows each.

    Raises
    ------
    FileFormatError
        No closed part, or an unreadable part.
    """
    for f in station_files(path):
        yield from parquet_chunks(f, chunk_rows)


def csv_chunks(path: Path, chunk_rows: int) -> Iterator[pd.DataFrame]:
    r"""The rows of a CSV or text log, ``chunk_rows`` at a time, in its detected layout; a
    parse failure mid-file is a :class:`~thermocal.errors.FileFormatError` naming the file
    (a Ctrl-C inside pandas' parser stays a KeyboardInterrupt).

    Parameters
    ----------
    path : pathlib.Path
        The CSV or text log (``.gz`` allowed).
    chunk_rows : int
        Rows per chunk.

    Yields
    ------
    pandas.DataFrame
        Up to ``chunk_rows`` rows each, column names stripped of blanks.

    Raises
    ------
    FileFormatError
        A line that cannot be parsed, or text that cannot be decoded.
    ThermocalInputError
        A text log without a header row.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from thermocal.readers.chunks import csv_chunks
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d, "run.csv")
    ...     _ = p.write_text("time, T1, gyro\n0,25.0,1.5\n1,25.1,1.6\n2,25.2,1.7\n")
    ...     [(list(c.columns), len(c)) for c in csv_chunks(p, 2)]
    [(['time', 'T1', 'gyro'], 2), (['time', 'T1', 'gyro'], 1)]
    """
    enc = csv_encoding(path)
    with warnings.catch_warnings():  # csv_head stated the layout already
        warnings.simplefilter("ignore", TextLayoutWarning)
        opts = csv_chunk_options(path, enc)
    reader = pd.read_csv(
        path,
        chunksize=chunk_rows,
        skipinitialspace=True,
        low_memory=False,
        encoding=enc,
        **csv_float_options(),
        **opts,
    )
    try:
        with reader, _ctrl_c_noted() as ctrl_c:
            for df in reader:
                df.columns = [str(c).strip() for c in df.columns]
                yield df
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        if ctrl_c.seen:  # Ctrl-C inside pandas' read: the C parser reports a read failure
            raise KeyboardInterrupt from None
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FileFormatError(f"{path}: not a readable CSV file ({msg})") from None


__all__ = [
    "Head",
    "csv_chunks",
    "csv_head",
    "parquet_chunks",
    "parquet_head",
    "station_chunks",
    "station_head",
]
