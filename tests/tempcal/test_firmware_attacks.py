"""Hostile flight-controller logs and calibrations against the firmware outputs (issue 39,
items 2 and 9 and the ArduPilot barometer "Also" items).

Every log is written here from the formats' descriptions (:mod:`ulog_writer`,
:mod:`dataflash_writer`), run through the CLI, hashed before and after.  Each attack ends in
exit 2 with one ``error:`` line naming the parameter and no output, or in exit 0 with an
explicit ``warning:`` and numbers checked against the simulator's truth through the
firmware's own formula written here:

* PX4 ``TemperatureCompensation``: ``offset = Σ X_k·(clamp(T, TMIN, TMAX) − TREF)^k``
  subtracted from the measurement (parameter reference ``TC_B0_X0…X5``);
* ArduPilot ``AP_TempCalibration::calculate_correction``: ``max(T − 25, 0)^e`` added to the
  pressure.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from ulog_writer import SENSOR_FIELDS, ulog_bytes

BARO = [("uint64_t", "timestamp"), ("uint32_t", "device_id"), ("float", "pressure"),
        ("float", "temperature")]  # fmt: skip
N = 12000
DT = 0.1


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def _px4_params(path: Path) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if not line.startswith("#"):
            _v, _c, name, value, _t = line.split("\t")
            out[name] = float(value)
    return out


def _sweep() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.arange(N) * DT
    temp = -5.0 + 55.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    return t, temp, (temp - 20.0) / 25.0


def _baro_bias(x: np.ndarray) -> np.ndarray:
    return 40.0 * x + 12.0 * x**2 - 9.0 * x**3 + 4.0 * x**5  # [Pa]


def _good_pressure(t: np.ndarray, x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    return 101325.0 + _baro_bias(x) + rng.normal(0.0, 1.0, t.size)


def _good_mag(t: np.ndarray, x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    bias = np.column_stack([0.01 * x, -0.006 * x + 0.004 * x**3, 0.008 * x**2])
    return np.array([0.2, 0.05, -0.4]) + bias + rng.normal(0.0, 5e-4, (t.size, 3))


Gen = Callable[[np.ndarray, np.ndarray, np.random.Generator], np.ndarray]


def _ulog(path: Path, *, gyro_scale: float = 1.0, pressure: Gen | None = None,
          mag: Gen | None = None, gyro_noise: float = 1e-3,
          gyro_offset: float = 0.0) -> np.ndarray:  # fmt: skip
    """A still board's ULog: a gyro (rad/s: ``gyro_offset`` + noise ``gyro_noise`` + drift,
    × ``gyro_scale``), optionally a barometer and a magnetometer; returns the temperature."""
    rng = np.random.default_rng(8)
    t, temp, x = _sweep()
    ts = (1e6 + t * 1e6).astype(np.int64)
    g = gyro_offset + rng.normal(0, gyro_noise, (N, 3)) + np.outer(x, [2e-3, -1e-3, 3e-3])
    g *= gyro_scale
    rows = lambda dev, v: [  # noqa: E731
        (int(s), dev, *np.atleast_1d(r).astype(float), float(c))
        for s, r, c in zip(ts, v, temp, strict=True)
    ]
    topics = [("sensor_gyro", 0, SENSOR_FIELDS, rows(11, g))]
    if pressure is not None:
        topics.append(("sensor_baro", 0, BARO, rows(22, pressure(t, x, rng))))
    if mag is not None:
        topics.append(("sensor_mag", 0, SENSOR_FIELDS, rows(33, mag(t, x, rng))))
    path.write_bytes(ulog_bytes(topics))
    return temp


def _px4(tmp_path: Path, **kw: Gen | float | None) -> tuple[int, str, dict[str, float], np.ndarray]:
    log = tmp_path / "bench.ulg"
    temp = _ulog(log, **kw)  # type: ignore[arg-type]
    before = _digest(log)
    code, _out, err = _run(["px4-tempcal", str(log), "-o", str(tmp_path / "out")])
    assert _digest(log) == before
    assert "Traceback" not in err and code in (0, 2), err
    params = tmp_path / "out" / "px4.params"
    return code, err, (_px4_params(params) if params.exists() else {}), temp


def _warnings(err: str) -> list[str]:
    return [ln for ln in err.splitlines() if ln.startswith("warning:")]


def _removed(p: dict[str, float], temp: np.ndarray, truth: np.ndarray) -> float:
    """The share of the simulated drift PX4's correction removes [%] (module docstring)."""
    t32 = temp.astype(np.float32).astype(np.float64)
    dt = np.clip(t32, p["TC_B0_TMIN"], p["TC_B0_TMAX"]) - p["TC_B0_TREF"]
    corr = sum(p[f"TC_B0_X{k}"] * dt**k for k in range(6))
    err = (corr - corr.mean()) - (truth - truth.mean())
    return 100.0 * (1.0 - float(np.sqrt(np.mean(err**2))) / float(np.std(truth)))


