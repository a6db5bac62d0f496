"""Issue 39: the station is safe whatever happens to its process, its chamber and its
folder.  Through the command line, in a real subprocess when a signal is involved, against
a scripted Modbus TCP server on 127.0.0.1 (:class:`thermocal.station.sim.SimulatedChamber`,
or a raw socket server sending broken replies) and pseudo-terminals as serial sensors.

Expected values come from outside the station: the set-points the server received, the
lines the simulated sensor sent, the TOML's numbers.  Every input is hashed before and after.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

pytest.importorskip("pymodbus")
pytest.importorskip("serial")

from station_harness import (
    HOT,
    SCALE,
    SRC,
    BrokenModbus,
    ScriptedSensor,
    _digest,
    _end,
    _events,
    _last_kept,
    _profile,
    _spawn,
    _toml,
    _wait,
    _where_is,
)
from thermocal.cli import main
from thermocal.station.config import parse_station
from thermocal.station.run import run_station
from thermocal.station.sim import ChamberModel, SimulatedChamber, SimulatedSerialSensor


@pytest.fixture
def rig(tmp_path: Path):  # type: ignore[no-untyped-def]
    """A chamber server and a 50 Hz gyro on a pseudo-terminal, K = 100."""
    model = ChamberModel(time_scale=100.0, tau_s=60.0)
    sim = SimulatedChamber(model=model, scale=SCALE).start()
    sen = SimulatedSerialSensor(model, rate_hz=50, time_scale=100.0).start()
    yield {"sim": sim, "sen": sen, "tmp": tmp_path}
    sen.stop()
    sim.stop()


@pytest.mark.parametrize("sig", ["SIGHUP", "SIGTERM", "SIGINT"])
def test_signal_writes_safe_setpoint_and_keeps_the_open_part(rig: dict, sig: str) -> None:
    """part_s = 60: every row of this run is in the part open when the signal comes."""
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml, prof = tmp / "st.toml", _profile(tmp)
    toml.write_text(_toml(sim.port, sen.device))
    before = _digest(toml, prof)
    out = tmp / "rec"
    proc = _spawn(["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
                   "--time-scale", "100"])  # fmt: skip
    try:
        _wait(lambda: sim.writes and sim.writes[-1][1] == 65.0, 60, "the hot set-point")
        time.sleep(0.5)
        n_sent = len(sen.sent)
        proc.send_signal(getattr(signal, sig))
        _o, err = proc.communicate(timeout=15)
    finally:
        _end(proc)
    num = getattr(signal, sig).value
    assert proc.returncode == 128 + num, err
    assert sim.writes[-1][1] == pytest.approx(21.5)  # the safe set-point, last
    assert f"interrupted ({sig})" in err and "--resume" in err
    # the open part closed: the rows up to the signal kept
    assert _last_kept(out, sen.sent) >= n_sent - 10
    stop = _events(out)[-1]
    assert stop["kind"] == "stop" and stop["reason"] == sig and stop["safe_setpoint_c"] == 21.5
    assert _digest(toml, prof) == before

    # --resume says how the run ended and where it left the chamber
    res = run_station(parse_station(toml.read_text()), HOT, out, resume=True,
                      time_scale=100.0, should_stop=lambda: True)  # fmt: skip
    assert res.previous == (
        f"the last run ended: interrupted by {sig}; the chamber was left at 21.50 °C "
        "(the safe set-point)"
    )


def test_closed_stderr_ends_in_the_safe_stop_and_closed_parts(rig: dict) -> None:
    """The reader of stderr goes away (a pipe to a dead ``tee``, an ssh session gone): the
    next message raises BrokenPipeError; the run stops safely, every row kept."""
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    steps = (
        tuple(float(t) for t in range(0, 2001, 20)),
        tuple(25.0 + (i % 2) * 40.0 for i in range(101)),
    )
    toml, prof = tmp / "st.toml", _profile(tmp, steps)  # a step (a stderr line) every 0.2 s
    toml.write_text(_toml(sim.port, sen.device))
    out = tmp / "rec"
    proc = _spawn(["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
                   "--time-scale", "100"], stdout=subprocess.DEVNULL)  # fmt: skip
    try:
        assert proc.stderr is not None
        try:
            _wait(lambda: len(sim.writes) >= 3, 60, "set-points", drain=proc.stderr.fileno())
        except AssertionError as exc:  # a stall fails, with where the child was
            raise AssertionError(f"{exc}; {_where_is(proc)}") from None
        n_sent = len(sen.sent)
        proc.stderr.close()
        proc.wait(timeout=15)
    finally:
        _end(proc)
    assert proc.returncode == 130
    assert sim.writes[-1][1] == pytest.approx(21.5)
    assert _last_kept(out, sen.sent) >= n_sent - 10
    stop = _events(out)[-1]
    assert stop["kind"] == "stop" and stop["reason"] == "stderr closed (BrokenPipeError)"


def test_resume_after_sigkill_says_the_chamber_was_left_hot(
    rig: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml, prof = tmp / "st.toml", _profile(tmp)
    toml.write_text(_toml(sim.port, sen.device, part_s=0.3))
    out = tmp / "rec"
    proc = _spawn(["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
                   "--time-scale", "100"])  # fmt: skip
    try:
        _wait(lambda: sim.writes and sim.writes[-1][1] == 65.0, 60, "the hot set-point")
        _wait(lambda: len(list(out.glob("imu-*.parquet"))) >= 2, 60, "closed parts")
        proc.kill()
        proc.communicate(timeout=10)
    finally:
        _end(proc)
    assert sim.writes[-1][1] == 65.0  # nobody could write the safe set-point
    rc = main(["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
               "--resume", "--time-scale", "400"])  # fmt: skip
    err = capsys.readouterr().err
    assert rc == 0, err
    assert (
        "warning: the last run was killed (no stop record: SIGKILL, a power cut or a crash); "
        "the chamber was left at 65.00 °C, the last set-point recorded"
    ) in err.splitlines()


# --- item 7: chamber values and set-points against the chamber's range ---------------------


def test_a_register_reading_0x8000_is_a_chamber_fault_not_a_temperature(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """0x8000 at 0.1 °C/count, signed: −3276.8 °C, what a controller sends for a broken
    probe.  ``check`` refuses it; ``run`` does not start on it (nothing written, no folder
    left); a probe that breaks during the run is a chamber that does not answer (the safe
    set-point written, exit 2 after ``timeout_s``), never a reading."""
    model = ChamberModel(temperature_c=-3276.8, setpoint_c=-3276.8, tau_s=1e9)
    sim = SimulatedChamber(model=model, scale=0.1).start()
    sen = SimulatedSerialSensor(lambda: 25.0, rate_hz=50).start()
    try:
        toml, prof = tmp_path / "st.toml", _profile(tmp_path)
        toml.write_text(_toml(sim.port, sen.device, part_s=0.3, timeout_s=0.5).replace(
            f"scale = {SCALE}", "scale = 0.1"))  # fmt: skip
        before = _digest(toml, prof)
        assert main(["station", "check", str(toml), "--listen", "0.3", "--json"]) == 2
        cap = capsys.readouterr()
        chamber = json.loads(cap.out)["chamber"]
        assert chamber["ok"] is False and chamber["temperature_c"] is None
        last = cap.err.strip().splitlines()[-1]
        assert last.startswith("error: did not answer: chamber (chamber modbus-tcp 127.0.0.1:")
        assert "0x8000 = -3276.8 °C is outside the chamber's range -75…180 °C" in last

        out = tmp_path / "rec"
        argv = ["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
                "--time-scale", "100"]  # fmt: skip
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("error: chamber modbus-tcp"), err
        assert "-3276.8 °C is outside" in err[0] and "st.toml" in err[0]
        assert sim.writes == [] and not out.exists()

        with model.lock:  # the probe works at the start, and breaks 1 s into the run
            model.temperature_c = model.setpoint_c = 25.0
        threading.Timer(1.0, lambda: setattr(model, "temperature_c", -3276.8)).start()
        rc = main(argv)
        err = capsys.readouterr().err
        assert rc == 2, err
        assert err.strip().splitlines()[-1].startswith("error: chamber modbus-tcp")
        assert "-3276.8 °C is outside" in err
        assert sim.writes[-1][1] == pytest.approx(21.5)
        for p in out.glob("*-*.parquet"):  # no row holds the fault as a temperature
            t = pq.read_table(p, columns=["chamber_c"])["chamber_c"].to_pylist()
            assert t and not any(v < -1000 for v in t), p
        assert _digest(toml, prof) == before
    finally:
        sen.stop()
        sim.stop()


@pytest.mark.parametrize(
    ("program", "extra", "words"),
    [
        (((0.0, 10.0, 20.0), (25.0, -100.0, -100.0)), {},
         "p.csv: set-point at program time 10 s: -100 °C is outside the chamber's range "
         "-75…180 °C"),
        (((0.0, 10.0, 20.0), (25.0, 150.0, 150.0)), {"max_c": 120},
         "p.csv: set-point at program time 10 s: 150 °C is outside the chamber's range -75…120"),
        (HOT, {"safe_setpoint_c": 200},
         "safe_setpoint_c = 200 °C is outside the chamber's range -75…180 °C"),
        (HOT, {"safe_setpoint_c": 90},
         "safe_setpoint_c = 90 °C is not a safe temperature (0…50 °C)"),
        (HOT, {"min_c": 50, "max_c": 20}, "min_c must be above -273.15 °C and below max_c"),
    ],
)  # fmt: skip
def test_setpoints_outside_the_chamber_range_are_refused_before_anything_is_written(
    rig: dict, capsys: pytest.CaptureFixture[str], program: tuple, extra: dict, words: str
) -> None:
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    text = _toml(sim.port, sen.device)
    if "safe_setpoint_c" in extra:
        text = text.replace("safe_setpoint_c = 21.5\n", "")
    toml, prof = tmp / "st.toml", _profile(tmp, program)
    toml.write_text(text.replace("[chamber]\n", "[chamber]\n" + "".join(
        f"{k} = {v}\n" for k, v in extra.items())))  # fmt: skip
    before = _digest(toml, prof)
    out = tmp / "rec"
    rc = main(["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
               "--time-scale", "100"])  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].startswith("error: "), err
    assert words in err[0] and ("st.toml" in err[0]), err
    assert sim.writes == [] and not out.exists()
    assert _digest(toml, prof) == before


def test_a_chamber_that_ignores_its_setpoint_is_noticed_in_a_short_hold(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A hold of 290 s at 60 °C, drift_s left at its 1800 s default: the chamber stays at
    25 °C (τ = 1e9 s); the hold's end says so, once; a chamber that follows says nothing."""
    k = 1000.0
    program = ((0.0, 100.0, 110.0, 400.0), (25.0, 25.0, 60.0, 60.0))
    for tau, warned in ((1e9, True), (1.0, False)):
        model = ChamberModel(time_scale=k, tau_s=tau)
        sim = SimulatedChamber(model=model, scale=SCALE).start()
        sen = SimulatedSerialSensor(model, rate_hz=50, time_scale=k).start()
        try:
            toml, prof = tmp_path / "st.toml", _profile(tmp_path, program)
            toml.write_text(_toml(sim.port, sen.device, part_s=0.3).replace(
                "poll_s = 0.1", "poll_s = 0.02"))  # fmt: skip
            out = tmp_path / f"rec{tau:g}"
            rc = main(["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
                       "--time-scale", str(k)])  # fmt: skip
        finally:
            sen.stop()
            sim.stop()
        err = capsys.readouterr().err
        assert rc == 0, err
        lines = [ln for ln in err.splitlines() if "in the hold" in ln]
        if not warned:
            assert lines == [], err
            continue
        assert lines == [
            "warning: chamber never within tolerance_c = 5 °C of the set-point 60.00 °C in "
            "the hold at program time 110–400 s (last read 25.00 °C): is it following its "
            "set-point?"
        ], err
        (ev,) = [e for e in _events(out) if e["kind"] == "hold"]
        assert ev["setpoint_c"] == 60.0 and ev["program_s"] == pytest.approx(400.0)


