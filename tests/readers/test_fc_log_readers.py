"""Flight-controller logs read by message, not by guess (issue 28, item 1).

Every log here is built from the format descriptions (:mod:`dataflash_writer`,
:mod:`ulog_writer`): an ArduPilot log in the older layout (Copter 3.4–3.6: ``IMU``, ``IMU2``
without an instance field, ``Temp``, no unit messages) and the same data in today's layout
(``IMU`` with ``I`` and ``T``) read with the firmware's units and calibrate to the same
parameters, which remove ≥ 90 % of the simulated thermal bias (ArduPilot's correction written
out here); a PX4 ``sensor_combined`` is read in rad/s (its Allan deviation against one
computed here with numpy); a field whose unit nothing states is read as raw values with a
warning, not as °/h."""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest

from dataflash_writer import (
    NEW_IMU_FMT,
    NEW_IMU_LABELS,
    OLD_IMU_FMT,
    OLD_IMU_LABELS,
    dataflash_log,
)
from fc_logs import imu_truth, parm_file
from thermocal.cli import main
from thermocal.errors import UnitWarning
from thermocal.readers.dispatch import read_recording
from thermocal.readers.options import ReadOptions
from ulog_writer import ulog_bytes


def old_layout(imus: list[dict[str, np.ndarray]]) -> bytes:
    formats = [(100 + k, "IMU" if k == 0 else f"IMU{k + 1}", OLD_IMU_FMT, OLD_IMU_LABELS)
               for k in range(len(imus))]  # fmt: skip
    msgs = []
    for i in range(imus[0]["temp"].size):
        for k, m in enumerate(imus):
            msgs.append((100 + k, (int(m["time_us"][i]), *m["gyro_meas"][i], *m["accel_meas"][i],
                                   0, 0, float(m["temp"][i]))))  # fmt: skip
    return dataflash_log(formats, msgs)


