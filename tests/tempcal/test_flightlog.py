"""A PX4 log read once into a FlightLog (thermocal.tempcal.flightlog): a log written here
from the ULog format description (tests/ulog_writer.py) with two gyros, one accelerometer
without a sensor behind it (temperature all 0), initial parameters and one change during
the recording; everything the calibration reads comes from ONE pyulog parse, and the data
are those written (a known slope per °C)."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from thermocal.tempcal.flightlog import open_px4_log
from ulog_writer import SENSOR_FIELDS, ulog_bytes

TOPICS = ("sensor_gyro", "sensor_accel", "sensor_baro", "sensor_mag")


def _log(path: Path) -> None:
    n = 2000
    t = np.arange(n) * 0.5
    temp = 10.0 + 40.0 * t / t[-1]
    topics: list[Any] = []
    for inst, slope in ((0, 1e-4), (1, -2e-4)):  # rad/s per °C on x
        rows = [(int(1e6 + ti * 1e6), 300 + inst, slope * (tt - 30.0), 0.0, 0.0, float(tt))
                for ti, tt in zip(t, temp, strict=True)]  # fmt: skip
        topics.append(("sensor_gyro", inst, SENSOR_FIELDS, rows))
    dead = [(int(1e6 + ti * 1e6), 400, 0.0, 0.0, -9.8, 0.0) for ti in t]
    topics.append(("sensor_accel", 0, SENSOR_FIELDS, dead))
    path.write_bytes(
        ulog_bytes(
            topics, params={"TC_G_ENABLE": 0, "TC_G0_X1_0": 0.5}, changed=[("TC_G0_X1_0", 0.25)]
        )
    )


def test_the_log_is_parsed_once_for_everything_the_calibration_reads(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import pyulog

    log = tmp_path / "two_gyros.ulg"
    _log(log)
    parses: list[Any] = []
    real = pyulog.ULog

    def counting(*args: Any, **kwargs: Any) -> Any:
        parses.append(kwargs.get("message_name_filter_list"))
        return real(*args, **kwargs)

    monkeypatch.setattr(pyulog, "ULog", counting)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        with open_px4_log(log, TOPICS) as flight:
            recs = {w: flight.recording(w) for w in ("sensor_gyro.0", "sensor_gyro.1")}
            table, _info = flight.table("sensor_gyro.1")
    assert len(parses) == 1, parses
    assert flight.instances == (("sensor_gyro", 0), ("sensor_gyro", 1))
    assert any("sensor_accel.0 (temperature all 0)" in str(w.message) for w in said)
    assert flight.parameters["TC_G_ENABLE"] == 0
    assert flight.parameters["TC_G0_X1_0"] == pytest.approx(0.5)
    assert [(name, v) for _t, name, v in flight.parameter_changes] == [("TC_G0_X1_0", 0.25)]
    # the data as written: x = slope·(T − 30) [rad/s]; the recording is in °/h
    for w, slope in (("sensor_gyro.0", 1e-4), ("sensor_gyro.1", -2e-4)):
        rec = recs[w]
        x, unit = rec.signal("x")
        assert unit == "deg/h"
        fitted = np.polyfit(rec.temperature_c("temperature"), x * np.pi / 180 / 3600, 1)[0]
        assert fitted == pytest.approx(slope, rel=1e-4)
    assert np.polyfit(table["temperature"], table["x"], 1)[0] == pytest.approx(-2e-4, rel=1e-4)


def test_a_log_without_a_sensor_has_no_instances_and_reads_no_parameters(tmp_path: Path) -> None:
    log = tmp_path / "dead.ulg"
    dead = [(int(1e6 + i * 1e6), 400, 0.0, 0.0, -9.8, 0.0) for i in range(50)]
    log.write_bytes(ulog_bytes([("sensor_accel", 0, SENSOR_FIELDS, dead)], params={"A": 1}))
    with pytest.warns(Warning, match="temperature all 0"), open_px4_log(log, TOPICS) as flight:
        assert flight.instances == () and dict(flight.parameters) == {}
