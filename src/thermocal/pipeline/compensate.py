"""Compensation of files with a fitted model; the maths (in memory, in chunks, live) is
:mod:`thermocal.compensate.kernels`.

A model gives the temperature-induced part of the signal, ``ŷ = model(T, Ṫ, …)``;
the compensated output is ``F' = F − ŷ`` (output F' = F − ΔF).

Three ways to apply a model, all giving the same numbers:

* :func:`compensate_run` — in memory, ``model.predict(run)`` on a whole run.
* :func:`compensate_file` — a CSV or Parquet file of any size, read and written
  in chunks with constant memory.  Every chunk is predicted together with the
  *context* the model needs (the samples since power-on that fix its start-up
  state and the last Δt seconds that feed the Ṫ buffer, see
  :meth:`~thermocal.models.base.TemperatureModel.chunk_context`); because ``predict``
  is causal (models/base.py
  contract) the values of the chunk's own rows equal those of a whole-file
  ``predict``.  Families without a context rule are streamed sample by sample
  (:class:`StreamingCompensator`), which is exact but slower.
* :class:`StreamingCompensator` — live data, one sample at a time; it wraps the
  family's :class:`~thermocal.models.base.ModelStream`, which carries exactly the
  state the model needs and resets its rate estimate after a gap (a step longer
  than ``GAP_FACTOR`` × the sample interval).

Units: the model predicts in its signal unit (``model.signal_unit``); data in
another unit of the same kind are converted with :mod:`thermocal.units`, and
the ``<signal>_model`` / ``<signal>_comp`` columns are written in the data
column's own unit.  A model and data of different kinds (°/h against mg) is a
:class:`~thermocal.errors.UnitError` naming both.
"""

from __future__ import annotations

import dataclasses
import gzip
import io
import json
import math
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from thermocal import units
from thermocal._lazy import LazyModule
from thermocal.compensate.kernels import (
    AbsoluteFigures,
    ChunkPredictor,
    absolute_error_worse,
    absolute_worse_message,
    check_signal_kind,
    model_scale_factor,
    temperature_inputs,
    unit_factor,
    zero_reference,
)
from thermocal.defaults import DEFAULT_CHUNK_ROWS
from thermocal.errors import (
    ExtrapolationWarning,
    FileFormatError,
    MissingColumnError,
    MissingValueError,
    ParameterError,
    PlausibilityWarning,
    ThermocalInputError,
    ThermocalWarning,
    TimestampError,
    UnitError,
)
from thermocal.models.base import TemperatureModel
from thermocal.models.ranges import outside_range_dict
from thermocal.models.rundata import check_sensor_id
from thermocal.outputs import refuse_special_input, sidecar_path, warn_formula_names
from thermocal.readers.chamber_log import (
    ChamberStream,
    chamber_clock_join,
    chamber_needs_series,
    read_chamber_log,
)
from thermocal.readers.common import default_time_column, names_list
from thermocal.readers.dispatch import (
    TIME_HINT_PARAMETERS,
    read_recording,
    read_whole_table,
    time_hint,
)
from thermocal.readers.formats import FileFormat, format_of
from thermocal.readers.options import CHAMBER_COLUMN, ChamberLogSpec, ReadOptions
from thermocal.readers.table import load_sidecar, numeric_column
from thermocal.recording import (
    ABSOLUTE_ZERO_C,
    FEW_SAMPLES,
    META_FORMAT,
    META_KEY,
    META_VERSION,
    PLAUSIBLE_COUNTS,
    PLAUSIBLE_SIGNAL,
    FloatArray,
    Metadata,
    Recording,
    median_interval,
)
from thermocal.writers import atomic_write_path, check_not_input, write_json, written_format

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq
else:
    pd = LazyModule("pandas")
    pa = LazyModule("pyarrow")
    pq = LazyModule("pyarrow.parquet")


MODEL_SUFFIX = "_model"
COMP_SUFFIX = "_comp"


@dataclass(frozen=True)
class CompensateFileResult:
    """Summary of :func:`compensate_file`.

    Attributes
    ----------
    output : str
        The output written.
    n_rows, n_chunks : int
        Rows compensated and chunks read.
    signal : str
        The signal column.
    model_column, comp_column : str
        The columns added: the model's prediction and the compensated signal.
    unit : str
        The data's unit.
    streamed : bool
        The family has no chunk-context rule: the file was compensated sample by sample
        (:class:`StreamingCompensator`, exact but slower).
    rms_before, rms_after : float
        RMS about the mean before and after [data unit].
    extra : dict
        Further figures.
    mean_before, mean_after : float
        Mean error about ``zero_reference`` [data unit].
    rms_about_zero_before, rms_about_zero_after : float
        RMS about ``zero_reference`` [data unit].
    max_abs_before, max_abs_after : float
        Largest |error| about ``zero_reference`` [data unit].
    zero_reference : dict
        ``{value, unit, what}``: the level an ideal sensor would output.
    absolute_error_worse : bool
        The compensation made the rms about zero or the largest |error| worse by over 1 %.
    outside_range : dict
        How far the file leaves the model's calibrated ranges, per input.
    outside_calibrated_range : bool
        The file leaves them.
    """

    output: str
    n_rows: int
    n_chunks: int
    signal: str
    model_column: str
    comp_column: str
    unit: str
    streamed: bool
    rms_before: float
    """Rms of the signal about its mean, whole file, per sample [data unit]."""
    rms_after: float
    """Rms of the compensated signal about its mean [data unit]."""
    extra: dict[str, Any] = field(default_factory=dict)
    mean_before: float = float("nan")
    """What the sensor's user sees (:class:`~thermocal.compensate.kernels.AbsoluteFigures`),
    per sample about :attr:`zero_reference`: ``mean(F − K)`` of the signal [data unit]."""
    mean_after: float = float("nan")
    """``mean(F' − K)`` of the compensated signal [data unit]."""
    rms_about_zero_before: float = float("nan")
    """``sqrt(mean((F − K)²))`` [data unit]."""
    rms_about_zero_after: float = float("nan")
    """``sqrt(mean((F' − K)²))`` [data unit]."""
    max_abs_before: float = float("nan")
    """``max |F − K|`` [data unit]."""
    max_abs_after: float = float("nan")
    """``max |F' − K|`` [data unit]."""
    zero_reference: dict[str, Any] = field(default_factory=dict)
    """``{value [data unit], unit, what}``: the level an ideal sensor would output."""
    absolute_error_worse: bool = False
    """The compensation raised the rms about zero or the max |error| by more than 1 %."""
    outside_range: dict[str, Any] = field(default_factory=dict)
    """How far the file leaves the model's calibrated ranges, per input
    (:func:`~thermocal.models.ranges.outside_range_dict`)."""
    outside_calibrated_range: bool = False

    def to_dict(self) -> dict[str, Any]:
        """The fields (``extra`` merged in) as a dict, for the JSON result."""
        d = {k: getattr(self, k) for k in self.__dataclass_fields__ if k != "extra"}
        d.update(self.extra)
        return d


class _RunningMoments:
    """Count, mean and sum of squared deviations merged chunk by chunk (Chan et al. 1979,
    "Updating formulae and a pairwise algorithm for computing sample variances")."""

    def __init__(self) -> None:
        self.n = 0
        self.mean = 0.0
        self.m2 = 0.0
        self.lo = math.inf
        self.hi = -math.inf

    def add(self, x: FloatArray) -> None:
        nb = int(x.size)
        if nb == 0:
            return
        self.lo = min(self.lo, float(np.min(x)))
        self.hi = max(self.hi, float(np.max(x)))
        mb = float(np.mean(x))
        m2b = float(np.sum((x - mb) ** 2))
        n = self.n + nb
        delta = mb - self.mean
        self.mean += delta * nb / n
        self.m2 += m2b + delta * delta * self.n * nb / n
        self.n = n

    def rms(self) -> float:
        """Root mean square about the mean, ``sqrt(Σ(x − x̄)²/n)``."""
        return math.sqrt(self.m2 / self.n) if self.n else float("nan")

    def about(self, reference: float) -> AbsoluteFigures:
        """Mean, rms and largest magnitude about ``reference`` (same unit):
        ``sqrt(Σ(x − K)²/n) = sqrt(m2/n + (x̄ − K)²)``, ``max |x − K| = max(x_max − K,
        K − x_min)``."""
        if not self.n:
            return AbsoluteFigures(float("nan"), float("nan"), float("nan"))
        d = self.mean - reference
        return AbsoluteFigures(
            d, math.sqrt(self.m2 / self.n + d * d), max(self.hi - reference, reference - self.lo)
        )


