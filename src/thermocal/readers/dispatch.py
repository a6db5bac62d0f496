"""One entry for every file a command takes: :func:`read_recording` dispatches by format
(CSV/Parquet, text log, ULog, DataFlash, station folder) and returns a :class:`Recording`."""

from __future__ import annotations

import dataclasses
import re
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal import units
from thermocal._lazy import LazyModule
from thermocal.errors import (
    FileFormatError,
    MissingColumnError,
    NonNumericError,
    ThermocalInputError,
    TimestampWarning,
    UnitWarning,
)
from thermocal.outputs import refuse_special_input
from thermocal.readers.common import (
    check_memory,
    check_unique_names,
    csv_encoding,
    csv_float_options,
    csv_rows_estimate,
    default_time_column,
    file_kind,
    named_like_temperature,
    names_list,
    short_name,
    thermocal_metadata,
)
from thermocal.readers.dataflash import read_dataflash
from thermocal.readers.station import is_station_path, read_station_table, with_sensor
from thermocal.readers.table import ParquetColumns, csv_header_names, load_sidecar, numeric_column
from thermocal.readers.text import (
    TextOptions,
    TooManyColumnsError,
    check_column_count,
    counter_column,
    counter_time,
    head_lines,
    rate_time,
    read_text,
    sniff_text,
)
from thermocal.readers.ulog import read_ulog
from thermocal.recording import (
    META_FORMAT,
    META_VERSION,
    FloatArray,
    Metadata,
    Recording,
    all_finite,
    nominal_time,
)

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq
else:
    pd = LazyModule("pandas")
    pa = LazyModule("pyarrow")
    pq = LazyModule("pyarrow.parquet")


def read_table(
    path: Path, kind: str, text: TextOptions | None = None, topic: str | None = None
) -> tuple[pd.DataFrame | ParquetColumns, dict[str, Any]]:
    if not path.exists():
        raise FileFormatError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise FileFormatError(f"{path}: the file is empty")
    if kind == "ulog":
        return read_ulog(path, topic)
    if kind == "dataflash":
        return read_dataflash(path, topic)
    if kind == "parquet":
        try:
            table = ParquetColumns(pq.ParquetFile(path, page_checksum_verification=True))
        except (pa.ArrowInvalid, OSError) as exc:
            raise FileFormatError(f"{path}: not a readable Parquet file ({exc})") from None
        check_unique_names(path, table.column_names)
        return table, thermocal_metadata(table.metadata, path)
    encoding = csv_encoding(path)
    # pandas holds every column of a CSV (and its parser about as much again)
    rows_est, cols_est = csv_rows_estimate(path)
    check_memory(path, rows_est, 2 * cols_est, estimated=True)
    if not path.name.lower().endswith(".gz"):
        head = head_lines(path, encoding, "replace")
        try:
            lay = sniff_text(head, text)
        except TooManyColumnsError as exc:
            raise FileFormatError(f"{path}: {exc}") from None
        except FileFormatError:
            lay = None  # not numeric text: the CSV reader says what is wrong
        needs_text = text is not None and (
            text.names is not None or text.on_bad_lines == "skip" or text.delimiter or text.decimal
        )
        if (lay is not None and not lay.plain) or needs_text:
            return read_text(path, encoding, text)
    header = csv_header_names(path, encoding)
    check_column_count(path, len(header))  # pandas makes an object per column first
    check_unique_names(path, header)  # before pandas renames
    try:
        df = pd.read_csv(
            path,
            skipinitialspace=True,
            comment=None,
            low_memory=False,
            **csv_float_options(),
            encoding=encoding,
        )
    except pd.errors.EmptyDataError:
        raise FileFormatError(f"{path}: the file is empty (no header)") from None
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FileFormatError(f"{path}: not a readable CSV file ({msg})") from None
    df.columns = [str(c).strip() for c in df.columns]
    check_unique_names(path, list(df.columns))  # ``a`` and ``a `` are one name stripped
    return df, {}


