"""A fit's temperature columns read from their Parquet file by row groups, as the fit's
passes go, instead of held whole (``thermocal fit`` on a long record).

A ``poly`` fit goes through its runs in blocks of rows (the scaling sample, the design's
reduction, the residuals: :mod:`thermocal.models.poly_fit`) and its checks look at one
temperature column at a time (:func:`thermocal.adequacy.judge`, the per-run offsets).
Held whole, four temperature columns of float64 are 32 bytes a row on top of the time
axis and the signal; :class:`TemperatureBlocks` stands in for the ``(n, k)`` array of
:attr:`thermocal.models.rundata.RunData.temps_c` and reads what is asked for: a block of
rows (the row groups it spans, the last one kept), a column, or rows picked by index.
Every value is the one a whole read gives (the same decoding,
:func:`thermocal.readers.common.arrow_chunk_f64`, element by element), in the layout the
whole array's slices have, so that every figure of the fit is the same, bit for bit.

Used where it saves memory and changes nothing: a Parquet file read with its columns on
demand (:class:`thermocal.readers.table.ColumnsOnDemand`), every temperature column as the
file has it (in °C: no conversion, no reconstruction), row groups of at most
:data:`MAX_GROUP_ROWS` rows.  Anything else is held whole as before.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
import numpy.typing as npt

from thermocal.recording import FloatArray, all_finite

if TYPE_CHECKING:
    import pyarrow.parquet as pq

    from thermocal.models.rundata import RunData
    from thermocal.recording import Recording

MIN_ROWS_BY_BLOCKS = 1 << 21
"""Rows from which a fit reads a Parquet file's columns on demand (below, four temperature
columns are at most 64 MB held whole, and reading them again as the fit goes costs more
than they weigh)."""

MAX_GROUP_ROWS = 1 << 21
"""Largest row group [rows] read block by block: beyond it one group's temperatures are
as large as holding them whole would be on a short file, and they are held whole."""


class TemperatureBlocks:
    """The ``(n, k)`` temperatures [°C] of a Parquet file's columns ``names``, read when
    sliced: ``blocks[a:b]`` (rows ``a`` to ``b``, their row groups read, the last kept),
    ``blocks[:, j]`` (column ``j`` whole), ``blocks[idx]`` (rows picked by an increasing
    integer index), ``np.asarray(blocks)`` (everything, as a whole read holds it).

    Parameters
    ----------
    source : pyarrow.parquet.ParquetFile
        The open file.
    names : sequence of str
        The temperature columns, in the fit's order (integer or floating point).
    path : Path, optional
        The file, to tell two stand-ins of the same columns (:meth:`same_columns`).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import numpy as np, pyarrow as pa, pyarrow.parquet as pq
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "r.parquet"
    >>> pq.write_table(pa.table({"T1": np.arange(5.0), "T2": 20.0 + np.arange(5.0)}), f,
    ...                row_group_size=2)
    >>> b = TemperatureBlocks(pq.ParquetFile(f), ["T1", "T2"])
    >>> b.shape, b[1:4].tolist(), b[:, 1].tolist()
    ((5, 2), [[1.0, 21.0], [2.0, 22.0], [3.0, 23.0]], [20.0, 21.0, 22.0, 23.0, 24.0])
    """

    ndim = 2
    dtype = np.dtype(np.float64)

    def __init__(
        self, source: pq.ParquetFile, names: Sequence[str], path: Path | None = None
    ) -> None:
        self._pf = source
        self._names = tuple(names)
        self.path = path
        meta = source.metadata
        sizes = [meta.row_group(i).num_rows for i in range(meta.num_row_groups)]
        self._starts = np.concatenate([[0], np.cumsum(sizes, dtype=np.int64)])
        self.shape = (int(self._starts[-1]), len(self._names))
        self._kept: tuple[int, FloatArray] | None = None

    @property
    def largest_group(self) -> int:
        """Rows of the file's largest row group."""
        return int(np.diff(self._starts).max()) if self._starts.size > 1 else 0

    def same_columns(self, other: object) -> bool:
        """Whether ``other`` stands in for the same columns of the same file (equal values
        without reading them: the channels of one run share them).

        Parameters
        ----------
        other : object
            Another run's temperatures.

        Returns
        -------
        bool
        """
        return (
            isinstance(other, TemperatureBlocks)
            and self.path is not None
            and self.path == other.path
            and self._names == other._names
            and self.shape == other.shape
        )

    def release(self) -> None:
        """Let go of the row group kept from the last block."""
        self._kept = None

    def _read(self, group: int, j: int, out: FloatArray) -> None:
        """Column ``j`` of row group ``group`` into ``out`` (decoded as a whole read does)."""
        from thermocal.readers.common import arrow_chunk_f64

        col = self._pf.read_row_group(group, columns=[self._names[j]], use_threads=False)
        pos = 0
        for chunk in col.column(0).chunks:
            out[pos : pos + len(chunk)] = arrow_chunk_f64(chunk)  # nulls → NaN
            pos += len(chunk)

    def _group(self, group: int) -> FloatArray:
        """Row group ``group``'s temperatures, ``(rows, k)`` column-major (kept)."""
        if self._kept is not None and self._kept[0] == group:
            return self._kept[1]
        self._kept = None  # the last one let go before the next is read
        rows = int(self._starts[group + 1] - self._starts[group])
        out = np.empty((rows, self.shape[1]), order="F")
        for j in range(self.shape[1]):
            self._read(group, j, out[:, j])
        self._kept = (group, out)
        return out

    def column(self, j: int) -> FloatArray:
        """Column ``j`` whole [°C] (a new array, the caller's own).

        Parameters
        ----------
        j : int
            The column's position.

        Returns
        -------
        numpy.ndarray
            Shape (n,).
        """
        self.release()
        out = np.empty(self.shape[0])
        for g in range(self._starts.size - 1):
            self._read(g, j, out[self._starts[g] : self._starts[g + 1]])
        return out

    def rows(self, a: int, b: int) -> FloatArray:
        """Rows ``a`` to ``b`` (column-major ``(b − a, k)``, the layout of a whole
        column-major array's rows made contiguous).

        Parameters
        ----------
        a, b : int
            First row and one past the last.

        Returns
        -------
        numpy.ndarray
            Shape (b − a, k).
        """
        start = a
        out = np.empty((max(b - a, 0), self.shape[1]), order="F")
        g = int(np.searchsorted(self._starts, a, side="right")) - 1
        while a < b:
            block = self._group(g)
            g0, g1 = int(self._starts[g]), int(self._starts[g + 1])
            stop = min(b, g1)
            out[a - start : stop - start] = block[a - g0 : stop - g0]
            a, g = stop, g + 1
        return out

    def pick(self, idx: npt.NDArray[np.integer[Any]]) -> FloatArray:
        """The rows of an increasing integer index, laid out as numpy lays out the rows a
        whole column-major array picks.

        Parameters
        ----------
        idx : numpy.ndarray
            Increasing row numbers.

        Returns
        -------
        numpy.ndarray
            Shape (idx.size, k).
        """
        idx = np.asarray(idx, dtype=np.intp)
        groups = np.searchsorted(self._starts, idx, side="right") - 1
        cut = np.flatnonzero(np.diff(groups)) + 1
        parts = [
            self._group(int(g[0]))[s - self._starts[g[0]]]
            for s, g in zip(np.split(idx, cut), np.split(groups, cut), strict=True)
            if s.size
        ]
        if not parts:
            return np.empty((0, self.shape[1]))
        out: FloatArray = np.empty_like(parts[0], shape=(idx.size, self.shape[1]))
        pos = 0
        for p in parts:
            out[pos : pos + p.shape[0]] = p
            pos += p.shape[0]
        return out

    def __getitem__(self, key: Any) -> FloatArray:
        if isinstance(key, slice):
            a, b, step = key.indices(self.shape[0])
            if step == 1:
                return self.rows(a, b)
            return self.pick(np.arange(a, b, step))
        if isinstance(key, tuple) and len(key) == 2 and key[0] == slice(None):
            j = key[1]
            if isinstance(j, (int, np.integer)):
                return self.column(int(j))
        if isinstance(key, np.ndarray) and key.ndim == 1 and key.dtype.kind in "iu":
            return self.pick(key)
        whole: FloatArray = np.asarray(self)
        return whole[key]  # type: ignore[no-any-return]

    def __array__(self, dtype: Any = None, copy: Any = None) -> FloatArray:
        out = np.empty(self.shape, order="F")
        for j in range(self.shape[1]):
            out[:, j] = self.column(j)
        return out if dtype is None else out.astype(dtype)

    def __len__(self) -> int:
        return self.shape[0]