# --- item 8: Modbus faults, a failed start, one writer per folder --------------------------


@pytest.mark.parametrize(
    ("mode", "words"),
    [
        ("zero", "read input register 100: the reply holds 0 registers, not 1"),
        ("cut", "read input register 100: ModbusIOException"),
        ("fc", "read input register 100: the reply is for function code 6, not 4"),
    ],
)
def test_modbus_faults_are_one_error_line_naming_the_chamber_and_leave_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], mode: str, words: str
) -> None:
    """``check`` and ``run`` end in exit 2 with one ``error:`` line naming the chamber's
    address and register (never ``internal: IndexError``, never a value read from a reply
    to another request, never pymodbus's own log line); the failed start leaves no folder,
    so the same command on a chamber that answers starts afresh."""
    server = BrokenModbus(mode)
    sen = SimulatedSerialSensor(lambda: 25.0, rate_hz=50).start()
    try:
        toml, prof = tmp_path / "st.toml", _profile(tmp_path, ((0.0, 30.0), (25.0, 25.0)))
        toml.write_text(_toml(server.port, sen.device, part_s=0.3))
        before = _digest(toml, prof)
        where = f"chamber modbus-tcp 127.0.0.1:{server.port} unit 1: {words}"
        # in a process of its own: pymodbus's logging reaches the real stderr there
        proc = _spawn(["station", "check", str(toml), "--listen", "0.3"])
        _o, text = proc.communicate(timeout=30)
        err = text.strip().splitlines()
        assert proc.returncode == 2 and len(err) == 1, err
        assert err[0].startswith("error: did not answer: chamber (") and where in err[0], err

        out = tmp_path / "rec"
        argv = ["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
                "--time-scale", "100"]  # fmt: skip
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("error: " + where), err
        assert str(toml) in err[0] and server.writes == 0
        assert not out.exists()  # the failed start left nothing
        assert _digest(toml, prof) == before

        # the corrected command (a chamber that answers) starts, with the same -o
        sim = SimulatedChamber(scale=SCALE).start()
        try:
            toml.write_text(_toml(sim.port, sen.device, part_s=0.3))
            rc = main(argv)
            assert rc == 0, capsys.readouterr().err
        finally:
            sim.stop()
        assert json.loads((out / "station.json").read_text())["runs"][0]["resumed"] is False
    finally:
        sen.stop()
        server.close()


