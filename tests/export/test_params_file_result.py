"""``thermocal.export.params.export_params_file``: its result's ``to_dict()`` is what
``thermocal export-params --json`` prints, and the unit of each firmware's offsets is the
firmware's own (PX4 ``TC_G*``/``TC_A*`` and ArduPilot ``INS_TCAL*``: rad/s and m/s²)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest

from thermocal.cli import main
from thermocal.errors import ThermocalWarning
from thermocal.export.params import export_params_file
from thermocal.simulate import SCENARIOS
from thermocal.writers import write_recording

GYROS = ("gx", "gy", "gz")


@pytest.mark.parametrize("fmt", ["px4", "ardupilot"])
def test_to_dict_and_units(fmt: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ((mod, _truth),) = SCENARIOS["mems-imu"](11, rate_hz=0.2)
    write_recording(mod, tmp_path / "mod.parquet")
    cal = tmp_path / "cal.json"
    assert main(["fit", str(tmp_path / "mod.parquet"), "--model", "poly", "--order", "3",
                 "--signal", ",".join(GYROS), "--temps", "T_die", "-o", str(cal)]) == 0  # fmt: skip
    out = tmp_path / "p.params"
    capsys.readouterr()
    assert main(["export-params", str(cal), "--format", fmt, "-o", str(out), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    with warnings.catch_warnings():  # PX4 without a device id: said by the CLI above
        warnings.simplefilter("ignore", ThermocalWarning)
        res = export_params_file(cal, fmt, out)
    assert json.loads(json.dumps(res.to_dict())) == printed
    # the firmware sources: PX4 TemperatureCompensation.cpp and ArduPilot
    # AP_InertialSensor_tempcal.cpp subtract gyro offsets in rad/s, accel in m/s²
    assert (res.unit_of("gyro"), res.unit_of("accel")) == ("rad/s", "m/s^2")
    assert main(["export-params", str(cal), "--format", fmt, "-o", str(out)]) == 0
    human = capsys.readouterr().out
    assert human.count("rad/s") == sum(a["kind"] == "gyro" for a in printed["axes"]) > 0
