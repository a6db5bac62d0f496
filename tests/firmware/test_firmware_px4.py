"""PX4's thermal-compensation fit as a pure function (thermocal.firmware.px4).

References outside the code under test: the simulator's true bias (a known polynomial over
−10…60 °C), and PX4's own fitting step restated here with numpy (``numpy.polyfit`` of order
3 in ``T − TREF``, ``TREF`` mid-range, as ``Tools/process_sensor_caldata.py`` does) on bin
medians computed in this file."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal.errors import ParameterError
from thermocal.firmware import FORMATS, px4_coefficients

N = 30_000
TRUE = {  # rad/s, coefficients of (T − 25)^k, k = 0…3, per axis
    "x": (2.0e-3, 4.0e-5, -1.5e-6, 2.0e-8),
    "y": (-1.0e-3, -2.0e-5, 1.0e-6, 0.0),
    "z": (5.0e-4, 1.0e-5, 0.0, -1.0e-8),
}


def _gyro(noise: float = 2e-4, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    temp = np.sort(rng.uniform(-10.0, 60.0, N))
    temp[0], temp[-1] = -10.0, 60.0
    truth = np.column_stack([np.polyval(c[::-1], temp - 25.0) for c in TRUE.values()])
    return temp, truth + noise * rng.standard_normal((N, 3)), truth


def _bin_medians(temp: np.ndarray, vals: np.ndarray, w: float = 0.5):
    lo = math.floor(temp.min() / w) * w
    k = np.floor((temp - lo) / w).astype(int)
    keys = np.unique(k)
    t = np.array([np.median(temp[k == b]) for b in keys])
    v = np.array([np.median(vals[k == b], axis=0) for b in keys])
    return t, v


def test_gyro_coefficients_recover_the_simulators_polynomial() -> None:
    temp, vals, truth = _gyro()
    fit = px4_coefficients(temp, vals, kind="gyro")
    assert (fit.tmin_c, fit.tmax_c, fit.tref_c) == (-10.0, 60.0, 25.0)
    assert not fit.relative
    for i, c in enumerate(TRUE.values()):
        got = fit.coefficients[i]
        assert got[0] == pytest.approx(c[0], abs=3e-6)
        assert got[1] == pytest.approx(c[1], abs=1e-6)
    # the firmware's correction against the truth over the range: at the noise of a bin
    grid = np.linspace(-10.0, 60.0, 500)
    true_grid = np.column_stack([np.polyval(c[::-1], grid - 25.0) for c in TRUE.values()])
    rms = np.sqrt(np.mean((fit.offset(grid) - true_grid) ** 2, axis=0))
    assert np.all(rms < 1.5e-5), rms  # 5x the standard error of a cubic on 140 bin medians
    # the swing it corrects is ~ 3e-3 rad/s: three orders of magnitude above
    assert np.ptp(truth[:, 0]) > 2e-3


def test_coefficients_are_numpy_polyfit_of_the_bin_medians_and_holdout_is_the_odd_bins() -> None:
    temp, vals, _ = _gyro(seed=3)
    fit = px4_coefficients(temp, vals)
    t_med, v_med = _bin_medians(temp, vals)
    assert fit.n_bins == t_med.size == 141  # 140 bins and the one holding 60.0 exactly
    for i in range(3):
        ref = np.polyfit(t_med - 25.0, v_med[:, i], 3)[::-1]  # PX4's script: numpy.polyfit
        np.testing.assert_allclose(fit.coefficients[i], ref, rtol=1e-8, atol=1e-15)
        held = np.polyfit(t_med[0::2] - 25.0, v_med[0::2, i], 3)
        pred = np.polyval(held, t_med[1::2] - 25.0)
        ref_rms = float(np.sqrt(np.mean((v_med[1::2, i] - pred) ** 2)))
        assert fit.holdout_rms[i] == pytest.approx(ref_rms, rel=1e-8)
    # against a fit of every raw sample (no bins): the same curve within the noise
    raw = np.polyfit(temp - 25.0, vals[:, 0], 3)
    grid = np.linspace(-10.0, 60.0, 200)
    assert np.max(np.abs(fit.offset(grid)[:, 0] - np.polyval(raw, grid - 25.0))) < 1e-5


def test_params_are_named_and_valued_as_px4_takes_them() -> None:
    temp, vals, _ = _gyro()
    fit = px4_coefficients(temp, vals, tref_c=30.0)
    p = fit.params(1, device_id=2293768)
    assert p["TC_G_ENABLE"] == 1 and p["TC_G1_ID"] == 2293768
    assert (p["TC_G1_TMIN"], p["TC_G1_TMAX"], p["TC_G1_TREF"]) == (-10.0, 60.0, 30.0)
    assert len([n for n in p if "_X" in n]) == 12
    # the firmware's formula on the parameters reproduces the truth at 30 °C and at 55 °C
    for t_c in (30.0, 55.0):
        d = t_c - p["TC_G1_TREF"]
        off = sum(p[f"TC_G1_X{k}_0"] * d**k for k in range(4))
        assert off == pytest.approx(np.polyval(TRUE["x"][::-1], t_c - 25.0), abs=2e-5)
    # clamped outside TMIN…TMAX as the firmware does
    np.testing.assert_allclose(fit.offset([80.0]), fit.offset([60.0]))


def test_accel_is_relative_to_its_median_and_baro_is_order_five() -> None:
    rng = np.random.default_rng(1)
    temp = np.linspace(0.0, 50.0, N)
    bias = 0.02 * (temp - 25.0) / 25.0  # m/s²
    acc = np.column_stack([bias, -bias, 9.80665 + 0.5 * bias]) + 0.01 * rng.standard_normal((N, 3))
    fit = px4_coefficients(temp, acc, kind="accel")
    assert fit.relative
    med = np.median(acc, axis=0)
    grid = np.linspace(0.0, 50.0, 100)
    truth = np.column_stack([0.02 * (grid - 25.0) / 25.0, -0.02 * (grid - 25.0) / 25.0,
                             9.80665 + 0.01 * (grid - 25.0) / 25.0])  # fmt: skip
    rms = np.sqrt(np.mean((fit.offset(grid) + med - truth) ** 2, axis=0))
    assert np.all(rms < 1.5e-3), rms  # the swing corrected: 0.04 m/s²
    pressure = 101325.0 + 30.0 * (temp - 25.0) / 25.0 + rng.standard_normal(N)
    baro = px4_coefficients(temp, pressure, kind="baro")
    assert len(baro.coefficients) == 1 and len(baro.coefficients[0]) == 6
    names = baro.params(0, device_id=7)
    assert "TC_B0_X5" in names and "TC_B0_X0_0" not in names
    assert baro.coefficients[0][1] == pytest.approx(30.0 / 25.0, rel=0.02)


def test_bad_arrays_are_refused_naming_the_parameter() -> None:
    temp, vals, _ = _gyro()
    with pytest.raises(ParameterError) as e:
        px4_coefficients(temp[:-1], vals)
    assert e.value.parameter == "values"
    with pytest.raises(ParameterError) as e:
        px4_coefficients(np.linspace(20.0, 22.0, 100), np.zeros((100, 3)))
    assert e.value.parameter == "temperature_c"
    assert "covers 5 bins of 0.5 °C; a polynomial of order 3 needs at least 8" in str(e.value)
    with pytest.raises(ParameterError) as e:
        px4_coefficients(temp, vals, kind="lidar")
    assert e.value.parameter == "kind"
    with pytest.raises(ParameterError) as e:
        px4_coefficients(temp, vals).params(FORMATS["px4"].max_instances)
    assert e.value.parameter == "instance" and "instances 0…3" in str(e.value)
    with pytest.raises(ParameterError) as e:
        px4_coefficients(temp, vals, tref_c=float("nan"))
    assert e.value.parameter == "tref_c"
