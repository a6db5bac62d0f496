"""One entry for every file a command takes: :func:`read_recording` looks the file's format
up in the registry (:mod:`thermocal.readers.formats`: CSV/Parquet, text log, ULog,
DataFlash, station folder, plugins) and returns a :class:`Recording`."""

from __future__ import annotations

import dataclasses
import re
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

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
    default_time_column,
    named_like_temperature,
    names_list,
    short_name,
)
from thermocal.readers.formats import TEXT_FIELDS, FileFormat, format_of, registered_formats
from thermocal.readers.options import CHAMBER_COLUMN, ReadOptions
from thermocal.readers.station import is_station_path
from thermocal.readers.table import (
    ON_DEMAND_MIN_COLUMNS,
    ColumnsOnDemand,
    ParquetColumns,
    load_sidecar,
    numeric_column,
)
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

    from thermocal.models.base import TemperatureModel
else:
    pd = LazyModule("pandas")


def _checked_file(path: Path) -> None:
    """A file that exists and holds something."""
    if not path.exists():
        raise FileFormatError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise FileFormatError(f"{path}: the file is empty")


def read_table(
    path: Path, read: ReadOptions, fmt: FileFormat | None = None
) -> tuple[pd.DataFrame | ParquetColumns, dict[str, Any]]:
    """The table of a file and what the file itself says of it, by its registered reader.

    Parameters
    ----------
    path : Path
        The file, or a station's recording folder.
    read : ReadOptions
        How to read it (its topic, a text log's layout).
    fmt : FileFormat, optional
        Its format, when known (default: :func:`~thermocal.readers.formats.format_of`).

    Returns
    -------
    tuple
        ``(table, metadata)``: a ``pandas.DataFrame`` (or the lazy Parquet table) and the
        file's own metadata (units, roles), before its sidecar.

    Raises
    ------
    thermocal.errors.FileFormatError
        No such file, an empty one, or one its format's reader cannot read.
    """
    fmt = fmt or format_of(path)
    if fmt.sniff is None or not fmt.sniff(path):  # a folder a format recognises is no file
        _checked_file(path)
    return fmt.read(path, read)


def read_whole_table(path: str | Path, read: ReadOptions) -> tuple[pd.DataFrame, dict[str, Any]]:
    """A file read whole as one table with its metadata and sidecar, for a command that then
    goes through it in chunks (compensate): a flight-controller log's topic, a plugin's
    format, or a text log read with its layout options (``names``, ``rate_hz`` — a ``time``
    column added —, ``on_bad_lines``, ``delimiter``, ``decimal``).

    Parameters
    ----------
    path : str or Path
        The file.
    read : ReadOptions
        How to read it.

    Returns
    -------
    tuple
        ``(table, metadata)``, the sidecar's metadata over the file's.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A field of ``read`` that does not apply to the file's format (named).
    """
    p = Path(path)
    fmt = format_of(p)
    if read.topic is not None and "topic" not in fmt.options:
        raise ThermocalInputError.naming(
            f"{p}: {{topic}} is for flight-controller logs (.ulg, .bin)", "topic"
        )
    if read.text_layout_given and not fmt.options >= TEXT_FIELDS:
        raise ThermocalInputError.naming(
            f"{p}: {{names}}, {{rate_hz}}, {{on_bad_lines}}, {{delimiter}} and {{decimal}} are "
            "for text logs",
            *_TEXT_LAYOUT,
        )
    obj, file_meta = read_table(p, read, fmt)
    info: dict[str, Any] = {**file_meta, **load_sidecar(p)}
    if not isinstance(obj, pd.DataFrame):
        raise FileFormatError(f"{p}: {fmt.title} ({fmt.name}) is not read whole as one table")
    names = list(obj.columns)
    if read.rate_hz is not None:
        from thermocal.readers.text import rate_time

        obj, names, t_col, t_unit, _mode = rate_time(
            p, obj, names, info, read.time, None, read, allow_column=False
        )
        info["time"], info["time_unit"] = t_col, t_unit
    return obj, info


