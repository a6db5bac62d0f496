"""The firmware dialects are one table (thermocal.firmware.formats.FORMATS): what the
exporters check comes from it, and a dialect added there is checked with no other edit."""

from __future__ import annotations

import pytest

from thermocal.errors import ThermocalInputError
from thermocal.export.params import ParamSet, check_documented
from thermocal.firmware.formats import (
    FORMATS,
    Documented,
    FirmwareFormat,
    ParamsFileLayout,
    firmware_format,
)


def test_the_table_holds_what_the_firmwares_publish() -> None:
    px4, ap = FORMATS["px4"], FORMATS["ardupilot"]
    # TemperatureCompensation.h: GYRO_COUNT_MAX = ACCEL_COUNT_MAX = 4; TC_B X0..X5; TC_M X0..X3
    assert px4.max_instances == 4 and px4.tref_c is None and px4.scale == 1.0
    assert [(k, s.order, s.n_axes, s.unit) for k, s in px4.sensors.items()] == [
        ("gyro", 3, 3, "rad/s"), ("accel", 3, 3, "m/s^2"), ("baro", 5, 1, "Pa"),
        ("mag", 3, 3, "gauss"),
    ]  # fmt: skip
    # AP_InertialSensor_tempcal.cpp: TEMP_REFERENCE 35, coefficients x1e6, INS_TCAL1..3
    assert (ap.tref_c, ap.scale, ap.max_instances) == (35.0, 1e-6, 3)
    assert (px4.params_file, ap.params_file) == ("px4.params", "ardupilot.parm")


def test_a_dialect_registered_in_the_table_is_checked(monkeypatch: pytest.MonkeyPatch) -> None:
    ps = ParamSet("toy", {"TOY_ENABLE": 2}, {"TOY_ENABLE": 6})
    check_documented(ps)  # nobody documents TOY_ENABLE yet
    toy = FirmwareFormat(
        "toy", "toy parameters", "toy.params", 1, "TOY0", 20.0, 1.0,
        documented=(Documented(r"TOY_ENABLE", 6, 0, 1, True, "toy firmware manual"),),
    )  # fmt: skip
    monkeypatch.setitem(FORMATS, "toy", toy)
    assert firmware_format("toy") is toy
    with pytest.raises(ThermocalInputError, match=r"TOY_ENABLE = 2: outside 0…1 \(toy firmware"):
        check_documented(ps)


def test_a_dialect_writes_its_parameter_file_from_its_layout(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """ParamSet.text is one code path over the table: a dialect's file is its layout's
    opening, the provenance line, its closing and one row per parameter (int32 as an
    integer, floats as Python's shortest repr) — the text expected is written out here."""
    toy = FirmwareFormat(
        "toy", "toy parameters", "toy.params", 1, "TOY0", 20.0, 1.0,
        layout=ParamsFileLayout("{name}={value};{type}", ("# toy v1",), ("# end",), "TOY_*"),
    )  # fmt: skip
    monkeypatch.setitem(FORMATS, "toy", toy)
    ps = ParamSet("toy", {"TOY_ENABLE": 1, "TOY_X0": 0.1 + 0.2}, {"TOY_ENABLE": 6})
    assert ps.text() == (
        "# toy v1\n# thermocal export-params --format toy (TOY_*)\n# end\n"
        "TOY_ENABLE=1;6\nTOY_X0=0.30000000000000004;9\n"
    )
    with pytest.raises(ThermocalInputError, match="format must be one of"):
        ParamSet("nope").text()


def test_the_built_in_layouts_write_the_files_ground_stations_load() -> None:
    """PX4: QGroundControl's tab-separated ``Vehicle-Id Component-Id Name Value Type``
    after its header; ArduPilot: ``NAME VALUE`` lines (Mission Planner's .parm)."""
    px4 = ParamSet("px4", {"TC_G0_ID": 2293768, "TC_G0_X0_0": -0.5}, {"TC_G0_ID": 6})
    assert px4.text() == (
        "# Onboard parameters for Vehicle 1\n#\n"
        "# thermocal export-params --format px4 (thermal compensation, TC_*)\n#\n"
        "# Vehicle-Id Component-Id Name Value Type\n"
        "1\t1\tTC_G0_ID\t2293768\t6\n1\t1\tTC_G0_X0_0\t-0.5\t9\n"
    )
    ap = ParamSet(
        "ardupilot", {"INS_TCAL1_ENABLE": 1, "INS_TCAL1_TMIN": 5}, {"INS_TCAL1_ENABLE": 6}
    )
    assert ap.text() == (
        "# thermocal export-params --format ardupilot (INS_TCAL*)\n"
        "INS_TCAL1_ENABLE 1\nINS_TCAL1_TMIN 5.0\n"
    )
