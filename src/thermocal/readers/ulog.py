"""PX4 ULog files (pyulog), read by topic and instance in the units of PX4's messages."""

from __future__ import annotations

import contextlib
import contextvars
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
    TextLayoutWarning,
    ThermocalInputError,
)
from thermocal.outputs import refuse_special_input
from thermocal.readers.common import (
    LogDamageWarning,
    TrackedReader,
    library_output_captured,
    parse_topic,
    warn_damage,
)
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    import pandas as pd
else:
    pd = LazyModule("pandas")


# --- PX4 ULog ------------------------------------------------------------------------------

_XYZ = ("x", "y", "z")
PX4_UNITS: dict[str, dict[str, str]] = {
    "sensor_gyro": {**dict.fromkeys(_XYZ, "rad/s"), "temperature": "degC"},
    "sensor_accel": {**dict.fromkeys(_XYZ, "m/s^2"), "temperature": "degC"},
    "sensor_baro": {"pressure": "Pa", "temperature": "degC"},
    "sensor_mag": {**dict.fromkeys(_XYZ, "gauss"), "temperature": "degC"},
    "sensor_combined": {
        **{f"gyro_rad[{i}]": "rad/s" for i in range(3)},
        **{f"accelerometer_m_s2[{i}]": "m/s^2" for i in range(3)},
        "gyro_integral_dt": "us", "accelerometer_integral_dt": "us",
    },
    "vehicle_imu": {
        **{f"delta_angle[{i}]": "rad" for i in range(3)},
        **{f"delta_velocity[{i}]": "m/s" for i in range(3)},
        "delta_angle_dt": "us", "delta_velocity_dt": "us",
        **{f"gyro_rad_s[{i}]": "rad/s" for i in range(3)},
        **{f"accel_m_s2[{i}]": "m/s^2" for i in range(3)},
    },
    "vehicle_imu_status": {"temperature_accel": "degC", "temperature_gyro": "degC"},
}  # fmt: skip
"""Units of PX4's sensor topics, from the uORB message definitions (PX4-Autopilot
``msg/SensorGyro.msg`` [rad/s], ``SensorAccel.msg`` [m/s²], ``SensorBaro.msg`` pressure [Pa],
``SensorMag.msg`` [gauss], ``SensorCombined.msg`` ``gyro_rad`` [rad/s] and
``accelerometer_m_s2`` [m/s²], ``VehicleImu.msg`` ``delta_angle`` [rad] and ``delta_velocity``
[m/s] over ``delta_angle_dt``/``delta_velocity_dt`` [µs]; temperatures [°C]).  pyulog names an
array's elements ``name[i]``.  ``vehicle_imu`` is also given as rates:
``gyro_rad_s[i] = delta_angle[i] / delta_angle_dt`` [rad/s] and
``accel_m_s2[i] = delta_velocity[i] / delta_velocity_dt`` [m/s²] (columns added by the
reader).  The time is ``timestamp`` [µs]."""


@dataclass(frozen=True)
class _ULogRead:
    """A parsed ULog and what its reading lost: ``notes`` (sentences for one warning)."""

    ulog: Any
    damaged: bool
    skipped: bool
    """pyulog skipped damaged messages inside the file (``file_corruption``)."""
    notes: tuple[str, ...]


_Cache = dict[tuple[Path, tuple[str, ...]], "_ULogRead | None"]
_PARSED: contextvars.ContextVar[_Cache | None] = contextvars.ContextVar(
    "thermocal_ulog_parsed", default=None
)


