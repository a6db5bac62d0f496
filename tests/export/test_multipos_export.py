"""``thermocal export-params`` of a calibration of triads (issue 30): PX4 ``CAL_ACC<n>_*`` /
``CAL_GYRO<n>_*`` and ArduPilot ``INS_ACCOFFS_*`` / ``INS_ACCSCAL_*`` / ``INS_GYROFFS_*``.

The firmware formulas, written here from the firmwares' sources and parameter docs:

* PX4 ``Accelerometer::Correct``: ``a_c = diag(CAL_ACCn_[XYZ]SCALE)·(a − CAL_ACCn_[XYZ]OFF)``
  [m/s²]; ``Gyroscope::Correct``: ``ω_c = ω − CAL_GYROn_[XYZ]OFF`` [rad/s];
* ArduPilot ``_rotate_and_correct_accel``: ``a_c = (a − INS_ACCOFFS)·INS_ACCSCAL`` [m/s/s],
  ``ω_c = ω − INS_GYROFFS`` [rad/s]; ``INS_ACCSCAL_*`` ``@Range: 0.8 1.2``.

A simulated session of a triad with known bias and scale (no misalignment, so the
firmware can hold it all) is calibrated by ``thermocal multipos``; the exported values put
through the firmware formula give back the true specific force on the six faces within
the calibration's own uncertainty.  A scale outside ArduPilot's range is refused (exit 2).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.models.calibration import Calibration, Triad
from thermocal.multipos.simulate import simulate_session
from thermocal.pipeline.model_file import save_calibration
from thermocal.turntable import thermal

MG = 9.80665e-3  # m/s² per mg
DH = math.pi / 180 / 3600  # rad/s per °/h
A_B = np.array([25.0, -30.0, 12.0])  # mg
A_S = np.array([6000.0, -4000.0, 2500.0])  # ppm
G_B = np.array([500.0, -800.0, 300.0])  # °/h


def _parse(path: Path, fmt: str) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if not line or line.startswith("#"):
            continue
        parts = line.split("\t") if fmt == "px4" else line.split()
        name, value = (parts[2], parts[3]) if fmt == "px4" else (parts[0], parts[1])
        out[name] = float(value)
    return out


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("mpx")
    ta = np.zeros(12)
    ta[0:3], ta[3:6] = A_B, A_S
    tg = np.zeros(12)
    tg[0:3] = G_B
    s = simulate_session(np.random.default_rng(7), ta, tg, n_poses=16)
    cols = {"time": s["time_s"]}
    for k, a in enumerate("xyz"):
        cols[f"ax_{a} [m/s^2]"] = s["accel_mg"][:, k] * MG
    for k, a in enumerate("xyz"):
        cols[f"gx_{a} [deg/s]"] = s["gyro_deg_s"][:, k]
    f = d / "session.csv"
    pd.DataFrame(cols).to_csv(f, index=False)
    cal = d / "cal.json"
    code, out, err = _run(["multipos", str(f), "--accel", "ax_x [m/s^2],ax_y [m/s^2],ax_z [m/s^2]",
                           "--gyro", "gx_x [deg/s],gx_y [deg/s],gx_z [deg/s]", "--latitude",
                           "45", "-o", str(cal), "--json"])  # fmt: skip
    assert code == 0, err
    return {"dir": d, "cal": cal, "summary": json.loads(out)}


@pytest.mark.parametrize("fmt", ["px4", "ardupilot"])
def test_export_params_of_a_triad_reproduces_the_truth(session: dict[str, Any], fmt: str) -> None:
    d, s = session["dir"], session["summary"]
    out = d / f"p_{fmt}.txt"
    args = ["export-params", str(session["cal"]), "--format", fmt, "-o", str(out)]
    code, _o, err = _run(args + (["--device-id", "2490378"] if fmt == "px4" else []))
    assert code == 0, err
    # the misalignment the firmware cannot hold is warned and written in the comments
    assert "warning: accel: misalignment" in err and "warning: gyro: misalignment" in err, err
    assert "# accel: misalignment" in out.read_text()
    p = _parse(out, fmt)
    if fmt == "px4":
        off = np.array([p[f"CAL_ACC0_{a}OFF"] for a in "XYZ"])
        sc = np.array([p[f"CAL_ACC0_{a}SCALE"] for a in "XYZ"])
        goff = np.array([p[f"CAL_GYRO0_{a}OFF"] for a in "XYZ"])
        assert p["CAL_ACC0_ID"] == p["CAL_GYRO0_ID"] == 2490378

        def firmware(a: np.ndarray) -> np.ndarray:
            return sc * (a - off)
    else:
        off = np.array([p[f"INS_ACCOFFS_{a}"] for a in "XYZ"])
        sc = np.array([p[f"INS_ACCSCAL_{a}"] for a in "XYZ"])
        goff = np.array([p[f"INS_GYROFFS_{a}"] for a in "XYZ"])

        def firmware(a: np.ndarray) -> np.ndarray:
            return (a - off) * sc

    # six faces: the true specific force, the raw reading the truth makes of it
    g = s["gravity_m_s2"]
    faces = np.vstack([np.eye(3) * g, -np.eye(3) * g])
    raw = faces * (1 + A_S * 1e-6) + A_B * MG
    sb = np.array(s["accel"]["bias_sigma"])  # m/s²
    ss = np.array(s["accel"]["scale_factor_ppm_sigma"]) * 1e-6
    tol = 3.5 * np.sqrt(sb**2 + (g * ss) ** 2) + 1e-9
    assert np.all(np.abs(firmware(raw) - faces) < tol), (firmware(raw) - faces, tol)
    # and the parameters against the truth the firmware needs: OFF = b, SCALE = 1/(1 + s)
    assert np.all(np.abs(off - A_B * MG) < 3.5 * sb)
    assert np.all(np.abs(sc - 1 / (1 + A_S * 1e-6)) < 3.5 * ss)
    gsb = np.array(s["gyro"]["bias_sigma"]) * math.pi / 180  # deg/s → rad/s
    assert np.all(np.abs(goff - G_B * DH) < 3.5 * gsb), (goff, G_B * DH, gsb)


def test_export_params_second_imu_names(session: dict[str, Any]) -> None:
    out = session["dir"] / "p2.parm"
    code, _o, err = _run(["export-params", str(session["cal"]), "--format", "ardupilot", "-o",
                          str(out), "--instance", "1"])  # fmt: skip
    assert code == 0, err
    p = _parse(out, "ardupilot")
    names = {f"INS_ACC2OFFS_{a}" for a in "XYZ"} | {f"INS_ACC2SCAL_{a}" for a in "XYZ"}
    assert set(p) == names | {f"INS_GYR2OFFS_{a}" for a in "XYZ"}
    code, _o, err = _run(["export-params", str(session["cal"]), "--format", "ardupilot", "-o",
                          str(out.with_suffix(".x")), "--instance", "3"])  # fmt: skip
    assert code == 2 and "instances 0…2" in err, err


def _constant_cal(path: Path, scale_ppm: float) -> None:
    th = np.zeros(12)
    th[0:3] = [10.0, -5.0, 3.0]  # mg
    th[3:6] = [scale_ppm, 1000.0, -2000.0]
    th[8] = 500.0  # xy misalignment [″]
    m = thermal.constant_triad("accel", 25.0, th, np.eye(12) * 1e-4, method="multipos")
    cols = ("ax [m/s^2]", "ay [m/s^2]", "az [m/s^2]")
    save_calibration(Calibration([], [Triad("accel", cols, "m/s^2", "", m)]), path)


def test_scale_outside_ardupilot_range_refused(tmp_path: Path) -> None:
    """A 30 % scale error: SCALE = 1/1.3 ≈ 0.769 < 0.8, ArduPilot's INS_ACCSCAL range."""
    cal = tmp_path / "c.json"
    _constant_cal(cal, 300000.0)
    code, _o, err = _run(["export-params", str(cal), "--format", "ardupilot", "-o",
                          str(tmp_path / "a.parm")])  # fmt: skip
    assert code == 2 and "INS_ACCSCAL_X" in err and "0.8…1.2" in err, err
    assert not (tmp_path / "a.parm").exists()
    # PX4 too (issue 39 item 9): the same sensor, the same range
    code, _o, err = _run(["export-params", str(cal), "--format", "px4", "-o",
                          str(tmp_path / "p.params")])  # fmt: skip
    assert code == 2 and "CAL_ACC0_XSCALE" in err and "0.8…1.2" in err, err
    assert not (tmp_path / "p.params").exists()
    # a 10 % scale error is written: the diagonal of (I + E)⁻¹
    _constant_cal(cal, 100000.0)
    code, _o, err = _run(["export-params", str(cal), "--format", "px4", "-o",
                          str(tmp_path / "p.params")])  # fmt: skip
    assert code == 0, err
    p = _parse(tmp_path / "p.params", "px4")
    e = np.diag([0.1, 1e-3, -2e-3])
    e[1, 0] = 500.0 * math.pi / 180 / 3600
    inv = np.linalg.inv(np.eye(3) + e)
    got = [p[f"CAL_ACC0_{a}SCALE"] for a in "XYZ"]
    np.testing.assert_allclose(got, np.diag(inv), rtol=1e-12)
    np.testing.assert_allclose([p[f"CAL_ACC0_{a}OFF"] for a in "XYZ"],
                               np.array([10.0, -5.0, 3.0]) * MG, rtol=1e-12)  # fmt: skip
    assert "CAL_ACC0_ID not written" in err and "misalignment up to" in err
