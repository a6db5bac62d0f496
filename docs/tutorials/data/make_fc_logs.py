"""Write the two flight-controller logs of the tutorial ``fc-params.md``: ``sweep.ulg`` (PX4
ULog: ``sensor_gyro`` and ``sensor_accel``, instance 0) and ``sweep.bin`` (ArduPilot DataFlash:
``IMU`` instance 0), the same board swept from −10 to +50 °C in 50 minutes, still, with
known cubic gyro and accelerometer biases, white noise and a few spikes; and ``heated.ulg``, a
board whose heater holds its IMU at 55 °C (``SENS_EN_THERMAL`` 1, ``SENS_IMU_TEMP`` 55): boot
at 15 °C, the heater's ramp, its overshoot and a 15-minute hold, one sample a second
(``tests/helpers/fc_logs.py``'s ``heated_truth``, seed 7).

Deterministic (NumPy's PCG64, seed 40): rerunning it rewrites the same bytes, which the test
suite checks.  The file writers are the test suite's own (``tests/helpers/ulog_writer.py``,
from the ULog format description at docs.px4.io; ``tests/helpers/dataflash_writer.py``, from
ArduPilot's LogStructure.h), so the logs are not made by the library that reads them.

Run from the repository's root: ``python docs/tutorials/data/make_fc_logs.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "tests" / "helpers"))

from dataflash_writer import imu_log  # noqa: E402
from fc_logs import heated_truth, heated_ulog  # noqa: E402
from ulog_writer import SENSOR_FIELDS, ulog_bytes  # noqa: E402

G0 = 9.80665
N = 3000
"""Samples: one a second, 50 minutes."""
GYRO_ID, ACCEL_ID = 2293768, 2293776
"""PX4 device ids (an ICM-20602 on SPI bus 1, as PX4 numbers it)."""


def truth() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Time [s], temperature [°C] and the true gyro [rad/s] and accelerometer [m/s²] outputs
    (bias only: the board is still, z up, so the accelerometer reads −g on z)."""
    t = np.arange(N, dtype=np.float64)
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 30.0
    gyro = np.column_stack(
        [0.002 + 0.004 * x - 0.001 * x**2 + 0.0005 * x**3, -0.001 + 0.002 * x, 0.003 * x**2]
    )
    accel = np.column_stack([0.05 + 0.08 * x + 0.02 * x**3, -0.03 * x, -G0 + 0.1 * x - 0.03 * x**2])
    return t, temp, gyro, accel


def measured() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The truth with white noise (gyro 0.001 rad/s, accelerometer 0.02 m/s² per sample) and
    5 gyro spikes of 0.2 rad/s on x."""
    rng = np.random.default_rng(40)
    t, temp, gyro, accel = truth()
    g = gyro + rng.normal(0.0, 0.001, gyro.shape)
    a = accel + rng.normal(0.0, 0.02, accel.shape)
    g[rng.integers(0, N, 5), 0] += 0.2
    return t, temp, g, a


def ulog() -> bytes:
    t, temp, g, a = measured()
    ts = (1e6 + t * 1e6).astype(np.int64)
    rows_g = [
        (int(s), GYRO_ID, *map(float, v), float(T)) for s, v, T in zip(ts, g, temp, strict=True)
    ]
    rows_a = [
        (int(s), ACCEL_ID, *map(float, v), float(T)) for s, v, T in zip(ts, a, temp, strict=True)
    ]
    return ulog_bytes(
        [("sensor_gyro", 0, SENSOR_FIELDS, rows_g), ("sensor_accel", 0, SENSOR_FIELDS, rows_a)]
    )


def dataflash() -> bytes:
    t, temp, g, a = measured()
    rows = [
        (int(1e6 + s * 1e6), 0, *map(float, gg), *map(float, aa), 0, 0, float(T))
        for s, gg, aa, T in zip(t, g, a, temp, strict=True)
    ]
    return imu_log(rows)


def heated() -> bytes:
    """The heated board's ULog (PX4's heater parameters in its header)."""
    truth = heated_truth(7, rate_hz=1.0)
    return heated_ulog(truth, {"SENS_EN_THERMAL": 1, "SENS_IMU_TEMP": 55.0})


if __name__ == "__main__":
    (HERE / "heated.ulg").write_bytes(heated())
    (HERE / "sweep.ulg").write_bytes(ulog())
    (HERE / "sweep.bin").write_bytes(dataflash())
