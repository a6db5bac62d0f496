"""PX4 ``TC_*`` parameters changed during the recording (issue 28, item 2): PX4 logs
``sensor_gyro`` before its temperature compensation (applied downstream in
sensors/vehicle_imu), so the fit is unaffected, but the coefficients compared with the new
ones (``previous``) must be those in force at the end of the log — the initial ``P``
messages updated by the ``P`` messages of the data section (ULog File Format) — and the
output names each change (parameter, old → new, log time)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from test_fc_reports import OLD_G, run_cli
from ulog_writer import SENSOR_FIELDS, ulog_bytes


def test_px4_tc_changed_mid_log_is_compared_at_the_end_and_said(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    n = 9000
    t = np.arange(n) * 0.1
    temp = -5.0 + 55.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 25.0
    gyro = np.column_stack([2e-3 * x, -1e-3 * x**2, 3e-3 * x**3]) + rng.normal(0, 2e-4, (n, 3))
    ts = (1e6 + t * 1e6).astype(np.int64)
    rows = [
        (int(s), 11, *map(float, g), float(tt)) for s, g, tt in zip(ts, gyro, temp, strict=True)
    ]
    params: dict = {"TC_G_ENABLE": 1, "TC_G0_ID": 11, **{f"TC_G0_{k}": v for k, v in OLD_G.items()}}
    log = tmp_path / "bench.ulg"
    log.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, rows)], params,
                               changed=[("TC_G0_X0_0", 0.0125), ("TC_G0_TREF", 25.0)]))  # fmt: skip
    code, text = run_cli(["px4-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, text
    out = json.loads(text)
    prev = out["sensors"]["sensor_gyro.0"]["previous"]["parameters"]
    assert prev["TC_G0_X0_0"]["old"] == pytest.approx(float(np.float32(0.0125)), rel=1e-7)
    assert prev["TC_G0_X0_1"]["old"] == pytest.approx(float(np.float32(OLD_G["X0_1"])), rel=1e-7)
    t_end = float(ts[-1]) * 1e-6  # pyulog times a data-section P by the last data before it
    note = next(s for s in out["notes"] if "changed during the recording" in s)
    assert f"TC_G0_X0_0 0.001 → 0.0125 at log time {t_end:.3f} s" in note
    assert "TC_G0_TREF" not in note  # set again to the same value: no change
    assert "those in force at the end of the log" in note
