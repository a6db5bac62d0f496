"""ROS 1 bags, ROS 2 bags (sqlite3 and MCAP storage) and MCAP files written for tests with
``rosbags``' own writers and message classes (``sensor_msgs/Imu``,
``sensor_msgs/Temperature``), from arrays of stamps and values, so that a test knows every
number a reader must return."""

from __future__ import annotations

import shutil
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

NS = 1_000_000_000
KINDS = ("ros1", "sqlite3", "mcap")


@dataclass
class Topic:
    """One topic's messages: ``header_ns`` (header stamps), ``receive_ns`` (the bag's
    times, the order they are written in) and ``values`` (n × 6 gyro [rad/s] then accel
    [m/s²] for an Imu topic; n × 1 [°C] for a Temperature topic)."""

    name: str
    msgtype: str
    header_ns: np.ndarray
    receive_ns: np.ndarray
    values: np.ndarray
    frame_ids: Sequence[str] | None = None


def _typestore(kind: str):
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS1_NOETIC if kind == "ros1" else Stores.ROS2_HUMBLE)


def _message(ts, kind: str, msgtype: str, stamp_ns: int, row: np.ndarray, frame: str):
    """One message object of ``msgtype`` with ``stamp_ns`` and the values of ``row``."""
    t = ts.types
    if kind == "ros1":
        stamp = t["builtin_interfaces/msg/Time"](sec=stamp_ns // NS, nanosec=stamp_ns % NS)
        header = t["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame)
    else:
        stamp = t["builtin_interfaces/msg/Time"](sec=stamp_ns // NS, nanosec=stamp_ns % NS)
        header = t["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)
    if msgtype.endswith("Temperature"):
        return t["sensor_msgs/msg/Temperature"](
            header=header, temperature=float(row[0]), variance=0.01
        )
    v3, q = t["geometry_msgs/msg/Vector3"], t["geometry_msgs/msg/Quaternion"]
    cov = np.zeros(9)
    return t["sensor_msgs/msg/Imu"](
        header=header, orientation=q(x=0.0, y=0.0, z=0.0, w=1.0), orientation_covariance=cov,
        angular_velocity=v3(x=row[0], y=row[1], z=row[2]), angular_velocity_covariance=cov,
        linear_acceleration=v3(x=row[3], y=row[4], z=row[5]),
        linear_acceleration_covariance=cov,
    )  # fmt: skip


def write_bag(path: Path, kind: str, topics: Sequence[Topic], extra: Sequence[str] = ()) -> Path:
    """Write ``topics`` to a ``kind`` bag at ``path`` (``ros1``: a ``.bag`` file;
    ``sqlite3``/``mcap``: a ROS 2 bag folder); ``extra`` names ``std_msgs/String`` topics
    holding one message each.  Messages are written in receive-time order."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import StoragePlugin
    from rosbags.rosbag2 import Writer as Writer2

    ts = _typestore(kind)
    if path.exists():
        shutil.rmtree(path) if path.is_dir() else path.unlink()
    if kind == "ros1":
        writer = Writer1(path)
        serialize = ts.serialize_ros1
    else:
        plugin = StoragePlugin.SQLITE3 if kind == "sqlite3" else StoragePlugin.MCAP
        writer = Writer2(path, version=9, storage_plugin=plugin)
        serialize = ts.serialize_cdr
    writer.open()
    events: list[tuple[int, int, bytes]] = []
    for k, topic in enumerate(topics):
        conn = writer.add_connection(topic.name, topic.msgtype, typestore=ts)
        frames = topic.frame_ids or ["imu_link"] * len(topic.header_ns)
        for i in range(len(topic.header_ns)):
            msg = _message(ts, kind, topic.msgtype, int(topic.header_ns[i]),
                           np.atleast_1d(topic.values[i]), frames[i])  # fmt: skip
            events.append((int(topic.receive_ns[i]), k, serialize(msg, msg.__msgtype__)))
        topics[k].conn = conn  # type: ignore[attr-defined]
    for k, name in enumerate(extra):
        conn = writer.add_connection(name, "std_msgs/msg/String", typestore=ts)
        msg = ts.types["std_msgs/msg/String"](data="hello")
        events.append((int(topics[0].receive_ns[0]) + k, -1 - k, serialize(msg, msg.__msgtype__)))
        setattr(writer, f"_extra{k}", conn)
    for t_ns, k, raw in sorted(events, key=lambda e: e[0]):
        conn = topics[k].conn if k >= 0 else getattr(writer, f"_extra{-1 - k}")  # type: ignore[attr-defined]
        writer.write(conn, t_ns, raw)
    writer.close()
    return path


def storage_file(path: Path) -> Path:
    """The one storage file (``.db3`` or ``.mcap``) of a ROS 2 bag folder."""
    (f,) = [p for p in path.iterdir() if p.suffix in (".db3", ".mcap")]
    return f
