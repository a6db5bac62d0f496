"""The adequacy tests' boundaries (:mod:`thermocal.adequacy`): samples per coefficient,
the firmware's minimum sweep, Ṫ in °C/min, the robust range and its emptier end, the
moving share.  Each kills a mutant of ``benchmarks/mutation_check.py`` (``adequacy-*``);
the expected values are written out here from the stated definitions, with their numbers."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal import adequacy


def test_ten_samples_per_coefficient_is_enough() -> None:
    """n / p ≥ 10 passes, the boundary included (mutant adequacy-samples-strict)."""
    assert adequacy.samples_test(40, 4).verdict == "pass"
    assert adequacy.samples_test(39, 4).verdict == "fail"
    assert adequacy.samples_test(4, 4).verdict == "fail"


def test_a_sweep_exactly_at_the_firmware_minimum_passes() -> None:
    """ArduPilot needs 10 °C: exactly 10 passes, 9.99 fails (mutant adequacy-firmware-strict)."""
    assert adequacy.firmware_test(10.0, "ardupilot", 10.0).verdict == "pass"
    assert adequacy.firmware_test(9.99, "ardupilot", 10.0).verdict == "fail"


def test_the_temperature_rate_is_in_degrees_per_minute() -> None:
    """A ramp of 1.5 °C/min sampled each second: Ṫ over Δ = 60 s is 1.5 [°C/min] from
    t = 60 s on (mutant adequacy-rate-per-second gives 0.025)."""
    t = np.arange(0.0, 600.0, 1.0)
    rate = adequacy.temperature_rate_c_per_min(t, 20.0 + 1.5 * t / 60.0)
    assert rate.size == t.size - 60
    np.testing.assert_allclose(rate, 1.5, rtol=1e-12)


def test_small_records_span_their_whole_range() -> None:
    """Under 1000 samples the span is max − min (no percentile cut): 999 samples from 20
    to 30 °C and one at 40 °C span 20 °C (mutant adequacy-robust-range-small cuts the
    0.1/99.9 percentiles)."""
    t = np.r_[np.linspace(20.0, 30.0, 998), 40.0]
    span = next(x for x in adequacy.temperature_tests(t, "T", 1) if x.name == "temperature_span")
    assert span.figure == pytest.approx(20.0, abs=1e-12)


def test_the_range_ends_figure_is_the_emptier_end() -> None:
    """989 samples at 20 °C and a ramp of 10 samples to 40 °C: the lowest tenth (≤ 22 °C)
    holds 990 of 999 samples, the highest tenth (≥ 38 °C) one: 0.1 %, a warning (mutant
    adequacy-ends-share judges the fuller end)."""
    t = np.r_[np.full(989, 20.0), np.linspace(20.0, 40.0, 10)]
    ends = next(x for x in adequacy.temperature_tests(t, "T", 1) if x.name == "range_ends")
    assert ends.figure == pytest.approx(100.0 / 999.0, rel=1e-12)
    assert ends.verdict == "warn"


def test_a_gyro_moving_a_tenth_of_the_time_is_refused() -> None:
    """2000 s at 10 Hz, still (10 °/h noise) but for twenty 10 s turns at 3000 °/h (above
    the 0.3 °/s = 1080 °/h floor, below the 20 °/s of a rotating gyro): moving ≈ 10 % of
    the record, more than the 2 % allowed: a failure (mutant adequacy-moving-share-strict
    allows 20 %)."""
    rng = np.random.default_rng(6)
    t = np.arange(0.0, 2000.0, 0.1)
    v = rng.normal(0.0, 10.0, t.size)
    for k in range(20):
        v[(t >= 50.0 + 100.0 * k) & (t < 60.0 + 100.0 * k)] += 3000.0
    res = adequacy.stillness_test(t, v, "gyro", "g")
    assert res.verdict == "fail"
    assert 5.0 < res.figure < 20.0  # [%]