_TEXT_LAYOUT: tuple[str, ...] = ("names", "rate_hz", "on_bad_lines", "delimiter", "decimal")
"""The :class:`ReadOptions` fields of a text log's layout, as messages name them."""


def _fc_log_unknown_units(
    p: Path,
    info: dict[str, Any],
    sig_names: Sequence[str],
    option: str | tuple[str, ...] | None,
    model: units.StatedUnits | None,
) -> None:
    """A flight-controller log's field whose unit neither the firmware's message definition
    known here (:data:`PX4_UNITS`, :data:`ARDUPILOT_UNITS`), nor ``signal_unit``, the column
    name or the model states is read as raw values (``counts``, not converted) with a
    :class:`~thermocal.errors.UnitWarning` — never guessed as °/h."""
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
            UnitWarning.naming(
                f"{p}: the unit of field {c!r} of {topic} is not known from the firmware's "
                "message definition: read as raw values (counts), not converted; give "
                "{signal_unit}",
                "signal_unit",
            ),
            stacklevel=3,
        )


def open_table(p: Path, read: ReadOptions) -> tuple[pd.DataFrame | ParquetColumns, dict[str, Any]]:
    """The table of a file (its registered format chooses the reader) or of a station's
    recording folder (``DIR`` or ``DIR/SENSOR``), and what the file and its sidecar say of
    it.  A FIFO, device or socket is refused before it is opened, a plain directory named.

    Parameters
    ----------
    p : Path
        The file or folder.
    read : ReadOptions
        How it is read (a log's topic, a text layout).

    Returns
    -------
    table : pandas.DataFrame or ParquetColumns
        The table (a Parquet file's columns are read when asked for).
    info : dict
        What the file's metadata and its sidecar state (units, roles, metadata).

    Raises
    ------
    thermocal.errors.FileFormatError
        No registered format reads it, or a folder that is not a station's recording.
    thermocal.errors.ThermocalInputError
        An option the format does not take (``topic``, ``stamp``).
    """
    refuse_special_input(p)
    fmt = format_of(p) if not p.is_dir() or is_station_path(p) else None
    if fmt is None and p.is_dir():  # a folder another format recognises (a ROS 2 bag)
        fmt = next((f for f in registered_formats() if f.sniff and f.sniff(p)), None)
    if fmt is None:
        raise FileFormatError(
            f"{p}: is a directory, not a recording file (a folder is read only when "
            "`thermocal station run` wrote it: it holds station.json)"
        )
    if read.topic is not None and "topic" not in fmt.options:
        raise ThermocalInputError.naming(
            f"{p}: {{topic}} is for flight-controller logs (.ulg, .bin) and station recordings",
            "topic",
        )
    if read.stamp != "header" and "stamp" not in fmt.options:
        raise ThermocalInputError.naming(f"{p}: {{stamp}} is for ROS bags and MCAP files", "stamp")
    obj, file_meta = read_table(p, read, fmt)
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
        lazy: Any = cols  # a numeric column of a file read on demand: read when asked for
        if (
            isinstance(lazy, ColumnsOnDemand)
            and isinstance(obj, ParquetColumns)
            and obj.is_numeric(c)
        ):
            lazy.add(c)
            unit_map[c] = units.other_column_unit(c, extra_units.get(c))
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
    """What to give when no time column is found: ``time`` or ``rate_hz``, naming a
    sample counter (the time with ``rate_hz``), a rate the file's banner states
    (``banner``: its lines) or a column named like a temperature (not time) among
    ``names``.  A template: ``{time}`` and ``{rate_hz}`` stand for the parameters
    (:data:`TIME_HINT_PARAMETERS`; build the message with
    :meth:`~thermocal.errors.ThermocalInputError.naming`).

    Parameters
    ----------
    names : list of str
        The file's column names.
    banner : sequence of str, optional
        The banner lines skipped before the data; default none.

    Returns
    -------
    str
        A parenthesised hint, beginning with a blank, to end an error message.

    Examples
    --------
    >>> from thermocal.readers.dispatch import time_hint
    >>> time_hint(["n", "gyro"], ["rate: 50 Hz"])
    " (the file's banner says 'rate: 50 Hz': give {rate_hz} 50)"
    """
    from thermocal.readers.text import counter_column

    counter = counter_column(names)
    temp_like = [n for n in names if named_like_temperature(n)]
    stated = [(b, m.group(4)) for b in banner if (m := _BANNER_RATE.match(b))]
    if stated:
        line, hz = stated[0]
        return f" (the file's banner says {line.strip()!r}: give {{rate_hz}} {hz})"
    if counter is not None:
        why = f"; {short_name(counter)} is a sample counter: give {{rate_hz}} HZ"
    elif temp_like:
        why = f"; {short_name(temp_like[0])} is named like a temperature, not time"
    else:
        why = ""
    return (
        f" (name the time column with {{time}}, or give {{rate_hz}} HZ for a log without one{why})"
    )


