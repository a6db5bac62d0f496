"""CSV and Parquet tables with units in a sidecar, in Parquet metadata or in column names."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator, MutableMapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal._lazy import LazyModule
from thermocal.errors import (
    FileFormatError,
    NonNumericError,
)
from thermocal.outputs import sidecar_path
from thermocal.readers.common import arrow_chunk_f64, short_name
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq
else:
    pd = LazyModule("pandas")
    pa = LazyModule("pyarrow")
    pq = LazyModule("pyarrow.parquet")


# --- reading -------------------------------------------------------------------------


def load_sidecar(path: Path) -> dict[str, Any]:
    """The metadata sidecar of a CSV file (``FILE.meta.json``), or ``{}`` when there is none.

    Parameters
    ----------
    path : pathlib.Path
        The data file (not the sidecar).

    Returns
    -------
    dict
        The sidecar's object (units, scale factor, time column, …).

    Raises
    ------
    FileFormatError
        A sidecar that is not valid JSON or not a JSON object.
    """
    side = sidecar_path(path)
    if not side.exists():
        return {}
    try:
        obj = json.loads(side.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:  # JSONDecodeError, a 5000-digit integer
        raise FileFormatError(f"{side}: not valid JSON ({exc})") from None
    except RecursionError:  # thousands of nested brackets
        raise FileFormatError(f"{side}: not a metadata sidecar (nested too deeply)") from None
    if not isinstance(obj, dict):
        raise FileFormatError(f"{side}: expected a JSON object")
    return obj


class ReaderFile:
    """A Parquet file open in pyarrow's own reader (``pyarrow._parquet.ParquetReader``, what
    :class:`pyarrow.parquet.ParquetFile` wraps), with the part of ``ParquetFile``'s interface
    :class:`ParquetColumns` uses, columns chosen by name as ``ParquetFile`` chooses them (a
    name selects its leaf columns).  Reading through it does not import
    :mod:`pyarrow.parquet`, which imports the file systems (:mod:`pyarrow.fs`: ``ssl``, S3,
    GCS, Azure, HDFS), 8–11 ms of every command's start that reads a local file.

    Parameters
    ----------
    reader : pyarrow._parquet.ParquetReader
        The open reader.
    """

    def __init__(self, reader: Any) -> None:
        self.reader = reader
        leaves: dict[str, list[int]] = {}
        for i, parts in enumerate(reader.column_paths):  # "a", "a.b", "a.b.c" → leaf i
            for k in range(1, len(parts) + 1):
                leaves.setdefault(".".join(parts[:k]), []).append(i)
        self._leaves = leaves

    @property
    def schema_arrow(self) -> pa.Schema:
        """The file's Arrow schema."""
        return self.reader.schema_arrow

    @property
    def metadata(self) -> Any:
        """The file's Parquet metadata (``pyarrow.parquet.FileMetaData``)."""
        return self.reader.metadata

    @property
    def num_row_groups(self) -> int:
        """Its number of row groups."""
        return int(self.reader.num_row_groups)

    def _indices(self, columns: Sequence[str]) -> list[int]:
        return [i for name in columns for i in self._leaves.get(name, [])]

    def read_row_group(self, i: int, columns: Sequence[str], use_threads: bool) -> pa.Table:
        """The columns ``columns`` of row group ``i``.

        Parameters
        ----------
        i : int
            The row group.
        columns : sequence of str
            Column names (a nested column's name reads its leaves).
        use_threads : bool
            Decode the columns on pyarrow's threads.

        Returns
        -------
        pyarrow.Table
        """
        return self.reader.read_row_group(
            i, column_indices=self._indices(columns), use_threads=use_threads
        )

    def read(self, columns: Sequence[str], use_threads: bool) -> pa.Table:
        """The columns ``columns``, read whole.

        Parameters
        ----------
        columns : sequence of str
            Column names (a nested column's name reads its leaves).
        use_threads : bool
            Decode the columns on pyarrow's threads.

        Returns
        -------
        pyarrow.Table
        """
        return self.reader.read_all(column_indices=self._indices(columns), use_threads=use_threads)


