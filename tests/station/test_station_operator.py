"""Issue 31 items 2 and 5: a chamber run by hand (``driver = "none"``) is shown the program
step by step (each step's goal once, not every value of a ramp); a chamber that stays away
from its set-point is reported; off a terminal the run prints a line per step and event and
no screen codes; the live display shows what the contract lists."""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import pyarrow.parquet as pq
import pytest

pytest.importorskip("pymodbus")
pytest.importorskip("serial")

from station_toml import sensor_toml
from thermocal.cli import main
from thermocal.station.display import render
from thermocal.station.run import SensorView, StationState
from thermocal.station.sim import ChamberModel, SimulatedChamber, SimulatedSerialSensor

K = 1000.0
# hold 25 °C, ramp to −10 °C, hold: three steps, two goals
PROGRAM = ((0.0, 300.0, 900.0, 1500.0), (25.0, 25.0, -10.0, -10.0))


def _profile(tmp: Path) -> Path:
    p = tmp / "p.csv"
    rows = "".join(f"{t},{c}\n" for t, c in zip(*PROGRAM, strict=True))
    p.write_text("time_s,setpoint_c\n" + rows)
    return p


def test_a_chamber_run_by_hand_is_told_each_step_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    model = ChamberModel(time_scale=K, tau_s=60.0)
    sen = SimulatedSerialSensor(model, rate_hz=50, time_scale=K).start()
    try:
        toml = tmp_path / "st.toml"
        toml.write_text('part_s = 0.5\n[chamber]\ndriver = "none"\nsafe_setpoint_c = 22\n'
                        + sensor_toml(sen.device))  # fmt: skip
        out = tmp_path / "rec"
        rc = main(["station", "run", str(toml), "--profile", str(_profile(tmp_path)),
                   "-o", str(out), "--time-scale", str(K)])  # fmt: skip
    finally:
        sen.stop()
    err = capsys.readouterr().err
    assert rc == 0, err
    told = [ln for ln in err.splitlines() if ln.startswith("operator:")]
    # the two goals of the program, then the safe set-point: no line per ramp value
    assert told == [
        "operator: set the chamber to 25.00 °C",
        "operator: set the chamber to -10.00 °C",
        "operator: set the chamber to 22.00 °C",
    ], told
    steps = [ln.split(":")[0] for ln in err.splitlines() if ln.startswith("step ")]
    assert steps == ["step 1/3", "step 2/3", "step 3/3"]
    assert "\x1b" not in err  # not a terminal: plain lines, no screen codes
    chamber = pq.read_table(sorted(out.glob("chamber-*.parquet"))[0]).to_pandas()
    assert chamber["chamber_c"].isna().all()  # nobody measured the chamber


def test_a_chamber_away_from_its_setpoint_is_reported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    model = ChamberModel(time_scale=K, tau_s=1e9)  # a broken chamber: it stays at 25 °C
    sim = SimulatedChamber(model=model, scale=0.1).start()
    sen = SimulatedSerialSensor(model, rate_hz=50, time_scale=K).start()
    try:
        toml = tmp_path / "st.toml"
        toml.write_text(f"""part_s = 0.5
[chamber]
driver = "modbus-tcp"
host = "127.0.0.1"
port = {sim.port}
setpoint_register = 300
temperature_register = 100
scale = 0.1
poll_s = 0.05
tolerance_c = 5
drift_s = 200
""" + sensor_toml(sen.device))  # fmt: skip
        out = tmp_path / "rec"
        rc = main(["station", "run", str(toml), "--profile", str(_profile(tmp_path)),
                   "-o", str(out), "--time-scale", str(K)])  # fmt: skip
    finally:
        sen.stop()
        sim.stop()
    err = capsys.readouterr().err
    assert rc == 0, err
    drift = [ln for ln in err.splitlines() if "from its set-point" in ln]
    assert len(drift) == 1 and drift[0].startswith("warning: chamber 25.00 °C"), err
    # the chamber leaves the 5 °C band when the ramp passes 20 °C (program 300 + 5/35·600 s)
    # and is reported drift_s = 200 s of program time later
    events = json.loads((out / "station.json").read_text())["events"]
    (ev,) = [e for e in events if e["kind"] == "drift"]
    assert 300 + 600 * 5 / 35 + 200 <= ev["program_s"] <= 300 + 600 * 5 / 35 + 200 + 0.1 * K


def test_the_live_display_shows_step_setpoint_chamber_sensors_and_time_left() -> None:
    from rich.console import Console

    state = StationState(
        step=2, n_steps=5, program_s=1200.0, end_s=4800.0, setpoint_c=-12.5, chamber_c=-11.8,
        time_scale=2.0, samples=123456, parts=7,
        sensors=[SensorView("imu1", 99.9, (0.01, -3.25), ("gx", "temp"), 4, 120000, False),
                 SensorView("imu2", math.nan, (), ("gx", "temp"), 0, 3456, True)],
    )  # fmt: skip
    con = Console(record=True, width=160, file=io.StringIO())
    con.print(render(state))
    text = con.export_text()
    for words in ("step 2/5", "set-point -12.50 °C", "chamber -11.80 °C",
                  "time left 0:30:00", "samples recorded 123,456", "parts closed 7",
                  "imu1", "99.9", "temp=-3.25", "120,000", "STOPPED"):  # fmt: skip
        assert words in text, (words, text)
