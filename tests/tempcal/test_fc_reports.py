"""The flight-controller calibrations' reports (issue 28, items 2 and 3).

The coefficients a log was recorded with against the new ones: an ArduPilot log built here
with active ``INS_TCAL1_*`` (:mod:`test_ardupilot_hygiene`) gives, per sensor, a
``previous`` object in ``--json`` and a table and figure in the HTML report whose old values
are the log's, new values the written ones, and whose curves are the firmware's correction
(AP_InertialSensor_tempcal.cpp: ``(c1 + (c2 + c3·t)·t)·t·1e-6``, ``t = clamp(T, TMIN,
TMAX) − 35``) written out here."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest

from fc_logs import imu_truth, parm_file
from test_ardupilot_hygiene import OLD, TMAX, TMIN, build


def run_cli(args: list[str]) -> tuple[int, str]:
    from thermocal.cli import main

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
        code = main(args)
    return code, buf.getvalue()


def firmware_curve(c: list[list[float]], temp: np.ndarray, lo: float, hi: float) -> np.ndarray:
    cc = np.asarray(c, dtype=np.float32).astype(np.float64)  # the log stores float32
    t = np.clip(temp, lo, hi)[:, None] - 35.0
    return (cc[0] + (cc[1] + cc[2] * t) * t) * t * 1e-6


def test_previous_coefficients_in_json_and_report(tmp_path: Path) -> None:
    m = imu_truth(12000, 9, 1.0)
    log = tmp_path / "recorded.bin"
    log.write_bytes(build(m, as_recorded=True))
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, text
    out = json.loads(text)
    new = parm_file(tmp_path / "out" / "ardupilot.parm")
    for key, tag, unit in (("IMU.Gyr.0", "GYR", "rad/s"), ("IMU.Acc.0", "ACC", "m/s^2")):
        prev = out["sensors"][key]["previous"]
        assert prev["unit"] == unit
        params = prev["parameters"]
        for k in range(3):
            for j, ax in enumerate("XYZ"):
                name = f"INS_TCAL1_{tag}{k + 1}_{ax}"
                p = params[name]
                assert p["old"] == pytest.approx(OLD[tag][k][j], rel=1e-6), name
                assert p["new"] == pytest.approx(new[name], rel=1e-5, abs=1e-9), name
                assert p["difference"] == pytest.approx(new[name] - OLD[tag][k][j], rel=1e-5)
        assert params["INS_TCAL1_TMIN"]["old"] == TMIN
        assert params["INS_TCAL1_TMAX"]["new"] == pytest.approx(new["INS_TCAL1_TMAX"], rel=1e-5)
        curves = prev["curves"]
        temp = np.asarray(curves["temperature_c"])
        lo, hi = out["sensors"][key]["sweep_c"]
        assert temp[0] == pytest.approx(lo) and temp[-1] == pytest.approx(hi)
        old_c = firmware_curve(OLD[tag], temp, TMIN, TMAX)
        new_c = [[new[f"INS_TCAL1_{tag}{k}_{a}"] for a in "XYZ"] for k in (1, 2, 3)]
        new_curve = firmware_curve(new_c, temp, new["INS_TCAL1_TMIN"], new["INS_TCAL1_TMAX"])
        for j, ax in enumerate("xyz"):
            assert np.allclose(curves["old"][ax], old_c[:, j], rtol=1e-9, atol=1e-12), ax
            assert np.allclose(curves["new"][ax], new_curve[:, j], rtol=1e-5, atol=1e-9), ax
    # the HTML report: the same table and a figure
    html = (tmp_path / "out" / "report_IMU_0_gyro.html").read_text()
    assert 'id="previous-coefficients"' in html and 'id="previous-figure"' in html
    found = re.findall(r'data-param="([^"]+)" data-old="([^"]+)" data-new="([^"]+)"', html)
    rows = {n: (float(o), float(v)) for n, o, v in found}
    assert rows["INS_TCAL1_GYR1_X"][0] == pytest.approx(60.0, rel=1e-6)
    assert rows["INS_TCAL1_GYR3_Z"][0] == pytest.approx(-0.01, rel=1e-6)
    assert rows["INS_TCAL1_GYR2_Y"][1] == pytest.approx(new["INS_TCAL1_GYR2_Y"], rel=1e-5)
    assert "INS_TCAL1_ACC1_X" not in rows  # the accelerometer's are in its own report
    acc = (tmp_path / "out" / "report_IMU_0_accel.html").read_text()
    assert 'data-param="INS_TCAL1_ACC1_X" data-old="800.0"' in acc


def test_no_previous_without_active_coefficients(tmp_path: Path) -> None:
    m = imu_truth(12000, 9, 1.0)
    log = tmp_path / "raw.bin"
    log.write_bytes(build(m, as_recorded=False))
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, text
    out = json.loads(text)
    assert out["sensors"]["IMU.Gyr.0"]["previous"] is None
    assert (
        'id="previous-coefficients"'
        not in (tmp_path / "out" / "report_IMU_0_gyro.html").read_text()
    )


# --- barometer and magnetometer reports (issue 28, item 3) -------------------------------


def baro_mag_log(
    path: Path, params: dict | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A ULog (:mod:`ulog_writer`) with a gyro, a barometer drifting 5th-order in Pa and a
    magnetometer with cubic offsets in gauss; returns (temperature, pressure, mag)."""
    from test_px4_baro_mag import BARO
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    rng = np.random.default_rng(8)
    n = 12000
    t = np.arange(n) * 0.1
    temp = -5.0 + 55.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 25.0
    pressure = 101325.0 + 40.0 * x + 12.0 * x**2 - 9.0 * x**3 + 4.0 * x**5 + rng.normal(0, 1, n)
    mag = np.array([0.2, 0.05, -0.4]) + np.column_stack(
        [0.01 * x, -0.006 * x + 0.004 * x**3, 0.008 * x**2]
    ) + rng.normal(0.0, 5e-4, (n, 3))  # fmt: skip
    ts = (1e6 + t * 1e6).astype(np.int64)
    gyro = [
        (int(s), 11, *rng.normal(0, 1e-3, 3), float(tt)) for s, tt in zip(ts, temp, strict=True)
    ]
    baro = [(int(s), 22, float(p), float(tt)) for s, p, tt in zip(ts, pressure, temp, strict=True)]
    mags = [(int(s), 33, *map(float, m), float(tt)) for s, m, tt in zip(ts, mag, temp, strict=True)]
    path.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, gyro),
                                 ("sensor_baro", 0, BARO, baro),
                                 ("sensor_mag", 0, SENSOR_FIELDS, mags)], params))  # fmt: skip
    f32 = np.float32
    return (
        temp.astype(f32).astype(float),
        pressure.astype(f32).astype(float),
        mag.astype(f32).astype(float),
    )


