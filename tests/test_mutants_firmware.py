"""Tests that catch a tired developer's bugs in the firmware outputs (issue 39, slice
h39-firmware): each kills a mutant of ``benchmarks/mutation_check.py`` (``fw-*``) that the
other tests let through.  The references come from outside the code under test: the
firmwares' published equations (quoted, evaluated here with numpy) and pyulog's own reading
of a ULog."""

from __future__ import annotations

import contextlib
import io
import struct
import warnings
from pathlib import Path

import numpy as np
import pytest

from thermocal.errors import ThermocalInputError

# --- ArduPilot: AHRS_ORIENTATION (libraries/AP_Math/rotations.h, Vector3<T>::rotate) ----------


def _yaw_90(v: list[float]) -> list[float]:  # ROTATION_YAW_90: tmp = x; x = -y; y = tmp;
    x, y, z = v
    return [-y, x, z]


def _roll_90(v: list[float]) -> list[float]:  # ROTATION_ROLL_90: tmp = z; z = y; y = -tmp;
    x, y, z = v
    return [x, -z, y]


def _pitch_90(v: list[float]) -> list[float]:  # ROTATION_PITCH_90: tmp = z; z = -x; x = tmp;
    x, y, z = v
    return [z, y, -x]


def _pitch_270(v: list[float]) -> list[float]:  # ROTATION_PITCH_270: tmp = x; x = -z; z = tmp;
    x, y, z = v
    return [-z, y, x]


FIRMWARE_ROTATIONS = {
    2: _yaw_90,
    16: _roll_90,
    24: _pitch_90,
    25: _pitch_270,
    28: lambda v: _pitch_90(_roll_90(v)),  # ROTATION_ROLL_90_PITCH_90: roll, then pitch
}


@pytest.mark.parametrize("code", sorted(FIRMWARE_ROTATIONS))
def test_ardupilot_rotation_is_the_firmwares(code: int) -> None:
    from thermocal.tempcal.ardupilot import ardupilot_rotation

    v = [0.3, -1.7, 2.9]
    got = ardupilot_rotation(code) @ np.array(v)
    np.testing.assert_allclose(got, FIRMWARE_ROTATIONS[code](v), atol=1e-12)


@pytest.mark.parametrize("code", [2, 24, 28])
def test_ardupilot_raw_undoes_the_board_rotation(code: int) -> None:
    """The logged vector is the sensor's rotated by AHRS_ORIENTATION (rotations.cpp, above):
    undone, the sensor frame comes back."""
    from thermocal.tempcal.ardupilot import ardupilot_raw

    rng = np.random.default_rng(code)
    sensor = rng.normal(0.0, 1.0, (50, 3))
    logged = np.array([FIRMWARE_ROTATIONS[code](list(r)) for r in sensor])
    back, active, got_code = ardupilot_raw(
        {"AHRS_ORIENTATION": float(code)}, 0, "gyro", np.full(50, 30.0), logged
    )
    assert active is None and got_code == code
    np.testing.assert_allclose(back, sensor, atol=1e-12)


# --- ArduPilot: TCLR and CALTEMP (AP_InertialSensor_tempcal.cpp) --------------------------------


def test_tclr_learned_is_the_firmwares_polyfit_in_t_minus_35() -> None:
    """``st.pfit.update(tdiff = T − TEMP_REFERENCE (35), sum)``, then
    ``coefficients[k] = p[2-k] * SCALE_FACTOR (1e6)``: c1…c3 are the t, t², t³ terms of the
    least-squares cubic in T − 35 (numpy's polyfit here, highest power first)."""
    from thermocal.tempcal.ardupilot import tclr_learned

    rng = np.random.default_rng(5)
    temp = np.linspace(12.0, 61.0, 40)
    t = temp - 35.0
    xyz = np.column_stack(
        [0.01 + 2e-4 * t - 3e-6 * t**2 + 5e-8 * t**3, -4e-4 * t + 1e-6 * t**2, 7e-8 * t**3]
    ) + rng.normal(0.0, 1e-6, (temp.size, 3))
    got = np.array(tclr_learned(temp, xyz))
    for axis in range(3):
        p = np.polyfit(t, xyz[:, axis], 3)  # [t³, t², t, 1]
        want = [p[2] * 1e6, p[1] * 1e6, p[0] * 1e6]
        np.testing.assert_allclose(got[:, axis], want, rtol=1e-9, atol=1e-9)