# --- PX4 barometer -----------------------------------------------------------------------------


def test_baro_3e38_every_7th_sample_is_set_aside_and_the_rest_fitted(tmp_path: Path) -> None:
    def spiky(t: np.ndarray, x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        p = _good_pressure(t, x, rng)
        p[::7] = 3e38
        return p

    code, err, p, temp = _px4(tmp_path, pressure=spiky)
    assert code == 0, err
    n_bad = len(range(0, N, 7))
    said = [w for w in _warnings(err) if "sensor_baro.0" in w]
    assert len(said) == 1 and f"{n_bad} of {N} samples set aside" in said[0], err
    assert abs(p["TC_B0_X0"]) < 100.0  # was 1.9e36
    _t, _temp, x = _sweep()
    assert _removed(p, temp, _baro_bias(x)) >= 95.0


def _hpa(t: np.ndarray, x: np.ndarray, r: np.random.Generator) -> np.ndarray:
    return _good_pressure(t, x, r) / 100.0


def _kpa(t: np.ndarray, x: np.ndarray, r: np.random.Generator) -> np.ndarray:
    return _good_pressure(t, x, r) / 1000.0


def _all_nan(t: np.ndarray, x: np.ndarray, r: np.random.Generator) -> np.ndarray:
    return np.full(t.size, np.nan)


def _climb(t: np.ndarray, x: np.ndarray, r: np.random.Generator) -> np.ndarray:
    """A 600 Pa climb (about 50 m) between 400 s and 500 s."""
    return _good_pressure(t, x, r) - 600.0 * np.clip((t - 400.0) / 100.0, 0.0, 1.0)


@pytest.mark.parametrize(
    ("name", "gen", "said"),
    [
        ("hPa", _hpa, "hPa"),
        ("kPa", _kpa, "kPa"),
        ("nan", _all_nan, "no finite value"),
        ("climb", _climb, "carried"),
    ],
    ids=["hPa", "kPa", "all-nan", "climb-600Pa"],
)
def test_baro_that_no_still_board_reads_is_left_out(
    tmp_path: Path, name: str, gen: Gen, said: str
) -> None:
    code, err, p, _temp = _px4(tmp_path, pressure=gen)
    assert code == 0, err
    w = [x for x in _warnings(err) if "sensor_baro.0" in x]
    assert len(w) == 1 and said in w[0] and "left out" in w[0], err
    assert "'pressure'" in w[0] or name == "climb"
    assert not any(k.startswith("TC_B") for k in p), p
    assert p["TC_G_ENABLE"] == 1 and "TC_G0_X0_0" in p  # the gyro is still calibrated
    if name == "climb":  # the span named lies in the simulated climb (400…500 s)
        span = w[0].split("fastest between ")[1].split(" of the log")[0]
        a, b = (float(v) for v in span.replace(" s", "").split(" and "))
        assert a >= 400.0 and b <= 501.0 and b - a >= 59.0, w[0]


# --- PX4 magnetometer --------------------------------------------------------------------------


def _mag_ut(t: np.ndarray, x: np.ndarray, r: np.random.Generator) -> np.ndarray:
    return _good_mag(t, x, r) * 100.0


def _mag_mgauss(t: np.ndarray, x: np.ndarray, r: np.random.Generator) -> np.ndarray:
    return _good_mag(t, x, r) * 1000.0


def _turning(t: np.ndarray, x: np.ndarray, r: np.random.Generator) -> np.ndarray:
    """A vehicle turning 180° about z over the log."""
    return np.column_stack(
        [0.45 * np.cos(t / 100.0), 0.45 * np.sin(t / 100.0), np.full(t.size, -0.2)]
    )


@pytest.mark.parametrize(
    ("gen", "said"),
    [(_mag_ut, "µT"), (_mag_mgauss, "milligauss"), (_turning, "turns by up to")],
    ids=["uT-as-gauss", "mgauss-as-gauss", "turning"],
)
def test_mag_that_no_still_board_reads_is_left_out(tmp_path: Path, gen: Gen, said: str) -> None:
    code, err, p, _temp = _px4(tmp_path, mag=gen)
    assert code == 0, err
    w = [x for x in _warnings(err) if "sensor_mag.0" in x]
    assert len(w) == 1 and said in w[0] and "left out" in w[0], err
    assert not any(k.startswith("TC_M") for k in p), p
    if said == "turns by up to":
        # the field turns through 180° about z: the largest angle from the median direction
        # computed here from the simulated field
        t = np.arange(N) * DT
        b = np.column_stack([np.cos(t / 100.0), np.sin(t / 100.0), np.full(N, -0.2 / 0.45)])
        b /= np.linalg.norm(b, axis=1, keepdims=True)
        med = np.median(b, axis=0)
        med /= np.linalg.norm(med)
        worst = float(np.degrees(np.max(np.arccos(np.clip(b @ med, -1, 1)))))
        got = float(w[0].split("turns by up to ")[1].split("°")[0])
        assert got == pytest.approx(worst, abs=2.0)


def test_good_baro_and_mag_are_not_warned(tmp_path: Path) -> None:
    code, err, p, temp = _px4(tmp_path, pressure=_good_pressure, mag=_good_mag)
    assert code == 0 and not _warnings(err), err
    _t, _temp, x = _sweep()
    assert _removed(p, temp, _baro_bias(x)) >= 95.0


def test_gyro_in_deg_s_in_the_rad_s_topic_is_warned(tmp_path: Path) -> None:
    code, err, p, _temp = _px4(tmp_path, gyro_scale=180.0 / math.pi)
    assert code == 0, err
    w = [x for x in _warnings(err) if "sensor_gyro.0" in x]
    assert len(w) == 1 and "deg/s" in w[0] and "rad/s" in w[0], err
    # the noise said: 1e-3 rad/s × 57.3 per sample, computed here
    got = float(w[0].split("a noise of ")[1].split(" rad/s")[0])
    assert got == pytest.approx(1e-3 * 180.0 / math.pi, rel=0.05)
    assert "TC_G0_X0_0" in p


def test_gyro_bias_beyond_att_bias_max_is_warned(tmp_path: Path) -> None:
    """The audit's case: a gyro logged in deg/s whose bias of 0.117 °/s is read as 0.117
    rad/s (6.7 °/s), with little noise: PX4's ATT_BIAS_MAX is 0.05 rad/s."""
    code, err, p, _temp = _px4(tmp_path, gyro_offset=0.117, gyro_noise=1e-4)
    assert code == 0, err
    w = [x for x in _warnings(err) if "sensor_gyro.0" in x]
    assert len(w) == 1 and "median rate of" in w[0] and "ATT_BIAS_MAX" in w[0], err
    got = float(w[0].split("median rate of ")[1].split(" rad/s")[0])
    _t, _temp, x = _sweep()
    want = max(abs(np.median(0.117 + k * x)) for k in (2e-3, -1e-3, 3e-3))
    assert got == pytest.approx(want, rel=1e-3)
    assert p["TC_G0_X0_0"] == pytest.approx(0.117, abs=0.01)


# --- ArduPilot barometer -----------------------------------------------------------------------


Curve = Callable[[np.ndarray], np.ndarray]


def _ap_log(
    path: Path, press_of: Curve, baro_temp_of: Curve = lambda t: t, gyro_scale: float = 1.0
) -> np.ndarray:
    """A DataFlash log: one still IMU (−10…50 °C, test_fc_log_readers.imu_truth) and a
    barometer at ``baro_temp_of(T)`` reading ``press_of(T_baro)`` [Pa]."""
    from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log
    from fc_logs import imu_truth
    from test_fc_reports import BARO_FORMAT, BARO_TYPE

    m = imu_truth(12000, 9, 1.0)
    tb100 = np.round(baro_temp_of(m["temp"]) * 100.0)
    press = press_of(tb100 / 100.0)
    msgs: list = []
    for i in range(m["temp"].size):
        gyro = m["gyro_meas"][i] * gyro_scale
        msgs.append((100, (int(m["time_us"][i]), 0, *gyro, *m["accel_meas"][i],
                           0, 0, float(m["temp"][i]), 1, 1, 1000, 1000)))  # fmt: skip
        msgs.append((BARO_TYPE, (int(m["time_us"][i]) + 10, 0, 0.0, 0.0, float(press[i]),
                                 int(tb100[i]), 0.0, 0, 0.0, 20.0, 1)))  # fmt: skip
    fmts = [PARM_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS), BARO_FORMAT]
    path.write_bytes(dataflash_log(fmts, msgs))
    return tb100 / 100.0


