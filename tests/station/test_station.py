"""The test station (issue 31): a real pymodbus server simulating the chamber (first-order
dynamics) on 127.0.0.1 with an OS-chosen port, serial sensors on pseudo-terminals streaming
``gx,temp`` lines with a known thermal bias, accelerated programs (--time-scale).

Every wait has a time limit.  Expected values are computed here from the program and the
lines the simulated sensor actually sent, not from the station's own records.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

pytest.importorskip("pymodbus")
pytest.importorskip("serial")

from station_toml import sensor_toml
from thermocal.cli import main
from thermocal.station.config import parse_station
from thermocal.station.run import run_station
from thermocal.station.sim import (
    ChamberModel,
    GyroTruth,
    SimulatedChamber,
    SimulatedSerialSensor,
)

SCALE = 0.01  # °C per count of the simulated controller
PROGRAM = ([0.0, 300.0, 900.0, 1500.0, 2400.0, 3000.0], [25.0, 25.0, -10.0, -10.0, 70.0, 70.0])
SRC = str(Path(__file__).resolve().parents[2] / "src")


def _toml(port: int, sensors: list[tuple[str, str]], **extra: object) -> str:
    ch = "\n".join(f"{k} = {json.dumps(v)}" for k, v in extra.items())
    text = f"""part_s = 0.5
