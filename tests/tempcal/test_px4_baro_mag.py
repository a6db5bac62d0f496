"""PX4 barometer and magnetometer thermal calibration (issue 28, item 3).

A ULog built here (:mod:`ulog_writer`) with a gyro, a barometer whose pressure drifts with
temperature (a 5th-order curve in Pa on top of the weather's 101 325 Pa) and a
magnetometer with cubic offsets in gauss: ``thermocal px4-tempcal`` writes ``TC_B0_*``
(X0…X5) and ``TC_M0_*`` (X0_i…X3_i), judged on held-out bins; PX4's correction
(``offset = Σ X_k·(clamp(T, TMIN, TMAX) − TREF)^k`` subtracted, written out here from the
parameter reference) removes ≥ 95 % of the simulated thermal drift of every axis."""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path

import numpy as np

from thermocal.cli import main
from ulog_writer import SENSOR_FIELDS, ulog_bytes

BARO = [("uint64_t", "timestamp"), ("uint32_t", "device_id"), ("float", "pressure"),
        ("float", "temperature")]  # fmt: skip
"""PX4 ``msg/SensorBaro.msg`` (the fields read)."""


def test_baro_and_mag_parameters(tmp_path: Path) -> None:
    rng = np.random.default_rng(8)
    n = 12000
    t = np.arange(n) * 0.1
    temp = -5.0 + 55.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 25.0
    baro_bias = 40.0 * x + 12.0 * x**2 - 9.0 * x**3 + 4.0 * x**5  # [Pa]
    pressure = 101325.0 + baro_bias + rng.normal(0.0, 1.0, n)
    mag_bias = np.column_stack([0.01 * x, -0.006 * x + 0.004 * x**3, 0.008 * x**2])  # [gauss]
    mag = np.array([0.2, 0.05, -0.4]) + mag_bias + rng.normal(0.0, 5e-4, (n, 3))
    ts = (1e6 + t * 1e6).astype(np.int64)
    gyro = [
        (int(s), 11, *rng.normal(0, 1e-3, 3), float(tt)) for s, tt in zip(ts, temp, strict=True)
    ]
    baro = [(int(s), 22, float(p), float(tt)) for s, p, tt in zip(ts, pressure, temp, strict=True)]
    mags = [(int(s), 33, *map(float, m), float(tt)) for s, m, tt in zip(ts, mag, temp, strict=True)]
    log = tmp_path / "bench.ulg"
    log.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, gyro),
                                ("sensor_baro", 0, BARO, baro),
                                ("sensor_mag", 0, SENSOR_FIELDS, mags)]))  # fmt: skip
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["px4-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, buf.getvalue()
    out = json.loads(buf.getvalue())
    for key, unit in (("sensor_baro.0", "Pa"), ("sensor_mag.0", "gauss")):
        s = out["sensors"][key]
        assert s["holdout_rms_unit"] == unit
        assert s["adequacy"]["verdict"] == "pass"
        assert all(math.isfinite(v) for v in s["holdout_rms"].values())
    assert out["sensors"]["sensor_baro.0"]["holdout_rms"]["pressure"] < 1.0  # [Pa]
    p: dict[str, float] = {}
    for line in (tmp_path / "out" / "px4.params").read_text().splitlines():
        if not line.startswith("#"):
            _v, _c, name, value, _t = line.split("\t")
            p[name] = float(value)
    assert p["TC_B_ENABLE"] == 1 and p["TC_M_ENABLE"] == 1
    assert p["TC_B0_ID"] == 22 and p["TC_M0_ID"] == 33
    t32 = temp.astype(np.float32).astype(np.float64)

    def offset(prefix: str, suffix: str, order: int) -> np.ndarray:
        dt = np.clip(t32, p[prefix + "TMIN"], p[prefix + "TMAX"]) - p[prefix + "TREF"]
        return sum(p[f"{prefix}X{k}{suffix}"] * dt**k for k in range(order + 1))

    def removed(corr: np.ndarray, truth: np.ndarray) -> float:
        err = (corr - corr.mean()) - (truth - truth.mean())
        return 100.0 * (1.0 - float(np.sqrt(np.mean(err**2))) / float(np.std(truth)))

    assert removed(offset("TC_B0_", "", 5), baro_bias) >= 95.0
    for i in range(3):
        assert removed(offset("TC_M0_", f"_{i}", 3), mag_bias[:, i]) >= 95.0, i
