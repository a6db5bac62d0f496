"""A record too short for the averaging time: ``metrics --average`` names the file and the
largest value that gives two averages (half the record: an independent count here)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main


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
