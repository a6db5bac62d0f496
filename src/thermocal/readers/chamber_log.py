"""A chamber's or data logger's own log: a text table with a wall clock.

Chambers and loggers write CSV/TSV files beside the sensor's recording: a clock column in
``hh:mm`` or ``hh:mm:ss`` (12 h with AM/PM too, or a date and time in one cell), sometimes a
date column or a date in the lines above the header (``YYYY-MM-DD``, ``DD.MM.YYYY``,
``DD/MM/YYYY`` or ``MM/DD/YYYY``), and temperature channels named by the instrument
(``TC1``, ``CH01 [°F]``, ``Chamber PV``, ``Set Point``) in °F, °C or K.

The parsing is pure (:func:`parse_chamber_log` on the file's text); :func:`read_chamber_log`
reads the file (never modifying it).  Temperatures are converted to °C:
:math:`T_C = (T_F - 32) \\cdot 5/9` and :math:`T_C = T_K - 273.15` (NIST SP 811, 2008, §B.8).
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
import re
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.chamber_join import (
    ClockJoin,
    join_clock,
    joined_values,
    timezone_seconds,
    timezone_text,
)
from thermocal.errors import (
    FileFormatError,
    PlausibilityWarning,
    ThermocalInputError,
    TimestampWarning,
)
from thermocal.outputs import refuse_special_input
from thermocal.readers.options import CHAMBER_COLUMN, ChamberLogSpec
from thermocal.recording import FloatArray, Recording

CHAMBER_UNITS: dict[str, tuple[float, float]] = {
    "degC": (1.0, 0.0),
    "degF": (5.0 / 9.0, -32.0 * 5.0 / 9.0),
    "K": (1.0, -273.15),
}
"""Chamber-log temperature units → ``(gain, offset)`` of :math:`T_C = g\\,v + o` (NIST SP 811,
§B.8: :math:`t/°C = (t/°F - 32)/1.8`, :math:`t/°C = T/K - 273.15`)."""

PLAUSIBLE_C = (-100.0, 300.0)
"""Chamber temperatures [°C] beyond which a channel's unit is doubted (a warning)."""

_UNIT_WORDS: dict[str, str] = {
    "°c": "degC", "degc": "degC", "c": "degC", "celsius": "degC", "deg c": "degC", "℃": "degC",
    "°f": "degF", "degf": "degF", "f": "degF", "fahrenheit": "degF", "deg f": "degF", "℉": "degF",
    "k": "K", "kelvin": "K",
}  # fmt: skip

_CLOCK = re.compile(
    r"^(?:(?P<date>\d{1,4}[-./]\d{1,2}[-./]\d{1,4})[ T]+)?"
    r"(?P<h>\d{1,2}):(?P<m>\d{2})(?::(?P<s>\d{2}(?:\.\d+)?))?"
    r"\s*(?P<ampm>[AaPp]\.?\s?[Mm]\.?)?$"
)
_CLOCK_ANYWHERE = re.compile(r"\d:\d\d")
_DATE = re.compile(r"(\d{1,4})([-./])(\d{1,2})\2(\d{1,4})")
_SETPOINT = re.compile(r"(?:^|[^a-z])(sp|sv|set ?point|setpoint|set|soll|target)(?:[^a-z]|$)", re.I)
_PROCESS = re.compile(r"(?:^|[^a-z])(pv|process|actual|ist|chamber|air)(?:[^a-z]|$)", re.I)
_BRACKET_UNIT = re.compile(r"[\[(]\s*([^\])]+?)\s*[\])]\s*$")


@dataclass(frozen=True)
class ChamberLog:
    """One channel of a chamber log on the log's clock.

    Attributes
    ----------
    source : str
        The file.
    time_s : numpy.ndarray
        The log's clock [s] from its first row (0 first), increasing.
    start : datetime.datetime or None
        The first row's date and time (local, naive) when the log has a date.
    channel : str
        The channel read (its header as written).
    temp_c : numpy.ndarray
        Its temperature [°C].
    unit : str
        Its unit in the file (``degF``, ``degC``, ``K``).
    unit_source : str
        ``option`` or ``header``.
    setpoint : bool
        The channel is a set-point (not a measured value).
    channels : tuple of str
        Every numeric channel of the log.
    """

    source: str
    time_s: FloatArray
    start: dt.datetime | None
    channel: str
    temp_c: FloatArray
    unit: str
    unit_source: str
    setpoint: bool
    channels: tuple[str, ...]