def read_log_table(path: str | Path, topic: str | None) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One topic instance of a flight-controller log (.ulg, .bin) as a table and its
    metadata (for commands that go through it in chunks: compensate)."""
    p = Path(path)
    kind = file_kind(p)
    if kind not in ("ulog", "dataflash"):
        raise ThermocalInputError(f"{p}: --topic is for flight-controller logs (.ulg, .bin)")
    obj, info = read_table(p, kind, None, topic)
    assert isinstance(obj, pd.DataFrame)
    return obj, info


def read_text_table(
    path: str | Path, text: TextOptions, time: str | None = None
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """A text log read whole with ``text`` (names, rate, bad lines, delimiter, decimal):
    the table (a ``time`` column added for ``--rate``) and its sidecar metadata — for
    commands that then go through it in chunks (compensate).  Text logs are small; the
    memory check still applies."""
    p = Path(path)
    if file_kind(p) != "csv":
        raise ThermocalInputError(
            f"{p}: --names, --rate, --on-bad-lines, --delimiter and --decimal are for text logs"
        )
    obj, file_meta = read_table(p, "csv", text)
    info: dict[str, Any] = {**file_meta, **load_sidecar(p)}
    assert isinstance(obj, pd.DataFrame)
    names = list(obj.columns)
    if text.rate_hz is not None:
        obj, names, t_col, t_unit, _mode = rate_time(
            p, obj, names, info, time, None, text, allow_column=False
        )
        info["time"], info["time_unit"] = t_col, t_unit
    return obj, info


def _fc_log_unknown_units(
    p: Path,
    info: dict[str, Any],
    sig_names: Sequence[str],
    option: str | None,
    model: units.StatedUnits | None,
) -> None:
    """A flight-controller log's field whose unit neither the firmware's message definition
    known here (:data:`PX4_UNITS`, :data:`ARDUPILOT_UNITS`), nor ``--signal-unit``, the column
    name or the model states is read as raw values (``counts``, not converted) with a
    :class:`~thermocal.errors.UnitWarning` — never guessed as °/h (issue 28)."""
    if option:
        return
    known: dict[str, str] = info.setdefault("units", {})
    topic = info.get("ulog_topic") or info.get("dataflash_message") or "?"
    for c in sig_names:
        if c in known or units.unit_in_column_name(c, "signal") is not None:
            continue
        if model is not None and model.columns.get(c):
            continue
        known[c] = "counts"
        warnings.warn(
            UnitWarning(
                f"{p}: the unit of field {c!r} of {topic} is not known from the firmware's "
                "message definition: read as raw values (counts), not converted; give "
                "--signal-unit"
            ),
            stacklevel=3,
        )


def _open_table(
    p: Path, text: TextOptions | None, topic: str | None
) -> tuple[pd.DataFrame | ParquetColumns, dict[str, Any]]:
    """The table of a file (its extension chooses the reader) or of a station's recording
    folder (``DIR`` or ``DIR/SENSOR``), and what the file and its sidecar say of it.  A
    FIFO, device or socket is refused before it is opened, a plain directory named."""
    refuse_special_input(p)
    station = is_station_path(p)  # a station's recording folder, DIR or DIR/SENSOR
    if p.is_dir() and not station:
        raise FileFormatError(
            f"{p}: is a directory, not a recording file (a folder is read only when "
            "`thermocal station run` wrote it: it holds station.json)"
        )
    kind = "station" if station else file_kind(p)
    if topic is not None and kind not in ("ulog", "dataflash", "station"):
        raise ThermocalInputError(
            f"{p}: --topic/--sensor is for flight-controller logs (.ulg, .bin) and station "
            "recordings"
        )
    obj: pd.DataFrame | ParquetColumns
    if station:  # --sensor ID (the same option as --topic) picks DIR/ID
        obj, file_meta = read_station_table(with_sensor(p, topic))
    else:
        obj, file_meta = read_table(p, kind, text, topic)
    side = load_sidecar(p)
    info: dict[str, Any] = {**file_meta, **side}
    return obj, info


def _resolve_units(
    p: Path,
    info: dict[str, Any],
    columns: tuple[str, list[str], list[str]],
    options: units.UnitOptions,
    meta: Metadata | None,
    model: units.StatedUnits | None,
) -> units.ResolvedInputs:
    """Units and conversions of the time, signal and temperature ``columns`` by the one
    resolver (:func:`thermocal.units.resolve_inputs`: option > file > column name > model
    file > a stated default); ``meta``'s conversions count as the file's.  A flight
    controller's log first refuses signals whose unit nothing states."""
    time_col, sig_names, tmp_names = columns
    if info.get("fc_log"):
        _fc_log_unknown_units(p, info, sig_names, options.signal_unit, model)
    where = str(p)
    stated = units.StatedUnits.from_file_info(info, where)
    return units.resolve_inputs(
        time_col,
        sig_names,
        tmp_names,
        options=options,
        file=dataclasses.replace(
            stated,
            conversions={**stated.conversions, **(meta.temperature_conversion if meta else {})},
        ),
        model=model,
        where=where,
    )


