"""Heated IMUs through ``px4-tempcal`` and ``ardupilot-tempcal`` (and the library calls
under them): logs written here as a heated board records them (tests/helpers/fc_logs.py:
boot at 15 °C, the heater's ramp to 55 °C, its overshoot, a ±0.3 °C hold, the heater turned
off, a log that starts at the set-point), the firmware's heater parameters in the log.

The truth is the simulator's; the correction is PX4's ``X0 + X1·dT + X2·dT² + X3·dT³``
with ``dT = clamp(T, TMIN, TMAX) − TREF`` (TemperatureCompensation.cpp), written out here."""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from fc_logs import heated_dataflash, heated_truth, heated_ulog
from thermocal.cli import main
from thermocal.errors import ThermocalInputError
from thermocal.heater import HeaterOptions, HeaterPolicy
from thermocal.tempcal.pipeline import GateWarning
from thermocal.tempcal.px4 import px4_tempcal

PX4_HEATER = {"SENS_EN_THERMAL": 1, "SENS_IMU_TEMP": 55.0}


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(args)
    return code, buf.getvalue(), capsys.readouterr().err


def _params(path: Path) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if not line.startswith("#"):
            _v, _c, name, value, _t = line.split("\t")
            out[name] = float(value)
    return out


def _gyro_residual(params: dict[str, float], temp: np.ndarray, truth: np.ndarray) -> float:
    """RMS over the axes of the truth minus PX4's correction (mean removed) [rad/s]."""
    p = params
    dT = np.clip(temp, p["TC_G0_TMIN"], p["TC_G0_TMAX"]) - p["TC_G0_TREF"]
    err = []
    for i in range(3):
        x = [p[f"TC_G0_X{k}_{i}"] for k in range(4)]
        e = truth[:, i] - (x[0] + x[1] * dT + x[2] * dT**2 + x[3] * dT**3)
        err.append(e - e.mean())
    return float(np.sqrt(np.mean(np.square(err))))


@pytest.fixture(scope="module")
def px4_heated(tmp_path_factory: pytest.TempPathFactory) -> dict:
    d = tmp_path_factory.mktemp("heated")
    tr = heated_truth(7)
    log = d / "heated.ulg"
    log.write_bytes(heated_ulog(tr, PX4_HEATER))
    return {"dir": d, "log": log, "truth": tr}


