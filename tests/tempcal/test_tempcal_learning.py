"""``ardupilot-tempcal --emulate-learning``: the firmware's in-flight learning emulated on a
DataFlash log whose ``TCLR`` messages were written by the test's own restatement of the
firmware (tests/helpers/learning_reference.py, from ``AP_InertialSensor_tempcal.cpp``), at
the time each window closed; the log's ``IMU.AHz`` says the driver ran 40× the log's rate."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log, parm
from learning_reference import reference_learning, sweep
from test_fc_reports import TCLR_FORMAT, TCLR_TYPE, run_cli

RATE_HZ = 25.0
DRIVER_HZ = 1000.0


def learning_log(
    path: Path, n: int, tmax: float, tclr_temp_offset: float = 0.0, nan_every: int = 0,
    first: int = 0,
) -> dict:  # fmt: skip
    t, temp, acc, gyr = sweep(n, RATE_HZ, 15.0, 0.02, seed=11)
    # what the log stores: float32 (the reader gives these values back exactly)
    temp, acc, gyr = (np.asarray(a, np.float32).astype(np.float64) for a in (temp, acc, gyr))
    g, st = reference_learning(t, temp, acc, gyr, tmax, DRIVER_HZ / RATE_HZ)
    time_us = np.round(t * 1e6).astype(np.int64)
    closing: dict[int, list] = {}
    for stype in (0, 1):
        for temp_c, x, y, z, n_s, i in st[stype]["pts_i"]:
            closing.setdefault(i, []).append((stype, temp_c + tclr_temp_offset, x, y, z, n_s))
    msgs: list = [parm("INS_TCAL1_ENABLE", 2), parm("INS_TCAL1_TMAX", tmax)]
    for i in range(first, t.size):  # the log starts at sample ``first``, the learning at 0
        tc = float("nan") if nan_every and i % nan_every == 7 else float(temp[i])
        msgs.append((100, (int(time_us[i]), 0, *gyr[i], *acc[i], 0, 0, tc, 1, 1,
                           int(DRIVER_HZ), int(DRIVER_HZ))))  # fmt: skip
        for stype, tc, x, y, z, n_s in closing.get(i, []):
            msgs.append((TCLR_TYPE, (int(time_us[i]), 0, stype, tc, x, y, z, n_s)))
    path.write_bytes(
        dataflash_log([PARM_FORMAT, TCLR_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs)
    )
    return g


def test_emulated_learning_equals_the_logged_tclr(tmp_path: Path) -> None:
    log = tmp_path / "learn.bin"
    g = learning_log(log, 60_000, 45.0)
    assert g["outcome"] == "completed"
    before = log.read_bytes()
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"),
                          "--json", "--emulate-learning"])  # fmt: skip
    assert code == 0, text
    assert log.read_bytes() == before
    em = json.loads(text)["emulated_learning"]["IMU.0"]
    assert em["outcome"] == "completed" and em["completed"] is True
    assert em["samples_per_sample"] == pytest.approx(DRIVER_HZ / RATE_HZ)
    for k, v in g["stored"].items():
        assert em["stored"][k] == pytest.approx(v, rel=1e-5, abs=1e-6), k
    for kind in ("accel", "gyro"):
        m = em["tclr"][kind]
        assert m["n_matched"] == m["n_logged"] == m["n_emulated"] > 40
        assert m["max_temp_diff_c"] < 1e-5 and m["max_value_diff"] < 1e-6
        assert m["max_time_diff_s"] == 0.0
    # beside thermocal's own fit: both corrections agree to the noise over the learned range
    assert em["max_difference_to_thermocal"]["gyro"] < 2e-4  # rad/s
    html = (tmp_path / "out" / "report_IMU_0_gyro.html").read_text()
    assert 'id="emulated-learning"' in html


def test_emulated_learning_text_and_a_shifted_tclr(tmp_path: Path) -> None:
    """TCLR points 0.3 °C off what the firmware computes: the largest difference is said."""
    log = tmp_path / "off.bin"
    learning_log(log, 60_000, 45.0, tclr_temp_offset=0.3)
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"),
                          "--emulate-learning"])  # fmt: skip
    assert code == 0, text
    assert "IMU.0 firmware learning (emulated): completed: the temperature reached" in text
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "o2"), "--json",
                          "--emulate-learning"])  # fmt: skip
    m = json.loads(text)["emulated_learning"]["IMU.0"]["tclr"]["gyro"]
    assert m["max_temp_diff_c"] == pytest.approx(0.3, abs=1e-4)


def test_emulated_learning_short_sweep_says_why(tmp_path: Path) -> None:
    log = tmp_path / "short.bin"
    g = learning_log(log, 60_000, 75.0)  # 15 → 63 °C: never reaches TMAX 75
    assert g["outcome"] is None and g["stored"]
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json",
                          "--emulate-learning"])  # fmt: skip
    assert code == 0, text
    em = json.loads(text)["emulated_learning"]["IMU.0"]
    assert em["outcome"] == "not completed" and em["partial"] is True
    assert "below INS_TCAL1_TMAX 75.0 °C" in em["reason"]
    for k, v in g["stored"].items():
        assert em["stored"][k] == pytest.approx(v, rel=1e-5, abs=1e-6), k


def test_without_the_option_nothing_changes(tmp_path: Path) -> None:
    log = tmp_path / "plain.bin"
    learning_log(log, 30_000, 45.0)
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, text
    assert "emulated_learning" not in json.loads(text)


@pytest.mark.parametrize("case", ["zero-bytes", "nan-samples"])
def test_emulate_learning_hostile_logs(tmp_path: Path, case: str) -> None:
    """A broken log (empty; NaN temperatures, which the calibration refuses before the
    emulation): exit 2 with one line naming the log, the log untouched."""
    import contextlib
    import hashlib
    import io

    from thermocal.cli import main

    log = tmp_path / "l.bin"
    if case == "zero-bytes":
        log.write_bytes(b"")
    else:
        learning_log(log, 30_000, 45.0, nan_every=1000)
    before = hashlib.sha256(log.read_bytes()).hexdigest()
    err, out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        code = main(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "o"), "--json",
                     "--emulate-learning"])  # fmt: skip
    assert hashlib.sha256(log.read_bytes()).hexdigest() == before
    assert code == 2 and out.getvalue() == ""
    lines = [x for x in err.getvalue().splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and "l.bin" in lines[0]


# --- px4-tempcal --emulate-learning ----------------------------------------------------------


def px4_log(path: Path, params: dict) -> tuple:
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    t, temp, acc, gyr = sweep(50_000, 20.0, 6.0, 0.012, seed=12)  # 6 → 36 °C from 5 s
    temp, acc, gyr = (np.asarray(a, np.float32).astype(np.float64) for a in (temp, acc, gyr))
    us = np.round(t * 1e6).astype(np.int64)
    topics = [
        (name, 0, SENSOR_FIELDS,
         [(int(us[i]), dev, *v[i], float(temp[i])) for i in range(t.size)])
        for name, dev, v in (("sensor_gyro", 7, gyr), ("sensor_accel", 9, acc))
    ]  # fmt: skip
    path.write_bytes(ulog_bytes(topics, params=params))
    return t, temp, acc, gyr


def test_px4_emulation_equals_the_restated_firmware(tmp_path: Path) -> None:
    from learning_reference import reference_px4

    log = tmp_path / "cal.ulg"
    t, temp, acc, gyr = px4_log(log, {"SYS_CAL_TDEL": 20, "SYS_CAL_TMIN": 5, "SYS_CAL_TMAX": 10})
    code, text = run_cli(["px4-tempcal", str(log), "-o", str(tmp_path / "out"), "--json",
                          "--emulate-learning"])  # fmt: skip
    assert code == 0, text
    em = json.loads(text)["emulated_learning"]
    assert em["completed"] is True and em["reason"].startswith("completed")
    for where, kind, v, tag in (("sensor_gyro.0", "gyro", gyr, "G"),
                                ("sensor_accel.0", "accel", acc, "A")):  # fmt: skip
        outcome, (low, high, ref, p) = reference_px4(t, temp, v, 20, 5, 10, kind == "accel")
        s = em["sensors"][where]
        assert outcome == s["outcome"] == "completed"
        assert s["limits"] == {"SYS_CAL_TDEL": 20.0, "SYS_CAL_TMIN": 5.0, "SYS_CAL_TMAX": 10.0}
        st = s["stored"]
        assert st[f"TC_{tag}0_TMIN"] == float(low) and st[f"TC_{tag}0_TMAX"] == float(high)
        assert st[f"TC_{tag}0_TREF"] == pytest.approx(float(ref), abs=1e-6)
        assert st[f"TC_{tag}0_ID"] == (7 if kind == "gyro" else 9)
        for axis in range(3):
            for k in range(4):
                got = st[f"TC_{tag}0_X{3 - k}_{axis}"]
                assert got == pytest.approx(p[k, axis], rel=1e-5, abs=1e-12), (where, axis, k)
    assert em["sensors"]["sensor_gyro.0"]["max_difference_to_thermocal"] < 2e-4  # rad/s


def test_px4_emulation_too_hot_and_short(tmp_path: Path) -> None:
    log = tmp_path / "hot.ulg"
    px4_log(log, {"SYS_CAL_TDEL": 20, "SYS_CAL_TMIN": 5, "SYS_CAL_TMAX": 5})
    code, text = run_cli(["px4-tempcal", str(log), "-o", str(tmp_path / "a"),
                          "--emulate-learning"])  # fmt: skip
    assert code == 0, text
    assert "too hot: the calibration started at 6.1 °C, above SYS_CAL_TMAX 5 °C" in text
    log2 = tmp_path / "short.ulg"
    px4_log(log2, {"SYS_CAL_TDEL": 40})
    code, text = run_cli(["px4-tempcal", str(log2), "-o", str(tmp_path / "b"), "--json",
                          "--emulate-learning"])  # fmt: skip
    em = json.loads(text)["emulated_learning"]
    assert em["completed"] is False and "PX4 writes nothing" in em["reason"]
    g = em["sensors"]["sensor_gyro.0"]
    rise = g["high_c"] - g["low_c"]
    assert 29.0 < rise < 31.0 and g["progress"] == int(rise / 40 * 100)
    assert g["reason"].startswith(f"not completed: the temperature rose {rise:.1f} °C of the 40")


def test_a_log_started_after_the_learning_is_said(tmp_path: Path) -> None:
    """The firmware learned from boot; the log starts 400 s later (with the TCLR the
    firmware wrote from then on): the emulation, started at the log's first sample, closes
    other windows, and says so."""
    log = tmp_path / "late.bin"
    learning_log(log, 60_000, 45.0, first=10_000)
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json",
                          "--emulate-learning"])  # fmt: skip
    assert code == 0, text
    em = json.loads(text)["emulated_learning"]["IMU.0"]
    m = em["tclr"]["gyro"]
    assert m["n_matched"] < m["n_logged"]
    assert f"{m['n_logged'] - m['n_matched']} of {m['n_logged']} gyro" in em["note"]
    assert "starts at boot" in em["note"]
