"""A chamber's own log parsed: clocks (hh:mm, hh:mm:ss, 12 h), dates (a column, the header,
day-first or month-first, midnight), units (°F, °C, K from the header, a units row or the
option) and channels (process value, set-point, by name)."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import pytest

from chamber_logs import air_c, write_log
from thermocal.errors import ThermocalInputError
from thermocal.readers.chamber_log import parse_chamber_log, read_chamber_log
from thermocal.readers.options import ChamberLogSpec


def _spec(path: Path, **given: object) -> ChamberLogSpec:
    return ChamberLogSpec(str(path), **given)  # type: ignore[arg-type]


@pytest.mark.parametrize("unit", ["degF", "degC", "K"])
def test_units_from_the_header_convert_to_celsius(tmp_path: Path, unit: str) -> None:
    path = write_log(tmp_path / "log.csv", unit=unit, span_s=3600.0, decimals=3)
    log = read_chamber_log(_spec(path))
    # the truth in °C, written in the unit with 3 decimals: back within half a digit
    half_digit = 0.0005 / (1.8 if unit == "degF" else 1.0)
    np.testing.assert_allclose(log.temp_c, air_c(np.arange(0, 3600, 60.0)), atol=half_digit)
    assert (log.unit, log.unit_source, log.channel, log.setpoint) == (
        unit, "header", f"Chamber PV [{ {'degF': '°F', 'degC': '°C', 'K': 'K'}[unit]}]", False
    )  # fmt: skip
    np.testing.assert_array_equal(log.time_s, np.arange(0, 3600, 60.0))


def test_the_option_states_a_unit_the_header_does_not(tmp_path: Path) -> None:
    text = "Time,TC1,TC2\n10:00:00,68.0,50\n10:00:10,77.0,50\n"
    with pytest.raises(ThermocalInputError, match="the unit of channel 'TC1' is not stated"):
        parse_chamber_log(text, ChamberLogSpec("x", channel="TC1"), "x")
    log = parse_chamber_log(text, ChamberLogSpec("x", channel="TC1", unit="degF"), "x")
    assert log.temp_c.tolist() == [20.0, 25.0]  # (68 − 32)/1.8, (77 − 32)/1.8
    assert log.unit_source == "option"


def test_a_units_row_under_the_header(tmp_path: Path) -> None:
    text = "Time,CH01,CH02\n,K,°C\n10:00:00,300.15,20\n10:00:10,301.15,21\n"
    log = parse_chamber_log(text, ChamberLogSpec("x", channel="CH01"), "x")
    np.testing.assert_allclose(log.temp_c, [27.0, 28.0], atol=1e-12)  # K − 273.15
    assert parse_chamber_log(text, ChamberLogSpec("x", channel="ch02"), "x").unit == "degC"


def test_an_option_contradicting_the_header_is_refused() -> None:
    text = "Time,TC1 [°C]\n10:00,20\n10:01,21\n"
    with pytest.raises(ThermocalInputError, match="in degC by its header, chamber_unit says degF"):
        parse_chamber_log(text, ChamberLogSpec("x", unit="degF"), "x")


def test_twelve_hour_clocks_cross_noon(tmp_path: Path) -> None:
    start = dt.datetime(2026, 3, 14, 11, 58, 0)
    path = write_log(tmp_path / "log.csv", start=start, period_s=30.0, span_s=300.0, style="12h")
    assert "12:00:00 PM" in path.read_text(encoding="utf-8")
    log = read_chamber_log(_spec(path))
    np.testing.assert_array_equal(log.time_s, np.arange(0, 300, 30.0))
    assert log.start is None  # no date in the log


def test_twelve_am_is_midnight() -> None:
    text = "Date,Time,TC [°C]\n2026-03-14,11:59:50 PM,20\n2026-03-15,12:00:10 AM,21\n"
    log = parse_chamber_log(text, ChamberLogSpec("x"), "x")
    assert log.time_s.tolist() == [0.0, 20.0]
    assert log.start == dt.datetime(2026, 3, 14, 23, 59, 50)


def test_midnight_without_a_date_is_refused_and_with_one_joined(tmp_path: Path) -> None:
    start = dt.datetime(2026, 3, 14, 23, 50, 0)
    path = write_log(tmp_path / "log.csv", start=start, span_s=1800.0)
    with pytest.raises(ThermocalInputError, match="wraps past midnight without a date: give"):
        read_chamber_log(_spec(path))
    log = read_chamber_log(_spec(path, date="2026-03-14"))
    np.testing.assert_array_equal(log.time_s, np.arange(0, 1800, 60.0))
    assert log.start == start
    dated = write_log(tmp_path / "dated.csv", start=start, span_s=1800.0, date="header")
    assert read_chamber_log(_spec(dated)).start == start


@pytest.mark.parametrize("order", ["dmy", "mdy", "iso"])
def test_a_date_column_day_or_month_first(tmp_path: Path, order: str) -> None:
    start = dt.datetime(2026, 3, 24, 23, 0, 0)  # day 24 > 12: the order is read from it
    path = write_log(tmp_path / "log.csv", start=start, span_s=7200.0, date=order)
    log = read_chamber_log(_spec(path))
    assert log.start == start
    np.testing.assert_array_equal(log.time_s, np.arange(0, 7200, 60.0))


def test_ambiguous_dates_need_the_order(tmp_path: Path) -> None:
    start = dt.datetime(2026, 3, 4, 23, 0, 0)  # 04/03 or 03/04
    path = write_log(tmp_path / "log.csv", start=start, span_s=7200.0, date="dmy")
    with pytest.raises(ThermocalInputError, match="give chamber_date_order dmy or mdy"):
        read_chamber_log(_spec(path))
    assert read_chamber_log(_spec(path, date_order="dmy")).start == start
    assert read_chamber_log(_spec(path, date_order="mdy")).start == dt.datetime(2026, 4, 3, 23)


def test_the_process_value_is_chosen_over_the_set_point() -> None:
    text = "Time\tSet Point [°C]\tChamber PV [°C]\n10:00\t25\t20\n10:01\t25\t21\n"
    log = parse_chamber_log(text, ChamberLogSpec("x"), "x")
    assert log.channel == "Chamber PV [°C]"
    assert log.temp_c.tolist() == [20.0, 21.0]
    sp = parse_chamber_log(text, ChamberLogSpec("x", channel="Set Point"), "x")
    assert sp.setpoint and sp.temp_c.tolist() == [25.0, 25.0]


def test_several_thermocouples_ask_for_one() -> None:
    text = "Time;TC1 [°C];TC2 [°C]\n10:00;20;21\n10:01;21;22\n"
    with pytest.raises(ThermocalInputError, match=r"several channels \('TC1 \[°C\]'.*FILE:CHANNEL"):
        parse_chamber_log(text, ChamberLogSpec("x"), "x")
    assert parse_chamber_log(text, ChamberLogSpec("x", channel="TC2"), "x").temp_c[0] == 21.0
    with pytest.raises(ThermocalInputError, match="no channel 'TC9' in the chamber log"):
        parse_chamber_log(text, ChamberLogSpec("x", channel="TC9"), "x")


def test_the_channel_after_a_colon() -> None:
    spec = ChamberLogSpec.parse("/data/run 3/log.csv:CH01 [°F]", unit="degF")
    assert (spec.path, spec.channel, spec.unit) == ("/data/run 3/log.csv", "CH01 [°F]", "degF")
    assert ChamberLogSpec.parse("log.csv").channel is None


def test_latin1_degree_signs(tmp_path: Path) -> None:
    path = tmp_path / "log.csv"
    path.write_bytes("Time,TC1 [°F]\n10:00,68\n10:01,77\n".encode("cp1252"))
    assert read_chamber_log(_spec(path)).temp_c.tolist() == [20.0, 25.0]
