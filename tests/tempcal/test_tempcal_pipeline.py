"""The tempcal library without the command line (issue 27): the binning, the hold-out check,
and the PX4 and ArduPilot dialects of the one pipeline called directly."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dataflash_writer import imu_log
from thermocal.firmware.binning import temperature_bins
from thermocal.tempcal.ardupilot import ardupilot_tempcal
from thermocal.tempcal.pipeline import ReportRequest, holdout_rms
from thermocal.tempcal.px4 import px4_tempcal
from ulog_writer import SENSOR_FIELDS, ulog_bytes


def test_temperature_bins_are_medians_of_half_degree_bins() -> None:
    temp = np.array([10.1, 10.2, 10.4, 10.6, 11.9, 11.6, 11.7])
    vals = np.array([[1.0], [5.0], [2.0], [7.0], [3.0], [9.0], [4.0]])
    centres, t_med, v_med = temperature_bins(temp, vals)
    # lo = 10.0: [10, 10.5) → 10.1, 10.2, 10.4; [10.5, 11) → 10.6; [11.5, 12) → the rest
    np.testing.assert_allclose(centres, [10.25, 10.75, 11.75], atol=1e-12)
    np.testing.assert_allclose(t_med, [10.2, 10.6, 11.7], atol=1e-12)
    np.testing.assert_allclose(v_med[:, 0], [2.0, 7.0, 4.0], atol=1e-12)


def test_holdout_is_judged_on_bins_it_was_not_fitted_to() -> None:
    """Even bins on a cubic, odd bins 0.3 above it: a cubic fitted to the even bins alone
    passes through them, so its rms on the odd ones is exactly 0.3; fitted to every bin it
    would split the difference (rms ≈ 0.15).  41 bins: the even ones span the range (the
    model clamps the temperature to the range it was fitted on)."""
    t = np.linspace(-10.0, 50.0, 41)
    cubic = 1.0 + 0.02 * t - 1e-3 * t**2 + 2e-5 * t**3
    v = cubic + np.where(np.arange(t.size) % 2 == 1, 0.3, 0.0)
    assert holdout_rms(t, v, "deg/h", "g0_x") == pytest.approx(0.3, abs=1e-6)


def _sweep(n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.03
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 30.0
    gyro = np.column_stack([0.002 + 0.004 * x, -0.003 * x, 0.006 * x**2])  # [rad/s]
    accel = np.column_stack([0.05 + 0.08 * x, -0.06 * x, -9.80665 + 0.1 * x])  # [m/s²]
    return t, temp, gyro + rng.normal(0, 1e-4, (n, 3)), accel + rng.normal(0, 2e-3, (n, 3))


def test_px4_tempcal_library_call(tmp_path: Path) -> None:
    t, temp, g, a = _sweep(6000, 1)
    ts = (1e6 + t * 1e6).astype(np.int64)
    rows_g = [(int(s), 7, *map(float, v), float(T)) for s, v, T in zip(ts, g, temp, strict=True)]
    rows_a = [(int(s), 8, *map(float, v), float(T)) for s, v, T in zip(ts, a, temp, strict=True)]
    log = tmp_path / "s.ulg"
    log.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, rows_g),
                                ("sensor_accel", 0, SENSOR_FIELDS, rows_a)]))  # fmt: skip
    seen: list[tuple[str, ReportRequest]] = []
    res = px4_tempcal(log, tmp_path / "out", reporter=lambda p, r: seen.append((p.name, r)))
    assert [(f.topic, f.kind, f.device_id) for f in res.fits] == [
        ("sensor_accel", "accel", 8), ("sensor_gyro", "gyro", 7)
    ]  # fmt: skip
    assert [n for n, _r in seen] == ["report_sensor_accel_0.html", "report_sensor_gyro_0.html"]
    assert (tmp_path / "out" / "px4.params").is_file()
    assert res.to_dict()["params"] == str(tmp_path / "out" / "px4.params")
    # the gyro's x bias: 0.002 + 0.004·(T − 20)/30 rad/s; at TREF (mid-range 20 °C) 0.002
    gx = next(ch for ch in res.fits[1].channels if ch.name == "g0_x")
    run_t = np.array([[20.0], [50.0]])
    from thermocal.models.rundata import RunData

    pred = gx.model.predict(RunData(np.arange(2.0), run_t, None, ("temperature",)))
    np.testing.assert_allclose(pred, np.array([0.002, 0.006]) * 180 / np.pi * 3600, rtol=2e-3)


def test_ardupilot_tempcal_library_call_without_reports(tmp_path: Path) -> None:
    t, temp, g, a = _sweep(6000, 2)
    rows = [
        (int(1e6 + ti * 1e6), 0, *map(float, gg), *map(float, aa), 0, 0, float(tt))
        for ti, gg, aa, tt in zip(t, g, a, temp, strict=True)
    ]
    log = tmp_path / "s.bin"
    log.write_bytes(imu_log(rows))
    res = ardupilot_tempcal(log, tmp_path / "out")
    assert [(f.topic, f.instance) for f in res.fits] == [("IMU.Gyr", 0), ("IMU.Acc", 0)]
    assert res.orientation == 0 and res.hygiene["IMU.0"]["active_tcal_removed"] is False
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "ardupilot.parm", "calibration.json"
    ]  # fmt: skip
    assert res.to_dict()["log_hygiene"]["rotated_back_to_sensor_frame"] is False