def _ap(
    tmp_path: Path, press_of: Curve, baro_temp_of: Curve = lambda t: t, gyro_scale: float = 1.0
) -> tuple[int, str, dict[str, float]]:
    log = tmp_path / "bench.bin"
    _ap_log(log, press_of, baro_temp_of, gyro_scale)
    before = _digest(log)
    code, _out, err = _run(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")])
    assert _digest(log) == before and "Traceback" not in err, err
    parm = tmp_path / "out" / "ardupilot.parm"
    out = {}
    if parm.exists():
        for line in parm.read_text().splitlines():
            if line and not line.startswith("#"):
                k, v = line.split()
                out[k] = float(v)
    return code, err, out


def test_ardupilot_gyro_in_deg_s_is_warned(tmp_path: Path) -> None:
    """IMU.GyrX/Y/Z are rad/s (LogStructure.h); a driver's deg/s (×57.3): warned, as PX4's."""
    code, err, p = _ap(
        tmp_path, lambda t: 101325.0 - np.maximum(t - 25.0, 0.0) ** 1.35,
        gyro_scale=180.0 / math.pi,
    )  # fmt: skip
    assert code == 0, err
    w = [x for x in _warnings(err) if "IMU.0 gyro" in x]
    assert len(w) == 1 and "deg/s" in w[0], err
    assert "INS_TCAL1_GYR1_X" in p


def test_ardupilot_baro_at_a_limit_is_not_enabled(tmp_path: Path) -> None:
    """A pressure that rises with T: the firmware's max(T − 25, 0)^e (added) cannot follow;
    TCAL_ENABLED 1 would add up to (50 − 25)^0 = 1 Pa or (50 − 25)^2 = 625 Pa."""
    code, err, p = _ap(tmp_path, lambda t: 101325.0 + np.maximum(t - 25.0, 0.0) ** 1.2)
    assert code == 0, err
    w = [x for x in _warnings(err) if "TCAL_BARO_EXP" in x]
    assert len(w) == 1 and "at a limit" in w[0] and "TCAL_ENABLED 0" in w[0], err
    assert p["TCAL_ENABLED"] == 0


def test_ardupilot_baro_nan_samples_are_counted(tmp_path: Path) -> None:
    def press(t: np.ndarray) -> np.ndarray:
        p = 101325.0 - np.maximum(t - 25.0, 0.0) ** 1.35
        p[::5] = np.nan
        return p

    code, err, p = _ap(tmp_path, press)
    assert code == 0, err
    w = [x for x in _warnings(err) if "BARO.0" in x]
    assert len(w) == 1 and f"{len(range(0, 12000, 5))} of 12000 samples set aside" in w[0], err
    assert "'Press'" not in w[0] or "Press" in w[0]
    assert p["TCAL_ENABLED"] == 1 and p["TCAL_BARO_EXP"] == pytest.approx(1.35, abs=0.02)


def test_ardupilot_baro_all_nan_is_named_not_fitted(tmp_path: Path) -> None:
    code, err, p = _ap(tmp_path, lambda t: np.full(t.size, np.nan))
    assert code == 0, err
    w = [x for x in _warnings(err) if "BARO.0" in x]
    assert len(w) == 1 and "'Press'" in w[0] and "no finite value" in w[0], err
    assert not any(k.startswith("TCAL_") for k in p)


def test_ardupilot_baro_sweep_beyond_int8_is_said(tmp_path: Path) -> None:
    """A barometer swept to 150 °C: TCAL_TEMP_MAX is an AP_Int8 (AP_TempCalibration.h),
    at most 127."""
    code, err, p = _ap(tmp_path, lambda t: 101325.0 - np.maximum(t - 25.0, 0.0) ** 1.35,
                       lambda t: 25.0 + (t + 10.0) * 125.0 / 60.0)  # fmt: skip
    assert code == 0, err
    assert p["TCAL_TEMP_MAX"] == 127
    w = [x for x in _warnings(err) if "int8" in x]
    assert len(w) == 1 and "150.0 °C" in w[0] and "127" in w[0], err


# --- export-params of a triad (item 9) ---------------------------------------------------------


def _triad_cal(path: Path, scale: float, offset_mg: float) -> None:
    """An accelerometer triad whose firmware scale is ``scale`` (the model's
    ``1 + s = 1/scale``) and x offset ``offset_mg``."""
    from thermocal.models.calibration import Calibration, Triad
    from thermocal.pipeline.model_file import save_calibration
    from thermocal.turntable import thermal

    th = np.zeros(12)
    th[0:3] = [offset_mg, -5.0, 3.0]  # mg
    th[3:6] = [(1.0 / scale - 1.0) * 1e6, 1000.0, -2000.0]  # ppm
    m = thermal.constant_triad("accel", 25.0, th, np.eye(12) * 1e-4, method="multipos")
    cols = ("ax [m/s^2]", "ay [m/s^2]", "az [m/s^2]")
    save_calibration(Calibration([], [Triad("accel", cols, "m/s^2", "", m)]), path)


@pytest.mark.parametrize("fmt", ["px4", "ardupilot"])
@pytest.mark.parametrize(
    ("scale", "offset_mg", "device_id", "names"),
    [
        (2.0, 10.0, None, "XSCALE|INS_ACCSCAL_X"),
        (0.102, 10.0, None, "XSCALE|INS_ACCSCAL_X"),
        (1.0, 5000.0, None, "XOFF|INS_ACCOFFS_X"),
        (1.0, 10.0, 2**31, "CAL_ACC0_ID"),
    ],
    ids=["scale-2.0", "scale-0.102", "offset-5g", "device-id-2^31"],
)
def test_triad_values_no_firmware_takes_are_refused(
    tmp_path: Path, fmt: str, scale: float, offset_mg: float, device_id: int | None, names: str
) -> None:
    cal = tmp_path / "c.json"
    _triad_cal(cal, scale, offset_mg)
    before = _digest(cal)
    out = tmp_path / "p.params"
    args = ["export-params", str(cal), "--format", fmt, "-o", str(out)]
    if device_id is not None:
        args += ["--device-id", str(device_id)]
    code, _o, err = _run(args)
    assert _digest(cal) == before
    if fmt == "ardupilot" and device_id is not None:  # ArduPilot has no device id parameter
        assert code == 0, err
        return
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2 and len(errors) == 1, err
    assert any(n in errors[0] for n in names.split("|")), errors[0]
    assert not out.exists()
    if "SCALE" in names and fmt == "px4":
        got = float(errors[0].split(" = ")[1].split(":")[0])
        assert got == pytest.approx(scale, rel=1e-9)


def test_triad_px4_values_in_range_are_written(tmp_path: Path) -> None:
    """A 3 % scale error and a 10 mg offset: written, PX4's a_c = SCALE·(a − OFF) with the
    triad model x = (1 + s)·a + b inverted here."""
    cal = tmp_path / "c.json"
    _triad_cal(cal, 1.0 / 1.03, 10.0)
    out = tmp_path / "p.params"
    code, _o, err = _run(["export-params", str(cal), "--format", "px4", "-o", str(out),
                          "--device-id", "3604490"])  # fmt: skip
    assert code == 0, err
    p = _px4_params(out)
    assert p["CAL_ACC0_XSCALE"] == pytest.approx(1.0 / 1.03, rel=1e-9)
    assert p["CAL_ACC0_XOFF"] == pytest.approx(10.0 * 9.80665e-3, rel=1e-9)
    assert p["CAL_ACC0_ID"] == 3604490


# --- every parameter against what the firmware documents (What to build 3) ---------------------


def _gyro_cal(path: Path, lo: float, hi: float) -> None:
    """Three gyro channels (°/h), a cubic in T fitted over ``lo``…``hi`` °C."""
    import warnings

    from thermocal.models.calibration import Calibration, Channel
    from thermocal.models.poly import PolyModel
    from thermocal.models.rundata import RunData
    from thermocal.pipeline.model_file import save_calibration

    temp = np.linspace(lo, hi, 400)
    u = (temp - 35.0) / 40.0
    chans = []
    for j, axis in enumerate("xyz"):
        run = RunData(
            np.arange(temp.size, dtype=np.float64), temp.reshape(-1, 1),
            (j + 1) * (40.0 * u + 10.0 * u**3), ("temperature",), name=f"g{axis}",
            signal_unit="deg/h",
        )  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = PolyModel(order=3, per_run_offset=False).fit([run])
        model.signal_name, model.signal_unit = axis, "deg/h"
        role = {"kind": "gyro", "axis": axis, "instance": 0}
        chans.append(Channel(f"g{axis}", axis, "deg/h", model, role))
    save_calibration(Calibration(chans), path)


def test_ins_tcal_tmax_beyond_its_documented_range_is_warned(tmp_path: Path) -> None:
    """INS_TCALn_TMAX ``@Range: -70 80`` (AP_InertialSensor_tempcal.cpp): a calibration
    fitted to 95 °C is written (the firmware clamps T to it) with a warning naming it."""
    cal = tmp_path / "c.json"
    _gyro_cal(cal, 0.0, 95.0)
    before = _digest(cal)
    out = tmp_path / "a.parm"
    code, _o, err = _run(["export-params", str(cal), "--format", "ardupilot", "-o", str(out)])
    assert code == 0 and _digest(cal) == before, err
    w = [x for x in _warnings(err) if "INS_TCAL1_TMAX" in x]
    assert len(w) == 1 and "= 95.0" in w[0] and "-70…80" in w[0], err
    assert "INS_TCAL1_TMAX 95.0" in out.read_text()
    # within the range: no such warning
    _gyro_cal(cal, 0.0, 70.0)
    code, _o, err = _run(["export-params", str(cal), "--format", "ardupilot", "-o", str(out)])
    assert code == 0 and "INS_TCAL1_T" not in err, err
