"""ROS 1 bags (``.bag``), ROS 2 bags (a folder of ``metadata.yaml`` and ``.db3`` or ``.mcap``
storage) and MCAP files (``.mcap``), read with ``rosbags``: a ``sensor_msgs/Imu`` topic as
gyro and accelerometer columns, a ``sensor_msgs/Temperature`` topic joined to its time."""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from thermocal._lazy import LazyModule
from thermocal.errors import (
    FileFormatError,
    MissingColumnError,
    ThermocalInputError,
    ThermocalWarning,
    TimestampWarning,
)
from thermocal.outputs import refuse_special_input
from thermocal.readers.common import check_memory
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    import pandas as pd
else:
    pd = LazyModule("pandas")

Stamp = Literal["header", "receive"]
"""Which time a message is read at: its ``header.stamp`` (when the sensor sampled) or the
bag's receive time (when the recorder wrote it)."""

IMU_TYPES: frozenset[str] = frozenset({"sensor_msgs/msg/Imu", "sensor_msgs/Imu"})
TEMPERATURE_TYPES: frozenset[str] = frozenset(
    {"sensor_msgs/msg/Temperature", "sensor_msgs/Temperature"}
)
IMU_COLUMNS: tuple[str, ...] = ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")
BAG_UNITS: dict[str, str] = {
    **dict.fromkeys(IMU_COLUMNS[:3], "rad/s"),
    **dict.fromkeys(IMU_COLUMNS[3:], "m/s^2"),
    "temperature": "degC",
}
"""Units of the columns read from a bag, from the ROS message definitions
(``sensor_msgs/Imu``: ``angular_velocity`` [rad/s], ``linear_acceleration`` [m/s²];
``sensor_msgs/Temperature``: ``temperature`` [°C]; REP 103)."""


class BagTopicWarning(ThermocalWarning):
    """A bag's temperature topic was not joined: several could be, none was named."""


_BATCH = 8192  # messages decoded together
_IMU_TAIL = 296  # bytes of an Imu message after its header (37 float64 + 4 of alignment)
_MIN_MESSAGE = 16  # bytes of the smallest message a bag can hold (a header without frame)
_NS = 1_000_000_000


def _definitions_before_iron() -> Any:
    """The message definitions to read a ROS 2 bag that stores none: rosbag2 writes them
    into its storage from ROS 2 Iron (2023) on; a bag recorded with Foxy, Galactic or Humble
    holds only the type names.  ``sensor_msgs/Imu`` and ``sensor_msgs/Temperature`` (and the
    ``std_msgs/Header`` they carry) are the same in every ROS 2 release, so Humble's set
    reads them; a bag that carries its own definitions is read with those."""
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE)


def _needs_rosbags(path: Path) -> Any:
    """The ``rosbags`` package, or one error naming the extra that installs it."""
    try:
        import rosbags.highlevel
    except ImportError:
        raise ThermocalInputError(
            f"{path}: reading ROS bags and MCAP files needs rosbags: "
            "pip install 'thermocal[bags]' (or pip install rosbags)"
        ) from None
    return rosbags.highlevel


def is_ros2_bag(path: str | Path) -> bool:
    """Whether ``path`` is a ROS 2 bag folder: a directory holding ``metadata.yaml`` or a
    ``.db3``/``.mcap`` storage file (a folder of storage without ``metadata.yaml`` is
    recognised so that its reader can say what is missing).

    Parameters
    ----------
    path : str or pathlib.Path
        A path given as a recording.

    Returns
    -------
    bool
        True for a ROS 2 bag folder.

    Examples
    --------
    >>> from thermocal.readers.bag import is_ros2_bag
    >>> is_ros2_bag("no/such/folder")
    False
    """
    p = Path(path)
    try:
        if not p.is_dir():
            return False
        if (p / "metadata.yaml").is_file():
            return True
        return any(c.suffix in (".db3", ".mcap") for c in p.iterdir())
    except OSError:
        return False