def test_caltemp_is_constrained_as_correct_sensor_does() -> None:
    """``correct_sensor``: ``temperature = constrain_float(temperature, temp_min, temp_max);
    cal_temp = constrain_float(cal_temp, temp_min, temp_max); v -= poly(temperature − 35);
    v += poly(cal_temp − 35)``, ``poly(t) = (c0 + (c1 + c2·t)·t)·t·1e-6``."""
    from thermocal.tempcal.ardupilot import ActiveTcal

    c = [[120.0, -80.0, 40.0], [-3.0, 2.5, 1.0], [0.05, -0.02, 0.01]]
    tmin, tmax, caltemp = 15.0, 45.0, 58.0  # CALTEMP beyond TMAX
    temp = np.linspace(0.0, 60.0, 61)

    def poly(t: float) -> np.ndarray:
        cc = np.asarray(c)
        return (cc[0] + (cc[1] + cc[2] * t) * t) * t * 1e-6

    want = np.array(
        [
            poly(min(max(x, tmin), tmax) - 35.0) - poly(min(max(caltemp, tmin), tmax) - 35.0)
            for x in temp
        ]
    )
    active = ActiveTcal(0, tmin, tmax, {"gyro": c}, {"gyro": caltemp})
    np.testing.assert_allclose(active.correction("gyro", temp), want, rtol=1e-12, atol=1e-15)


# --- PX4: the accelerometer's TC_A through px4-tempcal ------------------------------------------


def test_px4_tempcal_accel_cubic_removes_the_drift(tmp_path: Path) -> None:
    """PX4 (TemperatureCompensation, parameter reference TC_A0_X0…X3): the firmware
    subtracts ``Σ X_k·(clamp(T, TMIN, TMAX) − TREF)^k``; accelerometer offsets relative
    (gravity in the data).  Applied here to the simulated drift: ≥ 95 % removed."""
    from thermocal.cli import main
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    rng = np.random.default_rng(3)
    n = 12000
    t = np.arange(n) * 0.1
    temp = -5.0 + 55.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 25.0
    drift = np.column_stack([0.05 * x + 0.02 * x**3, -0.03 * x + 0.01 * x**2, 0.04 * x**2])
    acc = np.array([0.1, -0.2, 9.81]) + drift + rng.normal(0.0, 2e-3, (n, 3))
    gyro = rng.normal(0.0, 1e-3, (n, 3))
    ts = (1e6 + t * 1e6).astype(np.int64)
    rows = lambda dev, v: [  # noqa: E731
        (int(s), dev, *map(float, r), float(c)) for s, r, c in zip(ts, v, temp, strict=True)
    ]
    log = tmp_path / "bench.ulg"
    log.write_bytes(
        ulog_bytes(
            [
                ("sensor_gyro", 0, SENSOR_FIELDS, rows(11, gyro)),
                ("sensor_accel", 0, SENSOR_FIELDS, rows(12, acc)),
            ]
        )
    )
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["px4-tempcal", str(log), "-o", str(tmp_path / "out")]) == 0
    p = {}
    for line in (tmp_path / "out" / "px4.params").read_text().splitlines():
        if not line.startswith("#"):
            _v, _c, name, value, _t = line.split("\t")
            p[name] = float(value)
    t32 = temp.astype(np.float32).astype(np.float64)
    dt = np.clip(t32, p["TC_A0_TMIN"], p["TC_A0_TMAX"]) - p["TC_A0_TREF"]
    for i in range(3):
        offset = sum(p[f"TC_A0_X{k}_{i}"] * dt**k for k in range(4))
        corrected = drift[:, i] - offset
        left = float(np.std(corrected - corrected.mean()))
        assert left <= 0.05 * float(np.std(drift[:, i])), (i, left)


# --- PX4: the cubic only --------------------------------------------------------------------------


def _channels(order: int) -> object:
    """Three gyro channels (°/h): a polynomial of ``order`` in T fitted to a quartic drift."""
    from thermocal.models.calibration import Calibration, Channel
    from thermocal.models.poly import PolyModel
    from thermocal.models.rundata import RunData

    temp = np.linspace(-10.0, 60.0, 400)
    u = (temp - 25.0) / 35.0
    chans = []
    for j, axis in enumerate("xyz"):
        y = 50.0 * u + 20.0 * u**3 + (j + 1) * 30.0 * u**4
        run = RunData(np.arange(temp.size, dtype=np.float64), temp.reshape(-1, 1), y,
                      ("temperature",), name=f"g{axis}", signal_unit="deg/h")  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = PolyModel(order=order, per_run_offset=False).fit([run])
        model.signal_name, model.signal_unit = axis, "deg/h"
        chans.append(Channel(f"g{axis}", axis, "deg/h", model,
                             {"kind": "gyro", "axis": axis, "instance": 0}))  # fmt: skip
    return Calibration(chans)


