"""A record too short for the averaging time: ``ardupilot-tempcal`` has no averaging option, so
its reports fall back to an averaging time the record supports (stated in the report)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

from dataflash_writer import imu_log
from test_ardupilot_tempcal import _sweep
from thermocal.cli import main


def test_ardupilot_tempcal_short_log_reports_a_fitting_average(tmp_path: Path) -> None:
    _T, _g, _a, rows = _sweep(n=5000)  # 5000 samples every 0.03 s: 150 s
    log = tmp_path / "short.bin"
    log.write_bytes(imu_log(rows))
    buf, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(err):
        code = main(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")])
    assert code == 0, err.getvalue()
    assert "shorten --average" not in err.getvalue() + buf.getvalue()
    html = (tmp_path / "out" / "report_IMU_0_gyro.html").read_text()
    # the largest of 1-2-5 s giving ≥ 10 averages of 150 s: 150 // 10 = 15 ≥ 10, 150 // 20 = 7
    duration = 5000 * 0.03
    nice = [a for a in (1, 2, 5, 10, 20, 50, 100) if duration // a >= 10]
    assert max(nice) == 10
    assert "over 10 s averages" in html and "default 100 s" in html
