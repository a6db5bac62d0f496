"""Figures of merit (thermocal.metrics, SPEC §1) against hand-computed numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from thermocal import metrics, units
from thermocal.errors import MissingValueError, ThermocalInputError
from thermocal.recording import Recording


def test_bias_removes_earth_rate_component() -> None:
    lat = 45.0
    omega_up = units.EARTH_RATE_DEG_H * math.sin(math.radians(lat))  # 10.6357 °/h
    rate = 3.0 + omega_up + np.array([-0.2, 0.1, 0.1])
    assert metrics.bias(rate, earth_rate_deg_h=omega_up) == pytest.approx(3.0, abs=1e-12)
    assert omega_up == pytest.approx(10.63568, rel=1e-5)


def test_bias_from_counts() -> None:
    # K = 2 pulses/arcsec, τ = 0.5 s: rate = N/(τK) arcsec/s = N °/h
    counts = np.array([10.0, 12.0, 11.0, 9.0])
    b = metrics.bias_from_counts(counts, 2.0, 0.5, earth_rate_deg_h=1.0)
    assert b == pytest.approx(np.mean(counts) / (0.5 * 2.0) - 1.0, rel=1e-12)


def test_bias_stability_blocks_and_gaps() -> None:
    y = np.arange(12.0) ** 2
    # τ0 = 1 s, 4 s averages: blocks [0..3], [4..7], [8..11]
    means = np.array([3.5, 31.5, 91.5])
    assert metrics.bias_stability(y, 1.0, 4.0) == pytest.approx(np.std(means, ddof=1))
    # a gap after sample 5: blocks never straddle it → [0..3] and [6..9]
    t = np.r_[np.arange(6.0), 100.0 + np.arange(6.0)]
    m2 = np.array([y[0:4].mean(), y[6:10].mean()])
    assert metrics.bias_stability(y, 1.0, 4.0, time_s=t) == pytest.approx(np.std(m2, ddof=1))
    assert metrics.peak_to_peak(y, 1.0, 4.0, time_s=t) == pytest.approx(m2[1] - m2[0])
    with pytest.raises(ThermocalInputError, match="two"):
        metrics.bias_stability(y, 1.0, 10.0)


def test_bias_repeatability() -> None:
    assert metrics.bias_repeatability([1.0, 2.0, 3.0, 4.0]) == pytest.approx(math.sqrt(5 / 3))
    with pytest.raises(ThermocalInputError):
        metrics.bias_repeatability([1.0])


def test_temperature_sensitivity_both_figures() -> None:
    ts = metrics.temperature_sensitivity([20.0, -10.0, 0.0], [6.0, 1.0, 2.0])
    # sorted: (-10, 1), (0, 2), (20, 6): |1/10| and |4/20| → mean 0.15
    assert ts.mean_abs_adjacent == pytest.approx(0.15)
    slope = np.polyfit([-10.0, 0.0, 20.0], [1.0, 2.0, 6.0], 1)[0]
    assert ts.ls_slope == pytest.approx(slope, rel=1e-12)
    assert ts.unit == "deg/h/degC" and ts.n_points == 3
    assert ts.temps_c == (-10.0, 0.0, 20.0)
    with pytest.raises(ThermocalInputError, match="same temperature"):
        metrics.temperature_sensitivity([1.0, 1.0], [0.0, 1.0])


def test_temperature_sensitivity_of_a_non_monotonic_bias() -> None:
    """Bias up then down: |ΔB/ΔT| = |2/10| and |−1/20| → mean 0.125 °/h/°C (the signed
    mean would be 0.075); least-squares slope by hand: T̄ = 10/3, B̄ = 2,
    Σ(T−T̄)(B−B̄) = 10, Σ(T−T̄)² = 1400/3 → 3/140."""
    ts = metrics.temperature_sensitivity([-10.0, 0.0, 20.0], [1.0, 3.0, 2.0])
    assert ts.mean_abs_adjacent == pytest.approx(0.125, rel=1e-12)
    assert ts.ls_slope == pytest.approx(3.0 / 140.0, rel=1e-12)


def test_peak_to_peak_raw() -> None:
    assert metrics.peak_to_peak([1.0, 5.0, -2.0], 1.0, None) == pytest.approx(7.0)


def test_drift_angle_trapezoid() -> None:
    t = np.arange(0.0, 101.0)
    theta = metrics.drift_angle(t, np.full(t.size, 46.0), 10.0)
    assert theta[-1] == pytest.approx(1.0)  # 36 °/h × 100 s = 1°
    # a linear rate is integrated exactly by the trapezoid rule: ∫ 3600·t/100 dt / 3600
    theta = metrics.drift_angle(t, 36.0 * t, 0.0)
    assert_allclose(theta, 36.0 * t**2 / 2.0 / 3600.0, rtol=1e-12)
    # nothing is integrated over a gap
    tg = np.r_[np.arange(10.0), 1000.0 + np.arange(10.0)]
    theta = metrics.drift_angle(tg, np.full(20, 3600.0), 0.0)
    assert theta[-1] == pytest.approx(18.0)  # 9 + 9 one-second steps at 1 °/s


def test_nan_is_an_error() -> None:
    with pytest.raises(MissingValueError, match="row 1"):
        metrics.bias([1.0, np.nan])


def _chamber_recording(seed: int = 0) -> tuple[Recording, np.ndarray, np.ndarray]:
    """Holds of 1800 s at −10, 10, 30, 10 °C joined by 1 °C/min ramps; bias 0.02 °/h/°C."""
    rng = np.random.default_rng(seed)
    plan = [(-10.0, 1800.0), (10.0, 1800.0), (30.0, 1800.0), (10.0, 1800.0)]
    temps: list[np.ndarray] = []
    cur = plan[0][0]
    for target, hold in plan:
        ramp = abs(target - cur) * 60.0
        if ramp:
            temps.append(np.linspace(cur, target, int(ramp), endpoint=False))
        temps.append(np.full(int(hold), target))
        cur = target
    temp = np.concatenate(temps)
    t = np.arange(temp.size, dtype=np.float64)
    lat = 30.0
    omega_up = units.EARTH_RATE_DEG_H * 0.5
    rate = 2.0 + 0.02 * temp + omega_up + rng.standard_normal(t.size) * 0.05
    rec = Recording.from_arrays(t, {"gyro": rate}, {"T1": temp}, signal_unit="deg/h")
    rec.meta.latitude_deg = lat
    return rec, temp, rate


def test_compute_metrics_on_a_chamber_run() -> None:
    rec, _temp, rate = _chamber_recording()
    res = metrics.compute_metrics(rec, "gyro", 10.0, 30.0, "up", ["T1"])
    omega_up = units.EARTH_RATE_DEG_H * 0.5
    assert res.earth_rate_removed == pytest.approx(omega_up)
    assert res.bias == pytest.approx(rate.mean() - omega_up, rel=1e-12)
    blocks = rate[: rate.size // 10 * 10].reshape(-1, 10).mean(axis=1)
    assert res.bias_stability == pytest.approx(np.std(blocks, ddof=1), rel=1e-12)
    assert res.peak_to_peak == pytest.approx(blocks.max() - blocks.min(), rel=1e-12)
    assert res.averaging_s == 10.0 and res.unit == "deg/h"
    # the drift angle about the stated reference (issue 25/27: it was only checked to exist):
    # b0 = mean of ω − Ω over the first 10 % of the run, θ(t) = ∫ (ω − Ω − b0) dt by the
    # trapezoid rule in degrees (°/h × s / 3600), computed here with numpy alone
    rel = rec.time_s - rec.time_s[0]
    b0 = float(np.mean((rate - omega_up)[rel <= 0.1 * rel[-1]]))
    e = rate - omega_up - b0
    theta = np.concatenate([[0.0], np.cumsum(0.5 * (e[1:] + e[:-1]) * np.diff(rec.time_s))]) / 3600
    assert res.drift_angle_unit == "deg"
    assert res.drift_angle == pytest.approx(theta[-1], rel=1e-9)
    assert res.drift_angle_max == pytest.approx(np.abs(theta).max(), rel=1e-9)
    # the bias rises 0.8 °/h from the −10 °C hold to the 30 °C hold: the angle is not ≈ 0
    assert abs(res.drift_angle) > 0.5
    # four holds; bias per hold ≈ 2 + 0.02 T; the two 10 °C holds pooled → 3 points
    assert len(res.stages) == 4
    assert [round(s.mean_temp_c) for s in res.stages] == [-10, 10, 30, 10]
    # each hold's bias is the truth 2 + 0.02 T with the earth rate removed (noise 0.05 °/h
    # over ≥ 1200 s: σ of a hold mean ≤ 0.0015 °/h)
    for s in res.stages:
        assert s.bias == pytest.approx(2.0 + 0.02 * s.mean_temp_c, abs=0.006)
    # repeatability of the truth's hold biases 1.8, 2.2, 2.6, 2.2: sample σ = 0.3266 °/h
    truth_biases = np.array([1.8, 2.2, 2.6, 2.2])
    expect = math.sqrt(np.sum((truth_biases - truth_biases.mean()) ** 2) / 3.0)
    assert expect == pytest.approx(0.32660, abs=1e-5)
    assert res.bias_repeatability == pytest.approx(expect, abs=0.004)
    ts = res.temperature_sensitivity
    assert ts is not None and ts.n_points == 3
    assert ts.ls_slope == pytest.approx(0.02, abs=0.001)
    assert ts.mean_abs_adjacent == pytest.approx(0.02, abs=0.001)


def test_compute_metrics_accelerometer_and_errors() -> None:
    rng = np.random.default_rng(1)
    t = np.arange(1000.0)
    acc = 0.5 + rng.standard_normal(t.size) * 0.01  # in g
    rec = Recording.from_arrays(t, {"ax": acc}, signal_unit="g")
    res = metrics.compute_metrics(rec, "ax", 100.0)
    assert res.unit == "g" and res.bias == pytest.approx(acc.mean(), rel=1e-12)  # data's unit
    assert res.drift_angle is None
    with pytest.raises(ThermocalInputError, match="gyro"):
        metrics.compute_metrics(rec, "ax", 100.0, 45.0, "up")
    rec2, _temp, _rate = _chamber_recording()
    rec2.meta.latitude_deg = None
    with pytest.raises(ThermocalInputError, match="both"):
        metrics.compute_metrics(rec2, "gyro", 10.0, None, "up")


def test_drift_angle_total_equals_the_curves_end_across_gaps_and_blocks() -> None:
    """The block-by-block end value is the last point of the full curve (same trapezoids,
    nothing across a gap), whatever the block length."""
    from thermocal.metrics import drift_angle, drift_angle_total

    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.5, 1.5, 5000))
    t[2500:] += 100.0  # a gap
    w = 3.0 + rng.standard_normal(t.size)
    end = float(drift_angle(t, w, 2.5)[-1])
    for block in (7, 1000, 1 << 18):
        assert drift_angle_total(t, w, 2.5, block=block) == pytest.approx(end, rel=1e-12)