def _read_other_columns(
    p: Path,
    obj: pd.DataFrame | ParquetColumns,
    names: list[str],
    cols: dict[str, FloatArray],
    unit_map: dict[str, str],
    info: dict[str, Any],
    skipped: list[str] | None,
) -> None:
    """Add the numeric columns of ``names`` not read yet to ``cols`` (with their units:
    the file's, else from the name); non-numeric ones are skipped (their names appended to
    ``skipped``)."""
    extra_units: dict[str, str] = dict(info.get("units") or {})
    for c in names:
        if c in cols:
            continue
        try:
            cols[c] = numeric_column(obj, c, p)
        except NonNumericError:
            if skipped is not None:
                skipped.append(c)
            continue
        unit_map[c] = units.other_column_unit(c, extra_units.get(c))


_BANNER_RATE = re.compile(
    r"^\s*(fs|rate|sample[ _]?rate|sampling[ _]?rate|odr|freq(uency)?)\s*(\[?hz\]?)?\s*[,:=;\t ]"
    r"\s*([0-9]+(\.[0-9]*)?)\s*(hz)?\s*$",
    re.IGNORECASE,
)
"""A banner line stating the sample rate: ``Fs,100``, ``rate: 50 Hz``, ``ODR=400``."""


def time_hint(names: list[str], banner: Sequence[str] = ()) -> str:
    """What to give when no time column is found: ``--time`` or ``--rate``, naming a
    sample counter (the time with ``--rate``), a rate the file's banner states
    (``banner``: its lines) or a column named like a temperature (not time) among
    ``names``."""
    counter = counter_column(names)
    temp_like = [n for n in names if named_like_temperature(n)]
    stated = [(b, m.group(4)) for b in banner if (m := _BANNER_RATE.match(b))]
    if stated:
        line, hz = stated[0]
        return f" (the file's banner says {line.strip()!r}: give --rate {hz})"
    if counter is not None:
        why = f"; {short_name(counter)} is a sample counter: give --rate HZ"
    elif temp_like:
        why = f"; {short_name(temp_like[0])} is named like a temperature, not time"
    else:
        why = ""
    return f" (name the time column with --time, or give --rate HZ for a log without one{why})"