def test_one_writer_per_folder(rig: dict, capsys: pytest.CaptureFixture[str]) -> None:
    """A second ``--resume`` while a run writes the folder is refused (exit 2 naming the
    folder and the writer's process); once that process is gone — even by SIGKILL — the
    folder is free again."""
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml, prof = tmp / "st.toml", _profile(tmp)
    toml.write_text(_toml(sim.port, sen.device, part_s=0.3))
    out = tmp / "rec"
    argv = ["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
            "--time-scale", "100"]  # fmt: skip
    proc = _spawn(argv)
    try:
        _wait(lambda: len(list(out.glob("imu-*.parquet"))) >= 1, 60, "a closed part")
        n_writes = len(sim.writes)
        assert main([*argv, "--resume"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err == [
            f"error: {out}: another station run (process {proc.pid}) is writing this folder; "
            "wait for it to end, or stop it, before --resume"
        ]
        # the refused run wrote nothing to the chamber (the running one goes on)
        assert all(v in (25.0, 65.0) or 25.0 <= v <= 65.0 for _t, v in sim.writes[n_writes:])
        assert 21.5 not in [v for _t, v in sim.writes]
        proc.kill()
        proc.communicate(timeout=10)
    finally:
        _end(proc)
    rc = main([*argv, "--resume", "--time-scale", "400"])
    assert rc == 0, capsys.readouterr().err


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ('units = ["deg/s", "degC"]', 'units = ["rad/s", "degC"]',
         "sensor 'imu' units was ['deg/s', 'degC'], now ['rad/s', 'degC']"),
        ("rate_hz = 50", "rate_hz = 100", "sensor 'imu' rate_hz was 50.0, now 100.0"),
        (f"scale = {SCALE}", "scale = 0.1", f"[chamber] scale was {SCALE}, now 0.1"),
        ('id = "imu"', 'id = "imu2"', "sensors ['imu'] recorded, ['imu2'] given"),
    ],
)  # fmt: skip
def test_resume_with_other_units_or_options_is_refused(
    rig: dict, capsys: pytest.CaptureFixture[str], old: str, new: str, words: str
) -> None:
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml, prof = tmp / "st.toml", _profile(tmp)
    toml.write_text(_toml(sim.port, sen.device, part_s=0.3))
    out = tmp / "rec"
    run_station(parse_station(toml.read_text()), HOT, out, time_scale=100.0,
                should_stop=lambda: bool(list(out.glob("imu-*.parquet"))))  # fmt: skip
    capsys.readouterr()
    doc = (out / "station.json").read_bytes()
    toml.write_text(toml.read_text().replace(old, new))
    n_writes = len(sim.writes)
    assert main(["station", "run", str(toml), "--profile", str(prof), "-o", str(out),
                 "--resume", "--time-scale", "400"]) == 2  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(
        f"error: {out}: --resume with another STATION.toml than the recording's: {words}"
    ), err
    assert len(sim.writes) == n_writes and (out / "station.json").read_bytes() == doc


