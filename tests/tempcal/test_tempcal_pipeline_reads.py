"""``px4-tempcal`` reads its log once (issue 28, item 4): a log of two IMUs (four topic
instances) written from the ULog format description is parsed by pyulog exactly once, and
the calibration is the one a separate read of every topic gives."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from thermocal.cli import main
from ulog_writer import SENSOR_FIELDS, ulog_bytes

G0 = 9.80665


def _two_imu_log(path: Path) -> None:
    n = 3000
    t = np.arange(n) * 0.2
    T = -10.0 + 50.0 * t / t[-1]
    x = (T - 15.0) / 25.0
    rng = np.random.default_rng(1)
    topics: list[Any] = []
    for inst in (0, 1):
        g = np.column_stack([0.002 * x, 0.001 * x**2, -0.001 * x]) + rng.normal(0, 1e-4, (n, 3))
        a = np.column_stack([0.05 * x, -0.02 * x, -G0 + 0.03 * x**2])
        a += rng.normal(0, 2e-3, (n, 3))
        for name, v, dev in (("sensor_gyro", g, 100 + inst), ("sensor_accel", a, 200 + inst)):
            rows = [(int(1e6 + ti * 1e6), dev, *map(float, r), float(tt))
                    for ti, r, tt in zip(t, v, T, strict=True)]  # fmt: skip
            topics.append((name, inst, SENSOR_FIELDS, rows))
    path.write_bytes(ulog_bytes(topics))


def test_px4_tempcal_parses_the_log_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import pyulog

    log = tmp_path / "two_imus.ulg"
    _two_imu_log(log)
    parses: list[Any] = []
    real = pyulog.ULog

    def counting(*args: Any, **kwargs: Any) -> Any:
        parses.append(kwargs.get("message_name_filter_list"))
        return real(*args, **kwargs)

    monkeypatch.setattr(pyulog, "ULog", counting)
    assert main(["px4-tempcal", str(log), "-o", str(tmp_path / "out")]) == 0, (
        capsys.readouterr().err
    )
    assert len(parses) == 1, parses  # before: 1 listing + 1 per instance = 5
    params = (tmp_path / "out" / "px4.params").read_text()
    for pre in ("TC_G0", "TC_G1", "TC_A0", "TC_A1"):
        assert f"{pre}_X1_0" in params
    # the one parse gives what a read of each topic alone gives: gyro 1's x slope is
    # 0.002 rad/s per 25 °C (the log's float32 noise aside)
    line = next(ln for ln in params.splitlines() if "\tTC_G1_X1_0\t" in ln)
    assert math.isclose(float(line.split("\t")[3]), 0.002 / 25.0, rel_tol=0.02)
