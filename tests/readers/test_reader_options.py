"""Issue 38, the reader options every command shares: time units said once and where
they are really guessed, a stated unit that contradicts the column's name, columns named
like temperatures, sample counters and ``--rate``, host-timestamp jitter, text columns a
command does not use, units nothing states, and tables outside a terminal."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from thermocal.cli import main
from thermocal.errors import TextLayoutWarning, UnitError, UnitWarning
from thermocal.readers import read_recording
from thermocal.readers.options import ReadOptions


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def _warnings(err: str) -> list[str]:
    return [ln for ln in err.splitlines() if ln.startswith("warning: ")]


# --- 7: the time column's unit, named and said once -------------------------------------


def test_inspect_names_the_real_time_column_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "log.csv"
    path.write_text("time,gyro,temp\n" + "".join(f"{i},{i % 3},25\n" for i in range(20)))
    code, _out, err = _run(capsys, "inspect", str(path))
    assert code == 0, err
    timing = [w for w in _warnings(err) if "time column" in w]
    assert timing == [
        f"warning: {path}: no unit stated for the time column 'time'; assuming s (give "
        "--time-unit, or the unit in the file's metadata or column name)"
    ]
    assert "<time>" not in err
    with pytest.warns(UnitWarning) as caught:  # the library: one read, the real name
        rec = read_recording(path, guess_temperatures=True)
    said = [str(w.message) for w in caught]
    library = timing[0].removeprefix("warning: ").replace("--time-unit", "time_unit")
    assert [m for m in said if "time column" in m] == [library]  # the parameter's name
    assert rec.temperatures == ("temp",) and rec.unit_sources["temp"] == "default"


def test_inspect_with_time_unit_or_named_unit_says_nothing_of_time(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "log.csv"
    path.write_text("time,gyro,temp\n" + "".join(f"{i},{i % 3},25\n" for i in range(20)))
    code, _out, err = _run(capsys, "inspect", str(path), "--time-unit", "s")
    assert code == 0, err
    assert not [w for w in _warnings(err) if "time column" in w], err
    named = tmp_path / "named.csv"
    named.write_text("time (ms),gyro,temp\n" + "".join(f"{10 * i},{i % 3},25\n" for i in range(20)))
    code, out, err = _run(capsys, "inspect", str(named), "--json")
    assert code == 0, err
    assert not [w for w in _warnings(err) if "time column" in w], err
    assert_allclose(json.loads(out)["sample_rate_hz"], 100.0)


# --- 6: a stated unit that contradicts the column's name ---------------------------------


def test_time_unit_contradicting_the_column_name_is_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "log.csv"
    path.write_text("time (ms),gyro\n" + "".join(f"{10 * i},{i % 3}\n" for i in range(20)))
    code, out, err = _run(capsys, "inspect", str(path), "--time-unit", "s", "--json")
    assert code == 0, err
    said = [w for w in _warnings(err) if "contradicts" in w]
    assert said == [
        f"warning: {path}: --time-unit s contradicts the column name 'time (ms)', which says "
        "ms; using s (drop --time-unit if the name is right)"
    ]
    assert_allclose(json.loads(out)["sample_rate_hz"], 0.1)  # as the option says
    with pytest.warns(UnitWarning, match="contradicts the column name 'time \\(ms\\)'"):
        rec = read_recording(
            path, ReadOptions(time_unit="s", signals=["gyro"], signal_unit="deg/h")
        )
    assert_allclose(rec.time_s[1], 10.0)


# --- 5: a column named like a temperature is not time ---------------------------------------


def test_names_with_a_temperature_first_is_not_time(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "noh.txt"
    path.write_text("".join(f"25.{i % 3} 0.01 0.02 9.81\n" for i in range(50)))
    code, _out, err = _run(capsys, "inspect", str(path), "--names", "T,ax,ay,az")
    assert code == 2
    assert err.splitlines()[-1] == (
        f"error: {path}: no column 'time'; available: 'T', 'ax', 'ay', 'az' (name the time "
        "column with --time, or give --rate HZ for a log without one; 'T' is named like a "
        "temperature, not time)"
    )
    from thermocal.errors import MissingColumnError

    with (
        pytest.warns(TextLayoutWarning, match="blank-separated"),
        pytest.raises(MissingColumnError, match="'T' is named like a temperature, not time"),
    ):
        read_recording(path, ReadOptions(names=("T", "ax", "ay", "az")))
    code, out, err = _run(
        capsys, "inspect", str(path), "--names", "T,ax,ay,az", "--rate", "50", "--json"
    )
    assert code == 0, err
    d = json.loads(out)
    assert_allclose(d["sample_rate_hz"], 50.0)
    assert d["columns"]["T"]["role"] == "temperature"


# --- 2, 3: a sample counter is the time with --rate; multipos takes --rate ---------------

IMUCAL = Path(__file__).parents[1] / "data" / "imucal_ferraris" / "example_ferraris_session.csv"


def test_imucal_counter_is_time_with_rate(capsys: pytest.CaptureFixture[str]) -> None:
    """imucal's example session (``n_samples``, 102.4 Hz in imucal's own example): the
    counter over the rate is the time; without ``--rate`` the message says so."""
    code, _out, err = _run(capsys, "inspect", str(IMUCAL))
    assert code == 2
    assert "'n_samples' is a sample counter: give --rate HZ" in err.splitlines()[-1]
    code, out, err = _run(capsys, "inspect", str(IMUCAL), "--rate", "102.4", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["n_samples"] == 10376
    assert_allclose(d["duration_s"], 10375 / 102.4)
    assert d["gaps"] == []
    assert not [w for w in _warnings(err) if "time column" in w], err
    rec = read_recording(IMUCAL, _rate(102.4))
    counts = np.loadtxt(IMUCAL, delimiter=",", skiprows=1, usecols=0)
    assert_allclose(rec.time_s, counts / 102.4, rtol=0, atol=1e-12)


def _rate(hz: float) -> object:

    return ReadOptions(rate_hz=hz)


def test_counter_gaps_are_gaps(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    counts = np.r_[0:40, 43:80]  # 40, 41, 42 lost
    path = tmp_path / "c.csv"
    path.write_text("seq,gx\n" + "".join(f"{c},{c % 5}\n" for c in counts))
    code, out, err = _run(capsys, "inspect", str(path), "--rate", "10", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert [(g["after_row"], round(g["length_s"], 9)) for g in d["gaps"]] == [(39, 0.4)]
    named = tmp_path / "frame.csv"  # a counter of any name, named with --time
    named.write_text("frame,gx\n" + "".join(f"{c + 7},{c % 5}\n" for c in counts))
    code, out, err = _run(
        capsys, "inspect", str(named), "--time", "frame", "--rate", "10", "--json"
    )
    assert code == 0, err
    d = json.loads(out)
    assert [(g["after_row"], round(g["length_s"], 9)) for g in d["gaps"]] == [(39, 0.4)]
    assert_allclose(d["duration_s"], (counts[-1] - counts[0]) / 10.0)
    bad = tmp_path / "b.csv"
    bad.write_text("seq,gx\n0,1\n1,1\n1.5,1\n2,1\n")
    code, _out, err = _run(capsys, "inspect", str(bad), "--rate", "10")
    assert code == 2
    assert "row 2 holds 1.5, not a whole number" in err


def test_multipos_takes_rate(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """``multipos`` advised ``--rate`` and did not take it; now it reads imucal's counter
    with it (the pose count is the pose detector's business: only the reading is judged)."""
    out = tmp_path / "cal.json"
    code, _o, err = _run(
        capsys, "multipos", str(IMUCAL), "--accel", "acc_x,acc_y,acc_z", "-o", str(out),
        "--latitude", "49.6",
    )  # fmt: skip
    assert code == 2 and "give --rate HZ" in err.splitlines()[-1]
    code, _o, err = _run(
        capsys, "multipos", str(IMUCAL), "--rate", "102.4", "--accel", "acc_x,acc_y,acc_z",
        "-o", str(out), "--latitude", "49.6",
    )  # fmt: skip
    assert code == 2
    assert "No such option" not in err and "give --rate" not in err


# --- 8: an accelerometer column's unit is asked for, never a rate ---------------------------


def test_multipos_asks_for_the_accel_unit(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code, _o, err = _run(
        capsys, "multipos", str(IMUCAL), "--rate", "102.4", "--accel", "acc_x,acc_y,acc_z",
        "-o", str(tmp_path / "cal.json"), "--latitude", "49.6",
    )  # fmt: skip
    assert code == 2
    assert "deg/h" not in err
    assert err.splitlines()[-1] == (
        f"error: {IMUCAL}: no unit stated for column 'acc_x'; give --accel-unit (or the unit "
        "in the file's metadata or column name)"
    )
    with pytest.raises(UnitError, match="give accel_unit"):
        read_recording(
            IMUCAL, _rate(102.4).replace(signals=["acc_x"]), ask_units={"acc_x": "accel_unit"}
        )


# --- 4: host timestamps with Bluetooth jitter ---------------------------------------------


def _bluetooth(path: Path, lost: list[int], bursts: bool = True, ms: bool = True) -> np.ndarray:
    """A 100 Hz sensor stamped by a host: latency uniform over 0…60 % of the period, every
    50th sample a burst of 5 delivered at once, stamps in whole ms, rows ``lost`` dropped.
    Returns the true sample times of the rows kept (the simulator's truth)."""
    rng = np.random.default_rng(3)
    r, n = 100.0, 3000
    truth = 5.0 + np.arange(n) / r
    stamp = truth + rng.uniform(0.0, 0.6 / r, n)
    if bursts:
        for b in range(10, n - 10, 50):
            stamp[b : b + 5] = stamp[b + 4]
    if ms:
        stamp = np.floor(stamp * 1000.0) / 1000.0
    stamp = np.maximum.accumulate(stamp)
    keep = np.ones(n, dtype=bool)
    keep[lost] = False
    g = rng.normal(size=n)
    path.write_text(
        "time,gx\n" + "".join(f"{float(stamp[i])!r},{g[i]:.5f}\n" for i in np.flatnonzero(keep))
    )
    return truth[keep]


def test_jitter_is_said_and_rate_takes_the_nominal_grid(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from thermocal.recording import time_jitter

    path = tmp_path / "bt.csv"
    truth = _bluetooth(path, [700, 1500, 1501, 2300])
    base = ["--time-unit", "s", "--signal", "gx", "--signal-unit", "deg/s"]
    code, out, err = _run(capsys, "inspect", str(path), *base, "--json")
    assert code == 2  # bursts: samples share a stamp
    assert "give --rate HZ" in err.splitlines()[-1]
    d = json.loads(out)
    kinds = {p["kind"]: p for p in d["problems"]}
    assert "give --rate HZ" in kinds["timestamp_jitter"]["message"]
    stamps = np.loadtxt(path, delimiter=",", skiprows=1, usecols=0)
    dt = np.diff(stamps)
    want = (np.percentile(dt, 95) - np.percentile(dt, 5)) / (2 * np.median(dt))
    jit = time_jitter(stamps)
    assert jit is not None
    assert_allclose(jit.relative, want)
    assert jit.n_same == int(np.count_nonzero(dt == 0)) > 0
    assert_allclose(d["timestamp_jitter"]["relative"], want)
    assert d["timestamp_jitter"]["n_same"] == jit.n_same
    # --rate: the samples at the nominal rate, the lost ones as gaps (the truth, to 1e-9 s)
    code, out, err = _run(capsys, "inspect", str(path), *base, "--rate", "100", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert [(g["after_row"], round(g["length_s"], 9)) for g in d["gaps"]] == [
        (699, 0.02),
        (1498, 0.03),
        (2296, 0.02),
    ]
    rec = read_recording(
        path, _rate(100.0).replace(time_unit="s", signals=["gx"], signal_unit="deg/s")
    )
    assert_allclose(rec.time_s - rec.time_s[0], truth - truth[0], rtol=0, atol=1e-9)


def test_jitter_without_bursts_is_a_warning_of_every_command(tmp_path: Path) -> None:
    from thermocal.errors import TimestampWarning

    path = tmp_path / "bt.csv"
    _bluetooth(path, [], bursts=False)
    rec = read_recording(path, ReadOptions(time_unit="s", signals=["gx"], signal_unit="deg/s"))
    with pytest.warns(TimestampWarning, match=r"scatter ±\d+(\.\d+)? % .* give rate_hz HZ"):
        rec.validate()
    jit = rec.time_jitter()
    assert jit is not None and 0.2 < jit.relative < 0.4 and jit.n_same == 0


def test_rate_on_exact_stamps_recovers_whole_lost_periods(tmp_path: Path) -> None:
    """Stamps not rounded to ms: the latency floors before and after a loss differ by a
    fraction of a period, the samples lost are still whole periods (the truth to 1e-9 s)."""
    path = tmp_path / "bt.csv"
    truth = _bluetooth(path, [700, 1500, 1501, 2300], ms=False)
    rec = read_recording(
        path, _rate(100.0).replace(time_unit="s", signals=["gx"], signal_unit="deg/s")
    )
    assert_allclose(rec.time_s - rec.time_s[0], truth - truth[0], rtol=0, atol=1e-9)


# --- 9: tables outside a terminal are not cut ------------------------------------------------


def test_wide_table_is_not_cut_outside_a_terminal(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from thermocal.cli import common

    monkeypatch.delenv("COLUMNS", raising=False)
    monkeypatch.setattr(common.stdout, "_console", None)  # built anew, as a new process does
    names = [f"data/real/adis16465_run_{i}_static_2p8h_gyro_x" for i in range(3)]
    path = tmp_path / "wide.csv"
    path.write_text("time," + ",".join(names) + "\n" + "".join(f"{i},1,2,3\n" for i in range(20)))
    code, out, err = _run(capsys, "inspect", str(path), "--time-unit", "s")
    assert code == 0, err
    for name in names:
        assert name in out
    assert max(len(line) for line in out.splitlines()) > 80


# --- 1: a text column the command does not use ----------------------------------------------


def _mac_log(path: Path, sep: str = ";", dec: str = ",", banner: bool = True) -> np.ndarray:
    """An MPU logger's text log: a banner, ``time;mac;ax;ay;az`` with a MAC address on
    every line and decimal commas; returns ax as written."""
    ax = np.round(np.sin(np.arange(100) / 7.0) * 0.05, 4)
    rows = [
        sep.join(
            [f"{0.01 * i:.2f}", f"AA:BB:CC:DD:EE:{i % 99:02d}", f"{ax[i]:.4f}", "0.02", "9.81"]
        )
        for i in range(100)
    ]
    if dec == ",":
        rows = [r.replace(".", ",") for r in rows]
    head = ["MPU6050 logger v1"] if banner else []
    path.write_text("\n".join([*head, sep.join(["time", "mac", "ax", "ay", "az"]), *rows]) + "\n")
    return ax


def test_a_text_column_not_used_is_read_past(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "mpu.csv"
    ax = _mac_log(path)
    code, out, err = _run(capsys, "inspect", str(path), "--time-unit", "s", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert_allclose(d["columns"]["ax"]["mean"], ax.mean())
    assert_allclose(d["sample_rate_hz"], 100.0)
    assert [p["column"] for p in d["problems"] if p["kind"] == "non_numeric"] == ["mac"]
    skipped: list[str] = []
    with pytest.warns(TextLayoutWarning):  # the banner and the layout are stated
        rec = read_recording(
            path, ReadOptions(time_unit="s", signals=["ax"], signal_unit="g"), skipped=skipped
        )
    assert_allclose(rec.columns["ax"], ax)
    assert skipped == ["mac"]
    # a used column that holds text: exit 2 naming the column and the file
    code, _out, err = _run(
        capsys, "inspect", str(path), "--time-unit", "s", "--signal", "mac", "--signal-unit", "g"
    )
    assert code == 2
    assert err.splitlines()[-1] == (
        f"error: {path}: non-numeric value 'AA:BB:CC:DD:EE:00' in column 'mac' at row 0 "
        "(line 3 of the file)"  # after the banner and the header
    )


def test_a_stray_word_is_still_a_mangled_line(tmp_path: Path) -> None:
    from thermocal.errors import FileFormatError

    path = tmp_path / "m.log"
    lines = ["time;g"] + [f"{i};{i % 3}" for i in range(30)]
    lines[10] = "9;oops"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(FileFormatError, match="line 11 is not a data row"):
        read_recording(path, ReadOptions(time_unit="s", signals=["g"], signal_unit="deg/h"))


READING_COMMANDS = (
    "inspect", "allan", "metrics", "noise", "fit", "validate", "compensate", "report",
    "turntable", "multipos",
)  # fmt: skip
"""The commands that read a recording through the one reader, whose messages may say --rate."""


@pytest.mark.parametrize("command", READING_COMMANDS)
def test_every_reading_command_takes_rate(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([command, "--help"]) == 0
    out = capsys.readouterr().out
    for option in ("--rate", "--names", "--on-bad-lines", "--delimiter", "--decimal"):
        assert f"{option} " in out, f"{command} lacks {option}"


def test_multipos_on_bluetooth_stamps_with_rate_equals_true_time(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A simulated Ferraris session (six faces and named 360° turns, true gyro
    misalignments known) stamped by a Bluetooth host (latency 0…60 % of the period, bursts
    of 5 at one instant, whole ms): without ``--rate`` refused naming it; with ``--rate
    100`` the gyro calibration equals the one from the true sample times (to 0.01″ and
    0.01 ppm) and the simulator's truth within 5 σ."""
    import dataclasses

    from thermocal.simulate import SimulateOptions, simulate_scenario
    from thermocal.writers import write_recording

    opts = dataclasses.replace(SimulateOptions(), turns=True)
    rec, truth = simulate_scenario("multipos", 0, None, opts).results[0]
    clean = tmp_path / "clean.csv"
    write_recording(rec, clean)
    rng = np.random.default_rng(5)
    n, r = rec.n_samples, 100.0
    assert_allclose(np.diff(rec.time_s), 1.0 / r)
    stamp = rec.time_s + rng.uniform(0.0, 0.6 / r, n)
    for b in range(10, n - 10, 50):
        stamp[b : b + 5] = stamp[b + 4]
    stamp = np.maximum.accumulate(np.floor(stamp * 1000.0) / 1000.0)
    bt = tmp_path / "bt.csv"
    write_recording(dataclasses.replace(rec, time_s=stamp), bt)
    poses = tmp_path / "poses.json"
    poses.write_text(json.dumps(truth["sections"]))
    cols = ["--accel", "accel_x,accel_y,accel_z", "--gyro", "gyro_x,gyro_y,gyro_z"]

    def run(path: Path, *extra: str) -> tuple[int, dict[str, object], str]:
        code, out, err = _run(
            capsys, "multipos", str(path), *cols, "--poses", str(poses),
            "-o", str(tmp_path / f"{path.stem}{len(extra)}.json"), "--json", *extra,
        )  # fmt: skip
        return code, (json.loads(out) if code == 0 else {}), err

    code, _d, err = run(bt)
    assert code == 2 and "give --rate HZ" in err.splitlines()[-1]
    code, ref, err = run(clean)
    assert code == 0, err
    code, got, err = run(bt, "--rate", "100")
    assert code == 0, err
    g_ref, g_got = ref["gyro"], got["gyro"]
    assert isinstance(g_ref, dict) and isinstance(g_got, dict)
    assert_allclose(g_got["misalignment_arcsec"], g_ref["misalignment_arcsec"], atol=0.01)
    assert_allclose(g_got["scale_factor_ppm"], g_ref["scale_factor_ppm"], atol=0.01)
    true_mis = np.array(truth["gyro_theta"][6:12])
    z = (np.array(g_got["misalignment_arcsec"]) - true_mis) / np.array(
        g_got["misalignment_arcsec_sigma"]
    )
    assert np.all(np.abs(z) < 5.0), z


@pytest.mark.parametrize("seed", range(12))
def test_nominal_time_recovers_lost_samples_of_random_sessions(seed: int) -> None:
    """A 100 Hz sensor, a host whose latency is uniform over 0…60 % of a period (stamps
    exact or in whole ms), six samples lost at random places (two may be adjacent), a
    host clock 20 ppm slow: every sample back on the true grid (1e-9 s), six found lost."""
    from thermocal.recording import nominal_time

    rng = np.random.default_rng(seed)
    r, n = 100.0, 5000
    truth = 3.0 + np.arange(n) / r
    stamp = truth * (1.0 + 20e-6) + rng.uniform(0.0, 0.6 / r, n)
    if seed % 2:
        stamp = np.floor(stamp * 1000.0) / 1000.0
    keep = np.ones(n, dtype=bool)
    keep[rng.choice(np.arange(50, n - 50), size=6, replace=False)] = False
    t, lost = nominal_time(np.maximum.accumulate(stamp)[keep], r)
    assert lost == 6
    assert_allclose(t - t[0], truth[keep] - truth[keep][0], rtol=0, atol=1e-9)


def test_rate_the_stamps_contradict_is_said(tmp_path: Path) -> None:
    """Host stamps of a 100 Hz sensor read with --rate 102.4: the floor rises 2.4 % a
    sample, read as lost samples; the warning gives the rate the stamps say (100 Hz)."""
    from thermocal.errors import GapWarning, TimestampWarning

    path = tmp_path / "bt.csv"
    _bluetooth(path, [], bursts=False, ms=False)
    with pytest.warns(
        TimestampWarning, match=r"rate_hz 102\.4 Hz, but .* \((99\.9\d*|100) Hz\) and 9\d more"
    ):
        read_recording(path, _rate(102.4).replace(time_unit="s", signals=["gx"], signal_unit="g"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", TimestampWarning)
        warnings.simplefilter("error", GapWarning)
        read_recording(path, _rate(100.0).replace(time_unit="s", signals=["gx"], signal_unit="g"))