def _source_format(path: str | Path, read: ReadOptions) -> tuple[Path, FileFormat, ReadOptions]:
    """The input of a chunked pass, its registered format and how to read it: a format that
    cannot be read in chunks is refused naming the file, its format and what to do; a
    station folder's sensor (``DIR`` with ``topic`` ``ID``) is read as ``DIR/ID``."""
    src = Path(path)
    fmt = format_of(src)
    if fmt.chunks == "none":
        raise FileFormatError(
            f"{src}: {fmt.title} ({fmt.name} format) cannot be read in chunks, which "
            "compensate needs; write it as CSV or Parquet first (thermocal.read_recording, "
            "then thermocal.write_recording)"
        )
    if fmt.locate is not None:
        return fmt.locate(src, read.topic), fmt, read.replace(topic=None)
    if read.topic is not None and "topic" not in fmt.options:
        raise ThermocalInputError.naming(
            f"{src}: {{topic}} is for flight-controller logs (.ulg, .bin)", "topic"
        )
    return src, fmt, read


def _slices(table: pd.DataFrame, chunk_rows: int) -> Iterator[pd.DataFrame]:
    """A table read whole, ``chunk_rows`` rows at a time."""
    for a in range(0, len(table), chunk_rows):
        yield table.iloc[a : a + chunk_rows].reset_index(drop=True)


def _check_plausible(
    temps_c: FloatArray,
    names: Sequence[str],
    raw: FloatArray,
    unit: str,
    src: Path,
    row0: int,
    signal: str = "",
    counts_scale: tuple[float, str, float] | None = None,
) -> None:
    """The chunk's values against :func:`thermocal.recording.plausibility_problems`' limits:
    a temperature below absolute zero or a signal beyond any sensor is an input error.
    Raw counts are checked after their scale factor ``counts_scale`` (K, unit of K, τ [s])
    when one is given, else against :data:`~thermocal.recording.PLAUSIBLE_COUNTS`."""
    below = temps_c < ABSOLUTE_ZERO_C
    if below.any():
        r, j = (int(v) for v in np.argwhere(below)[0])
        raise ThermocalInputError(
            f"{src}: temperature column {names[j]!r} reads {temps_c[r, j]:.6g} °C at row "
            f"{row0 + r}, below absolute zero (−273.15 °C): a wrong unit, offset or conversion"
        )
    kind = units.signal_kind(unit)
    with np.errstate(over="ignore", invalid="ignore"):
        if kind != "raw":
            canon, canon_unit = units.to_canonical(raw, unit, finite=False)
            limit = PLAUSIBLE_SIGNAL[kind]
        elif counts_scale is None:
            canon, canon_unit, limit = raw, unit, PLAUSIBLE_COUNTS
        else:
            canon, canon_unit = units.counts_to_physical(raw, *counts_scale, finite=False)
            limit = PLAUSIBLE_SIGNAL["rate" if canon_unit == "deg/h" else "accel"]
    bad = ~np.isfinite(canon) | (np.abs(canon) > limit)
    if bad.any():
        r = int(np.argmax(bad))
        col = f"column {signal!r} " if signal else ""
        raise ThermocalInputError(
            f"{src}: signal {col}reads {raw[r]:.6g} {unit} at row {row0 + r} "
            f"({float(canon[r]):.6g} {canon_unit}), beyond any sensor "
            f"(|value| ≤ {limit:g} {canon_unit}): wrong unit, scale factor or corrupt data"
        )


def _check_finite(arr: FloatArray, label: str, path: Path, row0: int) -> None:
    bad = ~np.isfinite(arr)
    if bad.any():
        row = int(np.argwhere(bad)[0][0])
        raise MissingValueError(
            f"{path}: {label} has a NaN/non-finite value at row {row0 + row}; clean or cut the "
            "data first"
        )


def _append_columns(
    chunk: pd.DataFrame | pa.RecordBatch, new: dict[str, FloatArray]
) -> pd.DataFrame | pa.RecordBatch:
    if isinstance(chunk, pa.RecordBatch):
        arrays = [*chunk.columns, *(pa.array(v, type=pa.float64()) for v in new.values())]
        return pa.RecordBatch.from_arrays(arrays, names=[*chunk.schema.names, *new.keys()])
    out = chunk.copy()
    for k, v in new.items():
        out[k] = v
    return out


class _ParquetChunks:
    """Writes chunks to a Parquet file, the metadata in its key-value store."""

    sidecar = False
    """Whether the output's metadata also goes to a ``FILE.meta.json`` sidecar."""

    def __init__(self, tmp: Path, info: dict[str, Any]) -> None:
        self.tmp = tmp
        self.info = info
        self._pq: pq.ParquetWriter | None = None
        self._schema: pa.Schema | None = None

    def write(self, chunk: pd.DataFrame | pa.RecordBatch) -> None:
        if isinstance(chunk, pd.DataFrame):
            df = chunk.copy()
            for c in df.columns:
                dtype = df[c].dtype
                if pd.api.types.is_bool_dtype(dtype):
                    continue
                if pd.api.types.is_numeric_dtype(dtype):
                    df[c] = df[c].astype(np.float64)
                else:
                    df[c] = df[c].astype("string")
            table = pa.Table.from_pandas(df, preserve_index=False)
        else:
            table = pa.Table.from_batches([chunk])
        if self._pq is None:
            meta = dict(table.schema.metadata or {})
            meta.pop(b"pandas", None)
            meta[META_KEY.encode()] = json.dumps(self.info).encode("utf-8")
            self._schema = table.schema.with_metadata(meta)
            # dictionary encoding of float columns costs 3x the write time and rarely
            # shrinks measured data; keep it for the others (ids, counts, text)
            dict_cols = [f.name for f in self._schema if not pa.types.is_floating(f.type)]
            self._pq = pq.ParquetWriter(self.tmp, self._schema, use_dictionary=dict_cols)
        assert self._schema is not None
        self._pq.write_table(table.cast(self._schema))

    def close(self) -> None:
        if self._pq is not None:
            self._pq.close()


class _CsvChunks:
    """Writes chunks to a CSV file (its metadata goes to the sidecar)."""

    sidecar = True

    def __init__(self, tmp: Path, info: dict[str, Any]) -> None:
        self.tmp = tmp
        self._fh: Any = None
        self._first = True

    def write(self, chunk: pd.DataFrame | pa.RecordBatch) -> None:
        df = chunk.to_pandas() if isinstance(chunk, pa.RecordBatch) else chunk
        if self._fh is None:
            self._fh = open(self.tmp, "w", encoding="utf-8", newline="")  # noqa: SIM115
        df.to_csv(self._fh, index=False, header=self._first, lineterminator="\n")
        self._first = False

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()


class _GzipCsvChunks(_CsvChunks):
    """Writes chunks to a gzip-compressed CSV file (``out.csv.gz``): no name or time in the
    gzip header, so the same input gives the same bytes."""

    def write(self, chunk: pd.DataFrame | pa.RecordBatch) -> None:
        if self._fh is None:
            self._file = open(self.tmp, "wb")  # noqa: SIM115
            raw = gzip.GzipFile(filename="", mode="wb", fileobj=self._file, mtime=0)
            self._fh = io.TextIOWrapper(raw, encoding="utf-8", newline="")
        super().write(chunk)

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()  # flushes and ends the gzip stream, which leaves the file open
            self._file.close()


_CHUNK_WRITERS: dict[str, type[_ParquetChunks] | type[_CsvChunks]] = {
    "parquet": _ParquetChunks,
    "csv": _CsvChunks,
}
"""The chunked writer of each output format :func:`thermocal.writers.written_format` names."""


def _chunk_writer(kind_out: str, dst: Path) -> type[_ParquetChunks] | type[_CsvChunks]:
    """The chunked writer of ``dst``: its format's, gzip-compressed for a ``.csv.gz``."""
    if kind_out == "csv" and dst.name.lower().endswith(".gz"):
        return _GzipCsvChunks
    return _CHUNK_WRITERS[kind_out]


