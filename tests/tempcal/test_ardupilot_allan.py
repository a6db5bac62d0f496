"""ardupilot-tempcal's reports draw the per-axis Allan deviation only when asked (``allan``,
``--allan``): without it none is computed, the section and its contents entry are left out
and a note says how to get it; the parameters and the rest of the JSON are the same either
way."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("pymavlink")

import thermocal.report.calibration as calibration_report
from dataflash_writer import imu_log
from thermocal.cli import main


def _log(tmp_path: Path, n: int = 6000) -> Path:
    """One IMU over a −10…50 °C sweep (rad/s, m/s²), the IMU message of today's firmware."""
    rng = np.random.default_rng(41)
    t = np.arange(n) * 0.1
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 30.0
    g = np.column_stack([0.002 + 0.004 * x, -0.003 * x, 0.006 * x**2])
    a = np.column_stack([0.05 + 0.08 * x, -0.06 * x, -9.80665 + 0.1 * x])
    g, a = g + rng.normal(0, 1e-4, (n, 3)), a + rng.normal(0, 2e-3, (n, 3))
    rows = [
        (int(1e6 + ti * 1e6), 0, *map(float, gg), *map(float, aa), 0, 0, float(tt))
        for ti, gg, aa, tt in zip(t, g, a, temp, strict=True)
    ]
    log = tmp_path / "s.bin"
    log.write_bytes(imu_log(rows))
    return log


def _run(log: Path, out: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> dict[str, Any]:
    code = main(["ardupilot-tempcal", str(log), "-o", str(out), "--json", *extra])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    result: dict[str, Any] = json.loads(captured.out)
    return result


def test_allan_section_only_when_asked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[int] = []
    real = calibration_report.allan_of

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(calibration_report, "allan_of", counted)
    log = _log(tmp_path)
    plain = _run(log, tmp_path / "plain", capsys)
    assert calls == []  # nothing of the Allan section computed
    asked = _run(log, tmp_path / "asked", capsys, "--allan")
    assert len(calls) == 2 * 3 * 2  # gyro and accelerometer, three axes, before and after
    for name in ("report_IMU_0_gyro.html", "report_IMU_0_accel.html"):
        without = (tmp_path / "plain" / name).read_text()
        with_ = (tmp_path / "asked" / name).read_text()
        assert 'id="fig-allan-grid"' not in without and 'id="noise"' not in without
        assert "ardupilot-tempcal LOG -o DIR --allan draws it" in without
        assert 'id="fig-allan-grid"' in with_ and 'id="noise"' in with_
        assert "--allan draws it" not in with_
    assert (tmp_path / "plain" / "ardupilot.parm").read_text() == (
        tmp_path / "asked" / "ardupilot.parm"
    ).read_text()
    strip = {"params", "calibration", "reports"}
    assert {k: v for k, v in plain.items() if k not in strip} == {
        k: v for k, v in asked.items() if k not in strip
    }
