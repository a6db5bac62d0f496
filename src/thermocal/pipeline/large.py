"""Records too long for memory: whether a file is analysed window by window (from its
Parquet metadata, before a row is read) and the ``allan`` analysis of such a file, its
columns read a row group at a time into temporary files
(:mod:`thermocal.stability.streaming` does the maths on windows of them).

The temporary files (the samples, each stretch's phase, the octave levels) live in a
temporary folder beside nothing the user names (``$TMPDIR``, or ``scratch_dir``), removed
when the analysis ends, fails or is interrupted."""

from __future__ import annotations

import itertools
import math
import os
import tempfile
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule
from thermocal.errors import (
    GapWarning,
    MissingValueError,
    ThermocalInputError,
    TimestampError,
)
from thermocal.readers.common import (
    BYTES_PER_VALUE,
    WORKING_BYTES_PER_ROW,
    arrow_chunk_f64,
    memory_limit_bytes,
)
from thermocal.readers.options import ReadOptions
from thermocal.readers.table import ParquetColumns, open_parquet

if TYPE_CHECKING:
    import pyarrow as pa
    import pyarrow.parquet as pq

    from thermocal.metrics import MetricsOptions, MetricsResult
    from thermocal.recording import Recording
    from thermocal.stability.analysis import AllanAnalysis
    from thermocal.stability.streaming import BlockSource

else:
    pa = LazyModule("pyarrow")
    pq = LazyModule("pyarrow.parquet")

FloatArray = npt.NDArray[np.float64]

CHUNK_ROWS = 1 << 20
"""Rows per batch read from the Parquet file."""

HEAD_ROWS = 4096
"""Rows read through the ordinary reader to resolve the columns and units."""

MAX_DISTINCT_STEPS = 1 << 20
"""Distinct time steps kept for the exact median step of an irregular time column."""


def needs_streaming(
    path: str | Path, n_columns: int = 2, *, memory_budget: int | None = None
) -> bool:
    r"""Whether reading ``n_columns`` float64 columns of the Parquet file ``path`` whole
    would exceed the memory budget (the file's metadata only: no row is read).

    Parameters
    ----------
    path : str or Path
        The file; other formats than Parquet are never streamed (False).
    n_columns : int, optional
        Columns read (default 2: time and one signal).
    memory_budget : int, optional
        Memory a read may use [bytes] (default
        :func:`thermocal.readers.common.memory_limit_bytes`: ``THERMOCAL_MEMORY_LIMIT`` or
        half of ``MemAvailable``).

    Returns
    -------
    bool
        True when the in-memory read would not fit.

    Notes
    -----
    .. math:: \mathrm{need} = n_{\mathrm{rows}}\,(8\,n_{\mathrm{columns}} + 40)\ \mathrm{bytes}
    """
    p = Path(path)
    if p.suffix.lower() not in (".parquet", ".pq") or not p.is_file():
        return False
    try:
        rows = int(open_parquet(p, checksums=False).metadata.num_rows)
    except Exception:  # an unreadable file: the ordinary reader names what is wrong
        return False
    limit = memory_budget if memory_budget is not None else memory_limit_bytes()
    need = rows * (BYTES_PER_VALUE * n_columns + WORKING_BYTES_PER_ROW)
    return limit is not None and need > limit


class _RawFile:
    """float64 values appended to a file, read back by index range with ``pread`` (no
    memory map: the memory used is the window read, whatever the file's length; several
    threads may read at once)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.size = 0
        self._out: Any = open(path, "wb")  # noqa: SIM115 (closed by finish)
        self._fd = -1

    def write(self, values: FloatArray) -> None:
        np.ascontiguousarray(values, dtype=np.float64).tofile(self._out)
        self.size += int(values.size)

    def finish(self) -> _RawFile:
        if self._out is not None:
            self._out.close()
            self._out = None
            self._fd = os.open(self.path, os.O_RDONLY)
        return self

    def close(self) -> None:
        self.finish()
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1

    def read(self, start: int, stop: int) -> FloatArray:
        stop = min(stop, self.size)
        out = np.empty(max(stop - start, 0), dtype=np.float64)
        view, pos = out.data.cast("B"), 0
        while pos < out.nbytes:
            got = os.preadv(self._fd, [view[pos:]], start * 8 + pos)
            if got <= 0:
                raise OSError(f"{self.path}: short read")
            pos += got
        return out


class _TempStore:
    """Temporary files in one folder (:class:`thermocal.stability.streaming.BlockStore`);
    :meth:`close` closes every one still open (an analysis that fails or is interrupted)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.files: list[_RawFile] = []

    def create(self, name: str) -> _RawFile:
        f = _RawFile(self.folder / f"{name}.f64")
        self.files.append(f)
        return f

    def remove(self, source: BlockSource) -> None:
        if isinstance(source, _RawFile):
            source.close()
            source.path.unlink(missing_ok=True)

    def close(self) -> None:
        for f in self.files:
            f.close()