def _text_of(raw: bytes, where: str) -> str:
    """The file's text: UTF-8 (a BOM dropped), else Windows-1252; binary refused."""
    if not raw.strip():
        raise FileFormatError(f"{where}: the chamber log is empty")
    if b"\x00" in raw[:65536]:
        raise FileFormatError(f"{where}: a binary file, not a chamber log (a text table)")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("cp1252", errors="replace")


def _split(line: str, delim: str | None) -> list[str]:
    """A line's fields (blanks as separator when ``delim`` is None), stripped of quotes."""
    parts = line.split(delim) if delim is not None else re.split(r"\s{2,}|\t", line)
    return [p.strip().strip('"').strip() for p in parts]


def _delimiter(lines: list[str]) -> str | None:
    """The field separator: tab, ``;`` or ``,``, whichever splits the lines most evenly."""
    best: tuple[int, str | None] = (0, None)
    for d in ("\t", ";", ","):
        counts = [ln.count(d) for ln in lines[:50] if ln.strip()]
        if counts and min(counts[-10:]) > 0:
            best = max(best, (min(counts[-10:]), d), key=lambda x: x[0])
    return best[1]


def _is_clock(cell: str) -> bool:
    return _CLOCK.match(cell.strip()) is not None


def _unit_of(name: str) -> str | None:
    """The unit a channel's header states (``CH01 [°F]``, ``TC1 (K)``, ``Temp °C``)."""
    m = _BRACKET_UNIT.search(name)
    if m:
        return _UNIT_WORDS.get(m.group(1).strip().lower())
    low = name.strip().lower()
    for word, unit in _UNIT_WORDS.items():
        if len(word) > 1 and (low.endswith(" " + word) or (low.endswith(word) and "°" in word)):
            return unit
    return None


def _bare(name: str) -> str:
    """A channel's name without its unit (``CH01 [°F]`` → ``CH01``)."""
    return _BRACKET_UNIT.sub("", name).strip()


@dataclass(frozen=True)
class _Table:
    header: list[str]
    rows: list[tuple[int, list[str]]]  # (line number, fields)
    preamble: list[str]
    unit_row: list[str] | None


def _table(text: str, where: str) -> _Table:
    """Header, data rows (with their line numbers), the lines above the header and a row of
    units under it; the first data row is the first line with a clock in a field."""
    lines = text.splitlines()
    delim = _delimiter([ln for ln in lines if _CLOCK_ANYWHERE.search(ln)] or lines)
    first = next(
        (i for i, ln in enumerate(lines) if any(_is_clock(f) for f in _split(ln, delim))), None
    )
    if first is None or first == 0:
        header = _split(next((ln for ln in lines if ln.strip()), ""), delim)
        raise ThermocalInputError(
            f"{where}: clock column not found (hh:mm or hh:mm:ss under a header): columns are "
            + ", ".join(repr(h) for h in header[:20])
        )
    above = [i for i in range(first) if lines[i].strip()]
    unit_row = None
    h = above[-1]
    cells = _split(lines[h], delim)
    if len(above) >= 2 and all(not c or _UNIT_WORDS.get(c.lower()) for c in cells):
        unit_row, h = cells, above[-2]
    rows = [(i + 1, _split(lines[i], delim)) for i in range(first, len(lines)) if lines[i].strip()]
    return _Table(_split(lines[h], delim), rows, lines[:h], unit_row)


