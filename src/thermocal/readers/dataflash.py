"""ArduPilot DataFlash (.bin) logs (pymavlink), read by message with the firmware's units."""

from __future__ import annotations

import contextlib
import gc
import math
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

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
        Per wanted message type, its messages' numeric fields.
    names_seen : frozenset of str
        Every message type in the log.
    params : dict of str to float
        The first value of each parameter.
    notes : tuple of str
        What was lost to damage.
    param_changes : tuple of ParamChange
        Later changes of a parameter's value, in log order.
    """

    rows: dict[str, list[dict[str, float]]]
    names_seen: frozenset[str]
    params: dict[str, float]
    notes: tuple[str, ...]
    param_changes: tuple[ParamChange, ...] = ()

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
    every ``PARM``.  pymavlink's printed complaints are captured; bytes of the file that are
    not whole messages (file size − Σ message lengths, trailing padding of one fill byte
    excepted) are lost and said in a warning with their share.  Needs ``pymavlink``
    (``pip install 'thermocal[logs]'``)."""
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
                        backwards += _parm(m, params, current, changes, t_max_us)
                t_us = getattr(m, "TimeUS", None)
                if isinstance(t_us, int | float) and t_us > t_max_us:
                    t_max_us = float(t_us)
        finally:  # pymavlink keeps the file and its memory map open
            for attr in ("data_map", "filehandle"):
                h = getattr(log, attr, None)
                if h is not None:
                    h.close()
    if backwards:
        warnings.warn(
            PlausibilityWarning(
                f"{path}: {backwards} parameter change(s) carry a TimeUS earlier than data "
                "logged before them (the clock went backwards): each is taken at the latest "
                "time logged before it, where the firmware applied it"
            ),
            stacklevel=3,
        )
    notes = _dataflash_loss(path, size, accounted, last_end)
    said = noise.summary("pymavlink")
    if said and notes:
        notes.append(said)
    warn_damage(path, notes)
    return DataflashLog(rows, frozenset(names_seen), params, tuple(notes), tuple(changes))


def _parm(
    m: Any,
    first: dict[str, float],
    current: dict[str, float],
    changes: list[ParamChange],
    t_floor_us: float = -math.inf,
) -> int:
    """One ``PARM`` (LogStructure.h "TimeUS,Name,Value"): the first value of a name is its
    initial value (the log's parameter dump at start); a later one with another value is a
    change, at ``TimeUS`` — or at ``t_floor_us``, the latest time logged before it, when its
    stamp is earlier (a parameter takes effect where it is logged).  Returns 1 for a change
    so moved, else 0."""
    name, value = str(m.Name), float(m.Value)
    moved = 0
    if name not in current:
        first[name] = value
    elif value != current[name] and not (value != value and current[name] != current[name]):
        t_us = float(getattr(m, "TimeUS", 0))
        if t_us < t_floor_us:
            t_us, moved = t_floor_us, 1
        changes.append(ParamChange(t_us * 1e-6, name, current[name], value))
    current[name] = value
    return moved


def dataflash_table(
    log: DataflashLog, path: Path, name: str, inst: int
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
    rows = [r for r in log.rows.get(name, []) if int(r.get("I", 0)) == inst]
    source = name
    if not rows and legacy:
        rows = [r for r in log.rows.get(legacy, []) if "I" not in r]
        source = legacy
    if not rows:
        raise MissingColumnError(
            f"{path}: no {name} messages of instance {inst} in the log"
            + (" (they may be in its damaged part)" if log.notes else "")
            + "; it has: "
            + (", ".join(sorted(log.names_seen - {"FMT", "FMTU", "UNIT", "MULT"})) or "none")
        )
    df = pd.DataFrame(rows).astype(np.float64)
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