class _HeadColumns(ParquetColumns):
    """The first rows of a Parquet file for the ordinary reader: its columns, units and
    roles resolved exactly as when the file is read whole."""

    def __init__(self, pf: pq.ParquetFile, rows: int) -> None:
        super().__init__(pf)
        self.num_rows = min(rows, self.num_rows)

    def read_f64(self, names: Sequence[str]) -> None:
        """Nothing read ahead (:meth:`column_f64` reads the first rows)."""

    def column(self, name: str) -> pa.ChunkedArray:
        """The first rows of one column, as Arrow."""
        return _first_rows(self._pf, name, self.num_rows)

    def column_f64(self, name: str) -> FloatArray | None:
        """The first rows of one numeric column as float64 (None: not numeric)."""
        field_type = self._pf.schema_arrow.field(name).type
        if not (pa.types.is_integer(field_type) or pa.types.is_floating(field_type)):
            return None
        col = _first_rows(self._pf, name, self.num_rows)
        return np.concatenate([arrow_chunk_f64(c) for c in col.chunks])


def _first_rows(pf: pq.ParquetFile, name: str, rows: int) -> pa.ChunkedArray:
    """The first ``rows`` of one column, as Arrow."""
    batch = next(pf.iter_batches(batch_size=rows, columns=[name]))
    return pa.chunked_array([batch.column(0)])


@dataclass(frozen=True)
class _Plan:
    """What the head read settled: the columns, the time unit's factor, the signal's unit."""

    path: Path
    head: Recording
    time_col: str
    signal: str
    time_factor: float
    n_rows: int


def _plan(path: Path, read: ReadOptions, signal: str | None) -> _Plan:
    """Columns and units from the file's first rows, read by the ordinary reader."""
    from thermocal.readers import dispatch
    from thermocal.units import TIME_UNITS, UnitOptions

    if read.rate_hz is not None:
        raise ThermocalInputError.naming(
            f"{path}: a record analysed window by window takes its time from its time "
            "column; drop {rate_hz}",
            "rate_hz",
        )
    if read.chamber_log is not None:
        raise ThermocalInputError.naming(
            f"{path}: a record analysed window by window is read without a chamber log; drop "
            "{chamber_log}, or join it first (thermocal profile join -o) and cut the record",
            "chamber_log",
        )
    obj, info = dispatch.open_table(path, read)
    pf = pq.ParquetFile(path)
    opts = UnitOptions(read.time_unit, read.signal_unit, read.temp_unit, read.temp_conversion)
    head = dispatch.table_recording(
        path, _HeadColumns(pf, HEAD_ROWS), info, read, opts, meta=None, keep_other=False,
        skipped=None, stated=None, guess_temperatures=False,
    )  # fmt: skip
    del obj
    time_col, _sigs, _temps = dispatch.column_roles(
        path, list(pf.schema_arrow.names), info, read.time, read.signals, read.temperatures, False
    )
    if not head.signals:
        from thermocal.pipeline.reading import check_recording

        check_recording(head, read, validate=False)
    name = signal or head.signals[0]
    factor = 1.0 if head.time_unit == "s" else float(TIME_UNITS[head.time_unit])
    return _Plan(path, head, time_col, name, factor, int(pf.metadata.num_rows))


