"""ArduPilot logs in, ArduPilot parameters out (issue 16).

A DataFlash log built here (:mod:`dataflash_writer`: FMT + IMU messages) reads back with the
values and units written; ``thermocal ardupilot-tempcal`` fits a −10…50 °C sweep, and
ArduPilot's correction — ``poly(clamp(T) − 35) − poly(T_cal − 35)`` with
``poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6``, from AP_InertialSensor_tempcal.cpp, written out
here — applied to the truth removes ≥ 95 % of every axis's temperature-induced bias."""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest

from dataflash_writer import imu_log
from thermocal.cli import main
from thermocal.readers.dispatch import read_recording
from thermocal.readers.options import ReadOptions

G0 = 9.80665


def _sweep(n: int = 20000, seed: int = 5) -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.03
    T = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (T - 20.0) / 30.0
    gyro = np.column_stack([0.002 + 0.004 * x - 0.001 * x**2, -0.003 * x, 0.006 * x**2])
    accel = np.column_stack([0.05 + 0.08 * x, -0.06 * x + 0.04 * x**3, -G0 + 0.1 * x])
    g = gyro + rng.normal(0.0, 0.001, (n, 3))
    a = accel + rng.normal(0.0, 0.02, (n, 3))
    a[rng.integers(0, n, 40)] += 3.0  # spikes
    rows = [
        (int(1e6 + ti * 1e6), 0, *map(float, gg), *map(float, aa), 0, 0, float(tt))
        for ti, gg, aa, tt in zip(t, g, a, T, strict=True)
    ]
    return T, gyro, accel, rows


def test_dataflash_reads_back_values_and_units(tmp_path: Path) -> None:
    rows = [(1_000_000 + i * 20_000, i % 2, 0.001 * i, 0.0, -0.002, 0.1, 0.2, -9.81, 0, 0,
             30.0 + 0.05 * i) for i in range(60)]  # fmt: skip
    path = tmp_path / "imu.bin"
    path.write_bytes(imu_log(rows))
    rec = read_recording(
        path, ReadOptions(signals=["GyrX", "AccZ"], temperatures=["T"], topic="IMU.1")
    )
    mine = [r for r in rows if r[1] == 1]
    np.testing.assert_allclose(rec.time_s, [r[0] * 1e-6 for r in mine], rtol=0, atol=1e-9)
    np.testing.assert_allclose(rec.column("GyrX"), [r[2] for r in mine], rtol=1e-6)
    assert rec.units["GyrX"] == "rad/s" and rec.units["AccZ"] == "m/s^2"
    assert rec.units["T"] == "degC"
    np.testing.assert_allclose(rec.column("T"), [r[10] for r in mine], rtol=1e-6)
    with pytest.raises(Exception, match="no IMU messages of instance 2"):
        read_recording(path, ReadOptions(signals=["GyrX"], temperatures=["T"], topic="IMU.2"))


def test_ardupilot_correction_removes_95_percent(tmp_path: Path) -> None:
    T, gyro, accel, rows = _sweep()
    log = tmp_path / "sweep.bin"
    log.write_bytes(imu_log(rows))
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, buf.getvalue()
    summary = json.loads(buf.getvalue())
    assert set(summary["sensors"]) == {"IMU.Gyr.0", "IMU.Acc.0"}
    p = {}
    for line in (tmp_path / "out" / "ardupilot.parm").read_text().splitlines():
        if not line.startswith("#"):
            name, value = line.split()
            p[name] = float(value)
    assert p["INS_TCAL1_ENABLE"] == 1
    Tc = np.clip(T.astype(np.float32).astype(np.float64), p["INS_TCAL1_TMIN"],
                 p["INS_TCAL1_TMAX"])  # fmt: skip

    def poly(c: list[float], t: np.ndarray | float) -> np.ndarray:
        return np.asarray((c[0] + (c[1] + c[2] * t) * t) * t * 1e-6)

    for tag, truth in (("GYR", gyro), ("ACC", accel)):
        for i, ax in enumerate("XYZ"):
            c = [p[f"INS_TCAL1_{tag}{k}_{ax}"] for k in (1, 2, 3)]
            corr = poly(c, Tc - 35.0) - poly(c, 20.0 - 35.0)  # calibrated at 20 °C
            err = (corr - corr.mean()) - (truth[:, i] - truth[:, i].mean())
            removed = 100.0 * (1.0 - math.sqrt(float(np.mean(err**2))) / float(np.std(truth[:, i])))
            assert removed >= 95.0, (tag, ax, removed)
