"""Units (:mod:`thermocal.units`) against numbers written out here from their definitions
(``ω = N/(τK)`` for pulse outputs, ``N/K`` otherwise; WGS-84 constants from NIMA
TR8350.2), not taken from the package.  Each kills a mutant of
``benchmarks/mutation_check.py`` (``units-*``)."""

from __future__ import annotations

import math

import pytest

from thermocal import units

ARCSEC_PER_RAD = 180.0 / math.pi * 3600.0  # 206 264.806…


@pytest.mark.parametrize(
    ("k_unit", "counts", "k", "tau_s", "want", "unit"),
    [
        # 10 pulses over 10 ms, 100 pulses per degree: 10 °/s = 36 000 °/h
        ("counts/deg", 10.0, 100.0, 0.01, 36000.0, "deg/h"),
        # 1 pulse a second, 1 pulse per arcsec: 1 ″/s = 1 °/h
        ("counts/arcsec", 1.0, 1.0, 1.0, 1.0, "deg/h"),
        # 1 pulse a second, 1 pulse per radian: 1 rad/s = 206 264.8 °/h
        ("counts/rad", 1.0, 1.0, 1.0, ARCSEC_PER_RAD, "deg/h"),
        # MEMS LSB: 500 LSB at 1000 LSB/(°/s) = 0.5 °/s = 1800 °/h, whatever τ
        ("counts/(deg/s)", 500.0, 1000.0, 0.01, 1800.0, "deg/h"),
        # 250 LSB at 1000 LSB/g = 0.25 g = 250 mg
        ("counts/g", 250.0, 1000.0, 0.01, 250.0, "mg"),
        ("counts/mg", 250.0, 1000.0, 0.01, 0.25, "mg"),
    ],
)
def test_counts_to_physical_by_hand(
    k_unit: str, counts: float, k: float, tau_s: float, want: float, unit: str
) -> None:
    """Each scale-factor unit against SPEC §1 worked by hand (mutants units-counts-per-degree,
    units-counts-per-rad, units-counts-per-g, units-pulse-without-tau)."""
    got, got_unit = units.counts_to_physical([counts], k, k_unit, tau_s)
    assert got_unit == unit
    assert float(got[0]) == pytest.approx(want, rel=1e-12)


def test_int16_temperature_counts_by_hand() -> None:
    """Two's complement stored unsigned: 32768 is −32768, 65535 is −1, 32767 stays
    (mutant units-int16-sign)."""
    conv = units.TemperatureConversion(0.01, 25.0, "int16")
    got = conv.to_celsius([32767.0, 32768.0, 65535.0, 0.0])
    assert list(got) == pytest.approx([25.0 + 327.67, 25.0 - 327.68, 25.0 - 0.01, 25.0])


def test_normal_gravity_at_the_equator_and_the_poles() -> None:
    """WGS-84 (NIMA TR8350.2 table 3.4): γe = 9.7803253359, γp = 9.8321849378 m/s² — the
    poles included (mutants units-somigliana-sign, units-latitude-bound-strict)."""
    assert units.normal_gravity_m_s2(0.0) == pytest.approx(9.7803253359, abs=1e-10)
    assert units.normal_gravity_m_s2(90.0) == pytest.approx(9.8321849378, abs=1e-9)
    assert units.normal_gravity_m_s2(-90.0) == pytest.approx(9.8321849378, abs=1e-9)


def test_unit_constants_by_hand() -> None:
    """1 mg = 9.80665e-3 m/s²; an ARW of 1 °/h/√Hz is 1/60 °/√h (√3600 s in an hour)
    (mutants units-mg-factor, units-arw-per-60)."""
    assert pytest.approx(9.80665e-3, rel=1e-15) == units.MG_TO_MS2
    assert pytest.approx(1.0 / math.sqrt(3600.0)) == units.ARW_DEG_SQRT_H_PER_DEG_H_SQRT_HZ
    assert float(units.convert(1.0, "mg", "m/s^2")) == pytest.approx(9.80665e-3, rel=1e-15)
