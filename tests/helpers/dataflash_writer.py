"""A minimal ArduPilot DataFlash (.bin) writer for tests, from the log format as ArduPilot
documents it (LogStructure.h): every message is ``0xA3 0x95 <type>`` then its payload;
type 128 (FMT) defines a message: ``<BB4s16s64s>`` type, length (header included), name,
format characters, comma-separated labels."""

from __future__ import annotations

import struct
from collections.abc import Sequence

HEAD = b"\xa3\x95"
FMT_TYPE = 128
CODES = {
    "Q": "Q",
    "B": "B",
    "f": "f",
    "I": "I",
    "H": "H",
    "i": "i",
    "h": "h",
    "c": "h",  # int16 ×100 (LogStructure.h), pass round(value·100)
    "d": "d",
    "n": "4s",
    "N": "16s",
    "Z": "64s",
}


def fmt_message(msg_type: int, name: str, fmt: str, labels: Sequence[str]) -> bytes:
    length = 3 + struct.calcsize("<" + "".join(CODES[c] for c in fmt))
    payload = struct.pack(
        "<BB4s16s64s", msg_type, length, name.encode(), fmt.encode(), ",".join(labels).encode()
    )
    return HEAD + bytes([FMT_TYPE]) + payload


def data_message(msg_type: int, fmt: str, values: Sequence[float | bytes]) -> bytes:
    return HEAD + bytes([msg_type]) + struct.pack("<" + "".join(CODES[c] for c in fmt), *values)


IMU_FMT = "QBffffffIIf"
IMU_LABELS = ("TimeUS", "I", "GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ", "EG", "EA", "T")


def imu_log(rows: Sequence[Sequence[float]], msg_type: int = 100) -> bytes:
    """A log of FMT-self-description, the IMU format and IMU messages (rows in label order)."""
    out = bytearray(fmt_message(FMT_TYPE, "FMT", "BBnNZ", ("Type", "Length", "Name", "Format",
                                                           "Columns")))  # fmt: skip
    out += fmt_message(msg_type, "IMU", IMU_FMT, IMU_LABELS)
    for r in rows:
        out += data_message(msg_type, IMU_FMT, r)
    return bytes(out)


def dataflash_log(
    formats: Sequence[tuple[int, str, str, Sequence[str]]],
    messages: Sequence[tuple[int, Sequence[float | bytes]]],
) -> bytes:
    """A log of the FMT self-description, ``formats`` (type, name, format characters,
    labels) and ``messages`` (type, values in label order), in the order given."""
    out = bytearray(fmt_message(FMT_TYPE, "FMT", "BBnNZ", ("Type", "Length", "Name", "Format",
                                                           "Columns")))  # fmt: skip
    fmts = {}
    for t, name, fmt, labels in formats:
        out += fmt_message(t, name, fmt, labels)
        fmts[t] = fmt
    for t, values in messages:
        out += data_message(t, fmts[t], values)
    return bytes(out)


PARM_TYPE = 129
PARM_FORMAT = (PARM_TYPE, "PARM", "QNf", ("TimeUS", "Name", "Value"))
"""LogStructure.h: ``PARM`` "QNf" "TimeUS,Name,Value"."""


def parm(name: str, value: float, time_us: int = 1000) -> tuple[int, Sequence[float | bytes]]:
    return PARM_TYPE, (time_us, name.encode(), value)


OLD_IMU_FMT = "QffffffIIf"
OLD_IMU_LABELS = ("TimeUS", "GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ", "ErrG", "ErrA",
                  "Temp")  # fmt: skip
"""Copter 3.4–3.6: ``IMU``, ``IMU2``, ``IMU3`` without an instance field, ``Temp`` the
temperature, no unit messages."""
NEW_IMU_FMT = "QBffffffIIfBBHH"
NEW_IMU_LABELS = ("TimeUS", "I", "GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ", "EG", "EA",
                  "T", "GH", "AH", "GHz", "AHz")  # fmt: skip
"""Today's ``IMU`` (AP_InertialSensor/LogStructure.h), the instance in ``I``."""