[chamber]
driver = "modbus-tcp"
host = "127.0.0.1"
port = {port}
setpoint_register = 300
temperature_register = 100
register_kind = "input"
scale = {SCALE}
signed = true
poll_s = 0.1
io_timeout_s = 0.3
{ch}
"""
    for sid, dev in sensors:
        text += sensor_toml(dev, sid)
    return text


@pytest.fixture
def rig(tmp_path: Path):  # type: ignore[no-untyped-def]
    """A chamber server and one pseudo-terminal gyro, K = 500."""
    k = 500.0
    model = ChamberModel(time_scale=k, tau_s=60.0)
    sim = SimulatedChamber(model=model, scale=SCALE).start()
    sen = SimulatedSerialSensor(
        model, rate_hz=50, time_scale=k, truth=GyroTruth(tau_s=30.0), bad_every=41,
        banner=("BMI270 logger v1.2 (c) ACME",),
    ).start()  # fmt: skip
    prof = tmp_path / "p.csv"
    prof.write_text(
        "time_s,setpoint_c\n" + "".join(f"{t},{c}\n" for t, c in zip(*PROGRAM, strict=True))
    )
    yield {"k": k, "sim": sim, "sen": sen, "model": model, "prof": prof, "tmp": tmp_path}
    sen.stop()
    sim.stop()


def _recorded(out: Path, sid: str) -> list[tuple[float, float]]:
    rows: list[tuple[float, float]] = []
    for p in sorted(out.glob(f"{sid}-*.parquet")):
        t = pq.read_table(p, columns=["gx", "temp"])
        rows += list(zip(t["gx"].to_pylist(), t["temp"].to_pylist(), strict=True))
    return rows


def _contiguous_in(recorded: list[tuple[float, float]], sent: list[tuple[float, float]]) -> int:
    """Index in ``sent`` where ``recorded`` starts as one unbroken run (else fail)."""
    assert recorded, "nothing recorded"
    starts = [i for i, s in enumerate(sent) if s == recorded[0]]
    for i in starts:
        if sent[i : i + len(recorded)] == recorded:
            return i
    raise AssertionError("the recorded lines are not an unbroken run of the lines sent")


def _program(p: float) -> float:
    return float(np.interp(p, PROGRAM[0], PROGRAM[1]))


def test_run_follows_program_records_every_line_and_fit_recovers_slope(
    rig: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    tmp, sim, sen, k = rig["tmp"], rig["sim"], rig["sen"], rig["k"]
    (tmp / "st.toml").write_text(_toml(sim.port, [("imu", sen.device)]))
    out = tmp / "rec"
    rc = main(["station", "run", str(tmp / "st.toml"), "--profile", str(rig["prof"]),
               "-o", str(out), "--time-scale", str(k), "--json"])  # fmt: skip
    res = json.loads(capsys.readouterr().out)
    assert rc == 0 and res["ended"] == "end"
    n_sent = len(sen.sent)

    # set-points the chamber received against the program
    writes = sim.writes
    assert writes[-1][1] == pytest.approx(25.0)  # the safe set-point, last
    t0 = writes[0][0]
    for t, v in writes[:-1]:
        p = (t - t0) * k
        window = [_program(q) for q in np.linspace(p - 25 * k / 100, p + 25 * k / 100, 51)]
        assert min(window) - SCALE <= v <= max(window) + SCALE, (p, v)
    got = {round(v, 2) for _t, v in writes}
    assert {25.0, -10.0, 70.0} <= got
    # reached the last ramp's end, within the host-clock tolerance of the loop above (0.25 s:
    # the first write's time stamp t0 is taken after the program's clock started)
    assert (writes[-2][0] - t0) * k > 2400 - 0.25 * k

    # every line sent while the port was open is in the recording, in order, none twice
    rec = _recorded(out, "imu")
    i0 = _contiguous_in(rec, sen.sent[:n_sent])
    assert i0 <= 60 and i0 + len(rec) >= n_sent - 60  # 50 Hz: ≤ 1.2 s before open/after close
    bad = (out / "imu.bad.txt").read_text().splitlines()
    assert len(bad) >= len(rec) // 41 - 1
    assert all(line.split("\t")[3] in (*sen.sent_bad, sen.banner[0]) for line in bad)

    # the folder is one recording for every command: the fit recovers the thermal slope
    model_path = tmp / "m.json"
    rc = main(["fit", str(out), "--model", "poly", "--order", "1", "--signal", "gx",
               "--temps", "temp", "-o", str(model_path), "--json"])  # fmt: skip
    capsys.readouterr()
    assert rc == 0
    coef = {c["name"]: c for c in json.loads(model_path.read_text())["coefficients"]}
    slope_deg_h = GyroTruth().slope_deg_s_per_c * 3600.0  # 7.2 deg/h/°C
    assert coef["T1"]["value"] == pytest.approx(slope_deg_h, rel=0.01)


def _wait(pred, timeout_s: float, what: str) -> None:  # type: ignore[no-untyped-def]
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if pred():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def _spawn(args: list[str]) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONPATH": SRC}
    code = "import sys; from thermocal.cli import main; sys.exit(main())"
    return subprocess.Popen([sys.executable, "-c", code, *args], env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)  # fmt: skip


def test_ctrl_c_writes_safe_setpoint(rig: dict) -> None:
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    (tmp / "st.toml").write_text(_toml(sim.port, [("imu", sen.device)], safe_setpoint_c=21.5))
    out = tmp / "rec"
    proc = _spawn(["station", "run", str(tmp / "st.toml"), "--profile", str(rig["prof"]),
                   "-o", str(out), "--time-scale", "100"])  # fmt: skip
    try:
        _wait(lambda: len(sim.writes) >= 3, 15, "set-points")
        proc.send_signal(signal.SIGINT)
        _o, err = proc.communicate(timeout=15)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    assert sim.writes[-1][1] == pytest.approx(21.5)
    assert "safe set-point 21.5" in err and "--resume" in err
    assert _recorded(out, "imu")  # the open part was closed on the way out


def test_sigkill_loses_only_the_open_part_and_resume_continues(
    rig: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    tmp, sim, sen, k = rig["tmp"], rig["sim"], rig["sen"], 100.0
    rig["model"].time_scale = k
    sen.time_scale = k
    (tmp / "st.toml").write_text(_toml(sim.port, [("imu", sen.device)]))
    out = tmp / "rec"
    proc = _spawn(["station", "run", str(tmp / "st.toml"), "--profile", str(rig["prof"]),
                   "-o", str(out), "--time-scale", str(k)])  # fmt: skip
    try:
        _wait(lambda: len(list(out.glob("imu-*.parquet"))) >= 3, 20, "three closed parts")
        time.sleep(0.3)
        proc.kill()
        proc.communicate(timeout=10)
    finally:
        proc.kill()
    n_sent_at_kill = len(sen.sent)
    rec = _recorded(out, "imu")
    i0 = _contiguous_in(rec, sen.sent)
    lost = n_sent_at_kill - (i0 + len(rec))
    assert 0 <= lost <= 50 * 0.5 + 50 * 0.5  # the open part (part_s 0.5 s) and the kill delay
    program_reached = max(
        max(pq.read_table(p, columns=["program_s"])["program_s"].to_pylist())
        for p in out.glob("*-*.parquet")
    )
    # the part being written has a name no reader accepts
    for p in out.glob(".*.tmp"):
        assert main(["inspect", str(p)]) == 2

    # resume: the program continues where the recording ends, without a gap
    cfg = parse_station((tmp / "st.toml").read_text())
    n_before = len(sim.writes)
    stop_at = time.monotonic() + 3.0
    res = run_station(cfg, PROGRAM, out, resume=True, time_scale=k,
                      should_stop=lambda: time.monotonic() > stop_at)  # fmt: skip
    assert res.program_start_s == pytest.approx(program_reached)
    assert not list(out.glob(".*.tmp"))
    first_p, first_v = res.setpoints[0]
    # within the first loop turns: a second of wall time at k (a CI machine running two test
    # workers on two cores took half a second for the first turn after the resume)
    assert first_p - program_reached < 1.0 * k
    assert first_v == pytest.approx(round(_program(first_p) / SCALE) * SCALE, abs=1.5 * SCALE)
    assert sim.writes[n_before][1] == pytest.approx(first_v)
    # the recording reads as one, across both runs, time increasing
    capsys.readouterr()
    assert main(["inspect", str(out), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["n_samples"] == len(_recorded(out, "imu")) > len(rec)
    doc = json.loads((out / "station.json").read_text())
    assert [r["resumed"] for r in doc["runs"]] == [False, True]


def test_chamber_that_stops_answering_stops_the_run(
    rig: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    (tmp / "st.toml").write_text(_toml(sim.port, [("imu", sen.device)], timeout_s=1.0))
    threading.Timer(1.0, sim.stop).start()
    t = time.monotonic()
    rc = main(["station", "run", str(tmp / "st.toml"), "--profile", str(rig["prof"]),
               "-o", str(tmp / "rec"), "--time-scale", "100"])  # fmt: skip
    err = capsys.readouterr().err
    assert rc == 2 and time.monotonic() - t < 10
    last = err.strip().splitlines()[-1]
    assert last.startswith("error: chamber") and "--resume" in last
    assert "could not write the safe set-point" in err
    doc = json.loads((tmp / "rec" / "station.json").read_text())
    kinds = [e["kind"] for e in doc["events"]]
    assert "chamber" in kinds and kinds[-1] == "stop"
    assert _recorded(tmp / "rec", "imu")


def test_sensor_that_stops_is_reported(rig: dict, capsys: pytest.CaptureFixture[str]) -> None:
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    (tmp / "st.toml").write_text(_toml(sim.port, [("imu", sen.device)]))
    threading.Timer(1.5, sen.silence).start()
    rc = main(["station", "run", str(tmp / "st.toml"), "--profile", str(rig["prof"]),
               "-o", str(tmp / "rec"), "--time-scale", "1000"])  # fmt: skip
    err = capsys.readouterr().err
    assert rc == 0
    assert "warning: sensor imu" in err and "stopped" in err
    doc = json.loads((tmp / "rec" / "station.json").read_text())
    ev = [e for e in doc["events"] if e["kind"] == "sensor"]
    assert ev and ev[0]["program_s"] < PROGRAM[0][-1]


def test_check_and_two_sensors_read_by_id(rig: dict, capsys: pytest.CaptureFixture[str]) -> None:
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    (tmp / "st.toml").write_text(_toml(sim.port, [("imu", sen.device)]))
    rc = main(["station", "check", str(tmp / "st.toml"), "--listen", "1", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0
    assert out["chamber"]["temperature_c"] == pytest.approx(rig["model"].advance(), abs=1.0)
    assert out["sensors"][0]["rate_hz"] == pytest.approx(50, rel=0.3)
    gx, temp = (float(x) for x in out["sensors"][0]["first_line"].split(","))
    assert math.isfinite(gx) and math.isfinite(temp)

    (tmp / "bad.toml").write_text(_toml(sim.port, [("imu", sen.device), ("b", "/dev/nonexist")]))
    rc = main(["station", "check", str(tmp / "bad.toml"), "--listen", "0.5"])
    err = capsys.readouterr().err
    assert rc == 2 and "sensor b" in err.splitlines()[-1]


def test_two_sensors_each_read_as_a_recording(
    rig: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    tmp, sim, sen, model = rig["tmp"], rig["sim"], rig["sen"], rig["model"]
    sen2 = SimulatedSerialSensor(model, rate_hz=20, time_scale=rig["k"], seed=2).start()
    try:
        (tmp / "st.toml").write_text(_toml(sim.port, [("a", sen.device), ("b", sen2.device)]))
        out = tmp / "rec"
        stop_at = time.monotonic() + 2.0
        cfg = parse_station((tmp / "st.toml").read_text())
        run_station(cfg, PROGRAM, out, time_scale=rig["k"],
                    should_stop=lambda: time.monotonic() > stop_at)  # fmt: skip
    finally:
        sen2.stop()
    assert main(["inspect", str(out)]) == 2
    assert "name one with --sensor ID" in capsys.readouterr().err
    for sid, s in (("a", sen), ("b", sen2)):
        assert main(["inspect", str(out / sid), "--json"]) == 0
        info = json.loads(capsys.readouterr().out)
        assert info["n_samples"] == len(_recorded(out, sid))
        _contiguous_in(_recorded(out, sid), s.sent)


def test_modbus_rtu_over_a_pseudo_terminal_pair(tmp_path: Path) -> None:
    """Two pseudo-terminals joined by a thread copying bytes both ways: the station's
    client opens one end, pymodbus's RTU server the other."""
    import select
    import tty

    m1, s1 = os.openpty()
    m2, s2 = os.openpty()
    for fd in (s1, s2):
        tty.setraw(fd)
    stop = threading.Event()

    def bridge() -> None:
        while not stop.is_set():
            r, _w, _x = select.select([m1, m2], [], [], 0.05)
            for fd in r:
                try:
                    data = os.read(fd, 1024)
                except OSError:
                    return
                os.write(m2 if fd == m1 else m1, data)

    th = threading.Thread(target=bridge, daemon=True)
    th.start()
    model = ChamberModel(temperature_c=-12.34, setpoint_c=-12.34)
    sim = SimulatedChamber(model=model, scale=SCALE, rtu_port=os.ttyname(s2)).start()
    try:
        from thermocal.station.chamber import ModbusChamber
        from thermocal.station.config import ChamberConfig

        ch = ModbusChamber(ChamberConfig(driver="modbus-rtu", device=os.ttyname(s1),
                                         baud=115200, setpoint_register=300,
                                         temperature_register=100, scale=SCALE))  # fmt: skip
        ch.connect()
        assert ch.read_temperature() == pytest.approx(-12.34, abs=SCALE)  # signed counts
        ch.write_setpoint(-40.0)
        assert sim.writes[-1][1] == pytest.approx(-40.0)
        assert ch.read_setpoint() == pytest.approx(-40.0)
        ch.close()
    finally:
        sim.stop()
        stop.set()
        th.join(2)
        for fd in (m1, s1, m2, s2):
            os.close(fd)


