"""A PX4 calibration as text (:mod:`thermocal.report.firmware_text`): one row per sensor
instance, its device id and temperature sweep those of the log written here, its hold-out
rms one number per axis in the sensor's unit."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from thermocal.report.firmware_text import px4_tempcal_text
from thermocal.report.text import TextTable
from thermocal.tempcal.px4 import px4_tempcal
from ulog_writer import SENSOR_FIELDS, ulog_bytes


def test_px4_tempcal_text_rows_are_the_log_sensors(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    n = 8000
    t = np.arange(n) * 0.05
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))  # −10 … 50 °C
    x = (temp - 20.0) / 30.0
    gyro = np.column_stack([0.002 + 0.004 * x, -0.001 + 0.002 * x, 0.003 * x**2])  # [rad/s]
    gyro += rng.normal(0.0, 0.001, (n, 3))
    ts = (1e6 + t * 1e6).astype(np.int64)
    rows = [
        (int(s), 2293768, *map(float, v), float(c)) for s, v, c in zip(ts, gyro, temp, strict=True)
    ]
    log = tmp_path / "sweep.ulg"
    log.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, rows)]))
    res = px4_tempcal(log, tmp_path / "out")
    blocks = px4_tempcal_text(res)
    table = blocks[0]
    assert isinstance(table, TextTable)
    assert table.title == f"PX4 thermal calibration of {log}"
    (row,) = table.rows
    lo, hi = float(np.float32(temp.min())), float(np.float32(temp.max()))
    assert row[:3] == ("sensor_gyro.0", "2293768", f"{lo:.1f}…{hi:.1f}")
    assert row[2] == "-10.0…50.0"
    rms = row[4].split(" ")
    assert rms[1] == rms[3] == "/" and rms[-1] == "deg/h"
    assert all(isinstance(b, str) for b in blocks[1:])  # the notes
