"""ArduPilot DataFlash (.bin) logs, read by message with the firmware's units: a sound log
by a fixed-format parser (numpy records of each wanted message type, one walk over the
file), any other by pymavlink (which skips damage and says so); the same values either
way."""

from __future__ import annotations

import contextlib
import gc
import math
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule
from thermocal.errors import (
    FileFormatError,
    MissingColumnError,
    PlausibilityWarning,
    ThermocalInputError,
)
from thermocal.outputs import refuse_special_input
from thermocal.readers.common import (
    DEFAULT_DATAFLASH_TOPIC,
    library_output_captured,
    names_list,
    parse_topic,
    warn_damage,
)

if TYPE_CHECKING:
    import pandas as pd
else:
    pd = LazyModule("pandas")


# --- ArduPilot DataFlash --------------------------------------------------------------------

_IMU_UNITS = {
    **dict.fromkeys(("GyrX", "GyrY", "GyrZ"), "rad/s"),
    **dict.fromkeys(("AccX", "AccY", "AccZ"), "m/s^2"),
    "T": "degC", "Temp": "degC", "GHz": "Hz", "AHz": "Hz",
}  # fmt: skip
ARDUPILOT_UNITS: dict[str, dict[str, str]] = {
    "IMU": _IMU_UNITS, "IMU2": _IMU_UNITS, "IMU3": _IMU_UNITS,
    "GYR": dict.fromkeys(("GyrX", "GyrY", "GyrZ"), "rad/s"),
    "ACC": dict.fromkeys(("AccX", "AccY", "AccZ"), "m/s^2"),
    "BARO": {
        "Alt": "m", "AltAMSL": "m", "Press": "Pa", "CPress": "Pa", "Temp": "degC",
        "CRt": "m/s", "Offset": "m", "GndTemp": "degC",
    },
    "MAG": dict.fromkeys(
        ("MagX", "MagY", "MagZ", "OfsX", "OfsY", "OfsZ", "MOX", "MOY", "MOZ"), "mGauss"
    ),
    "TCLR": {"Temp": "degC"},
}  # fmt: skip
"""Units of ArduPilot's log messages, fixed by the firmware's message definitions whether or
not a log carries unit (FMTU/UNIT/MULT) messages — ArduPilot ``libraries/AP_InertialSensor/
LogStructure.h``: ``IMU`` "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz" with
units "s#EEEooo--O--zz" (E rad/s, o m/s², O degC, z Hz), multipliers 1; ``GYR``/``ACC`` the
same; older firmware (Copter 3.4–3.6) logs ``IMU``, ``IMU2``, ``IMU3`` without ``I`` and names
the temperature ``Temp`` (same units); ``libraries/AP_Logger/LogStructure.h``: ``BARO``
"TimeUS,I,Alt,AltAMSL,Press,Temp,…" units "s#mmPO…" (P Pa, O degC; ``Temp`` stored ×100 as
int16 'c', scaled by pymavlink), ``MAG`` "TimeUS,I,MagX,…" units "s#GGG…" with multiplier C
(10⁻³): milligauss; ``AP_InertialSensor_tempcal.cpp`` ``TCLR``
"TimeUS,I,SType,Temp,X,Y,Z,NSamp" (no units declared: Temp the learning's temperature [°C];
X,Y,Z the mean accelerometer [m/s², relative to the first] for SType 0, gyro [rad/s] for
SType 1 — set per read by :func:`read_dataflash`).  The time is ``TimeUS`` [µs]."""

DATAFLASH_PADDING = 528
"""Bytes at the end of a DataFlash log that may be padding rather than messages (block
logging fills its last page; pymavlink ignores up to this many, DFReader.py)."""


@dataclass(frozen=True)
class ParamChange:
    """A parameter set again later in a DataFlash log with another value: a ``PARM`` message
    (``TimeUS`` [µs] → ``time_s`` [s], the log's clock) whose value differs from the value of
    that name in force before it (``old``).

    Attributes
    ----------
    time_s : float
        When the new value was set, on the log's clock [s].
    name : str
        The parameter's name.
    old : float
        The value in force before.
    new : float
        The value set.
    """

    time_s: float
    name: str
    old: float
    new: float

    def to_dict(self) -> dict[str, float | str]:
        """The change as a JSON-ready mapping.

        Returns
        -------
        dict
            ``time_s`` [s], ``name``, ``old`` and ``new``.
        """
        return {"time_s": self.time_s, "name": self.name, "old": self.old, "new": self.new}


