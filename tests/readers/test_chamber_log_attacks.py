"""Hostile chamber logs through the command line: exit 2 with one ``error:`` line, the log
and the recording untouched."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from chamber_logs import write_recording
from thermocal.cli import main

HOSTILE: dict[str, tuple[bytes, str]] = {
    "empty": (b"", "the chamber log is empty"),
    "blank": (b"\n\n  \n", "the chamber log is empty"),
    "binary": (b"\x00\x01\x02PK\x03\x04" * 50, "a binary file, not a chamber log"),
    "no clock": (b"Stamp,TC1 [C]\n1,20\n2,21\n", "clock column not found"),
    "header only": (
        b"Time,TC1 [C]\n",
        "clock column not found (hh:mm or hh:mm:ss under a header): columns are 'Time', 'TC1 [C]'",
    ),
    "duplicate times": (
        b"Time,TC1 [C]\n10:00,20\n10:01,21\n10:01,21.5\n10:02,22\n",
        "the clock does not advance at line 4 ('10:01' then '10:01')",
    ),
    "backwards": (b"Time,TC1 [C]\n10:00,20\n09:59,21\n10:02,22\n", "does not advance at line 3"),
    "NaN row": (b"Time,TC1 [C]\n10:00,20\n10:01,\n10:02,22\n", "line 3: channel 'TC1 [C]' has"),
    "nan text": (b"Time,TC1 [C]\n10:00,20\n10:01,nan\n10:02,22\n", "has no value ('nan')"),
    "bad clock": (b"Time,TC1 [C]\n10:00,20\n10:61,21\n", "'10:61' is not a time of day"),
    "text cell": (b"Time,TC1 [C]\n10:00,20\n10:01,21\n10:02,OPEN\n", "has no value ('OPEN')"),
    "no unit": (b"Time,TC1\n10:00,20\n10:01,21\n", "give --chamber-unit degF, degC or K"),
    "midnight": (b"Time,TC1 [C]\n23:59,20\n00:00,21\n", "wraps past midnight without a date"),
}

UNITS = ("--time-unit", "s", "--signal-unit", "deg/h", "--temp-unit", "degC")


def _digest(*paths: Path) -> list[str]:
    return [hashlib.sha256(p.read_bytes()).hexdigest() for p in paths]


@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_logs_exit_2_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    data, said = HOSTILE[name]
    log = tmp_path / "log.csv"
    log.write_bytes(data)
    rec, _ = write_recording(tmp_path / "rec.csv", offset_s=20.0, span_s=600.0)
    before = _digest(log, rec)
    args = ["inspect", str(rec), *UNITS, "--temps", "T,chamber"]
    code = main([*args, "--chamber-log", str(log), "--chamber-offset", "0"])
    err = capsys.readouterr().err.splitlines()
    assert code == 2, err
    assert len(err) == 1 and err[0].startswith("error: "), err
    assert said in err[0]
    assert _digest(log, rec) == before


def test_chamber_options_without_a_log_and_a_missing_log(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec, _ = write_recording(tmp_path / "rec.csv", offset_s=20.0, span_s=600.0)
    base = ["inspect", str(rec), *UNITS]
    for extra, said in (
        (["--chamber-offset", "3"], "--chamber-offset applies with --chamber-log"),
        (["--chamber-log", str(tmp_path / "nope.csv")], "nope.csv: no such chamber log"),
        (["--chamber-log", str(tmp_path)], "a directory, not a chamber log"),
        (
            ["--chamber-log", str(rec), "--chamber-drift", "5"],
            "--chamber-drift applies with --chamber-offset",
        ),
        (["--chamber-log", str(rec), "--chamber-date-order", "ymd"], "must be dmy or mdy"),
        (["--temps", "T,chamber"], "is the chamber log's temperature: give the log, --chamber-log"),
    ):
        code = main([*base, *extra])
        err = capsys.readouterr().err.splitlines()
        assert code == 2 and len(err) == 1 and said in err[0], err


def test_chamber_without_a_log_names_the_parameter_in_the_library(tmp_path: Path) -> None:
    """The library's message names its parameter ``chamber_log``, not the command line's."""
    from thermocal.errors import MissingColumnError
    from thermocal.readers import read_recording
    from thermocal.readers.options import ReadOptions

    rec, _ = write_recording(tmp_path / "rec.csv", offset_s=20.0, span_s=600.0)
    with pytest.raises(MissingColumnError, match="give the log, chamber_log FILE:CHANNEL"):
        read_recording(rec, ReadOptions(temperatures=("T", "chamber"), time_unit="s",
                                        signal_unit="deg/h", temp_unit="degC"))  # fmt: skip
