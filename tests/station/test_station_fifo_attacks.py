"""A FIFO given to the station (a station file, a sensor's port) is named as a FIFO."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import pytest

from thermocal.cli import main


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _refused(code: int, err: str, *needles: str) -> str:
    """Exit 2, no traceback, exactly one ``error:`` line holding every needle; that line."""
    assert "Traceback" not in err, err
    assert code == 2, f"exit {code}; stderr: {err}"
    errors = [ln for ln in err.splitlines() if ln.startswith("error: ")]
    assert len(errors) == 1, err
    for n in needles:
        assert n in errors[0], (n, errors[0])
    return errors[0]


def test_station_file_that_is_a_fifo_is_named_as_a_fifo(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``station check FIFO`` said "no such file"."""
    fifo = tmp_path / "station.toml"
    os.mkfifo(fifo)
    code = main(["station", "check", str(fifo)])
    _o, err = capsys.readouterr()
    _refused(code, err, str(fifo), "FIFO")
    assert "no such file" not in err


def test_station_port_that_is_a_fifo_is_named_as_a_fifo(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A sensor's ``device`` that is a FIFO: pyserial's "Inappropriate ioctl for device";
    now the sensor, the path and what it is."""
    pytest.importorskip("serial")
    fifo = tmp_path / "port"
    os.mkfifo(fifo)
    toml = tmp_path / "station.toml"
    toml.write_text(
        '[chamber]\ndriver = "none"\n\n[[sensor]]\nid = "imu1"\n'
        f'device = "{fifo}"\nbaud = 115200\nnames = ["gx", "temp"]\n'
        'units = ["deg/s", "degC"]\nrate_hz = 10\n'
    )
    before = _digest(toml)
    code = main(["station", "check", str(toml)])
    _o, err = capsys.readouterr()
    line = _refused(code, err, "imu1", str(fifo), "FIFO")
    assert "ioctl" not in line
    assert _digest(toml) == before
