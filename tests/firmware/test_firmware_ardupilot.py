"""ArduPilot's IMU temperature calibration as a pure function (thermocal.firmware.ardupilot).

References outside the code under test: the simulator's true bias (a known cubic in
T − 35 °C), the firmware's correction written out here (``AP_InertialSensor_tempcal.cpp``
``correct_sensor``: ``p(clamp(T) − 35) − p(T_cal − 35)``, ``p(t) = (c1 + (c2 + c3·t)·t)·t·1e-6``)
and an independent ``numpy.polyfit`` of the bin medians."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal.errors import ParameterError
from thermocal.firmware import ardupilot_coefficients, firmware_format

P = (3.0e-3, 8.0e-5, -2.0e-6, 3.0e-8)  # rad/s: p0 + p1·t + p2·t² + p3·t³, t = T − 35


def _data(seed: int = 0):
    rng = np.random.default_rng(seed)
    temp = np.linspace(-10.0, 60.0, 30_000)
    t = temp - 35.0
    b = P[0] + P[1] * t + P[2] * t**2 + P[3] * t**3
    vals = np.column_stack([b, -b, 0.5 * b]) + 2e-4 * rng.standard_normal((temp.size, 3))
    return temp, vals


def _firmware(
    p: dict[str, float], n: int, tag: str, axis: str, temp_c: float, cal_c: float
) -> float:
    lo, hi = p[f"INS_TCAL{n}_TMIN"], p[f"INS_TCAL{n}_TMAX"]
    c = [p[f"INS_TCAL{n}_{tag}{k}_{axis}"] for k in (1, 2, 3)]

    def poly(t: float) -> float:
        return (c[0] + (c[1] + c[2] * t) * t) * t * 1e-6

    return poly(min(max(temp_c, lo), hi) - 35.0) - poly(min(max(cal_c, lo), hi) - 35.0)


def test_stored_coefficients_are_the_true_cubic_times_1e6_without_constant() -> None:
    temp, vals = _data()
    fit = ardupilot_coefficients(temp, vals, kind="gyro")
    assert (fit.tmin_c, fit.tmax_c) == (-10.0, 60.0)
    assert fit.coefficients[0][0] == pytest.approx(P[1] * 1e6, rel=0.02)
    assert fit.coefficients[1][0] == pytest.approx(P[2] * 1e6, rel=0.05)
    assert fit.coefficients[2][0] == pytest.approx(P[3] * 1e6, rel=0.1)
    assert fit.coefficients[0][1] == pytest.approx(-P[1] * 1e6, rel=0.02)


def test_firmware_correction_from_the_params_follows_the_truth() -> None:
    temp, vals = _data(1)
    p = ardupilot_coefficients(temp, vals, kind="gyro").params(1)
    assert p["INS_TCAL2_ENABLE"] == 1 and len([n for n in p if "_GYR" in n]) == 9
    for t_c in (0.0, 20.0, 50.0):  # calibrated at 25 °C: the change from there
        t, c = t_c - 35.0, 25.0 - 35.0
        truth = P[1] * (t - c) + P[2] * (t**2 - c**2) + P[3] * (t**3 - c**3)
        assert _firmware(p, 2, "GYR", "X", t_c, 25.0) == pytest.approx(truth, abs=2e-5)
        assert _firmware(p, 2, "GYR", "Z", t_c, 25.0) == pytest.approx(0.5 * truth, abs=2e-5)
    fit = ardupilot_coefficients(temp, vals, kind="gyro")
    got = fit.correction([0.0, 50.0], caltemp_c=25.0)[:, 0]
    np.testing.assert_allclose(got, [_firmware(p, 2, "GYR", "X", x, 25.0) for x in (0.0, 50.0)],
                               rtol=1e-12)  # fmt: skip


def test_coefficients_are_numpy_polyfit_of_the_bin_medians_in_t_minus_35() -> None:
    temp, vals = _data(2)
    lo = math.floor(temp.min() / 0.5) * 0.5
    k = np.floor((temp - lo) / 0.5).astype(int)
    keys = np.unique(k)
    t_med = np.array([np.median(temp[k == b]) for b in keys])
    v_med = np.array([np.median(vals[k == b], axis=0) for b in keys])
    fit = ardupilot_coefficients(temp, vals, kind="accel")
    for j in range(3):
        ref = np.polyfit(t_med - 35.0, v_med[:, j], 3)[::-1][1:] * 1e6
        np.testing.assert_allclose([row[j] for row in fit.coefficients], ref, rtol=1e-8)
    assert "INS_TCAL1_ACC3_Y" in fit.params(0)


def test_bad_input_is_refused_naming_the_parameter() -> None:
    temp, vals = _data()
    for call, name in (
        (lambda: ardupilot_coefficients(temp, vals, kind="baro"), "kind"),
        (lambda: ardupilot_coefficients(temp, vals[:, :2]), "values"),
        (lambda: ardupilot_coefficients(temp, vals).params(3), "instance"),
        (lambda: firmware_format("betaflight"), "format"),
    ):
        with pytest.raises(ParameterError) as e:
            call()
        assert e.value.parameter == name
    assert firmware_format("ardupilot").max_instances == 3