def _roles(
    p: Path,
    names: list[str],
    info: dict[str, Any],
    time: str | None,
    signals: list[str] | None,
    temperatures: list[str] | None,
    guess_temperatures: bool = False,
) -> tuple[str, list[str], list[str]]:
    """The time, signal and temperature columns: as given, else as the file or its
    sidecar says (else, with ``guess_temperatures``, the columns named like temperatures,
    :func:`~thermocal.readers.common.named_like_temperature`); a name the file does not have is
    refused, listing the available ones."""
    time_col = time or default_time_column(names, info.get("time"))
    sig_info: dict[str, str] = dict(info.get("signals") or {})
    tmp_info: dict[str, str] = dict(info.get("temperatures") or {})
    sig_names = list(signals) if signals is not None else list(sig_info)
    tmp_names = list(temperatures) if temperatures is not None else list(tmp_info)
    if guess_temperatures and temperatures is None and not tmp_names:
        tmp_names = [
            c for c in names if named_like_temperature(c) and c != time_col and c not in sig_names
        ]
    present = set(names)
    for c in [time_col, *sig_names, *tmp_names]:
        if c not in present:
            hint = ""
            if c == time_col and time is None:
                hint = time_hint(names, (info.get("text_layout") or {}).get("banner") or ())
            same = [n for n in names if units.strip_unit_from_name(n) == c.strip()]
            if len(same) == 1 and not hint:  # 'acc_x' for the file's 'acc_x [counts]'
                hint = f" (did you mean {same[0]!r}? give the name as the file writes it)"
            raise MissingColumnError(
                f"{p}: no column {short_name(c)}; available: {names_list(names)}{hint}"
            )
    return time_col, sig_names, tmp_names


def _read_columns(
    p: Path,
    obj: pd.DataFrame | ParquetColumns,
    n_rows: int,
    n_used: int,
    time_col: str,
    named: list[str],
) -> tuple[FloatArray, dict[str, FloatArray]]:
    """The time column (in the file's unit) and the ``named`` columns as float64; a Parquet
    file is read column by column, only these, once its ``n_used`` columns of ``n_rows``
    are known to fit in memory."""
    if isinstance(obj, ParquetColumns):  # read column by column: only what is used
        check_memory(p, n_rows, n_used)
        obj.read_f64([time_col, *named])
    t = numeric_column(obj, time_col, p)
    return t, {c: numeric_column(obj, c, p) for c in named}


def _n_rows(p: Path, obj: pd.DataFrame | ParquetColumns, names: list[str]) -> int:
    """The table's number of rows; a table without columns or rows is refused."""
    if not names:
        raise FileFormatError(f"{p}: the file has no columns")
    n_rows = obj.num_rows if isinstance(obj, ParquetColumns) else len(obj)
    if n_rows == 0:
        raise FileFormatError(f"{p}: the file has a header but no data rows")
    return n_rows


def _time_s(
    p: Path, col: str, t: FloatArray, unit: str, mode: str | None, text: TextOptions | None
) -> FloatArray:
    """The time column ``t`` (as read, in ``unit``) in seconds: with ``--rate`` a sample
    counter's ``n / rate`` (``mode`` ``"counter"``) or host stamps at the nominal rate
    (``"stamps"``), as :func:`~thermocal.readers.text.rate_time` found them."""
    rate = text.rate_hz if text is not None else None
    if mode == "counter" and rate is not None:
        return counter_time(p, col, t, rate)
    if unit != "s":
        t = t * units.TIME_UNITS[unit]
    if mode == "stamps" and rate is not None:
        t = _stamps_at_rate(p, col, t, rate)
    return t


STAMPS_RATE_RANGE = (0.8, 3.0)
"""With ``--rate`` on a file with a time column, the mean step of its stamps must lie
within these multiples of the nominal period (fewer samples than the rate: some lost;
more, or far fewer: the wrong rate or time unit)."""


STAMPS_RATE_TOLERANCE = 0.005
"""With ``--rate`` on host timestamps, a rate the stamps' span contradicts by more than
this fraction (lost samples counted) is stated in a warning: a wrong nominal rate lifts the
latency floor by a period every few dozen samples, read as samples lost."""