@dataclass
class _TimePass:
    """The time column's checks and nominal step gathered chunk by chunk, as
    :func:`thermocal.recording.scan_time` finds them on the whole column."""

    first: float = math.nan
    last: float = math.nan
    lo: float = math.inf
    hi: float = -math.inf
    n: int = 0
    steps: dict[float, int] | None = None

    def add(self, t: FloatArray, row0: int, where: Path) -> None:
        """Check one chunk's times (finite, increasing also across the chunk boundary)."""
        if not np.isfinite(t).all():
            bad = row0 + int(np.flatnonzero(~np.isfinite(t))[0])
            raise TimestampError(f"{where}: time is not finite at row {bad}")
        if self.n:
            dt = np.diff(np.concatenate(([self.last], t)))
            base = row0 - 1
        else:
            self.first, self.steps = float(t[0]), {}
            dt = np.diff(t)
            base = row0
        if dt.size:
            if (dt <= 0).any():
                r = base + int(np.argmax(dt <= 0)) + 1
                raise TimestampError(f"{where}: time does not increase at row {r}")
            self.lo, self.hi = min(self.lo, float(dt.min())), max(self.hi, float(dt.max()))
            if self.steps is not None and self.hi - self.lo > 0:
                u, c = np.unique(dt, return_counts=True)
                for v, k in zip(u.tolist(), c.tolist(), strict=True):
                    self.steps[v] = self.steps.get(v, 0) + k
                if len(self.steps) > MAX_DISTINCT_STEPS:
                    self.steps = None  # too scattered for an exact median from counts
        self.last = float(t[-1])
        self.n += int(t.size)

    def interval(self, where: Path) -> float:
        """The nominal step: the mean step on a regular grid, else the exact median step."""
        from thermocal.recording import REGULAR_GRID_ULPS

        stamp_ulp = math.ulp(max(abs(self.first), abs(self.last)))
        if self.lo > 0 and self.hi - self.lo <= REGULAR_GRID_ULPS * stamp_ulp:
            return (self.last - self.first) / (self.n - 1)
        if not self.steps:
            raise TimestampError(
                f"{where}: the time steps take more than {MAX_DISTINCT_STEPS} distinct values: "
                "too scattered to find the nominal step of a record this long window by "
                "window; resample it to a regular grid, or cut it"
            )
        return _median(self.steps)


def _median(steps: dict[float, int]) -> float:
    """The median of the steps counted in ``steps`` (numpy's: the mean of the middle two)."""
    total = sum(steps.values())
    lo_i, hi_i = (total - 1) // 2, total // 2
    seen, lo_v, hi_v = 0, math.nan, math.nan
    for v in sorted(steps):
        nxt = seen + steps[v]
        if seen <= lo_i < nxt:
            lo_v = v
        if seen <= hi_i < nxt:
            hi_v = v
            break
        seen = nxt
    return float(np.mean([lo_v, hi_v]))


def _chunks(plan: _Plan, signal: bool = True) -> Iterator[tuple[FloatArray, FloatArray]]:
    """(time [s], signal as read) a batch of rows at a time, only these columns (the
    signal empty when not asked)."""
    pf = pq.ParquetFile(plan.path, buffer_size=1 << 20, pre_buffer=False)
    cols = [plan.time_col, plan.signal] if signal else [plan.time_col]
    for batch in pf.iter_batches(batch_size=CHUNK_ROWS, columns=cols):
        t = np.asarray(arrow_chunk_f64(batch.column(plan.time_col)), dtype=np.float64)
        if plan.time_factor != 1.0:
            t = t * plan.time_factor
        raw = arrow_chunk_f64(batch.column(plan.signal)) if signal else np.zeros(0)
        yield t, raw


def _in_data_unit(plan: _Plan, t: FloatArray, raw: FloatArray) -> tuple[FloatArray, str]:
    """One chunk of the signal in the data's own unit, by the same conversions as the
    whole column (:func:`thermocal.stability.analysis.signal_in_data_unit`)."""
    import dataclasses

    from thermocal.stability.analysis import signal_in_data_unit

    rec = dataclasses.replace(plan.head, time_s=t, columns={plan.signal: raw})
    v, unit = signal_in_data_unit(rec, plan.signal)
    return np.array(v, dtype=np.float64), unit


@dataclass
class _Spooled:
    """The record's samples in a temporary file, with what the pass found."""

    rate: BlockSource
    times: _TimePass
    unit: str