# --- items 3 and 4: the sensor's time against the host clock; non-finite values -----------


@pytest.mark.parametrize(("rate", "ratio"), [(1000, 0.05), (2, 25.0), (50, None)])
def test_rate_hz_that_disagrees_with_the_host_clock_is_warned_during_the_run(
    rig: dict, capsys: pytest.CaptureFixture[str], rate: float, ratio: float | None
) -> None:
    """The simulated sensor sends 50 lines per host second: ``rate_hz = 1000`` makes the
    recording's time advance 50/1000 = 0.05× as fast as the host's, ``rate_hz = 2``
    25×; the right rate says nothing."""
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml = tmp / "st.toml"
    toml.write_text(
        _toml(sim.port, sen.device, part_s=0.5).replace("rate_hz = 50", f"rate_hz = {rate}")
    )
    out = tmp / "rec"
    stop_at = time.monotonic() + 3.0
    n0 = len(sen.sent)
    run_station(parse_station(toml.read_text(), str(toml)), HOT, out, time_scale=100.0,
                should_stop=lambda: time.monotonic() > stop_at)  # fmt: skip
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "as fast as the host clock" in ln]
    if ratio is None:
        assert lines == [], err
        return
    # the ratio expected from the lines sent per host second, not from the station's records
    sent_rate = (len(sen.sent) - n0) / 3.0
    assert sent_rate == pytest.approx(50, rel=0.1)
    assert len(lines) == 1 and lines[0].startswith("warning: sensor imu: its time advances "), err
    (ev,) = [e for e in _events(out) if e["kind"] == "clock"]
    assert ev["ratio"] == pytest.approx(sent_rate / rate, rel=0.1)
    assert ev["ratio"] == pytest.approx(ratio, rel=0.1)
    assert f"rate_hz = {rate} in {toml}" in lines[0]