@contextlib.contextmanager
def parsed_once(path: str | Path, names: Sequence[str]) -> Iterator[None]:
    """Within the block, every read of the ULog ``path`` asking for topics among ``names``
    (:func:`ulog_sensor_instances`, :func:`read_ulog`, so :func:`read_recording` with a
    topic) is served from ONE pyulog parse of those topics, made at the first read: a
    command that takes several topics of one log reads the file once.  What is read, and
    every warning said, is the same as without the block (the parse is the same, only
    shared).

    Parameters
    ----------
    path : str or pathlib.Path
        The ULog file.
    names : sequence of str
        The topics the commands within the block read.

    Yields
    ------
    None
    """
    cache: _Cache = {(Path(path).resolve(), tuple(sorted(set(names)))): None}  # parsed lazily
    token = _PARSED.set(cache)
    try:
        yield
    finally:
        _PARSED.reset(token)


def release_parsed_topic(path: str | Path, topic: str) -> bool:
    """Within :func:`parsed_once`, drop one topic instance's data from the block's parse of
    ``path`` (a caller that has read it and will not read it again gives its memory back:
    the instance's raw messages, about its share of the log's size).  A later read of that
    instance within the block says it is not in the log.

    Parameters
    ----------
    path : str or pathlib.Path
        The ULog file.
    topic : str
        The topic instance, ``NAME.N``.

    Returns
    -------
    bool
        True when the instance was parsed and is now dropped; False outside the block, or
        when the log has not been parsed or has no such instance.
    """
    cache = _PARSED.get()
    if cache is None:
        return False
    name, inst = parse_topic(topic)
    where = Path(path).resolve()
    for (at, _have), read in cache.items():
        if at != where or read is None:
            continue
        data = read.ulog.data_list
        keep = [d for d in data if not (d.name == name and d.multi_id == inst)]
        if len(keep) < len(data):
            data[:] = keep
            return True
    return False


def _parse_ulog(path: Path, names: list[str] | None) -> _ULogRead:
    """Parse a ULog (:func:`_parse_ulog_file`), or, within :func:`parsed_once` for this file
    and a superset of ``names``, take the block's one parse."""
    cache = _PARSED.get()
    if cache is not None and names is not None:
        for (where, have), read in cache.items():
            if set(names) <= set(have) and where == path.resolve():
                if read is None:
                    read = cache[(where, have)] = _parse_ulog_file(path, list(have))
                return read
    return _parse_ulog_file(path, names)


def _parse_ulog_file(path: Path, names: list[str] | None) -> _ULogRead:
    """Parse a ULog with pyulog (only the topics ``names``, all when None), its printed
    noise captured, and measure what was lost:

    * pyulog stops at a damaged message header (a zeroed length, say) without saying so:
      the bytes after the position it stopped at, as a share of the file;
    * a file cut inside its last message (a short read);
    * pyulog's own ``file_corruption`` flag (damaged messages skipped: the topics' missing
      samples are estimated from their sample interval, :func:`_topic_loss`).

    A clean log is read by :func:`thermocal.readers.ulog_fast.fast_ulog` (the same
    ``ULog`` object, its data messages gathered with numpy: 3–5× faster); any log it does
    not take as clean is parsed by pyulog as above.
    """
    refuse_special_input(path, "ULog")  # pyulog would block on a FIFO
    try:
        from pyulog import ULog
    except ImportError:
        raise ThermocalInputError(
            f"{path}: reading PX4 ULog files needs pyulog: pip install 'thermocal[logs]' "
            "(or pip install pyulog)"
        ) from None
    if not path.exists():
        raise FileFormatError(f"{path}: no such file")
    size = path.stat().st_size
    if size == 0:
        raise FileFormatError(f"{path}: the file is empty")
    from thermocal.readers import ulog_fast

    fast = ulog_fast.fast_ulog(path, names)
    if fast is not None:
        return _ULogRead(fast, False, False, ())
    fh = TrackedReader(path)
    try:
        with library_output_captured() as noise:
            ulog = ULog(fh, message_name_filter_list=names)
    except Exception as exc:  # pyulog raises several kinds on a bad file
        msg = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise FileFormatError(f"{path}: not a readable ULog file ({msg})") from None
    finally:
        fh.close()
    notes: list[str] = []
    stop = fh.stopped_at if fh.stopped_at is not None else size
    if stop < size:
        notes.append(
            f"pyulog stopped at byte {stop:,} of {size:,} (a damaged message header): the "
            f"last {100.0 * (size - stop) / size:.1f} % of the file is not read"
        )
    cut = fh.short_read and stop == size
    if cut:
        notes.append("the file ends inside a message (cut): its last message is lost")
    if ulog.file_corruption:
        notes.append("pyulog found damaged messages and skipped them")
    said = noise.summary("pyulog")
    if said:
        notes.append(said)
    skipped = bool(ulog.file_corruption)
    return _ULogRead(ulog, stop < size or cut or skipped, skipped, tuple(notes))