def _date(text: str, order: str | None, where: str) -> tuple[int, int, int] | str:
    """``(year, month, day)`` of a date cell, or ``"ambiguous"`` when day and month could be
    either (both ≤ 12, no ``order``)."""
    m = _DATE.search(text)
    if m is None:
        raise ThermocalInputError(f"{where}: {text!r} is not a date")
    a, sep, b, c = int(m.group(1)), m.group(2), int(m.group(3)), int(m.group(4))
    if len(m.group(1)) == 4:
        return a, b, c
    year = c + 2000 if c < 100 else c
    if sep == "." or order == "dmy":
        return year, b, a
    if order == "mdy":
        return year, a, b
    if a > 12:
        return year, b, a
    if b > 12:
        return year, a, b
    return "ambiguous"


def _seconds(m: re.Match[str], where: str) -> float:
    """Seconds of the day of a clock match (12 h with AM/PM)."""
    h, mi = int(m.group("h")), int(m.group("m"))
    s = float(m.group("s") or 0.0)
    ampm = (m.group("ampm") or "").lower().replace(".", "").replace(" ", "")
    if ampm:
        if not 1 <= h <= 12:
            raise ThermocalInputError(f"{where}: {h}:{mi:02d} {ampm.upper()} is no 12 h clock")
        h = h % 12 + (12 if ampm == "pm" else 0)
    if h > 23 or mi > 59 or s >= 60:
        raise ThermocalInputError(f"{where}: {m.group(0)!r} is not a time of day")
    return h * 3600.0 + mi * 60.0 + s


def _columns(table: _Table, where: str) -> tuple[int, int | None]:
    """The clock column and the date column (None) of the first data row."""
    first = table.rows[0][1]
    clock = next((i for i, f in enumerate(first) if _is_clock(f)), None)
    if clock is None:  # pragma: no cover - the first data row has a clock by construction
        raise ThermocalInputError(f"{where}: clock column not found")
    date = next((i for i, f in enumerate(first) if i != clock and _DATE.fullmatch(f.strip())), None)
    return clock, date


def _clock_times(
    table: _Table, spec: ChamberLogSpec, where: str
) -> tuple[FloatArray, dt.datetime | None]:
    """The log's clock [s] from its first row and its first row's date and time."""
    ci, di = _columns(table, where)
    header_date = spec.date or next(
        (m.group(0) for ln in table.preamble for m in [_DATE.search(ln)] if m), None
    )
    secs, days, dates = [], [], []
    for line, f in table.rows:
        cell = f[ci] if ci < len(f) else ""
        m = _CLOCK.match(cell.strip())
        if m is None:
            raise ThermocalInputError(f"{where}: line {line}: {cell!r} is not a clock (hh:mm[:ss])")
        secs.append(_seconds(m, f"{where}: line {line}"))
        dtext = m.group("date") or (f[di] if di is not None and di < len(f) else None)
        dates.append(dtext)
    have_dates = all(d for d in dates)
    if have_dates:
        ymd = [_date(str(d), spec.date_order, where) for d in dates]
        if "ambiguous" in ymd:
            raise ThermocalInputError.naming(
                f"{where}: dates like {dates[ymd.index('ambiguous')]!r} read day-first or "
                "month-first: give {chamber_date_order} dmy or mdy",
                "chamber_date_order",
            )
        base = dt.date(*ymd[0])
        days = [(dt.date(*d) - base).days for d in ymd]
        start_date: dt.date | None = base
    else:
        days = _wrapped_days(secs, header_date is not None, where)
        start_date = None
        if header_date is not None:
            ymd0 = _date(header_date, spec.date_order, where)
            if ymd0 == "ambiguous":
                raise ThermocalInputError.naming(
                    f"{where}: the date {header_date!r} reads day-first or month-first: give "
                    "{chamber_date_order} dmy or mdy",
                    "chamber_date_order",
                )
            start_date = dt.date(*ymd0)
    t = np.array(days, dtype=np.float64) * 86400.0 + np.array(secs)
    steps = np.diff(t)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        i = int(bad[0])
        raise ThermocalInputError(
            f"{where}: the clock does not advance at line {table.rows[i + 1][0]} "
            f"({table.rows[i][1][ci]!r} then {table.rows[i + 1][1][ci]!r}): repeated or "
            "out-of-order times"
        )
    start = None
    if start_date is not None:
        start = dt.datetime.combine(start_date, dt.time()) + dt.timedelta(seconds=float(t[0]))
    return t - t[0], start