@dataclass
class _Series:
    """The messages of one topic as they are read: int64 stamps [ns] and float64 values,
    gathered batch by batch (each column concatenated once at the end)."""

    names: tuple[str, ...]
    header: list[np.ndarray] = field(default_factory=list)
    receive: list[np.ndarray] = field(default_factory=list)
    values: list[list[np.ndarray]] = field(default_factory=list)
    pending: list[tuple[int, bytes]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.values = [[] for _ in self.names]

    def column(self, i: int) -> np.ndarray:
        """Column ``i`` whole, its batches released."""
        parts, self.values[i] = self.values[i], []
        return np.concatenate(parts) if parts else np.empty(0)


def _aligned(pos: int, cdr: bool) -> int:
    """The offset of the next float64: CDR aligns to 8 from the end of its 4-byte
    encapsulation header; ROS 1 packs without padding."""
    return 4 + -(-(pos - 4) // 8) * 8 if cdr else pos


def _layouts(raw: bytes, cdr: bool) -> Iterator[tuple[int, int]]:
    """Candidate (stamp offset, first float64 after the header) of a message: CDR
    (``sec``, ``nanosec``, ``frame_id``), ROS 1 with ``seq`` first, ROS 1 without."""
    for stamp in (4,) if cdr else (4, 0):
        at = stamp + 8
        if len(raw) < at + 4:
            continue
        n = int.from_bytes(raw[at : at + 4], "little")
        yield stamp, _aligned(at + 4 + n, cdr)


def _fast(block: np.ndarray, stamp: int, body: int, offsets: tuple[int, ...]) -> tuple[Any, ...]:
    """Stamps [ns] and float64 fields of equal-length messages ``block`` (rows of bytes)."""
    sec = block[:, stamp : stamp + 4].copy().view("<i4")[:, 0].astype(np.int64)
    nsec = block[:, stamp + 4 : stamp + 8].copy().view("<u4")[:, 0].astype(np.int64)
    vals = [block[:, body + o : body + o + 8].copy().view("<f8")[:, 0] for o in offsets]
    return sec * _NS + nsec, vals


def _slow(reader: Any, conn: Any, raws: list[bytes], kind: str) -> tuple[Any, ...]:
    """Stamps [ns] and fields of ``raws`` through the ROS deserializer, one by one."""
    stamps = np.empty(len(raws), dtype=np.int64)
    vals = np.empty((len(raws), 6 if kind == "imu" else 1))
    for i, raw in enumerate(raws):
        msg = reader.deserialize(raw, conn.msgtype)
        st = msg.header.stamp
        stamps[i] = int(getattr(st, "sec", getattr(st, "secs", 0))) * _NS + int(
            getattr(st, "nanosec", getattr(st, "nsecs", 0))
        )
        if kind == "imu":
            w, a = msg.angular_velocity, msg.linear_acceleration
            vals[i] = (w.x, w.y, w.z, a.x, a.y, a.z)
        else:
            vals[i, 0] = msg.temperature
    return stamps, list(vals.T)


_OFFSETS = {"imu": (104, 112, 120, 200, 208, 216), "temperature": (0,)}
"""Byte offsets, after the header, of ``angular_velocity`` and ``linear_acceleration``
(after the orientation quaternion and its 3×3 covariance) and of ``temperature``."""


def _decode(reader: Any, conn: Any, raws: list[bytes], kind: str) -> tuple[Any, ...]:
    """Stamps [ns] and fields of one batch of one topic: gathered with numpy when every
    message has the layout of the first (checked against the ROS deserializer), else one
    by one."""
    cdr = getattr(reader, "is2", True)
    first = raws[0]
    size = len(first)
    if cdr and first[:2] != b"\x00\x01":  # not little-endian CDR
        return _slow(reader, conn, raws, kind)
    if all(len(r) == size for r in raws):
        block = np.frombuffer(b"".join(raws), dtype=np.uint8).reshape(len(raws), size)
        want_stamps, want = _slow(reader, conn, raws[:1], kind)
        for stamp, body in _layouts(first, cdr):
            end = body + (_IMU_TAIL if kind == "imu" else 16)
            if end != size or np.any(
                block[:, stamp + 8 : stamp + 12] != block[0, stamp + 8 : stamp + 12]
            ):
                continue
            stamps, vals = _fast(block[:1], stamp, body, _OFFSETS[kind])
            same = stamps[0] == want_stamps[0] and all(
                np.array_equal(v, w, equal_nan=True) for v, w in zip(vals, want, strict=True)
            )
            if same:
                return _fast(block, stamp, body, _OFFSETS[kind])
    return _slow(reader, conn, raws, kind)


def _flush(reader: Any, conn: Any, series: _Series, kind: str) -> None:
    """Decode the pending messages of ``series`` into its batches."""
    if not series.pending:
        return
    recv = np.fromiter((t for t, _ in series.pending), dtype=np.int64, count=len(series.pending))
    stamps, vals = _decode(reader, conn, [r for _, r in series.pending], kind)
    series.pending = []
    series.header.append(np.asarray(stamps, dtype=np.int64))
    series.receive.append(recv)
    for i, v in enumerate(vals):
        series.values[i].append(np.asarray(v, dtype=np.float64))


def _topic_list(conns: list[Any]) -> str:
    """``/imu (sensor_msgs/msg/Imu, 1200 messages), …`` for messages."""
    seen: dict[str, tuple[str, int]] = {}
    for c in conns:
        _, n = seen.get(c.topic, (c.msgtype, 0))
        seen[c.topic] = (c.msgtype, n + int(getattr(c, "msgcount", 0) or 0))
    return ", ".join(f"{t} ({ty}, {n:,} messages)" for t, (ty, n) in sorted(seen.items()))


def _pick(path: Path, conns: list[Any], topic: str | None) -> tuple[str, str | None]:
    """The IMU (or temperature) topic and the temperature topic joined to it, from
    ``topic`` (``NAME`` or ``NAME,TEMPERATURE_NAME``) or, when None, the bag's only
    ``sensor_msgs/Imu`` topic."""
    types = {c.topic: c.msgtype for c in conns}
    have = _topic_list(conns) or "none"
    imus = sorted(t for t, ty in types.items() if ty in IMU_TYPES)
    temps = sorted(t for t, ty in types.items() if ty in TEMPERATURE_TYPES)
    names = [s.strip() for s in topic.split(",")] if topic else []
    if len(names) > 2 or any(not n for n in names):
        raise ThermocalInputError.naming(
            f"{path}: {{topic}} {topic!r}: give the IMU topic, or IMU_TOPIC,TEMPERATURE_TOPIC",
            "topic",
        )
    if not names:
        if not imus and temps:
            raise MissingColumnError.naming(
                f"{path}: no sensor_msgs/Imu topic; choose a sensor_msgs/Temperature topic "
                f"with {{topic}} to read it alone; it has: {have}",
                "topic",
            )
        if not imus:
            raise MissingColumnError(
                f"{path}: no sensor_msgs/Imu topic (thermocal reads sensor_msgs/Imu and "
                f"sensor_msgs/Temperature topics; record the IMU as sensor_msgs/Imu); "
                f"it has: {have}"
            )
        if len(imus) > 1:
            raise MissingColumnError.naming(
                f"{path}: several sensor_msgs/Imu topics; choose one with {{topic}}; "
                f"it has: {have}",
                "topic",
            )
        names = imus[:1]
    for i, n in enumerate(names):
        if n not in types:
            raise MissingColumnError.naming(
                f"{path}: no topic {n} in the bag; choose one with {{topic}}; it has: {have}",
                "topic",
            )
        ok = IMU_TYPES | TEMPERATURE_TYPES if i == 0 else TEMPERATURE_TYPES
        if types[n] not in ok:
            need = "sensor_msgs/Imu or sensor_msgs/Temperature" if i == 0 else "a Temperature"
            raise ThermocalInputError.naming(
                f"{path}: topic {n} is {types[n]}, not {need}; choose with {{topic}}; "
                f"it has: {have}",
                "topic",
            )
    if len(names) == 2:
        return names[0], names[1]
    if types[names[0]] in TEMPERATURE_TYPES:
        return names[0], None
    if len(temps) > 1:
        warnings.warn(
            BagTopicWarning.naming(
                f"{path}: several sensor_msgs/Temperature topics ({', '.join(temps)}): none "
                f"joined to {names[0]}; name one with {{topic}} {names[0]},TEMPERATURE_TOPIC",
                "topic",
            ),
            stacklevel=4,
        )
        return names[0], None
    return names[0], temps[0] if temps else None


def _scan(path: Path, topic: str | None) -> tuple[dict[str, _Series], str, str | None]:
    """One pass over the bag: the chosen topics' stamps and values."""
    highlevel = _needs_rosbags(path)
    try:
        reader = highlevel.AnyReader([path], default_typestore=_definitions_before_iron())
        reader.open()
    except Exception as exc:  # rosbags raises several kinds on a damaged bag
        raise FileFormatError(_unreadable(path, exc)) from None
    try:
        conns = list(reader.connections)
        if not conns:
            raise FileFormatError(f"{path}: the bag holds no topics (an empty recording)")
        imu, temp = _pick(path, conns, topic)
        kinds = {imu: "imu" if any(c.topic == imu and c.msgtype in IMU_TYPES for c in conns)
                 else "temperature"}  # fmt: skip
        if temp is not None:
            kinds[temp] = "temperature"
        claimed = sum(int(getattr(c, "msgcount", 0) or 0) for c in conns if c.topic in kinds)
        size = _size(path)
        check_memory(path, min(claimed, size // _MIN_MESSAGE + 1), 9, estimated=True)
        out = {
            t: _Series(IMU_COLUMNS if k == "imu" else ("temperature",)) for t, k in kinds.items()
        }
        _read_messages(reader, [c for c in conns if c.topic in kinds], kinds, out)
    except ThermocalInputError:
        raise
    except Exception as exc:  # a damaged chunk, a message that does not decode
        raise FileFormatError(_unreadable(path, exc)) from None
    finally:
        with contextlib.suppress(Exception):  # a damaged bag may fail again; said above
            reader.close()
    return out, imu, temp


def _read_messages(
    reader: Any, conns: list[Any], kinds: dict[str, str], out: dict[str, _Series]
) -> None:
    """Every message of ``conns`` into its topic's series, a batch at a time."""
    last: dict[str, Any] = {}
    for conn, t_ns, raw in reader.messages(connections=conns):
        s = out[conn.topic]
        if last.get(conn.topic) is not None and last[conn.topic] is not conn:
            _flush(reader, last[conn.topic], s, kinds[conn.topic])  # one connection a batch
        last[conn.topic] = conn
        s.pending.append((int(t_ns), bytes(raw)))
        if len(s.pending) >= _BATCH:
            _flush(reader, conn, s, kinds[conn.topic])
    for t, conn in last.items():
        _flush(reader, conn, out[t], kinds[t])


def _size(path: Path) -> int:
    """Bytes of a bag file or of a ROS 2 bag folder's files."""
    if path.is_dir():
        return sum(f.stat().st_size for f in path.iterdir() if f.is_file())
    return path.stat().st_size


_OTHER_SCHEMAS = frozenset({"ros1msg", "protobuf", "flatbuffer", "jsonschema"})
"""MCAP's well-known schema encodings other than ROS 2's (MCAP specification, appendix:
well-known encodings), which rosbags does not read."""


def _unreadable(path: Path, exc: BaseException) -> str:
    """One line for a bag rosbags could not read."""
    msg = " ".join(str(exc).split())[:200] or type(exc).__name__
    if path.is_dir() and not (path / "metadata.yaml").is_file():
        return (
            f"{path}: a ROS 2 bag folder needs its metadata.yaml (not found); give the "
            ".db3 or .mcap storage file itself instead"
        )
    if isinstance(exc, KeyError) and exc.args and exc.args[0] in _OTHER_SCHEMAS:
        return (
            f"{path}: an MCAP file whose message definitions are {exc.args[0]!r}, not ROS 2 "
            "(ros2msg, ros2idl): not read; record it with ROS 2 (ros2 bag record -s mcap) "
            "or give the ROS 1 .bag it was converted from"
        )
    return f"{path}: not a readable ROS bag or MCAP file ({msg})"


@dataclass(frozen=True)
class _Repaired:
    """One topic's samples in time order and what was repaired."""

    time_ns: np.ndarray
    columns: dict[str, np.ndarray]
    out_of_order: int
    duplicates: int


def _repair(path: Path, topic: str, s: _Series, stamp: Stamp) -> _Repaired:
    """Stamps sorted (stably), exact duplicates (same stamp, same values) dropped; a stamp
    repeated with other values is an error."""
    chosen = s.header if stamp == "header" else s.receive
    s.header, s.receive = [], []  # the other stamps released unread
    t = np.concatenate(chosen) if chosen else np.empty(0, np.int64)
    del chosen
    back = int(np.count_nonzero(np.diff(t) < 0))
    order = np.argsort(t, kind="stable") if back else None
    if order is not None:
        t = t[order]
    cols: dict[str, np.ndarray] = {}
    for i, name in enumerate(s.names):
        col = s.column(i)
        cols[name] = col[order] if order is not None else col
        del col
    same = t[1:] == t[:-1]
    if same.any():
        equal = same.copy()
        for c in cols.values():
            equal &= (c[1:] == c[:-1]) | (np.isnan(c[1:]) & np.isnan(c[:-1]))
        clash = int(np.count_nonzero(same & ~equal))
        if clash:
            other = "receive" if stamp == "header" else "header"
            raise FileFormatError.naming(
                f"{path}: {clash:,} messages of {topic} repeat the {stamp} stamp of another "
                f"with different values; read the bag's {other} stamps with {{stamp}} {other}",
                "stamp",
            )
        keep = np.ones(t.size, dtype=bool)
        keep[1:] = ~equal
        t = t[keep]
        cols = {k: v[keep] for k, v in cols.items()}
        return _Repaired(t, cols, back, int(np.count_nonzero(equal)))
    return _Repaired(t, cols, back, 0)


def _seconds(t_ns: np.ndarray) -> FloatArray:
    """Stamps [ns] as seconds since the first [s] (exact to the nanosecond for 104 days,
    where seconds since 1970 in float64 keep only a quarter of a microsecond)."""
    out: FloatArray = (t_ns - t_ns[0]).astype(np.float64) / 1e9
    return out


def _join(imu_ns: np.ndarray, temp: _Repaired) -> FloatArray:
    """The temperature at each IMU stamp, linear between its readings, NaN outside them."""
    if temp.time_ns.size == 0:
        return np.full(imu_ns.size, np.nan)
    t0 = min(int(imu_ns[0]) if imu_ns.size else 0, int(temp.time_ns[0]))
    x = (imu_ns - t0).astype(np.float64)
    xp = (temp.time_ns - t0).astype(np.float64)
    out = np.interp(x, xp, temp.columns["temperature"], left=np.nan, right=np.nan)
    return np.asarray(out, dtype=np.float64)


def read_bag(
    path: str | Path, topic: str | None = None, stamp: Stamp = "header"
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One IMU (or temperature) topic of a ROS 1 bag, a ROS 2 bag or an MCAP file as a table.

    A ``sensor_msgs/Imu`` topic gives ``gyro_x/y/z`` (``angular_velocity`` [rad/s]) and
    ``accel_x/y/z`` (``linear_acceleration`` [m/s²]); a ``sensor_msgs/Temperature`` topic
    ``temperature`` [°C], joined to the IMU's stamps (linear between its readings, NaN
    outside them) when it is the bag's only one or is named.  ``time`` [s] is each
    message's header stamp or the bag's receive time, in seconds since the first (the
    first, in ns since 1970, is the metadata's ``time_origin_ns``).  Stamps out
    of order are sorted (stably) and exact duplicates (same stamp and values) dropped, both
    counted in a warning.  Needs ``rosbags`` (``pip install 'thermocal[bags]'``).

    Parameters
    ----------
    path : str or pathlib.Path
        A ``.bag`` file, a ROS 2 bag folder (``metadata.yaml`` and its ``.db3`` or
        ``.mcap`` files), or a ``.mcap``/``.db3`` storage file.
    topic : str, optional
        ``IMU_TOPIC`` or ``IMU_TOPIC,TEMPERATURE_TOPIC`` (``"/imu"``,
        ``"/imu/data,/imu/temperature"``), or a temperature topic alone; default: the
        bag's only ``sensor_msgs/Imu`` topic.
    stamp : {"header", "receive"}
        The time of each message: its header stamp (when the sensor sampled; default) or
        the bag's receive time (when the recorder wrote it).

    Returns
    -------
    tuple of (pandas.DataFrame, dict)
        The columns (``time`` first), and what the reader found: time column and unit,
        the columns' units, the topics read.

    Raises
    ------
    thermocal.errors.MissingColumnError
        No such topic, or no single IMU topic to choose (the topics and types are listed).
    thermocal.errors.ThermocalInputError
        A topic that is neither ``sensor_msgs/Imu`` nor ``sensor_msgs/Temperature``;
        ``rosbags`` is not installed.
    thermocal.errors.FileFormatError
        A damaged, truncated or empty bag; a stamp repeated with other values.

    Warns
    -----
    thermocal.errors.TimestampWarning
        Stamps out of order (sorted) or duplicated (dropped), with their counts.

    References
    ----------
    - T. Foote and M. Purvis, *REP 103: Standard Units of Measure and Coordinate
      Conventions*, 2010; the ``sensor_msgs/Imu`` and ``sensor_msgs/Temperature`` message
      definitions (ROS ``common_msgs``, ROS 2 ``common_interfaces``).
    - ROS Wiki, *Bags/Format/2.0*; Foxglove, *MCAP File Format Specification*.

    Examples
    --------
    >>> from thermocal.readers.bag import read_bag
    >>> read_bag("missing.bag")
    Traceback (most recent call last):
    ...
    thermocal.errors.FileFormatError: missing.bag: no such file
    """
    p = Path(path)
    if stamp not in ("header", "receive"):
        raise ThermocalInputError.naming(
            f"{{stamp}} must be header or receive, got {stamp!r}", "stamp"
        )
    if not p.exists():
        raise FileFormatError(f"{p}: no such file")
    refuse_special_input(p, "ROS bag")
    series, first, temp = _scan(p, topic)
    main = _repair(p, first, series.pop(first), stamp)
    if main.time_ns.size == 0:
        raise FileFormatError.naming(
            f"{p}: topic {first} holds no messages; choose another with {{topic}}", "topic"
        )
    _warn_repairs(p, first, main, stamp)
    cols: dict[str, np.ndarray] = {"time": _seconds(main.time_ns), **main.columns}
    if temp is not None:
        tr = _repair(p, temp, series.pop(temp), stamp)
        _warn_repairs(p, temp, tr, stamp)
        cols["temperature"] = _join(main.time_ns, tr)
    df = pd.DataFrame(cols, copy=False)
    units_ = {k: u for k, u in BAG_UNITS.items() if k in df.columns}
    info: dict[str, Any] = {"time": "time", "time_unit": "s", "units": units_}
    info["bag_topic"] = first if temp is None else f"{first},{temp}"
    info["metadata"] = {"time_origin_ns": int(main.time_ns[0]), "stamp": stamp}
    return df, info


def _warn_repairs(path: Path, topic: str, r: _Repaired, stamp: Stamp) -> None:
    """One warning for the stamps of ``topic`` that were out of order or duplicated."""
    said = []
    if r.out_of_order:
        said.append(f"{r.out_of_order:,} {stamp} stamps out of order (sorted)")
    if r.duplicates:
        said.append(f"{r.duplicates:,} exact duplicates (dropped)")
    if said:
        other = "receive" if stamp == "header" else "header"
        warnings.warn(
            TimestampWarning.naming(
                f"{path}: {topic}: {' and '.join(said)}; read the bag's {other} stamps with "
                f"{{stamp}} {other}",
                "stamp",
            ),
            stacklevel=3,
        )


__all__ = [
    "BAG_UNITS",
    "IMU_COLUMNS",
    "IMU_TYPES",
    "TEMPERATURE_TYPES",
    "BagTopicWarning",
    "Stamp",
    "is_ros2_bag",
    "read_bag",
]
