"""ArduPilot log hygiene (issue 28, item 4): a log recorded with active ``INS_TCAL1_*``
coefficients on a board mounted ``AHRS_ORIENTATION`` 10 (ROLL_180_YAW_90) gives the same
parameters as the raw log of the same sensor.  The recorded log is made here as the firmware
makes it (AP_InertialSensor_tempcal.cpp ``correct_sensor``: ``v −= poly(clamp(T) − 35) −
poly(clamp(T_cal) − 35)``, then the board rotation; ROLL_180_YAW_90 maps (x, y, z) to
(y, x, −z), AP_Math/rotations.cpp), with the ``PARM`` messages that say so."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log, parm
from fc_logs import imu_truth, parm_file

OLD = {"ACC": [[800.0, -300.0, 150.0], [20.0, 5.0, -8.0], [0.4, -0.2, 0.1]],
       "GYR": [[60.0, -40.0, 25.0], [1.5, -0.7, 0.9], [0.03, 0.02, -0.01]]}  # fmt: skip
"""The coefficients active when the log was recorded (c_k per axis, as stored ×1e6)."""
TMIN, TMAX, CALTEMP = 0.0, 45.0, 22.0


def poly(c: np.ndarray, t: np.ndarray) -> np.ndarray:
    return (c[0] + (c[1] + c[2] * t) * t) * t * 1e-6


def recorded(raw: np.ndarray, temp: np.ndarray, tag: str) -> np.ndarray:
    c = np.asarray(OLD[tag], dtype=np.float32).astype(np.float64)[:, None, :]
    tt = np.clip(temp, TMIN, TMAX)[:, None] - 35.0
    corr = poly(c, tt) - poly(c, np.array([[CALTEMP - 35.0]]))
    v = raw - corr
    return np.column_stack([v[:, 1], v[:, 0], -v[:, 2]])  # ROLL_180_YAW_90


def build(m: dict[str, np.ndarray], *, as_recorded: bool) -> bytes:
    g, a = m["gyro_meas"], m["accel_meas"]
    if as_recorded:
        g = recorded(g, m["temp"].astype(np.float32).astype(np.float64), "GYR")
        a = recorded(a, m["temp"].astype(np.float32).astype(np.float64), "ACC")
    msgs: list = []
    if as_recorded:
        msgs += [parm("AHRS_ORIENTATION", 10), parm("INS_TCAL1_ENABLE", 1),
                 parm("INS_TCAL1_TMIN", TMIN), parm("INS_TCAL1_TMAX", TMAX),
                 parm("INS_ACC1_CALTEMP", CALTEMP), parm("INS_GYR1_CALTEMP", CALTEMP)]  # fmt: skip
        for tag, c in OLD.items():
            for k in range(3):
                for j, ax in enumerate("XYZ"):
                    msgs.append(parm(f"INS_TCAL1_{tag}{k + 1}_{ax}", c[k][j]))
    for i in range(m["temp"].size):
        msgs.append((100, (int(m["time_us"][i]), 0, *g[i], *a[i], 0, 0, float(m["temp"][i]),
                           1, 1, 1000, 1000)))  # fmt: skip
    return dataflash_log([PARM_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs)


def test_recorded_with_coefficients_and_rotation_gives_the_raw_parameters(tmp_path: Path) -> None:
    m = imu_truth(12000, 9, 1.0)
    results = {}
    for name, rec in (("raw", False), ("recorded", True)):
        log = tmp_path / f"{name}.bin"
        log.write_bytes(build(m, as_recorded=rec))
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
            from thermocal.cli import main

            code = main(["ardupilot-tempcal", str(log), "-o", str(tmp_path / name), "--json"])
        assert code == 0, buf.getvalue()
        results[name] = (parm_file(tmp_path / name / "ardupilot.parm"), json.loads(buf.getvalue()))
    raw, rec = results["raw"][0], results["recorded"][0]
    assert raw.keys() == rec.keys()
    for k, v in raw.items():  # the log stores float32: agreement to its precision
        assert rec[k] == pytest.approx(v, rel=2e-3, abs=0.05), k
    hyg = results["recorded"][1]["log_hygiene"]
    assert hyg["AHRS_ORIENTATION"] == 10 and hyg["rotated_back_to_sensor_frame"]
    imu = hyg["imus"]["IMU.0"]
    assert imu["active_tcal_removed"] and imu["caltemp_c"]["accel"] == pytest.approx(CALTEMP)
    assert imu["coefficients"]["INS_TCAL1_GYR1_X"]["old"] == pytest.approx(60.0)
    assert imu["coefficients"]["INS_TCAL1_GYR1_X"]["new"] == pytest.approx(raw["INS_TCAL1_GYR1_X"])
    assert not results["raw"][1]["log_hygiene"]["imus"]["IMU.0"]["active_tcal_removed"]