def _wrapped_days(secs: list[float], dated: bool, where: str) -> list[int]:
    """The day of each row of a clock without dates: a clock that goes back past midnight
    starts a new day when the log's date is known, and is refused otherwise."""
    days, day = [0], 0
    for a, b in itertools.pairwise(secs):
        if b < a and a - b > 12 * 3600.0:
            if not dated:
                raise ThermocalInputError.naming(
                    f"{where}: the clock wraps past midnight without a date: give "
                    "{chamber_date} (the first row's date, YYYY-MM-DD)",
                    "chamber_date",
                )
            day += 1
        days.append(day)
    return days


def _channels(table: _Table, skip: set[int]) -> dict[str, int]:
    """Numeric channels (name → column): every column but the clock's and date's whose
    first data rows are mostly numbers (a stray text cell is then refused, its line named)."""
    out: dict[str, int] = {}
    for i, name in enumerate(table.header):
        if i in skip or not name:
            continue
        cells = [f[i] for _, f in table.rows[:20] if i < len(f) and f[i]]
        if sum(_number(c) is not None for c in cells) > len(cells) / 2:
            out[name] = i
    return out


def _number(cell: str) -> float | None:
    """A cell as a number (``,`` as decimal mark too), None when it is none."""
    try:
        comma = cell.count(",") == 1 and "." not in cell
        v = float(cell.replace(",", ".")) if comma else float(cell)
    except ValueError:
        return None
    return v


def _pick(channels: dict[str, int], wanted: str | None, where: str) -> str:
    """The channel asked for (by name, with or without its unit), else the one process
    value (``PV``, ``Chamber``, ``Actual``) or the one channel that is not a set-point."""
    names = list(channels)
    listing = ", ".join(repr(n) for n in names[:20])
    if not names:
        raise ThermocalInputError(f"{where}: no numeric temperature channel beside the clock")
    if wanted is not None:
        for n in names:
            if wanted.strip().lower() in (n.lower(), _bare(n).lower()):
                return n
        raise ThermocalInputError(
            f"{where}: no channel {wanted!r} in the chamber log: channels are {listing}"
        )
    measured = [n for n in names if not _SETPOINT.search(_bare(n))]
    pv = [n for n in measured if _PROCESS.search(_bare(n))]
    for group in (pv, measured):
        if len(group) == 1:
            return group[0]
    raise ThermocalInputError.naming(
        f"{where}: the chamber log has several channels ({listing}): name one, "
        "{chamber_log} FILE:CHANNEL",
        "chamber_log",
    )


def _unit(
    table: _Table, channel: str, col: int, spec: ChamberLogSpec, where: str
) -> tuple[str, str]:
    """The channel's unit and its source: the option, else its header (or the units row)."""
    stated = _unit_of(channel)
    if stated is None and table.unit_row is not None and col < len(table.unit_row):
        stated = _UNIT_WORDS.get(table.unit_row[col].strip().lower())
    if spec.unit is not None:
        unit = _UNIT_WORDS.get(spec.unit.strip().lower(), spec.unit.strip())
        if unit not in CHAMBER_UNITS:
            raise ThermocalInputError.naming(
                f"{{chamber_unit}} {spec.unit!r}: give degF, degC or K", "chamber_unit"
            )
        if stated is not None and stated != unit:
            raise ThermocalInputError.naming(
                f"{where}: channel {channel!r} is in {stated} by its header, {{chamber_unit}} "
                f"says {unit}: drop {{chamber_unit}} or correct the header",
                "chamber_unit",
            )
        return unit, "option"
    if stated is None:
        raise ThermocalInputError.naming(
            f"{where}: the unit of channel {channel!r} is not stated in the log: give "
            "{chamber_unit} degF, degC or K",
            "chamber_unit",
        )
    return stated, "header"


