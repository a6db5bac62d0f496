"""px4-tempcal's accelerometer cubic against PX4's TemperatureCompensation equation evaluated
here with numpy (kills a mutant of ``benchmarks/mutation_check.py``, ``fw-*``)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np


def test_px4_tempcal_accel_cubic_removes_the_drift(tmp_path: Path) -> None:
    """PX4 (TemperatureCompensation, parameter reference TC_A0_X0…X3): the firmware
    subtracts ``Σ X_k·(clamp(T, TMIN, TMAX) − TREF)^k``; accelerometer offsets relative
    (gravity in the data).  Applied here to the simulated drift: ≥ 95 % removed."""
    from thermocal.cli import main
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    rng = np.random.default_rng(3)
    n = 12000
    t = np.arange(n) * 0.1
    temp = -5.0 + 55.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 25.0
    drift = np.column_stack([0.05 * x + 0.02 * x**3, -0.03 * x + 0.01 * x**2, 0.04 * x**2])
    acc = np.array([0.1, -0.2, 9.81]) + drift + rng.normal(0.0, 2e-3, (n, 3))
    gyro = rng.normal(0.0, 1e-3, (n, 3))
    ts = (1e6 + t * 1e6).astype(np.int64)
    rows = lambda dev, v: [  # noqa: E731
        (int(s), dev, *map(float, r), float(c)) for s, r, c in zip(ts, v, temp, strict=True)
    ]
    log = tmp_path / "bench.ulg"
    log.write_bytes(
        ulog_bytes(
            [
                ("sensor_gyro", 0, SENSOR_FIELDS, rows(11, gyro)),
                ("sensor_accel", 0, SENSOR_FIELDS, rows(12, acc)),
            ]
        )
    )
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["px4-tempcal", str(log), "-o", str(tmp_path / "out")]) == 0
    p = {}
    for line in (tmp_path / "out" / "px4.params").read_text().splitlines():
        if not line.startswith("#"):
            _v, _c, name, value, _t = line.split("\t")
            p[name] = float(value)
    t32 = temp.astype(np.float32).astype(np.float64)
    dt = np.clip(t32, p["TC_A0_TMIN"], p["TC_A0_TMAX"]) - p["TC_A0_TREF"]
    for i in range(3):
        offset = sum(p[f"TC_A0_X{k}_{i}"] * dt**k for k in range(4))
        corrected = drift[:, i] - offset
        left = float(np.std(corrected - corrected.mean()))
        assert left <= 0.05 * float(np.std(drift[:, i])), (i, left)