def compensate_file(
    model: TemperatureModel,
    path: str | Path,
    out: str | Path,
    read: ReadOptions | None = None,
    *,
    signal: str | None = None,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
    extrapolate: bool = False,
    known_input: float = 0.0,
    on_progress: Callable[[int], None] | None = None,
) -> CompensateFileResult:
    """Compensate a recording file into ``out`` with constant memory.

    ``out`` keeps every input column and adds ``<signal>_model`` (ŷ) and
    ``<signal>_comp`` (``F − ŷ``), both in the data column's unit.  One channel of
    :func:`compensate_channels`.

    Parameters
    ----------
    model : TemperatureModel
        A fitted model; its temperature columns are read from the file.
    path : str or Path
        The recording, in any registered format that can be read in chunks
        (:mod:`thermocal.readers.formats`).
    out : str or Path
        The output, CSV (with its ``FILE.meta.json`` sidecar) or Parquet; written to a
        temporary name and renamed when complete.  It may not be ``path``.
    read : ReadOptions, optional
        How the file is read (:class:`~thermocal.readers.options.ReadOptions`): time column
        and units, ``temp_conversion`` for raw-count temperatures (over the file's
        metadata), a log's topic, a text log's layout; ``chamber_log``: a chamber's own log
        joined once for the whole recording (a first pass over its time) and given to each
        chunk at its times as the column ``chamber`` [°C], kept in ``out``.
    signal : str, optional
        The signal column (default: the model's ``signal_name``).
    chunk_rows : int
        Rows read and written at a time (at least 2).
    extrapolate : bool
        Allow temperatures outside the fitted range (a warning instead of an error).
    known_input : float
        Known input [model unit] (earth rate, a gravity component) removed from what the
        model sees (a bank's start-up selection).
    on_progress : callable, optional
        Called with the number of rows done after each chunk.

    Returns
    -------
    CompensateFileResult
        Rows, chunks, the added columns and their unit, and the figures before and after
        (rms about the mean, mean, rms and largest error about the ideal output).

    Raises
    ------
    thermocal.errors.FileFormatError
        No registered format reads the file, or its format cannot be read in chunks.
    thermocal.errors.MissingColumnError
        The signal, time or a model temperature column is absent (the missing and the
        available columns are named).
    thermocal.errors.UnitError
        The model's and the data's signal units differ in kind; temperatures in raw counts
        without a conversion for a °C model, or in °C for a counts model.
    thermocal.errors.TimestampError
        Time not increasing.
    thermocal.errors.MissingValueError
        NaN in a used column.

    Notes
    -----
    The model gives the temperature-induced part of the output, the compensated output is

    .. math:: F'_k = F_k - \\hat y(T_k, \\dot T_k, \\ldots)

    Units and temperature conversions are resolved once
    (:func:`thermocal.units.resolve_inputs`): ``read``, then the file's sidecar or Parquet
    metadata, the unit in the column name, what the model file recorded of its inputs
    (:meth:`TemperatureModel.input_units`), else a default stated in a warning.  Chunks
    are predicted with their context (:class:`~thermocal.compensate.kernels.ChunkPredictor`:
    the samples since power-on and the last Δt seconds of the rate buffer), so the result
    equals an in-memory ``predict`` of the whole file.

    References
    ----------
    *A modelling and validation method for the temperature compensation model of a
    ring-laser gyroscope*, Chinese invention patent, published 2017 (the compensated output
    :math:`F' = F - \\hat y`); the References of ``docs/methods.md``.
    """
    sig = signal or model.signal_name
    return compensate_channels(
        [(sig, model)],
        path,
        out,
        read,
        chunk_rows=chunk_rows,
        extrapolate=extrapolate,
        known_input=known_input,
        on_progress=on_progress,
        signal_given=signal is not None,
    )[0]


@dataclass
class _ChannelPlan:
    """What one channel of :func:`compensate_channels` needs per chunk."""

    model: TemperatureModel
    signal: str
    model_col: str
    comp_col: str
    data_unit: str
    temp_names: list[str]
    convs: dict[str, units.TemperatureConversion | None]
    temp_units: dict[str, str]
    md: Metadata
    predictor: ChunkPredictor
    time_unit: str = "s"
    factor: float | None = None
    zero: tuple[float, str] = (0.0, "0")
    """The level an ideal sensor would output [model unit] and what it is."""
    before: _RunningMoments = field(default_factory=lambda: _RunningMoments())
    after: _RunningMoments = field(default_factory=lambda: _RunningMoments())


def compensate_channels(
    channels: Sequence[tuple[str, TemperatureModel]],
    path: str | Path,
    out: str | Path,
    read: ReadOptions | None = None,
    *,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
    extrapolate: bool = False,
    known_input: float = 0.0,
    on_progress: Callable[[int], None] | None = None,
    signal_given: bool = True,
) -> list[CompensateFileResult]:
    """Compensate several channels of one file in one chunked pass with constant memory.

    Every chunk is read once, its time checked once, each distinct temperature input
    converted once, and every channel adds its ``<signal>_model`` and ``<signal>_comp`` in
    its own data column's unit (:func:`compensate_file` gives the rules of one channel).

    Parameters
    ----------
    channels : sequence of (str, TemperatureModel)
        ``(signal column, fitted model)`` pairs, each column once.
    path, out : str or Path
        The recording and the output (as :func:`compensate_file`).
    read : ReadOptions, optional
        How the file is read; ``read.signal_unit`` is one unit for all channels or one per
        channel (``"deg/s,deg/s,deg/s,mg,mg,mg"``).
    chunk_rows, extrapolate, known_input, on_progress
        As :func:`compensate_file`.
    g_sensitivity : {"apply", "off"}
        A gyro triad's g-sensitivity taken off or not (:func:`compensate_triads`).
    signal_given : bool
        Whether the signal columns were named by the user (a missing one is then said as
        theirs, not the model's).

    Returns
    -------
    list of CompensateFileResult
        One per channel, in ``channels``' order.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        No channel, a column twice, or any error of :func:`compensate_file`.
    """
    src, fmt, r = _source_format(path, read or ReadOptions())
    dst = Path(out)
    kind_out = written_format(dst)
    check_not_input(dst, [src])
    _check_chunk_rows(chunk_rows)
    if not channels:
        raise ThermocalInputError("no channel to compensate")
    sig_list = [c for c, _m in channels]
    if len(set(sig_list)) != len(sig_list):
        raise ThermocalInputError(f"a signal column appears twice: {sig_list}")
    source = _chamber_columns(_open_source(src, fmt, r), r.chamber_log)
    sig_opts = units.per_signal_unit(r.signal_unit, sig_list)
    ctx = _FileContext(src, source.names, source.info, source.time_col, source.available,
                       signal_given)  # fmt: skip
    opts = units.UnitOptions(
        time_unit=r.time_unit, temp_unit=r.temp_unit, temp_conversion=r.temp_conversion
    )
    plans = [
        _channel_plan(ctx, sig_name, model, sig_opts[sig_name], opts,
                      extrapolate=extrapolate, known_input=known_input,
                      name=str(src) if len(channels) == 1 else f"{src} [{sig_name}]")
        for sig_name, model in channels
    ]  # fmt: skip
    t_units = {plan.time_unit for plan in plans}
    if len(t_units) > 1:
        raise UnitError.naming(
            f"{src}: the channels' models disagree on the time unit "
            f"({' and '.join(sorted(t_units))}); give {{time_unit}}",
            "time_unit",
        )
    t_unit = plans[0].time_unit
    used = [(c, p.convs[c]) for p in plans if p.model.temperature_unit == "degC"
            for c in p.temp_names]  # fmt: skip
    source = _chamber_joined(source, r.chamber_log, units.TIME_UNITS[t_unit],
                             _own_temperature(source, used), chunk_rows)  # fmt: skip
    out_info = _output_info(source.info, source.time_col, t_unit, plans)
    warn_formula_names(dst, source.names)  # every output column begins as an input's name
    state = _PassState()
    run = _ChannelPass(source, plans, _evaluation_groups(plans), units.TIME_UNITS[t_unit],
                       chunk_rows, on_progress, state)  # fmt: skip
    atomic_write_path(dst, lambda tmp: run.write(tmp, _chunk_writer(kind_out, dst), out_info))
    if _CHUNK_WRITERS[kind_out].sidecar:
        write_json(sidecar_path(dst), out_info)
    for plan in plans:
        plan.predictor.finish()
    return [_file_result(plan, str(dst), state.rows, state.chunks) for plan in plans]


def _check_chunk_rows(chunk_rows: int) -> None:
    """A chunk holds at least 2 rows (an input error otherwise)."""
    if chunk_rows < 2:
        raise ThermocalInputError(f"chunk size must be at least 2 rows, got {chunk_rows}")


@dataclass(frozen=True)
class _Source:
    """The input of a chunked pass: its path and format, its columns and metadata, the table
    of a file read whole (a log, a plugin's format, a text log with layout options; None:
    read a chunk at a time) and the time column, checked present."""

    src: Path
    fmt: FileFormat
    names: list[str]
    info: dict[str, Any]
    table: pd.DataFrame | None
    time_col: str
    available: str
    chamber: ChamberStream | None = None
    """A chamber log joined by time: its column appended to every chunk."""

    def chunks(self, chunk_rows: int) -> Iterator[pd.DataFrame | pa.RecordBatch]:
        """The file's rows, ``chunk_rows`` at a time."""
        if self.table is not None:
            return _slices(self.table, chunk_rows)
        assert self.fmt.stream is not None
        return self.fmt.stream(self.src, chunk_rows)

    def joined(
        self, chunk: pd.DataFrame | pa.RecordBatch, t: FloatArray
    ) -> pd.DataFrame | pa.RecordBatch:
        """The chunk with the chamber log's column at its times ``t`` [s] (as it is without
        a log)."""
        if self.chamber is None:
            return chunk
        return _append_columns(chunk, {CHAMBER_COLUMN: self.chamber.values(t)})


