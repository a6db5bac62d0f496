"""The firmware dialects are one table (thermocal.firmware.formats.FORMATS): what the
exporters check comes from it, and a dialect added there is checked with no other edit."""

from __future__ import annotations

import pytest

from thermocal.errors import ThermocalInputError
from thermocal.export.params import ParamSet, check_documented
from thermocal.firmware.formats import FORMATS, Documented, FirmwareFormat, firmware_format


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