@dataclass(frozen=True)
class DataflashLog:
    """What one pass over a DataFlash log kept: the rows of the wanted message types (numeric
    fields), every message type seen, the parameters (``params``: the first value of each
    name, the parameters the recording started with; ``param_changes``: every later ``PARM``
    that changed a value, in log order) and the sentences on what was lost
    (:func:`_dataflash_loss`).

    Attributes
    ----------
    rows : dict of str to list of dict
        Per wanted message type, its messages' numeric fields (logs read by pymavlink).
    names_seen : frozenset of str
        Every message type in the log.
    params : dict of str to float
        The first value of each parameter.
    notes : tuple of str
        What was lost to damage.
    param_changes : tuple of ParamChange
        Later changes of a parameter's value, in log order.
    columns : dict of str to dict of str to numpy.ndarray
        Per wanted message type, its numeric fields as columns in log order (logs read by
        the fixed-format parser, :func:`_fast_pass`): in their logged types (the scaled ones
        float64), each value exactly pymavlink's once made a float64.
    """

    rows: dict[str, list[dict[str, float]]]
    names_seen: frozenset[str]
    params: dict[str, float]
    notes: tuple[str, ...]
    param_changes: tuple[ParamChange, ...] = ()
    columns: dict[str, dict[str, npt.NDArray[Any]]] = field(default_factory=dict)

    def message_rows(self, name: str) -> list[dict[str, float]]:
        """Every message of type ``name`` (all instances), numeric fields, in log order,
        whichever way the log was read (:attr:`rows` or :attr:`columns`).

        Parameters
        ----------
        name : str
            A wanted message type.

        Returns
        -------
        list of dict
            Field name → value; empty when the log has none.
        """
        cols = self.columns.get(name)
        if cols is None:
            return self.rows.get(name, [])
        names = list(cols)
        rows = zip(*cols.values(), strict=True)
        return [dict(zip(names, map(float, vals), strict=True)) for vals in rows]

    def params_at_end(self) -> dict[str, float]:
        """The parameters in force at the end of the log (initial values and every change).

        Returns
        -------
        dict of str to float
            Parameter name → the last value set.
        """
        out = dict(self.params)
        for c in self.param_changes:
            out[c.name] = c.new
        return out


READ_BUDGET_S = 60.0
"""Seconds pymavlink may take over a DataFlash log, plus :data:`READ_BUDGET_S_PER_MB` per MB
of the file (it reads a few MB/s; far more than a sound log needs)."""
READ_BUDGET_S_PER_MB = 4.0


class _OverBudget(BaseException):
    """Raised by :func:`_time_budget`'s alarm inside pymavlink's read (a BaseException: the
    reader's ``except Exception`` around pymavlink must not turn it into another error)."""


@contextlib.contextmanager
def _time_budget(seconds: float) -> Iterator[None]:
    """Raise :class:`_OverBudget` in the block after ``seconds`` [s] of wall time: a damaged
    log once kept pymavlink's reader (pure Python) looping for ever (in
    ``DFReader.init_clock``); the alarm turns that into an error.  Only in the main thread
    of a platform with ``SIGALRM`` and when no other interval timer runs; else no limit."""
    import signal
    import threading

    usable = (
        hasattr(signal, "setitimer")
        and threading.current_thread() is threading.main_thread()
        and signal.getitimer(signal.ITIMER_REAL)[0] == 0.0
    )
    if not usable:
        yield
        return

    def alarm(signum: int, frame: Any) -> None:
        raise _OverBudget

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def read_dataflash_log(path: str | Path, messages: Sequence[str]) -> DataflashLog:
    """Read an ArduPilot DataFlash log (:func:`_read_dataflash_log`) within a time budget
    (:data:`READ_BUDGET_S` + :data:`READ_BUDGET_S_PER_MB` per MB): a log pymavlink cannot
    finish is a :class:`FileFormatError`, never a hang.

    Parameters
    ----------
    path : str or pathlib.Path
        The DataFlash ``.bin`` log.
    messages : sequence of str
        Message names to keep (``IMU``, ``TCLR``, …).

    Returns
    -------
    DataflashLog
        The kept messages' rows, the names seen and notes on damage.

    Raises
    ------
    FileFormatError
        A log pymavlink cannot read, or cannot finish within the time budget.
    ThermocalInputError
        A special file (FIFO, device), or pymavlink not installed.

    References
    ----------
    - ArduPilot, *Onboard Message Log Messages* and ``libraries/AP_Logger``
      (``FMT``/``FMTU``/``UNIT``/``MULT`` messages), ardupilot.org.
    """
    p = Path(path)
    refuse_special_input(p, "DataFlash log")  # pymavlink would block on a FIFO
    try:
        size_mb = p.stat().st_size / 1e6
    except OSError:
        size_mb = 0.0
    budget = READ_BUDGET_S + READ_BUDGET_S_PER_MB * size_mb
    try:
        with _time_budget(budget):
            return _read_dataflash_log(p, messages)
    except _OverBudget:
        gc.collect()  # the file pymavlink holds
        raise FileFormatError(
            f"{p}: pymavlink did not finish reading this DataFlash log in {budget:.0f} s "
            "(a damaged log can keep it looping); nothing was read"
        ) from None