def _spool(
    plan: _Plan,
    store: _TempStore,
    summary: Any,
    advance: Callable[[float], None],
    time: _RawFile | None = None,
) -> _Spooled:
    """Pass 1: every row group of the two columns checked and stored (the time too when
    a store for it is given)."""
    rate = store.create("rate")
    times = _TimePass()
    unit, row0 = "", 0
    for t, raw in _chunks(plan):
        times.add(t, row0, plan.path)
        v, unit = _in_data_unit(plan, t, raw)
        if not math.isfinite(float(v.sum())):
            bad = row0 + int(np.flatnonzero(~np.isfinite(v))[0])
            raise MissingValueError(
                f"{plan.path}: the column {plan.signal!r} has a NaN or infinite value at row "
                f"{bad}; remove those rows or split the record"
            )
        summary.add(v)
        rate.write(v)
        if time is not None:
            time.write(t)
        row0 += int(t.size)
        advance(t.size)
    return _Spooled(rate.finish(), times, unit)


def _segments(plan: _Plan, times: _TimePass) -> tuple[list[slice], float]:
    """The gap-free stretches (:func:`thermocal.recording.contiguous_slices`: a step longer
    than 1.5 nominal steps is a gap; the time column read again only when there is one)
    and the nominal step, the gaps said in one warning."""
    from thermocal.recording import GAP_FACTOR

    n, where = times.n, plan.path
    if n < 2:
        return [slice(0, n)], math.nan
    med = times.interval(where)
    bounds, starts, total = [0], [], 0.0
    if n >= 3 and med > 0 and times.hi > GAP_FACTOR * med:
        prev, a = math.nan, 0
        for t, _raw in _chunks(plan, signal=False):
            tt = np.concatenate(([prev], t)) if a else t  # the step into the chunk too
            dt = np.diff(tt)
            base = a - 1 if a else a
            for i in np.flatnonzero(dt > GAP_FACTOR * med).tolist():
                bounds.append(base + i + 1)
                starts.append(float(tt[i]) - times.first)
                total += float(dt[i])
            prev, a = float(t[-1]), a + int(t.size)
    bounds.append(n)
    if len(bounds) > 2:
        warnings.warn(
            GapWarning(
                f"{where}: {len(bounds) - 2} gaps in time ({total:.6g} s in all), first after "
                f"row {bounds[1] - 1} at {starts[0]:.6g} s"
            ),
            stacklevel=2,
        )
    return [slice(a, b) for a, b in itertools.pairwise(bounds) if b > a], med


def allan_streamed(
    path: str | Path,
    read: ReadOptions,
    signal: str | None = None,
    *,
    taus: Any = "octave",
    confidence: float | None = None,
    where: str = "",
    scratch_dir: str | Path | None = None,
    progress: Callable[[float], None] | None = None,
) -> AllanAnalysis:
    """``thermocal allan``'s default analysis of one channel of a Parquet file of any length,
    in bounded memory: its time and signal columns read a row group at a time into
    temporary files, then analysed window by window
    (:func:`thermocal.stability.streaming.streamed_channel`).

    Parameters
    ----------
    path : str or Path
        The Parquet file.
    read : ReadOptions
        How it is read (columns, units), as for :func:`thermocal.readers.read_recording`.
    signal : str, optional
        The channel (default the file's first signal).
    taus : str or sequence of float, optional
        ``"octave"`` (default) or octave τ [s].
    confidence : float, optional
        Confidence level of the intervals (default one sigma).
    where : str, optional
        The file as named in messages (default ``path``).
    scratch_dir : str or Path, optional
        Folder of the temporary files (default ``$TMPDIR``); they take about 2.5 times
        8 bytes a row at their largest and are removed when the analysis ends, fails or
        is interrupted.
    progress : callable, optional
        Called with each fraction of the work done (they add up to 1).

    Returns
    -------
    thermocal.stability.analysis.AllanAnalysis
        One channel's ADEV, intervals, noise terms and quantization.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A column or unit the file does not give, time that is not finite or does not
        increase, a NaN sample, a τ set other than octave, or an option of the in-memory
        analysis only (``rate_hz``).
    """
    from thermocal.stability import streaming
    from thermocal.stability.analysis import AllanAnalysis
    from thermocal.stability.edf import ONE_SIGMA_CONFIDENCE

    p = Path(path)
    plan = _plan(p, read, signal)
    where = where or str(p)
    spool_share = 0.15
    with tempfile.TemporaryDirectory(prefix="thermocal-allan-", dir=scratch_dir) as d:
        store = _TempStore(Path(d))
        try:
            summary = streaming.ValueSummary(plan.n_rows)
            rows = max(plan.n_rows, 1)
            sp = _spool(
                plan,
                store,
                summary,
                lambda k: progress(spool_share * k / rows) if progress else None,
            )
            segments, med = _segments(plan, sp.times)
            tau0 = plan.head.meta.sample_interval_s or med
            record = streaming.StreamedRecord(sp.rate, float(tau0), tuple(segments))
            ch = streaming.streamed_channel(
                record, summary, plan.signal, sp.unit, taus=taus,
                confidence=ONE_SIGMA_CONFIDENCE if confidence is None else confidence,
                where=where, store=store,
                progress=(lambda f: progress((1 - spool_share) * f)) if progress else None,
            )  # fmt: skip
            store.remove(sp.rate)
        finally:
            store.close()
    return AllanAnalysis((plan.signal,), channels={plan.signal: ch})