def open_parquet(path: Path, checksums: bool = True) -> Any:
    """A local Parquet file open for :class:`ParquetColumns`: a :class:`ReaderFile`, or a
    :class:`pyarrow.parquet.ParquetFile` where pyarrow's reader cannot be had directly.

    Parameters
    ----------
    path : pathlib.Path
        The file.
    checksums : bool, optional
        Verify the pages' checksums where the writer stored them (default True).

    Returns
    -------
    ReaderFile or pyarrow.parquet.ParquetFile
        The open file, options as ``pyarrow.parquet.ParquetFile(path,
        page_checksum_verification=checksums)`` sets them.

    Raises
    ------
    pyarrow.ArrowInvalid, OSError
        Not a Parquet file, or it cannot be opened.
    """
    try:
        from pyarrow._parquet import ParquetReader
    except ImportError:  # pragma: no cover - pyarrow's layout changed: the public class
        return pq.ParquetFile(path, page_checksum_verification=checksums)
    reader = ParquetReader()
    try:  # ParquetFile's own default since pyarrow 19; an error for older readers
        reader.open(str(path), page_checksum_verification=checksums, arrow_extensions_enabled=True)
    except TypeError:
        reader = ParquetReader()
        reader.open(str(path), page_checksum_verification=checksums)
    return ReaderFile(reader)


class ParquetColumns:
    """Columns of a Parquet file read one at a time, so that peak memory stays near
    the size of the float64 arrays handed back (not the Arrow table plus its copy).

    Parameters
    ----------
    pf : ReaderFile or pyarrow.parquet.ParquetFile
        The open Parquet file (:func:`open_parquet`).

    Attributes
    ----------
    column_names : list of str
        The file's column names.
    num_rows : int
        Its number of rows.
    metadata : dict of bytes to bytes
        Its key-value metadata.
    """

    def __init__(self, pf: ReaderFile | pq.ParquetFile) -> None:
        self._pf = pf
        schema = pf.schema_arrow
        self.column_names: list[str] = list(schema.names)
        self.num_rows: int = int(pf.metadata.num_rows)
        self.metadata: dict[bytes, bytes] = dict(schema.metadata or {})
        self._read: dict[str, FloatArray] = {}

    def read_f64(self, names: Sequence[str]) -> None:
        """Read the integer and floating-point columns among ``names`` together, one row
        group at a time (pyarrow decodes the columns of a row group on several threads);
        :meth:`column_f64` then hands each one over.  Peak memory: the results plus one
        row group of these columns.  The first (the time axis, converted on its own) is an
        array of its own; the others are the columns of one column-major block, so that
        consecutive ones are an ``(n, k)`` array without a copy
        (:meth:`thermocal.recording.Recording.temperatures_c`).

        Parameters
        ----------
        names : sequence of str
            The columns wanted; non-numeric ones are left to :meth:`column`.
        """
        schema = self._pf.schema_arrow
        todo = [
            n
            for n in dict.fromkeys(names)
            if n in self.column_names
            and n not in self._read
            and (
                pa.types.is_integer(schema.field(n).type)
                or pa.types.is_floating(schema.field(n).type)
            )
        ]
        if len(todo) < 2:
            return
        out = {todo[0]: np.empty(self.num_rows, dtype=np.float64)}
        # the others side by side in one column-major block: each a contiguous column, and
        # a run of them (the temperatures) an (n, k) array without a copy
        block = np.empty((self.num_rows, len(todo) - 1), dtype=np.float64, order="F")
        out.update((n, block[:, j]) for j, n in enumerate(todo[1:]))
        del block
        pos = 0
        try:
            for i in range(self._pf.num_row_groups):
                k = 0
                for n in todo:  # one column chunk at a time: the decoding buffers of one
                    group = self._pf.read_row_group(i, columns=[n], use_threads=False)
                    k = 0
                    for chunk in group.column(n).chunks:
                        out[n][pos + k : pos + k + len(chunk)] = arrow_chunk_f64(chunk)
                        k += len(chunk)
                    del group
                pos += k
        except (pa.ArrowInvalid, OSError):
            return  # a damaged file: column by column, the error names the column
        pa.default_memory_pool().release_unused()  # the decoders' pages: nothing holds them
        if pos == self.num_rows:
            self._read.update(out)

    def is_numeric(self, name: str) -> bool:
        """Whether the column ``name`` is stored as integers or floating-point numbers.

        Parameters
        ----------
        name : str
            The column's name (one of :attr:`column_names`).

        Returns
        -------
        bool
            True for an integer or floating-point column (read as float64 by
            :meth:`column_f64`).
        """
        field_type = self._pf.schema_arrow.field(name).type
        return bool(pa.types.is_integer(field_type) or pa.types.is_floating(field_type))

    def column(self, name: str) -> pa.ChunkedArray:
        """One column as Arrow, read whole.

        Parameters
        ----------
        name : str
            The column's name.

        Returns
        -------
        pyarrow.ChunkedArray
            The column.
        """
        col: pa.ChunkedArray = self._pf.read(columns=[name], use_threads=True).column(name)
        return col

    def column_f64(self, name: str) -> FloatArray | None:
        """A numeric column as float64, read one row group at a time into the result, so
        that the only memory beyond the result is one row group of one column (None for a
        column that is not integer or floating point: the caller reads it whole).

        Parameters
        ----------
        name : str
            The column's name.

        Returns
        -------
        numpy.ndarray or None
            float64 values (nulls as NaN), or ``None`` for a non-numeric column.
        """
        if name in self._read:  # read with others by :meth:`read_f64`
            return self._read.pop(name)
        field_type = self._pf.schema_arrow.field(name).type
        if not (pa.types.is_integer(field_type) or pa.types.is_floating(field_type)):
            return None
        out = np.empty(self.num_rows, dtype=np.float64)
        pos = 0
        for i in range(self._pf.num_row_groups):
            # one column: no threads to share it among (on a loaded machine they halve
            # the speed)
            col = self._pf.read_row_group(i, columns=[name], use_threads=False).column(name)
            for chunk in col.chunks:
                k = len(chunk)
                out[pos : pos + k] = arrow_chunk_f64(chunk)  # nulls → NaN
                pos += k
            del col
        pa.default_memory_pool().release_unused()
        if pos != self.num_rows:
            raise pa.ArrowInvalid(f"column {name!r} has {pos} rows, the file {self.num_rows}")
        return out