def _read_dataflash_log(path: str | Path, messages: Sequence[str]) -> DataflashLog:
    """Read an ArduPilot DataFlash log once, keeping the messages named in ``messages`` and
    every ``PARM``: a sound log by the fixed-format parser (:func:`_fast_pass`), any other
    (damage, formats it does not take) by pymavlink (:func:`_pymavlink_pass`), the same
    values either way."""
    path = Path(path)
    passed = _fast_pass(path, set(messages))
    return _pymavlink_pass(path, messages) if passed is None else passed


def _pymavlink_pass(path: str | Path, messages: Sequence[str]) -> DataflashLog:
    """Read an ArduPilot DataFlash log once with pymavlink, keeping the messages named in
    ``messages`` and every ``PARM``.  pymavlink's printed complaints are captured; bytes of
    the file that are not whole messages (file size − Σ message lengths, trailing padding of
    one fill byte excepted) are lost and said in a warning with their share.  Needs
    ``pymavlink`` (``pip install 'thermocal[logs]'``)."""
    try:
        from pymavlink import DFReader
    except ImportError:
        raise ThermocalInputError(
            f"{path}: reading ArduPilot DataFlash logs needs pymavlink: pip install "
            "'thermocal[logs]' (or pip install pymavlink)"
        ) from None
    path = Path(path)
    keep = set(messages)
    rows: dict[str, list[dict[str, float]]] = {m: [] for m in keep}
    params: dict[str, float] = {}
    current: dict[str, float] = {}
    changes: list[ParamChange] = []
    names_seen: set[str] = set()
    accounted = 0  # bytes in whole messages
    last_end = 0
    t_max_us = -math.inf  # the latest TimeUS read so far
    backwards = 0  # parameter changes stamped before data already logged
    size = path.stat().st_size
    with library_output_captured() as noise:
        failure = None
        try:
            log = DFReader.DFReader_binary(str(path), zero_time_base=False)
        except Exception as exc:  # pymavlink raises several kinds on a bad file
            failure = " ".join(str(exc).split())[:200] or type(exc).__name__
        if failure is not None:
            # pymavlink leaves the file of a log it could not open to the garbage collector:
            # close it now, quietly, rather than warn later in someone else's code
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ResourceWarning)
                gc.collect()
            raise FileFormatError(f"{path}: not a readable DataFlash log ({failure})")
        try:
            while True:
                try:
                    m = log.recv_msg()
                except Exception as exc:
                    msg = " ".join(str(exc).split())[:200] or type(exc).__name__
                    raise FileFormatError(
                        f"{path}: a damaged DataFlash log pymavlink cannot read past byte "
                        f"{getattr(log, 'offset', 0):,} ({msg})"
                    ) from None
                if m is None:
                    break
                accounted += int(m.fmt.len)  # header included (LogStructure.h)
                last_end = int(getattr(log, "offset", 0))
                mtype = m.get_type()
                names_seen.add(mtype)
                if mtype in keep:
                    d = m.to_dict()
                    rows[mtype].append(
                        {k: float(v) for k, v in d.items() if isinstance(v, int | float)}
                    )
                elif mtype == "PARM":
                    with contextlib.suppress(AttributeError, TypeError, ValueError):
                        name, value = str(m.Name), float(m.Value)
                        t_us = getattr(m, "TimeUS", 0)
                        backwards += _parm(name, value, t_us, params, current, changes, t_max_us)
                t_us = getattr(m, "TimeUS", None)
                if isinstance(t_us, int | float) and t_us > t_max_us:
                    t_max_us = float(t_us)
        finally:  # pymavlink keeps the file and its memory map open
            for attr in ("data_map", "filehandle"):
                h = getattr(log, attr, None)
                if h is not None:
                    h.close()
    _warn_backwards(path, backwards)
    notes = _dataflash_loss(path, size, accounted, last_end)
    said = noise.summary("pymavlink")
    if said and notes:
        notes.append(said)
    warn_damage(path, notes)
    return DataflashLog(rows, frozenset(names_seen), params, tuple(notes), tuple(changes))


def _warn_backwards(path: Path, backwards: int) -> None:
    """The warning on parameter changes stamped before data already logged (if any)."""
    if backwards:
        warnings.warn(
            PlausibilityWarning(
                f"{path}: {backwards} parameter change(s) carry a TimeUS earlier than data "
                "logged before them (the clock went backwards): each is taken at the latest "
                "time logged before it, where the firmware applied it"
            ),
            stacklevel=5,
        )


def _parm(
    name: str,
    value: float,
    stamp_us: Any,
    first: dict[str, float],
    current: dict[str, float],
    changes: list[ParamChange],
    t_floor_us: float = -math.inf,
) -> int:
    """One ``PARM`` (LogStructure.h "TimeUS,Name,Value"; ``stamp_us`` its TimeUS [µs]): the
    first value of a name is its initial value (the log's parameter dump at start); a later
    one with another value is a change, at ``TimeUS`` — or at ``t_floor_us``, the latest time
    logged before it, when its stamp is earlier (a parameter takes effect where it is
    logged).  Returns 1 for a change so moved, else 0."""
    moved = 0
    if name not in current:
        first[name] = value
    elif value != current[name] and not (value != value and current[name] != current[name]):
        t_us = float(stamp_us)
        if t_us < t_floor_us:
            t_us, moved = t_floor_us, 1
        changes.append(ParamChange(t_us * 1e-6, name, current[name], value))
    current[name] = value
    return moved


