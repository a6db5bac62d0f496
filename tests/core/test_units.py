"""Units: constants and conversions against independently known values."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from thermocal import units
from thermocal.errors import UnitError


def test_earth_rate_in_deg_per_hour() -> None:
    # 7.292115e-5 rad/s = 15.041 °/h (SPEC symbols)
    assert_allclose(units.EARTH_RATE_DEG_H, 7.292115e-5 * 206264.80624709636, rtol=1e-12)
    assert_allclose(units.EARTH_RATE_DEG_H, 15.041067, rtol=1e-7)


def test_rate_conversions_round_trip() -> None:
    assert_allclose(units.convert(1.0, "deg/s", "deg/h"), 3600.0)
    assert_allclose(units.convert(1.0, "rad/s", "deg/s"), 180.0 / math.pi)
    assert_allclose(units.convert(units.convert(0.123, "deg/h", "rad/s"), "rad/s", "deg/h"), 0.123)
    # 1 °/h = π/(180·3600) rad/s = 4.84813681109536e-6 rad/s (1 arcsec in rad)
    assert_allclose(units.DH_TO_RS, 4.84813681109536e-6, rtol=1e-14)
    assert_allclose(units.convert(1.0, "rad/s", "deg/h"), 206264.80624709636, rtol=1e-14)


def test_accel_conversions() -> None:
    assert_allclose(units.convert(1.0, "g", "mg"), 1000.0)
    assert_allclose(units.convert(9.80665, "m/s^2", "g"), 1.0)
    assert_allclose(units.convert(1000.0, "ug", "mg"), 1.0)


def test_arcsec_and_ppm() -> None:
    assert_allclose(units.ARCSEC_TO_RAD, math.pi / 180 / 3600)
    assert units.PPM == 1e-6


def test_cross_kind_conversion_refused() -> None:
    with pytest.raises(UnitError, match="different kinds"):
        units.convert(1.0, "deg/h", "mg")


def test_unknown_unit_named() -> None:
    with pytest.raises(UnitError, match="furlongs"):
        units.normalize_signal_unit("furlongs/fortnight")
    with pytest.raises(UnitError, match="kelvin"):
        units.normalize_temperature_unit("kelvin")


@pytest.mark.parametrize(
    ("latitude", "axis", "expected"),
    [
        (90.0, "up", units.EARTH_RATE_DEG_H),
        (0.0, "up", 0.0),
        (0.0, "north", units.EARTH_RATE_DEG_H),
        (30.0, "up", units.EARTH_RATE_DEG_H * 0.5),
        (45.0, "east", 0.0),
    ],
)
def test_earth_rate_on_axis(latitude: float, axis: str, expected: float) -> None:
    assert_allclose(
        units.earth_rate_on_axis_deg_h(latitude, units.parse_axis(axis)), expected, atol=1e-12
    )


def test_pulse_counts_to_rate() -> None:
    # K = 1 pulse/arcsec, τ = 1 s: 15 pulses per second = 15 arcsec/s = 15 °/h (SPEC §1)
    rate, unit = units.counts_to_physical(np.array([15.0]), 1.0, "counts/arcsec", 1.0)
    assert unit == "deg/h"
    assert_allclose(rate, [15.0])
    # MEMS LSB: 1000 LSB/g → 500 LSB = 500 mg
    acc, unit = units.counts_to_physical(np.array([500.0]), 1000.0, "counts/g", 0.01)
    assert unit == "mg"
    assert_allclose(acc, [500.0])