def _stamps_at_rate(p: Path, col: str, t: FloatArray, rate_hz: float) -> FloatArray:
    """``--rate`` on a file whose time column holds host timestamps [s]: the samples at the
    sensor's nominal rate (:func:`thermocal.recording.nominal_time`, lost samples kept as
    gaps); refused when the stamps are not finite or their mean step is not near the
    nominal period (:data:`STAMPS_RATE_RANGE`)."""
    if t.size < 2:
        return t
    if not all_finite(t):
        raise ThermocalInputError(
            f"{p}: the time column {col!r} has missing or non-finite values; --rate "
            f"{rate_hz:g} Hz takes the samples at the nominal rate only from finite stamps"
        )
    mean_step = float(t[-1] - t[0]) / (t.size - 1)
    lo, hi = STAMPS_RATE_RANGE
    if not lo / rate_hz <= mean_step <= hi / rate_hz:
        raise ThermocalInputError(
            f"{p}: --rate {rate_hz:g} Hz given but the file has a time column {col!r} whose "
            f"samples are {mean_step:.6g} s apart on average ({1.0 / mean_step:.6g} Hz); "
            "check --rate and --time-unit, or drop --rate"
            if mean_step > 0
            else f"{p}: --rate {rate_hz:g} Hz given but the file has a time column {col!r} "
            "that does not advance; drop --rate"
        )
    out, lost = nominal_time(t, rate_hz)
    seen_hz = (t.size - 1 + lost) / float(t[-1] - t[0])
    if abs(seen_hz / rate_hz - 1.0) > STAMPS_RATE_TOLERANCE:
        warnings.warn(
            TimestampWarning(
                f"{p}: --rate {rate_hz:g} Hz, but the time column {col!r} spans "
                f"{float(t[-1] - t[0]):.6g} s for {t.size} samples "
                f"({(t.size - 1) / float(t[-1] - t[0]):.6g} Hz) and {lost} more would be lost "
                "at that rate; check --rate (the nominal rate, not a rounded one)"
            ),
            stacklevel=3,
        )
    return out


def _conversions(
    md: Metadata, tmp_names: list[str], resolved: units.ResolvedInputs
) -> dict[str, units.TemperatureConversion]:
    """The temperature conversions a recording keeps: the resolved ones of its temperature
    columns, the metadata's for the other (guessed) columns."""
    return {  # the resolved ones; others kept for guessed columns
        **{c: v for c, v in md.temperature_conversion.items() if c not in tmp_names},
        **{c: r.conversion for c, r in resolved.conversions.items() if r.conversion is not None},
    }


