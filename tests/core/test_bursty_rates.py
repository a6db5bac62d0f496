"""Ṫ on bursty logs (issue 13 item 8): 5 s bursts at 10 Hz every 5 min.

Each burst is its own contiguous segment (the 295 s pause is a gap), shorter than the
60 s rate interval, so every Ṫ is a difference over at most 5 s of a noisy temperature —
hundreds of °C/min. The default model used to fit its rate terms on that without a word.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.models.fitting import short_rate_share


def _bursty(path: Path, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    starts = np.arange(0.0, 6 * 3600.0, 300.0)
    t = (starts[:, None] + np.arange(0.0, 5.0, 0.1)[None, :]).ravel()
    temp = 25.0 + 15.0 * np.sin(2 * np.pi * t / 21600.0) + 0.05 * rng.standard_normal(t.size)
    gyro = 0.3 * (temp - 25.0) + 0.5 * rng.standard_normal(t.size)
    pd.DataFrame({"time": t, "gyro": gyro, "T1": temp}).to_csv(path, index=False)


def test_bursty_log_warns_about_short_rate_spans(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _bursty(tmp_path / "b.csv")
    code = main(
        ["fit", str(tmp_path / "b.csv"), "--model", "poly", "--signal", "gyro",
         "--signal-unit", "deg/h", "--temps", "T1", "--temp-unit", "degC", "--time-unit", "s",
         "-o", str(tmp_path / "m.json")]
    )  # fmt: skip
    _, err = capsys.readouterr()
    assert code == 0, err
    assert "100% of the samples have a temperature rate" in err
    assert "72 contiguous segment(s)" in err


def test_plain_polynomial_on_the_same_log_does_not_warn(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _bursty(tmp_path / "b.csv")
    code = main(
        ["fit", str(tmp_path / "b.csv"), "--model", "poly", "--order", "2", "--signal", "gyro",
         "--signal-unit", "deg/h", "--temps", "T1", "--temp-unit", "degC", "--time-unit", "s",
         "-o", str(tmp_path / "m.json")]
    )  # fmt: skip
    _, err = capsys.readouterr()
    assert code == 0, err
    assert "temperature rate" not in err


@pytest.mark.parametrize(
    ("method", "expect"),
    [("backward", 30), ("forward", 30), ("centred", 0)],
)
def test_short_span_count_on_a_continuous_record(method: str, expect: int) -> None:
    """A continuous 1 Hz record of 1000 s with Δt = 60 s: the first (backward) or last
    (forward) 30 samples span < 30 s; centred differences reach ±30 s, never short."""
    t = np.arange(1000.0)
    assert short_rate_share(t, 60.0, method) == (expect, 1)