def test_px4_hold_reported_and_range_cut(
    px4_heated: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    d, log, tr = px4_heated["dir"], px4_heated["log"], px4_heated["truth"]
    before = hashlib.sha256(log.read_bytes()).hexdigest()
    code, out, err = run(["px4-tempcal", str(log), "-o", str(d / "out"), "--json"], capsys)
    assert code == 0, err
    assert hashlib.sha256(log.read_bytes()).hexdigest() == before  # the input untouched
    gyro = json.loads(out)["sensors"]["sensor_gyro.0"]["heater"]
    assert gyro["setpoint_source"] == "parameter SENS_IMU_TEMP" and gyro["setpoint_c"] == 55.0
    assert abs(gyro["reached_s"] - tr["reached_s"]) < 1.0  # the check
    assert abs(gyro["overshoot_c"] - tr["overshoot_c"]) < 0.32  # + ripple 0.2 + 4σ noise
    assert gyro["range_cut"] and gyro["heater_off_s"] is None
    cut = [ln for ln in err.splitlines() if "heater hold at 55.00 °C" in ln]
    # once for the IMU (named by its gyro), not for its gyro and again for its accelerometer
    assert len(cut) == 1 and cut[0].startswith("warning: ") and "sensor_gyro.0" in cut[0]
    assert "SENS_EN_THERMAL=0" in cut[0] and "stops rising" not in err
    # the parameters cover the sweep up to the set-point (and its overshoot), no further
    p = _params(d / "out" / "px4.params")
    assert p["TC_G0_TMIN"] == pytest.approx(15.0, abs=0.5)
    assert 55.0 - 0.5 <= p["TC_G0_TMAX"] <= 55.0 + tr["overshoot_c"] + 0.35
    notes = "\n".join(json.loads(out)["notes"])
    assert "sensor_gyro.0: heater hold at 55.00 °C (parameter SENS_IMU_TEMP)" in notes
    assert "equal weight per bin" in notes
    report = (d / "out" / "report_sensor_gyro_0.html").read_text(encoding="utf-8")
    assert "Heater: heater hold at 55.00 °C" in report


def test_px4_residual_on_the_sweep_as_without_the_hold(
    px4_heated: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    d, tr = px4_heated["dir"], px4_heated["truth"]
    if not (d / "out").exists():
        assert run(["px4-tempcal", str(px4_heated["log"]), "-o", str(d / "out")], capsys)[0] == 0
    sweep = tr["time_s"] < tr["reached_s"]  # the ramp, before the set-point
    cut = {k: (v[sweep] if isinstance(v, np.ndarray) else v) for k, v in tr.items()}
    short = d / "ramp_only.ulg"
    short.write_bytes(heated_ulog(cut, PX4_HEATER))
    code, _o, err = run(["px4-tempcal", str(short), "-o", str(d / "ramp")], capsys)
    assert code == 0, err
    assert "55.0 °C (SENS_IMU_TEMP) is never held" in err  # the parameter, never reached
    temp = tr["temp"][sweep].astype(np.float32).astype(np.float64)
    with_hold = _gyro_residual(_params(d / "out" / "px4.params"), temp, tr["gyro"][sweep])
    without = _gyro_residual(_params(d / "ramp" / "px4.params"), temp, tr["gyro"][sweep])
    assert with_hold <= 1.1 * without, (with_hold, without)


def test_px4_refuse_and_ignore(px4_heated: dict, capsys: pytest.CaptureFixture[str]) -> None:
    d, log = px4_heated["dir"], px4_heated["log"]
    code, _o, err = run(["px4-tempcal", str(log), "-o", str(d / "r"), "--heater", "refuse"], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {log}: sensor_")
    assert "give --heater cut" in lines[0] and "SENS_EN_THERMAL=0" in lines[0]
    assert not (d / "r").exists()
    code, out, err = run(
        ["px4-tempcal", str(log), "-o", str(d / "i"), "--heater", "ignore", "--json"], capsys
    )
    assert code == 0 and json.loads(out)["sensors"]["sensor_gyro.0"]["heater"] is None
    code, _o, err = run(["px4-tempcal", str(log), "-o", str(d / "x"), "--heater", "off"], capsys)
    assert code == 2 and "--heater must be cut, refuse or ignore" in err


def test_px4_api_given_setpoint(px4_heated: dict) -> None:
    d, log, tr = px4_heated["dir"], px4_heated["log"], px4_heated["truth"]
    with pytest.warns(GateWarning, match=r"heater hold at 55\.00 °C \(given\)"):
        res = px4_tempcal(log, d / "api", heater=HeaterOptions(setpoint_c=55.0))
    hold = {f.kind: f.heater for f in res.fits}["gyro"]
    assert hold is not None and hold["setpoint_source"] == "given"
    assert abs(hold["reached_s"] - tr["reached_s"]) < 1.0
    with pytest.raises(ThermocalInputError, match="give heater cut"):
        px4_tempcal(log, d / "api2", heater=HeaterOptions(HeaterPolicy.REFUSE))


def test_px4_log_at_the_setpoint_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "warm.ulg"
    log.write_bytes(heated_ulog(heated_truth(2, at_setpoint=True), PX4_HEATER))
    code, _o, err = run(["px4-tempcal", str(log), "-o", str(tmp_path / "o")], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "no sweep to calibrate" in lines[0]
    assert "heater off (SENS_EN_THERMAL=0)" in lines[0]


def test_ardupilot_heater_off_mid_log(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    tr = heated_truth(9, heater_off_s=1500.0)
    log = tmp_path / "off.bin"
    log.write_bytes(heated_dataflash(tr, {"BRD_HEAT_TARG": 55.0}))
    code, out, err = run(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "o"), "--json"],
                         capsys)  # fmt: skip
    assert code == 0, err
    hold = json.loads(out)["sensors"]["IMU.Gyr.0"]["heater"]
    assert hold["setpoint_source"] == "parameter BRD_HEAT_TARG"
    assert abs(hold["reached_s"] - tr["reached_s"]) < 1.0
    assert 0.0 <= hold["heater_off_s"] - 1500.0 < 5.0  # 0.13 °C/s cooling leaves ±0.5 °C
    assert "BRD_HEAT_TARG=-1" in err
    assert any("IMU.0: heater hold" in n and "heater off at" in n for n in json.loads(out)["notes"])


def test_ardupilot_hold_judged_on_the_reconstructed_temperature(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """ArduPilot, an IMU reading whole degrees: the hold is judged on the temperature the fits
    take (reconstructed by default: the set-point reached within 2 s of the simulator's
    instant, 1.5 s), the same for the gyro and the accelerometer; as logged
    (``--temperature raw``) the first whole-degree reading of 55 °C comes 8.9 s early."""
    tr = heated_truth(3)
    tr["temp"] = np.round(tr["temp"])
    log = tmp_path / "whole.bin"
    log.write_bytes(heated_dataflash(tr, {"BRD_HEAT_TARG": 55.0}))
    reached = {}
    for mode in ("reconstructed", "raw"):
        code, out, err = run(["ardupilot-tempcal", str(log), "-o", str(tmp_path / mode),
                              "--json", "--heater-min-hold", "120", "--temperature", mode],
                             capsys)  # fmt: skip
        assert code == 0, err
        sensors = json.loads(out)["sensors"]
        assert sensors["IMU.Gyr.0"]["heater"] == sensors["IMU.Acc.0"]["heater"]
        assert sensors["IMU.Gyr.0"]["thermometer"]["temperature"] == mode
        reached[mode] = sensors["IMU.Gyr.0"]["heater"]["reached_s"]
    assert abs(reached["reconstructed"] - tr["reached_s"]) < 2.0
    assert abs(reached["raw"] - tr["reached_s"]) > 5.0


def test_ardupilot_old_parameter_name_and_heater_disabled(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tr = heated_truth(11)
    log = tmp_path / "old.bin"
    log.write_bytes(heated_dataflash(tr, {"BRD_IMU_TARGTEMP": 55.0}))
    code, out, err = run(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "o"), "--json"],
                         capsys)  # fmt: skip
    assert code == 0, err
    assert json.loads(out)["sensors"]["IMU.Acc.0"]["heater"]["setpoint_source"] == (
        "parameter BRD_IMU_TARGTEMP"
    )
    off = tmp_path / "off.bin"
    off.write_bytes(heated_dataflash(tr, {"BRD_HEAT_TARG": -1.0}))
    code, out, err = run(["ardupilot-tempcal", str(off), "-o", str(tmp_path / "p"), "--json"],
                         capsys)  # fmt: skip
    assert code == 0 and json.loads(out)["sensors"]["IMU.Acc.0"]["heater"] is None


def test_the_tutorial_heated_log(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """docs/tutorials/fc-params.md's heated board: the hold within 1 s of its simulator's
    truth, and the warning the page shows is the one printed."""
    root = Path(__file__).resolve().parents[2]
    (tmp_path / "docs").symlink_to(root / "docs", target_is_directory=True)
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(tmp_path)
        code, out, err = run(["px4-tempcal", "docs/tutorials/data/heated.ulg", "-o", "heated",
                              "--json"], capsys)  # fmt: skip
    assert code == 0, err
    truth = heated_truth(7, rate_hz=1.0)  # what make_fc_logs.py wrote
    hold = json.loads(out)["sensors"]["sensor_gyro.0"]["heater"]
    assert abs(hold["reached_s"] - truth["reached_s"]) < 1.0
    page = (root / "docs" / "tutorials" / "fc-params.md").read_text(encoding="utf-8")
    shown = [ln for ln in page.splitlines() if ln.startswith("warning: ") and "heated" in ln]
    assert len(shown) == 1 and shown[0] in err.splitlines()


@pytest.mark.parametrize(
    ("option", "value", "words"),
    [
        ("--heater", "off", "--heater must be cut, refuse or ignore, got 'off'"),
        ("--heater-setpoint", "nan", "--heater-setpoint must be a finite temperature"),
        ("--heater-setpoint", "inf", "--heater-setpoint must be a finite temperature"),
        ("--heater-setpoint", "-300", "--heater-setpoint must be a finite temperature"),
    ],
)
@pytest.mark.parametrize("command", ["px4-tempcal", "ardupilot-tempcal"])
def test_hostile_heater_options(
    px4_heated: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str,
    option: str, value: str, words: str,
) -> None:  # fmt: skip
    log = px4_heated["log"]
    if command == "ardupilot-tempcal":
        log = tmp_path / "h.bin"
        log.write_bytes(heated_dataflash(heated_truth(1, hold_s=120.0), {"BRD_HEAT_TARG": 55.0}))
    before = hashlib.sha256(log.read_bytes()).hexdigest()
    code, _o, err = run([command, str(log), "-o", str(tmp_path / "o"), option, value], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], err
    assert not (tmp_path / "o").exists()
    assert hashlib.sha256(log.read_bytes()).hexdigest() == before


def test_whole_degree_thermometer_with_a_wider_band(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A thermometer that reads whole degrees (some Bosch parts).  As logged
    (``--temperature raw``): the set-point is reached within half a degree's step of the
    ramp (0.5 °C / 0.06 °C/s = 8.3 s), and the band held reads as whole degrees.  The hold
    is judged on the temperature the fit uses: reconstructed (the default), the set-point
    is reached within 2 s of the simulator's instant (1.5 s; as logged with the default
    band: 8.9 s early) and held within the default ±0.5 °C band."""
    tr = heated_truth(3)
    tr["temp"] = np.round(tr["temp"])
    log = tmp_path / "whole.ulg"
    log.write_bytes(heated_ulog(tr, PX4_HEATER))
    code, out, err = run(["px4-tempcal", str(log), "-o", str(tmp_path / "o"), "--json",
                          "--heater-band", "1", "--heater-min-hold", "120",
                          "--temperature", "raw"], capsys)  # fmt: skip
    assert code == 0, err
    hold = json.loads(out)["sensors"]["sensor_gyro.0"]["heater"]
    assert hold["band_c"] == 1.0 and hold["hold_s"] >= 120.0
    assert abs(hold["reached_s"] - tr["reached_s"]) < 0.5 / 0.06 + 0.5
    assert all(float(v).is_integer() for v in hold["held_c"])
    code, out, err = run(["px4-tempcal", str(log), "-o", str(tmp_path / "r"), "--json",
                          "--heater-min-hold", "120"], capsys)  # fmt: skip
    assert code == 0, err
    hold = json.loads(out)["sensors"]["sensor_gyro.0"]["heater"]
    assert hold["band_c"] == 0.5 and hold["hold_s"] >= 120.0
    assert abs(hold["reached_s"] - tr["reached_s"]) < 2.0
    assert -0.5 <= hold["held_c"][0] <= hold["held_c"][1] <= 0.5
    for option, value in (("--heater-band", "0"), ("--heater-min-hold", "-1")):
        code, _o, err = run(["px4-tempcal", str(log), "-o", str(tmp_path / "x"), option, value],
                            capsys)  # fmt: skip
        assert code == 2 and err.startswith(f"error: {option} must be positive"), err


def test_setpoint_converted_to_the_borrowed_thermometer() -> None:
    """Fitted on another thermometer (``--temps-from``) that reads 1.5 °C below the IMU's
    own: the firmware holds its own at SENS_IMU_TEMP = 55 °C, so the hold is at 53.5 °C on
    the borrowed one, reached when the truth says."""
    from thermocal.tempcal.heated import judge_instance

    tr = heated_truth(7)
    borrowed = tr["temp"] - 1.5
    held = judge_instance(
        "log: sensor_gyro.0", tr["time_s"], borrowed, PX4_HEATER, "px4", HeaterOptions(),
        own_minus_c=1.5,
    )  # fmt: skip
    assert held.hold is not None
    assert held.hold.setpoint_c == pytest.approx(53.5)
    assert abs(held.hold.reached_s - tr["reached_s"]) < 1.0
    assert "SENS_IMU_TEMP 55 °C on the IMU's own thermometer" in held.hold.setpoint_source
    assert "+1.50 °C from the one fitted on" in held.hold.setpoint_source
    # unconverted, the parameter's 55 °C is never held on the borrowed thermometer: the
    # hold is only inferred (and px4-tempcal would add a stall's warning)
    plain = judge_instance(
        "log: sensor_gyro.0", tr["time_s"], borrowed, PX4_HEATER, "px4", HeaterOptions()
    )
    assert plain.hold is not None and plain.hold.setpoint_source == "inferred"