def new_layout(imus: list[dict[str, np.ndarray]]) -> bytes:
    msgs = []
    for i in range(imus[0]["temp"].size):
        for k, m in enumerate(imus):
            msgs.append((100, (int(m["time_us"][i]), k, *m["gyro_meas"][i], *m["accel_meas"][i],
                               0, 0, float(m["temp"][i]), 1, 1, 1000, 1000)))  # fmt: skip
    return dataflash_log([(100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs)


def removed_percent(p: dict[str, float], imu: int, truth: dict[str, np.ndarray]) -> list[float]:
    """ArduPilot's correction (AP_InertialSensor_tempcal.cpp: ``v −= poly(clamp(T) − 35) −
    poly(clamp(T_cal) − 35)``, ``poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6``) against the truth,
    as the share of the bias's spread removed, per sensor axis."""
    n = imu + 1
    tc = np.clip(truth["temp"].astype(np.float32).astype(np.float64), p[f"INS_TCAL{n}_TMIN"],
                 p[f"INS_TCAL{n}_TMAX"])  # fmt: skip

    def poly(c: list[float], t: np.ndarray) -> np.ndarray:
        return (c[0] + (c[1] + c[2] * t) * t) * t * 1e-6

    out = []
    for tag, key in (("GYR", "gyro"), ("ACC", "accel")):
        for i, ax in enumerate("XYZ"):
            c = [p[f"INS_TCAL{n}_{tag}{k}_{ax}"] for k in (1, 2, 3)]
            corr = poly(c, tc - 35.0)
            bias = truth[key][:, i]
            err = (corr - corr.mean()) - (bias - bias.mean())
            out.append(100.0 * (1.0 - math.sqrt(float(np.mean(err**2))) / float(np.std(bias))))
    return out


def run(args: list[str]) -> tuple[int, str]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(args)
    return code, buf.getvalue()


@pytest.fixture(scope="module")
def two_imus() -> list[dict[str, np.ndarray]]:
    return [imu_truth(12000, 3, 1.0), imu_truth(12000, 4, -0.7)]


def test_older_layout_reads_with_the_firmware_units(tmp_path: Path, two_imus: list) -> None:
    log = tmp_path / "copter36.bin"
    log.write_bytes(old_layout(two_imus))
    with pytest.warns(UnitWarning, match="EG|ErrG") as said:
        rec = read_recording(
            log, ReadOptions(signals=["GyrX", "AccZ", "ErrG"], temperatures=["Temp"], topic="IMU.1")
        )
    assert len(said) == 1 and "counts" in str(said[0].message)
    assert rec.units["GyrX"] == "rad/s" and rec.units["AccZ"] == "m/s^2"
    assert rec.units["Temp"] == "degC" and rec.units["ErrG"] == "counts"
    m = two_imus[1]
    np.testing.assert_allclose(rec.column("GyrX"), m["gyro_meas"][:, 0].astype(np.float32))
    np.testing.assert_allclose(rec.column("Temp"), m["temp"].astype(np.float32))
    # the canonical conversion of a rad/s bias: 1 rad/s = 180/π·3600 °/h
    np.testing.assert_allclose(
        rec.signal("GyrX")[0], rec.column("GyrX") * 180.0 / math.pi * 3600.0, rtol=1e-12
    )


def test_both_layouts_calibrate_alike(tmp_path: Path, two_imus: list) -> None:
    outs = {}
    for name, build in (("old", old_layout), ("new", new_layout)):
        log = tmp_path / f"{name}.bin"
        log.write_bytes(build(two_imus))
        code, out = run(["ardupilot-tempcal", str(log), "-o", str(tmp_path / name), "--json"])
        assert code == 0, out
        assert set(json.loads(out)["sensors"]) == {
            "IMU.Gyr.0", "IMU.Acc.0", "IMU.Gyr.1", "IMU.Acc.1"
        }  # fmt: skip
        outs[name] = parm_file(tmp_path / name / "ardupilot.parm")
    assert outs["old"].keys() == outs["new"].keys()
    for k, v in outs["old"].items():
        assert v == pytest.approx(outs["new"][k], rel=1e-6, abs=1e-9), k
    for imu in (0, 1):
        removed = removed_percent(outs["old"], imu, two_imus[imu])
        assert min(removed) >= 90.0, (imu, removed)  # noise-limited on the small ones


COMBINED = [("uint64_t", "timestamp"), ("float[3]", "gyro_rad"), ("uint32_t", "gyro_integral_dt"),
            ("int32_t", "accelerometer_timestamp_relative"), ("float[3]", "accelerometer_m_s2"),
            ("uint32_t", "accelerometer_integral_dt")]  # fmt: skip
"""PX4 ``msg/SensorCombined.msg`` (the fields thermocal reads)."""


def overlapping_adev(y: np.ndarray, m: int) -> float:
    """Overlapping Allan deviation of rate samples ``y`` at cluster size ``m`` (IEEE 952)."""
    c = np.cumsum(np.r_[0.0, y])
    means = (c[m:] - c[:-m]) / m
    d = means[m:] - means[:-m]
    return float(np.sqrt(0.5 * np.mean(d**2)))


def test_px4_sensor_combined_is_read_in_rad_per_s(tmp_path: Path) -> None:
    rng = np.random.default_rng(11)
    n, dt = 20000, 0.01
    g = rng.normal(0.0, 2e-3, (n, 3)).astype(np.float32)  # white rate noise [rad/s]
    rows = [(int(1_000_000 + i * dt * 1e6), *g[i], 10000, 0, 0.0, 0.0, -9.8, 10000)
            for i in range(n)]  # fmt: skip
    log = tmp_path / "flight.ulg"
    log.write_bytes(ulog_bytes([("sensor_combined", 0, COMBINED, rows)]))
    code, out = run(["allan", str(log), "--topic", "sensor_combined.0", "--signal",
                     "gyro_rad[0]", "--taus", "0.1,1", "--json"])  # fmt: skip
    assert code == 0, out
    res = json.loads(out)
    assert res["unit"] == "rad/s"
    taus = list(res["tau_s"])
    for tau in (0.1, 1.0):
        want = overlapping_adev(g[:, 0].astype(np.float64), round(tau / dt))
        got = res["adev"][taus.index(pytest.approx(tau))]
        assert got == pytest.approx(want, rel=1e-6), tau