def test_nan_inf_and_1e999_lines_are_kept_aside_with_a_warning_during_the_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every 4th line is ``nan``, ``inf`` or ``1e999``: such lines go to imu.bad.txt with a
    warning while the run goes on; the recording holds only the finite lines and reads."""
    good = ["0.0500,25.000", "0.0510,25.010", "0.0490,25.020"]
    lines = [good[0], "nan,25.0", good[1], "0.05,inf", good[2], "1e999,25.0"]
    model = ChamberModel(time_scale=100.0)
    sim = SimulatedChamber(model=model, scale=SCALE).start()
    sen = ScriptedSensor(lines)
    try:
        toml = tmp_path / "st.toml"
        toml.write_text(
            _toml(sim.port, sen.device, part_s=0.5).replace("rate_hz = 50", "rate_hz = 100")
        )
        out = tmp_path / "rec"
        stop_at = time.monotonic() + 1.5
        res = run_station(
            parse_station(toml.read_text(), str(toml)),
            HOT,
            out,
            time_scale=100.0,
            should_stop=lambda: time.monotonic() > stop_at,
        )
    finally:
        sen.close()
        sim.stop()
    err = capsys.readouterr().err
    warned = [ln for ln in err.splitlines() if "not finite" in ln]
    assert len(warned) == 1 and warned[0].startswith("warning: sensor imu: line "), err
    rows = pq.read_table(sorted(out.glob("imu-*.parquet")), columns=["gx", "temp"])
    got = list(zip(rows["gx"].to_pylist(), rows["temp"].to_pylist(), strict=True))
    allowed = {tuple(float(x) for x in g.split(",")) for g in good}
    assert got and set(got) <= allowed  # only the finite lines, as sent
    bad = (out / "imu.bad.txt").read_text().splitlines()
    assert {ln.split("\t")[3] for ln in bad} <= {"nan,25.0", "0.05,inf", "1e999,25.0"}
    assert res.bad_lines["imu"] == len(bad) and abs(len(bad) - len(got)) <= 2
    assert main(["inspect", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_samples"] == len(got)


def test_a_10_mb_line_is_kept_aside_once_and_cut(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One 10 MB line between good lines: one bad line of at most 200 characters and a
    count, not 10 MB in imu.bad.txt; the good lines after it are recorded."""
    model = ChamberModel(time_scale=100.0)
    sim = SimulatedChamber(model=model, scale=SCALE).start()
    sen = ScriptedSensor(["0.0500,25.000"], rate_hz=100)
    try:
        toml = tmp_path / "st.toml"
        toml.write_text(
            _toml(sim.port, sen.device, part_s=0.5).replace("rate_hz = 50", "rate_hz = 100")
        )
        out = tmp_path / "rec"
        huge = ("1234567890," * 1_000_000).encode()

        def inject() -> None:
            fd = os.dup(sen.master)
            os.set_blocking(fd, True)
            os.write(fd, huge + b"\r\n")
            os.close(fd)

        threading.Timer(0.3, inject).start()
        stop_at = time.monotonic() + 3.0
        run_station(parse_station(toml.read_text(), str(toml)), HOT, out, time_scale=100.0,
                    should_stop=lambda: time.monotonic() > stop_at)  # fmt: skip
    finally:
        sen.close()
        sim.stop()
    capsys.readouterr()
    bad = (out / "imu.bad.txt").read_text().splitlines()
    assert len(bad) == 1 and (out / "imu.bad.txt").stat().st_size < 1000, bad[:2]
    assert bad[0].split("\t")[2] == "longer than 4096 bytes"
    t = pq.read_table(sorted(out.glob("imu-*.parquet")), columns=["host_time"])
    assert max(t["host_time"].to_pylist()) > 1.5  # lines after the long one recorded


