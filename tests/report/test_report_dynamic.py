"""``thermocal report --dynamic W``: the dynamic Allan deviation of the compensated output
as a heat map in the report's stability section, and a warning (in the report and as
``warning:`` on stderr) when the output is not stationary (issue 29 item 3).

Data written here as CSV, one sample a second for 20 000 s: a gyro [°/h] whose bias is
0.3 °/h/°C · (T − 25) plus white noise, the temperature a slow sine in °C.  A linear model
fitted on a modelling run removes the temperature effect, so what the dynamic ADEV sees is
the white noise: constant in one validation run, doubling halfway through the other.
"""

from __future__ import annotations

import base64
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

N = 20_000  # samples, 1 s apart
WINDOW_S = 2000.0
COMMON = ["--signal", "gyro [deg/h]", "--time", "time [s]"]


def _csv(path: Path, seed: int, phase: float, *, doubling: bool = False) -> Path:
    rng = np.random.default_rng(seed)
    t = np.arange(N, dtype=float)
    temp = 25.0 + 20.0 * np.sin(2 * np.pi * t / N + phase)
    noise = 0.05 * rng.standard_normal(N)
    if doubling:
        noise[N // 2 :] *= 2.0  # the white noise's σ doubles halfway
    gyro = 0.3 * (temp - 25.0) + noise
    pd.DataFrame({"time [s]": t, "gyro [deg/h]": gyro, "T1 [C]": temp}).to_csv(
        path, index=False, float_format="%.9g"
    )
    return path


@pytest.fixture(scope="module")
def work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("report_dynamic")
    _csv(d / "mod.csv", 1, 0.0)
    _csv(d / "steady.csv", 2, 1.9)
    _csv(d / "doubling.csv", 3, 1.9, doubling=True)
    code = main(["fit", str(d / "mod.csv"), "--model", "poly", "--order", "1", *COMMON,
                 "--temps", "T1 [C]", "-o", str(d / "lin.json")])  # fmt: skip
    assert code == 0
    return d


def _report(work: Path, rec: str, out: Path, *extra: str) -> int:
    return main(["report", "--model", str(work / "lin.json"), "--recording", str(work / rec),
                 *COMMON, "-o", str(out), *extra])  # fmt: skip


def _value(html: str, key: str) -> float:
    m = re.search(rf'data-key="{re.escape(key)}" data-value="([^"]*)"', html)
    assert m is not None, key
    return float(m.group(1))


def _section(html: str, sid: str) -> str:
    m = re.search(rf'<section id="{sid}">(.*?)</section>', html, re.S)
    assert m is not None
    return m.group(1)


def _windows(window_s: float, step_s: float) -> int:
    """Windows of ``window_s`` stepped by ``step_s`` over N one-second samples."""
    return int((N - window_s) // step_s) + 1


def _check_map(html: str) -> str:
    """The heat map and its caption in the stability section; returns the section."""
    sec = _section(html, "allan")
    img = re.search(
        r'<img class="figure" id="fig-dynamic" src="data:image/png;base64,([A-Za-z0-9+/=]+)', sec
    )
    assert img is not None
    png = base64.b64decode(img.group(1))
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    assert _value(html, "dynamic.window_s") == WINDOW_S
    assert _value(html, "dynamic.step_s") == WINDOW_S / 2  # half a window
    assert _value(html, "dynamic.n_windows") == _windows(WINDOW_S, WINDOW_S / 2) == 19
    cap = re.search(r'id="fig-dynamic".*?<figcaption>(.*?)</figcaption>', sec, re.S)
    assert cap is not None
    assert "windows of 2000 s stepped by 1000 s" in cap.group(1)
    return sec


def test_noise_doubling_halfway_gives_map_and_warning(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = work / "doubling.html"
    code = _report(work, "doubling.csv", out, "--dynamic", str(WINDOW_S))
    err = capsys.readouterr().err
    assert code == 0, err
    assert "warning:" in err and "not stationary" in err
    html = out.read_text(encoding="utf-8")
    sec = _check_map(html)
    warn = re.search(r'<ul class="warnings" id="nonstationary">(.*?)</ul>', sec, re.S)
    assert warn is not None
    assert "compensated output of the test run is not stationary" in warn.group(1)
    assert _value(html, "dynamic.n_changes") > 0
    assert 'id="stationary"' not in sec
    # listed with the report's other warnings too
    assert "not stationary" in re.search(r'id="warnings">(.*?)</ul>', html, re.S).group(1)  # type: ignore[union-attr]


def test_stationary_output_gives_map_and_no_warning(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = work / "steady.html"
    code = _report(work, "steady.csv", out, "--dynamic", str(WINDOW_S))
    err = capsys.readouterr().err
    assert code == 0, err
    assert "not stationary" not in err
    html = out.read_text(encoding="utf-8")
    sec = _check_map(html)
    assert 'id="nonstationary"' not in sec and "not stationary" not in html
    assert 'id="stationary"' in sec
    assert _value(html, "dynamic.n_changes") == 0


def test_no_dynamic_no_map(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = work / "plain.html"
    assert _report(work, "doubling.csv", out) == 0, capsys.readouterr().err
    html = out.read_text(encoding="utf-8")
    assert 'id="fig-dynamic"' not in html and "not stationary" not in html


@pytest.mark.parametrize(
    ("window", "why"),
    [("30000", "fewer than two windows"), ("0", "window length > 0"), ("-5", "window length > 0")],
)
def test_window_the_record_cannot_hold_is_exit_2(
    work: Path, capsys: pytest.CaptureFixture[str], window: str, why: str
) -> None:
    out = work / f"refused{window}.html"
    assert _report(work, "steady.csv", out, "--dynamic", window) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and "--dynamic" in err[0]
    assert why in err[0]
    assert not out.exists()
