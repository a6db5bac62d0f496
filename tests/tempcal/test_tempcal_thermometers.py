"""Coarse, slow and borrowed thermometers through ``px4-tempcal`` and ``ardupilot-tempcal``.

A ULog (:mod:`ulog_writer`) holds two gyros on one clock over a sweep with a heater's
overshoot and an operator's pause: instance 0 reads a BMI088-like thermometer (0.125 °C
lattice, updated every 1.28 s), instance 1 a fine one (the true temperature, float32).  The
same gyro-0 data with the true temperature is the reference fit.  PX4's correction
(``offset = Σ X_k·(clamp(T, TMIN, TMAX) − TREF)^k``, written out here from the parameter
reference) of the reconstructed fit leaves a residual on the true temperature within 1.1×
of the reference fit's; borrowing instance 1's thermometer gives the reference fit's
parameters; the JSON states the lattice and the period."""

from __future__ import annotations

import contextlib
import io
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from dataflash_writer import imu_log
from thermocal.cli import main
from thermocal.pipeline.model_file import load_calibration
from ulog_writer import SENSOR_FIELDS, ulog_bytes

RATE_HZ = 20.0


def _truth() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(11)
    t = np.arange(0, 3000.0, 1 / RATE_HZ)
    ramp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * np.clip(t / 2700.0, 0, 1)))
    overshoot = 1.5 * np.exp(-(((t - 1300.0) / 100.0) ** 2))
    pause = np.where((t > 1800) & (t < 2000), 0.0, 1.0)
    true = np.cumsum(np.gradient(ramp + overshoot) * pause) + ramp[0]
    x = (true - 20.0) / 30.0
    bias = np.column_stack([0.01 + 0.02 * x - 0.006 * x**2 + 0.004 * x**3, -0.015 * x, 0.01 * x**2])
    meas = bias + rng.normal(0, 3e-4, bias.shape)
    phase = 0.41
    upd = np.maximum(np.floor((t - phase) / 1.28) * 1.28 + phase, 0.0)
    bmi = 23.0 + 0.125 * np.round((np.interp(upd, t, true) - 23.0) / 0.125)
    return {"t": t, "true": true, "bias": bias, "meas": meas, "bmi": bmi}


def _rows(ts: np.ndarray, dev: int, v: np.ndarray, temp: np.ndarray) -> list[tuple]:
    return [(int(s), dev, *map(float, r), float(c)) for s, r, c in zip(ts, v, temp, strict=True)]


@pytest.fixture(scope="module")
def logs(tmp_path_factory: pytest.TempPathFactory) -> dict:
    d = tmp_path_factory.mktemp("thermo")
    tr = _truth()
    ts = (1e6 + tr["t"] * 1e6).astype(np.int64)
    other = tr["meas"][:, ::-1] * 0.5
    two = d / "two.ulg"
    two.write_bytes(ulog_bytes([
        ("sensor_gyro", 0, SENSOR_FIELDS, _rows(ts, 11, tr["meas"], tr["bmi"])),
        ("sensor_gyro", 1, SENSOR_FIELDS, _rows(ts, 12, other, tr["true"])),
    ]))  # fmt: skip
    ref = d / "ref.ulg"
    ref.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS,
                                 _rows(ts, 11, tr["meas"], tr["true"]))]))  # fmt: skip
    return {"d": d, "two": two, "ref": ref, **tr}


def _run(args: list[str]) -> tuple[int, dict]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main([*args, "--json"])
    return code, json.loads(buf.getvalue()) if code == 0 else {}


def _params(path: Path) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if not line.startswith("#"):
            _v, _c, name, value, _t = line.split("\t")
            out[name] = float(value)
    return out


def _px4_offset(p: dict[str, float], inst: int, temp: np.ndarray) -> np.ndarray:
    """PX4's TemperatureCompensation: Σ X_k (clamp(T, TMIN, TMAX) − TREF)^k per axis."""
    g = f"TC_G{inst}_"
    dt = np.clip(temp, p[g + "TMIN"], p[g + "TMAX"]) - p[g + "TREF"]
    return np.column_stack([sum(p[f"{g}X{k}_{i}"] * dt**k for k in range(4)) for i in range(3)])