def _values(table: _Table, channel: str, col: int, where: str) -> FloatArray:
    """The channel's numbers; an empty or non-numeric cell is refused, its line named."""
    out = np.empty(len(table.rows))
    for k, (line, f) in enumerate(table.rows):
        v = _number(f[col]) if col < len(f) else None
        if v is None or not math.isfinite(v):
            cell = f[col] if col < len(f) else ""
            raise ThermocalInputError(
                f"{where}: line {line}: channel {channel!r} has no value ({cell!r})"
            )
        out[k] = v
    return out


def parse_chamber_log(text: str, spec: ChamberLogSpec, where: str = "chamber log") -> ChamberLog:
    """One channel of a chamber log's text on the log's clock, in °C.

    Parameters
    ----------
    text : str
        The file's text.
    spec : ChamberLogSpec
        The channel, unit, date and date order given (None: from the file).
    where : str
        The file's name, for messages.

    Returns
    -------
    ChamberLog
        Clock [s] from the first row, the channel in °C (:math:`T_C = g\\,v + o`,
        :data:`CHAMBER_UNITS`; NIST SP 811 §B.8), its unit and source.

    Raises
    ------
    ThermocalInputError
        No clock column (the columns listed), a clock that repeats or goes back, a
        midnight wrap without a date, ambiguous dates, a channel missing or without unit,
        a row without a value.

    Examples
    --------
    >>> from thermocal.readers.options import ChamberLogSpec
    >>> log = parse_chamber_log("Time,TC1 [°F]\\n10:00,68\\n10:01,77\\n", ChamberLogSpec("x"))
    >>> log.time_s.tolist(), log.temp_c.tolist(), log.unit
    ([0.0, 60.0], [20.0, 25.0], 'degF')
    """
    table = _table(text, where)
    ci, di = _columns(table, where)
    t, start = _clock_times(table, spec, where)
    chans = _channels(table, {ci} | ({di} if di is not None else set()))
    name = _pick(chans, spec.channel, where)
    unit, source = _unit(table, name, chans[name], spec, where)
    gain, offset = CHAMBER_UNITS[unit]
    temp = gain * _values(table, name, chans[name], where) + offset
    lo, hi = PLAUSIBLE_C
    if float(temp.min()) < lo or float(temp.max()) > hi:
        warnings.warn(
            PlausibilityWarning.naming(
                f"{where}: channel {name!r} reads {temp.min():.4g}…{temp.max():.4g} °C as "
                f"{unit}: implausible for a chamber; check {{chamber_unit}}",
                "chamber_unit",
            ),
            stacklevel=2,
        )
    return ChamberLog(
        where, t, start, name, temp, unit, source, bool(_SETPOINT.search(_bare(name))),
        tuple(chans),
    )  # fmt: skip


def read_chamber_log(spec: ChamberLogSpec) -> ChamberLog:
    """Read a chamber log file (never modified) and parse it (:func:`parse_chamber_log`).

    Parameters
    ----------
    spec : ChamberLogSpec
        The file and what the user states about it.

    Returns
    -------
    ChamberLog

    Raises
    ------
    thermocal.errors.FileFormatError
        No such file, a special file, an empty or binary one.
    """
    p = Path(spec.path)
    if not p.exists():
        raise FileFormatError(f"{p}: no such chamber log")
    refuse_special_input(p, "chamber log")
    if p.is_dir():
        raise FileFormatError(f"{p}: a directory, not a chamber log")
    return parse_chamber_log(_text_of(p.read_bytes(), str(p)), spec, str(p))


def chamber_needs_series(spec: ChamberLogSpec, log: ChamberLog, t0: float) -> bool:
    """Whether the join needs the recording's whole time and temperature (the clocks found
    by correlation) rather than its first and last times (an offset given or from absolute
    clocks).

    Parameters
    ----------
    spec : ChamberLogSpec
        The log and what is stated of it.
    log : ChamberLog
        The log read.
    t0 : float
        The recording's first time [s].

    Returns
    -------
    bool

    Raises
    ------
    ThermocalInputError
        An absolute recording and a dated log without its time zone (``chamber_tz``).
    """
    return spec.offset_s is None and _absolute_offset(t0, log, spec) is None