def dataflash_table(
    log: DataflashLog, path: Path, name: str, inst: int, fields: Sequence[str] | None = None
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Instance ``inst`` of message ``name`` from a :func:`read_dataflash_log` pass, as a
    table with the firmware's units (:data:`ARDUPILOT_UNITS`).  Both layouts: the instance
    field ``I`` (newer firmware) or, for ``IMU.1``/``IMU.2``, the older messages
    ``IMU2``/``IMU3`` without it; ``T`` or ``Temp`` the temperature.

    Parameters
    ----------
    log : DataflashLog
        A :func:`read_dataflash_log` pass.
    path : pathlib.Path
        The log, named in errors.
    name : str
        Message name (``IMU``).
    inst : int
        Instance (0-based).
    fields : sequence of str, optional
        The fields wanted: the table holds those of them the message has (``TimeUS``
        always); None (default): every field.  A caller that reads a few fields of a long
        message spares the float64 copy of the others.

    Returns
    -------
    tuple of (pandas.DataFrame, dict)
        The fields as float64 columns, and what the reader found (time column ``TimeUS``
        [µs], units, message).

    Raises
    ------
    MissingColumnError
        No such message instance in the log (the message lists those it has).
    FileFormatError
        Messages without ``TimeUS`` (a damaged format definition).
    """
    legacy = f"{name}{inst + 1}" if inst > 0 else None  # IMU2 = IMU.1 in older logs
    keep = None if fields is None else {"TimeUS", *fields}
    if name in log.columns or (legacy is not None and legacy in log.columns):
        df, source = _columns_table(log, name, legacy, inst, keep)
    else:
        rows = [r for r in log.rows.get(name, []) if int(r.get("I", 0)) == inst]
        source = name
        if not rows and legacy:
            rows = [r for r in log.rows.get(legacy, []) if "I" not in r]
            source = legacy
        df = pd.DataFrame(rows).astype(np.float64) if rows else None
        if df is not None and keep is not None:
            df = df[[c for c in df.columns if c in keep]]
    if df is None:
        raise MissingColumnError(
            f"{path}: no {name} messages of instance {inst} in the log"
            + (" (they may be in its damaged part)" if log.notes else "")
            + "; it has: "
            + (", ".join(sorted(log.names_seen - {"FMT", "FMTU", "UNIT", "MULT"})) or "none")
        )
    if "TimeUS" not in df.columns:  # a damaged FMT message renames the fields
        raise FileFormatError(
            f"{path}: the {source} messages have no TimeUS field (their format definition is "
            "damaged); fields: " + names_list([str(c) for c in df.columns])
        )
    known = dict(ARDUPILOT_UNITS.get(source, {}))
    if source == "TCLR" and "SType" in df.columns:  # X, Y, Z: accel (0) or gyro (1) means
        kinds = set(df["SType"].astype(int).tolist())
        if len(kinds) == 1:
            u = {0: "m/s^2", 1: "rad/s"}.get(kinds.pop())
            if u:
                known.update(dict.fromkeys(("X", "Y", "Z"), u))
    units_ = {k: u for k, u in known.items() if k in df.columns}
    info: dict[str, Any] = {"time": "TimeUS", "time_unit": "us", "units": units_}
    info["dataflash_message"] = f"{name}.{inst}"
    info["dataflash_source"] = source
    info["fc_log"] = True
    return df, info


def _columns_table(
    log: DataflashLog, name: str, legacy: str | None, inst: int, keep: set[str] | None = None
) -> tuple[pd.DataFrame | None, str]:
    """:func:`dataflash_table`'s selection from :attr:`DataflashLog.columns`: the messages
    ``name`` of instance ``inst`` (no ``I`` field: instance 0), else those of ``legacy``
    without an ``I`` field; (None, name) when there are none; ``keep``: only these fields."""
    cols = log.columns.get(name)
    if cols is not None:
        inst_col = cols.get("I")
        if inst_col is not None:
            whole = np.trunc(inst_col) if inst_col.dtype.kind == "f" else inst_col
            rows = np.flatnonzero(whole == inst)
            if rows.size:
                return _frame(_kept(cols, keep), rows), name
        elif inst == 0 and len(next(iter(cols.values()))):
            return _frame(_kept(cols, keep), None), name
    old = log.columns.get(legacy) if legacy is not None else None
    if old is not None and "I" not in old and len(next(iter(old.values()))):
        return _frame(_kept(old, keep), None), str(legacy)
    return None, name


def _kept(cols: dict[str, npt.NDArray[Any]], keep: set[str] | None) -> dict[str, npt.NDArray[Any]]:
    """The columns named in ``keep`` (None: all), in the message's order."""
    return cols if keep is None else {k: v for k, v in cols.items() if k in keep}


def _frame(cols: dict[str, npt.NDArray[Any]], rows: npt.NDArray[np.intp] | None) -> pd.DataFrame:
    """The columns (those ``rows``; None: all) as one float64 frame, gathered straight into
    the frame's block (fields × rows, no second copy)."""
    n = len(next(iter(cols.values()), ())) if rows is None else rows.size
    block = np.empty((len(cols), n))
    for j, v in enumerate(cols.values()):
        block[j] = v if rows is None else v[rows]  # float64 on the way in
    return pd.DataFrame(block.T, columns=list(cols), copy=False)


def read_dataflash(path: Path, topic: str | None) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One message type and instance (field ``I``) of an ArduPilot DataFlash log as a
    table: the message's fields as columns, ``TimeUS`` [µs] the time, the firmware's units
    (:data:`ARDUPILOT_UNITS`, whether or not the log carries unit messages).  Older logs
    name their second and third IMU ``IMU2``/``IMU3`` (no ``I`` field): ``IMU.1`` reads
    ``IMU2`` (:func:`dataflash_table`).  The log is read once (:func:`read_dataflash_log`).

    Parameters
    ----------
    path : pathlib.Path
        The DataFlash ``.bin`` log.
    topic : str or None
        ``NAME`` or ``NAME.INSTANCE``; ``None``: the default message (``IMU.0``).

    Returns
    -------
    tuple of (pandas.DataFrame, dict)
        As :func:`dataflash_table`.

    Raises
    ------
    FileFormatError
        An unreadable log.
    MissingColumnError
        No such message instance.

    References
    ----------
    - ArduPilot, *Onboard Message Log Messages* and ``libraries/AP_Logger``
      (``FMT``/``FMTU``/``UNIT``/``MULT`` messages), ardupilot.org.
    """
    name, inst = parse_topic(topic, DEFAULT_DATAFLASH_TOPIC)
    wanted = [name] + ([f"{name}{inst + 1}"] if inst > 0 else [])
    log = read_dataflash_log(path, wanted)
    return dataflash_table(log, path, name, inst)


def _dataflash_loss(path: Path, size: int, accounted: int, last_end: int) -> list[str]:
    """Sentences on the bytes of a DataFlash log that were not whole messages: skipped as
    damaged inside the log, or left at its end (a cut last message; a tail shorter than
    :data:`DATAFLASH_PADDING` of one repeated fill byte is padding, not loss)."""
    lost_inside = max(0, last_end - accounted)
    tail = max(0, size - last_end)
    notes = []
    if lost_inside:
        notes.append(
            f"{lost_inside:,} bytes ({100.0 * lost_inside / size:.1f} % of the file) are not "
            "whole messages and were skipped, with the messages in them"
        )
    if tail:
        with open(path, "rb") as fh:
            fh.seek(last_end)
            rest = fh.read(DATAFLASH_PADDING + 1)
        padding = len(rest) < DATAFLASH_PADDING and len(set(rest)) == 1
        if not padding:
            notes.append(
                f"its last {tail:,} bytes ({100.0 * tail / size:.1f} % of the file) are not a "
                "whole message (the file is cut or damaged at its end)"
            )
    return notes


# --- the fixed-format parser ----------------------------------------------------------------

_HEAD = (0xA3, 0x95)
"""The two bytes that open every DataFlash message (``HEAD_BYTE1``, ``HEAD_BYTE2``)."""
_FMT_TYPE = 0x80
_FMT_DEF = ("FMT", 89, "BBnNZ", ("Type", "Length", "Name", "Format", "Columns"))
"""The format of ``FMT`` itself (LogStructure.h ``LOG_FORMAT_MSG``: type, length, name,
format characters, labels), known before the log defines it."""
_CODES: dict[str, tuple[str, float | None]] = {
    "a": ("S64", None), "b": ("i1", None), "B": ("u1", None), "g": ("<f2", None),
    "h": ("<i2", None), "H": ("<u2", None), "i": ("<i4", None), "I": ("<u4", None),
    "f": ("<f4", None), "n": ("S4", None), "N": ("S16", None), "Z": ("S64", None),
    "c": ("<i2", 100.0), "C": ("<u2", 100.0), "e": ("<i4", 100.0), "E": ("<u4", 100.0),
    "L": ("<i4", 1.0 / 1.0e-7), "d": ("<f8", None), "M": ("i1", None), "q": ("<i8", None),
    "Q": ("<u8", None),
}  # fmt: skip
"""DataFlash format characters (AP_Logger/LogStructure.h) → (little-endian numpy type, the
divisor of a scaled field: ``c``/``C``/``e``/``E`` ×100, ``L`` ×1e7, divided as pymavlink
divides them).  ``a`` (int16[32]) and the strings ``n``/``N``/``Z`` are not numeric."""
_TEXT = frozenset("anNZ")


@dataclass(frozen=True)
class _Format:
    """One message type's definition (an ``FMT`` message): name, length [bytes, header
    included], format characters, labels, and the numpy record of its payload."""

    name: str
    length: int
    chars: str
    columns: tuple[str, ...]
    record: np.dtype[Any]


def _format(name: str, length: int, chars: str, columns: tuple[str, ...]) -> _Format | None:
    """A definition the fixed-format parser takes, or None (unknown character, length not
    the fields' size, labels not one per field or repeated: left to pymavlink)."""
    if any(c not in _CODES for c in chars) or len(columns) != len(chars) or not chars:
        return None
    if len(set(columns)) != len(columns):
        return None
    if "TimeUS" in columns and chars[columns.index("TimeUS")] in _TEXT:
        return None
    offsets, pos = [], 3
    for c in chars:
        offsets.append(pos)
        pos += np.dtype(_CODES[c][0]).itemsize
    if pos != length:
        return None
    record = np.dtype(
        {"names": list(columns), "formats": [_CODES[c][0] for c in chars],
         "offsets": offsets, "itemsize": length}
    )  # fmt: skip
    return _Format(name, length, chars, columns, record)


def _text(raw: bytes) -> str:
    """A string field as pymavlink decodes it (UTF-8, else Latin-1; cut at the first NUL)."""
    try:
        s = raw.decode("utf-8")
    except UnicodeDecodeError:
        s = raw.decode("ISO-8859-1")
    return s.split("\0", 1)[0]


def _define(buf: bytes, pos: int, formats: dict[int, _Format]) -> bool:
    """Take the ``FMT`` message at ``pos`` into ``formats``; False when the parser cannot
    (a definition it does not take, or one that changes a type already defined)."""
    ftype, length = buf[pos + 3], buf[pos + 4]
    name = buf[pos + 5 : pos + 9].decode("utf-8", "backslashreplace").split("\0", 1)[0]
    chars = buf[pos + 9 : pos + 25].decode("utf-8", "backslashreplace").split("\0", 1)[0]
    cols = buf[pos + 25 : pos + 89].decode("utf-8", "backslashreplace").split("\0", 1)[0]
    new = _format(name, length, chars, tuple(cols.split(",")))
    if new is None or (name == "FMT") != (ftype == _FMT_TYPE):
        return False
    old = formats.get(ftype)
    if old is not None and (old.name, old.length, old.chars, old.columns) != (
        new.name,
        new.length,
        new.chars,
        new.columns,
    ):
        return False
    formats.setdefault(ftype, new)
    return True


def _walk(buf: bytes) -> tuple[list[int], dict[int, _Format], int] | None:
    """Every message's start in a sound log, its formats and where the messages end; None
    when a byte is not where a message should start before the end (damage: left to
    pymavlink, which skips it and says so)."""
    formats = {_FMT_TYPE: _format(*_FMT_DEF[:3], _FMT_DEF[3])}
    assert formats[_FMT_TYPE] is not None
    lengths = [0] * 256
    lengths[_FMT_TYPE] = _FMT_DEF[1]
    size, pos = len(buf), 0
    starts: list[int] = []
    add = starts.append
    while pos + 3 <= size:
        if buf[pos] != 0xA3 or buf[pos + 1] != 0x95:
            break
        t = buf[pos + 2]
        n = lengths[t]
        if n == 0 or pos + n > size:
            break
        if t == _FMT_TYPE:
            if not _define(buf, pos, formats):  # type: ignore[arg-type]
                return None
            lengths[buf[pos + 3]] = buf[pos + 4]
        add(pos)
        pos += n
    tail = buf[pos:]
    if not starts or (tail and not (len(tail) < DATAFLASH_PADDING and len(set(tail)) == 1)):
        return None
    return starts, formats, pos  # type: ignore[return-value]


_CHAIN_PASSES = 16
"""Passes of :func:`_walk_at_once` before it leaves a log to :func:`_walk`."""


def _walk_at_once(
    raw: bytes, u8: npt.NDArray[np.uint8]
) -> tuple[npt.NDArray[np.int64], dict[int, _Format], int] | None:
    """:func:`_walk`'s answer without a Python step per message, or None when it cannot
    tell (then :func:`_walk` decides).  Every ``A3 95`` is a candidate start (a payload may
    hold one too); with the lengths of the ``FMT`` candidates, each candidate's successor is
    the candidate its message ends at, and the messages of the log are the candidates the
    first leads to: all of them, less (pass by pass) those no kept candidate leads to (a
    start inside a payload; a few passes in a sound log).  Taken only when the ``FMT`` messages
    on that chain are the definitions used, each before its type's first message."""
    size = u8.size
    if size < 3:
        return None
    cand = np.flatnonzero(u8[:-2] == _HEAD[0])  # one byte mask at a time: less memory
    cand = cand[u8[cand + 1] == _HEAD[1]]
    if cand.size == 0 or cand[0] != 0:
        return None
    lengths = np.zeros(256, dtype=np.int64)
    lengths[_FMT_TYPE] = _FMT_DEF[1]
    seen: dict[int, _Format] = {}
    for p in cand[(u8[cand + 2] == _FMT_TYPE) & (cand + _FMT_DEF[1] <= size)].tolist():
        trial: dict[int, _Format] = dict(seen)
        if _define(raw, p, trial):  # a candidate that is no definition is skipped here
            seen = trial
            lengths[raw[p + 3]] = raw[p + 4]
    n = cand.size
    step = lengths[u8[cand + 2]]
    nxt = cand + step
    ok = (step > 0) & (nxt <= size)
    j = np.minimum(np.searchsorted(cand, nxt), n - 1)
    succ = np.where(ok & (cand[j] == nxt), j, n)  # n: no successor
    on = np.ones(n + 1, dtype=bool)
    for _ in range(_CHAIN_PASSES):  # keep the candidates some kept one leads to
        led = np.zeros(n + 1, dtype=bool)
        led[succ[on[:n]]] = True
        led[0] = True
        if np.array_equal(led[:n], on[:n]):
            break
        on = led
    else:
        return None  # a long chain that no message leads to (damage): the walk decides
    chain = np.flatnonzero(on[:n])
    last = int(chain[-1])
    end = int(nxt[last]) if ok[last] else int(cand[last])
    starts = cand[chain] if ok[last] else cand[chain[:-1]]
    tail = raw[end:]
    if starts.size == 0 or (tail and not (len(tail) < DATAFLASH_PADDING and len(set(tail)) == 1)):
        return None
    return _chain_defined(raw, starts, end, lengths)


def _chain_defined(
    raw: bytes, starts: npt.NDArray[np.int64], end: int, lengths: npt.NDArray[np.int64]
) -> tuple[npt.NDArray[np.int64], dict[int, _Format], int] | None:
    """The chain of :func:`_walk_at_once` if its own ``FMT`` messages define every type it
    holds, each before the type's first message, with the lengths it was walked by."""
    types = np.frombuffer(raw, np.uint8)[starts + 2]
    formats = {_FMT_TYPE: _format(*_FMT_DEF[:3], _FMT_DEF[3])}
    first_def: dict[int, int] = {}
    for k in np.flatnonzero(types == _FMT_TYPE).tolist():
        p = int(starts[k])
        if not _define(raw, p, formats):  # type: ignore[arg-type]
            return None
        first_def.setdefault(raw[p + 3], k)
    used, first_use = np.unique(types, return_index=True)
    for t, k in zip(used.tolist(), first_use.tolist(), strict=True):
        f = formats.get(t)
        if f is None or f.length != lengths[t] or (t != _FMT_TYPE and first_def.get(t, k) >= k):
            return None
    return starts, formats, end  # type: ignore[return-value]


def _units_sound(
    buf: bytes, at: npt.NDArray[np.int64], fmtu: _Format, formats: dict[int, _Format]
) -> bool:
    """Whether pymavlink takes every ``FMTU`` (units of a type) without failing: an
    instance mark ``#`` within the type's labels, multipliers for every label."""
    recs = np.lib.stride_tricks.sliding_window_view(np.frombuffer(buf, np.uint8), fmtu.length)
    rec = recs[at].copy().view(fmtu.record).reshape(-1)
    units = rec["UnitIds"] if "UnitIds" in fmtu.columns else None
    mults = rec["MultIds"] if "MultIds" in fmtu.columns else None
    for i in range(rec.size):
        for key in fmtu.columns[:2]:
            v = rec[key][i]
            if isinstance(v, bytes | np.bytes_):
                continue
            target = formats.get(int(v))
            if target is None:
                continue
            n = len(target.columns)
            if units is not None and _text(bytes(units[i])).find("#") >= n:
                return False
            if mults is not None and len(_text(bytes(mults[i]))) < n:
                return False
    return True


def _numeric(
    rec: npt.NDArray[Any], fmt: _Format, col: str, *, native: bool = False
) -> npt.NDArray[Any]:
    """One numeric field of ``rec`` as float64, scaled as pymavlink scales it (``native``:
    an unscaled field in its logged type, a copy; float64 gives pymavlink's value)."""
    divisor = _CODES[fmt.chars[fmt.columns.index(col)]][1]
    if divisor is not None:
        return rec[col].astype(np.float64) / divisor
    return rec[col].copy() if native else rec[col].astype(np.float64)


_CHUNK_ROWS = 1 << 16
"""Messages of one type parsed at a time by :func:`_parsed` (their bytes gathered: a few MB)."""


def _parsed(
    u8: npt.NDArray[np.uint8], at: npt.NDArray[np.int64], fmt: _Format, fields: bool
) -> tuple[npt.NDArray[np.float64] | None, dict[str, npt.NDArray[Any]]]:
    """The messages of one type starting at ``at``: their ``TimeUS`` as float64 (None
    without one) and, with ``fields``, every numeric field (:func:`_numeric`, native),
    :data:`_CHUNK_ROWS` messages at a time."""
    win = np.lib.stride_tricks.sliding_window_view(u8, fmt.length)
    timed = "TimeUS" in fmt.columns and fmt.chars[fmt.columns.index("TimeUS")] not in _TEXT
    times = np.empty(at.size) if timed else None
    cols: dict[str, npt.NDArray[Any]] = {}
    if fields:
        for c, ch in zip(fmt.columns, fmt.chars, strict=True):
            if ch not in _TEXT:
                scaled = _CODES[ch][1] is not None
                cols[c] = np.empty(at.size, np.float64 if scaled else fmt.record[c])
    for a in range(0, at.size, _CHUNK_ROWS):
        b = min(a + _CHUNK_ROWS, at.size)
        rec = win[at[a:b]].view(fmt.record).reshape(-1)
        if times is not None:
            times[a:b] = _numeric(rec, fmt, "TimeUS")
        for c, arr in cols.items():
            arr[a:b] = _numeric(rec, fmt, c, native=True)
    return times, cols


def _fast_pass(path: Path, keep: set[str]) -> DataflashLog | None:
    """Read a sound DataFlash log without pymavlink: the messages walked once by their
    lengths (:func:`_walk`), each wanted type's fields parsed at once as numpy records, the
    ``PARM`` messages in order; None when the log needs pymavlink (damage, a cut end, a
    format this parser does not take).  The values are pymavlink's: the same field types,
    the same scaling, the same parameter floors."""
    try:
        buf = path.read_bytes()
    except OSError:
        return None
    u8 = np.frombuffer(buf, np.uint8)
    walked = _walk_at_once(buf, u8) or _walk(buf)
    if walked is None:
        return None
    starts_list, formats, end = walked
    starts = np.asarray(starts_list, dtype=np.int64)
    del starts_list
    types = u8[starts + 2]
    present = np.flatnonzero(np.bincount(types, minlength=256))
    by_name = {formats[t].name: t for t in present.tolist()}
    if len(by_name) != present.size or not _parm_sound(formats, by_name):
        return None  # two types of one name, or a PARM this parser does not read
    if "FMTU" in by_name:
        t = by_name["FMTU"]
        if not _units_sound(buf, starts[types == t], formats[t], formats):
            return None
    columns: dict[str, dict[str, npt.NDArray[Any]]] = {}
    stamp = np.full(starts.size, np.nan)
    for t in present.tolist():
        fmt = formats[t]
        where = np.flatnonzero(types == t)
        times, cols = _parsed(u8, starts[where], fmt, fmt.name in keep)
        if times is not None:
            stamp[where] = times
        if fmt.name in keep:
            columns[fmt.name] = cols
    names_seen = frozenset(formats[t].name for t in present.tolist())
    params: dict[str, float] = {}
    changes: list[ParamChange] = []
    backwards = 0
    if "PARM" in by_name and "PARM" not in keep:
        backwards = _fast_params(u8, starts, types, stamp, formats[by_name["PARM"]],
                                 by_name["PARM"], params, changes)  # fmt: skip
    _warn_backwards(path, backwards)
    notes = _dataflash_loss(path, len(buf), end, end)
    warn_damage(path, notes)
    rows: dict[str, list[dict[str, float]]] = {m: [] for m in keep}
    return DataflashLog(rows, names_seen, params, tuple(notes), tuple(changes), columns)


def _parm_sound(formats: dict[int, _Format], by_name: dict[str, int]) -> bool:
    """Whether the log's ``PARM`` (if any) has a text ``Name`` and a numeric ``Value``."""
    if "PARM" not in by_name:
        return True
    fmt = formats[by_name["PARM"]]
    if "Name" not in fmt.columns or "Value" not in fmt.columns:
        return False
    kinds = {c: ch in _TEXT for c, ch in zip(fmt.columns, fmt.chars, strict=True)}
    return kinds["Name"] and not kinds["Value"]


def _fast_params(
    u8: npt.NDArray[np.uint8],
    starts: npt.NDArray[np.int64],
    types: npt.NDArray[np.uint8],
    stamp: npt.NDArray[np.float64],
    fmt: _Format,
    ptype: int,
    params: dict[str, float],
    changes: list[ParamChange],
) -> int:
    """The ``PARM`` messages in log order through :func:`_parm`, each floored at the latest
    ``TimeUS`` of the messages before it; returns the number of changes so moved."""
    where = np.flatnonzero(types == ptype)
    floor = np.fmax.accumulate(np.concatenate(([-math.inf], stamp)))[where]
    raw = np.lib.stride_tricks.sliding_window_view(u8, fmt.length)[starts[where]]
    rec: npt.NDArray[Any] = raw.view(fmt.record).reshape(-1)
    values = _numeric(rec, fmt, "Value").tolist()
    stamps = stamp[where].tolist() if "TimeUS" in fmt.columns else [0.0] * where.size
    current: dict[str, float] = {}
    moved = 0
    for raw, value, t_us, lo in zip(rec["Name"].tolist(), values, stamps, floor.tolist(),
                                    strict=True):  # fmt: skip
        moved += _parm(_text(raw), value, t_us, params, current, changes, lo)
    return moved
