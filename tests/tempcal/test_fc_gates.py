"""Gates the firmware communities asked for, each named in a ``warning:`` (issue 28, item 5):
a sweep that stops rising (ArduPilot's learning ends after 600 s without a 0.5 °C rise), a
sensor without a thermometer, a step-like bias on one instance of a multi-IMU board, and a
reference temperature too close to the calibration's end.  Logs built with the format
writers; the command still succeeds (warned, not refused)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np
import pytest

from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, dataflash_log
from thermocal.cli import main
from thermocal.tempcal.pipeline import sweep_stall
from ulog_writer import SENSOR_FIELDS, ulog_bytes


def board(n: int, dt: float, rise_share: float, *, step_on: int | None) -> bytes:
    """Three IMUs in today's layout: the temperature rises −5 → 45 °C over ``rise_share`` of
    the log then holds; IMU 2 has no thermometer (T = 0); ``step_on``: that IMU's gyro x
    jumps by 0.02 rad/s (1.1 °/s) half-way through."""
    rng = np.random.default_rng(2)
    t = np.arange(n) * dt
    k = int(rise_share * n)
    temp = np.r_[np.linspace(-5.0, 45.0, k), np.full(n - k, 45.0)]
    msgs = []
    g = 0.002 * (temp - 20.0)[:, None] / 25.0 + rng.normal(0, 5e-4, (3, n, 3))
    if step_on is not None:
        g[step_on, n // 2 :, 0] += 0.02
    for i in range(n):
        for imu in range(3):
            tt = float(temp[i]) if imu < 2 else 0.0
            msgs.append((100, (int(1e6 + t[i] * 1e6), imu, *g[imu, i], 0.0, 0.0, -9.8, 0, 0, tt,
                               1, 1, 1000, 1000)))  # fmt: skip
    return dataflash_log([(100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs)


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    with contextlib.redirect_stdout(io.StringIO()):
        code = main(args)
    return code, capsys.readouterr().err


def test_sweep_stall_figures() -> None:
    t = np.arange(0.0, 2000.0, 1.0)
    temp = np.minimum(20.0 + 0.05 * t, 50.0)  # reaches 50 °C at 600 s, then 1400 s flat
    gap, at_c, start = sweep_stall(t, temp)
    assert gap == pytest.approx(1999.0 - 600.0)  # the last 0.5 °C step (50 °C) entered at 600 s
    assert at_c == pytest.approx(50.0) and start == pytest.approx(600.0)


def test_board_gates_are_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = tmp_path / "board.bin"
    log.write_bytes(board(8000, 0.2, 0.5, step_on=1))  # 1600 s: 800 s rising, 800 s flat
    code, err = run(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")], capsys)
    assert code == 0, err
    lines = [ln for ln in err.splitlines() if ln.startswith("warning:")]
    assert any("IMU.0: the temperature sweep stops rising" in ln for ln in lines), err
    assert any("IMU.2 left out" in ln and "without a thermometer" in ln for ln in lines), err
    steps = [ln for ln in lines if "step-like bias" in ln]
    assert len(steps) == 1 and "IMU.Gyr.1" in steps[0], err


def test_a_clean_board_has_no_gate(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = tmp_path / "clean.bin"
    log.write_bytes(board(8000, 0.1, 0.98, step_on=None))
    code, err = run(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")], capsys)
    assert code == 0, err
    assert "stops rising" not in err and "step-like" not in err
    assert "IMU.2 left out" in err  # the third IMU still has no thermometer


def test_tref_too_close_to_the_end(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    n = 6000
    temp = np.linspace(0.0, 40.0, n)
    rng = np.random.default_rng(1)
    rows = [(int(1e6 + i * 0.1e6), 7, *(1e-4 * temp[i] + rng.normal(0, 1e-4, 3)), float(temp[i]))
            for i in range(n)]  # fmt: skip
    log = tmp_path / "g.ulg"
    log.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, rows)]))
    code, err = run(["px4-tempcal", str(log), "-o", str(tmp_path / "a"), "--tref", "39"], capsys)
    assert code == 0, err
    assert "TREF 39.0 °C is too close to the calibration's end" in err
    code, err = run(["px4-tempcal", str(log), "-o", str(tmp_path / "b"), "--tref", "20"], capsys)
    assert code == 0 and "too close" not in err