@dataclass(frozen=True)
class ChamberStream:
    """A chamber log joined once to a recording read in chunks: each chunk's chamber
    temperature :math:`L(\\tau(t))`, :math:`\\tau = o + (1 + \\delta)(t - t_0)`, interpolated
    linearly onto its own times (:func:`thermocal.chamber_join.joined_values` chunk by chunk).

    Attributes
    ----------
    log : ChamberLog
        The log.
    join : ClockJoin
        The clocks' mapping.
    t0 : float
        The recording's first time [s].
    """

    log: ChamberLog
    join: ClockJoin
    t0: float

    def values(self, t: npt.ArrayLike) -> FloatArray:
        """The log's temperature [°C] at recording times ``t`` [s].

        Parameters
        ----------
        t : array_like
            Recording times [s] (a chunk's).

        Returns
        -------
        numpy.ndarray
            Temperature [°C] at each time.
        """
        tau = self.join.clock(t, self.t0)
        return np.interp(tau, self.log.time_s, self.log.temp_c)

    def record(self) -> dict[str, Any]:
        """:func:`chamber_join_record` of the join."""
        return chamber_join_record(self.log, self.join)


ABSOLUTE_AFTER_S = 946_684_800.0
"""A recording whose first time [s] is after this (2000-01-01 00:00 UTC) holds absolute
times (seconds since 1970 in UTC); before it, time relative to its start."""


def _absolute_offset(t0: float, log: ChamberLog, spec: ChamberLogSpec) -> float | None:
    """The offset [s] from absolute clocks: a recording (first time ``t0`` [s]) in UTC and a
    dated log, its zone given (refused without it); None when either clock is relative."""
    if log.start is None or t0 < ABSOLUTE_AFTER_S:
        return None
    if spec.tz is None:
        raise ThermocalInputError.naming(
            f"{log.source}: the recording's time is absolute (UTC) and the chamber log's clock "
            "is local with a date: give {chamber_tz} (the log's offset from UTC, +HH:MM), or "
            "{chamber_offset}",
            "chamber_tz",
            "chamber_offset",
        )
    start_utc = log.start.replace(tzinfo=dt.UTC).timestamp()
    return t0 + timezone_seconds(spec.tz) - start_utc


def chamber_join_record(log: ChamberLog, join: ClockJoin) -> dict[str, Any]:
    """What a recording's metadata keeps of its chamber join (``meta.extra["chamber_log"]``).

    Parameters
    ----------
    log : ChamberLog
        The log joined.
    join : ClockJoin
        The clocks' mapping.

    Returns
    -------
    dict
        The log, channel, unit, its source, whether it is a set-point, and
        :meth:`~thermocal.chamber_join.ClockJoin.to_dict`.
    """
    return {
        "log": log.source, "channel": log.channel, "unit": log.unit,
        "unit_source": log.unit_source, "setpoint": log.setpoint, **join.to_dict(),
    }  # fmt: skip