def _chamber_columns(source: _Source, spec: ChamberLogSpec | None) -> _Source:
    """The source with the chamber log's column among its names and its unit (°C) among
    the stated temperatures (the values come with :func:`_chamber_joined`); a file that has
    a column of that name already is refused."""
    if spec is None:
        return source
    if CHAMBER_COLUMN in source.names:
        raise ThermocalInputError.naming(
            f"{source.src}: already has a column {CHAMBER_COLUMN!r}; was the chamber log "
            "joined already? Drop {chamber_log}, or rename the column",
            "chamber_log",
        )
    info = dict(source.info)
    info["temperatures"] = {**dict(info.get("temperatures") or {}), CHAMBER_COLUMN: "degC"}
    names = [*source.names, CHAMBER_COLUMN]
    return dataclasses.replace(source, names=names, info=info, available=names_list(names))


def _chamber_joined(
    source: _Source,
    spec: ChamberLogSpec | None,
    t_factor: float,
    own: tuple[str, units.TemperatureConversion | None] | None,
    chunk_rows: int,
) -> _Source:
    """The source with the chamber log joined once for the whole recording
    (:func:`thermocal.readers.chamber_log.chamber_clock_join`) from a first pass over its
    time: its first and last times with an offset given or from absolute clocks (constant
    memory), its time and ``own`` temperature [°C] (16 B a row) for the correlation."""
    if spec is None:
        return source
    log = read_chamber_log(spec)
    src, state = source.src, _PassState()
    ts: list[FloatArray] = []
    ys: list[FloatArray] = []
    first = math.nan
    series = False
    for chunk in source.chunks(chunk_rows):
        row0 = state.rows
        t = _chunk_time(chunk, source.time_col, t_factor, src, row0, state.last_t)
        if not t.size:
            continue
        if state.rows == 0:
            first = float(t[0])
            series = chamber_needs_series(spec, log, first)
        if series and own is not None:
            y = numeric_column(chunk, own[0], src, row0)
            if own[1] is not None:
                y = own[1].to_celsius(y, f"{src}: column {own[0]!r} (chunk from row {row0})")
            _check_finite(y, f"temperature column {own[0]!r}", src, row0)
            ts.append(t)
            ys.append(y)
        state.advance(t)
    state.check_rows(src)
    assert state.last_t is not None
    if series and own is None:
        raise ThermocalInputError.naming(
            f"{src}: the clocks are joined by correlating the recording's own temperature "
            "with the chamber log's, and the recording has none stated in °C: give "
            "{chamber_offset} (or {chamber_tz} with absolute clocks)",
            "chamber_offset",
            "chamber_tz",
        )
    t_all = np.concatenate(ts) if series else np.array([first, state.last_t])
    y_all = np.concatenate(ys) if series else None
    log, join = chamber_clock_join(
        spec, t_all, y_all, own[0] if own else None, log=log, stacklevel=5
    )
    return dataclasses.replace(source, chamber=ChamberStream(log, join, first))


def _own_temperature(
    source: _Source, used: Sequence[tuple[str, units.TemperatureConversion | None]]
) -> tuple[str, units.TemperatureConversion | None] | None:
    """The recording's own temperature to correlate with a chamber log: the first of the
    models' temperature columns in °C or converted to it (``used``: column, conversion),
    else the first the file states in °C; None without one."""
    for name, conv in used:
        if name != CHAMBER_COLUMN:
            return name, conv
    for name, unit in dict(source.info.get("temperatures") or {}).items():
        stated = name != CHAMBER_COLUMN and name in source.names and bool(unit)
        if stated and units.normalize_temperature_unit(str(unit)) == "degC":
            return str(name), None
    return None


def _head(src: Path, fmt: FileFormat) -> tuple[list[str], dict[str, Any]]:
    """Column names and metadata (sidecar over the file's) of a format read a chunk at a
    time, without reading its rows; a missing, special or empty file is refused."""
    if fmt.sniff is None or not fmt.sniff(src):
        if not src.exists():
            raise FileFormatError(f"{src}: no such file")
        refuse_special_input(src)
        if src.stat().st_size == 0:
            raise FileFormatError(f"{src}: the file is empty")
    assert fmt.head is not None
    names, meta, _n_rows = fmt.head(src)
    return names, {**meta, **load_sidecar(src)}


def _open_source(src: Path, fmt: FileFormat, read: ReadOptions) -> _Source:
    """The input's columns and metadata (a format read whole, or a text log with layout
    options, read first) and its time column (``read.time``, else the metadata's or the
    default); :class:`MissingColumnError` naming the available columns when it is absent."""
    table: pd.DataFrame | None = None
    if fmt.chunks == "whole" or read.text_layout_given:
        table, info = read_whole_table(src, read)
        names = [str(c) for c in table.columns]
    else:
        names, info = _head(src, fmt)
    time = read.time
    time_col = time or default_time_column(names, info.get("time"))
    available = names_list(names)  # the first 20 and how many more (10 000 columns: one line)
    if time_col not in names:
        hint = time_hint(names, (info.get("text_layout") or {}).get("banner") or ())
        raise MissingColumnError.naming(
            f"{src}: no time column {time_col!r}; available: {available}"
            + (hint if time is None else ""),
            *TIME_HINT_PARAMETERS,
        )
    return _Source(src, fmt, names, info, table, time_col, available)


@dataclass
class _PassState:
    """Progress of a chunked pass: rows and chunks done, the last time [s] seen."""

    rows: int = 0
    chunks: int = 0
    last_t: float | None = None

    def advance(self, t: FloatArray) -> None:
        """One chunk of times ``t`` [s] done."""
        self.rows += int(t.size)
        self.chunks += 1
        self.last_t = float(t[-1]) if t.size else self.last_t

    def check_rows(self, src: Path) -> None:
        """A file with a header and no row is a format error."""
        if self.rows == 0:
            raise FileFormatError(f"{src}: the file has a header but no data rows")


@dataclass(frozen=True)
class _ChannelPass:
    """The chunked pass of :func:`compensate_channels` over one source."""

    source: _Source
    plans: list[_ChannelPlan]
    groups: list[list[_ChannelPlan]]
    t_factor: float
    chunk_rows: int
    on_progress: Callable[[int], None] | None
    state: _PassState

    def write(
        self, tmp: Path, writer: type[_ParquetChunks] | type[_CsvChunks], out_info: dict[str, Any]
    ) -> None:
        """Every chunk compensated and written to ``tmp``; the previous chunk is written on
        a second thread while this one is computed (pyarrow and numpy release the GIL);
        one chunk in flight, errors re-raised here."""
        src, state = self.source.src, self.state
        w = writer(tmp, out_info)
        pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="thermocal-write")
        pending: Future[None] | None = None
        try:
            for raw_chunk in self.source.chunks(self.chunk_rows):
                row0 = state.rows
                t = _chunk_time(raw_chunk, self.source.time_col, self.t_factor, src, row0,
                                state.last_t)  # fmt: skip
                chunk = self.source.joined(raw_chunk, t)
                table = _compensate_one_chunk(chunk, t, self.plans, self.groups, src, row0)
                if pending is not None:
                    pending.result()
                pending = pool.submit(w.write, table)
                state.advance(t)
                if self.on_progress is not None:
                    self.on_progress(int(t.size))
            if pending is not None:
                pending.result()
        finally:
            pool.shutdown(wait=True)
            w.close()
        state.check_rows(src)
        if state.rows < FEW_SAMPLES:
            warnings.warn(
                PlausibilityWarning(
                    f"{src}: only {state.rows} samples: figures from so few are not "
                    f"meaningful (at least {FEW_SAMPLES} sample rows are expected)"
                ),
                stacklevel=2,
            )


def _file_result(
    plan: _ChannelPlan, output: str, n_rows: int, n_chunks: int
) -> CompensateFileResult:
    """One channel's summary: the figures about the mean and about zero (in the data's
    unit), with a warning when the compensation makes the absolute error worse."""
    k = plan.factor or 1.0
    ref = plan.zero[0] / k  # the reference in the data's unit
    b, a = plan.before.about(ref), plan.after.about(ref)
    worse = absolute_error_worse(b, a)
    if worse:
        warnings.warn(
            ThermocalWarning(
                absolute_worse_message(plan.predictor.name, plan.data_unit, b, a, worse)
            ),
            stacklevel=3,
        )
    excess = plan.predictor.outside_range
    return CompensateFileResult(
        output=output,
        n_rows=n_rows,
        n_chunks=n_chunks,
        signal=plan.signal,
        model_column=plan.model_col,
        comp_column=plan.comp_col,
        unit=plan.data_unit,
        streamed=plan.predictor.streams,
        rms_before=plan.before.rms(),
        rms_after=plan.after.rms(),
        mean_before=b.mean,
        mean_after=a.mean,
        rms_about_zero_before=b.rms_about_zero,
        rms_about_zero_after=a.rms_about_zero,
        max_abs_before=b.max_abs,
        max_abs_after=a.max_abs,
        zero_reference={"value": ref, "unit": plan.data_unit, "what": plan.zero[1]},
        absolute_error_worse=bool(worse),
        outside_range=outside_range_dict(excess),
        outside_calibrated_range=any(e.n_outside for e in excess),
    )


