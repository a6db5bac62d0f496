"""ArduPilot's calibration (:mod:`thermocal.tempcal.ardupilot`) against the firmware's published
equations (AP_InertialSensor_tempcal.cpp, rotations.cpp; quoted and evaluated here with
numpy): the board rotation, the learned polynomial in T − 35 and the constrained
calibration temperature.  Each kills a mutant of ``benchmarks/mutation_check.py``
(``fw-*``)."""

from __future__ import annotations

import numpy as np
import pytest


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
    from thermocal.firmware.ardupilot import ardupilot_rotation

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


def test_tclr_learned_is_the_firmwares_polyfit_in_t_minus_35() -> None:
    """``st.pfit.update(tdiff = T − TEMP_REFERENCE (35), sum)``, then
    ``coefficients[k] = p[2-k] * SCALE_FACTOR (1e6)``: c1…c3 are the t, t², t³ terms of the
    least-squares cubic in T − 35 (numpy's polyfit here, highest power first)."""
    from thermocal.firmware.ardupilot import tclr_learned

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