def read_by_blocks(path: Path) -> bool:
    """Whether a fit reads ``path``'s columns on demand (its temperatures then by
    :class:`TemperatureBlocks`): a Parquet file (by its suffix, as the reader dispatches it)
    of at least :data:`MIN_ROWS_BY_BLOCKS` rows.  Anything the footer does not say (not
    Parquet, unreadable) is ``False``: the reader then reads it, or says what is wrong.

    Parameters
    ----------
    path : Path
        The file given to the fit.

    Returns
    -------
    bool
    """
    from thermocal.errors import ThermocalInputError
    from thermocal.readers.formats import file_kind

    try:  # a folder (a station's recording) or a name no format claims: read as before
        if not path.is_file() or file_kind(path) != "parquet":
            return False
    except ThermocalInputError:
        return False
    import pyarrow.parquet as pq

    try:
        return int(pq.read_metadata(path).num_rows) >= MIN_ROWS_BY_BLOCKS
    except (OSError, ValueError):  # pyarrow's ArrowInvalid is a ValueError
        return False


def temperature_blocks(rec: Recording, names: Sequence[str]) -> TemperatureBlocks | None:
    """The temperatures ``names`` of ``rec`` read block by block, where that changes no value
    (module docstring): ``rec`` read on demand from a Parquet file, every column the file's
    own (not reconstructed, not read from text) and in °C, row groups of at most
    :data:`MAX_GROUP_ROWS`; else ``None`` (held whole).

    Parameters
    ----------
    rec : Recording
        The run as read.
    names : sequence of str
        The temperature columns a fit uses.

    Returns
    -------
    TemperatureBlocks or None
        The columns read when sliced, or ``None``.
    """
    from thermocal import units
    from thermocal.readers.table import ColumnsOnDemand

    cols = rec.columns
    if not isinstance(cols, ColumnsOnDemand) or not names or rec.source is None:
        return None
    for n in names:
        unit = rec.units.get(n)
        if not (
            cols.read_from_file(n) and unit and units.normalize_temperature_unit(unit) == "degC"
        ):
            return None
    import pyarrow.parquet as pq

    path = Path(rec.source)
    blocks = TemperatureBlocks(pq.ParquetFile(path), names, path)
    if blocks.shape[0] != rec.n_samples or blocks.largest_group > MAX_GROUP_ROWS:
        return None
    return blocks