@dataclass(frozen=True)
class _FileContext:
    """What every channel's plan checks against: the input file, its columns and metadata."""

    src: Path
    names: list[str]
    info: dict[str, Any]
    time_col: str
    available: str
    signal_given: bool


def _channel_plan(
    ctx: _FileContext,
    sig_name: str,
    model: TemperatureModel,
    signal_unit: str | tuple[str, ...] | None,
    opts: units.UnitOptions,
    *,
    extrapolate: bool,
    known_input: float,
    name: str,
) -> _ChannelPlan:
    """One channel checked against the file (its columns exist, its outputs do not yet)
    with its units and conversions resolved once (:func:`thermocal.units.resolve_inputs`:
    option > file metadata > column name > what the model recorded > default)."""
    src, names, where = ctx.src, ctx.names, str(ctx.src)
    model.check_fitted()
    temp_names = list(model.temp_names_)
    if sig_name not in names:
        raise MissingColumnError.naming(
            f"{src}: no signal column {sig_name!r} (the model's signal"
            f"{' given by {signals}' if ctx.signal_given else ''}); available: {ctx.available}",
            "signals",
        )
    missing = [c for c in temp_names if c not in names]
    if missing:
        chamber = CHAMBER_COLUMN in missing  # the model was fitted on a chamber log's column
        raise MissingColumnError.naming(
            f"{src}: the model's temperature column(s) "
            f"{', '.join(repr(c) for c in missing)} are not in the file; "
            f"available: {ctx.available}"
            + ("; give the chamber log, {chamber_log} FILE[:CHANNEL]" if chamber else ""),
            *(("chamber_log",) if chamber else ()),
        )
    model_col = sig_name + MODEL_SUFFIX
    comp_col = sig_name + COMP_SUFFIX
    for c in (model_col, comp_col):
        if c in names:
            raise ThermocalInputError(
                f"{src}: already has a column {c!r}; was the file compensated already?"
            )
    resolved = units.resolve_inputs(
        ctx.time_col,
        [sig_name],
        temp_names,
        options=dataclasses.replace(opts, signal_unit=signal_unit),
        file=units.StatedUnits.from_file_info(ctx.info, where),
        model=model.input_units(),
        where=where,
    )
    data_unit = resolved.signals[sig_name].unit
    check_signal_kind(data_unit, model.signal_unit, where)
    md = model_scale_factor(model, Metadata.from_dict(dict(ctx.info.get("metadata") or {})))
    check_sensor_id(getattr(model, "inputs_", None), md.sensor_id, where)
    return _ChannelPlan(
        model=model,
        signal=sig_name,
        model_col=model_col,
        comp_col=comp_col,
        data_unit=data_unit,
        temp_names=temp_names,
        convs=temperature_inputs(model, resolved, where),
        temp_units={c: r.unit for c, r in resolved.temperatures.items()},
        md=md,
        predictor=ChunkPredictor(
            model, extrapolate=extrapolate, name=name, known_input=known_input
        ),
        time_unit=resolved.time.unit,
        zero=zero_reference(model, md, known_input),
    )


def _compensate_one_chunk(
    chunk: pd.DataFrame | pa.RecordBatch,
    t: FloatArray,
    plans: Sequence[_ChannelPlan],
    groups: Sequence[Sequence[_ChannelPlan]],
    src: Path,
    row0: int,
) -> Any:
    """One chunk of every channel: inputs read and checked once, one prediction per group
    of channels sharing an evaluation, ``<sig>_model``/``<sig>_comp`` appended in the
    order the channels were given."""
    new: dict[str, FloatArray] = {}
    temps_cache: dict[tuple[str, str], FloatArray] = {}
    inputs = {id(plan): _chunk_inputs(plan, chunk, t, temps_cache, src, row0) for plan in plans}
    for group in groups:  # channels sharing one evaluation: one predict call
        lead = group[0]
        temps, raw = inputs[id(lead)]
        ys = lead.predictor.predict_with(
            t, temps, raw * cast(float, lead.factor), [p.predictor for p in group[1:]]
        )
        for plan, y_model in zip(group, ys, strict=True):
            y_data, comp = _chunk_outputs(plan, inputs[id(plan)][1], y_model)
            new[plan.model_col] = y_data
            new[plan.comp_col] = comp
    ordered = {c: new[c] for plan in plans for c in (plan.model_col, plan.comp_col)}
    return _append_columns(chunk, ordered)


def _output_info(
    info: dict[str, Any], time_col: str, t_unit: str, plans: Sequence[_ChannelPlan]
) -> dict[str, Any]:
    """The output's metadata: the input's, with the time unit, every channel's signal,
    model and compensated columns in the data's unit, and the conversions used."""
    out_info: dict[str, Any] = {
        "format": META_FORMAT,
        "version": META_VERSION,
        **{k: v for k, v in info.items() if k not in ("format", "version")},
    }
    out_info["time"] = time_col
    out_info["time_unit"] = t_unit
    signals = dict(info.get("signals") or {})
    temps = dict(info.get("temperatures") or {})
    extra = dict(info.get("units") or {})
    used_conv: dict[str, Any] = {}
    for plan in plans:
        signals[plan.signal] = plan.data_unit
        temps.update(plan.temp_units)
        extra[plan.model_col] = plan.data_unit
        extra[plan.comp_col] = plan.data_unit
        used_conv.update({c: v.to_json() for c, v in plan.convs.items() if v is not None})
    out_info["signals"] = signals
    out_info["temperatures"] = temps
    out_info["units"] = extra
    if used_conv:  # the conversions travel with the output too
        out_md = dict(out_info.get("metadata") or {})
        out_md["temperature_conversion"] = {
            **dict(out_md.get("temperature_conversion") or {}),
            **used_conv,
        }
        out_info["metadata"] = out_md
    return out_info


def _chunk_time(
    chunk: pd.DataFrame | pa.RecordBatch,
    time_col: str,
    t_factor: float,
    src: Path,
    row0: int,
    last_t: float | None,
) -> FloatArray:
    """The chunk's time [s], finite and increasing (also across the chunk boundary)."""
    t = numeric_column(chunk, time_col, src, row0) * t_factor
    _check_finite(t, f"time column {time_col!r}", src, row0)
    dt = np.diff(t)
    if (dt <= 0).any() or (last_t is not None and t.size and t[0] <= last_t):
        if last_t is not None and t.size and t[0] <= last_t:
            r = row0
        else:
            r = row0 + int(np.argmax(dt <= 0)) + 1
        raise TimestampError(f"{src}: time does not increase at row {r}")
    return t


def _chunk_inputs(
    plan: _ChannelPlan,
    chunk: pd.DataFrame | pa.RecordBatch,
    t: FloatArray,
    temps_cache: dict[tuple[str, str], FloatArray],
    src: Path,
    row0: int,
) -> tuple[FloatArray, FloatArray]:
    """One channel's inputs in one chunk: (temperatures [°C or counts], raw signal [data
    unit]), checked. Temperature inputs are converted once per chunk and shared between
    channels (``temps_cache``)."""
    temps = np.empty((t.size, len(plan.temp_names)))
    for j, c in enumerate(plan.temp_names):
        conv = plan.convs[c]
        key = (c, repr(conv.to_json()) if conv is not None else "")
        v = temps_cache.get(key)
        if v is None:
            v = numeric_column(chunk, c, src, row0)
            if conv is not None:  # raw counts → °C (else °C, or counts for a counts model)
                v = conv.to_celsius(v, f"{src}: column {c!r} (chunk from row {row0})")
            _check_finite(v, f"temperature column {c!r}", src, row0)
            temps_cache[key] = v
        temps[:, j] = v
    raw = numeric_column(chunk, plan.signal, src, row0)
    _check_finite(raw, f"signal column {plan.signal!r}", src, row0)
    counts_scale = None
    if units.signal_kind(plan.data_unit) == "raw" and plan.md.scale_factor is not None:
        tau_k = plan.md.sample_interval_s or (median_interval(t) if t.size > 1 else 1.0)
        k_unit = units.scale_factor_unit_or_default(plan.md.scale_factor_unit, str(src))
        counts_scale = (plan.md.scale_factor, k_unit, float(tau_k))
    _check_plausible(
        temps if plan.model.temperature_unit == "degC" else temps[:, :0],  # counts: no °C
        plan.temp_names, raw, plan.data_unit, src, row0, plan.signal, counts_scale,
    )  # fmt: skip
    if plan.factor is None:
        tau = plan.md.sample_interval_s or (median_interval(t) if t.size > 1 else None)
        plan.factor = unit_factor(
            plan.data_unit, plan.model.signal_unit, meta=plan.md, sample_interval_s=tau,
            where=str(src),
        )  # fmt: skip
    return temps, raw


