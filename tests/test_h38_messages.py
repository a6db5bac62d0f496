"""Issue 38, "errors without a way forward": a record too short for the averaging time.

``ardupilot-tempcal`` has no averaging option; its reports said "<recording>: … (shorten
--average)".  Now the tempcal reports fall back to an averaging time the record supports
(stated in the report), and the commands that have ``--average`` name the file and the
largest value that gives two averages (half the record: an independent count here)."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

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


def _short_csv(tmp_path: Path, n: int = 300, dt: float = 0.5) -> Path:
    rng = np.random.default_rng(2)
    t = np.arange(n) * dt
    path = tmp_path / "short run.csv"
    pd.DataFrame({"time": t, "gyro": 5.0 + rng.standard_normal(n), "T": 20.0 + 0.01 * t}).to_csv(
        path, index=False
    )
    return path


def test_metrics_names_file_and_the_average_that_fits(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _short_csv(tmp_path)  # 300 samples × 0.5 s = 150 s
    code = main(["metrics", str(path), "--signal", "gyro", "--average", "100"])
    err = " ".join(capsys.readouterr().err.split())
    assert code == 2
    assert str(path) in err.replace("\n", "")
    m = re.search(r"give --average (\S+) or less", err)
    assert m is not None, err
    assert float(m.group(1)) == pytest.approx(300 * 0.5 / 2)
    assert "shorten" not in err
    # the advice works: two averages of 75 s
    assert main(["metrics", str(path), "--signal", "gyro", "--average", m.group(1)]) == 0