def _topic_loss(time_us: FloatArray) -> tuple[int, int]:
    """(missing, expected) samples of a topic in a damaged log, judged by its median sample
    interval: expected = span / median interval + 1."""
    n = int(time_us.size)
    if n < 3:
        return 0, n
    dt = np.diff(time_us)
    med = float(np.median(dt))
    if not (math.isfinite(med) and med > 0):
        return 0, n
    span = float(time_us[-1] - time_us[0])
    expected = round(span / med) + 1
    return max(0, expected - n), max(expected, n)


def ulog_parameter_changes(
    path: str | Path, topics: Sequence[str]
) -> list[tuple[float, str, float]]:
    """The parameters set during the recording of a ULog: (time [s], name, value) of each
    ``P`` message of its data section (ULog File Format: a parameter changed in flight;
    pyulog's ``changed_parameters``, timed by the last data message before it), in log
    order, from the parse of ``topics`` (:func:`_parse_ulog`: within :func:`parsed_once`,
    no second read).  Values equal to those already in force are kept; the caller
    compares.

    Parameters
    ----------
    path : str or pathlib.Path
        The ULog file.
    topics : sequence of str
        The topics parsed with it (shares the parse).

    Returns
    -------
    list of (float, str, float)
        Time [s], parameter name and value of each change, in log order.

    References
    ----------
    - PX4 Autopilot, *ULog File Format*, PX4 User Guide (docs.px4.io,
      ``dev_log/ulog_file_format``).
    """
    read = _parse_ulog(Path(path), list(topics))
    return [(float(t) * 1e-6, str(n), float(v)) for t, n, v in read.ulog.changed_parameters]


def ulog_sensor_instances(path: str | Path, topics: Sequence[str]) -> list[tuple[str, int]]:
    """The instances of ``topics`` in a ULog that carry a temperature, sorted; every instance
    left out (no ``temperature`` field, or one that is all 0 or NaN: no sensor behind it) is
    named in a warning, and damage to the log is said (:func:`_parse_ulog`).

    Parameters
    ----------
    path : str or pathlib.Path
        The ULog file.
    topics : sequence of str
        Topic names (``sensor_gyro``, ``sensor_accel``, …).

    Returns
    -------
    list of (str, int)
        ``(topic, multi_id)`` of each instance with a usable temperature, sorted.

    Warns
    -----
    LogDamageWarning
        Instances left out, or damage to the log.
    """
    p = Path(path)
    read = _parse_ulog(p, list(topics))
    warn_damage(p, read.notes)
    out: list[tuple[str, int]] = []
    left: list[str] = []
    for d in read.ulog.data_list:
        t = d.data.get("temperature")
        where = f"{d.name}.{int(d.multi_id)}"
        if t is None:
            left.append(f"{where} (no temperature field)")
        elif not np.isfinite(t).any():
            left.append(f"{where} (temperature all NaN)")
        elif np.all(t == 0):
            left.append(f"{where} (temperature all 0)")
        else:
            out.append((d.name, int(d.multi_id)))
    if left:
        warnings.warn(
            LogDamageWarning(
                f"{p}: {len(left)} sensor instance(s) left out, without a usable temperature: "
                + ", ".join(left)
            ),
            stacklevel=2,
        )
    return sorted(out)


