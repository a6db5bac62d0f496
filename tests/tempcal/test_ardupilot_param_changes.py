"""ArduPilot log hygiene when the parameters change during the recording (issue 28, item 2):
the firmware reads ``INS_TCAL1_*``, ``INS_ACC1_CALTEMP`` and ``AHRS_ORIENTATION`` at each
sample (AP_InertialSensor_tempcal.cpp ``correct_sensor``), so a log whose coefficients were
replaced half-way (a ``PARM`` message with a later ``TimeUS``) holds data corrected with the
first set before that time and with the second after it.  Undone per interval, it gives the
parameters of the raw log of the same sensor; the output names each change (parameter,
old → new, log time) and which values were compared.  The recorded log is made here as the
firmware makes it: ``v −= poly(clamp(T, TMIN, TMAX) − 35) − poly(clamp(T_cal) − 35)``,
``poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6``, then ROLL_180_YAW_90: (x, y, z) → (y, x, −z)."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log, parm
from fc_logs import imu_truth, parm_file

SET_A = {
    "TMIN": 0.0, "TMAX": 45.0, "CALTEMP": 22.0,
    "ACC": [[800.0, -300.0, 150.0], [20.0, 5.0, -8.0], [0.4, -0.2, 0.1]],
    "GYR": [[60.0, -40.0, 25.0], [1.5, -0.7, 0.9], [0.03, 0.02, -0.01]],
}  # fmt: skip
"""The coefficients active when the recording started (c_k per axis, stored ×1e6)."""
SET_B = {
    "TMIN": -5.0, "TMAX": 50.0, "CALTEMP": 30.0,
    "ACC": [[-1500.0, 900.0, 400.0], [-30.0, 12.0, 6.0], [1.2, 0.5, -0.6]],
    "GYR": [[-120.0, 80.0, -45.0], [-2.5, 1.1, 0.4], [0.05, -0.04, 0.02]],
}  # fmt: skip
"""The coefficients set half-way through the recording."""


def f32(x: float) -> float:
    return float(np.float32(x))


def corrected(raw: np.ndarray, temp: np.ndarray, tag: str, cal: dict) -> np.ndarray:
    """What the firmware logs for the raw sensor vectors ``raw`` under calibration ``cal``."""
    c = np.asarray(cal[tag], dtype=np.float32).astype(np.float64)
    lo, hi, tc = f32(cal["TMIN"]), f32(cal["TMAX"]), f32(cal["CALTEMP"])

    def poly(t: np.ndarray) -> np.ndarray:
        t = t[:, None]
        return (c[0] + (c[1] + c[2] * t) * t) * t * 1e-6

    corr = poly(np.clip(temp, lo, hi) - 35.0) - poly(np.array([np.clip(tc, lo, hi) - 35.0]))
    v = raw - corr
    return np.column_stack([v[:, 1], v[:, 0], -v[:, 2]])  # ROLL_180_YAW_90


def set_parms(cal: dict, time_us: int) -> list:
    out = [parm("INS_TCAL1_TMIN", cal["TMIN"], time_us),
           parm("INS_TCAL1_TMAX", cal["TMAX"], time_us),
           parm("INS_ACC1_CALTEMP", cal["CALTEMP"], time_us),
           parm("INS_GYR1_CALTEMP", cal["CALTEMP"], time_us)]  # fmt: skip
    for tag in ("ACC", "GYR"):
        for k in range(3):
            for j, ax in enumerate("XYZ"):
                out.append(parm(f"INS_TCAL1_{tag}{k + 1}_{ax}", cal[tag][k][j], time_us))
    return out


def build(m: dict[str, np.ndarray], *, change_at: int | None) -> bytes:
    """The raw log (``change_at`` None: no calibration active, no rotation) or the one recorded
    with SET_A until sample ``change_at`` and SET_B from it on."""
    g, a = m["gyro_meas"], m["accel_meas"]
    temp32 = m["temp"].astype(np.float32).astype(np.float64)
    msgs: list = []
    if change_at is not None:
        first = slice(0, change_at)
        rest = slice(change_at, None)
        g = np.vstack([corrected(g[first], temp32[first], "GYR", SET_A),
                       corrected(g[rest], temp32[rest], "GYR", SET_B)])  # fmt: skip
        a = np.vstack([corrected(a[first], temp32[first], "ACC", SET_A),
                       corrected(a[rest], temp32[rest], "ACC", SET_B)])  # fmt: skip
        msgs += [parm("AHRS_ORIENTATION", 10), parm("INS_TCAL1_ENABLE", 1)]
        msgs += set_parms(SET_A, 1000)
    for i in range(m["temp"].size):
        if i == change_at:  # the PARM messages of the change, at this sample's time
            msgs += set_parms(SET_B, int(m["time_us"][i]))
        msgs.append((100, (int(m["time_us"][i]), 0, *g[i], *a[i], 0, 0, float(m["temp"][i]),
                           1, 1, 1000, 1000)))  # fmt: skip
    return dataflash_log([PARM_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs)


def run_cli(log: Path, out: Path) -> dict:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
        from thermocal.cli import main

        code = main(["ardupilot-tempcal", str(log), "-o", str(out), "--json"])
    assert code == 0, buf.getvalue()
    result: dict = json.loads(buf.getvalue())
    return result


def test_coefficients_changed_mid_log_are_undone_per_interval(tmp_path: Path) -> None:
    m = imu_truth(12000, 11, 1.0)
    change_at = 7000  # past the middle: the change falls at ≈ 36 °C, inside both ranges
    (tmp_path / "raw.bin").write_bytes(build(m, change_at=None))
    (tmp_path / "changed.bin").write_bytes(build(m, change_at=change_at))
    run_cli(tmp_path / "raw.bin", tmp_path / "raw")
    res = run_cli(tmp_path / "changed.bin", tmp_path / "changed")
    raw = parm_file(tmp_path / "raw" / "ardupilot.parm")
    rec = parm_file(tmp_path / "changed" / "ardupilot.parm")
    assert raw.keys() == rec.keys()
    for k, v in raw.items():  # the log stores float32: agreement to its precision
        assert rec[k] == pytest.approx(v, rel=2e-3, abs=0.05), k

    t_change = float(m["time_us"][change_at]) * 1e-6
    hyg = res["log_hygiene"]
    changes = {c["name"]: c for c in hyg["parameter_changes"]}
    assert changes["INS_TCAL1_GYR1_X"]["old"] == pytest.approx(60.0)
    assert changes["INS_TCAL1_GYR1_X"]["new"] == pytest.approx(-120.0)
    assert changes["INS_ACC1_CALTEMP"]["time_s"] == pytest.approx(t_change)
    assert "AHRS_ORIENTATION" not in changes and "INS_TCAL1_ENABLE" not in changes
    # the coefficients compared are those in force at the end of the log (SET_B)
    imu = hyg["imus"]["IMU.0"]
    assert imu["coefficients"]["INS_TCAL1_GYR1_X"]["old"] == pytest.approx(-120.0)
    assert imu["caltemp_c"]["accel"] == pytest.approx(30.0)
    prev = res["sensors"]["IMU.Gyr.0"]["previous"]
    assert prev is not None
    note = next(n for n in res["notes"] if "changed during the recording" in n)
    assert f"INS_TCAL1_GYR1_X 60 → -120 at log time {t_change:.3f} s" in note
    assert f"in force over {t_change:.3f}…" in note


def test_learning_finished_mid_log_undoes_only_the_corrected_part(tmp_path: Path) -> None:
    """The firmware's own learning (``INS_TCAL1_ENABLE`` 2: nothing subtracted) ends half-way
    and saves its coefficients with ENABLE 1: only the samples after it were corrected."""
    m = imu_truth(12000, 12, 1.0)
    change_at = 6500
    g, a = m["gyro_meas"], m["accel_meas"]
    temp32 = m["temp"].astype(np.float32).astype(np.float64)
    rest = slice(change_at, None)
    g = g.copy()
    a = a.copy()
    g[rest] = corrected(g[rest], temp32[rest], "GYR", SET_B)
    a[rest] = corrected(a[rest], temp32[rest], "ACC", SET_B)
    g[:change_at] = g[:change_at][:, [1, 0, 2]] * [1, 1, -1]
    a[:change_at] = a[:change_at][:, [1, 0, 2]] * [1, 1, -1]
    msgs: list = [parm("AHRS_ORIENTATION", 10), parm("INS_TCAL1_ENABLE", 2)]
    for i in range(m["temp"].size):
        if i == change_at:
            msgs += set_parms(SET_B, int(m["time_us"][i]))
            msgs.append(parm("INS_TCAL1_ENABLE", 1, int(m["time_us"][i])))
        msgs.append((100, (int(m["time_us"][i]), 0, *g[i], *a[i], 0, 0, float(m["temp"][i]),
                           1, 1, 1000, 1000)))  # fmt: skip
    log = tmp_path / "learned.bin"
    log.write_bytes(dataflash_log([PARM_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs))
    (tmp_path / "raw.bin").write_bytes(build(m, change_at=None))
    run_cli(tmp_path / "raw.bin", tmp_path / "raw")
    res = run_cli(log, tmp_path / "learned")
    raw = parm_file(tmp_path / "raw" / "ardupilot.parm")
    rec = parm_file(tmp_path / "learned" / "ardupilot.parm")
    for k, v in raw.items():
        assert rec[k] == pytest.approx(v, rel=2e-3, abs=0.05), k
    changes = {c["name"]: c for c in res["log_hygiene"]["parameter_changes"]}
    assert (changes["INS_TCAL1_ENABLE"]["old"], changes["INS_TCAL1_ENABLE"]["new"]) == (2.0, 1.0)
    assert res["log_hygiene"]["imus"]["IMU.0"]["active_tcal_removed"]