def _chunk_outputs(
    plan: _ChannelPlan, raw: FloatArray, y_model: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """(ŷ, F − ŷ) in the data's unit from ŷ in the model's unit."""
    assert plan.factor is not None
    y_data = y_model / plan.factor
    comp = raw - y_data
    plan.before.add(raw)
    plan.after.add(comp)
    return y_data, comp


def _evaluation_groups(plans: Sequence[_ChannelPlan]) -> list[list[_ChannelPlan]]:
    """Channels evaluated together: ``poly`` models with one evaluation key
    (:func:`thermocal.models.poly_eval.evaluation_key`: same inputs, ranges and term structure,
    as :func:`~thermocal.models.poly_fit.fit_shared` makes them) and the same temperature
    conversions; every other channel alone."""
    from thermocal.models.poly import PolyModel
    from thermocal.models.poly_eval import evaluation_key

    groups: dict[Any, list[_ChannelPlan]] = {}
    out: list[list[_ChannelPlan]] = []
    for plan in plans:
        if not isinstance(plan.model, PolyModel) or plan.predictor.streams:
            out.append([plan])
            continue
        convs = tuple(
            (c, repr(v.to_json()) if v is not None else "") for c, v in sorted(plan.convs.items())
        )
        key = (evaluation_key(plan.model), convs)
        if key not in groups:
            groups[key] = []
            out.append(groups[key])
        groups[key].append(plan)
    return out


__all__ = [
    "COMP_SUFFIX",
    "MODEL_SUFFIX",
    "CalibrationCompensation",
    "CompensateFileResult",
    "TriadCompensation",
    "compensate_calibration_file",
    "compensate_channels",
    "compensate_file",
    "compensate_triads",
    "read_for_triads",
]


@dataclass(frozen=True)
class TriadCompensation:
    """What :func:`compensate_triads` did for one triad: its columns, the added ones, the
    unit of the added ones, the share of samples outside the calibrated temperature range,
    the unit of the input columns and, for raw counts, the count scale applied (one count
    is ``count_scale`` ``unit``; None for columns already in a physical unit).

    Attributes
    ----------
    triad : str
        The triad.
    columns, comp_columns : tuple of str
        Its input columns and the columns added.
    unit : str
        Unit of the added columns.
    outside_range_fraction : float
        Share of samples outside the calibrated temperature range.
    input_unit : str
        Unit of the input columns.
    count_scale : float or None
        For raw counts, one count in ``unit`` (None: a physical unit).
    g_sensitivity : bool
        The gyro triad's g-sensitivity taken off (``A f``).
    """

    triad: str
    columns: tuple[str, ...]
    comp_columns: tuple[str, ...]
    unit: str
    outside_range_fraction: float
    input_unit: str = ""
    count_scale: float | None = None
    g_sensitivity: bool = False
    """True when the triad's g-sensitivity ``A f`` was taken off (a gyro triad)."""

    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict, for the JSON result."""
        return dataclasses.asdict(self)


def read_for_triads(
    path: str | Path,
    triads: Sequence[Any],
    read: ReadOptions | None = None,
) -> Recording:
    """A recording read for triad calibrations.

    Parameters
    ----------
    path : str or Path
        The recording.
    triads : sequence of Triad
        The calibration's triads; their temperature columns are read as temperatures, so
        that their units go through the resolver (option > metadata > column name); the
        triads' own columns keep the unit their metadata or name states.
    read : ReadOptions, optional
        How the file is read: its time column and unit, a text log's layout, a topic
        (its column roles are the triads').

    Returns
    -------
    Recording
    """
    temps = list(dict.fromkeys(t.temperature for t in triads if t.temperature))
    r = read or ReadOptions()
    return read_recording(
        path,
        ReadOptions(time=r.time, time_unit=r.time_unit, temperatures=tuple(temps), topic=r.topic,
                    names=r.names, rate_hz=r.rate_hz, on_bad_lines=r.on_bad_lines,
                    delimiter=r.delimiter, decimal=r.decimal),
    )  # fmt: skip


def compensate_triads(
    triads: Sequence[Any],
    path: str | Path,
    out: str | Path,
    read: ReadOptions | None = None,
    *,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
    g_sensitivity: str = "apply",
) -> list[TriadCompensation]:
    """Apply triad calibrations to a recording, in chunks with constant memory.

    Parameters
    ----------
    triads : sequence of Triad
        The calibration's triads.
    path, out : str or Path
        The recording and the output (as :func:`compensate_file`).
    read : ReadOptions, optional
        How the file is read (see below for ``signal_unit``).
    chunk_rows : int
        Rows read and written at a time (at least 2).
    g_sensitivity : {"apply", "off"}
        ``apply`` (default): a gyro triad's g-sensitivity ``A`` is taken off with the
        accelerometer triad's compensated output; ``off``: not, and a triad none of whose
        columns the recording holds is left out (a warning), so that a gyro-only recording
        takes the gyro triad alone.

    Returns
    -------
    list of TriadCompensation
        One per triad: its columns, the added ones, their unit, the share of samples
        outside the calibrated temperature range.

    Raises
    ------
    thermocal.errors.MissingColumnError
        A triad's column absent from the file.
    thermocal.errors.UnitError
        Raw-count temperatures without a conversion, or raw counts for a triad calibrated
        without a count scale.
    thermocal.errors.ThermocalInputError
        A gyro triad with a g-sensitivity, to be applied, and no accelerometer triad in the
        calibration or none of its columns in the recording.

    Notes
    -----
    For each triad and each of its axes a column

    .. math:: x^{comp} = \\left[(I + E(T))^{-1} (x - b(T) - A f)\\right]_{axis}

    in the column's own unit, ``T`` the triad's temperature column at each sample (clamped
    to the calibrated range, with a warning when samples leave it;
    :func:`thermocal.turntable.thermal.correct`); ``A f`` only for a gyro triad with a
    g-sensitivity ``A`` [its unit per g] (``Triad.g_sensitivity``; IEEE Std 952-1997 annex B,
    IEEE Std 1431-2004), ``f`` the accelerometer triad's compensated output at the same
    sample in g (g = 9.80665 m/s²): the gyro model is ``ω_raw = (I + E) ω + b + A f``, so
    ``A f`` comes off before the scale and misalignment are undone.
    Raw-count columns of a triad calibrated on counts (``Triad.count_scale``) are
    converted first, ``x = count_scale · N``, and their ``_comp`` columns are in the
    triad's physical unit; raw counts for a triad without a count scale are refused.
    ``read.signal_unit``: one unit for every triad column, or one per column in the triads'
    order; ``read`` also carries the time column and unit, a topic and a text log's layout
    (``rate_hz`` for a log without time).

    In chunks of ``chunk_rows`` rows with constant memory, like :func:`compensate_channels`:
    the correction is per sample, so each chunk's values equal those of a whole-file pass;
    every input column is kept as it is and the output is written chunk by chunk to a
    temporary name, renamed when complete.  Units: option > the file's
    metadata > a unit in the column name > the unit the triad was calibrated on
    (:func:`thermocal.units.resolve_inputs`).
    """
    src, fmt, r = _source_format(path, read or ReadOptions())
    dst = Path(out)
    kind_out = written_format(dst)
    check_not_input(dst, [src])
    _check_chunk_rows(chunk_rows)
    source = _chamber_columns(_open_source(src, fmt, r), r.chamber_log)
    plans = _triad_plans(triads, source.names, source.available, src, g_sensitivity)
    resolved = _resolve_triads(source, plans, r.time_unit, r.signal_unit)
    used = [(c, resolved.conversions[c].conversion) for c in _triad_temperatures(plans)]
    source = _chamber_joined(source, r.chamber_log, units.TIME_UNITS[resolved.time.unit],
                             _own_temperature(source, used), chunk_rows)  # fmt: skip
    out_info = _triad_output_info(source.info, source.time_col, resolved, plans)
    warn_formula_names(dst, source.names)
    state = _PassState()
    atomic_write_path(
        dst, lambda tmp: _write_triads(tmp, source, _chunk_writer(kind_out, dst), out_info,
                                       plans, resolved, chunk_rows, state)
    )  # fmt: skip
    if _CHUNK_WRITERS[kind_out].sidecar:
        write_json(sidecar_path(dst), out_info)
    return _triad_results(plans, state, src)


def _triad_results(
    plans: Sequence[_TriadPlan], state: _PassState, src: Path
) -> list[TriadCompensation]:
    """What :func:`compensate_triads` did per triad, with a warning for a triad whose
    samples left its calibrated temperature range."""
    results = []
    for p in plans:
        outside = p.n_outside / max(state.rows, 1)
        if outside > 0:
            warnings.warn(
                ExtrapolationWarning(
                    f"{src}: {100 * outside:.3g} % of the samples are outside the {p.tri.name} "
                    f"triad's calibrated range {p.tri.model.t_lo_c:g}…{p.tri.model.t_hi_c:g} "
                    "°C: its parameters are held at the nearest end there"
                ),
                stacklevel=3,
            )
        results.append(
            TriadCompensation(
                p.tri.name, tuple(p.columns), tuple(p.comp_columns), p.out_unit, outside,
                p.data_unit, p.count_scale, p.force_from is not None,
            )
        )  # fmt: skip
    return results


def _resolve_triads(
    source: _Source,
    plans: Sequence[_TriadPlan],
    time_unit: str | None,
    signal_unit: str | tuple[str, ...] | None = None,
) -> units.ResolvedInputs:
    """The units of the triads' columns and temperatures resolved once (option > metadata >
    column name > the unit each triad was calibrated on); raw-count temperatures without a
    conversion refused; each plan's data unit set."""
    src = source.src
    signals = [c for p in plans for c in p.columns]
    resolved = units.resolve_inputs(
        source.time_col,
        list(dict.fromkeys(signals)),
        _triad_temperatures(plans),
        options=units.UnitOptions(time_unit=time_unit, signal_unit=signal_unit),
        file=units.StatedUnits.from_file_info(source.info, str(src)),
        model=units.StatedUnits(None, {c: p.calibrated_unit() for p in plans for c in p.columns}),
        where=str(src),
    )
    unconverted = resolved.unconverted_counts()
    if unconverted:
        raise UnitError(
            f"{src}: temperature column(s) {', '.join(map(repr, unconverted))} in raw counts "
            "with no conversion to °C stated (metadata temperature_conversion)"
        )
    for p in plans:
        p.resolve(resolved, src)
    return resolved


def _triad_temperatures(plans: Sequence[_TriadPlan]) -> list[str]:
    """The triads' temperature columns, each once, in the triads' order."""
    return list(dict.fromkeys(p.temperature for p in plans if p.temperature))


def _write_triads(
    tmp: Path,
    source: _Source,
    writer: type[_ParquetChunks] | type[_CsvChunks],
    out_info: dict[str, Any],
    plans: Sequence[_TriadPlan],
    resolved: units.ResolvedInputs,
    chunk_rows: int,
    state: _PassState,
) -> None:
    """The chunked pass of :func:`compensate_triads`: every chunk's temperatures converted
    and checked once, each triad's compensated columns appended, the chunk written."""
    from thermocal.turntable import thermal

    src = source.src
    t_factor = units.TIME_UNITS[resolved.time.unit]
    temp_names = _triad_temperatures(plans)
    w = writer(tmp, out_info)
    try:
        for raw_chunk in source.chunks(chunk_rows):
            row0 = state.rows
            t = _chunk_time(raw_chunk, source.time_col, t_factor, src, row0, state.last_t)
            chunk = source.joined(raw_chunk, t)
            temps: dict[str, FloatArray] = {}
            for c in temp_names:
                v = numeric_column(chunk, c, src, row0)
                conv = resolved.conversions[c].conversion
                if conv is not None:
                    v = conv.to_celsius(v, f"{src}: column {c!r} (chunk from row {row0})")
                _check_finite(v, f"temperature column {c!r}", src, row0)
                _check_plausible(v[:, None], [c], v[:0], "deg/h", src, row0)
                temps[c] = v
            done: dict[int, FloatArray] = {}
            for p in sorted(plans, key=lambda q: q.force_from is not None):  # accel first
                temp = (temps[p.temperature] if p.temperature  # "": one temperature
                        else np.full(t.size, p.tri.model.tref_c))  # fmt: skip
                force = None if p.force_from is None else done[id(p.force_from)]
                done[id(p)] = p.correct(chunk, temp, src, row0, thermal, force)
            new = {name: np.ascontiguousarray(done[id(p)][:, k])
                   for p in plans for k, name in enumerate(p.comp_columns)}  # fmt: skip
            w.write(_append_columns(chunk, new))
            state.advance(t)
    finally:
        w.close()
    state.check_rows(src)


@dataclass
class _TriadPlan:
    """One triad of :func:`compensate_triads`: its columns checked against the file, its
    data unit (once resolved) and the count of samples outside its calibrated range."""

    tri: Any
    columns: list[str]
    temperature: str
    comp_columns: list[str]
    data_unit: str = ""
    out_unit: str = ""
    count_scale: float | None = None
    to_data: float = 1.0
    n_outside: int = 0
    force_from: _TriadPlan | None = None
    """The accelerometer triad whose output is the specific force of a gyro triad's
    g-sensitivity (None: none applied)."""

    def calibrated_unit(self) -> str:
        """The unit of the columns the triad was calibrated on (:meth:`Triad.calibrated_unit
        <thermocal.models.calibration.Triad.calibrated_unit>`)."""
        return str(self.tri.calibrated_unit())

    def resolve(self, resolved: units.ResolvedInputs, src: Path) -> None:
        """The data unit of the triad's columns (one for all three), the unit of their
        ``_comp`` columns (the data's, or the triad's for raw counts with a count scale)
        and the factor from its bias unit (°/h or mg) to the latter (:meth:`Triad.input_in
        <thermocal.models.calibration.Triad.input_in>`, shared with ``validate``)."""
        inp = self.tri.input_in([resolved.signals[c].unit for c in self.columns], str(src))
        self.data_unit, self.out_unit = inp.data_unit, inp.unit
        self.count_scale, self.to_data = inp.count_scale, inp.to_data

    def correct(
        self,
        chunk: pd.DataFrame | pa.RecordBatch,
        temp: FloatArray,
        src: Path,
        row0: int,
        thermal: Any,
        force: FloatArray | None = None,
    ) -> FloatArray:
        """The chunk's compensated samples (n, 3) (:meth:`Triad.correct
        <thermocal.models.calibration.Triad.correct>`: K2 inverted where the triad holds it),
        ``A f`` taken off first when ``force`` (the accelerometer triad's compensated output,
        in its unit) is given."""
        x = np.empty((temp.size, 3))
        for k, c in enumerate(self.columns):
            v = numeric_column(chunk, c, src, row0)
            _check_finite(v, f"signal column {c!r}", src, row0)
            if self.count_scale is not None:  # raw counts → the triad's unit
                with np.errstate(over="ignore"):  # an overflow is refused just below
                    v = v * self.count_scale
            _check_plausible(temp[:0, None], [], v, self.out_unit, src, row0, c)
            x[:, k] = v
        m = self.tri.model
        self.n_outside += int(np.count_nonzero((temp < m.t_lo_c) | (temp > m.t_hi_c)))
        if force is not None and self.force_from is not None:  # A f off (Triad.g_sensitivity)
            x = x - self.tri.g_sensitivity_term(force, self.force_from.out_unit, self.out_unit)
        out: FloatArray = self.tri.correct(x, temp, self.to_data, self.out_unit)
        return out


G_SENSITIVITY_CHOICES = ("apply", "off")
"""``g_sensitivity`` of :func:`compensate_triads`: a gyro triad's g-sensitivity applied or
not."""


def _triad_plans(
    triads: Sequence[Any], names: Sequence[str], available: str, src: Path, g_sensitivity: str
) -> list[_TriadPlan]:
    """Each triad's plan (:func:`_triad_plan`); a gyro triad's g-sensitivity linked to the
    accelerometer triad whose output is its specific force (``apply``), refused without
    one; with ``off``, a triad none of whose columns are in the file left out (a warning).
    Accelerometer plans come before the gyro plans that read them (resolved first)."""
    if g_sensitivity not in G_SENSITIVITY_CHOICES:
        raise ParameterError(
            "g_sensitivity", f"{{name}} {g_sensitivity!r}: {' or '.join(G_SENSITIVITY_CHOICES)}"
        )
    apply = g_sensitivity == "apply"
    keep = list(triads)
    gone = [t for t in triads if not any(c in names for c in t.columns)]
    if not apply and len(gone) < len(triads):
        keep = [t for t in triads if all(t is not g for g in gone)]
        for t in gone:
            warnings.warn(
                ThermocalWarning(
                    f"{src}: none of the {t.name} triad's columns "
                    f"({', '.join(map(repr, t.columns))}) is in the file: left out"
                ),
                stacklevel=4,
            )
    accel = next((t for t in keep if t.model.kind == "accel"), None)
    for t in keep:
        if apply and t.g_sensitivity is not None:
            _check_force_source(t, accel, names, src)
    plans = {id(t): _triad_plan(t, names, available, src) for t in keep}
    for t in keep:
        if apply and t.g_sensitivity is not None and accel is not None:
            plans[id(t)].force_from = plans[id(accel)]
    return sorted(plans.values(), key=lambda p: p.force_from is not None)


def _check_force_source(gyro: Any, accel: Any, names: Sequence[str], src: Path) -> None:
    """The gyro triad's g-sensitivity needs the accelerometer triad of its calibration and
    that triad's columns in the recording; one line naming ``g_sensitivity`` otherwise."""
    if accel is None:
        raise ThermocalInputError.naming(
            f"{src}: the {gyro.name} triad's g-sensitivity takes off A·f with the specific "
            "force f of an accelerometer triad, and the calibration holds none; give "
            "{g_sensitivity} off to compensate without it",
            "g_sensitivity",
        )
    missing = [c for c in accel.columns if c not in names]
    if missing:
        raise ThermocalInputError.naming(
            f"{src}: the {gyro.name} triad's g-sensitivity takes off A·f with the specific "
            f"force f from the {accel.name} triad's columns "
            f"{', '.join(map(repr, accel.columns))}, and {', '.join(map(repr, missing))} "
            "is not in the file; give {g_sensitivity} off to compensate without it",
            "g_sensitivity",
        )


def _triad_plan(tri: Any, names: Sequence[str], available: str, src: Path) -> _TriadPlan:
    """A triad's columns checked against the file: present, and their ``_comp`` columns
    not yet there."""
    # a triad calibrated at one temperature names none ("": applied at its TREF)
    missing = [c for c in (*tri.columns, tri.temperature) if c and c not in names]
    if missing:
        raise MissingColumnError(
            f"{src}: the {tri.name} triad reads {', '.join(map(repr, missing))}, absent; "
            f"available: {available}"
        )
    comp = [f"{c}{COMP_SUFFIX}" for c in tri.columns]
    for c in comp:
        if c in names:
            raise ThermocalInputError(
                f"{src}: already has a column {c!r}; was the file compensated already?"
            )
    return _TriadPlan(tri, list(tri.columns), tri.temperature, comp)


def _triad_output_info(
    info: dict[str, Any], time_col: str, resolved: units.ResolvedInputs, plans: Sequence[_TriadPlan]
) -> dict[str, Any]:
    """The output's metadata: the input's, with the time unit, the triads' columns and
    temperatures in their resolved units and the compensated columns in the data's unit."""
    out_info: dict[str, Any] = {
        "format": META_FORMAT,
        "version": META_VERSION,
        **{k: v for k, v in info.items() if k not in ("format", "version")},
    }
    out_info["time"] = time_col
    out_info["time_unit"] = resolved.time.unit
    signals = dict(info.get("signals") or {})
    extra = dict(info.get("units") or {})
    for p in plans:
        for c, comp in zip(p.columns, p.comp_columns, strict=True):
            (signals if c in signals else extra)[c] = p.data_unit
            extra[comp] = p.out_unit
    temps = dict(info.get("temperatures") or {})
    temps.update({c: r.unit for c, r in resolved.temperatures.items()})
    out_info["signals"] = signals
    out_info["temperatures"] = temps
    out_info["units"] = extra
    used_conv = {
        c: r.conversion.to_json()
        for c, r in resolved.conversions.items()
        if r.conversion is not None
    }
    if used_conv:
        out_md = dict(out_info.get("metadata") or {})
        out_md["temperature_conversion"] = {
            **dict(out_md.get("temperature_conversion") or {}),
            **used_conv,
        }
        out_info["metadata"] = out_md
    return out_info


@dataclass(frozen=True)
class CalibrationCompensation:
    """What :func:`compensate_calibration_file` did: the calibration file applied, the
    output written and, by the calibration's content, either ``triads`` (a turntable
    calibration), ``single`` (one channel: its family and result) or ``channels`` (each
    chosen channel's name, family and result, one pass).

    Attributes
    ----------
    model_file : str
        The model or calibration file applied.
    output : str
        The output written.
    kind : str
        ``"triads"``, ``"single"`` or ``"channels"``.
    triads : tuple of TriadCompensation
        Each triad (``triads``).
    channels : tuple of (str, str, CompensateFileResult)
        ``(channel name, model family, result)`` (``single``, ``channels``).
    """

    model_file: str
    output: str
    kind: str
    """``"triads"``, ``"single"`` or ``"channels"``."""
    triads: tuple[TriadCompensation, ...] = ()
    channels: tuple[tuple[str, str, CompensateFileResult], ...] = ()
    """``(channel name, model family, result)``; one entry for ``single``."""

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of the ``compensate`` command."""
        if self.kind == "triads":
            return {"model": self.model_file, "output": self.output,
                    "triads": [d.to_dict() for d in self.triads]}  # fmt: skip
        if self.kind == "single":
            _name, family, res = self.channels[0]
            return {"model": self.model_file, "family": family, **res.to_dict()}
        return {
            "model": self.model_file,
            "output": self.output,
            "channels": {
                name: {"family": family, **r.to_dict()} for name, family, r in self.channels
            },
        }


def compensate_calibration_file(
    model_file: str | Path,
    path: str | Path,
    out: str | Path,
    read: ReadOptions | None = None,
    *,
    signals: tuple[str, ...] | None = None,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
    extrapolate: bool = False,
    known_input: float = 0.0,
    on_progress: Callable[[int], None] | None = None,
    g_sensitivity: str = "apply",
) -> CalibrationCompensation:
    """Apply a model or calibration file to a recording (``thermocal compensate``).

    A calibration of triads is applied by :func:`compensate_triads`; one channel (a model
    file) by :func:`compensate_file`; several channels in one pass by
    :func:`compensate_channels`.

    Parameters
    ----------
    model_file : str or Path
        A model file or a calibration file.
    path : str or Path
        The recording.
    out : str or Path
        The output; it may be neither input (nor, for a CSV, may its sidecar).
    read : ReadOptions, optional
        How the recording is read (:class:`~thermocal.readers.options.ReadOptions`).
    signals : tuple of str, optional
        One channel: its column, ``("gx",)`` (default the model's); several: the channels
        to apply, ``("gx", "gy")`` (default all).
    chunk_rows, extrapolate, known_input, on_progress
        As :func:`compensate_file`.
    g_sensitivity : {"apply", "off"}
        A gyro triad's g-sensitivity taken off or not (:func:`compensate_triads`).

    Returns
    -------
    CalibrationCompensation
        What was applied (``triads``, ``single`` or ``channels``) and each result.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A calibration with both triads and channels, an output on an input, or any error
        of :func:`compensate_file` and :func:`compensate_triads`.
    """
    from thermocal.pipeline.model_file import load_calibration

    check_not_input(out, [path, model_file])
    if _CHUNK_WRITERS[written_format(Path(out))].sidecar:  # nor may its sidecar
        check_not_input(sidecar_path(out), [path, model_file])
    cal = load_calibration(model_file)  # a model file is a calibration of one channel
    if cal.triads:
        if cal.channels:
            raise ThermocalInputError(
                f"{model_file}: a calibration with both triads and single channels is not "
                "applied yet; split it"
            )
        done = compensate_triads(
            cal.triads, path, out, read, chunk_rows=chunk_rows, g_sensitivity=g_sensitivity
        )
        return CalibrationCompensation(str(model_file), str(out), "triads", tuple(done))
    common: dict[str, Any] = dict(
        chunk_rows=chunk_rows, extrapolate=extrapolate, known_input=known_input,
        on_progress=on_progress,
    )  # fmt: skip
    if len(cal.channels) == 1:
        ch = cal.channels[0]
        signal = ",".join(signals) if signals else None  # one column (a list: none such)
        res = compensate_file(ch.model, path, out, read, signal=signal, **common)
        return CalibrationCompensation(
            str(model_file), str(out), "single", channels=((ch.name, ch.model.family, res),)
        )
    chosen = list(signals or ()) or cal.names
    models = [(cal.channel(n).signal, cal.channel(n).model) for n in chosen]
    results = compensate_channels(models, path, out, read, **common)
    return CalibrationCompensation(
        str(model_file),
        str(out),
        "channels",
        channels=tuple(
            (name, cal.channel(name).model.family, r)
            for name, r in zip(chosen, results, strict=True)
        ),
    )