@pytest.mark.parametrize(
    ("part_s", "file"), [(0.3, "station.json"), (2.0, ".imu-0000.parquet.tmp")]
)
def test_a_full_disk_stops_the_run_safely_naming_the_file(
    rig: dict, part_s: float, file: str
) -> None:
    """Files may not grow beyond 6 kB (``RLIMIT_FSIZE``: every write beyond fails with
    EFBIG, as a full disk fails with ENOSPC): the run stops with the safe set-point, one
    ``error:`` line naming the file of the recording that could not be written, exit 2."""
    import resource

    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml, prof = tmp / "st.toml", _profile(tmp)
    toml.write_text(_toml(sim.port, sen.device, part_s=part_s))
    out = tmp / "rec"
    env = {**os.environ, "PYTHONPATH": SRC, "PYTHONDONTWRITEBYTECODE": "1"}
    code = "import sys; from thermocal.cli import main; sys.exit(main())"

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (6000, 6000))

    proc = subprocess.run(
        [sys.executable, "-c", code, "station", "run", str(toml), "--profile", str(prof),
         "-o", str(out), "--time-scale", "100"],
        env=env, text=True, capture_output=True, timeout=60, preexec_fn=limit,
    )  # fmt: skip
    err = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert err[-1].startswith(f"error: {out / file}: cannot write (File too large)"), err
    assert "--resume" in err[-1] and "Traceback" not in proc.stderr
    assert sim.writes[-1][1] == pytest.approx(21.5)  # the chamber was made safe


@pytest.mark.parametrize(("unit", "warned"), [("s", True), ("ms", False)])
def test_a_millisecond_counter_declared_in_seconds_is_warned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], unit: str, warned: bool
) -> None:
    """The lines carry their own time, a counter of milliseconds read from the sender's
    clock (a real sensor's clock runs with the host's, however late a loaded machine sends
    its lines): declared in s, the recording's time runs 1000× too fast; in ms, exactly as
    fast (a counter of 10 ms per line sent, at 59 lines/s on a loaded machine, ran 0.59×
    and failed this test twice in five parallel runs)."""
    model = ChamberModel(time_scale=100.0)
    sim = SimulatedChamber(model=model, scale=SCALE).start()
    t0 = time.monotonic()
    sen = ScriptedSensor(lambda i: f"{round((time.monotonic() - t0) * 1000)},0.05,25.0", 100)
    try:
        toml = tmp_path / "st.toml"
        text = _toml(sim.port, sen.device, part_s=0.5)
        text = text.replace('names = ["gx", "temp"]', 'names = ["time", "gx", "temp"]')
        text = text.replace('units = ["deg/s", "degC"]', f'units = ["{unit}", "deg/s", "degC"]')
        toml.write_text(text.replace("rate_hz = 50\n", ""))
        out = tmp_path / "rec"
        stop_at = time.monotonic() + 2.8
        run_station(parse_station(toml.read_text(), str(toml)), HOT, out, time_scale=100.0,
                    should_stop=lambda: time.monotonic() > stop_at)  # fmt: skip
    finally:
        sen.close()
        sim.stop()
    lines = [ln for ln in capsys.readouterr().err.splitlines() if "host clock" in ln]
    if not warned:
        assert lines == []
        return
    assert len(lines) == 1 and "its time field 'time' in s in " in lines[0], lines
    (ev,) = [e for e in _events(out) if e["kind"] == "clock"]
    assert ev["ratio"] == pytest.approx(1000.0, rel=0.15)  # ms of the sender's clock, in s