TIME_HINT_PARAMETERS: tuple[str, ...] = ("time", "rate_hz")
"""The parameters a :func:`time_hint` names."""


def column_roles(
    p: Path,
    names: list[str],
    info: dict[str, Any],
    time: str | None,
    signals: Sequence[str] | None,
    temperatures: Sequence[str] | None,
    guess_temperatures: bool = False,
) -> tuple[str, list[str], list[str]]:
    """The time, signal and temperature columns: as given, else as the file or its
    sidecar says (else, with ``guess_temperatures``, the columns named like temperatures,
    :func:`~thermocal.readers.common.named_like_temperature`); a name the file does not have is
    refused, listing the available ones.

    Parameters
    ----------
    p : Path
        The file, named in errors.
    names : list of str
        The file's columns.
    info : dict
        What the file and its sidecar state (:func:`open_table`).
    time, signals, temperatures : optional
        The columns given (``ReadOptions.time``, ``.signals``, ``.temperatures``).
    guess_temperatures : bool, optional
        No temperatures given or stated: take those named like one.

    Returns
    -------
    time_col : str
        The time column.
    sig_names, tmp_names : list of str
        The signal and the temperature columns.

    Raises
    ------
    thermocal.errors.MissingColumnError
        A column the file does not have (the available ones listed).
    """
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
            if c == CHAMBER_COLUMN and c in tmp_names and not hint:  # no log was joined
                hint = (
                    f" ({CHAMBER_COLUMN!r} is the chamber log's temperature: give the log, "
                    "{chamber_log} FILE:CHANNEL)"
                )
            raise MissingColumnError.naming(
                f"{p}: no column {short_name(c)}; available: {names_list(names)}{hint}",
                *TIME_HINT_PARAMETERS,
                *(("chamber_log",) if "{chamber_log}" in hint else ()),
            )
    return time_col, sig_names, tmp_names


def _read_columns(
    p: Path,
    obj: pd.DataFrame | ParquetColumns,
    size: tuple[int, int],
    time_col: str,
    named: list[str],
    on_demand: bool = False,
) -> tuple[FloatArray, dict[str, FloatArray]]:
    """The time column (in the file's unit) and the ``named`` columns as float64; a Parquet
    file is read column by column, only these, once its ``n_used`` columns of ``n_rows``
    (``size``) are known to fit in memory; ``on_demand``: its numeric columns read when
    asked for (:class:`ColumnsOnDemand`), three columns' memory needed at most."""
    if isinstance(obj, ParquetColumns):  # read column by column: only what is used
        n_rows, n_used = size  # on demand: time and two columns held at a time
        check_memory(p, n_rows, min(n_used, ON_DEMAND_MIN_COLUMNS) if on_demand else n_used)
        if on_demand:
            lazy = ColumnsOnDemand(obj, p)
            t = numeric_column(obj, time_col, p)
            for c in named:
                if obj.is_numeric(c):
                    lazy.add(c)
                else:  # read now: a non-numeric cell is refused as by a whole read
                    lazy[c] = numeric_column(obj, c, p)
            return t, cast("dict[str, FloatArray]", lazy)
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
    p: Path, col: str, t: FloatArray, unit: str, mode: str | None, text: ReadOptions
) -> FloatArray:
    """The time column ``t`` (as read, in ``unit``) in seconds: with ``rate_hz`` a sample
    counter's ``n / rate`` (``mode`` ``"counter"``) or host stamps at the nominal rate
    (``"stamps"``), as :func:`~thermocal.readers.text.rate_time` found them."""
    rate = text.rate_hz
    if mode == "counter" and rate is not None:
        from thermocal.readers.text import counter_time

        return counter_time(p, col, t, rate)
    if unit != "s":
        t = t * units.TIME_UNITS[unit]
    if mode == "stamps" and rate is not None:
        t = _stamps_at_rate(p, col, t, rate)
    return t


