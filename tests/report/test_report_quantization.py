"""The report's noise terms show the output quantisation ``thermocal allan`` finds
(``output_quantization``: step, kind, share, in the data's unit; issue 29 item 2).

Data written here as CSV, 100 Hz for 15 min: a gyro in [°/s] whose bias is
0.002 °/s/°C · (T − 25) plus white noise σ = 0.1 °/s, rounded to 0.05 °/s steps as a
common industrial MEMS IMU outputs it, the temperature a slow sine in °C."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

FS_HZ = 100.0
N = int(900 * FS_HZ)
STEP = 0.05  # °/s
SIGMA = 0.1  # °/s, white, before rounding
COMMON = ["--signal", "gyro z [deg/s]", "--time", "time [s]"]
KEY = "allan.before.output_quantization"


def _csv(path: Path, seed: int, phase: float, *, quantised: bool) -> Path:
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS_HZ
    temp = 25.0 + 20.0 * np.sin(2 * np.pi * t / t[-1] + phase)
    gyro = 0.002 * (temp - 25.0) + SIGMA * rng.standard_normal(N)
    if quantised:
        gyro = np.round(gyro / STEP) * STEP
    df = pd.DataFrame({"time [s]": t, "gyro z [deg/s]": gyro, "T1 [C]": temp})
    df.to_csv(path, index=False, float_format="%.6f")
    return path


@pytest.fixture(scope="module")
def work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("report_quant")
    _csv(d / "mod.csv", 1, 0.0, quantised=True)
    _csv(d / "val.csv", 2, 1.9, quantised=True)
    _csv(d / "plain.csv", 3, 1.9, quantised=False)
    code = main(["fit", str(d / "mod.csv"), "--model", "poly", "--order", "1", *COMMON,
                 "--temps", "T1 [C]", "-o", str(d / "lin.json")])  # fmt: skip
    assert code == 0
    return d


def _report(work: Path, rec: str, capsys: pytest.CaptureFixture[str]) -> str:
    out = work / f"{rec}.html"
    code = main(["report", "--model", str(work / "lin.json"), "--recording", str(work / rec),
                 *COMMON, "-o", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    return out.read_text(encoding="utf-8")


def _value(html: str, key: str) -> float:
    m = re.search(rf'data-key="{re.escape(key)}" data-value="([^"]*)"', html)
    assert m is not None, key
    return float(m.group(1))


def test_quantised_output_shows_its_step(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    html = _report(work, "val.csv", capsys)
    sec = re.search(r'<section id="allan">(.*?)</section>', html, re.S)
    assert sec is not None
    para = re.search(r'<p id="output-quantization">(.*?)</p>', sec.group(1), re.S)
    assert para is not None
    text = para.group(1)
    assert _value(html, f"{KEY}.step") == pytest.approx(STEP, rel=1e-9)
    assert "°/s" in text  # the data's own unit
    assert "rate quantisation" in text  # a rounded rate: white rate noise
    # N_q = q·√(τ0/12) [°/s·√s] → °/√h (× 60)
    n_q = STEP * math.sqrt(1.0 / FS_HZ / 12.0) * 60.0
    assert _value(html, f"{KEY}.white_density") == pytest.approx(n_q, rel=1e-9)
    # its share of the white noise: (q²/12) / (σ² + q²/12) for rounding noise independent
    # of the signal (the slope line reads N within a few %)
    share = (STEP**2 / 12.0) / (SIGMA**2 + STEP**2 / 12.0)
    assert _value(html, f"{KEY}.share_pct") == pytest.approx(100.0 * share, rel=0.15)
    # no τ⁻¹ term is claimed, and the Q cell says why (hover text)
    q_cell = re.search(
        r'title="([^"]*)"><span class="num" data-key="allan.before.slope.quant', html
    )
    assert q_cell is not None and "the rate output is quantised (step 0.05" in q_cell.group(1)
    # issue 38: the bias instability at the curve's minimum is a row of its own, a number
    for when in ("before", "after"):
        assert math.isfinite(_value(html, f"allan.{when}.minimum.bias_instability"))


def test_unquantised_output_shows_none(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    html = _report(work, "plain.csv", capsys)
    assert 'id="output-quantization"' not in html and KEY not in html