def _residual(p: dict[str, float], logs: dict) -> float:
    """The rms residual after PX4's correction, evaluated on the true temperature."""
    return float(np.sqrt(np.mean((logs["meas"] - _px4_offset(p, 0, logs["true"])) ** 2)))


def test_px4_reconstructed_raw_and_borrowed(logs: dict) -> None:
    d = logs["d"]
    code, ref = _run(["px4-tempcal", str(logs["ref"]), "-o", str(d / "ref")])
    assert code == 0
    assert ref["sensors"]["sensor_gyro.0"]["thermometer"]["kind"] == "continuous"
    code, rec = _run(["px4-tempcal", str(logs["two"]), "-o", str(d / "rec")])
    assert code == 0
    th = rec["sensors"]["sensor_gyro.0"]["thermometer"]
    assert th["step_c"] == pytest.approx(0.125, abs=1e-9)
    assert th["update_period_s"] == pytest.approx(1.28, abs=0.02)
    assert th["quantised"] and th["slow"] and th["temperature"] == "reconstructed"
    assert th["source"] == "sensor_gyro.0"
    assert not rec["sensors"]["sensor_gyro.1"]["thermometer"]["quantised"]
    assert any("sensor_gyro.0: the thermometer is quantised" in n for n in rec["notes"])
    cal = json.loads((d / "rec" / "calibration.json").read_text())
    assert "0.125" in json.dumps(cal)  # the calibration records the thermometer
    channel = load_calibration(d / "rec" / "calibration.json").channels[0]  # and reads back
    assert channel.model.inputs_["thermometer"]["step_c"] == pytest.approx(0.125, abs=1e-9)
    p_ref, p_rec = _params(d / "ref" / "px4.params"), _params(d / "rec" / "px4.params")
    assert _residual(p_rec, logs) <= 1.1 * _residual(p_ref, logs)
    code, raw = _run(["px4-tempcal", str(logs["two"]), "-o", str(d / "raw"),
                      "--temperature", "raw"])  # fmt: skip
    assert code == 0
    assert raw["sensors"]["sensor_gyro.0"]["thermometer"]["temperature"] == "raw"
    # borrowed: instance 1's thermometer, on the same clock, is the true temperature
    code, bor = _run(["px4-tempcal", str(logs["two"]), "-o", str(d / "bor"),
                      "--temps-from", "0=1"])  # fmt: skip
    assert code == 0
    assert bor["sensors"]["sensor_gyro.0"]["thermometer"]["source"] == "sensor_gyro.1"
    assert bor["sensors"]["sensor_gyro.1"]["thermometer"]["source"] == "sensor_gyro.1"
    assert any("calibrated against sensor_gyro.1's thermometer" in n for n in bor["notes"])
    p_bor = _params(d / "bor" / "px4.params")
    for i in range(3):
        for k in range(4):
            key = f"TC_G0_X{k}_{i}"
            assert p_bor[key] == pytest.approx(p_ref[key], rel=1e-6, abs=1e-12), key


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--temps-from", "5"], "--temps-from names sensor_gyro/sensor_accel instance 5"),
        (["--temps-from", "baro"], "--temps-from names sensor_baro"),
        (["--temps-from", "one"], "--temps-from 'one': give an instance number"),
        (["--temperature", "smooth"], "--temperature 'smooth': give reconstructed or raw"),
    ],
)
def test_px4_hostile_thermometer_options(
    logs: dict, args: list[str], words: str, capsys: pytest.CaptureFixture[str]
) -> None:
    before = logs["two"].read_bytes()
    out = logs["d"] / "bad"
    assert main(["px4-tempcal", str(logs["two"]), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and words in err[0], err
    assert not out.exists() and logs["two"].read_bytes() == before


def test_px4_constant_temperature_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tr = _truth()
    ts = (1e6 + tr["t"] * 1e6).astype(np.int64)
    log = tmp_path / "flat.ulg"
    flat = np.full(ts.size, 40.125)  # a lattice with a single level
    log.write_bytes(
        ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, _rows(ts, 11, tr["meas"], flat))])
    )
    assert main(["px4-tempcal", str(log), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    errors = [e for e in err if e.startswith("error: ")]
    assert len(errors) == 1 and err[-1] == errors[0] and "bins" in errors[0], err
    assert not (tmp_path / "o").exists()


def _ap_rows(tr: dict, inst: int, temp: np.ndarray) -> list[tuple]:
    """IMU rows (TimeUS, I, GyrX…Z, AccX…Z, EG, EA, T) of one instance."""
    acc = np.column_stack(
        [0.05 + 0.1 * tr["bias"][:, 0], 0.02 * tr["bias"][:, 1], -9.80665 + 0.0 * tr["t"]]
    )
    acc = acc + np.random.default_rng(inst).normal(0, 0.01, acc.shape)
    ts = (1e6 + tr["t"] * 1e6).astype(np.int64)
    return [
        (int(s), inst, *map(float, g), *map(float, a), 0, 0, float(c))
        for s, g, a, c in zip(ts, tr["meas"], acc, temp, strict=True)
    ]


def _parm(path: Path) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if line and not line.startswith("#"):
            name, value = line.split()
            out[name] = float(value)
    return out


def test_ardupilot_whole_degrees_and_borrowed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tr = _truth()
    whole = np.round(tr["true"])  # a Bosch whole-degree thermometer
    rows = sorted(_ap_rows(tr, 0, whole) + _ap_rows(tr, 1, tr["true"]), key=lambda r: (r[0], r[1]))
    two = tmp_path / "two.bin"
    two.write_bytes(imu_log(rows))
    ref = tmp_path / "ref.bin"
    ref.write_bytes(imu_log(_ap_rows(tr, 0, tr["true"])))
    code, out = _run(["ardupilot-tempcal", str(two), "-o", str(tmp_path / "rec")])
    assert code == 0
    th = out["sensors"]["IMU.Gyr.0"]["thermometer"]
    assert th["step_c"] == pytest.approx(1.0, abs=1e-6) and th["quantised"] and not th["slow"]
    assert th["temperature"] == "reconstructed" and th["source"] == "IMU.0"
    assert sum("IMU.0: the thermometer is quantised (1 °C)" in n for n in out["notes"]) == 1
    code, _ = _run(["ardupilot-tempcal", str(ref), "-o", str(tmp_path / "ref")])
    assert code == 0
    code, bor = _run(
        ["ardupilot-tempcal", str(two), "-o", str(tmp_path / "bor"), "--temps-from", "0=1"]
    )
    assert code == 0
    assert bor["sensors"]["IMU.Acc.0"]["thermometer"]["source"] == "IMU.1"
    p_ref, p_bor = (
        _parm(tmp_path / "ref" / "ardupilot.parm"),
        _parm(tmp_path / "bor" / "ardupilot.parm"),
    )
    for tag in ("GYR", "ACC"):
        for k in (1, 2, 3):
            for ax in "XYZ":
                key = f"INS_TCAL1_{tag}{k}_{ax}"
                assert p_bor[key] == pytest.approx(p_ref[key], rel=1e-5, abs=1e-9), key
    capsys.readouterr()
    assert (
        main(["ardupilot-tempcal", str(two), "-o", str(tmp_path / "bad"), "--temps-from", "baro"])
        == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--temps-from names BARO.0" in err[0] and "IMU.0, IMU.1" in err[0], err


BARO = [("uint64_t", "timestamp"), ("uint32_t", "device_id"), ("float", "pressure"),
        ("float", "temperature")]  # fmt: skip
"""PX4 ``msg/SensorBaro.msg`` (the fields read)."""


def test_px4_gyro_against_the_barometer_thermometer(logs: dict) -> None:
    """A whole-degree gyro 0 and a barometer at 10 Hz (its own instants, 0.01 °C noise) whose
    thermometer reads the true temperature: ``--temps-from baro`` fits the gyro on it; PX4's
    correction leaves a residual on the true temperature within 1.1× of the reference fit's."""
    d = logs["d"]
    ts = (1e6 + logs["t"] * 1e6).astype(np.int64)
    tb = np.arange(0.0, logs["t"][-1], 0.1) + 0.037
    rng = np.random.default_rng(3)
    baro_t = np.interp(tb, logs["t"], logs["true"]) + rng.normal(0, 0.01, tb.size)
    press = 101325.0 + 5.0 * (baro_t - 20.0) + rng.normal(0, 1.0, tb.size)
    rows_b = [(int(1e6 + s * 1e6), 22, float(p), float(c))
              for s, p, c in zip(tb, press, baro_t, strict=True)]  # fmt: skip
    log = d / "baro.ulg"
    log.write_bytes(ulog_bytes([
        ("sensor_gyro", 0, SENSOR_FIELDS, _rows(ts, 11, logs["meas"], np.round(logs["true"]))),
        ("sensor_baro", 0, BARO, rows_b),
    ]))  # fmt: skip
    code, out = _run(["px4-tempcal", str(log), "-o", str(d / "baro"), "--temps-from", "baro"])
    assert code == 0
    th = out["sensors"]["sensor_gyro.0"]["thermometer"]
    assert th["source"] == "sensor_baro.0" and not th["quantised"]
    assert th["samples_kept"] >= logs["t"].size - 2
    if not (d / "ref" / "px4.params").exists():
        assert _run(["px4-tempcal", str(logs["ref"]), "-o", str(d / "ref")])[0] == 0
    p_ref, p_bar = _params(d / "ref" / "px4.params"), _params(d / "baro" / "px4.params")
    assert _residual(p_bar, logs) <= 1.1 * _residual(p_ref, logs)


def test_borrowed_thermometer_reading_apart_is_said() -> None:
    """The sensor's own thermometer 3 °C above the borrowed one: the median difference is
    recorded and said in a warning."""
    from thermocal.recording import Recording
    from thermocal.tempcal.thermometers import TemperatureSeries, sensor_temperature
    from thermocal.thermometer import ThermometerWarning

    t = np.arange(0, 600.0, 0.01)
    true = 20.0 + 0.02 * t
    rec = Recording.from_arrays(
        t, {a: np.zeros(t.size) for a in "xyz"}, {"temperature": true + 3.0},
        signal_unit="rad/s",
    )  # fmt: skip
    src = TemperatureSeries("sensor_baro.0", t[::10], true[::10])
    with pytest.warns(ThermometerWarning, match=r"reads \+3.00 °C from sensor_baro.0's"):
        out, said = sensor_temperature(rec, "sensor_gyro.0", source=src)
    assert said["own_minus_source_c"] == pytest.approx(3.0, abs=1e-9)
    assert np.allclose(out.temperature_c("temperature"), true, rtol=0, atol=2e-3)  # end held
    close = TemperatureSeries("sensor_baro.0", t[::10], true[::10] + 2.9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _out, said = sensor_temperature(rec, "sensor_gyro.0", source=close)
    assert said["own_minus_source_c"] == pytest.approx(0.1, abs=1e-9)


def test_ardupilot_imu_against_the_barometer(tmp_path: Path) -> None:
    """The barometer log of :func:`test_fc_reports.baro_log` (IMU temperature continuous,
    BARO.0's ``Temp`` the same in hundredths of a degree, 10 µs later): ``--temps-from baro``
    fits IMU 0 on BARO.0's thermometer; the two agree (median own − borrowed within the
    rounding) and the coefficients are those of the IMU's own thermometer."""
    from test_fc_reports import baro_log

    log = tmp_path / "baro.bin"
    baro_log(log, 1.35, +1.0)
    code, own = _run(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "own")])
    assert code == 0
    code, bor = _run(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "bor"),
                      "--temps-from", "baro"])  # fmt: skip
    assert code == 0
    th = bor["sensors"]["IMU.Gyr.0"]["thermometer"]
    assert th["source"] == "BARO.0" and th["samples_kept"] == 12000
    assert abs(th["own_minus_source_c"]) <= 0.005
    assert own["sensors"]["IMU.Gyr.0"]["thermometer"]["own_minus_source_c"] is None
    p_own, p_bor = (
        _parm(tmp_path / "own" / "ardupilot.parm"),
        _parm(tmp_path / "bor" / "ardupilot.parm"),
    )
    for ax in "XYZ":
        key = f"INS_TCAL1_GYR1_{ax}"
        assert p_bor[key] == pytest.approx(p_own[key], rel=0.02, abs=1.0), key
