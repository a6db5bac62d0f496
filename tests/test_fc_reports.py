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

from test_ardupilot_hygiene import OLD, TMAX, TMIN, build
from test_fc_log_readers import imu_truth, parm_file


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