def run_in_blocks(
    rec: Recording,
    signal: str | None,
    temps: Sequence[str] | None,
    known_input: float,
    *,
    validated: bool = False,
) -> RunData:
    """The run a fit uses (:meth:`RunData.from_recording` with ``temperature_unit="auto"``),
    its temperatures read block by block where :func:`temperature_blocks` can, held whole
    otherwise; the same checks and refusals either way.

    Parameters
    ----------
    rec : Recording
        The run as read.
    signal : str or None
        Signal column; None: the recording's only signal.
    temps : sequence of str or None
        Temperature columns; None: every one.
    known_input : float
        Known input to remove [canonical signal unit].
    validated : bool, optional
        ``rec`` has passed :meth:`Recording.validate` (its temperature columns are known
        to be finite: not read again to check it).  Default ``False``.

    Returns
    -------
    RunData
        The run.
    """
    from thermocal.models.rundata import RunData

    names = tuple(temps) if temps else rec.temperatures
    blocks = temperature_blocks(rec, names)
    if blocks is not None and (
        validated or all(all_finite(blocks.column(j)) for j in range(len(names)))
    ):
        sig, sig_unit = rec.signal(signal)
        if all_finite(rec.time_s) and all_finite(sig):
            return RunData(
                time_s=rec.time_s,
                temps_c=cast(FloatArray, blocks),
                signal=sig,
                temp_names=names,
                name=rec.source or rec.meta.run_id or "",
                known_input=known_input,
                signal_unit=sig_unit,
                temperature_unit="degC",
            )
    return RunData.from_recording(
        rec, signal, temps, known_input=known_input, temperature_unit="auto"
    )


__all__ = [
    "MAX_GROUP_ROWS",
    "MIN_ROWS_BY_BLOCKS",
    "TemperatureBlocks",
    "read_by_blocks",
    "run_in_blocks",
    "temperature_blocks",
]
