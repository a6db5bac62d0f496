"""A tilted bench (issue 25 item 3): gravity along the measured direction, and firmware
accelerometer parameters that hold no share of gravity.

The board sits rotated 6° about x and 6° about y (no bench is level), in a cold and a hot
soak recorded as two files, as a logger writes them (time in ms with a gap, the unit in the
time column's name).  Everything the assertions compare with is written here from the
truth: gravity in the body frame ``g·Rᵀ·e_z`` with ``R = Rx(6°)·Ry(6°)``; each axis's bias
``b0 + s·(T − 25) + q·(T − 25)²`` [mg]; the firmware formulas of INTERFACE.md
("Firmware parameter formats"):

* PX4 subtracts ``X0 + X1·dT + X2·dT² + X3·dT³``, ``dT = T − TREF`` [m/s²]; the
  accelerometer offset is relative to mid-range, so ``X0 = b(TREF) − b(mid)``,
  ``X1 = s + 2q·(TREF − 25)``, ``X2 = q``, ``X3 = 0``;
* ArduPilot subtracts ``poly(T − 35) − poly(T_cal − 35)``,
  ``poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6``: about 35 °C the bias is
  ``… + (s + 20q)·t + q·t²``, so ``c1 = (s + 20q)·1e6``, ``c2 = q·1e6``, ``c3 = 0`` [m/s²].

Before the fix, PX4's ``X0`` of x and y held the tilt's 105 mg of gravity (1.03 m/s²).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

G0 = 9.80665
M_S2_PER_MG = G0 / 1000.0
TILT_X_DEG, TILT_Y_DEG = 6.0, 6.0
B0 = np.array([12.0, -8.0, 25.0])  # bias at 25 °C [mg]
S = np.array([0.40, -0.25, 0.60])  # slope [mg/°C]
Q = np.array([0.004, 0.002, -0.003])  # curvature [mg/°C²]
NOISE_MG = 1.0


def _rot(axis: str, deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    if axis == "x":
        return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


UP_BODY = (_rot("x", TILT_X_DEG) @ _rot("y", TILT_Y_DEG)).T @ np.array([0.0, 0.0, 1.0])
"""The up direction in the body frame: a static accelerometer reads +g along it."""


def bias_mg(temp_c: np.ndarray) -> np.ndarray:
    """The true bias of x, y, z [mg] at each temperature, shape (n, 3)."""
    d = np.asarray(temp_c)[:, None] - 25.0
    return B0 + S * d + Q * d**2


def _soak(path: Path, t0: float, t1: float, seed: int) -> None:
    """One soak: 1 Hz for 1500 s, the temperature settling from t0 towards t1, a 2-minute
    gap in the logger's record; time in ms, accelerations in mg."""
    rng = np.random.default_rng(seed)
    t = np.arange(1500.0)
    keep = (t < 600.0) | (t >= 720.0)
    t = t[keep]
    temp = t1 + (t0 - t1) * np.exp(-t / 400.0)
    f = 1000.0 * UP_BODY + bias_mg(temp) + NOISE_MG * rng.standard_normal((t.size, 3))
    pd.DataFrame(
        {"time_ms": 1000.0 * t, "temp": np.round(temp, 3),
         "ax": f[:, 0], "ay": f[:, 1], "az": f[:, 2]}
    ).to_csv(path, index=False)  # fmt: skip


def _run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def soaks(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict]:
    d = tmp_path_factory.mktemp("tilt")
    _soak(d / "cold.csv", -10.0, 12.0, 1)
    _soak(d / "hot.csv", 55.0, 33.0, 2)
    cal = d / "cal.json"
    code, out, err = _run("fit", str(d / "cold.csv"), str(d / "hot.csv"), "--model", "poly",
                          "--order", "2", "--signal", "ax,ay,az", "--signal-unit", "mg",
                          "--temps", "temp", "--temp-unit", "degC", "--no-per-run-offset",
                          "--gravity-axis", "+z", "--gravity", str(G0), "-o", str(cal),
                          "--json")  # fmt: skip
    assert code == 0, err
    return d, cal, json.loads(out)


def test_the_fit_removes_gravity_along_the_measured_direction(soaks: tuple) -> None:
    _d, _cal, res = soaks
    ch = res["channels"]
    got = np.array([ch[n]["known_input"]["value"] for n in ("ax", "ay", "az")])
    # g·u with u measured from the mean specific force; the horizontal mean bias (about
    # 10 mg across gravity) cannot be told from the tilt: 15 mg allowed, not 105
    np.testing.assert_allclose(got, 1000.0 * UP_BODY, atol=15.0)
    assert abs(float(np.linalg.norm(got)) - 1000.0) < 1e-6
    what = ch["ax"]["known_input"]["what"]
    assert "measured direction" in what and "+z up" in what
    tilt = math.degrees(math.acos(UP_BODY[2]))  # 8.48°
    assert f"tilted {tilt:.0f}." in what or f"tilted {tilt - 1:.0f}." in what, what


