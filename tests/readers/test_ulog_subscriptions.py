"""The ULog reader (:mod:`thermocal.readers.ulog_fast`) against pyulog's own reading of a
log whose data message comes before its subscription (kills a mutant of
``benchmarks/mutation_check.py``, ``fw-*``)."""

from __future__ import annotations

import contextlib
import io
import struct
from pathlib import Path

import numpy as np


def _msg(kind: str, payload: bytes) -> bytes:
    """ULog (docs.px4.io, "ULog File Format"): ``uint16 msg_size, uint8 msg_type``, payload."""
    return struct.pack("<HB", len(payload), ord(kind)) + payload


def test_a_data_message_before_its_subscription_is_read_as_pyulog_reads_it(
    tmp_path: Path,
) -> None:
    """In the data section, a ``D`` of msg_id 0 (sensor_gyro) written before the ``A`` that
    subscribes msg_id 0, between data of another topic: thermocal's read of both topics
    equals pyulog's own parse of the same file (pyulog drops that message)."""
    from pyulog import ULog

    from thermocal.readers import ulog as ulog_mod

    out = bytearray(b"ULog\x01\x12\x35\x01" + struct.pack("<Q", 1_000))
    out += _msg("B", bytes(16) + struct.pack("<3Q", 0, 0, 0))
    fields = b":uint64_t timestamp;uint32_t device_id;float x;float y;float z;float temperature;"
    out += _msg("F", b"sensor_gyro" + fields)
    out += _msg("F", b"sensor_accel" + fields)

    def row(msg_id: int, i: int) -> bytes:
        payload = struct.pack("<QI4f", 2_000 + 1000 * i, 7, 0.1 * i, -0.2, 0.3, 20.0 + i)
        return _msg("D", struct.pack("<H", msg_id) + payload)

    out += _msg("A", struct.pack("<BH", 0, 1) + b"sensor_accel")
    out += row(1, 0)
    out += row(0, 0)  # the gyro before its subscription
    out += _msg("A", struct.pack("<BH", 0, 0) + b"sensor_gyro")
    for i in range(1, 40):
        out += row(0, i) + row(1, i)
    path = tmp_path / "early.ulg"
    path.write_bytes(bytes(out))
    names = ["sensor_gyro", "sensor_accel"]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        ref = ULog(str(path), names)
        read = ulog_mod._parse_ulog_file(path, names)
    ours = {(d.name, d.multi_id): d.data for d in read.ulog.data_list}
    theirs = {(d.name, d.multi_id): d.data for d in ref.data_list}
    assert ours.keys() == theirs.keys() and len(theirs[("sensor_gyro", 0)]["timestamp"]) == 39
    for key, want in theirs.items():
        for field, values in want.items():
            np.testing.assert_array_equal(ours[key][field], values, err_msg=f"{key} {field}")