STAMPS_RATE_RANGE = (0.8, 3.0)
"""With ``rate_hz`` on a file with a time column, the mean step of its stamps must lie
within these multiples of the nominal period (fewer samples than the rate: some lost;
more, or far fewer: the wrong rate or time unit)."""


STAMPS_RATE_TOLERANCE = 0.005
"""With ``rate_hz`` on host timestamps, a rate the stamps' span contradicts by more than
this fraction (lost samples counted) is stated in a warning: a wrong nominal rate lifts the
latency floor by a period every few dozen samples, read as samples lost."""


def _stamps_at_rate(p: Path, col: str, t: FloatArray, rate_hz: float) -> FloatArray:
    """``rate_hz`` on a file whose time column holds host timestamps [s]: the samples at the
    sensor's nominal rate (:func:`thermocal.recording.nominal_time`, lost samples kept as
    gaps); refused when the stamps are not finite or their mean step is not near the
    nominal period (:data:`STAMPS_RATE_RANGE`)."""
    if t.size < 2:
        return t
    if not all_finite(t):
        raise ThermocalInputError.naming(
            f"{p}: the time column {col!r} has missing or non-finite values; {{rate_hz}} "
            f"{rate_hz:g} Hz takes the samples at the nominal rate only from finite stamps",
            "rate_hz",
        )
    mean_step = float(t[-1] - t[0]) / (t.size - 1)
    lo, hi = STAMPS_RATE_RANGE
    if not lo / rate_hz <= mean_step <= hi / rate_hz:
        raise ThermocalInputError.naming(
            f"{p}: {{rate_hz}} {rate_hz:g} Hz given but the file has a time column {col!r} "
            f"whose samples are {mean_step:.6g} s apart on average ({1.0 / mean_step:.6g} Hz); "
            "check {rate_hz} and {time_unit}, or drop {rate_hz}"
            if mean_step > 0
            else f"{p}: {{rate_hz}} {rate_hz:g} Hz given but the file has a time column {col!r} "
            "that does not advance; drop {rate_hz}",
            "rate_hz",
            "time_unit",
        )
    out, lost = nominal_time(t, rate_hz)
    seen_hz = (t.size - 1 + lost) / float(t[-1] - t[0])
    if abs(seen_hz / rate_hz - 1.0) > STAMPS_RATE_TOLERANCE:
        warnings.warn(
            TimestampWarning.naming(
                f"{p}: {{rate_hz}} {rate_hz:g} Hz, but the time column {col!r} spans "
                f"{float(t[-1] - t[0]):.6g} s for {t.size} samples "
                f"({(t.size - 1) / float(t[-1] - t[0]):.6g} Hz) and {lost} more would be lost "
                "at that rate; check {rate_hz} (the nominal rate, not a rounded one)",
                "rate_hz",
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


def _stated_by_model(
    model: TemperatureModel | units.StatedUnits | Mapping[str, Any] | None,
) -> tuple[units.StatedUnits | None, Mapping[str, Any] | None]:
    """What a model states of its inputs (units, conversions) and its record of them (the
    sensor id it was fitted on): from a fitted model, a model file's ``inputs`` or the
    stated units alone."""
    if model is None or isinstance(model, units.StatedUnits):
        return model, None
    if isinstance(model, Mapping):
        return units.StatedUnits.from_model_inputs(dict(model)), model
    return model.input_units(), getattr(model, "inputs_", None)


def read_recording(
    path: str | Path,
    read: ReadOptions | None = None,
    *,
    meta: Metadata | None = None,
    keep_other: bool = True,
    skipped: list[str] | None = None,
    model: TemperatureModel | units.StatedUnits | Mapping[str, Any] | None = None,
    guess_temperatures: bool = False,
    ask_units: dict[str, str] | None = None,
    implied_units: dict[str, str] | None = None,
    columns_on_demand: bool = False,
) -> Recording:
    """Read a recording from any registered file format into a :class:`Recording`.

    The format is looked up in the file-format registry
    (:func:`thermocal.readers.formats.format_of`: CSV and text logs, Parquet, PX4 ULog,
    ArduPilot DataFlash, a station's recording folder, and installed plugins).  Units and
    temperature conversions are resolved once by :func:`thermocal.units.resolve_inputs`
    (``read`` > file metadata > column name > ``model`` > a default stated in a warning);
    each one's source is ``Recording.unit_sources``.  Time is converted to seconds,
    temperatures stay in their unit with the conversion to °C recorded.

    Parameters
    ----------
    path : str or Path
        The file.  A folder written by ``thermocal station run`` is read as one recording
        (``DIR``, or ``DIR/SENSOR`` of several).
    read : ReadOptions, optional
        How to read it: columns and their roles, units, a raw-count temperature conversion,
        a log's topic, a text log's layout (:class:`~thermocal.readers.options.ReadOptions`).
        Default: everything from the file.
    meta : Metadata, optional
        Metadata that overrides the file's (its temperature conversions count as options).
    keep_other : bool
        Keep the other numeric columns (non-numeric ones are skipped).
    skipped : list of str, optional
        When given, the names of skipped non-numeric columns are appended.
    model : TemperatureModel, StatedUnits or mapping, optional
        A fitted model, a model file's ``inputs`` record or the units a model file states
        (:meth:`thermocal.units.StatedUnits.from_model_inputs`): used where ``read``, the
        file and the column name are silent; a model's sensor id must match the file's.
    guess_temperatures : bool
        No temperatures given or in a sidecar: those named like one.
    ask_units, implied_units : dict, optional
        Signal column → the parameter a :class:`~thermocal.errors.UnitError` asks for
        (``"accel_unit"``), or the unit another parameter implies (``counts``: a count
        scale), where nothing states its unit (:class:`thermocal.units.UnitOptions`).
    columns_on_demand : bool, optional
        A Parquet file's columns read at each use, one held at a time, when more than
        :data:`~thermocal.readers.table.ON_DEMAND_MIN_COLUMNS` are used (time included).

    Returns
    -------
    Recording
        Time [s], the columns as float64, their units and roles, the metadata.

    Raises
    ------
    thermocal.errors.FileFormatError
        No registered format reads it, or it is unreadable or empty.
    thermocal.errors.MissingColumnError
        A named column is absent (the available ones are listed).
    thermocal.errors.NonNumericError
        A non-numeric cell in a named column (row and column named).
    thermocal.errors.UnitError
        An unknown unit string.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from thermocal.readers import ReadOptions, read_recording
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "run.csv").write_text("t_ms,gx,T\\n0,0.5,20.0\\n10,0.25,20.5\\n20,0.5,21.0\\n")
    >>> rec = read_recording(
    ...     d / "run.csv",
    ...     ReadOptions(time="t_ms", time_unit="ms", signals="gx", temperatures="T",
    ...                 signal_unit="deg/s", temp_unit="degC"),
    ... )
    >>> rec.time_s.tolist(), rec.units["gx"], rec.temperature_c("T").tolist()
    ([0.0, 0.01, 0.02], 'deg/s', [20.0, 20.5, 21.0])
    """
    p = Path(path)
    r, joined = _chamber_apart(read or ReadOptions())  # the chamber's column: not in the file
    obj, info = open_table(p, r)
    stated, fitted = _stated_by_model(model)
    units_of = units.UnitOptions(  # the options' own; a rate's counter is in s (below)
        r.time_unit, r.signal_unit, r.temp_unit, r.temp_conversion,
        dict(ask_units or {}), dict(implied_units or {}),
    )  # fmt: skip
    rec = table_recording(
        p, obj, info, r, units_of, meta=meta, keep_other=keep_other, skipped=skipped,
        stated=stated, guess_temperatures=guess_temperatures, columns_on_demand=columns_on_demand,
    )  # fmt: skip
    if fitted is not None:
        from thermocal.models.rundata import check_sensor_id

        check_sensor_id(fitted, rec.meta.sensor_id, str(p))
    return rec if joined is None else joined(rec)


def _chamber_apart(r: ReadOptions) -> tuple[ReadOptions, Callable[[Recording], Recording] | None]:
    """The options without the chamber log (its column taken off the temperatures: it is
    not in the file) and what joins it to the recording read (None without a log)."""
    chamber, asked = r.chamber_log, r.temperatures
    if chamber is None:
        return r, None
    from thermocal.readers.chamber_log import join_chamber_log

    rest = tuple(c for c in asked or () if c != CHAMBER_COLUMN)
    r = r.replace(chamber_log=None, temperatures=rest or (None if asked else asked))
    return r, lambda rec: join_chamber_log(rec, chamber, asked)


def table_recording(
    p: Path,
    obj: pd.DataFrame | ParquetColumns,
    info: dict[str, Any],
    r: ReadOptions,
    options: units.UnitOptions,
    *,
    meta: Metadata | None,
    keep_other: bool,
    skipped: list[str] | None,
    stated: units.StatedUnits | None,
    guess_temperatures: bool,
    columns_on_demand: bool = False,
) -> Recording:
    """The :class:`Recording` of a table read from ``p``: roles, units resolved once, time in
    seconds (a rate's rows, counter or stamps), the other numeric columns kept.

    Parameters
    ----------
    p : Path
        The file.
    obj : pandas.DataFrame or ParquetColumns
        Its table (:func:`open_table`).
    info : dict
        What the file and its sidecar state.
    r : ReadOptions
        How it is read.
    options : thermocal.units.UnitOptions
        The units given.
    meta, keep_other, skipped, stated, guess_temperatures
        As for :func:`read_recording` (``stated``: the units a model states).
    columns_on_demand : bool, optional
        As for :func:`read_recording`.

    Returns
    -------
    Recording
        Time [s], the columns as float64, their units and roles, the metadata.
    """
    names = list(obj.column_names) if isinstance(obj, ParquetColumns) else list(obj.columns)
    time, time_unit = r.time, r.time_unit
    mode = None  # rate_hz: "rows", "counter" or "stamps" (rate_time)
    if r.rate_hz is not None:
        from thermocal.readers.text import rate_time

        obj, names, time, time_unit, mode = rate_time(p, obj, names, info, time, time_unit, r)
    n_rows = _n_rows(p, obj, names)
    md = Metadata.from_dict(dict(info.get("metadata") or {}))
    if meta is not None:
        md = md.merged(meta)
    time_col, sig_names, tmp_names = column_roles(
        p, names, info, time, r.signals, r.temperatures, guess_temperatures
    )
    options = dataclasses.replace(options, time_unit="s" if mode == "counter" else time_unit)
    resolved = _resolve_units(p, info, (time_col, sig_names, tmp_names), options, meta, stated)
    n_used = len(names) if keep_other else 1 + len(sig_names) + len(tmp_names)
    t, cols = _read_columns(
        p, obj, (n_rows, n_used), time_col, [*sig_names, *tmp_names],
        columns_on_demand and n_used > ON_DEMAND_MIN_COLUMNS,
    )  # fmt: skip
    t = _time_s(p, time_col, t, resolved.time.unit, mode, r)
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
    """The metadata object written beside (or into) a recording file.

    Parameters
    ----------
    rec : Recording
        The recording written.
    time : str
        Name of its time column in the file (written in [s]).

    Returns
    -------
    dict
        ``format``, ``version``, ``time``, ``time_unit``, the signal and temperature
        columns with their units, the other columns' units and the metadata, as a CSV's
        ``FILE.meta.json`` sidecar or a Parquet file's key-value store holds it.
    """
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
