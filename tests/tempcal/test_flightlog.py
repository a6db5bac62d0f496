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


def _dataflash_sweep(path: Path) -> dict[str, Any]:
    """An ArduPilot log of one IMU over a −10…50 °C sweep (x gyro = 1e-4 rad/s per °C about
    20 °C, z accel = −g + 2e-3 m/s² per °C), the parameters the recording started with and one
    changed half-way (``LOG_BITMASK`` 1 → 2)."""
    from dataflash_writer import IMU_FMT, IMU_LABELS, PARM_FORMAT, dataflash_log, parm

    rng = np.random.default_rng(7)
    n = 12000
    t = np.arange(n) * 0.05
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    gx = 1e-4 * (temp - 20.0) + rng.normal(0.0, 2e-4, n)
    az = -9.80665 + 2e-3 * (temp - 20.0) + rng.normal(0.0, 5e-3, n)
    imu = [(100, (int(1e6 + ti * 1e6), 0, float(g), 0.0, 0.0, 0.0, 0.0, float(a), 0, 0,
                  float(tt))) for ti, g, a, tt in zip(t, gx, az, temp, strict=True)]  # fmt: skip
    msgs = [parm("LOG_BITMASK", 1.0, 500), parm("INS_TCAL1_ENABLE", 0.0, 500)]
    half = n // 2
    msgs += [*imu[:half], parm("LOG_BITMASK", 2.0, int(1e6 + t[half] * 1e6)), *imu[half:]]
    path.write_bytes(dataflash_log([(100, "IMU", IMU_FMT, IMU_LABELS), PARM_FORMAT], msgs))
    return {"t": t, "temp": temp, "gx": gx, "change_s": 1.0 + t[n // 2]}


def test_an_ardupilot_log_is_read_once_into_one_object(tmp_path: Path) -> None:
    """read_ardupilot_log: the one pass's tables, parameters and changes are those written."""
    from thermocal.tempcal.flightlog import read_ardupilot_log

    log = tmp_path / "sweep.bin"
    truth = _dataflash_sweep(log)
    flight = read_ardupilot_log(log, ("IMU", "TCLR"))
    df, info = flight.table("IMU", 0)
    np.testing.assert_allclose(df["TimeUS"] * 1e-6, 1.0 + truth["t"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(df["GyrX"], truth["gx"], rtol=1e-6, atol=1e-9)  # float32
    np.testing.assert_allclose(df["T"], truth["temp"], rtol=1e-6)
    assert info["units"]["GyrX"] == "rad/s" and flight.rows("TCLR") == []
    assert dict(flight.parameters) == {"LOG_BITMASK": 1.0, "INS_TCAL1_ENABLE": 0.0}
    [change] = flight.parameter_changes
    assert (change.name, change.old, change.new) == ("LOG_BITMASK", 1.0, 2.0)
    assert change.time_s == pytest.approx(truth["change_s"], abs=1e-6)
    assert flight.parameters_at_end()["LOG_BITMASK"] == 2.0


def test_ardupilot_tempcal_reads_its_log_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The whole command, as a user runs it, opens the DataFlash log once (the fixed-format
    parser or pymavlink's reader, together once), and the gyro's fitted slope is the one
    written."""
    import json

    from pymavlink import DFReader

    from thermocal.cli import main
    from thermocal.readers import dataflash

    log = tmp_path / "sweep.bin"
    _dataflash_sweep(log)
    opened: list[str] = []
    real, real_fast = DFReader.DFReader_binary, dataflash._fast_pass

    def counting(filename: str, *args: Any, **kwargs: Any) -> Any:
        opened.append(filename)
        return real(filename, *args, **kwargs)

    def counting_fast(path: Path, *args: Any, **kwargs: Any) -> Any:
        passed = real_fast(path, *args, **kwargs)
        if passed is not None:  # read: pymavlink is not asked
            opened.append(str(path))
        return passed

    monkeypatch.setattr(DFReader, "DFReader_binary", counting)
    monkeypatch.setattr(dataflash, "_fast_pass", counting_fast)
    code = main(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert opened == [str(log)]
    params = {}
    for line in (tmp_path / "out" / "ardupilot.parm").read_text().splitlines():
        if not line.startswith("#"):
            name, value = line.split()
            params[name] = float(value)
    # the x gyro's slope about 35 °C is c1·1e-6 rad/s per °C: the written 1e-4
    assert params["INS_TCAL1_GYR1_X"] * 1e-6 == pytest.approx(1e-4, rel=0.05)
    assert "IMU.Gyr.0" in json.loads(out.out)["sensors"]
