"""Controller presets (issue 31 item 2): ``[chamber] preset = "eurotherm-2000"`` fills in the
register map of the Eurotherm 2000 series' communications handbook (HA026230: PV at Modbus
address 1, setpoint 1 at 24; the addresses are written out here from the handbook's table,
not read from the code), refuses a map key that disagrees with it, and needs ``scale``.  A
simulated controller with that map (pymodbus's server on 127.0.0.1) is read and written
through the preset."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

pytest.importorskip("pymodbus")
pytest.importorskip("serial")

from station_toml import sensor_toml
from thermocal.cli import main
from thermocal.station.config import parse_station
from thermocal.station.run import run_station
from thermocal.station.sim import ChamberModel, SimulatedChamber, SimulatedSerialSensor

HA026230_PV = 1  # process variable (read)
HA026230_SP1 = 24  # setpoint 1 (read/write)


def _toml(port: int, chamber: str, device: str = "/dev/null") -> str:
    return f"""part_s = 0.5
[chamber]
driver = "modbus-tcp"
host = "127.0.0.1"
port = {port}
poll_s = 0.1
io_timeout_s = 0.5
{chamber}
""" + sensor_toml(device)


def test_preset_fills_the_handbook_map_and_refuses_a_disagreement(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cfg = parse_station(_toml(502, 'preset = "eurotherm-2000"\nscale = 0.1'))
    ch = cfg.chamber
    assert (ch.setpoint_register, ch.temperature_register) == (HA026230_SP1, HA026230_PV)
    assert ch.register_kind == "holding" and ch.signed and ch.scale == 0.1
    assert ch.preset == "eurotherm-2000"
    same = parse_station(_toml(502, 'preset = "eurotherm-2000"\nscale = 1\nsetpoint_register = 24'))
    assert same.chamber.setpoint_register == HA026230_SP1 and same.chamber.scale == 1.0

    for chamber, words in (
        ('preset = "eurotherm-2000"\nscale = 0.1\nsetpoint_register = 2', "disagrees"),
        ('preset = "eurotherm-2000"', "needs scale"),
        ('preset = "watlow-f9"\nscale = 0.1', "unknown preset 'watlow-f9'"),
    ):
        toml = tmp_path / "st.toml"
        toml.write_text(_toml(502, chamber))
        assert main(["station", "check", str(toml)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0] and str(toml) in err[0], err


def test_a_controller_with_the_preset_map_is_read_and_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    k = 500.0
    # a slow chamber (τ = 10⁵ s at real time): its temperature stays put while it is read
    model = ChamberModel(time_scale=1.0, tau_s=1e5)
    model.setpoint_c = 37.5  # distinct from the temperature: which register was read shows
    sim = SimulatedChamber(
        model=model, scale=0.1, setpoint_register=HA026230_SP1,
        temperature_register=HA026230_PV,
    ).start()  # fmt: skip
    sen = SimulatedSerialSensor(model, rate_hz=50, time_scale=k).start()
    try:
        toml = tmp_path / "st.toml"
        toml.write_text(_toml(sim.port, 'preset = "eurotherm-2000"\nscale = 0.1', sen.device))
        assert main(["station", "check", str(toml), "--listen", "1", "--json"]) == 0
        out = json.loads(capsys.readouterr().out)["chamber"]
        assert out["setpoint_c"] == pytest.approx(37.5)
        assert out["temperature_c"] == pytest.approx(model.temperature_c, abs=0.11)

        program = ([0.0, 600.0, 1200.0], [-15.0, -15.0, 60.0])
        stop_at = time.monotonic() + 2.0
        run_station(parse_station(toml.read_text()), program, tmp_path / "rec",
                    time_scale=k, should_stop=lambda: time.monotonic() > stop_at)  # fmt: skip
    finally:
        sen.stop()
        sim.stop()
    writes = [v for _t, v in sim.writes]
    assert writes[0] == pytest.approx(-15.0)  # the program's first set-point, in register 24
    assert writes[-1] == pytest.approx(25.0)  # the safe set-point on stop