ON_DEMAND_MIN_COLUMNS = 3
"""Columns used (time included) up to which a Parquet file is read whole even where its
columns could be read on demand (:class:`ColumnsOnDemand`): time and two columns are what
reading on demand holds at a time anyway, and every use would read a column again."""


class ColumnsOnDemand(MutableMapping[str, FloatArray]):
    """The numeric columns of a Parquet file, each read as float64 when it is asked for
    and not kept beyond the next one: a recording's columns for a command that uses them
    one at a time (``inspect``, ``metrics``), so that its memory is the time axis and one
    or two columns whatever the number of columns.

    The values are those :meth:`ParquetColumns.column_f64` reads (the same as a whole
    read); a column assigned to the mapping is kept as given.  The order of the names is
    the order they were added in, as for a dict.

    Parameters
    ----------
    source : ParquetColumns
        The open file.
    path : Path
        The file, named in errors.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import pyarrow as pa, pyarrow.parquet as pq
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "r.parquet"
    >>> pq.write_table(pa.table({"t": [0.0, 1.0], "g": [1.5, 2.5]}), f)
    >>> cols = ColumnsOnDemand(ParquetColumns(pq.ParquetFile(f)), f)
    >>> cols.add("g")
    >>> list(cols), cols["g"].tolist()
    (['g'], [1.5, 2.5])
    """

    def __init__(self, source: ParquetColumns, path: Path) -> None:
        self._source, self._path = source, path
        self._names: list[str] = []
        self._given: dict[str, FloatArray] = {}
        self._last: tuple[str, FloatArray] | None = None

    def add(self, name: str) -> None:
        """Name a numeric column of the file as one of the mapping's (read when asked for).

        Parameters
        ----------
        name : str
            The column (integer or floating point in the file).
        """
        if name not in self._names:
            self._names.append(name)

    def read_from_file(self, name: str) -> bool:
        """Whether ``name`` is one of the file's numeric columns, read when asked for (not
        a column assigned to the mapping).

        Parameters
        ----------
        name : str
            The column.

        Returns
        -------
        bool
        """
        return name in self._names and name not in self._given

    def __getitem__(self, name: str) -> FloatArray:
        if name in self._given:
            return self._given[name]
        if name not in self._names:
            raise KeyError(name)
        if self._last is not None and self._last[0] == name:
            return self._last[1]
        self._last = None  # the previous column released before the next is read
        values = numeric_column(self._source, name, self._path)
        self._last = (name, values)
        return values

    def __setitem__(self, name: str, values: FloatArray) -> None:
        self.add(name)
        self._given[name] = values

    def __delitem__(self, name: str) -> None:
        if name not in self._names:
            raise KeyError(name)
        self._names.remove(name)
        self._given.pop(name, None)
        if self._last is not None and self._last[0] == name:
            self._last = None

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._names))

    def __len__(self) -> int:
        return len(self._names)

    def __contains__(self, name: object) -> bool:
        return name in self._names

    def __repr__(self) -> str:
        return f"ColumnsOnDemand({self._path}, {self._names!r})"


def csv_header_names(path: Path, encoding: str) -> list[str]:
    """The names of a comma CSV's header line as written (pandas renames a repeated name
    ``a.1``, so repeats are looked for here).  One pass over the line: linear in its
    length.  Empty for a header the ``csv`` module cannot split (the reader then says).

    Parameters
    ----------
    path : pathlib.Path
        The CSV file (``.gz`` allowed).
    encoding : str
        Its encoding.

    Returns
    -------
    list of str
        The header's names, as written.
    """
    opener: Callable[..., Any] = open
    if path.name.lower().endswith(".gz"):
        import gzip

        opener = gzip.open
    try:
        with opener(path, "rt", encoding=encoding, errors="replace", newline="") as fh:
            line = fh.readline().lstrip("\ufeff")
    except (OSError, EOFError):
        return []
    if '"' not in line:
        return [f.strip() for f in line.rstrip("\r\n").split(",")]
    import csv

    try:
        return [f.strip() for f in next(csv.reader([line], skipinitialspace=True), [])]
    except csv.Error:  # a quoted field beyond the csv module's size limit
        return []