def bin_medians(temp: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Medians of ``v`` in the occupied 0.5 °C bins from ⌊min T / 0.5⌋·0.5 (written here)."""
    k = np.floor((temp - np.floor(temp.min() / 0.5) * 0.5) / 0.5).astype(int)
    return np.array([np.median(v[k == b], axis=0) for b in np.unique(k)])


def test_baro_and_mag_reports(tmp_path: Path) -> None:
    log = tmp_path / "bench.ulg"
    temp, pressure, mag = baro_mag_log(log)
    out_dir = tmp_path / "out"
    code, text = run_cli(["px4-tempcal", str(log), "-o", str(out_dir), "--json"])
    assert code == 0, text
    out = json.loads(text)
    p = {}
    for line in (out_dir / "px4.params").read_text().splitlines():
        if not line.startswith("#"):
            _v, _c, name, value, _t = line.split("\t")
            p[name] = float(value)
    cases = (("sensor_baro", "TC_B0_", 5, pressure[:, None], [""], ["pressure"]),
             ("sensor_mag", "TC_M0_", 3, mag, ["_0", "_1", "_2"], ["x", "y", "z"]))  # fmt: skip
    for topic, prefix, order, values, suffixes, axes in cases:
        report = out_dir / f"report_{topic}_0.html"
        assert str(report) in out["reports"]
        html = report.read_text()
        assert html.count('class="figure"') == 2
        assert 'id="offset-residual"' in html and 'id="offset-holdout"' in html
        rows = {
            a: (float(h), float(b), float(af))
            for a, h, b, af in re.findall(
                r'data-axis="([^"]+)" data-holdout="([^"]+)" data-before="([^"]+)" '
                r'data-after="([^"]+)"', html)
        }  # fmt: skip
        assert list(rows) == axes
        dt = np.clip(temp, p[prefix + "TMIN"], p[prefix + "TMAX"]) - p[prefix + "TREF"]
        for j, (a, suf) in enumerate(zip(axes, suffixes, strict=True)):
            before = values[:, j] - np.median(values[:, j])
            after = before - sum(p[f"{prefix}X{k}{suf}"] * dt**k for k in range(order + 1))
            b_rms = float(np.sqrt(np.mean(bin_medians(temp, before) ** 2)))
            a_rms = float(np.sqrt(np.mean(bin_medians(temp, after) ** 2)))
            holdout, shown_before, shown_after = rows[a]
            assert holdout == pytest.approx(out["sensors"][f"{topic}.0"]["holdout_rms"][a])
            assert shown_before == pytest.approx(b_rms, rel=1e-6)
            assert shown_after == pytest.approx(a_rms, rel=2e-3, abs=1e-3 * b_rms)
            assert shown_after < 0.05 * shown_before, (topic, a)


# --- ArduPilot's own learning: TCLR (issue 28, item 2) -----------------------------------

TCLR_TYPE = 130
TCLR_FORMAT = (TCLR_TYPE, "TCLR", "QBBffffI", ("TimeUS", "I", "SType", "Temp", "X", "Y", "Z",
                                               "NSamp"))  # fmt: skip
"""AP_InertialSensor_tempcal.cpp ``Learn::add_sample``: ``Write("TCLR",
"TimeUS,I,SType,Temp,X,Y,Z,NSamp", …, "QBBffffI", …)``."""


def firmware_windows(temp: np.ndarray, v: np.ndarray, relative: bool) -> list[tuple]:
    """The firmware's learning windows, restated: sum samples until there are ≥ 100 and the
    temperature rose ≥ 0.5 °C since the last window; log T = (T + T_last)/2 and the mean
    (the accelerometer relative to its first window)."""
    out, start, last_t, first = [], 0, temp[0], None
    for i in range(temp.size):
        if i + 1 - start < 100 or temp[i] - last_t < 0.5:
            continue
        mean = v[start : i + 1].mean(axis=0)
        if relative:
            first = mean if first is None else first
            mean = mean - first
        out.append((0.5 * (temp[i] + last_t), mean, i + 1 - start))
        start, last_t = i + 1, temp[i]
    return out


def test_firmware_learning_tclr_compared(tmp_path: Path) -> None:
    from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log, parm

    m = imu_truth(12000, 9, 1.0)
    temp = m["temp"].astype(np.float32).astype(np.float64)
    msgs: list = [parm("INS_TCAL1_ENABLE", 2), parm("INS_TCAL1_TMAX", 50.0)]
    windows = {}
    for stype, key in ((0, "accel_meas"), (1, "gyro_meas")):
        windows[stype] = firmware_windows(temp, m[key], relative=stype == 0)
        for t_mid, mean, n in windows[stype]:
            msgs.append((TCLR_TYPE, (5000, 0, stype, float(t_mid), *map(float, mean), n)))
    for i in range(temp.size):
        msgs.append((100, (int(m["time_us"][i]), 0, *m["gyro_meas"][i], *m["accel_meas"][i],
                           0, 0, float(m["temp"][i]), 1, 1, 1000, 1000)))  # fmt: skip
    log = tmp_path / "learning.bin"
    log.write_bytes(
        dataflash_log([PARM_FORMAT, TCLR_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs)
    )
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, text
    out = json.loads(text)
    new = parm_file(tmp_path / "out" / "ardupilot.parm")
    for key, stype, tag, truth in (("IMU.Acc.0", 0, "ACC", m["accel"]),
                                   ("IMU.Gyr.0", 1, "GYR", m["gyro"])):  # fmt: skip
        fl = out["sensors"][key]["firmware_learning"]
        assert out["sensors"][key]["previous"] is None  # learning: nothing was active
        t_pts = np.array([w[0] for w in windows[stype]], dtype=np.float32).astype(float)
        v_pts = np.array([w[1] for w in windows[stype]], dtype=np.float32).astype(float)
        for j, ax in enumerate("XYZ"):
            p = np.polyfit(t_pts - 35.0, v_pts[:, j], 3)  # highest power first
            for k in (1, 2, 3):
                name = f"INS_TCAL1_{tag}{k}_{ax}"
                got = fl["parameters"][name]
                assert got["firmware"] == pytest.approx(p[3 - k] * 1e6, rel=1e-6, abs=1e-6), name
                assert got["thermocal"] == pytest.approx(new[name], rel=1e-5, abs=1e-9), name
        # both learned the same sensor: their corrections agree to a few % of the drift
        tt = np.asarray(fl["curves"]["temperature_c"])
        for j, ax in enumerate("xyz"):
            fw, tc = (
                np.asarray(fl["curves"]["firmware"][ax]),
                np.asarray(fl["curves"]["thermocal"][ax]),
            )
            span = float(np.ptp(np.interp(tt, m["temp"], truth[:, j])))
            assert np.max(np.abs(fw - tc)) < 0.08 * span, (key, ax)
    html = (tmp_path / "out" / "report_IMU_0_gyro.html").read_text()
    section = html[html.index('<section id="firmware-learning">') :]
    section = section[: section.index("</section>")]
    assert 'id="firmware-learning-figure"' in section
    found = dict(re.findall(r'data-param="(INS_TCAL1_GYR1_X)" data-old="([^"]+)"', section))
    assert float(found["INS_TCAL1_GYR1_X"]) == pytest.approx(
        fl["parameters"]["INS_TCAL1_GYR1_X"]["firmware"]
    )
    assert any("TCLR" in n for n in out["notes"])


# --- ArduPilot's barometer temperature calibration: TCAL_BARO_EXP -------------------------

BARO_TYPE = 131
BARO_FORMAT = (BARO_TYPE, "BARO", "QBfffcfIffB", ("TimeUS", "I", "Alt", "AltAMSL", "Press",
                                                  "Temp", "CRt", "SMS", "Offset", "GndTemp",
                                                  "H"))  # fmt: skip
"""AP_Baro_Logging / LogStructure.h ``BARO``: ``Temp`` an int16 of centi-degrees ('c')."""


def baro_log(path: Path, exponent_true: float, sign: float) -> tuple[np.ndarray, np.ndarray]:
    """An IMU and a barometer whose pressure drops by ``max(T − 25, 0)^e`` Pa (``sign`` +1:
    the drift ArduPilot's correction adds back; −1: a rise it cannot follow)."""
    from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log

    m = imu_truth(12000, 9, 1.0)
    rng = np.random.default_rng(3)
    temp_c100 = np.round(m["temp"] * 100.0)
    temp = temp_c100 / 100.0
    press = 101325.0 - sign * np.maximum(temp - 25.0, 0.0) ** exponent_true
    press = press + rng.normal(0.0, 0.5, temp.size)
    msgs: list = []
    for i in range(temp.size):
        msgs.append((100, (int(m["time_us"][i]), 0, *m["gyro_meas"][i], *m["accel_meas"][i],
                           0, 0, float(m["temp"][i]), 1, 1, 1000, 1000)))  # fmt: skip
        msgs.append((BARO_TYPE, (int(m["time_us"][i]) + 10, 0, 0.0, 0.0, float(press[i]),
                                 int(temp_c100[i]), 0.0, 0, 0.0, 20.0, 1)))  # fmt: skip
    fmts = [PARM_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS), BARO_FORMAT]
    path.write_bytes(dataflash_log(fmts, msgs))
    return temp, press.astype(np.float32).astype(float)


def test_ardupilot_baro_exponent(tmp_path: Path) -> None:
    log = tmp_path / "baro.bin"
    temp, press = baro_log(log, 1.35, +1.0)
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, text
    out = json.loads(text)
    p = parm_file(tmp_path / "out" / "ardupilot.parm")
    assert p["TCAL_ENABLED"] == 1
    assert p["TCAL_BARO_EXP"] == pytest.approx(1.35, abs=0.01)
    assert p["TCAL_TEMP_MIN"] == round(temp.min()) and p["TCAL_TEMP_MAX"] == round(temp.max())
    baro = out["sensors"]["BARO.0"]
    assert baro["exponent"] == pytest.approx(p["TCAL_BARO_EXP"]) and not baro["at_limit"]
    # the firmware's correction with the written exponent, applied here to the log's pressure
    corrected = press + np.maximum(temp - 25.0, 0.0) ** p["TCAL_BARO_EXP"]
    drift = float(np.ptp(np.maximum(temp - 25.0, 0.0) ** 1.35))  # [Pa]
    assert np.ptp(corrected) < np.ptp(press) and drift > 50.0
    k = np.floor((temp - np.floor(temp.min() / 0.5) * 0.5) / 0.5).astype(int)
    bins = np.array([np.median(corrected[k == b]) for b in np.unique(k)])
    assert float(np.std(bins)) < 0.05 * drift
    assert baro["rms_after_pa"] == pytest.approx(float(np.std(bins)), rel=0.05, abs=0.05)
    assert baro["holdout_rms_pa"] < 1.0


def test_ardupilot_baro_drift_the_firmware_cannot_follow(tmp_path: Path) -> None:
    log = tmp_path / "baro_up.bin"
    baro_log(log, 1.2, -1.0)  # the pressure rises with temperature
    from thermocal.cli import main

    buf, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(err):
        code = main(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, buf.getvalue()
    baro = json.loads(buf.getvalue())["sensors"]["BARO.0"]
    assert baro["at_limit"] and baro["exponent"] == pytest.approx(0.0, abs=1e-3)
    assert "TCAL_BARO_EXP" in err.getvalue() and "does not follow" in err.getvalue()


# --- PX4: the log's TC_* parameters against the new ones ----------------------------------

OLD_G = {
    "TMIN": 0.0, "TMAX": 45.0, "TREF": 25.0,
    **{f"X{k}_{i}": 1e-3 * (i + 1) * (-0.1) ** k for k in range(4) for i in range(3)},
}  # fmt: skip
OLD_B = {"TMIN": 5.0, "TMAX": 40.0, "TREF": 20.0, **{f"X{k}": 30.0 / 4**k for k in range(6)}}


def px4_offset(p: dict, prefix: str, order: int, suffix: str, temp: np.ndarray) -> np.ndarray:
    """PX4's offset Σ X_k·(clamp(T, TMIN, TMAX) − TREF)^k, written here."""
    x = np.clip(temp, p[prefix + "TMIN"], p[prefix + "TMAX"]) - p[prefix + "TREF"]
    return sum(p[f"{prefix}X{k}{suffix}"] * x**k for k in range(order + 1))


def test_px4_previous_tc_parameters(tmp_path: Path) -> None:
    old: dict = {"TC_G_ENABLE": 1, "TC_G1_ID": 11, "TC_B_ENABLE": 1, "TC_B0_ID": 22,
                 "TC_G0_ID": 999}  # fmt: skip  # the gyro's calibration is at index 1
    old |= {f"TC_G1_{k}": v for k, v in OLD_G.items()} | {f"TC_B0_{k}": v for k, v in OLD_B.items()}
    old |= {f"TC_G0_{k}": 7.0 for k in OLD_G}  # another device's: not this gyro's
    log = tmp_path / "bench.ulg"
    baro_mag_log(log, old)
    out_dir = tmp_path / "out"
    code, text = run_cli(["px4-tempcal", str(log), "-o", str(out_dir), "--json"])
    assert code == 0, text
    out = json.loads(text)
    new = {}
    for line in (out_dir / "px4.params").read_text().splitlines():
        if not line.startswith("#"):
            _v, _c, name, value, _t = line.split("\t")
            new[name] = float(value)
    f32 = lambda v: float(np.float32(v))  # noqa: E731  (ULog parameters are float32)
    gyro = out["sensors"]["sensor_gyro.0"]["previous"]
    assert gyro["unit"] == "rad/s"
    for k, v in OLD_G.items():
        row = gyro["parameters"][f"TC_G0_{k}"]
        assert row["old"] == pytest.approx(f32(v), rel=1e-7), k
        assert row["new"] == pytest.approx(new[f"TC_G0_{k}"], rel=1e-6), k
        assert row["difference"] == pytest.approx(row["new"] - row["old"]), k
    temp = np.asarray(gyro["curves"]["temperature_c"])
    old32 = {f"TC_G1_{k}": f32(v) for k, v in OLD_G.items()}
    for i, ax in enumerate("xyz"):
        want_old = px4_offset(old32, "TC_G1_", 3, f"_{i}", temp)
        want_new = px4_offset(new, "TC_G0_", 3, f"_{i}", temp)
        assert np.allclose(gyro["curves"]["old"][ax], want_old, rtol=1e-6, atol=1e-12), ax
        assert np.allclose(gyro["curves"]["new"][ax], want_new, rtol=1e-5, atol=1e-9), ax
    baro = out["sensors"]["sensor_baro.0"]["previous"]
    assert baro["unit"] == "Pa"
    assert baro["parameters"]["TC_B0_X1"]["old"] == pytest.approx(7.5)
    assert baro["parameters"]["TC_B0_X5"]["new"] == pytest.approx(new["TC_B0_X5"], rel=1e-6)
    assert out["sensors"]["sensor_mag.0"]["previous"] is None  # the log has no TC_M
    html = (out_dir / "report_sensor_baro_0.html").read_text()
    assert 'data-param="TC_B0_X1" data-old="7.5"' in html
    assert 'id="previous-figure"' in (out_dir / "report_sensor_gyro_0.html").read_text()