def test_hangup_of_the_operators_terminal_with_the_live_display(rig: dict) -> None:
    """stderr is a terminal (a pseudo-terminal: the live display runs); the terminal goes
    away (its master closed: every write then fails) and SIGHUP comes: the safe set-point,
    the open part closed, exit 129."""
    import tty

    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml, prof = tmp / "st.toml", _profile(tmp)
    toml.write_text(_toml(sim.port, sen.device))
    out = tmp / "rec"
    master, slave = os.openpty()
    tty.setraw(slave)
    env = {**os.environ, "PYTHONPATH": SRC, "COLUMNS": "120"}
    code = "import sys; from thermocal.cli import main; sys.exit(main())"
    proc = subprocess.Popen(
        [sys.executable, "-c", code, "station", "run", str(toml), "--profile", str(prof),
         "-o", str(out), "--time-scale", "100"],
        env=env, stdout=subprocess.DEVNULL, stderr=slave, stdin=subprocess.DEVNULL,
    )  # fmt: skip
    os.close(slave)
    try:
        _wait(lambda: sim.writes and sim.writes[-1][1] == 65.0, 60, "the hot set-point")
        time.sleep(0.5)
        seen = b""
        with contextlib.suppress(OSError):
            seen = os.read(master, 1 << 16)
        n_sent = len(sen.sent)
        os.close(master)  # the terminal is gone
        proc.send_signal(signal.SIGHUP)
        proc.wait(timeout=15)
    finally:
        _end(proc)
    assert b"\x1b[" in seen  # it was the live display
    assert proc.returncode == 129
    assert sim.writes[-1][1] == pytest.approx(21.5)
    assert _last_kept(out, sen.sent) >= n_sent - 10
    stop = _events(out)[-1]
    assert stop["kind"] == "stop" and stop["reason"] == "SIGHUP"


def test_1e300_deg_s_lines_are_kept_aside_with_a_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every other line reads 1e300 deg/s: beyond any gyro (1e8 deg/h, the limit every
    command applies to a recording, = 27 778 deg/s); those lines are kept aside with one
    warning during the run, the others recorded, and the recording reads."""
    model = ChamberModel(time_scale=100.0)
    sim = SimulatedChamber(model=model, scale=SCALE).start()
    sen = ScriptedSensor(["0.0500,25.000", "1e300,25.000", "-3e4,25.000"])
    try:
        toml = tmp_path / "st.toml"
        toml.write_text(
            _toml(sim.port, sen.device, part_s=0.5).replace("rate_hz = 50", "rate_hz = 100")
        )
        out = tmp_path / "rec"
        stop_at = time.monotonic() + 1.5
        run_station(parse_station(toml.read_text(), str(toml)), HOT, out, time_scale=100.0,
                    should_stop=lambda: time.monotonic() > stop_at)  # fmt: skip
    finally:
        sen.close()
        sim.stop()
    err = capsys.readouterr().err
    warned = [ln for ln in err.splitlines() if "beyond any sensor" in ln]
    assert len(warned) == 1 and "(|value| ≤ 27777.8 deg/s)" in warned[0], err
    gx = pq.read_table(sorted(out.glob("imu-*.parquet")), columns=["gx"])["gx"].to_pylist()
    assert gx and set(gx) == {0.05}
    bad = [ln.split("\t")[3] for ln in (out / "imu.bad.txt").read_text().splitlines()]
    assert set(bad) == {"1e+300,25", "-30000,25"}
    assert main(["inspect", str(out), "--json"]) == 0
    capsys.readouterr()


def _parts(out: Path) -> dict[str, str]:
    return {p.name: _digest(p)[0] for p in sorted(out.glob("imu-*.parquet"))}


def test_resume_keeps_every_part_continues_time_and_checks_the_setpoints(
    rig: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    """Survivors of the last wave: a resume that overwrites the last part, restarts the
    rate time at 0, or accepts a program whose set-points differ."""
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml = tmp / "st.toml"
    toml.write_text(_toml(sim.port, sen.device, part_s=0.3))
    cfg = parse_station(toml.read_text(), str(toml))
    out = tmp / "rec"
    run_station(cfg, HOT, out, time_scale=100.0,
                should_stop=lambda: len(list(out.glob("imu-*.parquet"))) >= 2)  # fmt: skip
    first = _parts(out)
    doc = (out / "station.json").read_bytes()
    other = _profile(tmp, (HOT[0], (25.0, 70.0, 70.0)))  # same times, other set-points
    assert main(["station", "run", str(toml), "--profile", str(other), "-o", str(out),
                 "--resume", "--time-scale", "100"]) == 2  # fmt: skip
    err = capsys.readouterr().err
    assert "--resume with another program than the recording's" in err
    assert (out / "station.json").read_bytes() == doc
    time.sleep(0.5)
    stop_at = time.monotonic() + 1.0
    run_station(cfg, HOT, out, resume=True, time_scale=100.0,
                should_stop=lambda: time.monotonic() > stop_at)  # fmt: skip
    capsys.readouterr()
    after = _parts(out)
    assert {k: after[k] for k in first} == first and len(after) > len(first)
    old = pq.read_table([out / n for n in first], columns=["time", "host_time"])
    new = pq.read_table([out / n for n in after if n not in first], columns=["time", "host_time"])
    t_old, h_old = old["time"].to_pylist(), old["host_time"].to_pylist()
    t_new, h_new = new["time"].to_pylist(), new["host_time"].to_pylist()
    assert t_new[0] > t_old[-1] + 0.4  # the pause of 0.5 s between the runs is in the time
    # the time continues with the host clock (the lines' own clock at rate_hz = 50)
    assert (t_new[0] - t_old[-1]) == pytest.approx(h_new[0] - h_old[-1], abs=0.1)


def test_started_without_stderr_the_json_on_stdout_stays_clean(rig: dict) -> None:
    """``2>&-``: Python starts with ``sys.stderr = None`` and ``print(file=None)`` writes to
    stdout; the run's messages must not land in the ``--json`` output."""
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml, prof = tmp / "st.toml", _profile(tmp, ((0.0, 10.0, 100.0), (25.0, 30.0, 30.0)))
    toml.write_text(_toml(sim.port, sen.device, part_s=0.3))
    out = tmp / "rec"
    env = {**os.environ, "PYTHONPATH": SRC}
    code = "import sys; from thermocal.cli import main; sys.exit(main())"
    proc = subprocess.run(
        [sys.executable, "-c", code, "station", "run", str(toml), "--profile", str(prof),
         "-o", str(out), "--time-scale", "100", "--json"],
        env=env, text=True, stdout=subprocess.PIPE, timeout=60,
        preexec_fn=lambda: os.close(2),
    )  # fmt: skip
    assert proc.returncode == 0, proc.stdout
    res = json.loads(proc.stdout)  # one JSON object, nothing else
    assert res["ended"] == "end" and res["safe_setpoint_c"] == 21.5
    assert sim.writes[-1][1] == pytest.approx(21.5)


