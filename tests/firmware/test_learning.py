"""The firmware's own temperature learning emulated (thermocal.firmware.learning), judged
against the firmware's published sources restated HERE, sample by sample, independently of
the module: ArduPilot ``AP_InertialSensor_tempcal.cpp`` ``Learn::add_sample`` /
``save_calibration``, ``polyfit.cpp`` and ``LowPassFilter2p.cpp``; PX4
``temperature_calibration/gyro.cpp``, ``accel.cpp``, ``polyfit.hpp``."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from learning_reference import _biquad, f32, reference_learning, reference_px4, sweep
from thermocal.errors import ParameterError
from thermocal.firmware.learning import (
    ardupilot_learning,
    ardupilot_temperature_filter,
    px4_oncal,
)


def test_filter_is_the_firmware_biquad():
    """The float32 recursion against scipy's lfilter with the same float32 coefficients
    run in float64 (the recursion's float32 rounding, poles 5e-4 of Nyquist: < 0.05 °C),
    and its DC gain: (b0 + b1 + b2) / (1 + a1 + a2) with the coefficients rounded to float
    is 1.0074, not 1 (1 + a1 + a2 ≈ 1e-5 keeps ~2 significant digits in float32): a constant
    30 °C comes out at 30.22 °C, as the firmware's filter would give it."""
    x = 20.0 + np.cumsum(np.random.default_rng(1).standard_normal(5000)) * 0.01
    b0, b1, b2, a1, a2 = (float(c) for c in _biquad(1000.0, 0.5))
    zi = signal.lfilter_zi([b0, b1, b2], [1.0, a1, a2]) * x[0]
    ref, _ = signal.lfilter([b0, b1, b2], [1.0, a1, a2], x, zi=zi)
    got = ardupilot_temperature_filter(x)
    assert np.max(np.abs(got - ref)) < 0.05
    gain = (b0 + b1 + b2) / float(f32(f32(1.0) + f32(a1) + f32(a2)))
    assert gain == pytest.approx(1.0074, abs=5e-4)
    flat = ardupilot_temperature_filter(np.full(3000, 30.0))
    assert float(flat[-1]) == pytest.approx(30.0 * gain, abs=2e-3)


@pytest.mark.parametrize("spc", [1.0, 40.0])
def test_ardupilot_completed_equals_the_restated_firmware(spc):
    t, temp, acc, gyr = sweep(60_000, 25.0, 15.0, 0.02, seed=2)  # 15 → 63 °C in 40 min
    g, st = reference_learning(t, temp, acc, gyr, 45.0, spc)
    r = ardupilot_learning(t, temp, acc, gyr, tmax_c=45.0, samples_per_sample=spc)
    assert g["outcome"] == "completed" and r.outcome == "completed" and r.completed
    assert set(r.stored) == set(g["stored"])
    for k, v in g["stored"].items():
        assert r.stored[k] == pytest.approx(v, rel=1e-5, abs=1e-6), k
    for s, pts in ((0, r.accel_points), (1, r.gyro_points)):
        ref = np.array(st[s]["pts"])
        got = np.array([(p.temp_c, *p.xyz, p.n) for p in pts])
        assert got.shape == ref.shape
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-6)
    # the gyro's last window is not added: the accelerometer's finished the learning first
    assert len(r.gyro_points) == len(r.accel_points) - 1
    assert r.stored["INS_TCAL1_TMAX"] >= 45.0 and r.stored["INS_TCAL1_TMIN"] < 16.5


def test_ardupilot_recovers_a_known_cubic():
    """A slow ramp whose filter lag is negligible (the driver at 40× the log's rate): the
    stored GYR1..3 X are the truth ×1e6 (2e-4, 3e-6, -5e-8 rad/s per °C^k)."""
    t, temp, acc, gyr = sweep(100_000, 25.0, 10.0, 0.015, seed=3)
    r = ardupilot_learning(t, temp, acc, gyr, tmax_c=65.0, samples_per_sample=40.0)
    assert r.outcome == "completed"
    assert r.stored["INS_TCAL1_GYR1_X"] == pytest.approx(200.0, abs=1.0)
    assert r.stored["INS_TCAL1_GYR2_X"] == pytest.approx(3.0, abs=0.1)
    assert r.stored["INS_TCAL1_GYR3_X"] == pytest.approx(-0.05, abs=0.01)
    assert r.stored["INS_TCAL1_GYR1_Y"] == pytest.approx(-100.0, abs=1.0)
    assert r.stored["INS_TCAL1_ACC1_X"] == pytest.approx(2000.0, abs=10.0)


def test_ardupilot_short_sweep_not_completed():
    t, temp, acc, gyr = sweep(20_000, 25.0, 20.0, 0.01, seed=4)  # 8 °C in 800 s
    r = ardupilot_learning(t, temp, acc, gyr, samples_per_sample=40.0)
    g, _ = reference_learning(t, temp, acc, gyr, 70.0, 40.0)
    assert g["outcome"] is None and not g["stored"]
    assert r.outcome == "not completed" and not r.completed and r.stored == {}
    rise = float(r.highest_c) - r.start_c
    assert 7.0 < rise < 8.0
    assert r.reason.startswith(f"not completed: the temperature rose {rise:.1f} °C of the 10 °C")


