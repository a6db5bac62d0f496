"""Coarse and slow thermometers (thermocal.thermometer) against a simulator's truth.

A sweep with a heater's overshoot and a pause is read by a BMI088-like thermometer (0.125 °C
lattice offset by 23 °C, updated every 1.28 s at a random phase, the IMU at 100 Hz) and by a
Bosch whole-degree thermometer (truncating, updated every sample); the lattice and the
period are recovered, and a cubic fitted on the reconstructed temperature leaves a
residual within 1.1× of the same fit on the true temperature, while on the raw reading the
staircase is there (the true bias left by the fit ≥ 2× that reconstructed).  The cubic is
numpy's ``polyfit``, written here."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.thermometer import (
    ThermometerWarning,
    borrowed_temperature,
    describe_thermometer,
    lattice_step,
    reconstruct_temperature,
    update_period,
)

RATE_HZ = 100.0


def _truth(seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Times, the true temperature (ramp −10…50 °C, overshoot, a held pause), the gyro's true
    bias (a cubic in T, rad/s) and its measurement (white noise)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, 3600.0, 1 / RATE_HZ)
    ramp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * np.clip(t / 3000.0, 0, 1)))
    overshoot = 1.5 * np.exp(-(((t - 1500.0) / 120.0) ** 2))  # a heater overshoots
    pause = np.where((t > 2000) & (t < 2300), 0.0, 1.0)  # the operator pauses: slower
    true = np.cumsum(np.gradient(ramp + overshoot) * pause) + ramp[0]
    true += rng.normal(0, 0.005, t.size).cumsum() * 0.002  # a slow wander
    x = (true - 20.0) / 30.0
    bias = 0.01 + 0.02 * x - 0.006 * x**2 + 0.004 * x**3
    meas = bias + rng.normal(0, 2e-4, t.size)
    return t, true, bias, meas


def _bmi088(t: np.ndarray, true: np.ndarray, seed: int = 1) -> np.ndarray:
    """0.125 °C lattice about 23 °C, the value sampled every 1.28 s at a random phase."""
    phase = np.random.default_rng(seed).uniform(0, 1.28)
    upd = np.floor((t - phase) / 1.28) * 1.28 + phase
    held = np.interp(np.maximum(upd, t[0]), t, true)
    return 23.0 + 0.125 * np.round((held - 23.0) / 0.125)


def _fit(t_used: np.ndarray, meas: np.ndarray) -> np.ndarray:
    """The cubic in the temperature used, fitted by least squares (numpy), at each sample."""
    return np.polyval(np.polyfit(t_used, meas, 3), t_used)


def _check_fits(
    true: np.ndarray, rec: np.ndarray, raw: np.ndarray, meas: np.ndarray, bias: np.ndarray
) -> None:
    """The residual (measurement − fit) on the reconstruction within 1.1× of that on the
    truth; the staircase (the true bias − the fit, noise-free) at least 2× larger raw than
    reconstructed."""

    def rms(x: np.ndarray) -> float:
        return float(np.sqrt(np.mean(x**2)))

    on_truth, on_rec = rms(meas - _fit(true, meas)), rms(meas - _fit(rec, meas))
    assert on_rec <= 1.1 * on_truth, (on_rec, on_truth)
    stair_rec, stair_raw = rms(bias - _fit(rec, meas)), rms(bias - _fit(raw, meas))
    assert stair_raw >= 2.0 * stair_rec, (stair_raw, stair_rec)


def test_bmi088_lattice_and_period_recovered_and_fit_as_good_as_truth() -> None:
    t, true, bias, meas = _truth()
    reading = _bmi088(t, true)
    th = describe_thermometer(t, reading)
    assert th.step_c == pytest.approx(0.125, abs=1e-9)
    assert th.update_period_s == pytest.approx(1.28, abs=0.01)
    assert th.quantised and th.slow
    rec = reconstruct_temperature(t, reading)
    assert rec.used == "reconstructed" and "0.125 °C" in (rec.note or "")
    # while the temperature moves, the reconstruction is far closer to the truth than the
    # reading (on the final hold, from 3000 s, the level is all there is to know)
    moving = t < 3000.0
    err_rec = np.sqrt(np.mean((rec.temp_c - true)[moving] ** 2))
    err_raw = np.sqrt(np.mean((reading - true)[moving] ** 2))
    assert err_rec < 0.5 * err_raw, (err_rec, err_raw)
    _check_fits(true, rec.temp_c, reading, meas, bias)


def test_whole_degree_truncating_thermometer() -> None:
    t, true, bias, meas = _truth(seed=3)
    reading = np.floor(true)  # whole degrees, truncated, every sample
    th = describe_thermometer(t, reading)
    assert th.step_c == pytest.approx(1.0, abs=1e-9)
    assert th.quantised and not th.slow
    rec = reconstruct_temperature(t, reading)
    # the boundaries are the midpoints: a truncating sensor's q/2 offset is kept, as the
    # firmware will read it in flight; about it, the error is small
    off = (rec.temp_c - (true - 0.5))[t < 3000.0]  # moving (then the final hold)
    assert abs(np.median(off)) < 0.05
    assert np.sqrt(np.mean(off**2)) < 0.1  # the reading: 1/√12 = 0.29 °C
    _check_fits(true, rec.temp_c, reading, meas, bias)
    raw = reconstruct_temperature(t, reading, mode="raw")
    assert raw.used == "raw" and np.array_equal(raw.temp_c, reading)
    assert "whole" not in (raw.note or "") and "1 °C" in (raw.note or "")


def test_fahrenheit_and_raw_counts_lattices() -> None:
    rng = np.random.default_rng(5)
    f = np.round(rng.uniform(14, 122, 20000))  # whole °F converted to °C, float32-stored
    c = ((f - 32.0) * 5.0 / 9.0).astype(np.float32).astype(np.float64)
    assert lattice_step(c) == pytest.approx(5.0 / 9.0, rel=1e-5)
    counts = rng.integers(-300, 300, 20000)  # BMI055: 0.5 °C per count about 23 °C
    assert lattice_step(23.0 + 0.5 * counts) == pytest.approx(0.5, abs=1e-9)
    fine = 36.53 + rng.integers(-9000, 9000, 20000) / 340.0  # MPU-6050: 1/340 °C
    th = describe_thermometer(np.arange(20000) * 0.01, fine)
    assert not th.quantised  # a step of 0.003 °C is no coarse thermometer
    # a glitch off the lattice does not hide it
    glitch = 23.0 + 0.5 * counts
    glitch[:5] = 23.37
    assert lattice_step(glitch) == pytest.approx(0.5, abs=1e-9)


def test_continuous_noisy_thermometer_is_left_alone() -> None:
    t, true, _b, _m = _truth()
    noisy = true + np.random.default_rng(2).normal(0, 0.02, t.size)
    th = describe_thermometer(t, noisy)
    assert not th.coarse and th.step_c is None and th.update_period_s is None
    rec = reconstruct_temperature(t, noisy)
    assert rec.used == "raw" and rec.note is None and np.array_equal(rec.temp_c, noisy)


def test_slow_continuous_thermometer_period() -> None:
    t = np.arange(0, 900, 0.004)  # 250 Hz
    true = 20 + 0.02 * t + 2 * np.sin(t / 100)
    held = np.interp(np.floor(t / 2.5) * 2.5, t, true)  # updated every 2.5 s, unquantised
    assert update_period(t, held) == pytest.approx(2.5, abs=0.01)
    th = describe_thermometer(t, held)
    assert th.slow and not th.quantised
    rec = reconstruct_temperature(t, held)
    # knots at the updates: the error is the curvature between them (2e-4 °C/s², 2.5 s:
    # 1.6e-4 °C; where the rate is zero two updates read alike and a knot is missing)
    err = np.abs(rec.temp_c - true)[t < 897.5]
    assert np.max(err) < 3e-3 and np.sqrt(np.mean(err**2)) < 5e-4
    raw_err = np.sqrt(np.mean((held - true)[t < 897.5] ** 2))
    assert raw_err > 0.02  # the held reading lags by up to 2.5 s


def test_hostile_temperatures() -> None:
    t = np.arange(1000) * 0.01
    with pytest.raises(ParameterError, match="one value"):
        reconstruct_temperature(t, np.full(1000, 25.0))
    with pytest.raises(ParameterError, match="one value"):
        reconstruct_temperature(t, np.full(1000, 23.125))  # a lattice with a single level
    with pytest.raises(ParameterError, match="no finite value"):
        describe_thermometer(t, np.full(1000, np.nan))
    with pytest.raises(ParameterError, match="reconstructed or raw"):
        reconstruct_temperature(t, t, mode="smooth")  # type: ignore[arg-type]


def test_borrowed_thermometer_joined_by_time() -> None:
    t, true, _bias, meas = _truth()
    tb = np.arange(0.0, 3600.0, 0.1) + 0.037  # a barometer at 10 Hz, its own instants
    baro = np.interp(tb, t, true) + np.random.default_rng(9).normal(0, 0.01, tb.size)
    rec, keep = borrowed_temperature(t, tb, baro, source="sensor_baro.0")
    assert keep.sum() >= t.size - 4
    assert np.sqrt(np.mean((rec.temp_c - true[keep]) ** 2)) < 0.015
    on_truth = np.std(meas[keep] - _fit(true[keep], meas[keep]))
    assert np.std(meas[keep] - _fit(rec.temp_c, meas[keep])) <= 1.1 * on_truth
    # partly overlapping: the rest left out, said
    with pytest.warns(ThermometerWarning, match="covers 50"):
        rec, keep = borrowed_temperature(t, tb[tb > 1800], baro[tb > 1800], source="b")
    assert keep.mean() == pytest.approx(0.5, abs=0.001)
    with pytest.raises(ThermocalInputError, match="do not overlap"):
        borrowed_temperature(t, tb + 5000, baro, source="sensor_baro.0")


def test_a_slow_lattice_reconstructed_without_lag() -> None:
    """A steady 1.8 °C/min ramp read every 1.28 s on a 0.125 °C lattice: the crossing is
    placed midway in the update interval, so the reconstruction has no lag (a crossing put
    where the new level is first seen lags 0.64 s: 0.019 °C)."""
    t = np.arange(0, 1200.0, 0.01)
    true = 20.0 + 0.03 * t
    upd = np.floor((t - 0.5) / 1.28) * 1.28 + 0.5
    reading = 0.125 * np.round(np.interp(np.maximum(upd, 0), t, true) / 0.125)
    th = describe_thermometer(t, reading)
    assert th.slow and th.update_period_s == pytest.approx(1.28, abs=0.01)
    rec = reconstruct_temperature(t, reading)
    inner = (t > 60) & (t < 1140)
    assert abs(np.mean((rec.temp_c - true)[inner])) < 0.005
    assert np.mean((reading - true)[inner]) < -0.015  # the held reading lags


def test_a_partly_lattice_thermometer_is_not_quantised() -> None:
    """60 % of the readings on a 0.5 °C lattice, 40 % anywhere: no lattice (99 % needed)."""
    rng = np.random.default_rng(4)
    v = np.where(
        rng.random(10000) < 0.6, 0.5 * rng.integers(40, 80, 10000), rng.uniform(20, 40, 10000)
    )
    assert lattice_step(v) is None
    assert lattice_step(0.5 * rng.integers(40, 80, 10000)) == pytest.approx(0.5, abs=1e-9)


def test_a_continuous_reading_counts_its_distinct_values() -> None:
    """A fine, continuous reading (no levels to merge) is described with the number of its
    distinct values, counted here by a set; a quantised one with its merged levels."""
    rng = np.random.default_rng(11)
    t = np.arange(0.0, 3000.0, 0.1)
    v = 20.0 + 10.0 * rng.random(t.size)
    v[::7] = v[3]  # one value held at every 7th sample: counted once
    th = describe_thermometer(t, v)
    assert th.n_levels == len(set(v.tolist()))
    assert th.step_c is None
    q = 0.25 * np.round((20.0 + 10.0 * t / t[-1]) / 0.25)
    assert describe_thermometer(t, q).n_levels == len(set(q.tolist())) == 41


@pytest.mark.parametrize(
    ("step", "quantised"), [(1.0, True), (2.0, True), (2.5, False), (5.0, False)]
)
def test_the_coarsest_thermometer_and_the_finest_set_temperatures(
    step: float, quantised: bool
) -> None:
    """MAX_STEP_C (2 °C) is the line between a thermometer's resolution and a record's set
    temperatures: a reading rounded to 1 or 2 °C along a slow ramp is a coarse thermometer
    (reconstructed between its changes); soaks held on a 2.5 or 5 °C lattice are set
    temperatures, their step found but nothing invented between them."""
    t = np.arange(0.0, 6 * 3600.0, 1.0)
    if quantised:  # a ramp −10 → 50 °C read on the lattice
        reading = step * np.round((-10.0 + 60.0 * t / t[-1]) / step)
    else:  # six one-hour soaks, the step apart, from 10 °C
        reading = 10.0 + step * np.floor(t / 3600.0)
    th = describe_thermometer(t, reading)
    assert th.step_c == pytest.approx(step, abs=1e-9)
    assert th.quantised is quantised