def chamber_clock_join(
    spec: ChamberLogSpec,
    time_s: npt.ArrayLike,
    own_temp_c: npt.ArrayLike | None,
    own: str | None,
    *,
    log: ChamberLog | None = None,
    stacklevel: int = 3,
) -> tuple[ChamberLog, ClockJoin]:
    """Read a chamber log and map a recording's clock onto it
    (:func:`thermocal.chamber_join.join_clock`: offset given, from absolute clocks, or by
    correlation with the recording's own temperature, stated in a warning).

    Parameters
    ----------
    spec : ChamberLogSpec
        The log and what is stated of it.
    time_s : array_like
        The recording's times [s] (the whole recording; with a given or absolute offset its
        first and last times suffice).
    own_temp_c : array_like, optional
        The recording's own temperature [°C] at ``time_s`` (correlation only).
    own : str, optional
        That temperature's column name, for the statement.
    log : ChamberLog, optional
        The log already read (default: read from ``spec``).
    stacklevel : int
        Of the correlation's warning.

    Returns
    -------
    (ChamberLog, ClockJoin)

    Raises
    ------
    ThermocalInputError
        The log unreadable, not covering the recording, or the clocks not joinable.
    """
    log = read_chamber_log(spec) if log is None else log
    t = np.asarray(time_s, dtype=np.float64)
    absolute = _absolute_offset(float(t[0]), log, spec) if spec.offset_s is None else None
    try:
        join = join_clock(
            t, log.time_s, log.temp_c, rec_temp_c=own_temp_c,
            offset_s=spec.offset_s, drift_ppm=spec.drift_ppm, absolute_offset_s=absolute,
            timezone=None if spec.tz is None else timezone_text(timezone_seconds(spec.tz)),
        )  # fmt: skip
    except ThermocalInputError as exc:
        raise ThermocalInputError.around(exc, f"{log.source}: ") from None
    if join.method == "correlation":
        warnings.warn(
            TimestampWarning.naming(
                f"{log.source}: clocks joined by correlating {log.channel!r} with the "
                f"recording's {own!r}: offset {join.offset_s:.6g} ± {join.offset_sigma_s:.2g} s, "
                f"drift {join.drift_ppm:.4g} ± {join.drift_sigma_ppm:.2g} ppm (r = "
                f"{join.correlation:.4f}); the offset includes the sensor's thermal lag; give "
                "{chamber_offset} when the clocks are known",
                "chamber_offset",
            ),
            stacklevel=stacklevel,
        )
    return log, join


def join_chamber_log(
    rec: Recording, spec: ChamberLogSpec, temperatures: tuple[str, ...] | None
) -> Recording:
    """``rec`` with the chamber log's channel joined by time as the temperature column
    :data:`~thermocal.readers.options.CHAMBER_COLUMN` [°C]
    (:func:`thermocal.chamber_join.join_clock`: offset given, from absolute clocks, or by
    correlation with the recording's first temperature; the log must cover the recording).

    Parameters
    ----------
    rec : Recording
        The recording as read (without the chamber column).
    spec : ChamberLogSpec
        The log and what is stated of it.
    temperatures : tuple of str, optional
        The temperature columns asked for, in order, the chamber column among them; None:
        the recording's own (the chamber column then a column, not a temperature).

    Returns
    -------
    Recording
        A copy with the column, its unit ``degC`` (source ``chamber log``) and the join
        in ``meta.extra["chamber_log"]`` (the log, channel, unit and
        :meth:`~thermocal.chamber_join.ClockJoin.to_dict`).

    Raises
    ------
    ThermocalInputError
        The log unreadable, not covering the recording, or the clocks not joinable.
    """
    import dataclasses

    own = next((c for c in rec.temperatures if c != CHAMBER_COLUMN), None)
    log, join = chamber_clock_join(
        spec, rec.time_s, rec.temperature_c(own) if own is not None else None, own, stacklevel=4
    )
    values = joined_values(join, rec.time_s, log.time_s, log.temp_c)
    out = rec.with_columns({CHAMBER_COLUMN: values}, {CHAMBER_COLUMN: "degC"})
    extra = dict(rec.meta.extra)
    extra["chamber_log"] = chamber_join_record(log, join)
    temps = rec.temperatures if temperatures is None else temperatures
    return dataclasses.replace(
        out,
        temperatures=tuple(temps),
        meta=dataclasses.replace(rec.meta, extra=extra),
        unit_sources={**rec.unit_sources, CHAMBER_COLUMN: "chamber log"},
    )


__all__ = [
    "ABSOLUTE_AFTER_S",
    "CHAMBER_UNITS",
    "ChamberLog",
    "ChamberStream",
    "chamber_clock_join",
    "chamber_join_record",
    "chamber_needs_series",
    "join_chamber_log",
    "parse_chamber_log",
    "read_chamber_log",
]
