"""What ``station check`` found, as data and as lines (:class:`thermocal.station.check.
StationCheck`): NaN and empty texts become None in the JSON; a sensor's rate is shown to a
tenth of a hertz, a silent one with its error."""

from __future__ import annotations

import json
import math

from thermocal.station.check import SensorCheck, StationCheck


def _check() -> StationCheck:
    good = SensorCheck("imu", "/dev/ttyUSB0", True, 99.96, 20, 1, "1,2,3", "")
    silent = SensorCheck("baro", "/dev/ttyUSB1", False, math.nan, 0, 0, "", "no data")
    return StationCheck("modbus", True, "", 25.5, math.nan, (good, silent))


def test_to_dict_turns_nan_and_empty_into_none() -> None:
    d = _check().to_dict()
    assert d["chamber"] == {"driver": "modbus", "ok": True, "temperature_c": 25.5,
                            "setpoint_c": None, "error": None}  # fmt: skip
    assert d["sensors"][0]["rate_hz"] == 99.96 and d["sensors"][0]["error"] is None
    assert d["sensors"][1]["rate_hz"] is None and d["sensors"][1]["first_line"] is None
    json.dumps(d, allow_nan=False)  # no NaN left


def test_text_one_line_each() -> None:
    assert _check().text() == [
        "chamber modbus: temperature 25.5 °C, set-point not reported",
        "sensor imu (/dev/ttyUSB0): 100.0 Hz, 20 lines (1 bad), first: 1,2,3",
        "sensor baro (/dev/ttyUSB1): NO ANSWER: no data",
    ]
    assert _check().failed == ["sensor baro (no data)"]
