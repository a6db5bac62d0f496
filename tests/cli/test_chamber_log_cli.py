"""--chamber-log on the recording commands: the chamber's own log as a model input (fit
--temps chamber), the ambient of validate (--ambient chamber), in allan/metrics/inspect,
stated by profile join, and profile correlate on two such logs."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from chamber_logs import air_c, write_log, write_recording
from thermocal.cli import main

UNITS = ("--time-unit", "s", "--signal-unit", "deg/h", "--temp-unit", "degC")


def _json(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, object]:
    code = main([*args, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return dict(json.loads(out))


def _files(tmp_path: Path) -> tuple[Path, Path, np.ndarray]:
    log = write_log(tmp_path / "log.csv", style="hh:mm:ss", period_s=10.0, unit="degF")
    rec, truth = write_recording(tmp_path / "rec.csv", offset_s=1234.0)
    return log, rec, truth


def test_fit_on_the_chamber_temperature_and_validate_with_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log, rec, _truth = _files(tmp_path)
    digest = hashlib.sha256(log.read_bytes()).hexdigest()
    model = tmp_path / "m.json"
    chamber = ("--chamber-log", f"{log}:Chamber PV", "--chamber-offset", "1234")
    fit = _json(
        capsys, "fit", str(rec), "--model", "poly", "--order", "1", "--signal", "gx",
        "--temps", "chamber", *UNITS, *chamber, "-o", str(model),
    )  # fmt: skip
    # gx = 5 + 0.02 (air − 20) + noise (tests/helpers/chamber_logs): the line in the air
    coefs = json.loads(model.read_text())
    assert fit["temperature_range"] == {"chamber": [pytest.approx(-10.0), pytest.approx(60.0)]}
    assert coefs["inputs"]["unit_sources"]["chamber"] == "chamber log"
    joined = coefs["inputs"]["chamber_log"]  # the model file says how the log was joined
    assert (joined["method"], joined["offset_s"], joined["unit"]) == ("given", 1234.0, "degF")
    val = _json(capsys, "validate", str(model), str(rec), "--ambient", "chamber", *UNITS, *chamber)
    assert val["ambient"] == "chamber"
    assert float(val["rms_after"]) < 0.0125  # the 0.01 deg/h noise left  # type: ignore[arg-type]
    assert float(val["rms_before"]) > 0.3  # the 0.02 deg/h/°C line over 70 °C  # type: ignore[arg-type]
    assert hashlib.sha256(log.read_bytes()).hexdigest() == digest


def test_profile_join_states_the_join_and_writes_the_column(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log, rec, truth = _files(tmp_path)
    out = tmp_path / "joined.csv"
    got = _json(
        capsys, "profile", "join", str(rec), "--temps", "T", "--time-unit", "s",
        "--temp-unit", "degC", "--chamber-log", str(log), "-o", str(out),
    )  # fmt: skip
    assert got["method"] == "correlation" and got["unit"] == "degF"
    offset, sigma = float(got["offset_s"]), float(got["offset_sigma_s"])  # type: ignore[arg-type]
    assert abs(offset - 1234.0) < max(3.0 * sigma, 1.0)
    assert abs(float(got["drift_ppm"])) < 4.0 * float(got["drift_sigma_ppm"])  # type: ignore[arg-type]
    assert got["output"] == str(out) and got["column"] == "chamber"
    back = np.genfromtxt(out, delimiter=",", names=True)
    assert float(np.max(np.abs(back["chamber"] - truth))) < 0.02


def test_profile_join_without_a_log_and_an_output_over_an_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log, rec, _ = _files(tmp_path)
    for args, said in (
        ([], "give the log, --chamber-log FILE[:CHANNEL]"),
        (["--chamber-log", str(log), "-o", str(log)], "log.csv"),
    ):
        code = main(["profile", "join", str(rec), "--time-unit", "s", *args])
        err = capsys.readouterr().err.splitlines()
        assert code == 2 and len(err) == 1 and said in err[0], err


def test_metrics_and_inspect_take_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log, rec, _ = _files(tmp_path)
    chamber = ("--chamber-log", str(log), "--chamber-offset", "1234")
    got = _json(capsys, "metrics", str(rec), "--signal", "gx", "--temps", "chamber", *UNITS,
                *chamber)  # fmt: skip
    assert got  # read with the chamber as its temperature
    code = main(["inspect", str(rec), *UNITS, "--temps", "T,chamber", *chamber, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "chamber" in out


def test_profile_correlate_two_chamber_logs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = write_log(tmp_path / "a.csv", style="hh:mm", unit="degF")
    b = tmp_path / "b.tsv"  # the same air on another logger: °C, tab-separated, 12 h
    times = np.arange(0.0, 20000.0, 60.0)
    rows = ["Clock\tTC1 [°C]\tTC2 [°C]"] + [
        f"{(9 + int(t) // 3600) % 12 or 12}:{(int(t) % 3600) // 60:02d}:00 "
        f"{'AM' if 9 + int(t) // 3600 < 12 else 'PM'}\t{air_c(t):.2f}\t{-air_c(t):.2f}"
        for t in times
    ]
    b.write_text("\n".join(rows) + "\n", encoding="utf-8")
    same = _json(capsys, "profile", "correlate", str(a), f"{b}:TC1", "--chamber-logs")
    assert same["r"] == pytest.approx(1.0, abs=1e-6)
    assert same["column_b"] == "TC1 [°C]"
    mirrored = _json(capsys, "profile", "correlate", str(a), f"{b}:TC2", "--chamber-logs")
    assert mirrored["r"] == pytest.approx(-1.0, abs=1e-6)


RECORDING_COMMANDS = (
    "inspect", "fit", "validate", "allan", "metrics", "noise", "report", "ratetable",
    "turntable", "multipos", "profile join", "compensate", "tumble",
)  # fmt: skip
"""The commands that read a sensor's recording and take its chamber log (compensate joins
it once and then chunk by chunk)."""


def test_every_recording_command_takes_the_same_options() -> None:
    import typer

    import thermocal.cli

    thermocal.cli._register()
    root = typer.main.get_command(thermocal.cli.app)
    want = {"--chamber-log", "--chamber-unit", "--chamber-date", "--chamber-date-order",
            "--chamber-offset", "--chamber-drift", "--chamber-tz"}  # fmt: skip
    for name in RECORDING_COMMANDS:
        command = root
        for part in name.split():
            command = command.commands[part]  # type: ignore[attr-defined]
        opts = {o for p in command.params for o in p.opts}
        assert want <= opts, (name, want - opts)


def test_a_record_streamed_window_by_window_refuses_the_log(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import pandas as pd

    log, rec, _ = _files(tmp_path)
    parquet = tmp_path / "rec.parquet"
    pd.read_csv(rec).to_parquet(parquet)
    for command in ("allan", "metrics"):
        code = main([command, str(parquet), "--signal", "gx", *UNITS, "--stream",
                     "--chamber-log", str(log), "--chamber-offset", "1234"])  # fmt: skip
        err = capsys.readouterr().err.splitlines()
        assert code == 2 and len(err) == 1, err
        assert "read without a chamber log; drop --chamber-log" in err[0]


def test_validate_on_another_run_with_its_own_log(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log, rec, _ = _files(tmp_path)
    other, _ = write_recording(tmp_path / "other.csv", offset_s=3000.0, span_s=12000.0, seed=5)
    model = tmp_path / "m.json"
    chamber = ("--chamber-log", str(log), "--chamber-offset")
    fit = ["fit", str(rec), "--model", "poly", "--order", "1", "--signal", "gx"]
    assert main([*fit, "--temps", "chamber", *UNITS, *chamber, "1234", "-o", str(model)]) == 0
    capsys.readouterr()
    code = main(["validate", str(model), str(other), "--ambient", "chamber", *UNITS,
                 *chamber, "3000", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    # the modelling run's own chamber history is not known: r is not computed, and said
    assert json.loads(out)["r"] is None
    assert "the modelling run has no chamber log: r of the ambient histories not computed" in err
    # the same line on the other run: 0.02 deg/h/°C removed, the 0.01 deg/h noise left
    assert float(json.loads(out)["rms_after"]) < 0.0125


def test_correlate_chamber_logs_names_channels_after_a_colon(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = write_log(tmp_path / "a.csv", span_s=3000.0)
    code = main(["profile", "correlate", str(log), str(log), "--chamber-logs", "--column", "TC1"])
    err = capsys.readouterr().err.splitlines()
    assert code == 2 and len(err) == 1 and "FILE:CHANNEL, not with --column" in err[0], err
