"""compensate --chamber-log: the chamber log joined once up front, then chunk by chunk onto
each chunk's times; the same numbers as compensating the file ``profile join -o`` wrote."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from chamber_logs import write_log, write_recording
from thermocal.cli import main

UNITS = ("--time-unit", "s", "--signal-unit", "deg/h", "--temp-unit", "degC")


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def _ok(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, object]:
    code, out, err = _run(capsys, *args, "--json")
    assert code == 0, err
    return dict(json.loads(out))


def _files(tmp_path: Path) -> tuple[Path, Path]:
    log = write_log(tmp_path / "log.csv", style="hh:mm:ss", period_s=10.0, unit="degF")
    rec, _truth = write_recording(tmp_path / "rec.csv", offset_s=1234.0)
    return log, rec


def _fit(capsys: pytest.CaptureFixture[str], tmp_path: Path, log: Path, rec: Path,
         temps: str) -> Path:  # fmt: skip
    model = tmp_path / f"m_{temps.replace(',', '_')}.json"
    _ok(capsys, "fit", str(rec), "--model", "poly", "--order", "1", "--signal", "gx",
        "--temps", temps, *UNITS, "--chamber-log", str(log), "--chamber-offset", "1234",
        "-o", str(model))  # fmt: skip
    return model


@pytest.mark.parametrize(
    ("temps", "clock"),
    [("chamber", ("--chamber-offset", "1234")), ("T,chamber", ())],
    ids=["given-offset", "correlation"],
)
def test_compensate_with_the_log_equals_compensate_of_the_joined_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], temps: str, clock: tuple[str, ...]
) -> None:
    log, rec = _files(tmp_path)
    model = _fit(capsys, tmp_path, log, rec, temps)
    digest = hashlib.sha256(rec.read_bytes()).hexdigest()
    joined = tmp_path / "joined.csv"
    _ok(capsys, "profile", "join", str(rec), "--temps", "T", "--time-unit", "s",
        "--temp-unit", "degC", "--chamber-log", str(log), *clock, "-o", str(joined))  # fmt: skip
    ref = tmp_path / "ref.csv"
    _ok(capsys, "compensate", str(model), str(joined), "-o", str(ref), *UNITS)
    out = tmp_path / "out.csv"
    # chunks of 1000 rows: the join is made once, each chunk interpolated on its own times
    got = _ok(capsys, "compensate", str(model), str(rec), "-o", str(out), *UNITS,
              "--chamber-log", str(log), *clock, "--chunk-rows", "1000")  # fmt: skip
    assert got["n_chunks"] == 14
    a = np.genfromtxt(out, delimiter=",", names=True)
    b = np.genfromtxt(ref, delimiter=",", names=True)
    assert set(a.dtype.names or ()) == set(b.dtype.names or ())  # profile join orders them
    for col in ("chamber", "gx_model", "gx_comp"):
        np.testing.assert_allclose(a[col], b[col], rtol=0.0, atol=1e-12)
    # the model's line in the air taken off: the 0.01 deg/h noise left (0.3 deg/h before)
    assert float(np.std(a["gx_comp"])) < 0.0125 < 0.3 < float(np.std(a["gx"]))
    assert hashlib.sha256(rec.read_bytes()).hexdigest() == digest


def test_compensate_refuses_a_log_that_does_not_cover_the_recording(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log, rec = _files(tmp_path)
    model = _fit(capsys, tmp_path, log, rec, "chamber")
    out = tmp_path / "out.csv"
    # the log spans 20000 s; the recording's 14000 s from 10000 s on it: 71 % covered
    code, _out, err = _run(capsys, "compensate", str(model), str(rec), "-o", str(out), *UNITS,
                           "--chamber-log", str(log), "--chamber-offset", "10000")  # fmt: skip
    assert code == 2
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    assert "covers only 71.4 % of the recording" in lines[0]
    assert not out.exists()


def test_compensate_correlation_needs_the_recordings_temperature(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log, rec = _files(tmp_path)
    model = _fit(capsys, tmp_path, log, rec, "chamber")  # the model has no own temperature
    code, _out, err = _run(capsys, "compensate", str(model), str(rec), "-o",
                           str(tmp_path / "o.csv"), *UNITS, "--chamber-log", str(log))  # fmt: skip
    assert code == 2
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1 and "--chamber-offset" in lines[0], err


def test_a_triad_calibration_takes_the_log_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A turntable calibration (triads on T_imu) applied with a chamber log: the chamber
    column is the log at each sample (written here: the log's °C, read every 10 s, linearly
    interpolated), the compensated columns those of the run without the log."""
    import pandas as pd

    from thermocal.turntable.simulate import simulate_turntable_thermal
    from thermocal.writers import write_recording

    soaks, held = [], None
    for rec, truth in simulate_turntable_thermal(seed=7):
        f = tmp_path / f"{truth['label']}.parquet"
        write_recording(rec, f)
        if truth["held_out"]:
            held = rec
        else:
            soaks.append(str(f))
    assert held is not None
    cal = tmp_path / "cal.json"
    _ok(capsys, "turntable", *soaks, "--temps", "T_imu", "-o", str(cal))
    rec_path = tmp_path / "held.csv"
    t = held.time_s
    pd.DataFrame({"time": t, **{c: held.column(c) for c in held.columns if c != "time"}}).to_csv(
        rec_path, index=False
    )
    log = tmp_path / "log.csv"
    lt = np.arange(0.0, float(t[-1] - t[0]) + 20.0, 10.0)
    lv = 20.0 + 0.001 * lt
    log.write_text("Time,Air [°C]\n" + "".join(
        f"{int(s) // 3600:02d}:{int(s) % 3600 // 60:02d}:{int(s) % 60:02d},{v:.3f}\n"
        for s, v in zip(lt, lv, strict=True)), encoding="utf-8")  # fmt: skip
    plain, joined = tmp_path / "plain.csv", tmp_path / "joined.csv"
    _ok(capsys, "compensate", str(cal), str(rec_path), "-o", str(plain), "--time-unit", "s")
    _ok(capsys, "compensate", str(cal), str(rec_path), "-o", str(joined), "--time-unit", "s",
        "--chamber-log", str(log), "--chamber-offset", "0", "--chunk-rows", "5000")  # fmt: skip
    a = pd.read_csv(joined)
    b = pd.read_csv(plain)
    expected = np.interp(t - t[0], lt, np.round(lv, 3))
    np.testing.assert_allclose(a["chamber"].to_numpy(), expected, rtol=0.0, atol=1e-9)
    comp = [c for c in b.columns if c.endswith("_comp")]
    assert len(comp) == 3  # the gyro triad
    for c in comp:
        np.testing.assert_allclose(a[c].to_numpy(), b[c].to_numpy(), rtol=0.0, atol=1e-12)


def test_a_model_on_the_chamber_column_without_the_log_says_how(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log, rec = _files(tmp_path)
    model = _fit(capsys, tmp_path, log, rec, "chamber")
    code, _out, err = _run(capsys, "compensate", str(model), str(rec), "-o",
                           str(tmp_path / "o.csv"), *UNITS)  # fmt: skip
    lines = [x for x in err.splitlines() if x.strip()]
    assert code == 2 and len(lines) == 1, err
    assert "'chamber' are not in the file" in lines[0]
    assert lines[0].endswith("give the chamber log, --chamber-log FILE[:CHANNEL]")
