"""A DataFlash log pymavlink cannot finish is an error within the read budget, never a hang
(a randomly damaged log once kept pymavlink's ``DFReader.init_clock`` looping)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

pytest.importorskip("pymavlink")

from thermocal.cli import main
from thermocal.readers import dataflash


class _Looping:
    """Stands in for pymavlink's reader: its constructor does not return for 20 s (bounded,
    so that without the budget the test fails rather than hangs)."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        end = time.monotonic() + 20.0
        while time.monotonic() < end:
            time.sleep(0.01)
        raise RuntimeError("still reading")


def test_a_reader_that_never_finishes_is_an_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from pymavlink import DFReader

    log = tmp_path / "log.bin"
    log.write_bytes(b"\xa3\x95\x80" + bytes(200))
    monkeypatch.setattr(DFReader, "DFReader_binary", _Looping)
    monkeypatch.setattr(dataflash, "READ_BUDGET_S", 0.5)
    t0 = time.monotonic()
    code = main(["inspect", str(log), "--topic", "IMU.0"])
    took = time.monotonic() - t0
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and took < 10, (code, took)
    assert len(err) == 1 and "did not finish reading" in err[0] and str(log) in err[0], err
    import signal

    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0.0  # the alarm is disarmed after
