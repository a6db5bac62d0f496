"""Flight-controller logs' truth for the tests: one IMU's thermal biases over a sweep, and
the parameter files the firmware commands write, read back as a dict."""

from __future__ import annotations

from pathlib import Path

import numpy as np

G0 = 9.80665


def imu_truth(n: int, seed: int, scale: float) -> dict[str, np.ndarray]:
    """A −10…50 °C sweep and one IMU's thermal biases (rad/s, m/s²) plus noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.05
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 30.0
    gyro = scale * np.column_stack([0.002 + 0.004 * x - 0.001 * x**2, -0.003 * x, 0.006 * x**2])
    accel = np.column_stack(
        [0.05 + 0.08 * x * scale, -0.06 * x + 0.04 * x**3, -G0 + 0.1 * x * scale]
    )
    return {
        "time_us": (1_000_000 + t * 1e6).astype(np.int64),
        "temp": temp,
        "gyro": gyro,
        "accel": accel,
        "gyro_meas": gyro + rng.normal(0.0, 0.001, (n, 3)),
        "accel_meas": accel + rng.normal(0.0, 0.02, (n, 3)),
    }


def parm_file(path: Path) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if line and not line.startswith("#"):
            name, value = line.split()
            out[name] = float(value)
    return out