def test_px4_takes_a_cubic_not_a_quartic() -> None:
    """PX4's TC_G<n> holds X0…X3 (parameter reference: ``TC_G0_X3_0`` "Gyro rate offset
    temperature ^3 polynomial coefficient" is the highest): a quartic is refused."""
    from thermocal.export.params import export_params

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ok = export_params(_channels(3), "px4", device_id={"gyro": 1})  # type: ignore[arg-type]
        assert "TC_G0_X3_2" in ok.params and "TC_G0_X4_2" not in ok.params
        with pytest.raises(ThermocalInputError, match=r"T\^4"):
            export_params(_channels(4), "px4", device_id={"gyro": 1})  # type: ignore[arg-type]


# --- the firmware export and its overrides ------------------------------------------------------


def test_firmware_export_takes_only_the_override_of_the_failed_test() -> None:
    """A fit whose stillness failed and that was let through with --allow-narrow only (an
    override of another test) gives no firmware parameters."""
    from thermocal.adequacy import check_for_firmware

    record = {
        "tests": [
            {"name": "stillness", "verdict": "fail", "override": "--allow-motion",
             "message": "moving 40 % of the time"},
            {"name": "span", "verdict": "pass", "override": "--allow-narrow", "message": ""},
        ],
        "overrides": ["--allow-narrow"],
    }  # fmt: skip
    with pytest.raises(ThermocalInputError, match="stillness"):
        check_for_firmware(record, "cal.json")
    record["overrides"] = ["--allow-motion"]
    with pytest.warns(Warning, match="--allow-motion"):
        check_for_firmware(record, "cal.json")


# --- the fast ULog reader against pyulog's own --------------------------------------------------


def _msg(kind: str, payload: bytes) -> bytes:
    """ULog (docs.px4.io, "ULog File Format"): ``uint16 msg_size, uint8 msg_type``, payload."""
    return struct.pack("<HB", len(payload), ord(kind)) + payload


def test_a_data_message_before_its_subscription_is_read_as_pyulog_reads_it(
    tmp_path: Path,
) -> None:
    """In the data section, a ``D`` of msg_id 0 (sensor_gyro) written before the ``A`` that
    subscribes msg_id 0, between data of another topic: thermocal's read of both topics
    equals pyulog's own parse of the same file (pyulog drops that message)."""
    from pyulog import ULog

    from thermocal.readers import ulog as ulog_mod

    out = bytearray(b"ULog\x01\x12\x35\x01" + struct.pack("<Q", 1_000))
    out += _msg("B", bytes(16) + struct.pack("<3Q", 0, 0, 0))
    fields = b":uint64_t timestamp;uint32_t device_id;float x;float y;float z;float temperature;"
    out += _msg("F", b"sensor_gyro" + fields)
    out += _msg("F", b"sensor_accel" + fields)

    def row(msg_id: int, i: int) -> bytes:
        payload = struct.pack("<QI4f", 2_000 + 1000 * i, 7, 0.1 * i, -0.2, 0.3, 20.0 + i)
        return _msg("D", struct.pack("<H", msg_id) + payload)

    out += _msg("A", struct.pack("<BH", 0, 1) + b"sensor_accel")
    out += row(1, 0)
    out += row(0, 0)  # the gyro before its subscription
    out += _msg("A", struct.pack("<BH", 0, 0) + b"sensor_gyro")
    for i in range(1, 40):
        out += row(0, i) + row(1, i)
    path = tmp_path / "early.ulg"
    path.write_bytes(bytes(out))
    names = ["sensor_gyro", "sensor_accel"]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        ref = ULog(str(path), names)
        read = ulog_mod._parse_ulog_file(path, names)
    ours = {(d.name, d.multi_id): d.data for d in read.ulog.data_list}
    theirs = {(d.name, d.multi_id): d.data for d in ref.data_list}
    assert ours.keys() == theirs.keys() and len(theirs[("sensor_gyro", 0)]["timestamp"]) == 39
    for key, want in theirs.items():
        for field, values in want.items():
            np.testing.assert_array_equal(ours[key][field], values, err_msg=f"{key} {field}")