def test_station_errors_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    st = tmp_path / "st.toml"
    st.write_text(_toml(1, [("imu", "/dev/null")]).replace('"modbus-tcp"', '"modbus-udp"'))
    assert main(["station", "check", str(st)]) == 2
    assert "driver must be one of" in capsys.readouterr().err
    st.write_text(_toml(1, [("imu", "/dev/null")]))
    monkeypatch.setitem(sys.modules, "pymodbus.client", None)
    assert main(["station", "check", str(st)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == (
        "error: the test station needs pymodbus, which is not installed: "
        "pip install 'thermocal[station]'"
    )


@pytest.mark.parametrize("unit", [248, 255, -1])
def test_a_modbus_slave_id_beyond_247_is_refused(unit: int) -> None:
    """Modbus over serial line (Modbus Organization, V1.02, §2.2): individual slave
    addresses are 1…247 (0 broadcast); 248…255 are reserved.  The id is a plain TOML
    integer, so a typo lands there first."""
    from thermocal.errors import ThermocalInputError

    with pytest.raises(ThermocalInputError, match=r"unit \(slave id\) must be 0\.\.247"):
        parse_station(_toml(1, [("imu", "/dev/null")], unit=unit))
    assert parse_station(_toml(1, [("imu", "/dev/null")], unit=247)).chamber.unit == 247