def read_ulog(path: Path, topic: str | None) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One topic instance of a PX4 ULog as a table: its fields as columns, ``timestamp``
    [µs] the time, PX4's units for the known topics, the median ``device_id`` as the
    sensor id.  Damage to the log is said in a warning with what was lost
    (:func:`_parse_ulog`).  Needs ``pyulog`` (``pip install 'thermocal[logs]'``).

    Parameters
    ----------
    path : pathlib.Path
        The ULog file.
    topic : str or None
        ``NAME`` or ``NAME.INSTANCE`` (default instance 0); ``None``: the default topic.

    Returns
    -------
    tuple of (pandas.DataFrame, dict)
        The topic's fields as float64 columns, and what the reader found (time column
        and its unit, column units, sensor id).

    Raises
    ------
    MissingColumnError
        No such topic instance in the log (the message lists those it has).
    FileFormatError
        A missing, empty or unreadable ULog file.
    ThermocalInputError
        ``pyulog`` is not installed (``pip install 'thermocal[logs]'``).

    Warns
    -----
    LogDamageWarning
        Damage to the log and the messages lost.

    References
    ----------
    - PX4 Autopilot, *ULog File Format*, PX4 User Guide (docs.px4.io,
      ``dev_log/ulog_file_format``).
    """
    name, inst = parse_topic(topic)
    read = _parse_ulog(path, [name])
    found = [d for d in read.ulog.data_list if d.name == name and d.multi_id == inst]
    if not found:
        warn_damage(path, read.notes)
        every = _parse_ulog(path, None).ulog.data_list if not read.damaged else []
        have = sorted(f"{d.name}.{d.multi_id}" for d in every or read.ulog.data_list)
        raise MissingColumnError(
            f"{path}: no topic {name}.{inst} in the log"
            + (" (it may be in the damaged part)" if read.damaged else "")
            + f"; it has: {', '.join(have) or 'none'}"
        )
    data = found[0].data
    cols = {k: np.asarray(v, dtype=np.float64) for k, v in data.items()}
    notes = list(read.notes)
    if read.skipped and "timestamp" in cols:  # messages skipped inside the read part
        missing, expected = _topic_loss(cols["timestamp"])
        if missing:
            notes.append(
                f"{name}.{inst} misses about {missing:,} of {expected:,} samples "
                f"({100.0 * missing / expected:.1f} %) judged by its sample interval"
            )
    warn_damage(path, notes)
    if name == "vehicle_imu":  # integrals over their intervals → rates (PX4_UNITS)
        for i in range(3):
            for d_col, dt_col, out in (
                (f"delta_angle[{i}]", "delta_angle_dt", f"gyro_rad_s[{i}]"),
                (f"delta_velocity[{i}]", "delta_velocity_dt", f"accel_m_s2[{i}]"),
            ):
                if d_col in cols and dt_col in cols:
                    dt_s = cols[dt_col] * 1e-6
                    with np.errstate(divide="ignore", invalid="ignore"):
                        cols[out] = np.where(dt_s > 0, cols[d_col] / dt_s, np.nan)
    df = pd.DataFrame(cols)
    units_ = {k: u for k, u in PX4_UNITS.get(name, {}).items() if k in df.columns}
    info: dict[str, Any] = {"time": "timestamp", "time_unit": "us", "units": units_}
    info["fc_log"] = True
    if "device_id" in df.columns:
        ids = df["device_id"].to_numpy()
        info["metadata"] = {"sensor_id": str(int(np.median(ids)))}
        if np.unique(ids).size > 1:
            warnings.warn(
                TextLayoutWarning(f"{path}: {name}.{inst} changes device_id during the log"),
                stacklevel=3,
            )
    info["ulog_topic"] = f"{name}.{inst}"
    return df, info