def read_recording(
    path: str | Path,
    *,
    time: str | None = None,
    time_unit: str | None = None,
    signals: list[str] | None = None,
    temperatures: list[str] | None = None,
    signal_unit: str | None = None,
    temp_unit: str | None = None,
    meta: Metadata | None = None,
    keep_other: bool = True,
    skipped: list[str] | None = None,
    temp_conversion: units.TemperatureConversion | None = None,
    model: units.StatedUnits | None = None,
    text: TextOptions | None = None,
    topic: str | None = None,
    guess_temperatures: bool = False,
    ask_units: dict[str, str] | None = None,
    implied_units: dict[str, str] | None = None,
) -> Recording:
    """Read a CSV, text log or Parquet recording, or a station's recording folder.

    Parameters
    ----------
    path : the file; its extension chooses the format.  A folder written by ``thermocal
        station run`` is read as one recording (``DIR``, or ``DIR/SENSOR`` of several).
    time : name of the time column (default: sidecar's, else ``"time"``).
    time_unit : ``s``, ``ms`` or ``us``; converted to [s].
    signals, temperatures : column names with those roles (default: sidecar's).
    signal_unit, temp_unit : units of those columns (override the sidecar); ``signal_unit``
        may be ``U1,…,Un``, one per signal.
    meta : metadata that overrides the file's (its temperature conversions count as options).
    keep_other : keep the other numeric columns (non-numeric ones are skipped).
    skipped : if a list is given, the names of skipped non-numeric columns are appended.
    temp_conversion : ``--temp-conversion``, the counts → °C conversion of every
        temperature column (which it says are raw counts).
    model : the units a model file recorded of its inputs
        (:meth:`thermocal.units.StatedUnits.from_model_inputs`): used where the option,
        the file and the column name are silent.
    text : how to read a text log (:class:`TextOptions`: ``--names``, ``--rate``,
        ``--on-bad-lines``, ``--delimiter``, ``--decimal``); banners, other delimiters and
        decimal commas are detected without it.
    topic : a PX4 ULog's topic instance, ``NAME[.N]`` (default ``sensor_gyro.0``).
    guess_temperatures : no temperatures given or in a sidecar: those named like one.
    ask_units, implied_units : signal column → the option a :class:`UnitError` asks for,
        or the unit another option implies (``counts``: a count scale), where nothing
        states its unit (:class:`thermocal.units.UnitOptions`).

    Units and temperature conversions are resolved once by
    :func:`thermocal.units.resolve_inputs` (option > file metadata > column name > model
    file > a default stated in a warning); each one's source is ``Recording.unit_sources``.

    Raises
    ------
    FileFormatError : not CSV/Parquet, unreadable or empty.
    MissingColumnError : a named column is absent (the available ones are listed).
    NonNumericError : a non-numeric cell in a named column (row and column named).
    UnitError : an unknown unit string.
    """
    p = Path(path)
    obj, info = _open_table(p, text, topic)

    names = list(obj.column_names) if isinstance(obj, ParquetColumns) else list(obj.columns)
    mode = None  # --rate: "rows", "counter" or "stamps" (rate_time)
    if text is not None and text.rate_hz is not None:
        obj, names, time, time_unit, mode = rate_time(p, obj, names, info, time, time_unit, text)
    n_rows = _n_rows(p, obj, names)
    md = Metadata.from_dict(dict(info.get("metadata") or {}))
    if meta is not None:
        md = md.merged(meta)
    time_col, sig_names, tmp_names = _roles(
        p, names, info, time, signals, temperatures, guess_temperatures
    )
    options = units.UnitOptions(  # a counter / rate is in s
        "s" if mode == "counter" else time_unit, signal_unit, temp_unit, temp_conversion,
        dict(ask_units or {}), dict(implied_units or {}),
    )  # fmt: skip
    resolved = _resolve_units(p, info, (time_col, sig_names, tmp_names), options, meta, model)
    n_used = len(names) if keep_other else 1 + len(sig_names) + len(tmp_names)
    t, cols = _read_columns(p, obj, n_rows, n_used, time_col, [*sig_names, *tmp_names])
    t = _time_s(p, time_col, t, resolved.time.unit, mode, text)
    unit_map: dict[str, str] = resolved.units()
    md.temperature_conversion = _conversions(md, tmp_names, resolved)
    if keep_other:
        _read_other_columns(
            p, obj, [c for c in names if c != time_col], cols, unit_map, info, skipped
        )

    return Recording(
        time_s=t,
        columns=cols,
        units=unit_map,
        signals=tuple(sig_names),
        temperatures=tuple(tmp_names),
        meta=md,
        source=str(p),
        time_unit=resolved.time.unit,
        unit_sources=resolved.sources(),
    )


def recording_info(rec: Recording, time: str = "time") -> dict[str, Any]:
    """The metadata object written beside (or into) a recording file."""
    return {
        "format": META_FORMAT,
        "version": META_VERSION,
        "time": time,
        "time_unit": "s",
        "signals": {s: rec.units.get(s, "") for s in rec.signals},
        "temperatures": {s: rec.units.get(s, "") for s in rec.temperatures},
        "units": {
            c: u
            for c, u in rec.units.items()
            if u and c not in rec.signals and c not in rec.temperatures
        },
        "metadata": rec.meta.to_dict(),
    }
