"""Write the two flight-controller logs the gallery draws its tempcal figures from.

* ``bench.ulg`` (PX4 ULog): a gyro, a barometer whose pressure drifts as a 5th-order
  polynomial in temperature [Pa] and a magnetometer with cubic offsets [gauss], swept from
  −5 to +50 °C, recorded with an older calibration active (``TC_G1_*`` for this gyro,
  ``TC_B0_*``): ``px4-tempcal`` writes the barometer's and magnetometer's reports
  (``offset-residual``, ``offset-holdout``) and the comparison with the old parameters
  (``previous-figure``).
* ``baro.bin`` (ArduPilot DataFlash): an IMU and a barometer whose pressure drops as
  ``max(T − 25 °C, 0)^1.35`` Pa, the drift ArduPilot's barometer correction adds back:
  ``ardupilot-tempcal`` writes its barometer report (``ardupilot-baro-residual``,
  ``ardupilot-baro-holdout``).

Deterministic (NumPy's PCG64, seed 41): rerunning it rewrites the same bytes, which the test
suite checks.  The file writers are the test suite's own (``tests/ulog_writer.py``, from the
ULog format description at docs.px4.io; ``tests/dataflash_writer.py``, from ArduPilot's
LogStructure.h), so the logs are not made by the library that reads them.

Run from the repository's root: ``python docs/_ext/gallery_data/make_gallery_logs.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "tests"))

from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log  # noqa: E402
from ulog_writer import SENSOR_FIELDS, ulog_bytes  # noqa: E402

N = 2500
"""Samples of each sensor: 10 Hz, 250 s."""
G0 = 9.80665
BARO_FIELDS = [("uint64_t", "timestamp"), ("uint32_t", "device_id"), ("float", "pressure"),
               ("float", "temperature")]  # fmt: skip
"""PX4 ``msg/SensorBaro.msg`` (the fields read)."""
OLD_G = {
    "TMIN": 0.0, "TMAX": 45.0, "TREF": 25.0,
    **{f"X{k}_{i}": 1e-3 * (i + 1) * (-0.1) ** k for k in range(4) for i in range(3)},
}  # fmt: skip
OLD_B = {"TMIN": 5.0, "TMAX": 40.0, "TREF": 20.0, "X0": -5.0, "X1": 1.2, "X2": 0.01,
         "X3": 0.0, "X4": 0.0, "X5": 0.0}  # fmt: skip
OLD = (
    {"TC_G_ENABLE": 1, "TC_G1_ID": 11, "TC_B_ENABLE": 1, "TC_B0_ID": 22}
    | {f"TC_G1_{k}": v for k, v in OLD_G.items()}
    | {f"TC_B0_{k}": v for k, v in OLD_B.items()}
)
"""The calibration active when the PX4 log was recorded (the gyro's at index 1)."""
BARO_TYPE = 101
BARO_FORMAT = (BARO_TYPE, "BARO", "QBfffcfIffB", ("TimeUS", "I", "Alt", "AltAMSL", "Press",
                                                  "Temp", "CRt", "SMS", "Offset", "GndTemp",
                                                  "H"))  # fmt: skip
"""LogStructure.h ``BARO``: ``Temp`` an int16 of centi-degrees ('c')."""


def ulog() -> bytes:
    rng = np.random.default_rng(41)
    t = np.arange(N) * 0.1
    temp = -5.0 + 55.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 25.0
    pressure = 101325.0 + 40.0 * x + 12.0 * x**2 - 9.0 * x**3 + 4.0 * x**5 + rng.normal(0, 1, N)
    mag = np.array([0.2, 0.05, -0.4]) + np.column_stack(
        [0.01 * x, -0.006 * x + 0.004 * x**3, 0.008 * x**2]
    ) + rng.normal(0.0, 5e-4, (N, 3))  # fmt: skip
    ts = (1e6 + t * 1e6).astype(np.int64)
    gyro_bias = np.column_stack([0.002 + 0.004 * x, -0.003 * x, 0.006 * x**2])
    gyro = gyro_bias + rng.normal(0.0, 1e-3, (N, 3))
    rows_g = [
        (int(s), 11, *map(float, g), float(T)) for s, g, T in zip(ts, gyro, temp, strict=True)
    ]
    rows_b = [(int(s), 22, float(p), float(T)) for s, p, T in zip(ts, pressure, temp, strict=True)]
    rows_m = [(int(s), 33, *map(float, m), float(T)) for s, m, T in zip(ts, mag, temp, strict=True)]
    return ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, rows_g),
                       ("sensor_baro", 0, BARO_FIELDS, rows_b),
                       ("sensor_mag", 0, SENSOR_FIELDS, rows_m)], OLD)  # fmt: skip


def dataflash() -> bytes:
    rng = np.random.default_rng(42)
    t = np.arange(N) * 0.1
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 30.0
    gyro = np.column_stack([0.002 + 0.004 * x - 0.001 * x**2, -0.003 * x, 0.006 * x**2])
    accel = np.column_stack([0.05 + 0.08 * x, -0.06 * x + 0.04 * x**3, -G0 + 0.1 * x])
    gyro = gyro + rng.normal(0.0, 0.001, (N, 3))
    accel = accel + rng.normal(0.0, 0.02, (N, 3))
    temp_c100 = np.round(temp * 100.0)
    press = 101325.0 - np.maximum(temp_c100 / 100.0 - 25.0, 0.0) ** 1.35
    press = press + rng.normal(0.0, 0.5, N)
    time_us = (1_000_000 + t * 1e6).astype(np.int64)
    msgs: list[tuple[int, tuple[float | bytes, ...]]] = []
    for i in range(N):
        msgs.append((100, (int(time_us[i]), 0, *map(float, gyro[i]), *map(float, accel[i]),
                           0, 0, float(temp[i]), 1, 1, 1000, 1000)))  # fmt: skip
        msgs.append((BARO_TYPE, (int(time_us[i]) + 10, 0, 0.0, 0.0, float(press[i]),
                                 int(temp_c100[i]), 0.0, 0, 0.0, 20.0, 1)))  # fmt: skip
    fmts = [PARM_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS), BARO_FORMAT]
    return dataflash_log(fmts, msgs)


if __name__ == "__main__":
    (HERE / "bench.ulg").write_bytes(ulog())
    (HERE / "baro.bin").write_bytes(dataflash())
