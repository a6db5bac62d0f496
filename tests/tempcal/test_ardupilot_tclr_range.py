"""The range of the firmware's own learning (issue 28, item 2): ArduPilot saves ONE
``INS_TCAL<n>_TMIN/TMAX`` per IMU for both its sensors (AP_InertialSensor_tempcal.cpp
``Learn::save_calibration``: ``temp_min = start_temp``, the mid temperature of the
accelerometer's first window; ``temp_max`` the temperature when the last window closed), so
the gyro's learned curve is clamped to the accelerometer's start, not to its own first
window.  The ``TCLR`` messages are written here at the time each window closes, as
``Learn::add_sample`` logs them; learning stops when the temperature reaches
``INS_TCAL1_TMAX`` (``start_tmax``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log, parm
from fc_logs import imu_truth
from test_fc_reports import TCLR_FORMAT, TCLR_TYPE, run_cli

START_TMAX = 45.0


def windows(temp: np.ndarray, v: np.ndarray, start: int, relative: bool) -> list[tuple]:
    """(index of the closing sample, T mid, mean, count) of the firmware's windows from sample
    ``start``: ≥ 100 samples and a rise ≥ 0.5 °C; stop at ``START_TMAX``."""
    out, first_i, last_t, first = [], start, temp[start], None
    for i in range(start, temp.size):
        if i + 1 - first_i < 100 or temp[i] - last_t < 0.5:
            continue
        mean = v[first_i : i + 1].mean(axis=0)
        if relative:
            first = mean if first is None else first
            mean = mean - first
        out.append((i, 0.5 * (temp[i] + last_t), mean, i + 1 - first_i))
        first_i, last_t = i + 1, temp[i]
        if temp[i] >= START_TMAX:
            break
    return out


def learning_log(path: Path, saved: tuple[float, float] | None) -> dict:
    m = imu_truth(12000, 9, 1.0)
    temp = m["temp"].astype(np.float32).astype(np.float64)
    learn_from = int(np.argmax(temp > 5.0))  # learning started at ≈ 5 °C
    acc = windows(temp, m["accel_meas"], learn_from, relative=True)
    gyr = windows(temp, m["gyro_meas"], learn_from + 37, relative=False)  # starts a bit later
    closing: dict[int, list] = {}
    for stype, ws in ((0, acc), (1, gyr)):
        for i, t_mid, mean, n in ws:
            closing.setdefault(i, []).append((stype, t_mid, mean, n))
    last = max(closing)
    msgs: list = [parm("INS_TCAL1_ENABLE", 2), parm("INS_TCAL1_TMAX", START_TMAX),
                  parm("INS_TCAL1_TMIN", 0.0)]  # fmt: skip
    for i in range(temp.size):
        msgs.append((100, (int(m["time_us"][i]), 0, *m["gyro_meas"][i], *m["accel_meas"][i],
                           0, 0, float(m["temp"][i]), 1, 1, 1000, 1000)))  # fmt: skip
        for stype, t_mid, mean, n in closing.get(i, []):
            msgs.append((TCLR_TYPE, (int(m["time_us"][i]), 0, stype, float(t_mid),
                                     *map(float, mean), n)))  # fmt: skip
        if i == last and saved is not None:  # finish_calibration: the firmware saves its range
            msgs += [parm("INS_TCAL1_TMIN", saved[0], int(m["time_us"][i])),
                     parm("INS_TCAL1_TMAX", saved[1], int(m["time_us"][i])),
                     parm("INS_TCAL1_ENABLE", 1, int(m["time_us"][i]))]  # fmt: skip
    path.write_bytes(
        dataflash_log([PARM_FORMAT, TCLR_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs)
    )
    f32 = lambda x: float(np.float32(x))  # noqa: E731  (TCLR stores float32)
    return {"acc_first_t": f32(acc[0][1]), "gyr_first_t": f32(gyr[0][1]),
            "close_t": float(temp[last]), "gyr_max_t": f32(max(w[1] for w in gyr))}  # fmt: skip


def learned_range(out: dict, key: str) -> tuple[float, float]:
    p = out["sensors"][key]["firmware_learning"]["parameters"]
    return p["INS_TCAL1_TMIN"]["firmware"], p["INS_TCAL1_TMAX"]["firmware"]


def test_tclr_range_is_the_imus_from_the_accelerometer_start(tmp_path: Path) -> None:
    import json

    log = tmp_path / "learn.bin"
    want = learning_log(log, saved=None)
    assert abs(want["gyr_first_t"] - want["acc_first_t"]) > 0.05  # the test can tell them apart
    assert want["close_t"] - want["gyr_max_t"] > 0.1
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, text
    out = json.loads(text)
    for key in ("IMU.Acc.0", "IMU.Gyr.0"):  # one range for both sensors of the IMU
        lo, hi = learned_range(out, key)
        assert lo == pytest.approx(want["acc_first_t"], abs=1e-4), key
        assert hi == pytest.approx(want["close_t"], abs=1e-4), key


def test_tclr_range_saved_by_the_firmware_is_used(tmp_path: Path) -> None:
    import json

    log = tmp_path / "learned.bin"
    learning_log(log, saved=(12.5, 44.75))
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, text
    out = json.loads(text)
    for key in ("IMU.Acc.0", "IMU.Gyr.0"):
        assert learned_range(out, key) == (pytest.approx(12.5), pytest.approx(44.75)), key
