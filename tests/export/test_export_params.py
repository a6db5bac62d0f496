"""Firmware parameters (issue 16): PX4 TC_* and ArduPilot INS_TCAL* from a calibration.

The firmware's corrections are written out here, independently, from the formulas of PX4's
TemperatureCompensation and ArduPilot's AP_InertialSensor_tempcal (INTERFACE.md):
PX4 subtracts ``X0 + X1·dT + X2·dT² + X3·dT³``, ``dT = clamp(T, TMIN, TMAX) − TREF`` [rad/s,
m/s²]; ArduPilot subtracts ``poly(clamp(T) − 35) − poly(T_cal − 35)``,
``poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6``.  Applied to the simulator's truth on the
validation run, each must remove ≥ 95 % of every axis's temperature-induced bias.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.simulate import SCENARIOS
from thermocal.writers import write_recording

G0 = 9.80665
GYROS, ACCELS = ("gx", "gy", "gz"), ("ax", "ay", "az")


@pytest.fixture(scope="module")
def setup(tmp_path_factory: pytest.TempPathFactory) -> dict:
    d = tmp_path_factory.mktemp("params")
    ((mod, truth),) = SCENARIOS["mems-imu"](11, rate_hz=0.2)
    ((val, _),) = SCENARIOS["mems-imu"](11, run="validation", rate_hz=0.2)
    write_recording(mod, d / "mod.parquet")
    cal = d / "cal.json"
    assert main(["fit", str(d / "mod.parquet"), "--model", "poly", "--order", "3", "--signal",
                 ",".join(GYROS + ACCELS), "--temps", "T_die", "--gravity-axis", "+z",
                 "--gravity", str(G0), "-o", str(cal)]) == 0  # fmt: skip
    return {"dir": d, "cal": cal, "val": val, "truth": truth}


def _px4(path: Path) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        _v, _c, name, value, typ = line.split("\t")
        out[name] = float(value)
        assert typ in ("6", "9")
    return out


def _removed(correction: np.ndarray, truth: np.ndarray, *, absolute: bool = True) -> float:
    """How much of the true thermal error the firmware's correction removes [%]: the rms of
    correction − truth against the rms of the truth about zero (absolute: a constant error
    in X0 counts), or about their means where the firmware's convention is relative (PX4's
    accelerometer offsets)."""
    if absolute:
        err = correction - truth
        return 100.0 * (1.0 - math.sqrt(float(np.mean(err**2) / np.mean(truth**2))))
    err = (correction - correction.mean()) - (truth - truth.mean())
    return 100.0 * (1.0 - math.sqrt(float(np.mean(err**2))) / float(np.std(truth)))


def test_px4_parameters_remove_95_percent(setup: dict, tmp_path: Path) -> None:
    out = tmp_path / "imu.params"
    assert main(["export-params", str(setup["cal"]), "--format", "px4", "-o", str(out),
                 "--device-id", "1310988"]) == 0  # fmt: skip
    p = _px4(out)
    val = setup["val"]
    T = val.column("T_die")
    for kind, chans, to_data in (("G", GYROS, 180.0 / math.pi), ("A", ACCELS, 1000.0 / G0)):
        assert p[f"TC_{kind}0_ID"] == 1310988 and p[f"TC_{kind}_ENABLE"] == 1
        dT = np.clip(T, p[f"TC_{kind}0_TMIN"], p[f"TC_{kind}0_TMAX"]) - p[f"TC_{kind}0_TREF"]
        for i, name in enumerate(chans):
            x = [p[f"TC_{kind}0_X{k}_{i}"] for k in range(4)]
            offset = x[0] + x[1] * dT + x[2] * dT**2 + x[3] * dT**3  # firmware unit
            # gyro offsets are absolute (the truth column leaves out the cubic's constant
            # c0: added back); accelerometer offsets relative to mid-range
            c0 = setup["truth"]["channels"][name]["coefficients"][0]
            truth = val.column(f"truth_{name}") + (c0 if kind == "G" else 0.0)
            removed = _removed(offset * to_data, truth, absolute=kind == "G")
            assert removed >= 95.0, (name, removed)


def test_px4_accel_offset_is_relative_to_mid_range(setup: dict, tmp_path: Path) -> None:
    """From one placement a horizontal bias cannot be told from the bench's tilt (issue 25):
    X0 is the true bias at TREF minus the true bias at mid-range, PX4's convention."""
    out = tmp_path / "imu.params"
    assert main(["export-params", str(setup["cal"]), "--format", "px4", "-o", str(out),
                 "--tref", "25", "--device-id", "1"]) == 0  # fmt: skip
    p = _px4(out)
    assert p["TC_A0_TREF"] == 25.0
    mid = 0.5 * (p["TC_A0_TMIN"] + p["TC_A0_TMAX"])
    for i, name in enumerate(ACCELS):
        c = setup["truth"]["channels"][name]["coefficients"]  # cubic in (T − 25)/40 [mg]
        want = c[0] - sum(cj * ((mid - 25.0) / 40.0) ** j for j, cj in enumerate(c))
        assert p[f"TC_A0_X0_{i}"] * 1000.0 / G0 == pytest.approx(want, abs=0.3), name


