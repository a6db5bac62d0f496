"""Units and text-log tests written to kill mutants of the mutation check (issue 27 item
6: ``benchmarks/mutation_check.py``, the mutants named ``units-*`` and ``text-*``).

The expected numbers are written out here from their definitions (SPEC §1: ``ω = N/(τK)``
for pulse outputs, ``N/K`` otherwise; WGS-84 constants from NIMA TR8350.2), not taken
from the package."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from thermocal import units
from thermocal.errors import FileFormatError
from thermocal.readers.options import ReadOptions
from thermocal.readers.text import parse_number, read_text, sniff_text

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


def test_a_row_with_an_empty_field_is_data_not_a_banner() -> None:
    """A headerless log whose first row has a missing value starts at that row
    (mutant text-empty-field-not-number)."""
    lay = sniff_text(["0,,1", "1,2,3", "2,3,4"])
    assert (lay.skip, lay.header, lay.banner) == (0, False, ())


def test_a_line_with_an_empty_name_is_no_header() -> None:
    """``t,,b`` has an empty name: a banner line, not the header (mutant
    text-header-empty-name)."""
    lay = sniff_text(["t,,b", "0,1,2", "1,2,3"])
    assert (lay.skip, lay.header, lay.banner) == (1, False, ("t,,b",))


def test_the_decimal_mark_tie_goes_to_the_point() -> None:
    """``1;2`` reads the same with either decimal mark: a point (mutant
    text-decimal-tie-comma)."""
    assert sniff_text(["1;2", "3;4", "5;6"]).decimal == "."
    assert sniff_text(["1,5;2", "3,25;4", "5;6"]).decimal == ","


def test_underscores_and_foreign_digits_are_not_numbers() -> None:
    """``0_5`` is 5.0 to Python's float, a malformed number here (mutant
    text-underscore-number)."""
    with pytest.raises(ValueError, match="malformed"):
        parse_number("0_5")
    assert parse_number(" -1.5e3 ") == -1500.0


def test_a_row_with_too_many_fields_is_a_bad_line(tmp_path: Path) -> None:
    """A row with four fields in a three-field log: named as bad, or dropped with skip
    (mutant text-wrong-field-count-kept)."""
    f = tmp_path / "log.txt"
    f.write_text("logger v1\nt;a;b\n0;1;2\n1;2;3;4\n2;3;4\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the layout and the skipped line are stated
        with pytest.raises(FileFormatError, match="line 4"):
            read_text(f, "utf-8", ReadOptions())
        df, _info = read_text(f, "utf-8", ReadOptions(on_bad_lines="skip"))
    assert df.shape == (2, 3)
    assert list(df["t"]) == [0.0, 2.0]


def test_ulog_vehicle_imu_integrals_become_rates(tmp_path: Path) -> None:
    """PX4's ``vehicle_imu`` logs Δθ [rad] and Δv [m/s] over Δt [µs]: the reader's rates
    are Δθ/Δt [rad/s] and Δv/Δt [m/s²] with Δt in seconds (mutant ulog-delta-dt-us reads
    Δt in ms: rates 1000× too small).  Written with the test's own ULog writer."""
    from thermocal.readers.dispatch import read_whole_table
    from thermocal.readers.options import ReadOptions
    from ulog_writer import ulog_bytes

    fields = [("uint64_t", "timestamp"), ("float[3]", "delta_angle"),
              ("float[3]", "delta_velocity"), ("uint32_t", "delta_angle_dt"),
              ("uint32_t", "delta_velocity_dt")]  # fmt: skip
    w, a, dt_us = (0.1, -0.2, 0.3), (0.5, 0.0, -9.8), 4000
    rows = [
        (1_000_000 + k * dt_us, *(x * dt_us * 1e-6 for x in w), *(x * dt_us * 1e-6 for x in a),
         dt_us, dt_us)
        for k in range(200)
    ]  # fmt: skip
    log = tmp_path / "imu.ulg"
    log.write_bytes(ulog_bytes([("vehicle_imu", 0, fields, rows)]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        df, info = read_whole_table(log, ReadOptions(topic="vehicle_imu"))
    for i in range(3):
        np.testing.assert_allclose(df[f"gyro_rad_s[{i}]"], w[i], rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(df[f"accel_m_s2[{i}]"], a[i], rtol=1e-6, atol=1e-9)
    assert info["time_unit"] == "us"