def arrow_to_f64(col: pa.ChunkedArray | pa.Array, name: str, path: Path) -> FloatArray:
    """An Arrow column as float64 (copied chunk by chunk into one array).

    Parameters
    ----------
    col : pyarrow.ChunkedArray or pyarrow.Array
        The column (integer, float, boolean or decimal).
    name : str
        Its name, for the error.
    path : pathlib.Path
        The file, for the error.

    Returns
    -------
    numpy.ndarray
        float64 values, nulls as NaN.

    Raises
    ------
    NonNumericError
        A column of another type (text, dates).
    """
    if not (pa.types.is_integer(col.type) or pa.types.is_floating(col.type)):
        if pa.types.is_boolean(col.type) or pa.types.is_decimal(col.type):
            return np.asarray(col.to_numpy(zero_copy_only=False), dtype=np.float64)
        raise NonNumericError(f"{path}: column {name!r} is not numeric (type {col.type})")
    chunks = col.chunks if isinstance(col, pa.ChunkedArray) else [col]
    if col.null_count == 0 and pa.types.is_float64(col.type):
        if len(chunks) == 1:
            return arrow_chunk_f64(chunks[0])
        out = np.empty(len(col), dtype=np.float64)
        pos = 0
        for chunk in chunks:
            n = len(chunk)
            out[pos : pos + n] = chunk.to_numpy(zero_copy_only=True)
            pos += n
        return out
    out = np.empty(len(col), dtype=np.float64)
    pos = 0
    for chunk in chunks:
        out[pos : pos + len(chunk)] = arrow_chunk_f64(chunk)
        pos += len(chunk)
    return out


def numeric_column(
    obj: pd.DataFrame | pa.RecordBatch | ParquetColumns,
    name: str,
    path: str | Path,
    row_offset: int = 0,
) -> FloatArray:
    """A column of a table (or of a chunk of one) as float64.

    Missing cells become NaN.  A cell that is not a number raises
    :class:`NonNumericError` naming the column and the row (``row_offset`` is the
    file row of the chunk's first row, for chunked readers).

    Parameters
    ----------
    obj : pandas.DataFrame or pyarrow.RecordBatch or ParquetColumns
        The table (or chunk).
    name : str
        The column's name.
    path : str or pathlib.Path
        The file, named in errors.
    row_offset : int, optional
        File row of ``obj``'s first row; default 0.

    Returns
    -------
    numpy.ndarray
        float64 values (n,).

    Raises
    ------
    NonNumericError
        A cell that is not a number (names the column, row and line).
    FileFormatError
        A Parquet column that cannot be read.

    Examples
    --------
    >>> import pandas as pd
    >>> from thermocal.readers.table import numeric_column
    >>> numeric_column(pd.DataFrame({"g": ["1.5", "", "2"]}), "g", "run.csv").tolist()
    [1.5, nan, 2.0]
    """
    p = Path(path)
    if isinstance(obj, ParquetColumns):
        try:
            direct = obj.column_f64(name)
            if direct is not None:
                return direct
            col = obj.column(name)
        except (pa.ArrowInvalid, OSError) as exc:
            raise FileFormatError(f"{p}: cannot read column {name!r} ({exc})") from None
        return arrow_to_f64(col, name, p)
    if isinstance(obj, pa.RecordBatch):
        return arrow_to_f64(obj.column(name), name, p)
    series = obj[name]
    if pd.api.types.is_numeric_dtype(series.dtype) and not pd.api.types.is_bool_dtype(series.dtype):
        return series.to_numpy(dtype=np.float64, na_value=np.nan)
    conv = pd.to_numeric(series, errors="coerce")
    bad = conv.isna() & series.notna() & (series.astype(str).str.strip() != "")
    if bad.any():
        row = row_offset + int(np.argmax(bad.to_numpy()))
        lines = obj.attrs.get("file_lines")  # a text log's lines (banner, comments skipped)
        line = int(lines[row]) if lines is not None and row < len(lines) else row + 2
        raise NonNumericError(
            f"{p}: non-numeric value {short_name(str(series.iloc[row - row_offset]))} in column "
            f"{short_name(name)} at row {row} (line {line} of the file)"
        )
    return conv.to_numpy(dtype=np.float64, na_value=np.nan)