def test_ardupilot_parameters_remove_95_percent(setup: dict, tmp_path: Path) -> None:
    out = tmp_path / "imu.parm"
    assert main(["export-params", str(setup["cal"]), "--format", "ardupilot", "-o",
                 str(out)]) == 0  # fmt: skip
    p = {}
    for line in out.read_text().splitlines():
        if line.startswith("#"):
            continue
        name, value = line.split()
        p[name] = float(value)
    assert p["INS_TCAL1_ENABLE"] == 1
    val = setup["val"]
    T = np.clip(val.column("T_die"), p["INS_TCAL1_TMIN"], p["INS_TCAL1_TMAX"])
    t_cal = 25.0

    def poly(c: list[float], t: np.ndarray | float) -> np.ndarray:
        return np.asarray((c[0] + (c[1] + c[2] * t) * t) * t * 1e-6)

    for tag, chans, to_data in (("GYR", GYROS, 180.0 / math.pi), ("ACC", ACCELS, 1000.0 / G0)):
        for name, ax in zip(chans, "XYZ", strict=True):
            c = [p[f"INS_TCAL1_{tag}{k}_{ax}"] for k in (1, 2, 3)]
            corr = poly(c, T - 35.0) - poly(c, t_cal - 35.0)
            # ArduPilot corrects relative to the calibration temperature, 25 °C: the truth
            # column (the cubic in (T − 25)/40 less its constant) is zero there too
            removed = _removed(corr * to_data, val.column(f"truth_{name}"))
            assert removed >= 95.0, (name, removed)


def test_what_the_firmware_cannot_express_is_refused(
    setup: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    d = setup["dir"]
    rate = tmp_path / "rate.json"
    args = ["--signal", ",".join(GYROS), "--temps", "T_die"]
    assert main(["fit", str(d / "mod.parquet"), "--model", "poly", "--terms", "T1,T1^2,dT1",
                 *args, "-o", str(rate)]) == 0  # fmt: skip
    capsys.readouterr()
    assert main(["export-params", str(rate), "--format", "px4", "-o", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "temperature-rate term" in err and "--order 3" in err
    pw = tmp_path / "pw.json"
    assert main(["fit", str(d / "mod.parquet"), "--model", "piecewise", "--signal",
                 ",".join(GYROS), "--temps", "T_die", "-o", str(pw)]) == 0  # fmt: skip
    capsys.readouterr()
    assert main(["export-params", str(pw), "--format", "ardupilot", "-o",
                 str(tmp_path / "y")]) == 2  # fmt: skip
    assert "a piecewise model cannot be written" in capsys.readouterr().err
    assert not (tmp_path / "x").exists() and not (tmp_path / "y").exists()


def test_channels_without_roles_need_the_triad_named(
    setup: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "p.params"
    assert main(["export-params", str(setup["cal"]), "--format", "px4", "-o", str(out),
                 "--gyro", "gx,gy"]) == 2  # fmt: skip
    assert "three channels" in capsys.readouterr().err
    # an explicit mapping reorders the axes
    assert main(["export-params", str(setup["cal"]), "--format", "px4", "-o", str(out),
                 "--gyro", "gy,gx,gz", "--device-id", "1"]) == 0  # fmt: skip
    p = _px4(out)
    q = tmp_path / "q.params"
    assert main(["export-params", str(setup["cal"]), "--format", "px4", "-o", str(q),
                 "--device-id", "1"]) == 0  # fmt: skip
    r = _px4(q)
    assert p["TC_G0_X1_0"] == r["TC_G0_X1_1"] and p["TC_G0_X1_1"] == r["TC_G0_X1_0"]