def test_ardupilot_times_out_on_a_plateau():
    """Heated to a hold 12 °C above the start, below TMAX: 600 s without a 0.5 °C step
    after the 10 °C rise finish the learning with TMAX the last point's temperature."""
    t, temp, acc, gyr = sweep(60_000, 25.0, 20.0, 0.01, seed=5)
    temp = np.minimum(temp, 32.0)
    g, _ = reference_learning(t, temp, acc, gyr, 70.0, 40.0)
    r = ardupilot_learning(t, temp, acc, gyr, samples_per_sample=40.0)
    assert g["outcome"] == r.outcome == "timed out" and r.completed
    for k, v in g["stored"].items():
        assert r.stored[k] == pytest.approx(v, rel=1e-5, abs=1e-6), k
    assert r.stored["INS_TCAL1_TMAX"] == pytest.approx(r.accel_points[-1].temp_c, abs=0.3)
    last = r.accel_points[-1].time_s
    assert 600.0 < r.end_time_s - last < 601.0
    assert r.reason.startswith("timed out: no 0.5 °C rise for 600 s")


def test_ardupilot_partial_save_when_the_log_ends_early():
    # 20 → 44 °C, TMAX 70: a point every 10 s, a partial save every other one
    t, temp, acc, gyr = sweep(12_000, 25.0, 20.0, 0.05, seed=6)
    g, _ = reference_learning(t, temp, acc, gyr, 70.0, 40.0)
    r = ardupilot_learning(t, temp, acc, gyr, samples_per_sample=40.0)
    assert g["outcome"] is None and g["stored"]
    assert r.outcome == "not completed" and r.partial
    for k, v in g["stored"].items():
        assert r.stored[k] == pytest.approx(v, rel=1e-5, abs=1e-6), k
    assert "below INS_TCAL1_TMAX 70.0 °C" in r.reason and "partial save" in r.reason


def test_ardupilot_bad_inputs():
    t, temp, acc, gyr = sweep(1000, 25.0, 20.0, 0.01)
    with pytest.raises(ParameterError, match="gyro"):
        ardupilot_learning(t, temp, acc, gyr[:10])
    with pytest.raises(ParameterError, match="time_s"):
        ardupilot_learning(t[::-1], temp, acc, gyr)
    with pytest.raises(ParameterError, match="samples_per_sample"):
        ardupilot_learning(t, temp, acc, gyr, samples_per_sample=1000.0)


# --- PX4 ---------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["gyro", "accel"])
def test_px4_completed_equals_the_restated_firmware(kind):
    t, temp, acc, gyr = sweep(50_000, 20.0, 6.0, 0.012, seed=7)  # 6 → 36 °C
    v = gyr if kind == "gyro" else acc
    outcome, (low, high, _ref, p) = reference_px4(t, temp, v, 24, 5, 10, kind == "accel")
    r = px4_oncal(t, temp, v, kind=kind, instance=1)
    assert outcome == r.outcome == "completed"
    tag = "G" if kind == "gyro" else "A"
    assert r.stored[f"TC_{tag}1_TMIN"] == float(low) and r.stored[f"TC_{tag}1_TMAX"] == float(high)
    assert r.stored[f"TC_{tag}1_TREF"] == pytest.approx(float(low) + 12.0, abs=1e-5)
    for axis in range(3):
        for k in range(4):
            got = r.stored[f"TC_{tag}1_X{3 - k}_{axis}"]
            assert got == pytest.approx(p[k, axis], rel=1e-5, abs=1e-12), (axis, k)
    # and against the truth (the sweep's cubic in T − 35, about TREF)
    if kind == "gyro":
        assert r.stored["TC_G1_X1_1"] == pytest.approx(-1e-4, rel=0.02)


def test_px4_stops_short_and_too_hot():
    t, temp, _acc, gyr = sweep(30_000, 20.0, 6.0, 0.012, seed=8)  # 6 → 24 °C
    r = px4_oncal(t, temp, gyr)
    outcome, (low, high) = reference_px4(t, temp, gyr, 24, 5, 10)
    assert outcome == r.outcome == "not completed" and r.stored == {}
    rise = float(high - low)
    assert r.reason.startswith(f"not completed: the temperature rose {rise:.1f} °C of the 24 °C")
    assert r.progress == int(rise / 24 * 100)
    hot = px4_oncal(t, temp + 10.0, gyr)
    assert hot.outcome == "too hot" and "SYS_CAL_TMAX 10" in hot.reason
    cold = px4_oncal(t, temp - 20.0, gyr)
    assert cold.outcome == "not started" and "SYS_CAL_TMIN 5" in cold.reason