def metrics_streamed(
    path: str | Path,
    read: ReadOptions,
    signal: str | None,
    options: MetricsOptions,
    *,
    scratch_dir: str | Path | None = None,
    progress: Callable[[float], None] | None = None,
) -> dict[str, MetricsResult]:
    """``thermocal metrics`` of one rate channel of a Parquet file of any length, without
    temperatures, in bounded memory: its time and signal read a row group at a time into
    temporary files (removed at the end, on failure or interruption), then
    :func:`thermocal.metrics_streaming.streamed_metrics`.

    Parameters
    ----------
    path : str or Path
        The Parquet file.
    read : ReadOptions
        How it is read (columns, units).
    signal : str, optional
        The channel (default the file's first signal).
    options : MetricsOptions
        Averaging time, earth-rate removal, the drift angle's reference (no temperatures).
    scratch_dir : str or Path, optional
        Folder of the temporary files (default ``$TMPDIR``; about 16 bytes a row).
    progress : callable, optional
        Called with each fraction of the work done.

    Returns
    -------
    dict of str to MetricsResult
        The channel's figures.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        What the in-memory metrics refuse, and temperature columns (their hold stages are
        computed in memory only).
    """
    from thermocal import metrics as mt
    from thermocal.metrics_streaming import streamed_metrics
    from thermocal.stability import streaming

    p = Path(path)
    plan = _plan(p, read, signal)
    if options.temps or plan.head.temperatures:
        names = ", ".join(options.temps or plan.head.temperatures)
        raise ThermocalInputError.naming(
            f"{p}: a record analysed window by window has no temperature hold stages; "
            f"drop the temperature column(s) {names} ({{temps}}), or cut the record",
            "temps",
        )
    canon = plan.head.signal(plan.signal)[1]
    unit, k = mt.data_unit_of(plan.head, plan.signal, canon)
    earth = mt.earth_rate_to_remove(
        plan.head, plan.signal, canon, unit, k, options.latitude_deg, options.axis
    )
    share = 0.6
    with tempfile.TemporaryDirectory(prefix="thermocal-metrics-", dir=scratch_dir) as d:
        store = _TempStore(Path(d))
        try:
            rows = max(plan.n_rows, 1)
            times = store.create("time")
            sp = _spool(
                plan, store, streaming.ValueSummary(plan.n_rows),
                lambda n: progress(share * n / rows) if progress else None, time=times,
            )  # fmt: skip
            segments, med = _segments(plan, sp.times)
            time = times.finish()
            res = streamed_metrics(
                time, sp.rate, segments, float(plan.head.meta.sample_interval_s or med),
                name=plan.signal, unit=sp.unit, earth_rate=earth,
                averaging_s=options.averaging_s, drift_reference_s=options.drift_reference_s,
                drift_bias=options.drift_bias, store=store, where=str(p),
                progress=(lambda f: progress((1 - share) * f)) if progress else None,
            )  # fmt: skip
        finally:
            store.close()
    return {plan.signal: res}


__all__ = ["allan_streamed", "metrics_streamed", "needs_streaming"]