def test_parts_recorded_in_different_units_are_not_concatenated(
    rig: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    """A folder whose second part says rad/s where the first says deg/s (what a --resume
    with other units wrote before it was refused): every command refuses it, naming the
    part, the column and both units, instead of reading all of it in one unit."""
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    toml = tmp / "st.toml"
    toml.write_text(_toml(sim.port, sen.device, part_s=0.3))
    out = tmp / "rec"
    run_station(parse_station(toml.read_text(), str(toml)), HOT, out, time_scale=100.0,
                should_stop=lambda: len(list(out.glob("imu-*.parquet"))) >= 3)  # fmt: skip
    capsys.readouterr()
    assert main(["inspect", str(out), "--json"]) == 0
    capsys.readouterr()
    parts = sorted(out.glob("imu-*.parquet"))
    t = pq.read_table(parts[-1])
    key = b"thermocal"
    meta = dict(t.schema.metadata)
    (k,) = [k for k in meta if key in k]
    doc = json.loads(meta[k])
    assert doc["signals"]["gx"] == "deg/s"
    doc["signals"]["gx"] = "rad/s"
    pq.write_table(t.replace_schema_metadata({**meta, k: json.dumps(doc).encode()}), parts[-1])
    before = _digest(*parts)
    assert main(["inspect", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {parts[0]}: column 'gx' is deg/s"), err
    assert f"rad/s (signals) in {parts[-1].name}" in err[0]
    assert _digest(*parts) == before


@pytest.mark.parametrize("resume", [False, True])
def test_a_deeply_nested_station_json_is_refused_in_one_line(
    rig: dict, capsys: pytest.CaptureFixture[str], resume: bool
) -> None:
    """``[`` × 100 000: Python's JSON parser recurses (RecursionError, was exit 1)."""
    tmp, sim, sen = rig["tmp"], rig["sim"], rig["sen"]
    out = tmp / "rec"
    out.mkdir()
    (out / "station.json").write_text("[" * 100_000 + "]" * 100_000)
    before = _digest(out / "station.json")
    toml, prof = tmp / "st.toml", _profile(tmp)
    toml.write_text(_toml(sim.port, sen.device))
    argv = (["station", "run", str(toml), "--profile", str(prof), "-o", str(out), "--resume"]
            if resume else ["inspect", str(out)])  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: {out / 'station.json'}: nested too deeply to be a thermocal "
                   "station file"]  # fmt: skip
    assert _digest(out / "station.json") == before and sim.writes == []
