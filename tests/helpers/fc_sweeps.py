"""What the flight-controller calibration tests share: one IMU's gyro and accelerometer over
a −10…50 °C sweep with thermal biases and white noise, written as a PX4 ULog or an ArduPilot
DataFlash log; a command run with ``--json`` read back; Allan deviation calls counted."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

G0 = 9.80665


def sweep(n: int, dt_s: float, seed: int) -> tuple[np.ndarray, ...]:
    """(time [s], temperature [°C], gyro (n, 3) [rad/s], accel (n, 3) [m/s²]): a half-cosine
    sweep −10…50 °C, biases in x = (T − 20)/30, white noise 1e-4 rad/s and 2e-3 m/s²."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt_s
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 30.0
    g = np.column_stack([0.002 + 0.004 * x, -0.003 * x, 0.006 * x**2])  # [rad/s]
    a = np.column_stack([0.05 + 0.08 * x, -0.06 * x, -G0 + 0.1 * x])  # [m/s²]
    g, a = g + rng.normal(0, 1e-4, (n, 3)), a + rng.normal(0, 2e-3, (n, 3))
    return t, temp, g, a


def px4_sweep_log(path: Path, n: int, dt_s: float, seed: int) -> Path:
    """:func:`sweep` as a PX4 ULog (``sensor_gyro`` and ``sensor_accel`` instance 0)."""
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    t, temp, g, a = sweep(n, dt_s, seed)
    ts = (1e6 + t * 1e6).astype(np.int64)
    rows_g = [(int(s), 7, *map(float, v), float(T)) for s, v, T in zip(ts, g, temp, strict=True)]
    rows_a = [(int(s), 8, *map(float, v), float(T)) for s, v, T in zip(ts, a, temp, strict=True)]
    path.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, rows_g),
                                 ("sensor_accel", 0, SENSOR_FIELDS, rows_a)]))  # fmt: skip
    return path


def ardupilot_sweep_log(path: Path, n: int, dt_s: float, seed: int) -> Path:
    """:func:`sweep` as an ArduPilot DataFlash log (today's ``IMU`` message, instance 0)."""
    from dataflash_writer import imu_log

    t, temp, g, a = sweep(n, dt_s, seed)
    rows = [
        (int(1e6 + ti * 1e6), 0, *map(float, gg), *map(float, aa), 0, 0, float(tt))
        for ti, gg, aa, tt in zip(t, g, a, temp, strict=True)
    ]
    path.write_bytes(imu_log(rows))
    return path


def run_json(
    command: str, log: Path, out: Path, capsys: pytest.CaptureFixture[str], *extra: str
) -> dict[str, Any]:
    """``thermocal COMMAND LOG -o OUT --json EXTRA…``: exit 0 asserted, the JSON read back."""
    from thermocal.cli import main

    code = main([command, str(log), "-o", str(out), "--json", *extra])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    result: dict[str, Any] = json.loads(captured.out)
    return result


def count_allan_calls(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """The calibration report's Allan deviations counted: one entry per call."""
    import thermocal.report.calibration as calibration_report

    calls: list[int] = []
    real = calibration_report.allan_of

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(calibration_report, "allan_of", counted)
    return calls