def test_px4_accelerometer_parameters_of_a_tilted_board(soaks: tuple, tmp_path: Path) -> None:
    d, cal, _res = soaks
    for tref in (25.0, None):
        out = tmp_path / "imu.params"
        extra = ["--tref", str(tref)] if tref is not None else []
        code, _o, err = _run("export-params", str(cal), "--format", "px4", "-o", str(out),
                             "--device-id", "2490378", *extra)  # fmt: skip
        assert code == 0, err
        p = {}
        for line in out.read_text().splitlines():
            if not line.startswith("#"):
                _v, _c, name, value, _t = line.split("\t")
                p[name] = float(value)
        temps = np.concatenate([pd.read_csv(d / f)["temp"] for f in ("cold.csv", "hot.csv")])
        assert p["TC_A0_TMIN"] == pytest.approx(temps.min(), abs=0.01)
        assert p["TC_A0_TMAX"] == pytest.approx(temps.max(), abs=0.01)
        mid = 0.5 * (p["TC_A0_TMIN"] + p["TC_A0_TMAX"])
        tr = p["TC_A0_TREF"]
        assert tr == (tref if tref is not None else pytest.approx(mid))
        b_tref, b_mid = bias_mg(np.array([tr, mid]))
        for i in range(3):
            x0 = (b_tref[i] - b_mid[i]) * M_S2_PER_MG
            x1 = (S[i] + 2.0 * Q[i] * (tr - 25.0)) * M_S2_PER_MG
            x2 = Q[i] * M_S2_PER_MG
            assert p[f"TC_A0_X0_{i}"] == pytest.approx(x0, abs=0.15 * M_S2_PER_MG), (i, tref)
            assert p[f"TC_A0_X1_{i}"] == pytest.approx(x1, abs=0.01 * M_S2_PER_MG), (i, tref)
            assert p[f"TC_A0_X2_{i}"] == pytest.approx(x2, abs=3e-4 * M_S2_PER_MG), (i, tref)
            assert p[f"TC_A0_X3_{i}"] == 0.0
        assert "relative" in err or "CAL_ACC" in _o


def test_ardupilot_accelerometer_parameters_of_a_tilted_board(soaks: tuple, tmp_path: Path) -> None:
    _d, cal, _res = soaks
    out = tmp_path / "imu.parm"
    code, stdout, err = _run("export-params", str(cal), "--format", "ardupilot", "-o", str(out))
    assert code == 0, err
    p = dict(
        (ln.split()[0], float(ln.split()[1]))
        for ln in out.read_text().splitlines()
        if not ln.startswith("#")
    )
    for i, ax in enumerate("XYZ"):
        c1 = (S[i] + 20.0 * Q[i]) * M_S2_PER_MG * 1e6
        c2 = Q[i] * M_S2_PER_MG * 1e6
        assert p[f"INS_TCAL1_ACC1_{ax}"] == pytest.approx(c1, abs=0.01 * M_S2_PER_MG * 1e6), ax
        assert p[f"INS_TCAL1_ACC2_{ax}"] == pytest.approx(c2, abs=3e-4 * M_S2_PER_MG * 1e6), ax
        assert p[f"INS_TCAL1_ACC3_{ax}"] == 0.0
    assert "relative to the calibration temperature" in stdout


def test_a_lone_channel_says_the_direction_is_unknown(soaks: tuple, tmp_path: Path) -> None:
    d, _cal, _res = soaks
    model = tmp_path / "ax.json"
    code, _o, err = _run("fit", str(d / "cold.csv"), "--model", "poly", "--order", "1",
                         "--signal", "ax", "--signal-unit", "mg", "--temps", "temp",
                         "--temp-unit", "degC", "--gravity-axis", "+z", "--gravity", str(G0),
                         "-o", str(model))  # fmt: skip
    assert code == 0, err
    warned = [ln for ln in err.splitlines() if ln.startswith("warning:")]
    assert any("gravity direction is unknown" in ln for ln in warned), err
    ki = json.loads(model.read_text())["inputs"]["known_input"]
    assert ki["gravity"]["direction_measured"] is False and ki["value"] == 0.0
    assert "direction not measured" in ki["what"]
